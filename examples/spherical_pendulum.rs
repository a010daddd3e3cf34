//! The spherical pendulum on the unit sphere `S²` beside the same pendulum in Cartesian
//! coordinates with a holonomic constraint, both against a Dop853 reference, and the vertical
//! angular momentum on the sphere over 10⁵ steps with each retraction, with and without gravity,
//! and with the solver's tolerances at 1e-15:
//! `cargo run --release --example spherical_pendulum`.

use dirac::prelude::*;
use scenes::spherical_pendulum::{SCENE, SphericalPendulum, start, vertical_momentum};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    scenes::print_table(&scenes::spherical_pendulum::reports()?);
    let steps = 100_000;
    let tight = NewtonOptions {
        residual_tolerance: 1e-15,
        step_tolerance: 1e-15,
        ..NewtonOptions::default()
    };
    let runs = [
        (
            "gravity",
            SCENE.g,
            Product::cayley(),
            NewtonOptions::default(),
        ),
        ("gravity", SCENE.g, Product::exp(), NewtonOptions::default()),
        (
            "gravity, tolerances 1e-15",
            SCENE.g,
            Product::cayley(),
            tight,
        ),
        ("free", 0.0, Product::cayley(), NewtonOptions::default()),
        ("free", 0.0, Product::exp(), NewtonOptions::default()),
    ];
    for (what, g, space, options) in runs {
        let model = SphericalPendulum { g, ..SCENE };
        let mut stepper = Stepper::on_manifold(model, space, Quadrature::midpoint(), 0.01)?
            .with_newton_options(options)?;
        let (n0, v0) = start();
        stepper.start_from_velocity(Configuration::of_direction(n0), Rates::of_direction(v0))?;
        let lz = |s: &ManifoldStepper<_, 2, Product<0, 0, 1>>| {
            vertical_momentum(&s.q().direction[0], &s.p().direction[0])
        };
        let l0 = lz(&stepper);
        stepper.run(steps)?;
        let drift = lz(&stepper) - l0;
        println!(
            "{:?}, {what}: L_z = {l0:.4} moved by {drift:.1e} in {steps} steps ({:.1e} per step)",
            space.retraction(),
            drift / steps as f64
        );
    }
    Ok(())
}
