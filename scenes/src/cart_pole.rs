//! An inverted pendulum on a cart, stabilised upright by discrete LQR built from the step map's
//! exact derivatives: `A = ∂(q_{k+1}, p_{k+1})/∂(q_k, p_k)` and `B = ∂(q_{k+1}, p_{k+1})/∂u` of
//! one midpoint step at the upright equilibrium, the Riccati recursion for the gain `K`, and the
//! feedback `u_k = −K (q_k, p_k)` applied as the model's input at every step of the variational
//! integrator itself (not of a linear model).

use dirac::prelude::*;

/// `θ` from the upright vertical; a force `u` pushes the cart.
#[dirac_system(
    coordinates(x, theta),
    lagrangian = 0.5 * (cart + bob) * dot(x).powi(2)
        + bob * l * dot(x) * dot(theta) * cos(theta)
        + 0.5 * bob * l * l * dot(theta).powi(2)
        - bob * g * l * cos(theta),
    forces(u * dx),
    inputs(u),
    quadrature = midpoint,
)]
#[derive(Debug, Clone, Copy)]
pub struct CartPole {
    pub cart: f64,
    pub bob: f64,
    pub l: f64,
    pub g: f64,
}

pub const SCENE: CartPole = CartPole {
    cart: 1.0,
    bob: 0.5,
    l: 0.5,
    g: 9.81,
};

pub use crate::lqr::Lqr;

/// One sample of the closed loop.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub t: f64,
    pub x: f64,
    pub theta: f64,
    pub u: f64,
}

/// `A`, `B` of one step at the upright equilibrium, and the LQR gain `K` for the cost
/// `Σ zᵀz + r u²` ([`lqr::gain`](crate::lqr::gain)).
pub fn linearisation_and_gain(h: f64, r: f64) -> Result<Lqr, DiracError> {
    Lqr::at_origin(SCENE, h, r)
}

/// Closed loop from the cart at rest with the pole tilted by `theta0`, one sample per step: the
/// feedback `u_k = −K (q_k, p_k)` set by the run's controller before each step and held over it.
pub fn closed_loop(h: f64, theta0: f64, steps: usize) -> Result<Vec<Sample>, DiracError> {
    let k = linearisation_and_gain(h, 0.1)?.k;
    let mut stepper = Stepper::from_system(SCENE, h)?;
    stepper.start_from_velocity(vector![0.0, theta0], SVector::zeros())?;
    let force = stepper.input("u")?.index();
    let mut samples = Vec::with_capacity(steps + 1);
    let run = Run::<2>::steps(steps as u64 + 1)
        .every(steps + 1)
        .control(|now, inputs| {
            let (q, p) = (now.sample.q, now.sample.p);
            let u = crate::lqr::feedback(&k, &q, &p);
            inputs[force] = u;
            samples.push(Sample {
                t: now.sample.t,
                x: q[0],
                theta: q[1],
                u,
            });
        });
    stepper.solve(run)?;
    Ok(samples)
}
