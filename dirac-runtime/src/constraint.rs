//! Constraints on a step: one-forms `A(q) v = 0` evaluated at a chosen point of the step, and
//! holonomic constraints `g(q) = 0` imposed exactly at `q_{k+1}`.
//!
//! With `q_c = q_k + θ (q_{k+1} − q_k)` the one-forms' discrete constraint is
//! `A(q_c)(q_{k+1} − q_k) = 0` and the constraint impulse is `A(q_c)ᵀ μ`:
//!
//! ```text
//! p_k + D1 L_d + f⁻ + σ A(q_c)ᵀ μ = 0,     p_{k+1} = D2 L_d + f⁺ − (1 − σ) A(q_c)ᵀ μ … (sign of μ free)
//! ```
//!
//! where `σ` is the share of the impulse on `p_k`'s equation. At the start and the end point
//! `σ = 1` (the seed's (+) and (−) schemes; at the end `σ = 0` would leave `μ` undetermined). At
//! the midpoint the impulse is split `σ = ½`, as the midpoint rule splits any force
//! (`f⁻ = f⁺ = (h/2) F`): the scheme is then symmetric, and for quadratic energies with constant
//! one-forms (circuits) it conserves `E(q_k, p_k)` exactly, and its balance with resistors
//! (`E_{k+1} − E_k = −h R (Δq/h)²`) holds to round-off. Holonomic constraints
//! `g(q_{k+1}) = 0` take their impulse `dg(q_k)ᵀ λ` on `p_k`'s equation (SHAKE).

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

pub use crate::constraint_point::ConstraintPoint;
use crate::derivatives::{gradient, lift};
use crate::system::DiracSystem;

/// One-form `a` at `q`: the row `A_a(q)` and its derivative `∂A_a,i/∂q_j` (row `i`, column `j`).
pub(crate) fn one_form<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    a: usize,
) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
    let row = system.one_form(&lift(q, 1.0), a);
    let value = row.map(|x| x.re);
    let derivative = SMatrix::<f64, N, N>::from_fn(|i, j| gradient(&row[i])[j]);
    (value, derivative)
}

/// Holonomic constraint `b` at `q`: `g_b(q)` and its one-form `dg_b(q)`.
pub(crate) fn holonomic<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    b: usize,
) -> (f64, SVector<f64, N>) {
    let g = system.holonomic(&lift(q, 1.0), b);
    (g.re, gradient(&g))
}

/// What the constraint rows of one step need besides the unknowns: the system, where the
/// one-forms are evaluated, the start `q_k`, and `dg_b(q_k)` (constant over the step, see
/// [`holonomic_forms`]).
pub(crate) struct StepConstraints<'a, S, const N: usize> {
    pub system: &'a S,
    pub point: ConstraintPoint,
    pub base: &'a SVector<f64, N>,
    pub holonomic_forms: &'a [SVector<f64, N>],
}

impl<S: DiracSystem<N>, const N: usize> StepConstraints<'_, S, N> {
    /// The constraint rows, appended after the `N s` Euler–Lagrange rows.
    ///
    /// `x` holds the unknowns `[Z_1..Z_s, μ (one-forms), λ (holonomic)]`. Adds the constraint
    /// forces to rows `0..N`, writes the constraint residuals, fills the matching Jacobian entries,
    /// and returns the total constraint impulse `A(q_c)ᵀ μ + dg(q_k)ᵀ λ` (what they add to
    /// `p_{k+1} − p_k`) with the size of the terms of the constraint rows.
    pub(crate) fn add(
        &self,
        x: &DVector<f64>,
        euler_lagrange_rows: usize,
        residual: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> (SVector<f64, N>, f64) {
        let Self {
            system,
            point,
            base,
            holonomic_forms,
        } = *self;
        let step_col = euler_lagrange_rows - N;
        let step = x.fixed_rows::<N>(step_col).into_owned();
        let (theta, share) = (point.theta(), point.share());
        let mut impulse = SVector::<f64, N>::zeros();
        let mut scale = 0.0_f64;
        let q_c = base + step * theta;
        for a in 0..S::ONE_FORMS {
            let (row, derivative) = one_form(system, &q_c, a);
            let col = euler_lagrange_rows + a;
            let mu = x[col];
            impulse += row * mu;
            for i in 0..N {
                residual[i] += share * mu * row[i];
                jacobian[(i, col)] += share * row[i];
                for j in 0..N {
                    jacobian[(i, step_col + j)] += share * theta * mu * derivative[(i, j)];
                }
            }
            // A_a(q_c) · Z_s and its derivative in Z_s (q_c moves with Z_s by θ).
            residual[col] = row.dot(&step);
            scale = scale.max(row.abs().dot(&step.abs()));
            let through_point = derivative.transpose() * step * theta;
            for j in 0..N {
                jacobian[(col, step_col + j)] = row[j] + through_point[j];
            }
        }
        let end = base + step;
        for (b, force_form) in holonomic_forms.iter().enumerate() {
            let col = euler_lagrange_rows + S::ONE_FORMS + b;
            let lambda = x[col];
            impulse += force_form * lambda;
            for i in 0..N {
                residual[i] += lambda * force_form[i];
                jacobian[(i, col)] += force_form[i];
            }
            let (g, form) = holonomic(system, &end, b);
            residual[col] = g;
            scale = scale.max(form.abs().dot(&end.abs()).max(g.abs()));
            for j in 0..N {
                jacobian[(col, step_col + j)] = form[j];
            }
        }
        (impulse, scale)
    }
}

/// Fills `forms[b] = dg_b(q)`: the directions of the holonomic constraint forces of a step from `q`.
pub(crate) fn holonomic_forms<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    forms: &mut [SVector<f64, N>],
) {
    for (b, form) in forms.iter_mut().enumerate() {
        *form = holonomic(system, q, b).1;
    }
}

/// The largest constraint violation of a step from `q0` to `q1`: `|A(q_c)(q1 − q0)|` over the
/// one-forms and `|g(q1)|` over the holonomic constraints.
pub(crate) fn violation<S: DiracSystem<N>, const N: usize>(
    system: &S,
    point: ConstraintPoint,
    q0: &SVector<f64, N>,
    q1: &SVector<f64, N>,
) -> f64 {
    let q_c = q0 + (q1 - q0) * point.theta();
    let forms = (0..S::ONE_FORMS).map(|a| system.one_form(&q_c, a).dot(&(q1 - q0)).abs());
    let holonomic = (0..S::HOLONOMIC).map(|b| system.holonomic(q1, b).abs());
    forms.chain(holonomic).fold(0.0, f64::max)
}
