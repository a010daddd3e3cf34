//! The discrete Hamiltonian route: `cargo run --release --example hamiltonian`.
//!
//! Models written with `hamiltonian = ...` (momenta `p(x)`) and stepped by the Galerkin discrete
//! Hamiltonian `H_d⁺`: the non-separable `H = ½(q² + 1)(p² + 1)` on both routes (the same
//! steps), Kepler's angular momentum, the knife edge written with `H` against its closed form,
//! and `H = p(1 − q²)`, which has no Lagrangian, against its exact flow.

use dirac::prelude::*;
use scenes::hamiltonian::{Kepler, KnifeEdge, Lifted, lifted_exact};

fn main() -> Result<(), DiracError> {
    let reports = scenes::quadratures()
        .into_iter()
        .map(scenes::hamiltonian::report)
        .collect::<Result<Vec<_>, _>>()?;
    scenes::print_table(&reports);

    let (q0, p0) = (vector![0.5, 0.0], vector![0.0, 3f64.sqrt()]);
    let mut kepler = Stepper::hamiltonian(Kepler { mu: 1.0 }, Quadrature::galerkin(2)?, 0.01)?;
    kepler.start_from_momentum(q0, p0)?;
    let trajectory = kepler.run(100_000)?;
    let l = |q: &SVector<f64, 2>, p: &SVector<f64, 2>| q[0] * p[1] - q[1] * p[0];
    let drift = trajectory
        .q()
        .iter()
        .zip(trajectory.p())
        .map(|(q, p)| (l(q, p) - l(&q0, &p0)).abs())
        .fold(0.0, f64::max);
    println!(
        "\nKepler (e = 0.5), galerkin(2), h = 0.01, 10⁵ steps: max |ΔL| = {drift:.1e}, \
         max |ΔH| = {:.1e}",
        trajectory.max_energy_error()
    );

    let knife = KnifeEdge {
        m: 1.0,
        j: 1.0,
        g: 9.81,
        alpha: std::f64::consts::FRAC_PI_6,
    };
    let mut skate = Stepper::hamiltonian(knife, Quadrature::midpoint(), 0.01)?;
    skate.start_from_momentum(
        SVector::zeros(),
        vector![0.0, 0.0, scenes::knife_edge::OMEGA],
    )?;
    let trajectory = skate.run(1000)?;
    println!(
        "knife edge written with H, midpoint, h = 0.01: |q(10) − q_exact| = {:.1e}, max \
         violation {:.1e}",
        (skate.q() - scenes::knife_edge::exact(10.0)).amax(),
        trajectory.max_constraint_violation()
    );

    let mut lifted = Stepper::hamiltonian(Lifted, Quadrature::galerkin(2)?, 0.1)?;
    lifted.start_from_momentum(vector![0.0], vector![1.0])?;
    lifted.run(10)?;
    let (q, p) = lifted_exact(1.0, 1.0);
    println!(
        "H = p(1 − q²) (no Lagrangian), galerkin(2), h = 0.1: |q(1) − tanh 1| = {:.1e}, \
         |p(1) − cosh² 1| = {:.1e}",
        (lifted.q()[0] - q).abs(),
        (lifted.state().expect("started").p()[0] - p).abs()
    );
    Ok(())
}
