//! Constraints on a step: one-forms `A(q) v = 0` evaluated at a chosen point of a degree-1
//! step (at the Gauss nodes of a Galerkin step), and holonomic constraints `g(q) = 0` imposed
//! exactly at `q_{k+1}` (and at the internal points of a Galerkin step).
//!
//! In the chart centred at `q_k` (on `Rⁿ`: `ξ = q − q_k`) the one-forms read
//! `Ã(ξ) = (T_ξ R_{q_k})ᵀ A(R_{q_k}(ξ))`. With the constraint point `ξ_c = θ ξ_s` (on `Rⁿ`,
//! `q_c = q_k + θ (q_{k+1} − q_k)`) the discrete constraint is `Ã(ξ_c) ξ_s = 0` and the
//! constraint impulse is `Ã(ξ_c)ᵀ μ`:
//!
//! ```text
//! p_k + D1 L_d + f⁻ + σ Ãᵀ μ = 0,     p_{k+1} = D2 L_d + f⁺ + (1 − σ) Ãᵀ μ
//! ```
//!
//! where `σ` is the share of the impulse on `p_k`'s equation. At the start and the end point
//! `σ = 1` (the seed's (+) and (−) schemes; at the end `σ = 0` would leave `μ` undetermined). At
//! the midpoint the impulse is split `σ = ½`, as the midpoint rule splits any force
//! (`f⁻ = f⁺ = (h/2) F`): the scheme is then symmetric, and for quadratic energies with constant
//! one-forms (circuits) it conserves `E(q_k, p_k)` exactly, and its balance with resistors
//! (`E_{k+1} − E_k = −h R (Δq/h)²`) holds to round-off. Holonomic constraints
//! `g(R_{q_k}(ξ_s)) = 0` take their impulse `d(g∘R_{q_k})(0)ᵀ λ` (on `Rⁿ`, `dg(q_k)ᵀ λ`) on
//! `p_k`'s equation (SHAKE).

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

pub use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::base::scalar::Scalar;
use crate::discrete::layout::Layout;
use crate::model::derivatives::{gradient, lift};
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;
use crate::space::configuration_space::{ConfigurationSpace, Euclidean, Point, StepCovectors};
use crate::space::manifold::{Manifold, Vectors};

/// One-form `a` read in the chart centred at `base`, at `xi`: the row `Ã_a(ξ)` and its
/// derivative `∂Ã_a,i/∂ξ_j` (row `i`, column `j`), `None` for a constant one-form on a
/// translation chart (it is zero, and the step skips it).
pub(crate) fn one_form_in_chart<
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
    const N: usize,
>(
    system: &S,
    space: &C,
    base: &Point<C, N, f64>,
    xi: &SVector<f64, N>,
    a: usize,
) -> (SVector<f64, N>, Option<SMatrix<f64, N, N>>) {
    if C::TRANSLATION && system.one_form_is_constant(a) {
        // On Rⁿ the chart is a translation: a constant one-form reads the same in it.
        return (one_form_value_in_chart(system, space, base, xi, a), None);
    }
    let xi = lift(xi, 1.0);
    let row = space.pull_back(base, &xi, &system.one_form(&space.retract(base, &xi), a));
    let value = row.map(|x| x.re);
    let derivative = SMatrix::<f64, N, N>::from_fn(|i, j| gradient(&row[i])[j]);
    (value, Some(derivative))
}

/// One-form `a` read in the chart at `base` carried by `g(δ)` to `R_q(δ)`
/// ([`ConfigurationSpace::carried`]), at `xi`: the model's form at `g(δ) R_q(ξ)` paired with the
/// carried chart's coordinate directions, over any scalar (its derivatives in `δ` and `ξ` by
/// dual numbers). `None` where the space does not carry its charts.
pub(crate) fn carried_one_form<
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
    D: Scalar,
    const N: usize,
>(
    system: &S,
    space: &C,
    base: &Point<C, N, f64>,
    xi: &SVector<D, N>,
    delta: &SVector<D, N>,
    a: usize,
) -> Option<SVector<D, N>> {
    let point = space.retract(base, xi);
    let zero = <C::Manifold as Manifold<N>>::zero();
    let (moved, _) = space.carried(base, delta, &point, &zero)?;
    let form = system.one_form(&moved, a);
    let mut row = SVector::<D, N>::from_element(D::from(0.0));
    for r in 0..N {
        let e = SVector::<D, N>::from_fn(|k, _| D::from(if k == r { 1.0 } else { 0.0 }));
        let (_, direction) =
            space.carried(base, delta, &point, &space.push_forward(base, xi, &e))?;
        row[r] = <C::Manifold as Manifold<N>>::pair(&form, &direction);
    }
    Some(row)
}

/// One-form `a` read in the chart centred at `base`, at `xi`: the row `Ã_a(ξ)` alone, without
/// the dual numbers of its derivative (the same numbers as [`one_form_in_chart`]'s row).
pub(crate) fn one_form_value_in_chart<
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
    const N: usize,
>(
    system: &S,
    space: &C,
    base: &Point<C, N, f64>,
    xi: &SVector<f64, N>,
    a: usize,
) -> SVector<f64, N> {
    space.pull_back(base, xi, &system.one_form(&space.retract(base, xi), a))
}

/// Refuses constraints that are dependent at `q` (a one-form or a holonomic constraint's
/// differential that combines others: the multipliers would not be unique and the step's KKT
/// matrix singular), naming them.
pub(crate) fn check_independent<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
) -> Result<(), crate::base::error::DiracError> {
    // A form that vanishes at `q` is left to the step (it may not vanish where it is held).
    let (indices, rows): (Vec<usize>, Vec<SVector<f64, N>>) = (0..S::ONE_FORMS)
        .map(|a| one_form(system, q, a).0)
        .chain((0..S::HOLONOMIC).map(|b| holonomic(system, q, b).1))
        .enumerate()
        .filter(|(_, row)| row.amax() > 0.0)
        .unzip();
    let name = |k: usize| match k.checked_sub(S::ONE_FORMS) {
        None => system.one_form_name(k),
        Some(b) => format!("holonomic constraint {b}"),
    };
    match crate::model::interconnection::dependent_row(&rows) {
        None => Ok(()),
        Some((k, on)) => Err(crate::base::error::DiracError::InconsistentInitialState(
            format!(
                "the constraints are dependent at the initial position: {} is a combination of {} \
             (their multipliers are not unique; drop one)",
                name(indices[k]),
                on.iter()
                    .map(|&j| name(indices[j]))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// Refuses a one-form the model says is constant whose derivative at `q` is not zero
/// (`InconsistentDerivatives`, naming it): the runtime would otherwise drop that derivative.
pub(crate) fn check_constant<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
) -> Result<(), crate::base::error::DiracError> {
    for a in (0..S::ONE_FORMS).filter(|&a| system.one_form_is_constant(a)) {
        let row = system.one_form(&lift(q, 1.0), a);
        let scale = row.iter().fold(1.0f64, |m, x| m.max(x.re.abs()));
        let moved = row.iter().fold(0.0f64, |m, x| m.max(gradient(x).amax()));
        if moved > 1e-12 * scale {
            return Err(crate::base::error::DiracError::InconsistentDerivatives(
                format!(
                    "{} is said to be constant (one_form_is_constant), but its coefficients \
                 change with the position by {moved:e} per unit at the start",
                    system.one_form_name(a)
                ),
            ));
        }
    }
    Ok(())
}

/// Holonomic constraint `b` read in the chart centred at `base`, at `xi`: `g_b(R(ξ))` and its
/// gradient in `ξ`.
pub(crate) fn holonomic_in_chart<
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
    const N: usize,
>(
    system: &S,
    space: &C,
    base: &Point<C, N, f64>,
    xi: &SVector<f64, N>,
    b: usize,
) -> (f64, SVector<f64, N>) {
    let g = system.holonomic(&space.retract(base, &lift(xi, 1.0)), b);
    (g.re, gradient(&g))
}

/// One-form `a` at `q` in the model's coordinates: `A_a(q)` and `∂A_a,i/∂q_j` (`None` when
/// the one-form is constant).
pub(crate) fn one_form<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    a: usize,
) -> (SVector<f64, N>, Option<SMatrix<f64, N, N>>) {
    one_form_in_chart(system, &Euclidean, q, &SVector::zeros(), a)
}

/// Holonomic constraint `b` at `q` in the model's coordinates: `g_b(q)` and `dg_b(q)`.
pub(crate) fn holonomic<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    b: usize,
) -> (f64, SVector<f64, N>) {
    holonomic_in_chart(system, &Euclidean, q, &SVector::zeros(), b)
}

/// What the constraint rows of one step need besides the unknowns: the system and its space,
/// where the one-forms are evaluated, the start `q_k`, the layout of the unknowns, and the
/// holonomic impulse directions `d(g_b∘R_{q_k})(0)` (constant over the step, see
/// [`holonomic_forms`]).
pub(crate) struct StepConstraints<'a, S, C: ConfigurationSpace<N>, const N: usize> {
    pub system: &'a S,
    pub space: &'a C,
    pub point: ConstraintPoint,
    pub base: &'a Point<C, N, f64>,
    pub layout: &'a Layout,
    pub holonomic_forms: &'a [SVector<f64, N>],
    /// The path's points `ξ_1, …, ξ_s` of the point being assembled (read from its unknowns).
    pub increments: &'a [SVector<f64, N>],
    /// The step's quadrature and size (one-forms of a Galerkin step hold at its nodes).
    pub quadrature: &'a Quadrature,
    pub h: f64,
}

impl<S: DiracSystem<N, C::Manifold>, C: ConfigurationSpace<N>, const N: usize>
    StepConstraints<'_, S, C, N>
{
    /// The one-forms of a degree-1 step, held at its constraint point `ξ_c = θ ξ_s`: adds
    /// `σ Ã(ξ_c)ᵀμ` to the rows of `p_k`'s equation, writes the rows `Ã(ξ_c) ξ_s`, fills the
    /// matching Jacobian entries where one is asked for, and returns the impulse `Ã(ξ_c)ᵀμ` (its
    /// end point's share is `1 − σ`) with the size of the rows' terms. Closed forms on a
    /// translation chart go to [`closed_one_forms`]; by dual numbers, the one-forms are read
    /// without their derivatives where no Jacobian is asked for.
    #[inline(always)]
    pub(crate) fn add_one_forms(
        &self,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        jacobian: Option<&mut DMatrix<f64>>,
    ) -> (SVector<f64, N>, f64) {
        let Self {
            system,
            space,
            point,
            base,
            layout,
            ..
        } = *self;
        if C::TRANSLATION && S::ONE_FORM_DERIVATIVES {
            // On a translation chart a closed form is the chart's.
            // A degree-1 step: the end point's increment leads the unknowns, the multipliers
            // follow it.
            debug_assert!(layout.end_point() == 0 && layout.one_form(0) == N);
            return closed_one_forms(
                system,
                space,
                base,
                point,
                x.as_slice(),
                residual.as_mut_slice(),
                jacobian.map(|j| j.as_mut_slice()),
            );
        }
        // A degree-1 step: the end point's increment leads the unknowns, the multipliers follow.
        debug_assert!(layout.end_point() == 0 && layout.one_form(0) == N);
        let (x, residual) = (x.as_slice(), residual.as_mut_slice());
        let mut jacobian = jacobian.map(|j| j.as_mut_slice());
        let n = x.len();
        let step = SVector::<f64, N>::from_fn(|i, _| x[i]);
        let (theta, share) = (point.theta(), point.share());
        let mut impulse = SVector::<f64, N>::zeros();
        let mut scale = 0.0_f64;
        let xi_c = step * theta;
        for a in 0..S::ONE_FORMS {
            let (row, derivative) = if jacobian.is_some() {
                one_form_in_chart(system, space, base, &xi_c, a)
            } else {
                (one_form_value_in_chart(system, space, base, &xi_c, a), None)
            };
            let mu = x[N + a];
            let turning = jacobian.as_deref_mut().map(|jacobian| {
                let Some(derivative) = derivative else {
                    return (jacobian, row);
                };
                let weight = share * theta * mu;
                for j in 0..N {
                    for i in 0..N {
                        jacobian[j * n + i] += derivative[(i, j)] * weight;
                    }
                }
                (jacobian, row + derivative.transpose() * step * theta)
            });
            let size = add_one_form_row(
                &row,
                &step,
                mu,
                share,
                N + a,
                residual,
                &mut impulse,
                turning,
            );
            scale = scale.max(size);
        }
        (impulse, scale)
    }
}

/// The one-forms of a degree-1 step on a translation chart (`Rⁿ`) from their closed forms
/// ([`DiracSystem::one_form_with_derivative`]), held at `q_c = q_k + θ ξ_s`: adds `σ A(q_c)ᵀμ`
/// to the rows `0..N`, writes the rows `A(q_c) ξ_s`, and where a Jacobian is asked for (`n × n`
/// by columns, `n = x.len()`) adds `σ θ Σ_a μ_a ∂A_a/∂q` to the block of `ξ_s` over the entries
/// the closed form gives, `σ A_aᵀ` to the column of `μ_a` and writes the row of `μ_a`'s
/// constraint, `A_a + θ ξ_sᵀ ∂A_a/∂q`. The unknowns are a degree-1 step's: `ξ_s` in `0..N`, then
/// `μ`. Returns the impulse `A(q_c)ᵀμ` with the size of the rows' terms. On slices: their own
/// indices, without a check each.
#[inline(always)]
pub(crate) fn closed_one_forms<
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
    const N: usize,
>(
    system: &S,
    space: &C,
    base: &Point<C, N, f64>,
    point: ConstraintPoint,
    x: &[f64],
    residual: &mut [f64],
    mut jacobian: Option<&mut [f64]>,
) -> (SVector<f64, N>, f64) {
    let n = x.len();
    let step = SVector::<f64, N>::from_fn(|i, _| x[i]);
    let (theta, share) = (point.theta(), point.share());
    debug_assert!(C::TRANSLATION && S::ONE_FORM_DERIVATIVES);
    let xi_c = step * theta;
    let q_c = space.retract(base, &xi_c);
    let mut impulse = SVector::<f64, N>::zeros();
    let mut scale = 0.0_f64;
    for a in 0..S::ONE_FORMS {
        let col = N + a;
        let mu = x[col];
        let weight = share * theta * mu;
        // Σ_i ξ_s,i ∂A_i/∂q_j over the closed form's entries.
        let mut sum = SVector::<f64, N>::zeros();
        // One call whether or not a Jacobian is asked for: in two branches the compiler would
        // hoist the row's `sin` above them and part it from its `cos`.
        let row = system.one_form_with_derivative(&q_c, a, |i, j, d| {
            if let Some(jacobian) = jacobian.as_deref_mut() {
                jacobian[j * n + i] += d * weight;
                sum[j] += d * step[i];
            }
        });
        // The chart's row (the model's, on a translation chart).
        let row = space.pull_back(base, &xi_c, &row);
        // `∂(A ξ_s)/∂ξ_s = A + θ ξ_sᵀ ∂A`, over the closed form's entries.
        let turning = jacobian.as_deref_mut().map(|j| (j, row + sum * theta));
        let size = add_one_form_row(&row, &step, mu, share, col, residual, &mut impulse, turning);
        scale = scale.max(size);
    }
    (impulse, scale)
}

/// One-form row `row` (in the chart, at the constraint point) of a degree-1 step whose end
/// point's increment `step` leads the unknowns, its multiplier `μ` in column `col`: adds `σ μ row`
/// to the rows `0..N` and `μ row` to `impulse`, writes the constraint row `row · ξ_s`, and where a
/// Jacobian is given (`n × n` by columns, `n = residual.len()`) adds `σ row` to the column of `μ`
/// and writes the constraint row's derivative in `ξ_s`, `turning`, into row `col`. Returns the
/// size of the row's terms.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn add_one_form_row<const N: usize>(
    row: &SVector<f64, N>,
    step: &SVector<f64, N>,
    mu: f64,
    share: f64,
    col: usize,
    residual: &mut [f64],
    impulse: &mut SVector<f64, N>,
    turning: Option<(&mut [f64], SVector<f64, N>)>,
) -> f64 {
    let n = residual.len();
    for i in 0..N {
        impulse[i] += row[i] * mu;
        residual[i] += share * mu * row[i];
    }
    // The same sums as nalgebra's `dot`, in its order.
    residual[col] = row.dot(step);
    if let Some((jacobian, turning)) = turning {
        for i in 0..N {
            jacobian[col * n + i] += row[i] * share;
            jacobian[i * n + col] = turning[i];
        }
    }
    row.abs().dot(&step.abs())
}

impl<S: DiracSystem<N>, C: ConfigurationSpace<N, Manifold = Vectors>, const N: usize>
    StepConstraints<'_, S, C, N>
{
    /// Adds the constraint forces to the rows of `p_k`'s equation, writes the constraint rows,
    /// fills the matching Jacobian entries where one is asked for, and returns the constraint
    /// impulses (total, and the share on the end point) with the size of the terms of the
    /// constraint rows.
    #[inline(always)]
    pub(crate) fn add(
        &self,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
    ) -> (StepCovectors<N>, f64) {
        let Self {
            system,
            space,
            point,
            base,
            layout,
            holonomic_forms,
            ..
        } = *self;
        let share = point.share();
        if S::HOLONOMIC == 0 && layout.points() == 1 {
            // One-forms alone on a degree-1 step.
            let (impulse, scale) = self.add_one_forms(x, residual, jacobian);
            let end = impulse * (1.0 - share);
            return (StepCovectors { impulse, end }, scale);
        }
        let step_col = layout.end_point();
        let step = x.fixed_rows::<N>(step_col).into_owned();
        let (mut impulse, mut scale) = if layout.points() == 1 {
            self.add_one_forms(x, residual, jacobian.as_deref_mut())
        } else {
            (SVector::zeros(), 0.0)
        };
        let mut end = impulse * (1.0 - share);
        if layout.points() > 1 && S::ONE_FORMS > 0 {
            let (forces, size) = self.add_at_nodes(x, residual, jacobian.as_deref_mut());
            impulse += forces.impulse;
            end += forces.end;
            scale = scale.max(size);
        }
        for (b, force_form) in holonomic_forms.iter().enumerate() {
            let col = layout.holonomic(b);
            let lambda = x[col];
            impulse += force_form * lambda;
            for i in 0..N {
                residual[i] += lambda * force_form[i];
            }
            if let Some(jacobian) = jacobian.as_deref_mut() {
                for i in 0..N {
                    jacobian[(i, col)] += force_form[i];
                }
            }
            let (g, form) = holonomic_in_chart(system, space, base, &step, b);
            residual[col] = g;
            // Round-off of g at q_{k+1}: |dg(q_{k+1})| |q_{k+1}| in the model's coordinates.
            let end_point = space.retract(base, &step);
            let model_form = if C::TRANSLATION {
                form
            } else {
                holonomic(system, &end_point, b).1
            };
            scale = scale.max(model_form.abs().dot(&end_point.abs()).max(g.abs()));
            if let Some(jacobian) = jacobian.as_deref_mut() {
                for j in 0..N {
                    jacobian[(col, step_col + j)] = form[j];
                }
            }
        }
        if layout.points() > 1 {
            let (more, size) = self.add_internal(x, residual, jacobian);
            impulse += more;
            scale = scale.max(size);
        }
        (StepCovectors { impulse, end }, scale)
    }

    /// The one-forms of a Galerkin step (Gauss rule, `s` nodes, on a translation chart): the
    /// velocity constraints `A_a(Q_i) Q̇_i = 0` at the nodes `Q_i = Q(c_i)`, with the constraint
    /// force `Σ_a μ_{i,a} A_a(Q_i)` at node `i` entering the rows as a force does (Lagrange–
    /// d'Alembert by the quadrature): row `j` gets `h Σ_i b_i ℓ_j(c_i) Σ_a μ_{i,a} A_a(Q_i)`.
    /// For one node this is the midpoint constraint point. Returns the impulses (total, on the
    /// end point) and the size of the constraint rows' terms.
    fn add_at_nodes(
        &self,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
    ) -> (StepCovectors<N>, f64) {
        let (system, layout, base, quad, h) =
            (self.system, self.layout, self.base, self.quadrature, self.h);
        let s = layout.points();
        let mut impulse = SVector::<f64, N>::zeros();
        let mut end = SVector::<f64, N>::zeros();
        let mut scale = 0.0_f64;
        let increments = self.increments;
        for (i, &b) in quad.weights().iter().enumerate() {
            let (xi, xi_dot) = quad.path_at(i, increments, h);
            let node = base + xi;
            for a in 0..S::ONE_FORMS {
                let (row, derivative) = one_form(system, &node, a);
                let col = layout.one_form_at(i, a);
                let mu = x[col];
                let w = h * b;
                impulse += row * (w * mu);
                end += row * (w * mu * quad.ell(i, s));
                for j in 0..s {
                    let lj = w * quad.ell(i, j);
                    for r in 0..N {
                        residual[j * N + r] += lj * mu * row[r];
                        let Some(jacobian) = jacobian.as_deref_mut() else {
                            continue;
                        };
                        jacobian[(j * N + r, col)] += lj * row[r];
                        let Some(derivative) = &derivative else {
                            continue;
                        };
                        for k in 1..=s {
                            for m in 0..N {
                                jacobian[(j * N + r, layout.point(k) + m)] +=
                                    lj * mu * derivative[(r, m)] * quad.ell(i, k);
                            }
                        }
                    }
                }
                // A_a(Q_i) · Q̇_i, scaled by h to read as a displacement.
                residual[col] = h * row.dot(&xi_dot);
                scale = scale.max(h * row.abs().dot(&xi_dot.abs()));
                let Some(jacobian) = jacobian.as_deref_mut() else {
                    continue;
                };
                let turning = derivative.map_or_else(SVector::zeros, |d| d.transpose() * xi_dot);
                for k in 1..=s {
                    for m in 0..N {
                        jacobian[(col, layout.point(k) + m)] =
                            h * turning[m] * quad.ell(i, k) + row[m] * quad.ell_prime(i, k);
                    }
                }
            }
        }
        (StepCovectors { impulse, end }, scale)
    }

    /// The holonomic constraints at the internal points `Q_j = q_k + ξ_j` (`j = 1..s−1`, on a
    /// translation chart): `g_b(Q_j) = 0`, with the impulse `dg_b(Q_j)ᵀλ_{j,b}` on the row of
    /// `Q_j`. Returns the impulses' sum and the size of the constraint rows' terms.
    fn add_internal(
        &self,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
    ) -> (SVector<f64, N>, f64) {
        let (system, layout, base) = (self.system, self.layout, self.base);
        let mut impulse = SVector::<f64, N>::zeros();
        let mut scale = 0.0_f64;
        for j in 1..layout.points() {
            // The unknown ξ_j and the Euler–Lagrange row of Q_j (row blocks are j = 0..s−1).
            let (column, row) = (layout.point(j), j * N);
            let point = base + x.fixed_rows::<N>(column);
            for b in 0..S::HOLONOMIC {
                let col = layout.holonomic_at(j, b);
                let lambda = x[col];
                let (g, form) = holonomic(system, &point, b);
                impulse += form * lambda;
                for i in 0..N {
                    residual[row + i] += lambda * form[i];
                }
                if let Some(jacobian) = jacobian.as_deref_mut() {
                    let curvature = crate::model::derivatives::holonomic_hessian(system, &point, b);
                    for i in 0..N {
                        jacobian[(row + i, col)] += form[i];
                        for m in 0..N {
                            jacobian[(row + i, column + m)] += lambda * curvature[(i, m)];
                        }
                        jacobian[(col, column + i)] = form[i];
                    }
                }
                residual[col] = g;
                scale = scale.max(form.abs().dot(&point.abs()).max(g.abs()));
            }
        }
        (impulse, scale)
    }
}

/// Refuses holonomic constraints with a path of degree above 2: held at the path's points they
/// give order 4 at every degree above 1 (measured on the Cartesian pendulum: 3.99 for degree 3
/// with Gauss or Lobatto rules), not `2s`.
pub(crate) fn check_holonomic_degree(
    holonomic: usize,
    quadrature: &Quadrature,
) -> Result<(), DiracError> {
    if holonomic > 0 && quadrature.degree() > 2 {
        return Err(DiracError::InvalidQuadrature(format!(
            "{}: with holonomic constraints held at the path's points the step is of order 4 \
             for every degree above 1 (measured on the Cartesian pendulum, 3.99 for degree 3 \
             with Gauss or Lobatto rules), not 2s; use degree 2 (order 4)",
            quadrature.name()
        )));
    }
    Ok(())
}

/// Fills `forms[b] = d(g_b∘R_q)(0)`: the directions of the holonomic constraint impulses of a
/// step from `q`, in the chart at `q`.
pub(crate) fn holonomic_forms<
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
    const N: usize,
>(
    system: &S,
    space: &C,
    q: &Point<C, N, f64>,
    forms: &mut [SVector<f64, N>],
) {
    for (b, form) in forms.iter_mut().enumerate() {
        *form = holonomic_in_chart(system, space, q, &SVector::zeros(), b).1;
    }
}

/// The largest constraint violation of the step from `q0` to the stored `q1`: `|Ã(ξ_c) ξ|` over
/// the one-forms (on `Rⁿ`, `|A(q_c)(q1 − q0)|`) and `|g(q1)|` over the holonomic constraints,
/// with `ξ` read back from the stored points as a user reading the trajectory would (the step's
/// own `solved` increment where the chart does not reach `q1`).
pub(crate) fn violation<
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
    const N: usize,
>(
    system: &S,
    space: &C,
    point: ConstraintPoint,
    q0: &Point<C, N, f64>,
    q1: &Point<C, N, f64>,
    solved: &SVector<f64, N>,
) -> f64 {
    let xi = &space.local(q0, q1).unwrap_or(*solved);
    let xi_c = xi * point.theta();
    let forms = (0..S::ONE_FORMS).map(|a| {
        let row = space.pull_back(q0, &xi_c, &system.one_form(&space.retract(q0, &xi_c), a));
        row.dot(xi).abs()
    });
    let holonomic = (0..S::HOLONOMIC).map(|b| system.holonomic(q1, b).abs());
    forms.chain(holonomic).fold(0.0, f64::max)
}

/// The largest violation of the one-forms at the nodes of a Galerkin step from `base` with points
/// `increments` (`|A_a(Q_i) Q̇_i| h`, a displacement like the degree-1 step's `|A(q_c) ξ|`),
/// with that of the holonomic constraints at its end.
pub(crate) fn node_violation<S: DiracSystem<N>, const N: usize>(
    system: &S,
    quadrature: &Quadrature,
    h: f64,
    base: &SVector<f64, N>,
    increments: &[SVector<f64, N>],
) -> f64 {
    let mut worst = 0.0_f64;
    for i in 0..quadrature.nodes().len() {
        let (xi, xi_dot) = quadrature.path_at(i, increments, h);
        let node = base + xi;
        for a in 0..S::ONE_FORMS {
            worst = worst.max((system.one_form(&node, a).dot(&xi_dot) * h).abs());
        }
    }
    let end = base + increments[increments.len() - 1];
    (0..S::HOLONOMIC).fold(worst, |w, b| w.max(system.holonomic(&end, b).abs()))
}
