//! A knife edge (skate) on an inclined plane: the nonholonomic constraint sin φ dx − cos φ dy = 0
//! keeps its velocity along its blade.

use dirac::prelude::*;

use super::{Report, timed};

/// Position (x, y) on the plane (x down the slope), blade angle φ.
#[dirac_system(
    coordinates(x, y, phi),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) + 0.5 * j * dot(phi).powi(2)
        + m * g * sin(alpha) * x,
    constraints(sin(phi) * dx - cos(phi) * dy),
)]
#[derive(Debug, Clone, Copy)]
pub struct KnifeEdge {
    pub m: f64,
    pub j: f64,
    pub g: f64,
    pub alpha: f64,
}

pub const SCENE: KnifeEdge = KnifeEdge {
    m: 1.0,
    j: 1.0,
    g: 9.81,
    alpha: std::f64::consts::FRAC_PI_6,
};
/// Spin rate.
pub const OMEGA: f64 = 1.0;
/// q(10) of the closed form.
pub const Q10: [f64; 3] = [0.72583937, 23.40550089, 10.0];

/// The closed form from rest with φ̇ = Ω: φ = Ωt, x = (g sin α / 2Ω²) sin² Ωt,
/// y = (g sin α / 2Ω²)(Ωt − ½ sin 2Ωt).
pub fn exact(t: f64) -> SVector<f64, 3> {
    let k = SCENE.g * SCENE.alpha.sin() / (2.0 * OMEGA * OMEGA);
    let wt = OMEGA * t;
    vector![k * wt.sin().powi(2), k * (wt - 0.5 * (2.0 * wt).sin()), wt]
}

/// A started stepper with the constraint evaluated at `point`.
pub fn stepper(point: ConstraintPoint, h: f64) -> Result<Stepper<KnifeEdge, 3>, DiracError> {
    let mut stepper = Stepper::new(SCENE, Quadrature::midpoint(), h)?.with_constraint_point(point);
    stepper.start_from_velocity(SVector::zeros(), vector![0.0, 0.0, OMEGA])?;
    Ok(stepper)
}

/// Position error at T = `t` with step `h`.
pub fn error_at(point: ConstraintPoint, h: f64, t: f64) -> Result<f64, DiracError> {
    let mut stepper = stepper(point, h)?;
    for _ in 0..(t / h).round() as usize {
        stepper.step()?;
    }
    Ok((stepper.q() - exact(t)).amax())
}

pub fn report_point(point: ConstraintPoint) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 10.0);
    let mut stepper = stepper(point, h)?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    let name = format!("midpoint, constraint at {point:?}");
    trajectory.save_csv(format!("output/knife_edge_{point:?}.csv").to_lowercase())?;
    let drift = trajectory.energy().last().unwrap_or(&0.0) - trajectory.energy()[0];
    Ok(Report {
        scene: "knife edge",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!(
            "|q(10) − exact| = {:.2e}, E(10) − E(0) = {drift:+.2e}",
            (stepper.q() - SVector::from(Q10)).amax()
        ),
    })
}
