//! Lotka–Volterra in Lagrangian form, linear in the velocities: L = ϑ(q)·q̇ − H(q) with
//! H = a1 q1 + a2 q2 + b1 ln q1 + b2 ln q2 and ϑ = (ln q2 / q1, 0). Its equations
//! (ϑ'ᵀ − ϑ') q̇ = ∇H read q̇1 = q1 (a2 q2 + b2), q̇2 = −q2 (a1 q1 + b1), and H is conserved.

use dirac::prelude::*;

use super::{Report, timed};

#[dirac_system(
    coordinates(q1, q2),
    lagrangian = ln(q2) / q1 * dot(q1) - (a1 * q1 + a2 * q2 + b1 * ln(q1) + b2 * ln(q2)),
)]
#[derive(Debug, Clone, Copy)]
pub struct LotkaVolterra {
    pub a1: f64,
    pub a2: f64,
    pub b1: f64,
    pub b2: f64,
}

pub const SCENE: LotkaVolterra = LotkaVolterra {
    a1: 1.0,
    a2: 1.0,
    b1: -1.0,
    b2: -2.0,
};

pub fn q0() -> SVector<f64, 2> {
    vector![2.0, 1.0]
}

pub fn hamiltonian(q: &SVector<f64, 2>) -> f64 {
    let LotkaVolterra { a1, a2, b1, b2 } = SCENE;
    a1 * q[0] + a2 * q[1] + b1 * q[0].ln() + b2 * q[1].ln()
}

/// The vector field, derived by hand from the Lagrangian.
pub fn field(q: &SVector<f64, 2>) -> SVector<f64, 2> {
    let LotkaVolterra { a1, a2, b1, b2 } = SCENE;
    vector![q[0] * (a2 * q[1] + b2), -q[1] * (a1 * q[0] + b1)]
}

/// The state at `t` by classical Runge–Kutta at h ≈ 1e-4 (an independent reference).
pub fn reference(t: f64) -> SVector<f64, 2> {
    let steps = (t / 1e-4).round() as usize;
    let h = t / steps as f64;
    let mut q = q0();
    for _ in 0..steps {
        let k1 = field(&q);
        let k2 = field(&(q + k1 * (h / 2.0)));
        let k3 = field(&(q + k2 * (h / 2.0)));
        let k4 = field(&(q + k3 * h));
        q += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
    }
    q
}

/// 200 steps of h = 0.05 from q0 alone (T = 10): the Hamiltonian's largest error and the
/// distance to the Runge–Kutta reference.
pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.05, 10.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(SCENE, quadrature, h)?;
    stepper.start_from_position(q0())?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    let h0 = hamiltonian(&q0());
    let drift = trajectory
        .q()
        .iter()
        .map(|q| (hamiltonian(q) - h0).abs())
        .fold(0.0, f64::max);
    Ok(Report {
        scene: "Lotka–Volterra",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(drift),
        wall,
        check: format!(
            "from q0 alone; |q(10) − RK4| = {:.2e}, |p − ϑ(q)| = 0 by construction",
            (stepper.q() - reference(10.0)).amax()
        ),
    })
}
