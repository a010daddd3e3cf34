//! A satellite's attitude driven by three torque inputs (reaction wheels or thrusters), one per
//! body axis: `forces(dot([tau_x, tau_y, tau_z], dR))` is the torque's virtual work on the body
//! angular displacement. A constant torque about a principal axis from rest turns the body about
//! that axis by `τ t² / (2 I)`; `slew` steers it to a target attitude with a PD law on the
//! attitude error, the feedback set as the inputs before every step.

use dirac::prelude::*;

use super::Report;

/// A rigid satellite with principal moments of inertia `j`, torques `tau_x, tau_y, tau_z` about
/// its body axes.
#[dirac_system(
    coordinates(R: SO3),
    lagrangian = 0.5 * (j[0] * omega(R)[0].powi(2) + j[1] * omega(R)[1].powi(2)
        + j[2] * omega(R)[2].powi(2)),
    forces(dot([tau_x, tau_y, tau_z], dR)),
    inputs(tau_x, tau_y, tau_z),
)]
#[derive(Debug, Clone, Copy)]
pub struct Satellite {
    pub j: [f64; 3],
}

pub const SCENE: Satellite = Satellite { j: [2.0, 3.0, 4.0] };

/// The attitude a constant torque `tau` about body axis `axis` gives from rest at `t`.
pub fn spun_up(axis: usize, tau: f64, t: f64) -> Matrix3<f64> {
    let angle = tau * t * t / (2.0 * SCENE.j[axis]);
    Retraction::Exp.map(&(Vector3::from_fn(|k, _| if k == axis { 1.0 } else { 0.0 }) * angle))
}

/// A slew from the identity to `target`: the torque `−k_p e − k_d Ω`, `e` the attitude error's
/// rotation vector in body axes, held over each step of `h`. Returns the attitude error's angle
/// at every step.
pub fn slew(target: &Matrix3<f64>, h: f64, t_end: f64) -> Result<(Vec<f64>, Vec<f64>), DiracError> {
    let (kp, kd) = (6.0, 10.0);
    let mut stepper = Stepper::on_manifold(SCENE, Product::cayley(), Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(
        Configuration::of_rotation(Matrix3::identity()),
        Rates::of_rotation(Vector3::zeros()),
    )?;
    let inputs = ["tau_x", "tau_y", "tau_z"].map(|name| stepper.input(name));
    let (mut times, mut errors) = (Vec::new(), Vec::new());
    while stepper.t() < t_end - 0.5 * h {
        let r = stepper.q().rotation[0];
        let error = Retraction::Exp
            .inverse(&(target.transpose() * r))
            .unwrap_or_else(Vector3::zeros);
        let omega = stepper.v()?.rotation[0];
        let torque = -error * kp - omega * kd;
        for (input, value) in inputs.iter().zip(torque.iter()) {
            stepper.set_input_value(input.clone()?, *value)?;
        }
        times.push(stepper.t());
        errors.push(error.norm());
        stepper.step()?;
    }
    Ok((times, errors))
}

/// The tour's row: the slew to a target 1.5 rad away (midpoint, h = 0.01, 12 s).
pub fn report() -> Result<Report, DiracError> {
    let h = 0.01;
    let start = std::time::Instant::now();
    let (times, errors) = slew(&target(), h, 12.0)?;
    Ok(Report {
        scene: "satellite slew",
        quadrature: "midpoint, Cayley".into(),
        h,
        steps: times.len() as u64,
        max_energy_error: None,
        wall: start.elapsed(),
        check: format!(
            "attitude error {:.2} → {:.1e} rad",
            errors.first().copied().unwrap_or_default(),
            errors.last().copied().unwrap_or_default()
        ),
    })
}

/// The slew's target attitude.
pub fn target() -> Matrix3<f64> {
    Retraction::Exp.map(&Vector3::new(0.5, -0.8, 1.2))
}

/// The torque limit of the detumbling law, per axis.
pub const DETUMBLE_TORQUE: f64 = 0.05;

/// The satellite tumbling at body rate `omega0` and detumbled by the rate-damping torque
/// `τ = −k Ω`, saturated at [`DETUMBLE_TORQUE`] per axis and held over each step: one controlled
/// run to `t_end` (midpoint, Cayley, step `h`, every `every`-th step saved).
pub fn detumbled(
    omega0: Vector3<f64>,
    k: f64,
    h: f64,
    t_end: f64,
    every: usize,
) -> Result<Solution<3, Product<0, 1, 0>>, DiracError> {
    let mut stepper = Stepper::on_manifold(SCENE, Product::cayley(), Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(
        Configuration::of_rotation(Matrix3::identity()),
        Rates::of_rotation(omega0),
    )?;
    let run = Run::until(t_end).every(every).control(
        |now: &Feedback<3, Product<0, 1, 0>>, torque: &mut [f64]| {
            let omega = now.sample.v.rotation[0];
            for (tau, w) in torque.iter_mut().zip(omega.iter()) {
                *tau = (-k * w).clamp(-DETUMBLE_TORQUE, DETUMBLE_TORQUE);
            }
        },
    );
    Ok(stepper.solve(run)?)
}
