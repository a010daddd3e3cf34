//! The spherical pendulum on the unit sphere `S²` beside the same pendulum in Cartesian
//! coordinates with a holonomic constraint, both against a Dop853 reference, and the vertical
//! angular momentum on the sphere over 10⁵ steps with each retraction, with and without gravity
//! (kept to round-off: each unit vector's angular momentum advances by the step's torque):
//! `cargo run --release --example spherical_pendulum`.

use dirac::prelude::*;
use scenes::spherical_pendulum::{SCENE, SphericalPendulum, start, vertical_momentum};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    scenes::print_table(&scenes::spherical_pendulum::reports()?);
    let steps = 100_000;
    let runs = [
        ("gravity", SCENE.g, Product::cayley()),
        ("gravity", SCENE.g, Product::exp()),
        ("free", 0.0, Product::cayley()),
        ("free", 0.0, Product::exp()),
    ];
    for (what, g, space) in runs {
        let model = SphericalPendulum { g, ..SCENE };
        let mut stepper = Stepper::on_manifold(model, space, Quadrature::midpoint(), 0.01)?;
        let (n0, v0) = start();
        stepper.start_from_velocity(Configuration::of_direction(n0), Rates::of_direction(v0))?;
        let lz = |q: &Configuration<f64, 0, 0, 1>, p: &Rates<f64, 0, 0, 1>| {
            vertical_momentum(&q.direction[0], &p.direction[0])
        };
        let l0 = lz(&stepper.q(), &stepper.p());
        let trajectory = stepper.run(steps)?;
        let drift = trajectory
            .q()
            .iter()
            .zip(trajectory.p())
            .map(|(q, p)| (lz(q, p) - l0).abs())
            .fold(0.0, f64::max);
        println!(
            "{:?}, {what}: L_z = {l0:.4}, |ΔL_z| ≤ {drift:.1e} over {steps} steps",
            space.retraction(),
        );
    }
    Ok(())
}
