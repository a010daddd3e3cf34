//! Rigid bodies on `SO(3)`: a free body (Euler's equations; a symmetric one has a closed form),
//! and a body in gravity held at a fixed point, the heavy top and the 3D pendulum. The attitude
//! `R` maps body axes to space axes, `Ω` is the body angular velocity (`Ṙ = R Ω̂`), `Π = J Ω` the
//! body angular momentum and `R Π` the spatial one.
//!
//! The models are written with the macro; `HeavyTopByHand` is the top written against the
//! runtime's traits, and `reference` integrates the same motion as a quaternion ODE with Dop853
//! (an independent method for the convergence tests).

use dirac::prelude::*;
use ode_solvers::System;

use super::{Report, timed};

/// A free rigid body with principal moments of inertia `j`: `L = ½ Σ j_i Ω_i²`.
#[dirac_system(
    coordinates(R: SO3),
    lagrangian = 0.5 * (j[0] * omega(R)[0].powi(2) + j[1] * omega(R)[1].powi(2)
        + j[2] * omega(R)[2].powi(2)),
)]
#[derive(Debug, Clone, Copy)]
pub struct FreeBody {
    pub j: [f64; 3],
}

/// A rigid body of mass `m` held at a fixed point, its centre of mass at `rho` in body axes, in
/// gravity `g` along `−e₃`: `L = ½ Ωᵀ J Ω − m g e₃ᵀ R ρ`. With `J` symmetric about `ρ`'s axis it
/// is the heavy top; otherwise the 3D pendulum of Lee, Leok and McClamroch.
#[dirac_system(
    coordinates(R: SO3),
    lagrangian = 0.5 * dot(omega(R), j * omega(R)) - m * g * dot([0.0, 0.0, 1.0], R * rho),
)]
#[derive(Debug, Clone, Copy)]
pub struct HeavyTop {
    pub j: [[f64; 3]; 3],
    pub m: f64,
    pub g: f64,
    pub rho: [f64; 3],
}

/// The same body written against the runtime's traits, without the macro.
#[derive(Debug, Clone, Copy)]
pub struct HeavyTopByHand(pub HeavyTop);

impl DiracSystem<3, Product<0, 1, 0>> for HeavyTopByHand {
    fn lagrangian<D: Scalar>(&self, q: &Configuration<D, 0, 1, 0>, v: &Rates<D, 0, 1, 0>) -> D {
        let HeavyTop { j, m, g, rho } = self.0;
        let (r, w) = (q.rotation[0], v.rotation[0]);
        let lifted = |x: f64| D::from(x);
        let j = Matrix3::from_fn(|a, b| lifted(j[a][b]));
        let rho = Vector3::from_fn(|a, _| lifted(rho[a]));
        w.dot(&(j * w)) * 0.5 - (r * rho)[2] * (m * g)
    }

    fn coordinate_name(&self, _i: usize) -> String {
        "R".into()
    }
}

/// An asymmetric free body tumbling about all three axes.
pub const ASYMMETRIC: FreeBody = FreeBody { j: [1.0, 2.0, 3.0] };

/// A symmetric free body (`I₁ = I₂`), whose motion has a closed form ([`symmetric`]).
pub const SYMMETRIC: FreeBody = FreeBody { j: [1.0, 1.0, 2.5] };

/// A fast symmetric top (`J = diag(1, 1, 0.5)`, centre of mass 0.3 up its axis), tilted by
/// 0.4 rad and spinning at 20 rad/s about its axis: it precesses and nutates.
pub const TOP: HeavyTop = HeavyTop {
    j: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]],
    m: 1.0,
    g: 9.81,
    rho: [0.0, 0.0, 0.3],
};

/// The 3D pendulum: an asymmetric body hanging from a point off its centre of mass.
pub const PENDULUM: HeavyTop = HeavyTop {
    j: [[0.13, 0.0, 0.0], [0.0, 0.28, 0.0], [0.0, 0.0, 0.17]],
    m: 1.0,
    g: 9.81,
    rho: [0.0, 0.05, -0.3],
};

/// The free bodies' initial attitude and body angular velocity.
pub fn free_start() -> (Matrix3<f64>, Vector3<f64>) {
    (
        Retraction::Exp.map(&Vector3::new(0.3, -0.2, 0.5)),
        Vector3::new(0.4, -1.1, 0.7),
    )
}

/// The top's initial attitude (tilted about `e₁`) and spin.
pub fn top_start() -> (Matrix3<f64>, Vector3<f64>) {
    (
        Retraction::Exp.map(&Vector3::new(0.4, 0.0, 0.0)),
        Vector3::new(0.0, 0.0, 20.0),
    )
}

/// The 3D pendulum's initial attitude and body angular velocity.
pub fn pendulum_start() -> (Matrix3<f64>, Vector3<f64>) {
    (
        Retraction::Exp.map(&Vector3::new(0.7, 0.2, -0.4)),
        Vector3::new(1.5, -0.6, 2.0),
    )
}

/// A symmetric free body's attitude at `t` from `(R0, Ω0)`: with `π = R0 J Ω0` the spatial
/// angular momentum and `c = (1/I₃ − 1/I₁) Π₃`,
/// `R(t) = exp(t π̂ / I₁) R0 exp(c t ê₃)`.
pub fn symmetric(
    body: &FreeBody,
    r0: &Matrix3<f64>,
    omega0: &Vector3<f64>,
    t: f64,
) -> Matrix3<f64> {
    let [i1, _, i3] = body.j;
    let pi0 = Vector3::from_fn(|a, _| body.j[a] * omega0[a]);
    let spatial = r0 * pi0;
    let c = (1.0 / i3 - 1.0 / i1) * pi0[2];
    Retraction::Exp.map(&(spatial * (t / i1))) * r0 * Retraction::Exp.map(&(Vector3::z() * (c * t)))
}

/// The heavy top's motion as an ODE in the unit quaternion `q` (attitude) and the body momentum
/// `Π`: `q̇ = ½ q ⊗ (0, Ω)`, `Π̇ = Π × Ω + m g (Rᵀe₃) × ρ − i Ω₃ e₃ × Ω`, `Ω = J⁻¹Π`. The last
/// term is a flywheel of inertia `i` whose rate is `Ω₃` and whose momentum does not turn with
/// the body (`J` then holds `i` on its third axis; see `shafted_body`).
struct QuaternionOde {
    top: HeavyTop,
    inverse: Matrix3<f64>,
    wheel: f64,
}

type Y = ode_solvers::SVector<f64, 7>;

impl System<f64, Y> for QuaternionOde {
    fn system(&self, _t: f64, y: &Y, dy: &mut Y) {
        let (w, x, yq, z) = (y[0], y[1], y[2], y[3]);
        let pi = Vector3::new(y[4], y[5], y[6]);
        let omega = self.inverse * pi;
        // q ⊗ (0, Ω) / 2
        dy[0] = 0.5 * (-x * omega[0] - yq * omega[1] - z * omega[2]);
        dy[1] = 0.5 * (w * omega[0] + yq * omega[2] - z * omega[1]);
        dy[2] = 0.5 * (w * omega[1] + z * omega[0] - x * omega[2]);
        dy[3] = 0.5 * (w * omega[2] + x * omega[1] - yq * omega[0]);
        let r = rotation_of(&[w, x, yq, z]);
        let up = r.transpose() * Vector3::z();
        let rho = Vector3::from(self.top.rho);
        let torque = up.cross(&rho) * (self.top.m * self.top.g)
            - Vector3::z().cross(&omega) * (self.wheel * omega[2]);
        let rate = pi.cross(&omega) + torque;
        dy[4] = rate[0];
        dy[5] = rate[1];
        dy[6] = rate[2];
    }
}

/// The rotation of a unit quaternion `(w, x, y, z)` (normalised first).
fn rotation_of(q: &[f64; 4]) -> Matrix3<f64> {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let (w, x, y, z) = (q[0] / n, q[1] / n, q[2] / n, q[3] / n);
    Matrix3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// A unit quaternion of the rotation `r` (Shepperd's method).
fn quaternion_of(r: &Matrix3<f64>) -> [f64; 4] {
    let trace = r.trace();
    if trace > 0.0 {
        let s = (trace + 1.0).sqrt() * 2.0;
        [
            0.25 * s,
            (r[(2, 1)] - r[(1, 2)]) / s,
            (r[(0, 2)] - r[(2, 0)]) / s,
            (r[(1, 0)] - r[(0, 1)]) / s,
        ]
    } else if r[(0, 0)] > r[(1, 1)] && r[(0, 0)] > r[(2, 2)] {
        let s = (1.0 + r[(0, 0)] - r[(1, 1)] - r[(2, 2)]).sqrt() * 2.0;
        [
            (r[(2, 1)] - r[(1, 2)]) / s,
            0.25 * s,
            (r[(0, 1)] + r[(1, 0)]) / s,
            (r[(0, 2)] + r[(2, 0)]) / s,
        ]
    } else if r[(1, 1)] > r[(2, 2)] {
        let s = (1.0 + r[(1, 1)] - r[(0, 0)] - r[(2, 2)]).sqrt() * 2.0;
        [
            (r[(0, 2)] - r[(2, 0)]) / s,
            (r[(0, 1)] + r[(1, 0)]) / s,
            0.25 * s,
            (r[(1, 2)] + r[(2, 1)]) / s,
        ]
    } else {
        let s = (1.0 + r[(2, 2)] - r[(0, 0)] - r[(1, 1)]).sqrt() * 2.0;
        [
            (r[(1, 0)] - r[(0, 1)]) / s,
            (r[(0, 2)] + r[(2, 0)]) / s,
            (r[(1, 2)] + r[(2, 1)]) / s,
            0.25 * s,
        ]
    }
}

/// The attitude and body momentum at `t_end` from `(R0, Ω0)`, by Dop853 on the quaternion ODE
/// at relative and absolute tolerance `tolerance`: a reference independent of dirac's
/// discretisation.
pub fn reference(
    top: &HeavyTop,
    r0: &Matrix3<f64>,
    omega0: &Vector3<f64>,
    t_end: f64,
    tolerance: f64,
) -> Result<(Matrix3<f64>, Vector3<f64>), String> {
    with_wheel(top, 0.0, r0, omega0, t_end, tolerance)
}

/// [`reference()`] with a flywheel of inertia `wheel` on the third body axis (see
/// `QuaternionOde`); the momentum returned is `J Ω` with `J` the body's and the wheel's.
pub fn with_wheel(
    top: &HeavyTop,
    wheel: f64,
    r0: &Matrix3<f64>,
    omega0: &Vector3<f64>,
    t_end: f64,
    tolerance: f64,
) -> Result<(Matrix3<f64>, Vector3<f64>), String> {
    let mut j = Matrix3::from_fn(|a, b| top.j[a][b]);
    j[(2, 2)] += wheel;
    let inverse = j.try_inverse().ok_or("a singular inertia")?;
    let pi0 = j * omega0;
    let q0 = quaternion_of(r0);
    let y0 = Y::from([q0[0], q0[1], q0[2], q0[3], pi0[0], pi0[1], pi0[2]]);
    let ode = QuaternionOde {
        top: *top,
        inverse,
        wheel,
    };
    let end = super::peers::dop853_end(ode, y0, t_end, tolerance)?;
    Ok((
        rotation_of(&[end[0], end[1], end[2], end[3]]),
        Vector3::new(end[4], end[5], end[6]),
    ))
}

/// A stepper for `body` from `(R0, Ω0)`.
pub fn started<S: DiracSystem<3, Product<0, 1, 0>>>(
    body: S,
    space: Product<0, 1, 0>,
    quadrature: Quadrature,
    h: f64,
    (r0, omega0): (Matrix3<f64>, Vector3<f64>),
) -> Result<ManifoldStepper<S, 3, Product<0, 1, 0>>, DiracError> {
    let mut stepper = Stepper::on_manifold(body, space, quadrature, h)?;
    stepper.start_from_velocity(Configuration::of_rotation(r0), Rates::of_rotation(omega0))?;
    Ok(stepper)
}

/// The heavy top's vertical angular momentum `e₃ · R Π`.
pub fn vertical_momentum(q: &Configuration<f64, 0, 1, 0>, p: &Rates<f64, 0, 1, 0>) -> f64 {
    q.spatial(p, 0)[2]
}

/// The 3D pendulum to T = 5 with `quadrature` (Cayley, h = 0.01) against the quaternion reference
/// (Dop853 at 1e-13).
pub fn pendulum_report(quadrature: Quadrature) -> Result<Report, Box<dyn std::error::Error>> {
    let (h, t_end) = (0.01, 5.0);
    let name = quadrature.name();
    let start = pendulum_start();
    let mut stepper = started(PENDULUM, Product::cayley(), quadrature, h, start)?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    let (r_ref, pi_ref) = reference(&PENDULUM, &start.0, &start.1, t_end, 1e-13)?;
    let error = (stepper.q().rotation[0] - r_ref)
        .amax()
        .max((stepper.p().rotation[0] - pi_ref).amax());
    trajectory.save_csv(format!("output/pendulum_3d_{name}.csv"))?;
    Ok(Report {
        scene: "3D pendulum",
        quadrature: format!("{name}, Cayley"),
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("|(R, Π)(5) − Dop853| = {error:.1e}"),
    })
}

/// The axis of the top's symmetry in space, `R e₃`, at every `every`-th step of `steps`.
pub fn top_axis(
    space: Product<0, 1, 0>,
    h: f64,
    steps: u64,
    every: usize,
) -> Result<Vec<(f64, Vector3<f64>)>, DiracError> {
    let mut stepper = started(TOP, space, Quadrature::midpoint(), h, top_start())?;
    let trajectory = stepper.solve(Run::steps(steps).every(every))?.trajectory;
    Ok(trajectory
        .t()
        .iter()
        .zip(trajectory.q())
        .map(|(t, q)| (*t, q.rotation[0] * Vector3::z()))
        .collect())
}

/// The top's energy error and vertical momentum drift every 1 000 steps of a run of `steps`
/// (h = 0.01): `(t, |E − E₀|, |ΔL_z|)`.
pub fn top_invariants(
    space: Product<0, 1, 0>,
    steps: u64,
) -> Result<Vec<(f64, f64, f64)>, DiracError> {
    let mut stepper = started(TOP, space, Quadrature::midpoint(), 0.01, top_start())?;
    let solution = stepper.solve(Run::steps(steps).every(1000))?;
    let trajectory = solution.trajectory;
    let (e0, lz0) = (
        trajectory.energy()[0],
        vertical_momentum(&trajectory.q()[0], &trajectory.p()[0]),
    );
    Ok((0..trajectory.len())
        .map(|k| {
            let sample = trajectory.sample(k).expect("in range");
            (
                sample.t,
                (trajectory.energy()[k] - e0).abs(),
                (vertical_momentum(&sample.q, &sample.p) - lz0).abs(),
            )
        })
        .collect())
}

/// The tour's rows: the top over 10 s with both retractions, its vertical momentum and
/// `RᵀR − I` checked.
pub fn report(space: Product<0, 1, 0>) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 10.0);
    let mut stepper = started(TOP, space, Quadrature::midpoint(), h, top_start())?;
    let lz0 = vertical_momentum(&stepper.q(), &stepper.p());
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    let drift = trajectory
        .q()
        .iter()
        .zip(trajectory.p())
        .map(|(q, p)| (vertical_momentum(q, p) - lz0).abs())
        .fold(0.0, f64::max);
    let orthogonality = trajectory
        .q()
        .iter()
        .map(|q| (q.rotation[0].transpose() * q.rotation[0] - Matrix3::identity()).amax())
        .fold(0.0, f64::max);
    Ok(Report {
        scene: "heavy top",
        quadrature: format!("midpoint, {:?}", space.retraction()),
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("|ΔL_z| = {drift:.1e}, |RᵀR − I| = {orthogonality:.1e}"),
    })
}
