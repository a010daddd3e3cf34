//! The spherical pendulum two ways: a unit vector `n ∈ S²` (the bob at `l n`), and three
//! Cartesian coordinates held on the sphere by the holonomic constraint `|x|² = l²`. Both keep the
//! vertical angular momentum `e₃ · (x × p)` (rotations about the vertical are a symmetry), and
//! `reference` integrates the motion as an ODE with Dop853.

use dirac::prelude::*;
use ode_solvers::System;

use super::{Report, timed};

/// A bob of mass `m` on a massless rod of length `l` from a fixed point, `n` the rod's direction,
/// gravity `g` along `−e₃`.
#[dirac_system(
    coordinates(n: S2),
    lagrangian = 0.5 * m * l * l * dot(dot(n), dot(n)) - m * g * l * n[2],
)]
#[derive(Debug, Clone, Copy)]
pub struct SphericalPendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

/// The same pendulum in Cartesian coordinates of the bob, on the sphere `|x| = l`.
#[dirac_system(
    coordinates(x, y, z),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2) + dot(z).powi(2)) - m * g * z,
    holonomic(x * x + y * y + z * z - l * l),
)]
#[derive(Debug, Clone, Copy)]
pub struct CartesianSphericalPendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

pub const SCENE: SphericalPendulum = SphericalPendulum {
    m: 1.0,
    l: 1.0,
    g: 9.81,
};

pub const CARTESIAN: CartesianSphericalPendulum = CartesianSphericalPendulum {
    m: 1.0,
    l: 1.0,
    g: 9.81,
};

/// Released at 0.6 rad from the downward vertical with a horizontal velocity across the plane of
/// release: the bob swings on a precessing, nearly elliptical path.
pub fn start() -> (Vector3<f64>, Vector3<f64>) {
    let theta: f64 = 0.6;
    (
        Vector3::new(theta.sin(), 0.0, -theta.cos()),
        Vector3::new(0.0, 1.5, 0.0),
    )
}

/// A stepper for the pendulum on `S²` from [`start`].
pub fn on_sphere(
    space: Product<0, 0, 1>,
    quadrature: Quadrature,
    h: f64,
) -> Result<ManifoldStepper<SphericalPendulum, 2, Product<0, 0, 1>>, DiracError> {
    let (n0, v0) = start();
    let mut stepper = Stepper::on_manifold(SCENE, space, quadrature, h)?;
    stepper.start_from_velocity(Configuration::of_direction(n0), Rates::of_direction(v0))?;
    Ok(stepper)
}

/// A stepper for the Cartesian pendulum from [`start`].
pub fn cartesian(
    quadrature: Quadrature,
    h: f64,
) -> Result<Stepper<CartesianSphericalPendulum, 3>, DiracError> {
    let (n0, v0) = start();
    let l = CARTESIAN.l;
    let mut stepper = Stepper::new(CARTESIAN, quadrature, h)?;
    stepper.start_from_velocity(n0 * l, v0 * l)?;
    Ok(stepper)
}

/// The vertical angular momentum of the bob at `x` with momentum `p`.
pub fn vertical_momentum(x: &Vector3<f64>, p: &Vector3<f64>) -> f64 {
    x.cross(p)[2]
}

/// `ẍ = −g e₃ − ((|ẋ|² − g x₃)/|x|²) x`: the constrained motion on the sphere as an ODE in
/// `(x, ẋ)`. With `|x|²` (not `l²`) in the denominator `d²|x|²/dt² = 0` everywhere, so a drift
/// off the sphere stays linear in the round-off instead of growing exponentially.
struct Ode {
    g: f64,
}

type Y = ode_solvers::SVector<f64, 6>;

impl System<f64, Y> for Ode {
    fn system(&self, _t: f64, y: &Y, dy: &mut Y) {
        let x = Vector3::new(y[0], y[1], y[2]);
        let v = Vector3::new(y[3], y[4], y[5]);
        let mu = (v.dot(&v) - self.g * x[2]) / x.dot(&x);
        let a = -Vector3::z() * self.g - x * mu;
        for k in 0..3 {
            dy[k] = v[k];
            dy[3 + k] = a[k];
        }
    }
}

/// The bob's position and velocity at `t_end` from [`start`] (scaled by `l`), by Dop853 at
/// relative and absolute tolerance `tolerance`.
pub fn reference(t_end: f64, tolerance: f64) -> Result<(Vector3<f64>, Vector3<f64>), String> {
    reference_from(start(), t_end, tolerance)
}

/// The bob's position and velocity at `t_end` from the direction and velocity `(n0, v0)`
/// (scaled by `l`), by Dop853 at relative and absolute tolerance `tolerance`.
pub fn reference_from(
    (n0, v0): (Vector3<f64>, Vector3<f64>),
    t_end: f64,
    tolerance: f64,
) -> Result<(Vector3<f64>, Vector3<f64>), String> {
    let l = SCENE.l;
    let y0 = Y::from([
        n0[0] * l,
        n0[1] * l,
        n0[2] * l,
        v0[0] * l,
        v0[1] * l,
        v0[2] * l,
    ]);
    let ode = Ode { g: SCENE.g };
    let end = super::peers::dop853_end(ode, y0, t_end, tolerance)?;
    Ok((
        Vector3::new(end[0], end[1], end[2]),
        Vector3::new(end[3], end[4], end[5]),
    ))
}

/// The tour's rows: the pendulum on `S²` (both retractions) and the Cartesian one (SHAKE), to
/// T = 10 with the midpoint rule at h = 0.01, against Dop853 at 1e-13.
pub fn reports() -> Result<Vec<Report>, Box<dyn std::error::Error>> {
    let (h, t_end) = (0.01, 10.0);
    let (x_ref, _) = reference(t_end, 1e-13)?;
    let l = SCENE.l;
    let mut reports = Vec::new();
    for space in [Product::cayley(), Product::exp()] {
        let mut stepper = on_sphere(space, Quadrature::midpoint(), h)?;
        let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
        let error = (stepper.q().direction[0] * l - x_ref).amax();
        let drift = trajectory
            .q()
            .iter()
            .zip(trajectory.p())
            .map(|(q, p)| vertical_momentum(&q.direction[0], &p.direction[0]))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), l| {
                (lo.min(l), hi.max(l))
            });
        reports.push(Report {
            scene: "spherical pend.",
            quadrature: format!("midpoint on S², {:?}", space.retraction()),
            h,
            steps: stepper.steps(),
            max_energy_error: Some(trajectory.max_energy_error()),
            wall,
            check: format!(
                "|x(10) − Dop853| = {error:.1e}, |ΔL_z| = {:.1e}",
                drift.1 - drift.0
            ),
        });
    }
    let mut stepper = cartesian(Quadrature::midpoint(), h)?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    let error = (stepper.q() - x_ref).amax();
    reports.push(Report {
        scene: "spherical pend.",
        quadrature: "midpoint, Cartesian + SHAKE".into(),
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("|x(10) − Dop853| = {error:.1e}"),
    });
    Ok(reports)
}
