//! The spherical pendulum on the unit sphere `S²` beside the same pendulum in Cartesian
//! coordinates with a holonomic constraint, both against a Dop853 reference, and the vertical
//! angular momentum on the sphere over 10⁵ steps with each retraction:
//! `cargo run --release --example spherical_pendulum`.

mod scenes;

use dirac::prelude::*;
use scenes::spherical_pendulum::{on_sphere, vertical_momentum};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    scenes::print_table(&scenes::spherical_pendulum::reports()?);
    let steps = 100_000;
    for space in [Product::cayley(), Product::exp()] {
        let mut stepper = on_sphere(space, Quadrature::midpoint(), 0.01)?;
        let lz = |s: &ManifoldStepper<_, 2, Product<0, 0, 1>>| {
            vertical_momentum(&s.q().direction[0], &s.p().direction[0])
        };
        let l0 = lz(&stepper);
        stepper.run(steps)?;
        let drift = lz(&stepper) - l0;
        println!(
            "{:?}: L_z = {l0:.4} moved by {drift:.1e} in {steps} steps ({:.1e} per step)",
            space.retraction(),
            drift / steps as f64
        );
    }
    Ok(())
}
