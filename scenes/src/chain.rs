//! An n-link pendulum chain written with a coordinate array and a generic Lagrangian function.

use dirac::prelude::*;

use super::{Report, timed};

/// `L` equal links of length `l` with point masses `m`, angles from the downward vertical.
#[dirac_system(coordinates(theta[L]), lagrangian = chain_lagrangian)]
#[derive(Debug, Clone, Copy)]
pub struct Chain<const L: usize> {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

/// `Σ_i m (ẋ_i² + ẏ_i²)/2 − m g y_i` with `x_i = l Σ_{k≤i} sin θ_k`, `y_i = −l Σ_{k≤i} cos θ_k`.
pub fn chain_lagrangian<D: Scalar, const L: usize>(
    chain: &Chain<L>,
    theta: &SVector<D, L>,
    omega: &SVector<D, L>,
) -> D {
    let zero = D::from(0.0);
    let (mut vx, mut vy, mut y, mut lagrangian) = (zero, zero, zero, zero);
    for k in 0..L {
        let (sin, cos) = theta[k].sin_cos();
        vx += cos * omega[k] * chain.l;
        vy += sin * omega[k] * chain.l;
        y -= cos * chain.l;
        lagrangian += (vx * vx + vy * vy) * (0.5 * chain.m) - y * (chain.m * chain.g);
    }
    lagrangian
}

/// A chain released from rest with its links bent alternately by ±0.3 rad about 0.5 rad.
pub fn initial<const L: usize>() -> SVector<f64, L> {
    SVector::from_fn(|i, _| 0.5 + if i % 2 == 0 { 0.3 } else { -0.3 })
}

pub const SCENE8: Chain<8> = Chain {
    m: 1.0,
    l: 1.0,
    g: 9.81,
};

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.005, 10.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(SCENE8, quadrature, h)?;
    stepper.start_from_velocity(initial(), SVector::zeros())?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 10)?;
    trajectory.save_csv(format!(
        "output/chain8_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    Ok(Report {
        scene: "chain (8 links)",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("T = {t_end}"),
    })
}
