//! Pendulum q̈ = −sin q from q0 = 1, p0 = 0; q(5) and p(5) known to 14 digits.

use dirac::prelude::*;

use super::{Report, timed};

/// L = m l² θ̇²/2 + m g l cos θ.
#[dirac_system(
    coordinates(theta),
    lagrangian = 0.5 * m * l * l * dot(theta).powi(2) + m * g * l * cos(theta),
)]
#[derive(Debug, Clone, Copy)]
pub struct Pendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

/// Unit pendulum: q̈ = −sin q.
pub const SCENE: Pendulum = Pendulum {
    m: 1.0,
    l: 1.0,
    g: 1.0,
};
pub const Q5: f64 = -0.02395128485293;
pub const P5: f64 = 0.95855190346756;

/// Error |(q, p)(5) − exact| with step `h` (which must divide 5).
pub fn error_at_5(quadrature: Quadrature, h: f64) -> Result<f64, DiracError> {
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    stepper.start_from_momentum(vector![1.0], vector![0.0])?;
    for _ in 0..(5.0 / h).round() as usize {
        stepper.step()?;
    }
    Ok((stepper.q()[0] - Q5).abs().max((stepper.p()[0] - P5).abs()))
}

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.05, 1000.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(SCENE, quadrature.clone(), h)?;
    stepper.start_from_momentum(vector![1.0], vector![0.0])?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 10)?;
    trajectory.save_csv(format!(
        "output/pendulum_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    Ok(Report {
        scene: "pendulum",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("|(q,p)(5) − exact| = {:.2e}", error_at_5(quadrature, h)?),
    })
}
