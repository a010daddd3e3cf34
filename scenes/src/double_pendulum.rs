//! Double pendulum l = (2, 3), m = (1, 2), g = 9.80665, θ0 = (π/4, π/2), θ̇0 = (0, π/8).

use std::f64::consts::PI;

use dirac::prelude::*;

use super::{Report, timed};

/// Two point masses on massless rods, angles from the downward vertical.
#[dirac_system(
    coordinates(theta1, theta2),
    lagrangian = 0.5 * (m1 + m2) * l1 * l1 * dot(theta1).powi(2)
        + 0.5 * m2 * l2 * l2 * dot(theta2).powi(2)
        + m2 * l1 * l2 * dot(theta1) * dot(theta2) * cos(theta1 - theta2)
        + (m1 + m2) * g * l1 * cos(theta1)
        + m2 * g * l2 * cos(theta2),
)]
#[derive(Debug, Clone, Copy)]
pub struct DoublePendulum {
    pub m1: f64,
    pub m2: f64,
    pub l1: f64,
    pub l2: f64,
    pub g: f64,
}

pub const SCENE: DoublePendulum = DoublePendulum {
    m1: 1.0,
    m2: 2.0,
    l1: 2.0,
    l2: 3.0,
    g: 9.80665,
};

pub fn q0() -> SVector<f64, 2> {
    vector![PI / 4.0, PI / 2.0]
}

pub fn v0() -> SVector<f64, 2> {
    vector![0.0, PI / 8.0]
}

/// A started stepper for the scene.
pub fn stepper(quadrature: Quadrature, h: f64) -> Result<Stepper<DoublePendulum, 2>, DiracError> {
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    stepper.start_from_velocity(q0(), v0())?;
    Ok(stepper)
}

/// (q, p) after time `t` with step `h`.
pub fn state_at(quadrature: Quadrature, h: f64, t: f64) -> Result<SVector<f64, 4>, DiracError> {
    let mut stepper = stepper(quadrature, h)?;
    for _ in 0..(t / h).round() as usize {
        stepper.step()?;
    }
    let (q, p) = (stepper.q(), stepper.p());
    Ok(vector![q[0], q[1], p[0], p[1]])
}

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 10.0);
    let name = quadrature.name();
    let mut stepper = stepper(quadrature, h)?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    trajectory.save_csv(format!(
        "output/double_pendulum_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    let newton = stepper.last_report().map_or(0, |r| r.iterations);
    Ok(Report {
        scene: "double pendulum",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("T = 10; Newton iterations on the last step: {newton}"),
    })
}
