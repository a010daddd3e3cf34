//! Models written with a Hamiltonian, stepped on the discrete Hamiltonian route (`H_d⁺`), each
//! beside its Lagrangian counterpart where it has one.

use dirac::prelude::*;

use super::{Report, timed};

/// `H = ½(q² + 1)(p² + 1)`: not separable. Its Lagrangian counterpart is [`CoupledLagrangian`].
#[dirac_system(
    coordinates(q),
    hamiltonian = 0.5 * (q * q + 1.0) * (p(q) * p(q) + 1.0),
)]
#[derive(Debug, Clone, Copy)]
pub struct Coupled;

/// The Legendre transform of [`Coupled`]: `v = (q² + 1) p`, `L = v²/(2(q² + 1)) − (q² + 1)/2`.
#[dirac_system(
    coordinates(q),
    lagrangian = 0.5 * dot(q) * dot(q) / (q * q + 1.0) - 0.5 * (q * q + 1.0),
)]
#[derive(Debug, Clone, Copy)]
pub struct CoupledLagrangian;

/// The pendulum, `H = p²/(2 m l²) − m g l cos θ`.
#[dirac_system(
    coordinates(theta),
    hamiltonian = p(theta).powi(2) / (2.0 * m * l * l) - m * g * l * cos(theta),
)]
#[derive(Debug, Clone, Copy)]
pub struct Pendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

pub const PENDULUM: Pendulum = Pendulum {
    m: 1.0,
    l: 1.0,
    g: 9.81,
};

/// Kepler's problem, `H = |p|²/2 − μ/|q|`.
#[dirac_system(
    coordinates(x, y),
    hamiltonian = 0.5 * (p(x).powi(2) + p(y).powi(2)) - mu / sqrt(x * x + y * y),
)]
#[derive(Debug, Clone, Copy)]
pub struct Kepler {
    pub mu: f64,
}

/// The knife edge on an inclined plane written with its Hamiltonian and the one-form
/// `sin φ dx − cos φ dy` (the Lagrangian scene is `knife_edge::KnifeEdge`).
#[dirac_system(
    coordinates(x, y, phi),
    hamiltonian = (p(x).powi(2) + p(y).powi(2)) / (2.0 * m) + p(phi).powi(2) / (2.0 * j)
        - m * g * sin(alpha) * x,
    constraints(sin(phi) * dx - cos(phi) * dy),
)]
#[derive(Debug, Clone, Copy)]
pub struct KnifeEdge {
    pub m: f64,
    pub j: f64,
    pub g: f64,
    pub alpha: f64,
}

/// A damped, driven oscillator: `H = (p² + q²)/2`, the force `(u − c p) dq`.
#[dirac_system(
    coordinates(q),
    hamiltonian = 0.5 * (p(q) * p(q) + q * q),
    forces((u - c * p(q)) * dq),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
pub struct Damped {
    pub c: f64,
}

/// `H = p f(q)` with `f(q) = 1 − q²`: the cotangent lift of `q̇ = 1 − q²` (`q = tanh t` from 0),
/// with `ṗ = 2 q p` its adjoint. `∂²H/∂p² = 0`: there is no Lagrangian counterpart.
#[dirac_system(
    coordinates(q),
    hamiltonian = p(q) * (1.0 - q * q),
)]
#[derive(Debug, Clone, Copy)]
pub struct Lifted;

/// The exact flow of [`Lifted`] from `(0, p0)`: `q = tanh t`, `p = p0 cosh² t` (so that
/// `H = p (1 − q²) = p0` is conserved).
pub fn lifted_exact(t: f64, p0: f64) -> (f64, f64) {
    (t.tanh(), p0 * t.cosh().powi(2))
}

/// The tour's row: the non-separable [`Coupled`] on both routes over 10⁴ steps, with the largest
/// difference between them and the energy error.
pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 100.0);
    let name = quadrature.name();
    let mut stepper = Stepper::hamiltonian(Coupled, quadrature.clone(), h)?;
    stepper.start_from_momentum(vector![0.5], vector![0.0])?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    let mut lagrangian = Stepper::new(CoupledLagrangian, quadrature, h)?;
    lagrangian.start_from_momentum(vector![0.5], vector![0.0])?;
    let reference = lagrangian.run(stepper.steps())?;
    let difference = trajectory
        .q()
        .iter()
        .zip(reference.q())
        .map(|(a, b)| (a - b).amax())
        .fold(0.0, f64::max);
    Ok(Report {
        scene: "hamiltonian",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("H = (q²+1)(p²+1)/2: max |q_H − q_L| = {difference:.1e} (Lagrangian route)"),
    })
}
