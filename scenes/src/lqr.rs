//! Discrete LQR: the gain of the infinite-horizon regulator of `z_{k+1} = A z_k + B u_k` for the
//! cost `Σ z_kᵀ Q z_k + r |u_k|²`, by the Riccati recursion run to a fixed point.

use dirac::nalgebra::DMatrix;
use dirac::prelude::*;

/// One step's derivatives at an equilibrium and the LQR gain.
#[derive(Debug, Clone)]
pub struct Lqr {
    /// `∂(q_{k+1}, p_{k+1})/∂(q_k, p_k)`.
    pub a: DMatrix<f64>,
    /// `∂(q_{k+1}, p_{k+1})/∂u`.
    pub b: DMatrix<f64>,
    /// The feedback gain: `u = −K (q, p)`.
    pub k: DMatrix<f64>,
}

impl Lqr {
    /// `A`, `B` of one step of `system` (its own quadrature, step `h`) from rest at the origin,
    /// and the gain for the cost `Σ zᵀz + r |u|²`.
    pub fn at_origin<S: DiracSystem<N>, const N: usize>(
        system: S,
        h: f64,
        r: f64,
    ) -> Result<Self, DiracError> {
        let mut stepper = Stepper::from_system(system, h)?;
        stepper.start_from_momentum(SVector::zeros(), SVector::zeros())?;
        let derivatives = stepper.step_linearised()?;
        let (a, b) = (derivatives.matrix(), derivatives.input_matrix());
        let k = gain(&a, &b, r)?;
        Ok(Self { a, b, k })
    }
}

/// The first input of the feedback `u = −K z` at `z = (q, p)`, without allocating.
pub fn feedback<const N: usize>(k: &DMatrix<f64>, q: &SVector<f64, N>, p: &SVector<f64, N>) -> f64 {
    -(0..N)
        .map(|i| k[(0, i)] * q[i] + k[(0, N + i)] * p[i])
        .sum::<f64>()
}

/// The gain `K` of the feedback `u = −K z`, with `Q = I` and the input weight `r`; an error if
/// the recursion has not settled to 1e-13 (relative) in 100 000 iterations.
pub fn gain(a: &DMatrix<f64>, b: &DMatrix<f64>, r: f64) -> Result<DMatrix<f64>, DiracError> {
    let q = DMatrix::<f64>::identity(a.nrows(), a.ncols());
    let weight = DMatrix::<f64>::identity(b.ncols(), b.ncols()) * r;
    let gain = |p: &DMatrix<f64>| -> Option<DMatrix<f64>> {
        let scale = &weight + b.transpose() * p * b;
        Some(scale.try_inverse()? * b.transpose() * p * a)
    };
    let mut p = q.clone();
    for _ in 0..100_000 {
        let Some(k) = gain(&p) else { break };
        let next = &q + a.transpose() * &p * a - a.transpose() * &p * b * &k;
        let change = (&next - &p).amax();
        p = next;
        if change <= 1e-13 * p.amax() {
            if let Some(k) = gain(&p) {
                return Ok(k);
            }
            break;
        }
    }
    Err(DiracError::NoConvergence {
        problem: "the Riccati recursion",
        step: 0,
        residual: f64::NAN,
        update: f64::NAN,
        iterations: 100_000,
        tolerance: 1e-13,
        step_tolerance: 1e-13,
    })
}
