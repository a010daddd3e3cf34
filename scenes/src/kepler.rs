//! Kepler problem with e = 0.5: q0 = (0.5, 0), p0 = (0, √3); angular momentum is conserved by
//! the discrete Noether theorem.

use dirac::prelude::*;

use super::{Report, timed};

/// A unit mass in the potential −μ/|q|.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)) + mu / sqrt(x * x + y * y),
)]
#[derive(Debug, Clone, Copy)]
pub struct Kepler {
    pub mu: f64,
}

pub const SCENE: Kepler = Kepler { mu: 1.0 };

pub fn q0() -> SVector<f64, 2> {
    vector![0.5, 0.0]
}

pub fn p0() -> SVector<f64, 2> {
    vector![0.0, 3f64.sqrt()]
}

/// Angular momentum x p_y − y p_x.
pub fn angular_momentum(q: &SVector<f64, 2>, p: &SVector<f64, 2>) -> f64 {
    q[0] * p[1] - q[1] * p[0]
}

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 100.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    stepper.start_from_momentum(q0(), p0())?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 10)?;
    trajectory.save_csv(format!(
        "output/kepler_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    let l0 = angular_momentum(&q0(), &p0());
    let drift = trajectory
        .q()
        .iter()
        .zip(trajectory.p())
        .map(|(q, p)| ((angular_momentum(q, p) - l0) / l0).abs())
        .fold(0.0, f64::max);
    Ok(Report {
        scene: "kepler",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("max relative angular momentum error = {drift:.2e}"),
    })
}
