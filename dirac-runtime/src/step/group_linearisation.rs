//! Derivatives of the step map on configuration spaces whose charts a motion carries (rotations,
//! unit vectors, their products with vectors, `Positive`):
//! `A = ∂(q_{k+1}, p_{k+1})/∂(q_k, p_k)` and `B = ∂(q_{k+1}, p_{k+1})/∂u` of a
//! [`GroupEulerLagrange`](crate::group_euler_lagrange::GroupEulerLagrange) step, read in the
//! tangent chart.
//!
//! **Coordinates.** Near a point `q` the state is read in the cotangent lift of the chart
//! centred at `q`: `(ζ, μ) ↦ (R_q(ζ), p)` with `(T_ζ R_q)ᵀ p = μ`. These coordinates are
//! canonical, so `A` of a conservative model is symplectic for `J = [[0, I], [−I, 0]]`; at
//! `ζ = 0`, `μ` is the momentum read in the chart (on a rotation, the body angular momentum).
//! `A` maps perturbations `(δ, dμ_k)` in the chart at `q_k` to `(ε, dμ_{k+1})` in the chart at
//! `q_{k+1}`, the chart the next step starts in, so the derivatives of consecutive steps
//! compose.
//!
//! **The moved start.** A step from `R_q(δ)` is the step from `q` in the chart carried there by
//! the motion `g(δ)`, `R_{R_q(δ)}(ζ) = g(δ) R_q(ζ)`
//! ([`carried`](crate::configuration_space::ConfigurationSpace::carried): a translation, a turn
//! on the left of a rotation, the carrier of a unit vector). On a unit vector the carried chart's
//! frame `g B` is not the frame `B(R_q(δ))` the step at `R_q(δ)` takes, but the step does not see
//! the frame: the retraction is equivariant (`R_{gq}(g w) = g R_q(w)`), and a change of frame is
//! a linear change of the chart coordinates, which commutes with the path's interpolation and
//! turns the rows as covectors. Its residual is the step's own
//! with every point and velocity of the path moved by `g(δ)`, so its derivative in `δ` comes
//! from one more seed of the dual numbers, and its unknowns `ξ'` live in the carried chart.
//! With `ξ'(ζ) = R_q⁻¹(g(δ)⁻¹ R_q(ζ))` the carried chart's coordinates of a point, the momentum
//! read there is `π' = C⁻ᵀ μ`, `C = ∂ξ'/∂ζ` at `ζ = δ` (the identity at `δ = 0`), so
//!
//! ```text
//! dπ' = dμ − P dδ,     P_ra = Σ_m π_m ∂²ξ'_m/∂ζ_r∂δ_a.
//! ```
//!
//! **The implicit function theorem.** The residual `r(δ, ξ', μ_a, π', u)` (rows
//! `π' + D1 L_d + f_0 + σ Σ_a μ_a Ã_a`, `∂L_d/∂ξ_j + f_j` for `j = 1..s−1`, and the one-forms'
//! `Ã_a · ξ'_s`, each `Ã_a` read in the carried chart at the constraint point `θ ξ'_s`) vanishes
//! along the perturbed steps, so `d(ξ', μ) = −J⁻¹ (∂r/∂δ dδ + [dπ'; 0] + ∂r/∂u du)` with
//! Newton's Jacobian `J` factorised at the root.
//!
//! **The end.** The new point is `g(δ) R_q(ξ'_s)`, read in the chart at `q_{k+1}` as
//! `ε = R_{q_{k+1}}⁻¹(g(δ) R_q(ξ'_s))`. Its momentum has the end covector
//! `E = ∂L_d/∂ξ'_s + f_s + (1 − σ) Σ_a μ_a Ã_a` as its pull-back to the carried chart, so
//! `μ_{k+1} = Zᵀ E` with `Z = ∂ξ'/∂z` at `z = 0` for `ξ'(z) = R_q⁻¹(g(δ)⁻¹ R_{q_{k+1}}(ε + z))`:
//!
//! ```text
//! dμ_{k+1} = Z₀ᵀ dE + P_δ dδ + P_ε dε,   (P_δ)_ra = Σ_m E_m ∂²ξ'_m/∂z_r∂δ_a,  likewise P_ε.
//! ```
//!
//! Every second derivative is taken by hyper-dual numbers, exact to round-off; the tests check
//! `A` and `B` against central differences through the retraction, `A`'s symplecticity, and the
//! derivatives on `Rⁿ` against the vector step's.

use nalgebra::{Const, DMatrix, DVector, SMatrix, SVector, U1};
use num_dual::{Derivative, HyperDualSVec64};

use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::discrete::constraint::carried_one_form;
use crate::discrete::discrete_lagrangian::DiscreteLagrangian;
use crate::discrete::layout::Layout;
use crate::discrete::state::State;
use crate::model::derivatives::{Dual, gradient, lift, start_blocks};
use crate::model::system::DiracSystem;
use crate::solve::newton::Newton;
use crate::space::configuration_space::{ConfigurationSpace, Point};
use crate::space::manifold::Manifold;
use crate::step::euler_lagrange::stale_factorisation;
use crate::step::step_derivatives::StepDerivatives;

/// The derivatives of the step from `state` solved by `x` (Newton's root, its Jacobian
/// factorised there) of a model without junctions, its one-forms (on a degree-1 step) held at
/// `point` (see the [module](self)).
#[allow(clippy::too_many_arguments)]
pub(crate) fn linearise<S, C, const N: usize>(
    discrete: &DiscreteLagrangian<S, N, C>,
    layout: &Layout,
    point: ConstraintPoint,
    inputs: &[f64],
    state: &State<N, C::Manifold>,
    x: &DVector<f64>,
    newton: &Newton,
) -> Result<StepDerivatives<N>, DiracError>
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    let not_carried = || {
        DiracError::Unsupported(
            "derivatives of the step map on a space whose charts no motion carries".into(),
        )
    };
    let outside =
        || DiracError::OutsideChart("the step's end, read in the chart at the new point".into());
    let (space, system) = (discrete.space(), discrete.system());
    let (quadrature, h) = (discrete.quadrature(), discrete.h());
    let s = layout.points();
    let q = &state.q;
    let points: Vec<SVector<f64, N>> = (1..=s)
        .map(|j| x.fixed_rows::<N>(layout.point(j)).into_owned())
        .collect();
    let end_point = points[s - 1];
    let mut next = state.q;
    let mut carry = state.q_carry;
    space.advance(&mut next, &mut carry, &end_point);

    let action = start_blocks(system, space, q, quadrature, h, &points).ok_or_else(not_carried)?;
    let forces = if S::FORCES {
        force_derivatives(discrete, q, &points, state.t, inputs).ok_or_else(not_carried)?
    } else {
        ForceDerivatives::none(s, inputs.len())
    };
    let (theta, share) = (point.theta(), point.share());
    let forms = one_forms(discrete, q, &(end_point * theta)).ok_or_else(not_carried)?;
    let multipliers: Vec<f64> = (0..S::ONE_FORMS).map(|a| x[layout.one_form(a)]).collect();
    let pi = space.pull_back(q, &SVector::zeros(), &state.p);
    let (_, p_in) = chart_change(space, q, q, &pi, Moved::Start).ok_or_else(outside)?;
    // The end covector takes the one-forms' impulse's share `1 − σ`.
    let mut end = action.end + forces.end;
    for (form, mu) in forms.iter().zip(&multipliers) {
        end += form.value * (mu * (1.0 - share));
    }
    let (z0, p_delta) = chart_change(space, q, &next, &end, Moved::Start).ok_or_else(outside)?;
    let (_, p_eps) = chart_change(space, q, &next, &end, Moved::Point).ok_or_else(outside)?;
    let (position_start, position_end) =
        end_position(space, q, &next, &end_point).ok_or_else(outside)?;

    // ∂r/∂z for z = (δ, μ_k, u), one column each.
    let n_in = inputs.len();
    let parameters = 2 * N + n_in;
    let mut dx = DMatrix::zeros(layout.len(), parameters);
    for j in 0..s {
        let mut block = action.start[j] + forces.start[j];
        if j == 0 {
            block -= p_in;
            for (form, mu) in forms.iter().zip(&multipliers) {
                block += form.start * (mu * share);
            }
        }
        // The rows of point j's equation sit where the unknowns of point j + 1 do.
        let row = layout.point(j + 1);
        dx.view_mut((row, 0), (N, N)).copy_from(&block);
        dx.view_mut((row, 2 * N), (N, n_in))
            .copy_from(&forces.inputs[j]);
    }
    for i in 0..N {
        dx[(i, N + i)] = 1.0;
    }
    // The one-form rows `Ã_a(θ ξ'_s) · ξ'_s` move with the start as `ξ'_sᵀ ∂Ã_a/∂δ`.
    for (a, form) in forms.iter().enumerate() {
        let row = form.start.transpose() * end_point;
        dx.view_mut((layout.one_form(a), 0), (1, N))
            .copy_from(&row.transpose());
    }
    newton
        .implicit_derivatives(x, &mut dx)
        .ok_or_else(stale_factorisation)?;

    let end_moving = action.start[s] + forces.start[s];
    let mut derivatives = StepDerivatives::<N>::zeros(n_in, newton.pivot_ratio());
    for c in 0..parameters {
        let d_end = dx.fixed_view::<N, 1>(layout.end_point(), c).into_owned();
        let mut d_position = position_end * d_end;
        let mut d_covector = SVector::<f64, N>::zeros();
        for m in 0..s {
            let d_point = dx.fixed_view::<N, 1>(layout.point(m + 1), c);
            d_covector += (action.end_blocks[m] + forces.end_blocks[m]) * d_point;
        }
        if c < N {
            d_position += position_start.column(c);
            d_covector += end_moving.column(c);
        } else if c >= 2 * N {
            d_covector += forces.inputs[s].column(c - 2 * N);
        }
        for (a, (form, mu)) in forms.iter().zip(&multipliers).enumerate() {
            let d_mu = dx[(layout.one_form(a), c)];
            let mut d_form = form.along * d_end * theta;
            if c < N {
                d_form += form.start.column(c);
            }
            d_covector += (form.value * d_mu + d_form * *mu) * (1.0 - share);
        }
        let mut d_momentum = z0.transpose() * d_covector + p_eps * d_position;
        if c < N {
            d_momentum += p_delta.column(c);
        }
        derivatives.set_column(c, &d_position, &d_momentum);
    }
    derivatives.finite()
}

/// A one-form at the step's constraint point `ξ_c` read in the carried chart: its row `Ã_a`,
/// `∂Ã_a/∂δ` and `∂Ã_a/∂ξ_c`.
struct OneForm<const N: usize> {
    value: SVector<f64, N>,
    start: SMatrix<f64, N, N>,
    along: SMatrix<f64, N, N>,
}

/// The model's one-forms at `xi_c` with their derivatives in the start and the point, by
/// first-order duals through [`carried_one_form`]; `None` where the charts are not carried.
fn one_forms<S, C, const N: usize>(
    discrete: &DiscreteLagrangian<S, N, C>,
    q: &Point<C, N, f64>,
    xi_c: &SVector<f64, N>,
) -> Option<Vec<OneForm<N>>>
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    let (system, space) = (discrete.system(), discrete.space());
    let still = SVector::from_element(Dual::from(0.0));
    (0..S::ONE_FORMS)
        .map(|a| {
            let moved = carried_one_form(
                system,
                space,
                q,
                &xi_c.map(Dual::from),
                &lift(&SVector::zeros(), 1.0),
                a,
            )?;
            let along = carried_one_form(system, space, q, &lift(xi_c, 1.0), &still, a)?;
            Some(OneForm {
                value: moved.map(|f| f.re),
                start: derivatives_of(&moved),
                along: derivatives_of(&along),
            })
        })
        .collect()
}

/// The forces' part of the derivatives: `∂f_j/∂δ` (`j = 0..=s`), `f_s`, `∂f_s/∂ξ_m`
/// (`m = 1..=s`) and `∂f_j/∂u`.
struct ForceDerivatives<const N: usize> {
    start: Vec<SMatrix<f64, N, N>>,
    end: SVector<f64, N>,
    end_blocks: Vec<SMatrix<f64, N, N>>,
    inputs: Vec<DMatrix<f64>>,
}

impl<const N: usize> ForceDerivatives<N> {
    /// A model without forces.
    fn none(s: usize, inputs: usize) -> Self {
        Self {
            start: vec![SMatrix::zeros(); s + 1],
            end: SVector::zeros(),
            end_blocks: vec![SMatrix::zeros(); s],
            inputs: vec![DMatrix::zeros(N, inputs); s + 1],
        }
    }
}

/// `e_i` as the derivative part of a dual number.
fn unit<const N: usize>(i: usize) -> SVector<f64, N> {
    SVector::from_fn(|r, _| if r == i { 1.0 } else { 0.0 })
}

/// The derivatives of dual numbers, a row each.
fn derivatives_of<const N: usize>(f: &SVector<Dual<N>, N>) -> SMatrix<f64, N, N> {
    SMatrix::from_fn(|i, j| gradient(&f[i])[j])
}

/// [`ForceDerivatives`] by first-order duals through
/// [`carried_forces`](DiscreteLagrangian::carried_forces); `None` where the charts are not
/// carried.
fn force_derivatives<S, C, const N: usize>(
    discrete: &DiscreteLagrangian<S, N, C>,
    q: &Point<C, N, f64>,
    points: &[SVector<f64, N>],
    t: f64,
    inputs: &[f64],
) -> Option<ForceDerivatives<N>>
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    let s = points.len();
    let constant: Vec<SVector<Dual<N>, N>> = points.iter().map(|x| x.map(Dual::from)).collect();
    let held: Vec<Dual<N>> = inputs.iter().map(|&u| Dual::from(u)).collect();
    let still = SVector::from_element(Dual::from(0.0));
    let moved = discrete.carried_forces(q, &constant, &lift(&SVector::zeros(), 1.0), t, &held)?;
    let mut out = ForceDerivatives::none(s, inputs.len());
    for (j, f) in moved.iter().enumerate() {
        out.start[j] = derivatives_of(f);
    }
    out.end = moved[s].map(|f| f.re);
    for m in 0..s {
        let mut varied = constant.clone();
        varied[m] = lift(&points[m], 1.0);
        let f = discrete.carried_forces(q, &varied, &still, t, &held)?;
        out.end_blocks[m] = derivatives_of(&f[s]);
    }
    for first in (0..inputs.len()).step_by(N) {
        let chunk = first..(first + N).min(inputs.len());
        let lifted: Vec<Dual<N>> = inputs
            .iter()
            .enumerate()
            .map(|(k, &u)| match chunk.contains(&k) {
                true => Dual::<N>::new(u, Derivative::some(unit(k - first))),
                false => Dual::from(u),
            })
            .collect();
        let f = discrete.carried_forces(q, &constant, &still, t, &lifted)?;
        for (j, f) in f.iter().enumerate() {
            let d = derivatives_of(f);
            for k in chunk.clone() {
                out.inputs[j].set_column(k, &d.column(k - first));
            }
        }
    }
    Some(out)
}

/// Which first argument of `ξ'(δ, ε, z)` a [`chart_change`] pass moves.
#[derive(Clone, Copy, PartialEq)]
enum Moved {
    /// The start, `δ`.
    Start,
    /// The point read in the chart at the target, `ε`.
    Point,
}

/// For `ξ'(δ, ε, z) = R_q⁻¹(g(δ)⁻¹ R_target(ε + z))`, the carried chart's coordinates of the
/// point at `ε + z` of the chart at `target`: `(Z₀, P)` with `Z₀ = ∂ξ'/∂z` and
/// `P_ra = Σ_m w_m ∂²ξ'_m/∂z_r∂x_a` for `x` the argument `moved` (`δ` or `ε`), at
/// `δ = ε = z = 0`. `None` outside the chart at `q` or where the charts are not carried.
fn chart_change<C: ConfigurationSpace<N>, const N: usize>(
    space: &C,
    q: &Point<C, N, f64>,
    target: &Point<C, N, f64>,
    w: &SVector<f64, N>,
    moved: Moved,
) -> Option<(SMatrix<f64, N, N>, SMatrix<f64, N, N>)> {
    type H<const N: usize> = HyperDualSVec64<N, N>;
    let z = SVector::<H<N>, N>::from_fn(|i, _| {
        H::<N>::new(
            0.0,
            Derivative::some(unit(i)),
            Derivative::none(),
            Derivative::none(),
        )
    });
    let x = SVector::<H<N>, N>::from_fn(|i, _| {
        let seed = Derivative::some(unit::<N>(i).transpose());
        H::<N>::new(0.0, Derivative::none(), seed, Derivative::none())
    });
    let zero = SVector::<H<N>, N>::from_element(H::<N>::from(0.0));
    let (delta, eps) = match moved {
        Moved::Start => (&x, &zero),
        Moved::Point => (&zero, &x),
    };
    let y = space.retract(target, &(eps + z));
    let (y, _) = space.carried(q, &(-delta), &y, &C::Manifold::zero())?;
    let xi = space.local_over(q, &y)?;
    let (mut z0, mut pairing) = (SMatrix::<f64, N, N>::zeros(), SMatrix::<f64, N, N>::zeros());
    for m in 0..N {
        z0.set_row(m, &xi[m].eps1.unwrap_generic(Const::<N>, U1).transpose());
        pairing += xi[m].eps1eps2.unwrap_generic(Const::<N>, Const::<N>) * w[m];
    }
    Some((z0, pairing))
}

/// `∂ε/∂δ` and `∂ε/∂ξ_s` of `ε = R_next⁻¹(g(δ) R_q(ξ_s))`, the step's end read in the chart at
/// `next`. `None` outside that chart or where the charts are not carried.
fn end_position<C: ConfigurationSpace<N>, const N: usize>(
    space: &C,
    q: &Point<C, N, f64>,
    next: &Point<C, N, f64>,
    end: &SVector<f64, N>,
) -> Option<(SMatrix<f64, N, N>, SMatrix<f64, N, N>)> {
    let read = |delta: &SVector<Dual<N>, N>, xi: &SVector<Dual<N>, N>| {
        let y = space.retract(q, xi);
        let (y, _) = space.carried(q, delta, &y, &C::Manifold::zero())?;
        space.local_over(next, &y).map(|e| derivatives_of(&e))
    };
    let still = SVector::from_element(Dual::from(0.0));
    let start = read(&lift(&SVector::zeros(), 1.0), &end.map(Dual::from))?;
    let along = read(&still, &lift(end, 1.0))?;
    Some((start, along))
}
