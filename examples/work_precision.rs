//! The speed/accuracy trade of the double pendulum (the README's model, from its initial state),
//! measured with `Study`: midpoint, `galerkin(2)` and `galerkin(3)` at five steps, to T = 10 and
//! T = 100, against a converged reference. Writes a CSV and a work–precision PNG per horizon and
//! prints the cheapest run for a few targets. The double pendulum is chaotic: by T = 100 the
//! converged reference no longer resolves the trajectory (its two runs differ by 1e-2), so error
//! targets are refused there and only the energy error chooses.
//!
//! `cargo run --release --example work_precision`

mod scenes;

use dirac::prelude::*;
use dirac::work_precision::{Measurement, Study};
use scenes::double_pendulum;

fn main() -> Result<(), DiracError> {
    for horizon in [10.0, 100.0] {
        let study = Study::new(double_pendulum::SCENE, horizon, |s| {
            s.start_from_velocity(double_pendulum::q0(), double_pendulum::v0())
        })
        .steps([0.04, 0.02, 0.01, 0.005, 0.0025])
        .run()?;
        let name = format!("output/work_precision_T{horizon}");
        study.save_csv(format!("{name}.csv"))?;
        study.save_png(
            format!("{name}.png"),
            &format!("Double pendulum to T = {horizon}: error against cost"),
        )?;
        println!(
            "T = {horizon}: reference {} (estimated error {:.1e})",
            study.reference_method, study.reference_error
        );
        println!(
            "  {:<12} {:>7} {:>10} {:>10} {:>8} {:>12}",
            "quadrature", "h", "error", "|ΔE|", "Newton", "µs per unit t"
        );
        for m in &study.measurements {
            println!(
                "  {:<12} {:>7} {:>10.2e} {:>10.2e} {:>8.2} {:>12.1}",
                m.quadrature,
                m.h,
                m.error,
                m.energy_error,
                m.newton_iterations,
                m.seconds_per_unit_time * 1e6
            );
        }
        for failure in &study.failures {
            println!(
                "  {} at h = {}: {}",
                failure.quadrature, failure.h, failure.error
            );
        }
        for target in [1e-3, 1e-6, 1e-9] {
            print_choice("error", target, study.cheapest(target));
        }
        for target in [1e-4, 1e-8] {
            print_choice("energy error", target, study.cheapest_in_energy(target));
        }
        println!("  wrote {name}.csv and {name}.png");
    }
    Ok(())
}

/// Prints the cheapest run meeting `target` in `what`, or why there is none.
fn print_choice(what: &str, target: f64, choice: Result<&Measurement, DiracError>) {
    match choice {
        Ok(m) => println!(
            "  {what} ≤ {target:e}: {} at h = {} ({:.1} µs per unit t)",
            m.quadrature,
            m.h,
            m.seconds_per_unit_time * 1e6
        ),
        Err(why) => println!("  {what} ≤ {target:e}: {why}"),
    }
}
