//! The scenes with known answers (`docs/scenes.md`), shared by the examples, the tour, the tests and the
//! benches so that each model is written once.
#![allow(dead_code)]

pub mod cart_pole;
pub mod cartesian_pendulum;
pub mod chain;
pub mod circuit;
pub mod components;
pub mod double_pendulum;
pub mod ensemble;
pub mod field;
pub mod field_lines;
pub mod figures;
pub mod first_order;
pub mod furuta;
pub mod hamiltonian;
pub mod hand_written;
pub mod hand_written_lgvi;
pub mod kepler;
pub mod knife_edge;
pub mod ladder;
pub mod lotka_volterra;
pub mod lqr;
pub mod mechanism;
pub mod membrane;
pub mod motor;
pub mod oscillator;
pub mod peers;
pub mod pendulum;
pub mod port;
pub mod ports;
pub mod progress;
pub mod reaction_wheels;
pub mod rigid_body;
pub mod rigid_chain;
pub mod rlc_ladder;
pub mod rolling_ball;
pub mod rolling_disk;
pub mod roundoff;
pub mod satellite;
pub mod shafted_body;
pub mod spherical_pendulum;
pub mod study;

use std::time::{Duration, Instant};

use dirac::prelude::*;

/// One row of the tour's table.
#[derive(Debug, Clone)]
pub struct Report {
    pub scene: &'static str,
    pub quadrature: String,
    pub h: f64,
    pub steps: u64,
    /// `max |E − E0|`; `None` where energy is not conserved by design (a driven system).
    pub max_energy_error: Option<f64>,
    pub wall: Duration,
    /// What this scene checks against its known answer, e.g. `|q(5) − q_exact| = 3e-9`.
    pub check: String,
}

/// Runs `stepper` to `t_end`, recording every `every`-th state, with a progress bar, and times it.
pub fn timed<E: dirac::StepEquations<N>, const N: usize>(
    stepper: &mut Stepper<E::System, N, E>,
    t_end: f64,
    every: usize,
) -> Result<(Trajectory<N, E::Manifold>, Duration), DiracError> {
    let bar = progress::bar(stepper.t(), t_end, stepper.h());
    let start = Instant::now();
    let run = Run::until(t_end)
        .every(every)
        .observe(progress::observer(&bar));
    let solution = stepper.solve(run)?;
    bar.finish_and_clear();
    Ok((solution.trajectory, start.elapsed()))
}

/// The quadratures every scene is run with in the tour: two second-order rules and the Gauss
/// Galerkin methods of order 4 and 6.
pub fn quadratures() -> Vec<Quadrature> {
    vec![
        Quadrature::midpoint(),
        Quadrature::trapezoid(),
        Quadrature::galerkin(2).expect("degree 2 is valid"),
        Quadrature::galerkin(3).expect("degree 3 is valid"),
    ]
}

/// Prints reports as an aligned table.
pub fn print_table(reports: &[Report]) {
    println!(
        "{:<16} {:<32} {:>7} {:>8} {:>12} {:>10}  check",
        "scene", "quadrature", "h", "steps", "max |ΔE|", "wall"
    );
    for r in reports {
        println!(
            "{:<16} {:<32} {:>7} {:>8} {:>12} {:>10.2?}  {}",
            r.scene,
            r.quadrature,
            r.h,
            r.steps,
            r.max_energy_error
                .map_or_else(|| "—".to_string(), |e| format!("{e:.3e}")),
            r.wall,
            r.check
        );
    }
}

/// Writes reports as CSV.
pub fn save_table(reports: &[Report], path: &str) -> Result<(), csv::Error> {
    if let Some(dir) = std::path::Path::new(path).parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut table = csv::Writer::from_path(path)?;
    table.write_record([
        "scene",
        "quadrature",
        "h",
        "steps",
        "max_energy_error",
        "wall_seconds",
        "check",
    ])?;
    for r in reports {
        table.write_record([
            r.scene.to_string(),
            r.quadrature.clone(),
            r.h.to_string(),
            r.steps.to_string(),
            r.max_energy_error
                .map_or(String::new(), |e| format!("{e:e}")),
            r.wall.as_secs_f64().to_string(),
            r.check.clone(),
        ])?;
    }
    table.flush()?;
    Ok(())
}
