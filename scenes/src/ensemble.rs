//! An ensemble of double pendulums: for each initial angle pair, the time a perturbation of 1e-9
//! in θ1 takes to grow to 1e-3 (a divergence time, about ln(10⁶) Lyapunov times). Each member is
//! independent, so members run in parallel with rayon: a `Stepper` is `Clone + Send`, built once
//! and cloned per member.

use dirac::prelude::*;
use rayon::prelude::*;

use super::double_pendulum::{DoublePendulum, SCENE};

/// The initial angles of an `n × n` grid over `[0.5, 2.5]²`, at rest.
pub fn grid(n: usize) -> Vec<SVector<f64, 2>> {
    let angle = |i: usize| 0.5 + 2.0 * i as f64 / (n - 1).max(1) as f64;
    (0..n * n)
        .map(|k| vector![angle(k / n), angle(k % n)])
        .collect()
}

/// The divergence time from `angles` (at rest), or `horizon` if the perturbation stays below
/// 1e-3 until then.
pub fn divergence_time(
    template: &Stepper<DoublePendulum, 2>,
    angles: SVector<f64, 2>,
    horizon: f64,
) -> Result<f64, DiracError> {
    let mut reference = template.clone();
    let mut perturbed = template.clone();
    reference.start_from_velocity(angles, SVector::zeros())?;
    perturbed.start_from_velocity(angles + vector![1e-9, 0.0], SVector::zeros())?;
    while reference.t() < horizon {
        reference.step()?;
        perturbed.step()?;
        if (reference.q() - perturbed.q()).amax() > 1e-3 {
            return Ok(reference.t());
        }
    }
    Ok(horizon)
}

/// The divergence times of every member, in parallel (on rayon's current pool).
pub fn divergence_times(
    quadrature: Quadrature,
    h: f64,
    members: &[SVector<f64, 2>],
    horizon: f64,
) -> Result<Vec<f64>, DiracError> {
    let template = Stepper::new(SCENE, quadrature, h)?;
    members
        .par_iter()
        .map(|&angles| divergence_time(&template, angles, horizon))
        .collect()
}
