//! A vertical disk rolling without slipping: q = (x, y, θ, φ), rolling angle θ, heading φ,
//! one-forms dx − r cos φ dθ and dy − r sin φ dθ. θ̇ = Ω and φ̇ = ω stay constant and the contact
//! point runs on a circle: x = x0 + (rΩ/ω)(sin(ωt + φ0) − sin φ0),
//! y = y0 − (rΩ/ω)(cos(ωt + φ0) − cos φ0).

use dirac::prelude::*;

use super::{Report, timed};

#[dirac_system(
    coordinates(x, y, theta, phi),
    lagrangian = 0.5 * mass * (dot(x).powi(2) + dot(y).powi(2))
        + 0.5 * rolling * dot(theta).powi(2)
        + 0.5 * turning * dot(phi).powi(2),
    constraints(dx - radius * cos(phi) * dtheta, dy - radius * sin(phi) * dtheta),
)]
#[derive(Debug, Clone, Copy)]
pub struct RollingDisk {
    pub mass: f64,
    pub rolling: f64,
    pub turning: f64,
    pub radius: f64,
}

pub const SCENE: RollingDisk = RollingDisk {
    mass: 1.0,
    rolling: 0.5,
    turning: 0.25,
    radius: 1.0,
};
/// θ̇, φ̇ and φ at t = 0.
pub const SPIN: f64 = 1.0;
pub const TURN: f64 = 0.7;
pub const HEADING: f64 = 0.3;

pub fn exact(t: f64) -> SVector<f64, 4> {
    let (r, phi0) = (SCENE.radius, HEADING);
    let phi = phi0 + TURN * t;
    vector![
        r * SPIN / TURN * (phi.sin() - phi0.sin()),
        -r * SPIN / TURN * (phi.cos() - phi0.cos()),
        SPIN * t,
        phi
    ]
}

pub fn stepper(quadrature: Quadrature, h: f64) -> Result<Stepper<RollingDisk, 4>, DiracError> {
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    let v0 = vector![
        SCENE.radius * HEADING.cos() * SPIN,
        SCENE.radius * HEADING.sin() * SPIN,
        SPIN,
        TURN
    ];
    stepper.start_from_velocity(vector![0.0, 0.0, 0.0, HEADING], v0)?;
    Ok(stepper)
}

/// 200 steps of h = 0.05 (T = 10) against the closed form.
pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.05, 10.0);
    let name = quadrature.name();
    let mut stepper = stepper(quadrature, h)?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    Ok(Report {
        scene: "rolling disk",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!(
            "|q(10) − exact| = {:.2e}, one-forms at the nodes ≤ {:.1e}",
            (stepper.q() - exact(10.0)).amax(),
            trajectory.max_constraint_violation()
        ),
    })
}
