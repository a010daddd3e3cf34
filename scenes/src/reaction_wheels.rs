//! A satellite turned by three reaction wheels, stabilised by discrete LQR on the step map's
//! derivatives on `R³ × SO(3)`. The wheels' angles `a, b, c` are measured against the body; a
//! motor's torque acts on its wheel's angle (`forces(u_x * da, ...)`) and, through the
//! Lagrangian's coupling, back on the body. The torques are internal: the spatial angular
//! momentum, zero from rest, stays zero, and the body is turned by moving momentum between it
//! and the wheels.
//!
//! The regulator is designed in the tangent chart at the target attitude: the state
//! `z = (ζ, μ)` with `ζ = R_{q*}⁻¹(q)` and `μ` the momentum pulled back to that chart, the
//! coordinates in which [`Stepper::step_linearised`] gives `A` and `B` at the rest point.

use dirac::configuration_space::ConfigurationSpace;
use dirac::nalgebra::DMatrix;
use dirac::prelude::*;

use crate::{Report, lqr};

/// A rigid body of inertia `j` (wheels included) with a wheel of axial inertia `i` on each body
/// axis: `L = ½ Ωᵀ J Ω + ½ i Σ_k (Ω_k + ẇ_k)²`.
#[dirac_system(
    coordinates(a, b, c, R: SO3),
    lagrangian = 0.5 * dot(omega(R), j * omega(R))
        + 0.5 * i * ((omega(R)[0] + dot(a)).powi(2) + (omega(R)[1] + dot(b)).powi(2)
            + (omega(R)[2] + dot(c)).powi(2)),
    forces(u_x * da, u_y * db, u_z * dc),
    inputs(u_x, u_y, u_z),
)]
#[derive(Debug, Clone, Copy)]
pub struct WheeledSatellite {
    pub j: [[f64; 3]; 3],
    pub i: f64,
}

/// A satellite with products of inertia and three wheels.
pub const SCENE: WheeledSatellite = WheeledSatellite {
    j: [[4.0, 0.2, -0.1], [0.2, 5.0, 0.3], [-0.1, 0.3, 3.0]],
    i: 0.1,
};

/// The configuration space: wheel angles and the attitude.
pub type Space = Product<3, 1, 0>;

/// The target: wheels at zero, the body at the identity.
pub fn target() -> Configuration<f64, 3, 1, 0> {
    Configuration::new(SVector::zeros(), [Matrix3::identity()], [])
}

/// The state `z = (ζ, μ)` of `(q, p)` in the cotangent lift of the chart at the target.
pub fn chart_state(
    q: &Configuration<f64, 3, 1, 0>,
    p: &Rates<f64, 3, 1, 0>,
) -> Option<SVector<f64, 12>> {
    let space = Space::cayley();
    let target = target();
    let zeta: SVector<f64, 6> = space.local(&target, q)?;
    let mu = space.pull_back(&target, &zeta, p);
    Some(SVector::<f64, 12>::from_fn(|k, _| {
        if k < 6 { zeta[k] } else { mu[k - 6] }
    }))
}

/// The components of `z` the regulator reads: the attitude's chart coordinates and the wheels'
/// momenta. The wheels' angles are cyclic (nothing depends on them) and the body's momentum,
/// the spatial angular momentum linearised at rest, is kept by every step whatever the torques
/// (zero from rest): neither can be regulated, and `A` keeps the subspace where the latter
/// vanishes.
pub const REGULATED: [usize; 6] = [3, 4, 5, 6, 7, 8];

/// `A`, `B` of one midpoint step of `h` from rest at the target (12 × 12 and 12 × 3), and the
/// LQR gain `K` (3 × 12, zero on the components not [`REGULATED`]) for the cost
/// `Σ z_rᵀ z_r + r |u|²` over the regulated components `z_r`.
pub fn regulator(h: f64, r: f64) -> Result<lqr::Lqr, DiracError> {
    let mut stepper = Stepper::on_manifold(SCENE, Space::cayley(), Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(target(), Rates::zero())?;
    let derivatives = stepper.step_linearised()?;
    let (a, b) = (derivatives.matrix(), derivatives.input_matrix());
    let m = REGULATED.len();
    let a_r = DMatrix::from_fn(m, m, |i, j| a[(REGULATED[i], REGULATED[j])]);
    let b_r = DMatrix::from_fn(m, b.ncols(), |i, j| b[(REGULATED[i], j)]);
    let k_r = lqr::gain(&a_r, &b_r, r)?;
    let mut k = DMatrix::zeros(b.ncols(), a.ncols());
    for (c, &column) in REGULATED.iter().enumerate() {
        k.set_column(column, &k_r.column(c));
    }
    Ok(lqr::Lqr { a, b, k })
}

/// One sample of the closed loop.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub t: f64,
    /// The attitude's angle from the target.
    pub angle: f64,
    /// `|ω|` of the body.
    pub rate: f64,
    /// The spatial angular momentum's norm.
    pub momentum: f64,
    /// The wheels' rates.
    pub wheels: Vector3<f64>,
}

/// The closed loop from rest at the attitude `Exp(tilt)`: the feedback `u = −K z` computed
/// inside the run before every step of `h` (midpoint, Cayley) until `t_end`, every
/// `every`-th step sampled. Where the attitude is a half turn from the target (outside the
/// chart there) the feedback is zero.
pub fn stabilised(
    gain: &DMatrix<f64>,
    tilt: Vector3<f64>,
    h: f64,
    t_end: f64,
    every: usize,
) -> Result<Vec<Sample>, DiracError> {
    let mut stepper = Stepper::on_manifold(SCENE, Space::cayley(), Quadrature::midpoint(), h)?;
    let start = Configuration::new(SVector::zeros(), [Retraction::Exp.map(&tilt)], []);
    stepper.start_from_velocity(start, Rates::zero())?;
    let run =
        Run::until(t_end)
            .every(every)
            .control(|now: &Feedback<6, Space>, torque: &mut [f64]| {
                let z = chart_state(&now.sample.q, &now.sample.p).unwrap_or_else(SVector::zeros);
                for (k, u) in torque.iter_mut().enumerate() {
                    *u = -(0..12).map(|c| gain[(k, c)] * z[c]).sum::<f64>();
                }
            });
    let solution = stepper.solve(run)?;
    let trajectory = &solution.trajectory;
    Ok(trajectory
        .t()
        .iter()
        .zip(trajectory.q())
        .zip(trajectory.v().iter().zip(trajectory.p()))
        .map(|((&t, q), (v, p))| Sample {
            t,
            angle: Retraction::Exp
                .inverse(&q.rotation[0])
                .map_or(f64::NAN, |e| e.norm()),
            rate: v.rotation[0].norm(),
            momentum: q.spatial(p, 0).norm(),
            wheels: v.vector.fixed_rows::<3>(0).into_owned(),
        })
        .collect())
}

/// The tilt the example and the tour start from, 0.78 rad.
pub fn tilt() -> Vector3<f64> {
    Vector3::new(0.5, -0.4, 0.45)
}

/// The tour's row: the regulator at h = 0.05 and the closed loop from [`tilt`] over 20 s.
pub fn report() -> Result<Report, DiracError> {
    let (h, t_end) = (0.05, 20.0);
    let start = std::time::Instant::now();
    let regulator = regulator(h, 0.01)?;
    let samples = stabilised(&regulator.k, tilt(), h, t_end, 20)?;
    let momentum = samples.iter().map(|s| s.momentum).fold(0.0, f64::max);
    let (first, last) = (samples[0], samples[samples.len() - 1]);
    Ok(Report {
        scene: "satellite LQR, reaction wheels",
        quadrature: "midpoint, Cayley".into(),
        h,
        steps: (t_end / h).round() as u64,
        max_energy_error: None,
        wall: start.elapsed(),
        check: format!(
            "attitude {:.2} → {:.1e} rad, |L| ≤ {momentum:.0e}",
            first.angle, last.angle
        ),
    })
}
