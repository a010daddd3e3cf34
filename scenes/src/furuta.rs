//! A Furuta pendulum: an arm turning in the horizontal plane under a motor torque `τ`, with a
//! pendulum hinged at its tip swinging in the plane normal to the arm. Balanced upright by
//! discrete LQR on the step map's exact derivatives, with the motor's torque saturated at
//! `τ_max`; the saturated feedback runs inside one [`Run`] through its controller.
//!
//! With `φ` the arm's angle, `θ` the pendulum's from the upright, `J` the arm's inertia, `m` the
//! bob's mass at distance `l` from the hinge and `r` the arm's length, the bob moves at
//! `|ẋ|² = r² φ̇² + 2 r l cos θ φ̇ θ̇ + l² θ̇² + l² sin²θ φ̇²`, so
//! `L = ½ J φ̇² + ½ m |ẋ|² − m g l cos θ`, and the torque does work `τ dφ`.

use dirac::prelude::*;

use crate::lqr::Lqr;

#[dirac_system(
    coordinates(phi, theta),
    lagrangian = 0.5 * j * dot(phi).powi(2)
        + 0.5 * m * (r * r * dot(phi).powi(2)
            + 2.0 * r * l * cos(theta) * dot(phi) * dot(theta)
            + l * l * dot(theta).powi(2)
            + l * l * sin(theta).powi(2) * dot(phi).powi(2))
        - m * g * l * cos(theta),
    forces(tau * dphi),
    inputs(tau),
    quadrature = midpoint,
)]
#[derive(Debug, Clone, Copy)]
pub struct Furuta {
    pub j: f64,
    pub m: f64,
    pub r: f64,
    pub l: f64,
    pub g: f64,
}

/// A small laboratory Furuta pendulum (SI units).
pub const SCENE: Furuta = Furuta {
    j: 0.01,
    m: 0.1,
    r: 0.2,
    l: 0.3,
    g: 9.81,
};

/// The motor's largest torque, N m.
pub const TAU_MAX: f64 = 0.5;

/// `A = ∂(q_{k+1}, p_{k+1})/∂(q_k, p_k)` and `B = ∂(q_{k+1}, p_{k+1})/∂τ` of one step at the
/// upright equilibrium, and the LQR gain for the cost `Σ zᵀz + r τ²`.
pub fn linearisation_and_gain(h: f64, r: f64) -> Result<Lqr, DiracError> {
    Lqr::at_origin(SCENE, h, r)
}

/// One sample of the closed loop: the state a step starts from and the torque held over it.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub t: f64,
    pub phi: f64,
    pub theta: f64,
    pub tau: f64,
}

/// The closed loop from rest with the pendulum tilted by `theta0`: before each step the
/// controller sets `τ = clamp(−K (q, p), −tau_max, tau_max)`, held over the step. Returns one
/// sample per step and the run's solution (every `every`-th state, with energies).
pub fn closed_loop(
    h: f64,
    theta0: f64,
    tau_max: f64,
    steps: u64,
    every: usize,
) -> Result<(Vec<Sample>, Solution<2>), DiracError> {
    let k = linearisation_and_gain(h, 10.0)?.k;
    let mut stepper = Stepper::from_system(SCENE, h)?;
    stepper.start_from_velocity(vector![0.0, theta0], SVector::zeros())?;
    let tau = stepper.input("tau")?.index();
    let mut samples = Vec::new();
    let run = Run::<2>::steps(steps).every(every).control(|now, inputs| {
        let (q, p) = (now.sample.q, now.sample.p);
        let torque = crate::lqr::feedback(&k, &q, &p).clamp(-tau_max, tau_max);
        inputs[tau] = torque;
        samples.push(Sample {
            t: now.sample.t,
            phi: q[0],
            theta: q[1],
            tau: torque,
        });
    });
    let solution = stepper.solve(run)?;
    Ok((samples, solution))
}
