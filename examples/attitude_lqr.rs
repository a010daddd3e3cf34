//! Attitude control by LQR on the step map's derivatives on `R³ × SO(3)`: a satellite with three
//! reaction wheels, tilted 0.78 rad from its target at rest, is brought back by the feedback
//! `u = −K z` computed inside the run, `K` the discrete LQR gain of the exact `A`, `B` at the
//! target. The wheels' torques are internal: the spatial angular momentum stays zero while the
//! body turns. `cargo run --release --example attitude_lqr`.

use dirac::prelude::*;
use scenes::reaction_wheels;

fn main() -> Result<(), DiracError> {
    let h = 0.05;
    let regulator = reaction_wheels::regulator(h, 0.01)?;
    let radius = |m: &dirac::nalgebra::DMatrix<f64>| {
        m.complex_eigenvalues()
            .iter()
            .map(|e| e.norm())
            .fold(0.0, f64::max)
    };
    let regulated = |m: &dirac::nalgebra::DMatrix<f64>| {
        let r = &reaction_wheels::REGULATED;
        dirac::nalgebra::DMatrix::from_fn(r.len(), r.len(), |i, j| m[(r[i], r[j])])
    };
    let closed = &regulator.a - &regulator.b * &regulator.k;
    println!(
        "on the attitude and the wheels' momenta: spectral radius of A {:.4}, of A − BK {:.4} \
         (h = {h})",
        radius(&regulated(&regulator.a)),
        radius(&regulated(&closed))
    );
    let tilt = reaction_wheels::tilt();
    let samples = reaction_wheels::stabilised(&regulator.k, tilt, h, 30.0, 40)?;
    println!("\nfrom rest at {:.2} rad from the target:", tilt.norm());
    for s in &samples {
        println!(
            "t = {:4.0} s   angle = {:.2e} rad   |Ω| = {:.2e} rad/s   wheels' rates = \
             [{:7.3}, {:7.3}, {:7.3}]   |spatial angular momentum| = {:.1e}",
            s.t, s.angle, s.rate, s.wheels[0], s.wheels[1], s.wheels[2], s.momentum
        );
    }
    Ok(())
}
