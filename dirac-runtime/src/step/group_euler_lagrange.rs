//! The discrete Euler–Lagrange equations on a configuration space whose charts have non-affine
//! transitions: rotations and unit vectors, alone or with ordinary coordinates
//! ([`Product`](crate::space::product::Product)). With the Cayley or exponential retraction these are
//! the Lie group variational integrators of Lee, Leok and McClamroch, for any quadrature.
//!
//! A step from `(q_k, p_k)` solves, in the chart centred at `q_k` (`q = R_{q_k}(ξ)`), for the
//! step's points `ξ_1, …, ξ_s` (and the one-forms' multipliers `μ`):
//!
//! ```text
//! π_k + D1 L_d + f_0 + σ Ãᵀμ = 0,     ∂L_d/∂ξ_j + f_j = 0 (j = 1..s−1),     Ã(ξ_c) ξ_s = 0
//! ```
//!
//! where `π_k = (T_0 R)ᵀ p_k` is the momentum read in the chart (for a rotation, the body angular
//! momentum `Π_k`), `L_d(q_k, q_{k+1})` is the quadrature of `L` along the chart path, forces and
//! one-forms are pulled back into the chart as on `Rⁿ`, and `D1 L_d` is the derivative of `L_d`
//! in its first point taken through the moving chart: `∂/∂η` at `η = 0` of `L_d` in the chart
//! centred at `R_{q_k}(η)`, the other points held where they are on the manifold. That makes
//! `L_d` a function on `Q × Q` and the step symplectic, and keeps the momentum maps of the
//! model's symmetries exactly (discrete Noether: a free rigid body's spatial angular momentum, a
//! heavy top's vertical one). Then `q_{k+1} = R_{q_k}(ξ_s)` (rotations re-orthonormalised and
//! unit vectors renormalised, to round-off) and `p_{k+1}` solves
//! `(T_{ξ_s} R)ᵀ p_{k+1} = ∂L_d/∂ξ_s + f_s + (1 − σ) Ãᵀμ`: for a rotation,
//! `Π_{k+1} = dτ_{ξ_s}⁻ᵀ (∂L_d/∂ξ_s + …)`.
//!
//! The step map's derivatives `A` and `B` are read in the tangent chart (the cotangent lift of
//! the chart at each end of the step; the mathematics guide derives them) for every model but a
//! component of an interconnection. Holonomic constraints are not offered on these spaces: their differentials are
//! held as one-forms.

use nalgebra::{DMatrix, DVector, SVector};

use crate::base::error::DiracError;
use crate::base::float::exceeds;
use crate::discrete::constraint::{self, ConstraintPoint, StepConstraints};
use crate::discrete::discrete_lagrangian::DiscreteLagrangian;
use crate::discrete::group_slots;
use crate::discrete::layout::Layout;
use crate::model::derivatives::{Dual, InChart, Seed, seeded};
use crate::model::legendre;
use crate::model::system::DiracSystem;
use crate::solve::newton::{Newton, NewtonFailure};
use crate::space::configuration_space::{ConfigurationSpace, Point, StepCovectors, Tangent};
use crate::space::manifold::Manifold;
use crate::step::dense_output::{ChartPath, Sample, chart_path};
use crate::step::group_linearisation;
use crate::step::step_derivatives::StepDerivatives;
use crate::step::step_equations::{State, StepEquations, StepWork};

/// The discrete Euler–Lagrange equations of a [`DiracSystem`] on a configuration space `C` whose
/// step differentiates the discrete Lagrangian through the moving chart (see the
/// [module](self)): the [`StepEquations`] of a model on rotations and unit vectors.
///
/// ```
/// use dirac_runtime::group_euler_lagrange::GroupEulerLagrange;
/// use dirac_runtime::product::{Configuration, Product, Rates};
/// use dirac_runtime::step_equations::StepEquations;
/// use dirac_runtime::{DiracSystem, DiscreteLagrangian, Quadrature, Scalar};
///
/// /// A free rigid body, L = ½ Ωᵀ J Ω.
/// struct Body;
/// impl DiracSystem<3, Product<0, 1, 0>> for Body {
///     fn lagrangian<D: Scalar>(
///         &self,
///         _q: &Configuration<D, 0, 1, 0>,
///         v: &Rates<D, 0, 1, 0>,
///     ) -> D {
///         let w = v.rotation[0];
///         (w[0] * w[0] + w[1] * w[1] * 2.0 + w[2] * w[2] * 3.0) * 0.5
///     }
/// }
/// let discrete = DiscreteLagrangian::on_space(Body, Product::cayley(), Quadrature::midpoint(), 0.1);
/// let equations = GroupEulerLagrange::new(discrete)?;
/// assert_eq!(equations.unknowns(), 3);
/// assert_eq!(equations.unknown_name(0), "q0_x (q_{k+1})"); // variable 0 is called q0
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct GroupEulerLagrange<S, const N: usize, C: ConfigurationSpace<N>> {
    discrete: DiscreteLagrangian<S, N, C>,
    point: ConstraintPoint,
    layout: Layout,
    /// Current values of the system's inputs.
    inputs: Vec<f64>,
    /// The inputs as constant dual numbers, for the step's force evaluations (set per step).
    lifted_inputs: Vec<Dual<N>>,
    /// `p_k` read in the chart at `q_k`, for the step being solved.
    momentum: SVector<f64, N>,
    /// `ξ_1, …, ξ_s` of the point being assembled.
    increments: Vec<SVector<f64, N>>,
    /// The step's end covector at the point assembled last.
    covectors: StepCovectors<N>,
    /// The one-forms' and the junctions' impulse at the point assembled last (for their work).
    constraint_impulse: SVector<f64, N>,
    /// `covectors` lacks the discrete Lagrangian's part (an assembly without a Jacobian leaves it
    /// to `advance`).
    covectors_pending: bool,
    /// Where the force and one-form rows put their Jacobian when Newton asks for the residual
    /// alone.
    scratch: DMatrix<f64>,
    /// The junctions' impulse on the model as a component of a modular interconnection and its
    /// share on `p_k`'s equation (see [`set_coupling`](Self::set_coupling)); `None` alone.
    coupling: Option<(SVector<f64, N>, f64)>,
}

impl<S: DiracSystem<N, C::Manifold>, C: ConfigurationSpace<N>, const N: usize>
    GroupEulerLagrange<S, N, C>
{
    /// The equations of `discrete`, with the one-forms at the system's
    /// [`constraint_point`](DiracSystem::constraint_point) and every input at 0. Fails on a
    /// non-positive or non-finite step, a non-finite parameter, one-forms with a quadrature of
    /// degree above 1, or holonomic constraints (not offered on these spaces: write their
    /// differentials as one-forms).
    pub fn new(discrete: DiscreteLagrangian<S, N, C>) -> Result<Self, DiracError> {
        discrete.check()?;
        let quadrature = discrete.quadrature();
        if S::HOLONOMIC > 0 {
            return Err(DiracError::Unsupported(
                "holonomic constraints on a space of rotations or unit vectors (hold them as \
                 one-forms, their differentials)"
                    .into(),
            ));
        }
        if S::ONE_FORMS > 0 && quadrature.degree() > 1 {
            return Err(DiracError::InvalidQuadrature(format!(
                "{}: constraint one-forms on a space of rotations or unit vectors are held at \
                 one point of a degree-1 step (midpoint or trapezoid)",
                quadrature.name()
            )));
        }
        let s = quadrature.degree();
        Ok(Self {
            point: discrete.system().constraint_point(),
            layout: Layout::new(N, s, S::ONE_FORMS, 0),
            inputs: vec![0.0; S::INPUTS],
            lifted_inputs: vec![Dual::from(0.0); S::INPUTS],
            momentum: SVector::zeros(),
            increments: vec![SVector::zeros(); s],
            covectors: StepCovectors::zero(),
            constraint_impulse: SVector::zeros(),
            covectors_pending: false,
            scratch: DMatrix::zeros(0, 0),
            coupling: None,
            discrete,
        })
    }

    /// The junctions' impulse `ι = Σ_j μ_j a_j` on this component over the next step, a
    /// covector read in the chart at each end of the step: its share `σ ι` enters the rows of
    /// `p_k`'s equation (in the chart at `q_k`) and the rest the momentum `p_{k+1}` (in the chart
    /// at `q_{k+1}`). A junction's form is thus the same covector in the chart at every point
    /// (on a rotation, a fixed covector of the body angular velocity) and, as a constant form on
    /// `Rⁿ`, gives the same positions for any `σ`: the start's and the next step's shares meet
    /// in one chart. `σ` is the interconnection's.
    pub(crate) fn set_coupling(&mut self, impulse: &SVector<f64, N>, share: f64) {
        self.coupling = Some((*impulse, share));
    }

    /// The one-forms read in the chart at `q`, at `ξ = 0` (rows over the chart coordinates).
    pub(crate) fn forms(&self, q: &Point<C, N, f64>) -> DMatrix<f64> {
        self.forms_at(q)
    }

    /// `∂ℓ/∂ξ̇` and `∂²ℓ/∂ξ̇²` at `(0, ξ̇)` in the chart at `q`.
    pub(crate) fn legendre_in_chart(
        &self,
        q: &Point<C, N, f64>,
        xi_dot: &SVector<f64, N>,
    ) -> (SVector<f64, N>, nalgebra::SMatrix<f64, N, N>) {
        let l = seeded(
            &self.chart(q),
            &SVector::zeros(),
            xi_dot,
            Seed::VELOCITY,
            Seed::VELOCITY,
        );
        (l.first, l.mixed)
    }

    /// The discrete Lagrangian.
    pub fn discrete(&self) -> &DiscreteLagrangian<S, N, C> {
        &self.discrete
    }

    /// Where the constraint one-forms are evaluated on a step.
    pub fn constraint_point(&self) -> ConstraintPoint {
        self.point
    }

    /// Evaluates the one-forms at `point` of each step.
    pub fn set_constraint_point(&mut self, point: ConstraintPoint) {
        self.point = point;
    }

    /// The Lagrangian read in the chart centred at `q`.
    fn chart<'a>(&'a self, q: &'a Point<C, N, f64>) -> InChart<'a, S, C, N> {
        self.discrete.in_chart(q)
    }

    /// The one-forms read in the chart at `q`, at `ξ = 0` (rows).
    fn forms_at(&self, q: &Point<C, N, f64>) -> DMatrix<f64> {
        let (system, space) = (self.discrete.system(), self.discrete.space());
        let mut forms = DMatrix::zeros(S::ONE_FORMS, N);
        for a in 0..S::ONE_FORMS {
            let (row, _) = constraint::one_form_in_chart(system, space, q, &SVector::zeros(), a);
            forms.row_mut(a).copy_from(&row.transpose());
        }
        forms
    }

    /// The covector at `R_q(ξ)` whose pull-back to the chart at `q` is `chart`, checked finite.
    fn covector(
        &self,
        q: &Point<C, N, f64>,
        xi: &SVector<f64, N>,
        chart: SVector<f64, N>,
    ) -> Option<Tangent<C, N, f64>> {
        let p = self.discrete.space().push_covector(q, xi, &chart)?;
        finite(&<C::Manifold as Manifold<N>>::tangent_components(&p)).then_some(p)
    }

    /// The one-forms' violation `|Ã(0) ξ̇| ≤ tolerance Σ|Ã_i ξ̇_i|` at a state: an error naming
    /// the first one-form the velocity does not satisfy.
    fn check_one_forms(
        &self,
        q: &Point<C, N, f64>,
        xi_dot: &SVector<f64, N>,
        tolerance: f64,
    ) -> Result<(), DiracError> {
        let forms = self.forms_at(q);
        for a in 0..S::ONE_FORMS {
            let row = forms.row(a);
            let rate = (row * xi_dot)[0];
            let size = row.abs().dot(&xi_dot.abs().transpose());
            if exceeds(rate.abs(), tolerance * size.max(f64::MIN_POSITIVE)) {
                return Err(DiracError::InconsistentInitialState(format!(
                    "the initial velocity violates one-form {a}: A·v = {rate:.3e}"
                )));
            }
        }
        Ok(())
    }

    /// Whether the step's action is the discrete Lagrangian alone: no forces, constraints or
    /// junction impulses add to its momentum.
    fn conservative(&self) -> bool {
        !S::FORCES && S::ONE_FORMS == 0 && S::HOLONOMIC == 0 && self.coupling.is_none()
    }

    /// The name of the variable with index `variable`.
    fn variable(&self, variable: usize) -> String {
        self.discrete.system().coordinate_name(variable)
    }

    /// The velocity at `(q, p)` solved in the chart at `q` from `guess`.
    fn chart_velocity(
        &self,
        newton: &mut Newton,
        q: &Point<C, N, f64>,
        p: &Tangent<C, N, f64>,
        guess: &Tangent<C, N, f64>,
    ) -> Result<Tangent<C, N, f64>, NewtonFailure> {
        let space = self.discrete.space();
        let chart = self.chart(q);
        let zero = SVector::zeros();
        let pi = space.pull_back(q, &zero, p);
        let guess = space.chart_velocity(q, guess).unwrap_or(zero);
        let xi_dot = if S::ONE_FORMS > 0 {
            let forms = self.forms_at(q);
            legendre::constrained_velocity(&chart, newton, &zero, &pi, &forms, &guess, None)?.0
        } else {
            legendre::velocity(&chart, newton, &zero, &pi, &guess, &[])?
        };
        Ok(space.push_forward(q, &zero, &xi_dot))
    }

    /// `∂ℓ/∂ξ̇` at `(ξ, ξ̇)` in the chart at `q`.
    fn chart_momentum(
        &self,
        q: &Point<C, N, f64>,
        xi: &SVector<f64, N>,
        xi_dot: &SVector<f64, N>,
    ) -> SVector<f64, N> {
        seeded(&self.chart(q), xi, xi_dot, Seed::VELOCITY, Seed::NONE).first
    }
}

/// Whether every number is finite.
fn finite(values: &[f64]) -> bool {
    values.iter().all(|x| x.is_finite())
}

impl<S: DiracSystem<N, C::Manifold>, C: ConfigurationSpace<N>, const N: usize> StepEquations<N>
    for GroupEulerLagrange<S, N, C>
{
    type System = S;
    type Manifold = C::Manifold;

    fn system(&self) -> &S {
        self.discrete.system()
    }

    const NAME: &'static str = "the discrete Euler–Lagrange equations in the moving chart";
    const VELOCITY: &'static str = "the Legendre transform (velocity from momentum)";
    const FORCED: bool = S::FORCES;

    fn h(&self) -> f64 {
        self.discrete.h()
    }

    fn method(&self) -> String {
        self.discrete.quadrature().name()
    }

    fn unknowns(&self) -> usize {
        self.layout.len()
    }

    fn multipliers(&self) -> usize {
        S::ONE_FORMS
    }

    fn multiplier_names(&self) -> Vec<String> {
        (0..S::ONE_FORMS).map(|a| format!("mu_{a}")).collect()
    }

    fn coordinate_name(&self, i: usize) -> String {
        self.variable(i)
    }

    /// The position on the manifold (rotations orthogonal, unit vectors of unit length, to the
    /// relative `tolerance`), the velocity tangent and finite, `L` and the energy finite, the
    /// model's body-frame closed forms equal to dual numbers (on `Rᴷ × SO(3)ᴬ`), and the
    /// one-forms satisfied.
    fn check_start(&self, state: &State<N, C::Manifold>, tolerance: f64) -> Result<(), DiracError> {
        let (q, p, v) = (&state.q, &state.p, &state.velocity);
        if S::ONE_FORMS > 0 && self.point != ConstraintPoint::Midpoint && self.layout.points() > 1 {
            return Err(DiracError::InvalidQuadrature(
                "one-forms on these spaces are held on degree-1 steps only".into(),
            ));
        }
        let inconsistent = |(variable, why): (usize, String)| {
            DiracError::InconsistentInitialState(format!(
                "the initial position of {} {why}",
                self.variable(variable)
            ))
        };
        if let Some(violation) = <C::Manifold as Manifold<N>>::violation(q, tolerance) {
            return Err(inconsistent(violation));
        }
        if let Some((variable, why)) =
            <C::Manifold as Manifold<N>>::tangent_violation(q, v, tolerance)
        {
            return Err(DiracError::InconsistentInitialState(format!(
                "the initial velocity of {} {why}",
                self.variable(variable)
            )));
        }
        if let Some((variable, why)) =
            <C::Manifold as Manifold<N>>::tangent_violation(q, p, tolerance)
        {
            return Err(DiracError::InconsistentInitialState(format!(
                "the initial momentum of {} {why}",
                self.variable(variable)
            )));
        }
        let lagrangian = self.discrete.system().lagrangian(q, v);
        if !lagrangian.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the Lagrangian at the initial state (is (q0, v0) in its domain?)".into(),
                value: lagrangian,
            });
        }
        let energy = self.energy(q, p, v);
        if !energy.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the initial energy".into(),
                value: energy,
            });
        }
        let xi_dot = self
            .discrete
            .space()
            .chart_velocity(q, v)
            .ok_or_else(|| DiracError::OutsideChart("the initial velocity".into()))?;
        if self.discrete.space().group_chart().is_some() {
            group_slots::check_closed_forms(self.discrete.system(), self.discrete.space(), q, v)?;
        }
        self.check_one_forms(q, &xi_dot, tolerance)
    }

    fn charts_continue(&self, from: &Point<C, N, f64>, to: &Point<C, N, f64>) -> bool {
        self.discrete.space().charts_continue(from, to)
    }

    fn predict(
        &mut self,
        state: &State<N, C::Manifold>,
        previous: Option<&DVector<f64>>,
        x: &mut DVector<f64>,
    ) {
        let space = self.discrete.space();
        let xi_dot = || {
            space
                .chart_velocity(&state.q, &state.velocity)
                .unwrap_or_else(SVector::zeros)
        };
        self.layout.predict(previous, xi_dot, self.discrete.h(), x);
        self.momentum = space.pull_back(&state.q, &SVector::zeros(), &state.p);
        for (lifted, &u) in self.lifted_inputs.iter_mut().zip(&self.inputs) {
            *lifted = Dual::from(u);
        }
    }

    fn assemble(
        &mut self,
        state: &State<N, C::Manifold>,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
    ) -> f64 {
        for (j, z) in self.increments.iter_mut().enumerate() {
            z.copy_from(&x.fixed_rows::<N>(self.layout.point(j + 1)));
        }
        let discrete = &self.discrete;
        let (lagrangian, mut scale) = discrete.euler_lagrange(
            &state.q,
            &self.increments,
            &self.momentum,
            residual,
            jacobian.as_deref_mut(),
        );
        self.covectors_pending = lagrangian.is_none();
        let mut covectors = lagrangian.unwrap_or_else(StepCovectors::zero);
        self.constraint_impulse = SVector::zeros();
        if let Some((impulse, share)) = self.coupling {
            // The end's share is added to `p_{k+1}` in its own chart (`advance`).
            for i in 0..N {
                residual[i] += share * impulse[i];
            }
            covectors.impulse += impulse * share;
            self.constraint_impulse = impulse;
        }
        if !S::FORCES && S::ONE_FORMS == 0 {
            self.covectors = covectors;
            return scale;
        }
        if S::FORCES {
            // Forces write their derivatives as they go: without a Jacobian asked for, into
            // `scratch`. Constraint rows take none then.
            let n = x.len();
            if self.scratch.shape() != (n, n) {
                self.scratch = DMatrix::zeros(n, n);
            }
            let jacobian = match jacobian.as_deref_mut() {
                Some(jacobian) => jacobian,
                None => {
                    self.scratch.as_mut_slice().fill(0.0);
                    &mut self.scratch
                }
            };
            let (forces, size) = discrete.add_forces(
                &state.q,
                &self.increments,
                state.t,
                &self.lifted_inputs,
                residual,
                jacobian,
            );
            covectors += forces;
            scale = scale.max(size);
        }
        if S::ONE_FORMS > 0 {
            let constraints = StepConstraints {
                system: discrete.system(),
                space: discrete.space(),
                point: self.point,
                base: &state.q,
                layout: &self.layout,
                holonomic_forms: &[],
                increments: &self.increments,
                quadrature: discrete.quadrature(),
                h: discrete.h(),
            };
            let (impulse, size) = constraints.add_one_forms(x, residual, jacobian);
            self.constraint_impulse += impulse;
            covectors.impulse += impulse;
            covectors.end += impulse * (1.0 - self.point.share());
            scale = scale.max(size);
        }
        self.covectors = covectors;
        scale
    }

    /// Newton's method (a Jacobian at every iteration but the last). Simplified Newton converges
    /// linearly and from one side, and leaves a residual of the same sign step after step, which
    /// the momentum maps sum up. Measured on the free rigid body over 10⁶ steps (h = 0.01, spatial
    /// angular momentum of norm 3.1): off by 2.8e-9 with the Jacobian kept (4.8 residuals and
    /// 0.016 Jacobians per step), by 2.4e-11 when a kept Jacobian's point must also be at
    /// round-off relative to its own size (5.4 residuals, 40 % fewer instructions than Newton's
    /// method), and by 1.1e-12 with Newton's method (3 evaluations, 2 with a Jacobian).
    /// `NewtonOptions::jacobian_reuse` chooses otherwise.
    fn jacobian_cost(&self) -> f64 {
        1.0
    }

    fn advance(
        &self,
        state: &State<N, C::Manifold>,
        x: &DVector<f64>,
        step: u64,
    ) -> Result<State<N, C::Manifold>, DiracError> {
        let space = self.discrete.space();
        for j in 1..=self.layout.points() {
            let point = x.fixed_rows::<N>(self.layout.point(j)).into_owned();
            if let Some((variable, why)) = space.outside_chart(&point) {
                return Err(DiracError::OutsideChart(format!(
                    "step {step}: {} {why}",
                    self.variable(variable)
                )));
            }
        }
        let xi = x.fixed_rows::<N>(self.layout.end_point()).into_owned();
        let mut next = self.discrete.advanced(
            state,
            &xi,
            &self.increments,
            self.covectors,
            self.covectors_pending,
            self.conservative(),
            step,
        )?;
        // The end's share of the junctions' impulse, in the chart at `q_{k+1}` (none to add for
        // a component no junction pulls, or a share of 1).
        let end_share = self
            .coupling
            .map(|(impulse, share)| impulse * (1.0 - share));
        if let Some(end_share) = end_share.filter(|e| e.iter().any(|x| *x != 0.0)) {
            let zero = SVector::zeros();
            let end = space.pull_back(&next.q, &zero, &next.p) + end_share;
            next.p = self
                .covector(&next.q, &zero, end)
                .ok_or_else(|| DiracError::NonFinite {
                    what: format!("the momentum after step {step} (try a smaller step)"),
                    value: f64::NAN,
                })?;
        }
        let points = <C::Manifold as Manifold<N>>::point_components(&next.q);
        let momenta = <C::Manifold as Manifold<N>>::tangent_components(&next.p);
        if !finite(&points) || !finite(&momenta) {
            return Err(DiracError::NonFinite {
                what: format!("the state after step {step} (try a smaller step)"),
                value: f64::NAN,
            });
        }
        next.velocity = space.push_forward(&state.q, &xi, &(xi / self.discrete.h()));
        self.discrete.check_end(&next.q, &next.velocity, step)?;
        Ok(next)
    }

    fn violation(
        &self,
        from: &State<N, C::Manifold>,
        to: &State<N, C::Manifold>,
        x: &DVector<f64>,
    ) -> f64 {
        if S::ONE_FORMS == 0 {
            return 0.0;
        }
        let (space, system) = (self.discrete.space(), self.discrete.system());
        let xi = x.fixed_rows::<N>(self.layout.end_point()).into_owned();
        constraint::violation(system, space, self.point, &from.q, &to.q, &xi)
    }

    fn first_multiplier(&self) -> usize {
        self.layout.multipliers()
    }

    fn unknown_name(&self, column: usize) -> String {
        let variables: Vec<String> = (0..<C::Manifold as Manifold<N>>::VARIABLES)
            .map(|i| self.variable(i))
            .collect();
        let names = <C::Manifold as Manifold<N>>::chart_names(&variables);
        self.layout.name(column, &|i| names[i].clone())
    }

    /// `N`, plus one multiplier per one-form.
    fn velocity_unknowns(&self) -> usize {
        N + S::ONE_FORMS
    }

    /// The Legendre inversion in the chart at `q`: `∂ℓ/∂ξ̇(0, ξ̇) = π` with `π` the momentum read
    /// in the chart; with one-forms, the velocity they allow whose momentum differs from `p` by a
    /// constraint impulse (`∂ℓ/∂ξ̇ = π + Ãᵀν`, `Ã ξ̇ = 0`).
    fn velocity(
        &self,
        newton: &mut Newton,
        _t: f64,
        q: &Point<C, N, f64>,
        p: &Tangent<C, N, f64>,
        guess: &Tangent<C, N, f64>,
    ) -> Result<Tangent<C, N, f64>, NewtonFailure> {
        self.chart_velocity(newton, q, p, guess)
    }

    fn momentum(
        &self,
        q: &Point<C, N, f64>,
        v: &Tangent<C, N, f64>,
    ) -> Result<Tangent<C, N, f64>, DiracError> {
        let not_finite = |what: &str| DiracError::NonFinite {
            what: what.into(),
            value: f64::NAN,
        };
        if !finite(&<C::Manifold as Manifold<N>>::point_components(q)) {
            return Err(not_finite("initial position"));
        }
        if !finite(&<C::Manifold as Manifold<N>>::tangent_components(v)) {
            return Err(not_finite("initial velocity"));
        }
        let zero = SVector::zeros();
        let xi_dot = self
            .discrete
            .space()
            .chart_velocity(q, v)
            .ok_or_else(|| not_finite("initial velocity read in the chart"))?;
        self.covector(q, &zero, self.chart_momentum(q, &zero, &xi_dot))
            .ok_or_else(|| not_finite("initial momentum"))
    }

    /// `A` and `B` in the cotangent lifts of the charts centred at `q_k` and `q_{k+1}`:
    /// perturbations `(δ, dμ)` of `(R_{q_k}(δ), p)` with `(T_δ R_{q_k})ᵀ p = μ`. Refused with
    /// `Unsupported` for a component of an interconnection.
    fn linearise(
        &self,
        state: &State<N, C::Manifold>,
        x: &DVector<f64>,
        newton: &Newton,
    ) -> Result<StepDerivatives<N>, DiracError> {
        if self.coupling.is_some() {
            return Err(DiracError::Unsupported(
                "derivatives of the step map of one component of an interconnection".into(),
            ));
        }
        group_linearisation::linearise(
            &self.discrete,
            &self.layout,
            self.point,
            &self.inputs,
            state,
            x,
            newton,
        )
    }

    fn inputs(&self) -> &[f64] {
        &self.inputs
    }

    fn inputs_mut(&mut self) -> &mut [f64] {
        &mut self.inputs
    }

    fn input_name(&self, i: usize) -> String {
        self.discrete.system().input_name(i)
    }

    /// The forces' work along the step's path in the chart at `q_k`; the one-forms' and
    /// junctions' from their impulse on a degree-1 step (see [`StepWork`]).
    fn work(&self, state: &State<N, C::Manifold>, x: &DVector<f64>) -> Option<StepWork<N>> {
        let forces = if S::FORCES {
            self.discrete
                .force_work(&state.q, &self.increments, state.t, &self.inputs)
        } else {
            SVector::zeros()
        };
        let constraints = (self.discrete.quadrature().degree() == 1).then(|| {
            let xi = x.fixed_rows::<N>(self.layout.end_point()).into_owned();
            self.constraint_impulse.component_mul(&xi) / self.discrete.h()
        });
        Some(StepWork {
            forces,
            constraints,
        })
    }

    /// `⟨∂L/∂v, v⟩ − L(q, v)`, read in the chart at `q`.
    fn energy(&self, q: &Point<C, N, f64>, _p: &Tangent<C, N, f64>, v: &Tangent<C, N, f64>) -> f64 {
        let Some(xi_dot) = self.discrete.space().chart_velocity(q, v) else {
            return f64::NAN;
        };
        let zero = SVector::zeros();
        let l = seeded(&self.chart(q), &zero, &xi_dot, Seed::VELOCITY, Seed::NONE);
        l.first.dot(&xi_dot) - l.value
    }

    /// The path through the step's points in the chart at its start, with end slopes corrected
    /// to the end states' velocities (see [`dense_output`](crate::step::dense_output)); the momentum is
    /// `∂ℓ/∂ξ̇` along it plus the linear blend of its defects at the ends, read in that chart.
    fn dense(
        &self,
        ends: [&Sample<N, C::Manifold>; 2],
        x: &DVector<f64>,
        theta: f64,
    ) -> Option<Sample<N, C::Manifold>> {
        let [a, b] = ends;
        let space = self.discrete.space();
        let (quadrature, h) = (self.discrete.quadrature(), self.discrete.h());
        let internal =
            (1..self.layout.points()).map(|j| x.fixed_rows::<N>(self.layout.point(j)).into_owned());
        let ChartPath { xi, xi_dot, end } =
            chart_path(space, quadrature, h, ends, internal, theta)?;
        let zero = SVector::zeros();
        let start_rate = space.chart_velocity(&a.q, &a.v)?;
        let end_rate = space.chart_rate(&a.q, &end, &b.v)?;
        let defect_a =
            space.pull_back(&a.q, &zero, &a.p) - self.chart_momentum(&a.q, &zero, &start_rate);
        let defect_b =
            space.pull_back(&a.q, &end, &b.p) - self.chart_momentum(&a.q, &end, &end_rate);
        let pi =
            self.chart_momentum(&a.q, &xi, &xi_dot) + defect_a * (1.0 - theta) + defect_b * theta;
        Some(Sample {
            t: a.t + theta * h,
            q: space.retract(&a.q, &xi),
            v: space.push_forward(&a.q, &xi, &xi_dot),
            p: self.covector(&a.q, &xi, pi)?,
        })
    }
}
