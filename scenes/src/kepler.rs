//! Kepler problem with e = 0.5: q0 = (0.5, 0), p0 = (0, √3); angular momentum is conserved by
//! the discrete Noether theorem. And an orbit of eccentricity 0.9 at a fixed step and with the
//! time-transformed step (`dt/ds = |q|`), against Kepler's equation.

use dirac::prelude::*;

use std::time::Instant;

use super::first_order::{FirstOrder, KeplerOde};
use super::{Report, timed};

/// A unit mass in the potential −μ/|q|.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)) + mu / sqrt(x * x + y * y),
)]
#[derive(Debug, Clone, Copy)]
pub struct Kepler {
    pub mu: f64,
}

pub const SCENE: Kepler = Kepler { mu: 1.0 };

pub fn q0() -> SVector<f64, 2> {
    vector![0.5, 0.0]
}

pub fn p0() -> SVector<f64, 2> {
    vector![0.0, 3f64.sqrt()]
}

/// Angular momentum x p_y − y p_x.
pub fn angular_momentum(q: &SVector<f64, 2>, p: &SVector<f64, 2>) -> f64 {
    q[0] * p[1] - q[1] * p[0]
}

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 100.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    stepper.start_from_momentum(q0(), p0())?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 10)?;
    trajectory.save_csv(format!(
        "output/kepler_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    let l0 = angular_momentum(&q0(), &p0());
    let drift = trajectory
        .q()
        .iter()
        .zip(trajectory.p())
        .map(|(q, p)| ((angular_momentum(q, p) - l0) / l0).abs())
        .fold(0.0, f64::max);
    Ok(Report {
        scene: "kepler",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("max relative angular momentum error = {drift:.2e}"),
    })
}

/// The orbit of eccentricity 0.9 (semi-major axis 1, from its pericentre) over 100 revolutions
/// by Kahan–Li 8: at a fixed step `h = 0.0025`, and time-transformed with `δs = 0.2` (31 fictive
/// steps a revolution); each against Kepler's equation at the end.
pub fn eccentric_reports() -> Result<Vec<Report>, DiracError> {
    let orbit = KeplerOde {
        kepler: SCENE,
        e: 0.9,
    };
    let y = orbit.initial();
    let (q0, v0) = (vector![y[0], y[1]], vector![y[2], y[3]]);
    let t_end = 200.0 * std::f64::consts::PI;
    let exact = orbit.exact(t_end).expect("Kepler's equation");
    let check = |q: SVector<f64, 2>| {
        let error = (q - vector![exact[0], exact[1]]).amax();
        format!("|q(200π) − Kepler| = {error:.1e}")
    };
    let h = 0.0025;
    let mut fixed = Stepper::explicit(SCENE, Composition::kahan_li_8(), h)?;
    fixed.start_from_velocity(q0, v0)?;
    // Every step recorded, as the time-transformed run below records its own.
    let (trajectory, wall) = timed(&mut fixed, t_end, 1)?;
    let fixed_report = Report {
        scene: "kepler e = 0.9",
        quadrature: Composition::kahan_li_8().name().to_string(),
        h,
        steps: fixed.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: check(fixed.q()),
    };
    let ds = 0.2;
    let mut adaptive = TimeTransformed::new(SCENE, Composition::kahan_li_8(), ds)?;
    adaptive.start_from_velocity(q0, v0)?;
    let clock = Instant::now();
    let trajectory = adaptive.trajectory_until(t_end)?;
    let wall = clock.elapsed();
    let adaptive_report = Report {
        scene: "kepler e = 0.9",
        quadrature: format!("{}, time-transformed", Composition::kahan_li_8().name()),
        h: ds,
        steps: adaptive.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: check(adaptive.q()),
    };
    Ok(vec![fixed_report, adaptive_report])
}
