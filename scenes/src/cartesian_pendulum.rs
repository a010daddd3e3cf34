//! The pendulum in Cartesian coordinates with the holonomic length constraint x² + y² = l².

use dirac::prelude::*;

use super::{Report, timed};

/// A point mass at (x, y), y upwards, on a rod of length l.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) - m * g * y,
    holonomic(x * x + y * y - l * l),
)]
#[derive(Debug, Clone, Copy)]
pub struct CartesianPendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

/// The unit pendulum (q̈ = −sin q for the angle from the downward vertical).
pub const SCENE: CartesianPendulum = CartesianPendulum {
    m: 1.0,
    l: 1.0,
    g: 1.0,
};

/// Released from rest at angle `theta0`.
pub fn q0(theta0: f64) -> SVector<f64, 2> {
    vector![theta0.sin(), -theta0.cos()]
}

/// The angle from the downward vertical.
pub fn angle(q: &SVector<f64, 2>) -> f64 {
    q[0].atan2(-q[1])
}

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.05, 100.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    stepper.start_from_velocity(q0(1.0), SVector::zeros())?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    trajectory.save_csv(format!(
        "output/cartesian_pendulum_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    let theta5 = angle(&trajectory.q()[100]);
    Ok(Report {
        scene: "pendulum (x, y)",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!(
            "|θ(5) − exact| = {:.2e}, |g(q)| ≤ {:.1e}",
            (theta5 - super::pendulum::Q5).abs(),
            trajectory.max_constraint_violation()
        ),
    })
}
