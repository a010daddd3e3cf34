//! Exact derivatives of the step map `(q_k, p_k) ↦ (q_{k+1}, p_{k+1})`.
//!
//! A step solves `F(x; q_k, p_k, u) = 0` for its unknowns `x` by Newton's method. At the root
//! the implicit function theorem gives `∂x/∂(q_k, p_k, u) = −(∂F/∂x)⁻¹ ∂F/∂(q_k, p_k, u)`,
//! which reuses the factorisation Newton accepted the root with: `2N + inputs` solves, and the
//! partial derivatives of the residual, evaluated afresh by dual numbers (the slot Hessian of
//! `L_d`, the forces' and the constraints' derivatives). The new state is then differentiated
//! along. Second derivatives take the third slot derivatives of `L_d` (hyper-hyper-dual
//! numbers) through the same factorisation.

use nalgebra::{DMatrix, SMatrix, SVector};

use crate::base::error::DiracError;

/// `A_k = ∂(q_{k+1}, p_{k+1})/∂(q_k, p_k)` of one step, by blocks, and
/// `B_k = ∂(q_{k+1}, p_{k+1})/∂u_k` for the model's inputs (held over the step).
///
/// ```
/// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
///
/// /// The harmonic oscillator: the midpoint step is the Cayley transform of its generator.
/// struct Oscillator;
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
/// }
/// let h = 0.1;
/// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), h)?;
/// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
/// let a = stepper.step_linearised()?;
/// let c = (1.0 - h * h / 4.0) / (1.0 + h * h / 4.0);
/// assert!((a.q_q[(0, 0)] - c).abs() < 1e-15);
/// assert!((a.matrix().determinant() - 1.0).abs() < 1e-15); // area preserving
/// assert!(a.symplecticity_defect() < 1e-15);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct StepDerivatives<const N: usize> {
    /// `∂q_{k+1}/∂q_k`.
    pub q_q: SMatrix<f64, N, N>,
    /// `∂q_{k+1}/∂p_k`.
    pub q_p: SMatrix<f64, N, N>,
    /// `∂p_{k+1}/∂q_k`.
    pub p_q: SMatrix<f64, N, N>,
    /// `∂p_{k+1}/∂p_k`.
    pub p_p: SMatrix<f64, N, N>,
    /// `∂q_{k+1}/∂u` (`N × inputs`).
    pub q_u: DMatrix<f64>,
    /// `∂p_{k+1}/∂u` (`N × inputs`).
    pub p_u: DMatrix<f64>,
    /// `max |u_ii| / min |u_ii|` over the pivots of the step's factorised Jacobian: a lower
    /// bound of its condition number. The derivatives lose about `log10` of it in digits.
    pub pivot_ratio: f64,
}

impl<const N: usize> StepDerivatives<N> {
    /// Zero derivatives for a model with `inputs` inputs, to be filled column by column.
    pub(crate) fn zeros(inputs: usize, pivot_ratio: f64) -> Self {
        Self {
            q_q: SMatrix::zeros(),
            q_p: SMatrix::zeros(),
            p_q: SMatrix::zeros(),
            p_p: SMatrix::zeros(),
            q_u: DMatrix::zeros(N, inputs),
            p_u: DMatrix::zeros(N, inputs),
            pivot_ratio,
        }
    }

    /// Sets column `c` of `[A B]` (`c < N`: along `q_k`; `c < 2N`: along `p_k`; else along input
    /// `c − 2N`) to the derivatives `dq` and `dp` of `q_{k+1}` and `p_{k+1}`.
    pub(crate) fn set_column(&mut self, c: usize, dq: &SVector<f64, N>, dp: &SVector<f64, N>) {
        match c {
            c if c < N => {
                self.q_q.set_column(c, dq);
                self.p_q.set_column(c, dp);
            }
            c if c < 2 * N => {
                self.q_p.set_column(c - N, dq);
                self.p_p.set_column(c - N, dp);
            }
            c => {
                self.q_u.set_column(c - 2 * N, dq);
                self.p_u.set_column(c - 2 * N, dp);
            }
        }
    }

    /// An error where a derivative is not finite.
    pub(crate) fn finite(self) -> Result<Self, DiracError> {
        let blocks = [self.q_q, self.q_p, self.p_q, self.p_p];
        let finite = blocks.iter().all(|m| m.iter().all(|v| v.is_finite()))
            && self
                .q_u
                .iter()
                .chain(self.p_u.iter())
                .all(|v| v.is_finite());
        if finite {
            Ok(self)
        } else {
            Err(DiracError::NonFinite {
                what: "a derivative of the step map".into(),
                value: f64::NAN,
            })
        }
    }

    /// The `2N × 2N` matrix `[[q_q, q_p], [p_q, p_p]]`.
    pub fn matrix(&self) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(2 * N, 2 * N);
        a.view_mut((0, 0), (N, N)).copy_from(&self.q_q);
        a.view_mut((0, N), (N, N)).copy_from(&self.q_p);
        a.view_mut((N, 0), (N, N)).copy_from(&self.p_q);
        a.view_mut((N, N), (N, N)).copy_from(&self.p_p);
        a
    }

    /// The `2N × inputs` matrix `B = [[q_u], [p_u]]`.
    pub fn input_matrix(&self) -> DMatrix<f64> {
        let inputs = self.q_u.ncols();
        let mut b = DMatrix::zeros(2 * N, inputs);
        b.view_mut((0, 0), (N, inputs)).copy_from(&self.q_u);
        b.view_mut((N, 0), (N, inputs)).copy_from(&self.p_u);
        b
    }

    /// The same derivatives in positions and velocities, `∂(q_{k+1}, v_{k+1})/∂(q_k, v_k)` and
    /// `∂(q_{k+1}, v_{k+1})/∂u` (the `p` blocks then read `v`), by the chain rule through the
    /// Legendre map `p = ∂L/∂v(q, v)`: `start` and `end` are its derivatives
    /// `(∂p/∂q, ∂p/∂v) = ((∂²L/∂v∂q), ∂²L/∂v²)` at the step's two states. With
    /// `J = [[I, 0], [∂p/∂q, ∂p/∂v]]`, `A_v = J_{k+1}⁻¹ A J_k` and `B_v = J_{k+1}⁻¹ B`. `None`
    /// where `∂²L/∂v²` is singular at the end (a degenerate Lagrangian).
    pub fn in_velocities(
        &self,
        start: (&SMatrix<f64, N, N>, &SMatrix<f64, N, N>),
        end: (&SMatrix<f64, N, N>, &SMatrix<f64, N, N>),
    ) -> Option<Self> {
        let ((p_q0, p_v0), (p_q1, p_v1)) = (start, end);
        let dynamic = |m: &SMatrix<f64, N, N>| DMatrix::from_fn(N, N, |i, j| m[(i, j)]);
        let inverse = dynamic(p_v1).lu().try_inverse()?;
        // Singular to working precision: a Lagrangian degenerate at the end.
        let condition = inverse.amax() * p_v1.amax() * N as f64;
        if !condition.is_finite() || condition > 1e13 {
            return None;
        }
        let fixed = |m: &DMatrix<f64>| SMatrix::<f64, N, N>::from_fn(|i, j| m[(i, j)]);
        let q_q = self.q_q + self.q_p * p_q0;
        let q_v = self.q_p * p_v0;
        let v_q = fixed(&(&inverse * dynamic(&(self.p_q + self.p_p * p_q0 - p_q1 * q_q))));
        let v_v = fixed(&(&inverse * dynamic(&(self.p_p * p_v0 - p_q1 * q_v))));
        let v_u = &inverse * (&self.p_u - dynamic(p_q1) * &self.q_u);
        Some(Self {
            q_q,
            q_p: q_v,
            p_q: v_q,
            p_p: v_v,
            q_u: self.q_u.clone(),
            p_u: v_u,
            pivot_ratio: self.pivot_ratio,
        })
    }

    /// `‖AᵀJA − J‖∞` with `J = [[0, I], [−I, 0]]`: zero to round-off for a symplectic step (a
    /// conservative model without constraints).
    pub fn symplecticity_defect(&self) -> f64 {
        let a = self.matrix();
        let mut j = DMatrix::zeros(2 * N, 2 * N);
        for i in 0..N {
            j[(i, N + i)] = 1.0;
            j[(N + i, i)] = -1.0;
        }
        (a.transpose() * &j * &a - j).amax()
    }
}

/// Second derivatives of one step with respect to `z = (q_k, p_k)`: for each output component,
/// its `2N × 2N` Hessian, `q[i][(a, b)] = ∂²q_{k+1,i}/∂z_a∂z_b` and likewise `p`.
///
/// ```
/// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
///
/// /// A linear oscillator: its step map is linear, so every second derivative vanishes.
/// struct Oscillator;
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
/// }
/// let mut stepper = Stepper::new(Oscillator, Quadrature::galerkin(2)?, 0.1)?;
/// stepper.start_from_velocity(vector![1.0], vector![0.3])?;
/// let (_, hessians) = stepper.step_second_order()?;
/// assert!(hessians.q[0].amax() < 1e-14 && hessians.p[0].amax() < 1e-14);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct StepHessians<const N: usize> {
    /// `∂²q_{k+1,i}/∂z²` for `i = 0..N`.
    pub q: Vec<DMatrix<f64>>,
    /// `∂²p_{k+1,i}/∂z²` for `i = 0..N`.
    pub p: Vec<DMatrix<f64>>,
}
