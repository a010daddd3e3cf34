//! Harmonic oscillator m = 1, k = 0.5, q0 = 0.5, p0 = 0: q(t) = q0 cos(ωt), ω = √(k/m).

use dirac::prelude::*;

use super::{Report, timed};

/// L = m v²/2 − k x²/2.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * m * dot(x).powi(2) - 0.5 * k * x.powi(2),
    quadrature = midpoint,
)]
#[derive(Debug, Clone, Copy)]
pub struct Oscillator {
    pub m: f64,
    pub k: f64,
}

pub const SCENE: Oscillator = Oscillator { m: 1.0, k: 0.5 };
pub const Q0: f64 = 0.5;

/// The exact position at time `t`.
pub fn exact(t: f64) -> f64 {
    Q0 * ((SCENE.k / SCENE.m).sqrt() * t).cos()
}

/// Largest position error over T = 1 with step `h`.
pub fn max_error(quadrature: Quadrature, h: f64) -> Result<f64, DiracError> {
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    stepper.start_from_momentum(vector![Q0], vector![0.0])?;
    let trajectory = stepper.run_until(1.0)?;
    Ok(trajectory
        .t()
        .iter()
        .zip(trajectory.q())
        .map(|(t, q)| (q[0] - exact(*t)).abs())
        .fold(0.0, f64::max))
}

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.1, 1.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(SCENE, quadrature.clone(), h)?;
    stepper.start_from_momentum(vector![Q0], vector![0.0])?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    trajectory.save_csv(format!("output/oscillator_{}.csv", file_name(&name)))?;
    Ok(Report {
        scene: "oscillator",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!(
            "max |q − q_exact| on [0, 1] = {:.2e}",
            max_error(quadrature, h)?
        ),
    })
}

/// A quadrature's name as a file name.
pub fn file_name(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect::<String>()
        .trim_end_matches('_')
        .to_string()
}
