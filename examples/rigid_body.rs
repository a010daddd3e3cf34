//! Rigid bodies on `SO(3)`: the heavy top with both retractions (vertical momentum and `RᵀR − I`
//! checked), the 3D pendulum against a quaternion Dop853 reference with two quadratures, and the
//! free body's spatial momentum over 10⁶ steps with Newton's method and with the Jacobian kept
//! across iterations and steps (simplified Newton):
//! `cargo run --release --example rigid_body`.

use dirac::prelude::*;
use scenes::rigid_body;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut reports = Vec::new();
    for space in [Product::cayley(), Product::exp()] {
        reports.push(rigid_body::report(space)?);
    }
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2)?] {
        reports.push(rigid_body::pendulum_report(quadrature)?);
    }
    scenes::print_table(&reports);
    let steps = 1_000_000;
    for (what, reuse) in [("Newton's method", None), ("Jacobian kept", Some(0.25))] {
        let options = NewtonOptions {
            jacobian_reuse: reuse,
            ..NewtonOptions::default()
        };
        let mut stepper = rigid_body::started(
            rigid_body::ASYMMETRIC,
            Product::cayley(),
            Quadrature::midpoint(),
            0.01,
            rigid_body::free_start(),
        )?
        .with_newton_options(options)?;
        let pi0 = stepper.q().spatial(&stepper.p(), 0);
        let (mut residuals, mut jacobians, mut drift) = (0, 0, 0.0_f64);
        for _ in 0..steps {
            stepper.step()?;
            let report = stepper.last_report().expect("a step was taken");
            residuals += report.iterations;
            jacobians += report.jacobians;
            drift = drift.max((stepper.q().spatial(&stepper.p(), 0) - pi0).amax());
        }
        println!(
            "free body, 10⁶ steps, {what}: |ΔRΠ| ≤ {drift:.1e} (|RΠ| = {:.2}), {:.2} residuals \
             and {:.3} Jacobians per step",
            pi0.norm(),
            residuals as f64 / steps as f64,
            jacobians as f64 / steps as f64
        );
    }
    Ok(())
}
