//! A homogeneous ball rolling without slipping on a horizontal plane: its centre `(x, y)` and its
//! attitude `R ∈ SO(3)`, with the two one-forms of rolling, `ẋ = r ω_y` and `ẏ = −r ω_x`
//! (`ω = R Ω` the spatial angular velocity). With no friction torque the ball rolls at a constant
//! velocity with a constant spatial angular velocity: `x(t) = x₀ + v t`,
//! `R(t) = exp(t ω̂) R₀`.

use dirac::prelude::*;

use super::{Report, timed};

/// A ball of mass `m`, radius `r` and moment of inertia `i` about any axis through its centre.
#[dirac_system(
    coordinates(x, y, R: SO3),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) + 0.5 * i * dot(omega(R), omega(R)),
    constraints(dx - r * (R * dR)[1], dy + r * (R * dR)[0]),
)]
#[derive(Debug, Clone, Copy)]
pub struct RollingBall {
    pub m: f64,
    pub i: f64,
    pub r: f64,
}

/// A solid ball of unit mass and radius (`i = 2/5`).
pub const SCENE: RollingBall = RollingBall {
    m: 1.0,
    i: 0.4,
    r: 1.0,
};

/// The spatial angular velocity: rolling along `x` at unit speed while spinning about the
/// vertical.
pub fn omega() -> Vector3<f64> {
    Vector3::new(0.0, 1.0 / SCENE.r, 0.7)
}

/// The initial attitude.
pub fn r0() -> Matrix3<f64> {
    Retraction::Exp.map(&Vector3::new(0.2, -0.3, 0.1))
}

/// The closed form at `t`: the centre and the attitude.
pub fn exact(t: f64) -> (SVector<f64, 2>, Matrix3<f64>) {
    let w = omega();
    let v = vector![SCENE.r * w[1], -SCENE.r * w[0]];
    (v * t, Retraction::Exp.map(&(w * t)) * r0())
}

/// A stepper rolling from the origin with the one-forms at `point`.
pub fn started(
    quadrature: Quadrature,
    h: f64,
    point: ConstraintPoint,
) -> Result<ManifoldStepper<RollingBall, 5, Product<2, 1, 0>>, DiracError> {
    let (r0, w) = (r0(), omega());
    let mut stepper =
        Stepper::on_manifold(SCENE, Product::cayley(), quadrature, h)?.with_constraint_point(point);
    let start = Configuration::new(vector![0.0, 0.0], [r0], []);
    let rates = Rates::new(
        vector![SCENE.r * w[1], -SCENE.r * w[0]],
        [r0.transpose() * w],
        [],
    );
    stepper.start_from_velocity(start, rates)?;
    Ok(stepper)
}

/// The tour's row: rolling for 10 s (midpoint, h = 0.01) with the one-forms at `point`.
pub fn report(point: ConstraintPoint) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 10.0);
    let mut stepper = started(Quadrature::midpoint(), h, point)?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    let (x, r) = exact(stepper.t());
    let q = stepper.q();
    let error = (q.vector - x).amax().max((q.rotation[0] - r).amax());
    Ok(Report {
        scene: "rolling ball",
        quadrature: format!("midpoint, one-forms at {point:?}"),
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!(
            "|q(10) − exact| = {error:.1e}, violation {:.1e}",
            trajectory.max_constraint_violation()
        ),
    })
}
