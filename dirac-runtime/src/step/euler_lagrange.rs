//! The discrete Euler–Lagrange equations of one step: with forces, the discrete
//! Lagrange–d'Alembert equations; with constraint one-forms, the discrete
//! Lagrange–d'Alembert–Pontryagin equations. In the chart centred at `q_k`, in position–momentum
//! form,
//!
//! ```text
//! π_k + ∂L_d/∂ξ_0 + f_0 + σ Ãᵀμ + dg̃ᵀλ = 0     (π_k = p_k read in the chart)
//!       ∂L_d/∂ξ_j + f_j                  = 0     (internal points, j = 1..s−1)
//!       Ã(ξ_c) ξ_s = 0,   g(R(ξ_s)) = 0          (one-forms, holonomic constraints)
//! ```
//!
//! solved for `x = [ξ_1, …, ξ_s, μ, λ]` (the `layout` module; a Galerkin step also holds the
//! one-forms at its Gauss nodes and the holonomic constraints at its internal points, see
//! [`EulerLagrange::new`]); then `q_{k+1} = R_{q_k}(ξ_s)` and the
//! momentum advances by the configuration space from the step's covectors (on `Rⁿ`,
//! `p_{k+1} = p_k + Σ_j (∂L_d/∂ξ_j + f_j) + Ãᵀμ + dg̃ᵀλ`, which equals
//! `D_2 L_d + f_s + (1 − σ) Ãᵀμ` at the solution without its cancellation).

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

use crate::base::error::DiracError;
use crate::base::first_order_scheme::FirstOrderScheme;
use crate::base::float::{exceeds, largest};
use crate::base::holonomic_scheme::HolonomicScheme;
use crate::discrete::constraint::{self, ConstraintPoint, StepConstraints};
use crate::discrete::discrete_lagrangian::{DiscreteLagrangian, SlotBlocks};
use crate::discrete::first_order;
use crate::discrete::hidden_constraint::HiddenConstraints;
use crate::discrete::initial_state;
use crate::discrete::layout::Layout;
use crate::model::derivatives::{self, Dual, Seed, seeded};
use crate::model::legendre;
use crate::model::system::DiracSystem;
use crate::quadrature::MAX_DEGREE;
use crate::solve::jacobian::{Dense, Jacobian};
use crate::solve::newton::NewtonOptions;
use crate::solve::newton::{Newton, NewtonFailure, NewtonReport};
use crate::space::configuration_space::{ConfigurationSpace, StepCovectors, compensated_add};
use crate::space::manifold::Vectors;
use crate::step::affine_step::{self, AffineStep};
use crate::step::dense_output::{ChartPath, Sample, chart_path};
use crate::step::fixed_point::{self, FixedPoint, Settled};
use crate::step::step_derivatives::{StepDerivatives, StepHessians};
use crate::step::step_equations::{State, StepEquations, StepWork};
use crate::step::verlet::Kinetic;

/// The discrete Euler–Lagrange equations of a [`DiracSystem`] under a quadrature, on the
/// configuration space `C`, with the system's forces, inputs and constraints: the
/// [`StepEquations`] of a Lagrangian model.
///
/// ```
/// use dirac_runtime::euler_lagrange::EulerLagrange;
/// use dirac_runtime::step_equations::StepEquations;
/// use dirac_runtime::{DiracSystem, DiscreteLagrangian, Quadrature, Scalar};
/// use nalgebra::SVector;
/// struct Oscillator;
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
/// }
/// // Galerkin with 3 points per step: two internal points and q_{k+1}, one coordinate each.
/// let discrete = DiscreteLagrangian::new(Oscillator, Quadrature::galerkin(3)?, 0.1);
/// let equations = EulerLagrange::new(discrete)?;
/// assert_eq!(equations.unknowns(), 3);
/// assert_eq!(equations.unknown_name(2), "q0 (q_{k+1})");
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct EulerLagrange<S, const N: usize, C> {
    discrete: DiscreteLagrangian<S, N, C>,
    point: ConstraintPoint,
    holonomic_scheme: HolonomicScheme,
    /// The hidden constraints of the run (found when it begins; `None` before a run).
    hidden: Option<HiddenConstraints>,
    /// The coordinates whose Euler–Lagrange rows are collocated at the Gauss nodes (found when
    /// a run begins, see [`first_order`]): every coordinate of a Lagrangian linear in every
    /// velocity, the coordinates without kinetic energy of an unconstrained Lagrangian linear
    /// in some velocities and quadratic in others, none otherwise.
    collocated: Vec<usize>,
    first_order_scheme: FirstOrderScheme,
    /// The run's Lagrangian has closed-form second derivatives
    /// ([`DiracSystem::lagrangian_hessian`]; found when a run begins).
    closed_form: bool,
    /// The run's steps are of degree 1 on a translation chart, `L` has closed-form derivatives,
    /// and nothing but constraints and a coupling joins its rows (no forces, collocated rows or
    /// projection): [`DiscreteLagrangian::pair_in_closed_form`] assembles them directly.
    closed_pair: bool,
    layout: Layout,
    /// Current values of the system's inputs.
    inputs: Vec<f64>,
    /// The inputs as constant dual numbers, for the step's force evaluations (set per step).
    lifted_inputs: Vec<Dual<N>>,
    /// `p_k` read in the chart at `q_k`, for the step being solved.
    momentum: SVector<f64, N>,
    /// The holonomic impulse directions of the step being solved (constant over the step).
    holonomic_forms: Vec<SVector<f64, N>>,
    /// `ξ_1, …, ξ_s` of the point being assembled.
    increments: Vec<SVector<f64, N>>,
    /// The step's covectors at the point assembled last.
    covectors: StepCovectors<N>,
    /// The constraint and coupling impulse in `covectors` (its part `μ̃` from the multipliers
    /// and the junctions), for the constraints' work.
    constraint_impulse: SVector<f64, N>,
    /// `covectors` lacks the discrete Lagrangian's part, which `advance` then computes (an
    /// assembly without a Jacobian leaves it out where the residual does not need it).
    covectors_pending: bool,
    /// Where the rows other than the discrete Euler–Lagrange ones put their Jacobian when Newton
    /// asks for the residual alone (their derivatives are first-order and cheap).
    scratch: DMatrix<f64>,
    /// The impulse of the junctions on a component of a modular interconnection (see
    /// [`set_coupling`](Self::set_coupling)), `None` for a model stepped on its own.
    coupling: Option<(SVector<f64, N>, f64)>,
    /// The run's step map, where its equations are linear with constant coefficients and it has
    /// been read off (see [`affine_step`](crate::step::affine_step)); `None` before the first
    /// step of a run.
    /// (Boxed: a step takes it out and puts it back, moving a pointer.)
    affine: Option<Box<AffineStep>>,
    /// Why a reading of the run's step map failed (every later step of the run fails so).
    affine_refused: Option<String>,
    /// The run's fixed-point iteration (see [`fixed_point`](crate::step::fixed_point)), set up
    /// at its first step; `None` before.
    iteration: Option<FixedPoint<N>>,
    /// Why the run's steps cannot be iterated (a mass matrix that is not constant or not
    /// invertible): its first step is handed over, and every step is then Newton's.
    iteration_refused: Option<String>,
    /// The residual of a solution found by iteration, checked before it is taken.
    iterated_residual: DVector<f64>,
}

impl<S: DiracSystem<N>, C: ConfigurationSpace<N, Manifold = Vectors>, const N: usize>
    EulerLagrange<S, N, C>
{
    /// The equations of `discrete`, with the constraint one-forms evaluated at the system's
    /// [`constraint_point`](DiracSystem::constraint_point) and every input at 0. Fails on a
    /// non-positive or non-finite step, a non-finite parameter, constraint one-forms with a
    /// Galerkin quadrature other than a Gauss rule with as many nodes as its degree (they are
    /// held at its nodes: `A(Q(c_i)) Q̇(c_i) = 0`, the force `A(Q(c_i))ᵀμ_i` entering the rows
    /// as a force does, so that `mu_a_node_i` are forces where a degree-1 step's `mu_a` are
    /// impulses), or holonomic constraints with a quadrature of degree above 2: they are held at
    /// every point of the step's path (`g(Q_j) = 0` with an impulse `dg(Q_j)ᵀλ_j` on the row of
    /// each internal point), which gives order 4 at degree 2 and still 4 above it.
    pub fn new(discrete: DiscreteLagrangian<S, N, C>) -> Result<Self, DiracError> {
        discrete.check()?;
        let quadrature = discrete.quadrature();
        if S::ONE_FORMS > 0
            && quadrature.degree() > 1
            && (quadrature.nodes().len() != quadrature.degree() || !C::TRANSLATION)
        {
            return Err(DiracError::InvalidQuadrature(format!(
                "{}: constraint one-forms of a Galerkin step are held at the nodes of a Gauss \
                 rule with as many nodes as the path's degree (galerkin(s) with \
                 gauss_legendre(s)), on Rⁿ",
                quadrature.name()
            )));
        }
        if S::HOLONOMIC > 0 && quadrature.degree() > 1 && !C::TRANSLATION {
            return Err(DiracError::InvalidQuadrature(format!(
                "{} has internal points: holonomic constraints at internal points are held on \
                 Rⁿ only",
                quadrature.name()
            )));
        }
        constraint::check_holonomic_degree(S::HOLONOMIC, quadrature)?;
        let s = quadrature.degree();
        let point = discrete.system().constraint_point();
        Ok(Self {
            point,
            holonomic_scheme: HolonomicScheme::default(),
            hidden: None,
            collocated: Vec::new(),
            first_order_scheme: FirstOrderScheme::default(),
            closed_form: false,
            closed_pair: false,
            layout: Layout::new(N, s, S::ONE_FORMS, S::HOLONOMIC),
            inputs: vec![0.0; S::INPUTS],
            lifted_inputs: vec![Dual::from(0.0); S::INPUTS],
            momentum: SVector::zeros(),
            holonomic_forms: vec![SVector::zeros(); S::HOLONOMIC],
            increments: vec![SVector::zeros(); s],
            covectors: StepCovectors::zero(),
            constraint_impulse: SVector::zeros(),
            covectors_pending: false,
            scratch: DMatrix::zeros(0, 0),
            coupling: None,
            affine: None,
            affine_refused: None,
            iteration: None,
            iteration_refused: None,
            iterated_residual: DVector::zeros(0),
            discrete,
        })
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
        self.forget_step_map();
    }

    /// What a step does with the momentum of a model with holonomic constraints.
    pub fn holonomic_scheme(&self) -> HolonomicScheme {
        self.holonomic_scheme
    }

    /// Sets what a step does with the momentum of a model with holonomic constraints.
    pub fn set_holonomic_scheme(&mut self, scheme: HolonomicScheme) {
        self.holonomic_scheme = scheme;
        self.forget_step_map();
    }

    /// Which step a Lagrangian linear in the velocities is advanced by.
    pub fn first_order_scheme(&self) -> FirstOrderScheme {
        self.first_order_scheme
    }

    /// Sets which step a Lagrangian linear in the velocities is advanced by (taken up when a
    /// run begins).
    pub fn set_first_order_scheme(&mut self, scheme: FirstOrderScheme) {
        self.first_order_scheme = scheme;
        self.forget_step_map();
    }

    /// Forgets the run's step map and fixed-point tables: the next step sets them up again.
    fn forget_step_map(&mut self) {
        self.affine = None;
        self.affine_refused = None;
        self.iteration = None;
        self.iteration_refused = None;
    }

    /// Whether the run's steps are projected onto `p = ϑ(q)` by the multipliers at the end of
    /// the unknowns.
    fn projected(&self) -> bool {
        self.layout.len() > self.layout.projection()
    }

    /// The step's increment `ξ_s` of the end point solved by `x` (projected onto `p = ϑ(q)`
    /// where the run's steps are).
    #[inline(always)]
    fn end_increment(&self, x: &DVector<f64>) -> SVector<f64, N> {
        let xi = x.fixed_rows::<N>(self.layout.end_point()).into_owned();
        if !self.projected() {
            return xi;
        }
        let shift = x.fixed_rows::<N>(self.layout.projection()).into_owned();
        first_order::projected_increment(self.discrete.quadrature(), &xi, &shift)
    }

    /// Whether the run's Lagrangian is linear in every velocity.
    fn first_order(&self) -> bool {
        N > 0 && self.collocated.len() == N
    }

    /// The coordinates whose rows a run from `(q, v)` collocates (see `collocated`), given the
    /// degenerate coordinates `hidden` found there.
    fn collocated_rows(
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        hidden: &HiddenConstraints,
    ) -> Vec<usize> {
        if first_order::is_first_order(system, q, v) {
            (0..N).collect()
        } else if !Self::constrained()
            && hidden.count() == 0
            && hidden.dynamic() > 0
            && Self::turning(system, q, v, hidden.coordinates()).is_some()
        {
            hidden.coordinates().to_vec()
        } else {
            // Where every degenerate momentum ϑ_d is constant, the variational step's rows of
            // those coordinates already are a Gauss method's (their ℓ' terms telescope).
            Vec::new()
        }
    }

    /// A coordinate among `coordinates` (without kinetic energy) whose momentum `ϑ_d = ∂L/∂v_d`
    /// depends on the position, probed at `(q, v)` and at a point moved off `q` by uneven
    /// amounts (a dependence can vanish at one point).
    pub(crate) fn turning(
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        coordinates: &[usize],
    ) -> Option<usize> {
        let moved = SVector::<f64, N>::from_fn(|i, _| {
            q[i] + 0.0137 * (1.0 + 0.1 * i as f64) * (1.0 + q[i].abs())
        });
        [*q, moved].iter().find_map(|point| {
            let turning = seeded(system, point, v, Seed::POSITION, Seed::VELOCITY).mixed;
            if !turning.iter().all(|x| x.is_finite()) {
                return None;
            }
            coordinates
                .iter()
                .copied()
                .find(|&d| turning.column(d).iter().any(|x| *x != 0.0))
        })
    }

    /// Sets every input, in the order of the system's inputs; fails on the wrong number of
    /// values or a value that is not finite, and then changes nothing.
    pub fn set_inputs(&mut self, values: &[f64]) -> Result<(), DiracError> {
        if values.len() != S::INPUTS {
            return Err(DiracError::UnknownInput(format!(
                "the system has {} input(s), got {} value(s)",
                S::INPUTS,
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(DiracError::NonFinite {
                what: format!("input {}", self.discrete.system().input_name(i)),
                value: values[i],
            });
        }
        self.inputs.copy_from_slice(values);
        Ok(())
    }

    /// What a run takes up at its start besides the degenerate coordinates: closed forms and
    /// the first-order scheme.
    fn begin_run(&mut self, state: &State<N>) {
        self.forget_step_map();
        let system = self.discrete.system();
        // Closed forms serve only a translation chart (elsewhere `L` is read in the chart).
        self.closed_form = C::TRANSLATION
            && system
                .lagrangian_hessian(&state.q, &state.velocity)
                .is_some();
        // The scheme is taken up here, at the start of a run: the unknowns follow it.
        let projected =
            self.first_order() && self.first_order_scheme == FirstOrderScheme::SymmetricProjection;
        self.layout = self.layout.with_projection(if projected { N } else { 0 });
        self.closed_pair = self.closed_form
            && self.discrete.quadrature().degree() == 1
            && self.collocated.is_empty()
            && !self.projected()
            && !S::FORCES;
    }

    /// Begins a run of the model as a component of a modular interconnection: its degenerate
    /// coordinates are left to the junctions (the interconnection examines them as a whole), so
    /// no hidden constraints or collocated rows of its own.
    pub(crate) fn begin_as_component(&mut self, state: &State<N>) {
        self.hidden = Some(HiddenConstraints::none());
        self.collocated = Vec::new();
        self.begin_run(state);
    }

    /// The junctions' impulse `ι = Σ_j μ_j a_j` on this component over the next step (a covector
    /// of its coordinates): its share `σ ι` enters the rows of `p_k`'s equation and the rest the
    /// momentum `p_{k+1}`, as a constant constraint one-form's impulse would. `σ` is the
    /// interconnection's (one for all its junctions), not necessarily this component's.
    pub(crate) fn set_coupling(&mut self, impulse: &SVector<f64, N>, share: f64) {
        self.coupling = Some((*impulse, share));
    }

    /// The checks of a start that do not depend on the model's degenerate coordinates: finite,
    /// in the configuration space and the Lagrangian's domain, closed forms and constant
    /// one-forms as claimed, independent constraints.
    fn check_state(&self, state: &State<N>) -> Result<(), DiracError> {
        let system = self.discrete.system();
        if S::ONE_FORMS > 0 && self.layout.points() > 1 && self.point != ConstraintPoint::Midpoint {
            return Err(DiracError::InvalidQuadrature(format!(
                "{} holds the one-forms at its Gauss nodes, so it has no constraint point; \
                 {:?} applies to degree-1 quadratures only (leave the default, Midpoint)",
                self.discrete.quadrature().name(),
                self.point
            )));
        }
        let (q, p, v) = (&state.q, &state.p, &state.velocity);
        check_finite(system, "initial position", q)?;
        let space = self.discrete.space();
        if !space.contains(q) {
            return Err(DiracError::InconsistentInitialState(format!(
                "the initial position {:?} is not a point of the configuration space {space:?}",
                q.as_slice()
            )));
        }
        check_finite(system, "initial momentum", p)?;
        check_finite(system, "initial velocity", v)?;
        let lagrangian = system.lagrangian(q, v);
        if !lagrangian.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the Lagrangian at the initial state (is (q0, v0) in its domain?)".into(),
                value: lagrangian,
            });
        }
        let energy = legendre::energy(system, q, v);
        if !energy.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the initial energy".into(),
                value: energy,
            });
        }
        crate::model::closed_form::check(system, q, v)?;
        constraint::check_constant(system, q)?;
        constraint::check_independent(system, q)?;
        Ok(())
    }

    /// [`StepEquations::check_start`] of the model as a component of a modular interconnection:
    /// its own constraints, not its degenerate rows (the junctions balance them; the
    /// interconnection examines them as a whole).
    pub(crate) fn check_component_start(
        &self,
        state: &State<N>,
        tolerance: f64,
    ) -> Result<(), DiracError> {
        self.check_state(state)?;
        initial_state::check_constraints(
            self.discrete.system(),
            &state.q,
            &state.velocity,
            tolerance,
        )
        .map_err(DiracError::InconsistentInitialState)
    }

    fn constrained() -> bool {
        S::ONE_FORMS + S::HOLONOMIC > 0
    }

    /// The run's hidden constraints (none before a run).
    fn hidden(&self) -> &HiddenConstraints {
        static NONE: HiddenConstraints = HiddenConstraints::none();
        self.hidden.as_ref().unwrap_or(&NONE)
    }

    /// The rows of the constraints on the velocity at `q`: the one-forms, the holonomic
    /// differentials and the hidden constraints' differentials (found at `(q, guess)`, so that
    /// the velocity of a state is solved the same way before a run begins; none where they
    /// cannot be evaluated: the velocity solve then reports the coordinates it cannot fix).
    fn velocity_forms(
        &self,
        q: &SVector<f64, N>,
        guess: &SVector<f64, N>,
        hidden: &HiddenConstraints,
    ) -> DMatrix<f64> {
        let system = self.discrete.system();
        let forms = HiddenConstraints::forms(system, q);
        if hidden.count() == 0 {
            return forms;
        }
        // The hidden constraints do not depend on t (refused at the start otherwise).
        match hidden.evaluate(system, q, guess, 0.0, &self.inputs) {
            Ok(e) => {
                let (m, k) = (forms.nrows(), e.differential.nrows());
                DMatrix::from_fn(m + k, N, |r, c| {
                    if r < m {
                        forms[(r, c)]
                    } else {
                        e.differential[(r - m, c)]
                    }
                })
            }
            _ => forms,
        }
    }

    /// The velocity at `(q, p)` with the constraints' multipliers `ν` (see
    /// [`legendre::constrained_velocity`]), or the plain Legendre inversion with no multipliers.
    /// `run` holds the run's hidden constraints once a run has begun; before it they are found
    /// at `(q, guess)`.
    fn velocity_with_multipliers(
        &self,
        newton: &mut Newton,
        t: f64,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        guess: &SVector<f64, N>,
        run: Option<&HiddenConstraints>,
    ) -> Result<Legendre<N>, NewtonFailure> {
        let system = self.discrete.system();
        let found;
        let hidden = match run {
            Some(hidden) => hidden,
            None => {
                found = HiddenConstraints::find(system, q, guess, t, &self.inputs);
                &found
            }
        };
        if N > 0 && !Self::constrained() && hidden.coordinates().len() == N {
            // Linear in every velocity: the first-order equations fix the velocity.
            return legendre::first_order_velocity(system, newton, q, guess)
                .map(|v| Legendre::plain(v, None));
        }
        if let Some(solved) = self.unconstrained_velocity(newton, q, p, guess, hidden) {
            return solved.map(|(v, energy)| Legendre::plain(v, energy));
        }
        let dead = hidden.coordinates();
        let mut spare = None;
        if hidden.dynamic() > 0 && hidden.count() == 0 {
            // Degenerate rows that are first-order equations (a resistor on a capacitor's
            // branch) fix their velocities through the dynamics, not through p.
            let forms = HiddenConstraints::forms(system, q);
            let (reached, unreached) = hidden.reach(system, q);
            // Forms that are not finite here (NaN bases) fix no velocity: not the
            // unconstrained one either.
            let finite = |m: &DMatrix<f64>| m.iter().all(|x| x.is_finite());
            if !(finite(&forms) && finite(&reached) && finite(&unreached)) {
                return Err(NewtonFailure::NonFinite);
            }
            if reached.ncols() + unreached.ncols() == hidden.coordinates().len() {
                let newton = sized(newton, N + forms.nrows(), &mut spare)?;
                let rows =
                    |v: &SVector<f64, N>| hidden.rows_in_velocity(system, q, v, t, &self.inputs);
                let dynamic = legendre::DynamicRows {
                    coordinates: hidden.coordinates(),
                    reached: &reached,
                    unreached: &unreached,
                    rows: &rows,
                };
                return legendre::constrained_velocity(
                    system,
                    newton,
                    q,
                    p,
                    &forms,
                    guess,
                    Some(&dynamic),
                )
                .map(Legendre::constrained);
            }
        }
        if hidden.dynamic() > 0 {
            // With hidden constraints among the same rows, the plain inversion keeps the
            // guess on the degenerate velocities (see "Not supported yet").
            let newton = sized(newton, N, &mut spare)?;
            return legendre::velocity_with_energy(system, newton, q, p, guess, dead)
                .map(|(v, energy)| Legendre::plain(v, energy));
        }
        let forms = self.velocity_forms(q, guess, hidden);
        let newton = sized(newton, N + forms.nrows(), &mut spare)?;
        if forms.nrows() > 0 {
            legendre::constrained_velocity(system, newton, q, p, &forms, guess, None)
                .map(Legendre::constrained)
        } else {
            legendre::velocity_with_energy(system, newton, q, p, guess, dead)
                .map(|(v, energy)| Legendre::plain(v, energy))
        }
    }

    /// The plain Legendre inversion where no rows constrain the velocity (no constraints, no
    /// hidden constraints, fewer than `N` velocities without kinetic energy: not a first-order
    /// model) and `newton` has `N` unknowns, with the energy where its chord step gives it:
    /// what [`velocity_with_multipliers`](Self::velocity_with_multipliers) finds there,
    /// without its bookkeeping. `None` elsewhere.
    #[inline(always)]
    fn unconstrained_velocity(
        &self,
        newton: &mut Newton,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        guess: &SVector<f64, N>,
        hidden: &HiddenConstraints,
    ) -> Option<Result<VelocityAndEnergy<N>, NewtonFailure>> {
        let plain = !Self::constrained()
            && hidden.count() == 0
            && hidden.dynamic() == 0
            && hidden.coordinates().len() < N
            && newton.unknowns() == N;
        let system = self.discrete.system();
        let dead = hidden.coordinates();
        plain.then(|| legendre::velocity_with_energy(system, newton, q, p, guess, dead))
    }

    /// RATTLE's momentum projection at the end of a step: `p ← p + Σ_b ν_b dg_b(q)` with `ν`
    /// from the constrained Legendre transform at `(q, p)`, so that the velocity of the new
    /// momentum is tangent to the holonomic constraints (and allowed by the other constraints).
    fn project_momentum(&self, state: &mut State<N>, t: f64, step: u64) -> Result<(), DiracError> {
        let options = crate::solve::newton::NewtonOptions {
            line_search: true,
            max_contraction: f64::INFINITY,
            ..Default::default()
        };
        let mut newton = Newton::new(self.velocity_unknowns(), options)?;
        let Legendre {
            velocity: v,
            multipliers: nu,
            ..
        } = self
            .velocity_with_multipliers(
                &mut newton,
                t,
                &state.q,
                &state.p,
                &state.velocity,
                self.hidden.as_ref(),
            )
            .map_err(|failure| DiracError::Projection {
                step,
                why: format!(
                    "the velocity tangent to the holonomic constraints could not be solved for \
                     ({failure:?})"
                ),
            })?;
        let system = self.discrete.system();
        for b in 0..S::HOLONOMIC {
            let form = constraint::holonomic(system, &state.q, b).1;
            let nu = nu
                .get(S::ONE_FORMS + b)
                .ok_or_else(|| DiracError::Projection {
                    step,
                    why: "the velocity solve gave no multipliers of the holonomic constraints"
                        .into(),
                })?;
            state.p += form * *nu;
        }
        state.velocity = v;
        Ok(())
    }

    /// Why the run's steps are not read off a step map
    /// ([`affine_step`](crate::step::affine_step)), or `Ok(())` where they are: `L` quadratic
    /// with constant coefficients on `Rⁿ`, constant one-forms, and nothing else in a step (no
    /// forces, whose time and inputs change the step; no holonomic constraints or coupling).
    /// A projection after the solve (hidden constraints, collocated rows) is linear too, and
    /// part of the map.
    /// Whether the model's kind allows a step map (the part of
    /// [`refuse_step_map`](Self::refuse_step_map) known when it is compiled).
    const MAY_MAP: bool = S::QUADRATIC && C::TRANSLATION && !S::FORCES && S::HOLONOMIC == 0;

    fn refuse_step_map(&self) -> Result<(), String> {
        let system = self.discrete.system();
        let why = if !S::QUADRATIC {
            "the Lagrangian is not quadratic with constant coefficients (QUADRATIC)"
        } else if !C::TRANSLATION {
            "the configuration space is not a vector space"
        } else if S::FORCES {
            "the model has forces (a force's time and inputs change the step from one step to \
             the next; forces of the state alone, such as a damper, are refused too for now)"
        } else if S::HOLONOMIC > 0 {
            "the model has holonomic constraints"
        } else if self.coupling.is_some() {
            "the model is a component of an interconnection"
        } else if !(0..S::ONE_FORMS).all(|a| system.one_form_is_constant(a)) {
            "a constraint one-form depends on the position"
        } else {
            return Ok(());
        };
        Err(why.to_string())
    }

    /// Reading `reading` of the run's step map at `state` (see [`AffineStep`]), or why there is
    /// none.
    fn read_step_map(&mut self, state: &State<N>, reading: u64) -> Result<Box<AffineStep>, String> {
        let m = self.unknowns();
        let (mut x, mut residual) = (DVector::zeros(m), DVector::zeros(m));
        let origin = State::new(
            state.t,
            SVector::zeros(),
            SVector::zeros(),
            SVector::zeros(),
        );
        self.predict(&origin, None, &mut x);
        x.fill(0.0);
        let mut jacobian = Dense::new(m);
        self.assemble(&origin, &x, &mut residual, Some(jacobian.matrix()));
        jacobian
            .factorise(NewtonOptions::default().singular_tolerance)
            .map_err(|_| "the step's Jacobian is singular".to_string())?;
        let z: Vec<f64> = state.q.iter().chain(state.p.iter()).copied().collect();
        AffineStep::read(&z, reading, |z| {
            self.probe(state.t, z, &jacobian, &mut x, &mut residual)
        })
        .map(Box::new)
    }

    /// The stacked outputs of the step from `z = (q_k, p_k)` solved by one update of `x = 0` with
    /// the factorised `jacobian`: the unknowns, the momentum's impulse and end covector, the
    /// constraints' impulse. `Err` where the update does not reach a root.
    fn probe(
        &mut self,
        t: f64,
        z: &[f64],
        jacobian: &Dense,
        x: &mut DVector<f64>,
        residual: &mut DVector<f64>,
    ) -> Result<DVector<f64>, String> {
        let q = SVector::<f64, N>::from_column_slice(&z[..N]);
        let p = SVector::<f64, N>::from_column_slice(&z[N..]);
        let state = State::new(t, q, p, SVector::zeros());
        self.predict(&state, None, x);
        x.fill(0.0);
        // An update from x = 0 and one refinement (a root to round-off, however conditioned
        // `J` is, where the equations are linear), the last point assembled.
        for _ in 0..2 {
            self.assemble(&state, x, residual, None);
            affine_step::correction(jacobian, residual);
            *x -= &*residual;
        }
        self.assemble(&state, x, residual, None);
        affine_step::correction(jacobian, residual);
        if !affine_step::is_root(x.as_slice(), residual.as_slice()) {
            return Err(format!(
                "an update and a refinement do not solve the step from a unit state (the \
                 correction left is {:.1e}): the step equations are not linear",
                residual.amax()
            ));
        }
        let next = self.advance(&state, x, 0).map_err(|e| e.to_string())?;
        let m = x.len();
        let mut y = DVector::zeros(m + 3 * N);
        y.rows_mut(0, m).copy_from(x);
        y.fixed_rows_mut::<N>(m)
            .copy_from(&(next.q - q + next.q_carry));
        y.fixed_rows_mut::<N>(m + N)
            .copy_from(&(next.p - p + next.p_carry));
        y.fixed_rows_mut::<N>(m + 2 * N)
            .copy_from(&self.constraint_impulse);
        Ok(y)
    }

    /// The step from `state` by the run's step map `map`: its solution into `x` and the
    /// equations' record of the step (for its work), and the new state by the compensated sums
    /// of the map's increments.
    fn step_by_map(
        &mut self,
        map: &mut AffineStep,
        state: &State<N>,
        x: &mut DVector<f64>,
        step: u64,
    ) -> Result<State<N>, DiracError> {
        let m = x.len();
        let y = map.apply(state.q.as_slice(), state.p.as_slice());
        x.copy_from(&y.rows(0, m));
        let dq = y.fixed_rows::<N>(m).into_owned();
        let dp = y.fixed_rows::<N>(m + N).into_owned();
        let constraint_impulse = y.fixed_rows::<N>(m + 2 * N).into_owned();
        self.momentum = self
            .discrete
            .space()
            .pull_back(&state.q, &SVector::zeros(), &state.p);
        self.read_increments(x);
        self.constraint_impulse = constraint_impulse;
        let xi = self.end_increment(x);
        let (space, system) = (self.discrete.space(), self.discrete.system());
        let mut next = *state;
        space.advance(&mut next.q, &mut next.q_carry, &dq);
        compensated_add(&mut next.p, &mut next.p_carry, &dp);
        for &d in &self.collocated {
            // The primary constraint p = ϑ(q), kept as Newton's steps keep it: no carry.
            next.p_carry[d] = 0.0;
        }
        check_finite(system, "new position", &next.q)?;
        check_finite(system, "new momentum", &next.p)?;
        next.velocity = space.push_forward(&state.q, &xi, &(xi / self.discrete.h()));
        self.discrete.check_end(&next.q, &next.velocity, step)?;
        Ok(next)
    }

    /// Whether the model's kind allows a fixed-point iteration (the part of
    /// [`refuse_fixed_point`](Self::refuse_fixed_point) known when it is compiled).
    const MAY_ITERATE: bool = C::TRANSLATION && S::ONE_FORMS + S::HOLONOMIC == 0;

    /// Whether the iteration runs on the tables of a separable model, one gradient of `L` a node
    /// an iteration (its forces, if any, free of the velocity), rather than on the assembled
    /// rows (see [`fixed_point`](crate::step::fixed_point)).
    const ITERATES_TABLES: bool = S::SEPARABLE && (!S::FORCES || S::FORCES_FREE_OF_VELOCITY);

    fn refuse_fixed_point(&self) -> Result<(), String> {
        let why = if !C::TRANSLATION {
            "the configuration space is not a vector space"
        } else if S::ONE_FORMS + S::HOLONOMIC > 0 {
            "the model has constraints (their multipliers are not iterated)"
        } else if self.coupling.is_some() {
            "the model is a component of an interconnection"
        } else {
            return Ok(());
        };
        Err(why.to_string())
    }

    /// The run's fixed-point tables, set up from `state` at its first step, or why there are
    /// none (kept for the run): for a separable model with its constant kinetic terms, checked;
    /// for another with its mass matrix at `state` (replaced at every step), where the run's
    /// Lagrangian is regular there.
    fn iteration_tables(&mut self, state: &State<N>) -> Result<FixedPoint<N>, String> {
        if let Some(why) = &self.iteration_refused {
            return Err(why.clone());
        }
        if let Some(tables) = self.iteration.take() {
            return Ok(tables);
        }
        let system = self.discrete.system();
        let kinetic = if Self::ITERATES_TABLES {
            Kinetic::of(system, &state.q, &state.velocity)
                .map_err(|e| format!("the run's kinetic terms: {e}"))
        } else if self.projected() || !self.collocated.is_empty() || self.hidden().count() > 0 {
            Err(
                "the run's Lagrangian is degenerate (some coordinates carry no kinetic energy \
                 of their own): its rows are not iterated"
                    .to_string(),
            )
        } else {
            Kinetic::frozen(derivatives::velocity_hessian(
                system,
                &state.q,
                &state.velocity,
            ))
            .ok_or_else(|| "the mass matrix ∂²L/∂v² at the start has no finite inverse".to_string())
        };
        let tables = kinetic.and_then(|kinetic| {
            FixedPoint::new(self.discrete.quadrature(), kinetic).ok_or_else(|| {
                format!(
                    "{} has no fixed-point tables",
                    self.discrete.quadrature().name()
                )
            })
        });
        if let Err(why) = &tables {
            self.iteration_refused = Some(why.clone());
        }
        tables
    }

    /// Solves the step from `state` by iterating on its assembled rows from the predictor in
    /// `x`, `ξ ← ξ − h (K⁻¹ ⊗ M⁻¹) R(ξ)` with the mass matrix `M` at the middle of the predicted
    /// step (see [`fixed_point`](crate::step::fixed_point)), until the update is at round-off;
    /// the solution is left in `x` with its rows assembled, and its residual checked against
    /// `tolerance` times the size of its terms.
    fn iterate_on_rows(
        &mut self,
        state: &State<N>,
        x: &mut DVector<f64>,
        tolerance: f64,
    ) -> Result<NewtonReport, String> {
        let mut tables = self.iteration_tables(state)?;
        let (h, layout, s) = (self.discrete.h(), self.layout, self.increments.len());
        let end = x.fixed_rows::<N>(layout.point(s)).into_owned();
        let mass = derivatives::velocity_hessian(
            self.discrete.system(),
            &(state.q + end * 0.5),
            &(end / h),
        );
        let Some(kinetic) = Kinetic::frozen(mass) else {
            self.iteration = Some(tables);
            return Err(
                "the mass matrix ∂²L/∂v² at the middle of the predicted step has no finite \
                 inverse"
                    .to_string(),
            );
        };
        tables.set_kinetic(kinetic);
        tables.restart_acceleration();
        let gain = tables.correction_gain(h);
        let mut residual = self.residual_buffer(x.len());
        let mut previous: Option<f64> = None;
        let (mut contraction, mut slow_before) = (0.0f64, false);
        // Formatted where it is the outcome: a step that settles allocates nothing.
        let mut settled = Err(None);
        for iteration in 1..=fixed_point::MAX_ITERATIONS {
            let scale = self.assemble(state, x, &mut residual, None);
            // `amax` skips a NaN that a later entry follows.
            if !residual.iter().all(|r| r.is_finite()) {
                settled = Err(Some(format!(
                    "the iteration on the rows left the finite numbers at iteration {iteration}"
                )));
                break;
            }
            let update = tables.correct(h, |j| {
                residual.fixed_rows::<N>(layout.point(j + 1)).into_owned()
            });
            // The update's round-off: the increments' own, the positions' carried by the
            // contraction, and the rows' terms' through `h (K⁻¹ ⊗ M⁻¹)`.
            let size = (1..=s)
                .map(|m| x.fixed_rows::<N>(layout.point(m)).amax())
                .fold(0.0, f64::max);
            let floor =
                4.0 * f64::EPSILON * (size + contraction.min(1.0) * state.q.amax() + gain * scale);
            // An update that did not shrink: the iteration is at its round-off.
            let stalled = previous.is_some_and(|before| update >= before);
            if update <= f64::EPSILON * size || (stalled && update <= 64.0 * floor) {
                // The last correction is taken too, and the rows assembled there (for
                // `advance` and the check): left out, it would bias every step alike (an
                // update stopped at 4 ε |ξ| drifted the charge's angular momentum by 1.7e-17 a
                // step).
                self.read_increments(x);
                tables.apply(&mut self.increments);
                self.write_increments(x);
                let scale = self.assemble(state, x, &mut residual, None);
                settled = Ok((iteration, scale));
                break;
            }
            // The contraction as the updates above round-off show it. Two running above ½ hand
            // the step over (the mixed updates need not shrink monotonically).
            let ratio = previous
                .filter(|&before| before > 64.0 * floor && update > 64.0 * floor)
                .map(|before| update / before);
            contraction = contraction.max(ratio.unwrap_or(0.0));
            let slow = ratio.filter(|&ratio| ratio > fixed_point::MAX_ROW_CONTRACTION);
            // The first ratio is the plain iteration's (the second update follows one
            // unmixed): above ½ the predictor is not where the iteration vouches for a root
            // near it, and the step is Newton's, whose contraction test then decides.
            if let (Some(ratio), 2) = (slow, iteration) {
                settled = Err(Some(format!(
                    "the iteration on the rows contracts too slowly from the predictor: its \
                     second update {ratio:.2} times its first (at most {})",
                    fixed_point::MAX_ROW_CONTRACTION
                )));
                break;
            }
            if let (Some(ratio), true) = (slow, slow_before) {
                settled = Err(Some(format!(
                    "the iteration on the rows contracts too slowly: its update shrank by less \
                     than {} twice running, {ratio:.2} at iteration {iteration}",
                    fixed_point::MAX_ROW_CONTRACTION
                )));
                break;
            }
            slow_before = slow.is_some();
            // The increments lead the unknowns (an unconstrained step without projection).
            debug_assert_eq!(layout.point(1), 0);
            tables.accelerate(&mut x.as_mut_slice()[..s * N]);
            previous = Some(update);
        }
        let (iterations, scale) = match settled {
            Ok(settled) => settled,
            Err(why) => {
                self.iteration = Some(tables);
                self.iterated_residual = residual;
                return Err(why.unwrap_or_else(|| {
                    format!(
                        "the iteration on the rows did not settle in {} iterations",
                        fixed_point::MAX_ITERATIONS
                    )
                }));
            }
        };
        let settled = Settled {
            iterations,
            contraction,
        };
        self.checked_iteration(state, tables, residual, scale, tolerance, settled, "")
    }

    /// The buffer for the rows of an iterated solution, of `n` rows.
    fn residual_buffer(&mut self, n: usize) -> DVector<f64> {
        let residual = std::mem::take(&mut self.iterated_residual);
        match residual.len() == n {
            true => residual,
            false => DVector::zeros(n),
        }
    }

    /// The increments `ξ_1, …, ξ_s` of the point `x`, into `increments`.
    fn read_increments(&mut self, x: &DVector<f64>) {
        for (j, z) in self.increments.iter_mut().enumerate() {
            z.copy_from(&x.fixed_rows::<N>(self.layout.point(j + 1)));
        }
    }

    /// `increments` into the point `x`.
    fn write_increments(&self, x: &mut DVector<f64>) {
        for (j, z) in self.increments.iter().enumerate() {
            x.fixed_rows_mut::<N>(self.layout.point(j + 1)).copy_from(z);
        }
    }

    /// The iterated solution in `increments`, whose rows `residual` were assembled last
    /// (`scale` the size of their terms), checked as Newton's roots are: its residual against
    /// `tolerance` times the rows' terms (the assembly's count, and at least `p_k` and
    /// `M ξ_s / h`), `why` added to a refusal. Puts the tables and the buffer back.
    #[allow(clippy::too_many_arguments)]
    fn checked_iteration(
        &mut self,
        state: &State<N>,
        tables: FixedPoint<N>,
        residual: DVector<f64>,
        scale: f64,
        tolerance: f64,
        settled: Settled,
        why: &str,
    ) -> Result<NewtonReport, String> {
        let terms = scale
            .max(state.p.amax())
            .max(tables.momentum_size(self.discrete.h(), &self.increments));
        self.iteration = Some(tables);
        let size = residual.amax();
        // `amax` skips a NaN that a later entry follows.
        let finite = residual.iter().all(|x| x.is_finite());
        self.iterated_residual = residual;
        if !finite || exceeds(size, tolerance * terms) {
            return Err(format!(
                "the iteration's solution leaves a residual of {size:.1e} against a tolerance \
                 of {:.1e}{why}",
                tolerance * terms
            ));
        }
        Ok(NewtonReport {
            iterations: settled.iterations,
            jacobians: 0,
            residual: size,
            contraction: settled.contraction,
        })
    }

    /// Solves the step from `state` by the fixed-point iteration from the predictor in `x`
    /// (see [`fixed_point`](crate::step::fixed_point)), writes the solution into `x` and
    /// assembles it, its residual checked against `tolerance` times the size of its terms.
    fn iterate(
        &mut self,
        state: &State<N>,
        x: &mut DVector<f64>,
        tolerance: f64,
    ) -> Result<NewtonReport, String> {
        let mut tables = self.iteration_tables(state)?;
        self.read_increments(x);
        let (system, inputs) = (self.discrete.system(), &self.inputs);
        let at_rest = SVector::zeros();
        let pull = |y: &SVector<f64, N>, t: f64| {
            let g = derivatives::directional_gradient(system, y, &at_rest, Seed::POSITION);
            match S::FORCES {
                true => g + system.force(y, &at_rest, t, inputs),
                false => g,
            }
        };
        let h = self.discrete.h();
        let settled = tables.solve(&state.q, &state.p, state.t, h, &mut self.increments, pull);
        let settled = match settled {
            Ok(settled) => settled,
            Err(why) => {
                self.iteration = Some(tables);
                return Err(why);
            }
        };
        let mut residual = self.residual_buffer(x.len());
        // The tables' solution refined on the assembled rows (each correction taken, at
        // round-off too: a correction left out biases every step alike, and the energy's
        // round-off drifts faster), the rows assembled at the last point (for `advance`).
        // `assemble` reads the increments from `x`.
        let mut scale;
        let mut refinements = 0;
        loop {
            self.write_increments(x);
            scale = self.assemble(state, x, &mut residual, None);
            if refinements == fixed_point::refinements(settled.contraction) {
                break;
            }
            let layout = self.layout;
            tables.correct(h, |j| {
                residual.fixed_rows::<N>(layout.point(j + 1)).into_owned()
            });
            tables.apply(&mut self.increments);
            refinements += 1;
        }
        let why = ": the model may not be separable as it declares";
        self.checked_iteration(state, tables, residual, scale, tolerance, settled, why)
    }

    /// Second derivatives of the step from `state` solved by `x` with respect to `(q_k, p_k)`,
    /// `newton` holding the Jacobian factorised at `x`: for models on `Rⁿ` without constraints
    /// (others are refused with `Unsupported`).
    ///
    /// The step's points depend on `z = (q_k, p_k)` through `Q_0 = q_k`, `Q_m = q_k + ξ_m`, and
    /// the rows `R_j = δ_j0 p_k + ∂L_d/∂Q_j + f_j = 0` hold for every `z`. Differentiating twice,
    /// `D³L_d[e_j, dQ_a, dQ_b] + D²f_j[dQ_a, dQ_b] + Σ_m G_jm ∂²ξ_m/∂z_a∂z_b = 0`, so `∂²ξ` is one
    /// solve with the factorised `J`, and `p_{k+1} = ∂L_d/∂Q_s + f_s` gives
    /// `∂²p_{k+1} = D³L_d[e_s, dQ_a, dQ_b] + D²f_s[dQ_a, dQ_b] + Σ_m G_sm ∂²ξ_m`.
    pub fn second_derivatives(
        &self,
        state: &State<N>,
        x: &DVector<f64>,
        newton: &Newton,
    ) -> Result<StepHessians<N>, DiracError> {
        if Self::constrained()
            || !C::TRANSLATION
            || !self.collocated.is_empty()
            || self.hidden().count() > 0
        {
            return Err(DiracError::Unsupported(
                "second derivatives of the step map of a model with constraints (hidden ones \
                 included), linear in the velocities, or on a space other than Rⁿ"
                    .into(),
            ));
        }
        let Sensitivity { g, dx, points, .. } = self.sensitivity(state, x, newton)?;
        let layout = &self.layout;
        let s = layout.points();
        let increments = &points[..s];
        let unit = |i: usize| SVector::<f64, N>::from_fn(|r, _| if r == i { 1.0 } else { 0.0 });
        // dQ_m/dz_a for every point m = 0..=s.
        let moves: Vec<Vec<SVector<f64, N>>> = (0..2 * N)
            .map(|a| {
                let base = if a < N { unit(a) } else { SVector::zeros() };
                (0..=s)
                    .map(|m| match m {
                        0 => base,
                        _ => base + dx.column(a).fixed_rows::<N>(layout.point(m)),
                    })
                    .collect()
            })
            .collect();
        // Point m moved along its component r.
        let nudge = |m: usize, r: usize| -> Vec<SVector<f64, N>> {
            (0..=s)
                .map(|k| if k == m { unit(r) } else { SVector::zeros() })
                .collect()
        };
        let discrete = &self.discrete;
        let mut q = vec![DMatrix::zeros(2 * N, 2 * N); N];
        let mut p = vec![DMatrix::zeros(2 * N, 2 * N); N];
        let mut column = DVector::zeros(layout.len());
        for a in 0..2 * N {
            for b in a..2 * N {
                let third = |m: usize, r: usize| {
                    discrete.slot_third(&state.q, increments, [&nudge(m, r), &moves[a], &moves[b]])
                };
                // The forces' second derivatives along the same displacements (f_0..f_s).
                let forces = if S::FORCES {
                    discrete.force_second_derivatives(
                        &state.q,
                        increments,
                        state.t,
                        &self.inputs,
                        [&moves[a], &moves[b]],
                    )
                } else {
                    vec![SVector::zeros(); s + 1]
                };
                for (j, force) in forces.iter().take(s).enumerate() {
                    for r in 0..N {
                        column[layout.point(j + 1) + r] = third(j, r) + force[r];
                    }
                }
                newton
                    .solve_factorised(x, &mut column)
                    .ok_or_else(stale_factorisation)?;
                column.neg_mut();
                let mut end = SVector::<f64, N>::from_fn(|r, _| third(s, r)) + forces[s];
                for (m, g_sm) in g.row(s).iter().enumerate().skip(1) {
                    end += g_sm * column.fixed_rows::<N>(layout.point(m));
                }
                for r in 0..N {
                    let q_ab = column[layout.end_point() + r];
                    q[r][(a, b)] = q_ab;
                    q[r][(b, a)] = q_ab;
                    p[r][(a, b)] = end[r];
                    p[r][(b, a)] = end[r];
                }
            }
        }
        if q.iter().chain(&p).all(|m| m.iter().all(|v| v.is_finite())) {
            Ok(StepHessians { q, p })
        } else {
            Err(DiracError::NonFinite {
                what: "a second derivative of the step map".into(),
                value: f64::NAN,
            })
        }
    }

    /// The implicit function theorem's first half: `∂x/∂(q_k, p_k, u) = −J⁻¹ ∂R/∂(q_k, p_k, u)`
    /// at the solution `x`, with what the new state's derivatives need besides (see
    /// [`StepEquations::linearise`] for the terms).
    fn sensitivity(
        &self,
        state: &State<N>,
        x: &DVector<f64>,
        newton: &Newton,
    ) -> Result<Sensitivity<N>, DiracError> {
        if !C::TRANSLATION
            || !self.collocated.is_empty()
            || (Self::constrained() && self.layout.points() > 1)
        {
            return Err(DiracError::Unsupported(
                "derivatives of the step map on a configuration space other than Rⁿ (step it \
                 with Stepper::on_manifold, whose derivatives cover Positive, rotations and unit \
                 vectors), of a Lagrangian linear in the velocities, or with constraints at \
                 internal points or nodes"
                    .into(),
            ));
        }
        let discrete = &self.discrete;
        let system = discrete.system();
        let layout = &self.layout;
        let s = layout.points();
        let mut points = [SVector::<f64, N>::zeros(); MAX_DEGREE];
        for (j, point) in points.iter_mut().take(s).enumerate() {
            point.copy_from(&x.fixed_rows::<N>(layout.point(j + 1)));
        }
        let increments = &points[..s];
        let mut g = discrete.slot_hessian(&state.q, increments);
        if S::FORCES {
            discrete.add_force_slot_derivatives(
                &state.q,
                increments,
                state.t,
                &self.inputs,
                &mut g,
            );
        }
        let inputs = self.inputs.len();
        let force_u = if S::FORCES && inputs > 0 {
            discrete.force_input_derivatives(&state.q, increments, state.t, &self.inputs)
        } else {
            Vec::new()
        };
        // The constraints at the solution: A_a(q_c), ∂A_a(q_c), μ, and dg_b, ∂²g_b, λ.
        let (theta, share) = (self.point.theta(), self.point.share());
        let xi_s = increments[s - 1];
        let q_c = state.q + xi_s * theta;
        let one_forms: Vec<_> = (0..S::ONE_FORMS)
            .map(|a| constraint::one_form(system, &q_c, a))
            .collect();
        let mu: Vec<f64> = (0..S::ONE_FORMS).map(|a| x[layout.one_form(a)]).collect();
        let lambda: Vec<f64> = (0..S::HOLONOMIC).map(|b| x[layout.holonomic(b)]).collect();
        // Σ_a μ_a ∂A_a(q_c): how the one-form impulse turns with q_c.
        let turning: SMatrix<f64, N, N> = one_forms
            .iter()
            .zip(&mu)
            .filter_map(|((_, derivative), mu)| derivative.map(|d| d * *mu))
            .sum();
        let curvature: SMatrix<f64, N, N> = (0..S::HOLONOMIC)
            .map(|b| crate::model::derivatives::holonomic_hessian(system, &state.q, b) * lambda[b])
            .sum();
        // ∂R/∂z, one column per parameter: q_k (N), p_k (N), u (inputs).
        let n = layout.len();
        let parameters = 2 * N + inputs;
        let mut dr = DMatrix::zeros(n, parameters);
        for j in 0..s {
            let mut block = g.row_sum(j);
            if j == 0 {
                block += turning * share + curvature;
            }
            dr.view_mut((layout.point(j + 1), 0), (N, N))
                .copy_from(&block);
        }
        for i in 0..N {
            dr[(i, N + i)] = 1.0;
        }
        for (j, force) in force_u.iter().take(s).enumerate() {
            dr.view_mut((layout.point(j + 1), 2 * N), (N, inputs))
                .copy_from(force);
        }
        for (a, (_, derivative)) in one_forms.iter().enumerate() {
            let Some(derivative) = derivative else {
                continue;
            };
            let row = derivative.transpose() * xi_s;
            dr.view_mut((layout.one_form(a), 0), (1, N))
                .copy_from(&row.transpose());
        }
        for b in 0..S::HOLONOMIC {
            let (_, form) = constraint::holonomic(system, &(state.q + xi_s), b);
            dr.view_mut((layout.holonomic(b), 0), (1, N))
                .copy_from(&form.transpose());
        }
        // ∂x/∂z = −J⁻¹ ∂R/∂z.
        let mut dx = dr;
        newton
            .implicit_derivatives(x, &mut dx)
            .ok_or_else(stale_factorisation)?;
        Ok(Sensitivity {
            g,
            dx,
            points,
            force_u,
            end_rows: one_forms
                .iter()
                .map(|(row, _)| row * (1.0 - share))
                .collect(),
            end_turning: turning * (1.0 - share),
            theta,
            inputs,
        })
    }
}

impl<S: DiracSystem<N>, C: ConfigurationSpace<N, Manifold = Vectors>, const N: usize>
    EulerLagrange<S, N, C>
{
    /// The collocated rows of the coordinates linear in their velocities (see
    /// [`first_order`]), with their Jacobian.
    fn collocate(
        &self,
        state: &State<N>,
        residual: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> f64 {
        let (q, increments) = (&state.q, &self.increments);
        first_order::collocation(
            &self.discrete,
            q,
            increments,
            &self.collocated,
            residual,
            jacobian,
        )
    }

    /// The rows of a degree-1 step without holonomic rows or a coupling, its one-forms (if
    /// any) in closed form: the pair of slots and the one-forms straight from the closed forms
    /// into the buffers (the Jacobian by columns). `None`, with nothing written, where the
    /// Lagrangian has no closed forms.
    #[inline(always)]
    fn direct_rows(
        &mut self,
        state: &State<N>,
        xi: &SVector<f64, N>,
        x: &DVector<f64>,
        residual: &mut [f64],
        jacobian: Option<&mut [f64]>,
    ) -> Option<f64> {
        // The unknowns are the end point's increment and the multipliers. Cut to their number,
        // a constant here, the buffers' lengths are known below, and so is every index.
        let n = N + S::ONE_FORMS;
        let x = x.as_slice();
        if x.len() != n
            || residual.len() != n
            || jacobian.as_ref().is_some_and(|j| j.len() != n * n)
        {
            return None;
        }
        let (x, residual) = (&x[..n], &mut residual[..n]);
        let mut jacobian = jacobian.map(|j| &mut j[..n * n]);
        let discrete = &self.discrete;
        let (mut covectors, mut scale) = discrete.pair_in_closed_form(
            &state.q,
            xi,
            &self.momentum,
            residual,
            jacobian.as_deref_mut(),
            true,
        )?;
        let mut constraint_impulse = SVector::zeros();
        if S::ONE_FORMS > 0 {
            let (impulse, size) = constraint::closed_one_forms(
                discrete.system(),
                discrete.space(),
                &state.q,
                self.point,
                x,
                residual,
                jacobian,
            );
            constraint_impulse = impulse;
            covectors += StepCovectors {
                impulse,
                end: impulse * (1.0 - self.point.share()),
            };
            scale = scale.max(size);
        }
        self.covectors = covectors;
        self.constraint_impulse = constraint_impulse;
        self.covectors_pending = false;
        Some(scale)
    }

    /// [`StepEquations::assemble`] with `scratch` (`n × n`) taking the Jacobian of the rows
    /// beyond the discrete Euler–Lagrange ones when none is asked for. Kept out of line: inlined,
    /// it made Newton's evaluation larger for the degree-1 path too (the knife edge took 56
    /// instructions a step more).
    #[inline(never)]
    fn assemble_into(
        &mut self,
        state: &State<N>,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
        scratch: &mut DMatrix<f64>,
    ) -> f64 {
        if self.closed_pair {
            // The end point's increment leads the unknowns of a degree-1 step; the constraint
            // rows write every row after it (there are no others without a projection).
            debug_assert_eq!(x.len(), N + S::ONE_FORMS + S::HOLONOMIC);
            let xi = self.increments[0];
            if let Some((covectors, scale)) = self.discrete.pair_in_closed_form(
                &state.q,
                &xi,
                &self.momentum,
                residual.as_mut_slice(),
                jacobian.as_deref_mut().map(|j| j.as_mut_slice()),
                false,
            ) {
                self.covectors_pending = false;
                return self
                    .add_constraints_and_coupling(state, x, residual, jacobian, covectors, scale);
            }
        }
        let discrete = &self.discrete;
        if self.projected() || self.first_order() {
            // First-order (collocated) steps take their rows' derivatives together.
            let jacobian = jacobian.unwrap_or(scratch);
            if self.projected() {
                let shift = x.fixed_rows::<N>(self.layout.projection()).into_owned();
                return first_order::symmetric_projection(
                    discrete,
                    &state.q,
                    &state.p,
                    &self.increments,
                    &shift,
                    residual,
                    jacobian,
                );
            }
            return self.collocate(state, residual, jacobian);
        }
        let (lagrangian, mut scale) = discrete.euler_lagrange(
            &state.q,
            &self.increments,
            &self.momentum,
            residual,
            jacobian.as_deref_mut(),
        );
        // Left to `advance` where the residual did not need them.
        self.covectors_pending = lagrangian.is_none();
        let mut covectors = lagrangian.unwrap_or_else(StepCovectors::zero);
        // Collocated rows and forces write their derivatives as they go: without a Jacobian
        // asked for, into `scratch`. Constraint rows take none then.
        let sink = !self.collocated.is_empty() || S::FORCES;
        if jacobian.is_none() && sink {
            scratch.as_mut_slice().fill(0.0);
        }
        if !self.collocated.is_empty() {
            // A mixed Lagrangian: the rows of the coordinates linear in their velocities are
            // collocated, the others stay variational.
            let jacobian = jacobian.as_deref_mut().unwrap_or(&mut *scratch);
            scale = scale.max(self.collocate(state, residual, jacobian));
        }
        if S::FORCES {
            let jacobian = jacobian.as_deref_mut().unwrap_or(&mut *scratch);
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
        self.add_constraints_and_coupling(state, x, residual, jacobian, covectors, scale)
    }

    /// The rows' constraint impulses and coupling added to the step's `covectors` (kept for
    /// `advance`), with the constraint rows written: returns the size of the residual's terms,
    /// `scale` or more.
    #[inline(always)]
    fn add_constraints_and_coupling(
        &mut self,
        state: &State<N>,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        jacobian: Option<&mut DMatrix<f64>>,
        mut covectors: StepCovectors<N>,
        mut scale: f64,
    ) -> f64 {
        let discrete = &self.discrete;
        let mut constraint_impulse = SVector::zeros();
        if Self::constrained() {
            let constraints = StepConstraints {
                system: discrete.system(),
                space: discrete.space(),
                point: self.point,
                base: &state.q,
                layout: &self.layout,
                holonomic_forms: &self.holonomic_forms,
                increments: &self.increments,
                quadrature: discrete.quadrature(),
                h: discrete.h(),
            };
            let (impulses, size) = constraints.add(x, residual, jacobian);
            constraint_impulse += impulses.impulse;
            covectors += impulses;
            scale = scale.max(size);
        }
        if let Some((impulse, share)) = self.coupling {
            for i in 0..N {
                residual[i] += share * impulse[i];
            }
            constraint_impulse += impulse;
            covectors += StepCovectors {
                impulse,
                end: impulse * (1.0 - share),
            };
        }
        self.covectors = covectors;
        self.constraint_impulse = constraint_impulse;
        scale
    }
}

impl<S: DiracSystem<N>, C: ConfigurationSpace<N, Manifold = Vectors>, const N: usize>
    StepEquations<N> for EulerLagrange<S, N, C>
{
    type System = S;
    type Manifold = Vectors;

    fn system(&self) -> &S {
        self.discrete.system()
    }

    const NAME: &'static str = "the discrete Euler–Lagrange equations";
    const VELOCITY: &'static str = "the Legendre transform (velocity from momentum)";
    const FORCED: bool = S::FORCES;

    fn h(&self) -> f64 {
        self.discrete.h()
    }

    fn method(&self) -> String {
        self.discrete.quadrature().name()
    }

    fn dense(&self, ends: [&Sample<N>; 2], x: &DVector<f64>, theta: f64) -> Option<Sample<N>> {
        let [a, b] = ends;
        let (space, system) = (self.discrete.space(), self.discrete.system());
        // The step's internal points in the chart at q_k (from the shifted start of a projected
        // step).
        let shift = if self.projected() {
            x.fixed_rows::<N>(self.layout.projection()).into_owned()
        } else {
            SVector::zeros()
        };
        let internal =
            (1..self.layout.points()).map(|j| x.fixed_rows::<N>(self.layout.point(j)) + shift);
        let (quadrature, h) = (self.discrete.quadrature(), self.discrete.h());
        let ChartPath { xi, xi_dot, .. } = chart_path(space, quadrature, h, ends, internal, theta)?;
        let q = space.retract(&a.q, &xi);
        let v = space.push_forward(&a.q, &xi, &xi_dot);
        let momentum = |q, v| legendre::momentum(system, q, v);
        let p = momentum(&q, &v)
            + (a.p - momentum(&a.q, &a.v)) * (1.0 - theta)
            + (b.p - momentum(&b.q, &b.v)) * theta;
        Some(Sample {
            t: a.t + theta * h,
            q,
            v,
            p,
        })
    }

    fn unknowns(&self) -> usize {
        self.layout.len()
    }

    fn multipliers(&self) -> usize {
        (S::ONE_FORMS + S::HOLONOMIC) * self.layout.points()
    }

    fn multiplier_names(&self) -> Vec<String> {
        let s = self.layout.points();
        (0..if s == 1 { S::ONE_FORMS } else { 0 })
            .map(|a| format!("mu_{a}"))
            .chain(
                (0..if s > 1 { s } else { 0 })
                    .flat_map(|i| (0..S::ONE_FORMS).map(move |a| format!("mu_{a}_node_{}", i + 1))),
            )
            .chain(
                (1..self.layout.points()).flat_map(|j| {
                    (0..S::HOLONOMIC).map(move |b| format!("lambda_{b}_internal_{j}"))
                }),
            )
            .chain((0..S::HOLONOMIC).map(|b| format!("lambda_{b}")))
            .collect()
    }

    fn coordinate_name(&self, i: usize) -> String {
        self.discrete.system().coordinate_name(i)
    }

    /// `L` and the energy finite at `(q, v)`, and the constraints, their velocity form and the
    /// hidden constraints of coordinates without kinetic energy satisfied.
    fn check_start(&self, state: &State<N>, tolerance: f64) -> Result<(), DiracError> {
        self.check_state(state)?;
        let system = self.discrete.system();
        let (q, p, v) = (&state.q, &state.p, &state.velocity);
        initial_state::check(system, state.t, q, v, &self.inputs, tolerance)
            .map_err(DiracError::InconsistentInitialState)?;
        let hidden = HiddenConstraints::find(system, q, v, state.t, &self.inputs);
        let collocated = Self::collocated_rows(system, q, v, &hidden);
        if collocated.is_empty() && hidden.dynamic() > 0 {
            // First-order rows that are not collocated (with constraints or hidden constraints)
            // are stepped variationally; that keeps the orders where their momenta ϑ_d do not
            // depend on q (a resistor beside a capacitor), and loses them otherwise.
            if let Some(d) = Self::turning(system, q, v, hidden.coordinates()) {
                return Err(DiracError::Unsupported(format!(
                    "constraints or hidden constraints on a Lagrangian linear in the velocity \
                     of {} with a momentum ∂L/∂v that depends on the position (its rows would \
                     be stepped variationally, which loses order)",
                    system.coordinate_name(d)
                )));
            }
            if hidden.count() > 0
                && S::HOLONOMIC > 0
                && self.holonomic_scheme == HolonomicScheme::Rattle
            {
                return Err(DiracError::Unsupported(format!(
                    "RATTLE's momentum projection on a model whose coordinates without kinetic \
                     energy ({}) have both hidden constraints and first-order rows (their \
                     velocity is not solved for; use SHAKE)",
                    hidden.names(system)
                )));
            }
        }
        if collocated.is_empty()
            && hidden.dynamic() > 0
            && first_order::refusal(self.discrete.quadrature()).is_some()
        {
            let quadrature = self.discrete.quadrature();
            return Err(DiracError::InvalidQuadrature(format!(
                "{}: the rows of {} are first-order equations (coordinates without kinetic \
                 energy whose rows contain velocities), and a rule whose nodes are not the \
                 path's Gauss points follows a parasitic mode of them (a resistor beside a \
                 capacitor: under the trapezoid the error grows as e^(2t); with two Gauss nodes \
                 on a straight path, order 1); use a Gauss rule (midpoint, galerkin(s))",
                quadrature.name(),
                hidden.names(system)
            )));
        }
        if !collocated.is_empty() {
            if S::FORCES || !C::TRANSLATION {
                return Err(DiracError::Unsupported(
                    "a Lagrangian linear in some or all velocities (without constraints) with \
                     forces, or on a configuration space other than Rⁿ"
                        .into(),
                ));
            }
            if let Some(why) = first_order::refusal(self.discrete.quadrature()) {
                return Err(DiracError::InvalidQuadrature(why));
            }
            let theta = legendre::momentum(system, q, v);
            let size = largest(theta.iter().chain(p.iter()).copied());
            if collocated
                .iter()
                .any(|&d| exceeds((p[d] - theta[d]).abs(), tolerance * size))
            {
                let names: Vec<String> = collocated
                    .iter()
                    .map(|&d| system.coordinate_name(d))
                    .collect();
                return Err(DiracError::InconsistentInitialState(format!(
                    "the Lagrangian is linear in the velocities of {}, so their momenta are \
                     ϑ(q) = ∂L/∂v = {:?}, not {:?} (start a Lagrangian linear in every velocity \
                     from its position alone with Stepper::start_from_position)",
                    names.join(", "),
                    collocated.iter().map(|&d| theta[d]).collect::<Vec<_>>(),
                    collocated.iter().map(|&d| p[d]).collect::<Vec<_>>(),
                )));
            }
        }
        if hidden.count() > 0 {
            if !C::TRANSLATION {
                return Err(DiracError::Unsupported(format!(
                    "hidden constraints of coordinates without kinetic energy ({}) on a \
                     configuration space other than Rⁿ",
                    hidden.names(system)
                )));
            }
            // c must not depend on t explicitly: its velocity form would miss ∂c/∂t. Probed at
            // incommensurate times (a periodic force can vanish at whole offsets), at q and at a
            // point moved along the free directions (a force f(t) q_c vanishes at q_c = 0).
            let at = |q: &SVector<f64, N>, t: f64| {
                hidden
                    .evaluate(system, q, v, t, &self.inputs)
                    .map_err(DiracError::InconsistentInitialState)
            };
            let start = at(q, state.t)?;
            if let Some(&value) = start.value.iter().find(|c| !c.is_finite()) {
                return Err(DiracError::NonFinite {
                    what: format!(
                        "a hidden constraint of the coordinates without kinetic energy ({}) at \
                         the initial state",
                        hidden.names(system)
                    ),
                    value,
                });
            }
            let moved = q + start.free()
                * DVector::from_element(start.free().ncols(), 1.0)
                * (1e-2 * (1.0 + q.amax()));
            let moved = SVector::<f64, N>::from_fn(|i, _| moved[i]);
            for point in [*q, moved] {
                let Ok(here) = at(&point, state.t) else {
                    continue;
                };
                if !here.value.iter().all(|c| c.is_finite()) {
                    continue;
                }
                for t in [-1.0, 0.371, 1.13, 2.9, 17.3].map(|offset| state.t + offset) {
                    let change = largest((at(&point, t)?.value - &here.value).iter().copied());
                    if exceeds(change, 1e-12 * here.scale) {
                        return Err(DiracError::Unsupported(format!(
                            "a hidden constraint of the coordinates without kinetic energy ({}) \
                             that depends on time explicitly (a force on them that depends on t)",
                            hidden.names(system)
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// Finds the hidden constraints of the coordinates without kinetic energy at the start.
    fn begin(&mut self, state: &State<N>) {
        let system = self.discrete.system();
        let hidden =
            HiddenConstraints::find(system, &state.q, &state.velocity, state.t, &self.inputs);
        self.collocated = Self::collocated_rows(system, &state.q, &state.velocity, &hidden);
        self.hidden = Some(hidden);
        self.begin_run(state);
    }
    /// The stepper's prediction from the last steps (their solutions extrapolated), or the path
    /// `ξ_j = c_j h ξ̇` along the state's velocity with zero multipliers.
    fn predict(&mut self, state: &State<N>, previous: Option<&DVector<f64>>, x: &mut DVector<f64>) {
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
        if S::HOLONOMIC > 0 {
            constraint::holonomic_forms(
                self.discrete.system(),
                space,
                &state.q,
                &mut self.holonomic_forms,
            );
        }
    }

    #[inline(always)]
    fn assemble(
        &mut self,
        state: &State<N>,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
    ) -> f64 {
        // A degree-1 step with closed forms on a one-node rule, without holonomic rows or a
        // coupling, and with the one-forms (if any) in closed form: the rows go straight from
        // the closed forms into the buffers. Inlined into Newton's evaluation; every other
        // step is assembled out of line (`assemble_into`).
        let direct = S::HOLONOMIC == 0
            && (S::ONE_FORMS == 0 || (C::TRANSLATION && S::ONE_FORM_DERIVATIVES))
            && self.closed_pair
            && self.coupling.is_none()
            && self.discrete.one_node();
        if direct {
            let xi = x.fixed_rows::<N>(0).into_owned();
            self.increments[0] = xi;
            let rows = residual.as_mut_slice();
            // Two calls, each with its case known: one code for each (see `closed_one_forms`).
            let scale = match jacobian.as_deref_mut() {
                Some(jacobian) => {
                    self.direct_rows(state, &xi, x, rows, Some(jacobian.as_mut_slice()))
                }
                None => self.direct_rows(state, &xi, x, rows, None),
            };
            if let Some(scale) = scale {
                return scale;
            }
        }
        self.read_increments(x);
        let n = x.len();
        if self.scratch.shape() != (n, n) {
            self.scratch = DMatrix::zeros(n, n);
        }
        let mut scratch = std::mem::take(&mut self.scratch);
        let scale = self.assemble_into(state, x, residual, jacobian, &mut scratch);
        self.scratch = scratch;
        scale
    }

    /// `L` quadratic with constant coefficients (`QUADRATIC`) on a translation chart, its
    /// one-forms constant, its forces (if any) affine with constant coefficients
    /// (`FORCES_AFFINE`), and no holonomic constraint or coupling: every row is linear in the
    /// unknowns with coefficients fixed by `h`.
    fn constant_jacobian(&self) -> bool {
        let system = self.discrete.system();
        S::QUADRATIC
            && C::TRANSLATION
            && S::HOLONOMIC == 0
            && (!S::FORCES || S::FORCES_AFFINE)
            && self.coupling.is_none()
            && (0..S::ONE_FORMS).all(|a| system.one_form_is_constant(a))
    }

    /// A Jacobian takes the hyper-dual Hessian of `L` (about `(N + 1)²` numbers per operation
    /// of `L`; three such passes per node beyond the midpoint rule) where the residual takes one
    /// or two first-order passes (`N + 1` numbers each): `(N + 1)/2` per pass is the cautious
    /// count. Where `L` has closed-form second derivatives (and the model no forces, whose
    /// derivatives are taken by dual numbers) a Jacobian takes the closed-form Hessian where the
    /// residual takes the gradient, at every node alike: up to 4 coordinates, as far as it is
    /// measured (the double pendulum, the knife edge and the rolling disk, midpoint to
    /// `galerkin(3)`: 2 to 3 evaluations a step against 5 to 7 with a kept Jacobian, up to 2.3×
    /// less time), that is about a residual more, `1 + N/5`, and Newton's method; above, where
    /// the factorisation weighs more and nothing is measured, the cautious count stays.
    /// Collocated rows (first-order and mixed Lagrangians) take their Jacobian with their
    /// residual, so there a Jacobian costs about a residual.
    fn jacobian_cost(&self) -> f64 {
        if self.projected() || self.first_order() || !self.collocated.is_empty() {
            return 1.0;
        }
        if self.closed_form && !S::FORCES && N <= 4 {
            return 1.0 + N as f64 / 5.0;
        }
        let passes = if self.layout.points() == 1 { 1.0 } else { 3.0 };
        passes * (N + 1) as f64 / 2.0
    }

    #[inline(always)]
    fn advance(
        &self,
        state: &State<N>,
        x: &DVector<f64>,
        step: u64,
    ) -> Result<State<N>, DiracError> {
        let space = self.discrete.space();
        let system = self.discrete.system();
        let xi = self.end_increment(x);
        let mut next = self.discrete.advanced(
            state,
            &xi,
            &self.increments,
            self.covectors,
            self.covectors_pending,
            false,
            step,
        )?;
        if !self.collocated.is_empty() {
            // The primary constraint p = ϑ(q) on the collocated coordinates.
            let theta = legendre::momentum(system, &next.q, &next.velocity);
            for &d in &self.collocated {
                next.p[d] = theta[d];
                next.p_carry[d] = 0.0;
            }
        }
        check_finite(system, "new position", &next.q)?;
        check_finite(system, "new momentum", &next.p)?;
        next.velocity = space.push_forward(&state.q, &xi, &(xi / self.discrete.h()));
        if self.hidden().count() > 0 {
            let t = state.t + self.discrete.h();
            self.hidden()
                .project(system, &mut next.q, &next.velocity, t, &self.inputs)
                .map_err(|why| DiracError::Projection { step, why })?;
        }
        if S::HOLONOMIC > 0 && self.holonomic_scheme == HolonomicScheme::Rattle {
            self.project_momentum(&mut next, state.t + self.discrete.h(), step)?;
        }
        self.discrete.check_end(&next.q, &next.velocity, step)?;
        Ok(next)
    }

    fn affine_step(
        &mut self,
        state: &State<N>,
        x: &mut DVector<f64>,
        step: u64,
    ) -> Option<Result<State<N>, DiracError>> {
        // Known when the model is compiled: models that cannot have a step map compile none.
        if !Self::MAY_MAP {
            return Some(Err(DiracError::Unsupported(format!(
                "a step map: {}",
                self.refuse_step_map().err().unwrap_or_default()
            ))));
        }
        if let Err(why) = self.refuse_step_map() {
            return Some(Err(DiracError::Unsupported(format!("a step map: {why}"))));
        }
        let claim = |why: &str| {
            DiracError::InconsistentDerivatives(format!(
                "the model claims step equations linear with constant coefficients (QUADRATIC), \
                 but at step {step} the step map cannot be read: {why}"
            ))
        };
        if let Some(why) = &self.affine_refused {
            return Some(Err(claim(why)));
        }
        let mut map = match self.affine.take() {
            None => match self.read_step_map(state, 0) {
                Ok(map) => map,
                Err(why) => {
                    let error = claim(&why);
                    self.affine_refused = Some(why);
                    return Some(Err(error));
                }
            },
            Some(mut map) => match map.serve() {
                None => map,
                Some(reading) => match self.read_step_map(state, reading) {
                    Ok(map) => map,
                    Err(why) => {
                        let error = claim(&format!(
                            "{why}; the steps since step {} may be wrong too",
                            step.saturating_sub(u64::from(affine_step::READ_EVERY))
                        ));
                        self.affine_refused = Some(why);
                        return Some(Err(error));
                    }
                },
            },
        };
        let taken = self.step_by_map(&mut map, state, x, step);
        self.affine = Some(map);
        Some(taken)
    }

    fn step_map_refusal(&self) -> Result<(), String> {
        self.refuse_step_map()
    }

    fn fixed_point_step(
        &mut self,
        state: &State<N>,
        x: &mut DVector<f64>,
        tolerance: f64,
    ) -> Option<Result<NewtonReport, String>> {
        // Known when the model is compiled: models that cannot be iterated compile no iteration.
        // A run whose kinetic terms refused it was handed over at its first step; its later
        // steps are Newton's without a word.
        if !Self::MAY_ITERATE
            || self.refuse_fixed_point().is_err()
            || self.iteration_refused.is_some()
        {
            return None;
        }
        Some(match Self::ITERATES_TABLES {
            true => self.iterate(state, x, tolerance),
            false => self.iterate_on_rows(state, x, tolerance),
        })
    }

    fn fixed_point_refusal(&self) -> Result<(), String> {
        self.refuse_fixed_point()
    }

    fn violation(&self, from: &State<N>, to: &State<N>, x: &DVector<f64>) -> f64 {
        if !Self::constrained() {
            return 0.0;
        }
        let (space, system) = (self.discrete.space(), self.discrete.system());
        let xi = self.end_increment(x);
        if S::ONE_FORMS > 0 && self.layout.points() > 1 {
            // Measured with the stored end point (after any projection).
            let s = self.layout.points();
            // The path of the point `x`, its end the stored one; on the stack.
            let mut path = [SVector::<f64, N>::zeros(); MAX_DEGREE];
            for (j, point) in path[..s].iter_mut().enumerate() {
                *point = x.fixed_rows::<N>(self.layout.point(j + 1)).into_owned();
            }
            path[s - 1] = space.local(&from.q, &to.q).unwrap_or(xi);
            let h = self.discrete.h();
            let quadrature = self.discrete.quadrature();
            constraint::node_violation(system, quadrature, h, &from.q, &path[..s])
        } else {
            constraint::violation(system, space, self.point, &from.q, &to.q, &xi)
        }
    }

    fn first_multiplier(&self) -> usize {
        self.layout.multipliers()
    }

    fn unknown_name(&self, column: usize) -> String {
        self.layout.name(column, &|i| self.coordinate_name(i))
    }

    /// `N`, plus one multiplier per constraint on the velocity for a constrained model or one
    /// with hidden constraints.
    fn velocity_unknowns(&self) -> usize {
        N + S::ONE_FORMS + S::HOLONOMIC + self.hidden().count()
    }

    /// The Legendre inversion; for a constrained model (or one with hidden constraints), the
    /// velocity the constraints allow whose momentum differs from `p` by a constraint impulse,
    /// solving `∂L/∂v(q, v) = p + Cᵀν`, `C v = 0`: `A(q) v = 0`, `dg(q) v = 0`, `dc(q) v = 0`.
    /// Degenerate rows that are first-order equations (a resistor beside a capacitor) fix their
    /// coordinates' velocities at `(q, t)` instead (see `legendre::constrained_velocity`).
    fn velocity(
        &self,
        newton: &mut Newton,
        t: f64,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        guess: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, NewtonFailure> {
        let system = self.discrete.system();
        let run = self
            .hidden
            .as_ref()
            .filter(|hidden| hidden.matches(system, q, guess));
        self.velocity_with_multipliers(newton, t, q, p, guess, run)
            .map(|solved| solved.velocity)
    }

    /// As [`velocity`](StepEquations::velocity), with the run's degenerate coordinates and hidden
    /// constraints as found when it began (not checked again at the state).
    fn velocity_in_run(
        &self,
        newton: &mut Newton,
        t: f64,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        guess: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, NewtonFailure> {
        self.velocity_and_energy_in_run(newton, t, q, p, guess)
            .map(|(velocity, _)| velocity)
    }

    /// The plain Legendre inversion's chord step (no constraints, kinetic energy in every
    /// velocity) brings the energy with it.
    fn velocity_and_energy_in_run(
        &self,
        newton: &mut Newton,
        t: f64,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        guess: &SVector<f64, N>,
    ) -> Result<(SVector<f64, N>, Option<f64>), NewtonFailure> {
        if let Some(hidden) = &self.hidden
            && let Some(solved) = self.unconstrained_velocity(newton, q, p, guess, hidden)
        {
            return solved;
        }
        self.velocity_with_multipliers(newton, t, q, p, guess, self.hidden.as_ref())
            .map(|solved| (solved.velocity, solved.energy))
    }

    /// The forces' work along the step's path; the constraints' from their impulse on a
    /// degree-1 step that no projection follows (see [`StepWork`]). First-order and projected
    /// steps have no forces (refused when the run begins): no work, the constraints' unknown.
    fn work(&self, state: &State<N>, x: &DVector<f64>) -> Option<StepWork<N>> {
        if self.projected() || self.first_order() {
            return (!S::FORCES).then(|| StepWork {
                forces: SVector::zeros(),
                constraints: None,
            });
        }
        let forces = if S::FORCES {
            self.discrete
                .force_work(&state.q, &self.increments, state.t, &self.inputs)
        } else {
            SVector::zeros()
        };
        let single = self.discrete.quadrature().degree() == 1
            && self.hidden().count() == 0
            && !(S::HOLONOMIC > 0 && self.holonomic_scheme == HolonomicScheme::Rattle);
        let constraints = single.then(|| {
            let xi = self.end_increment(x);
            self.constraint_impulse.component_mul(&xi) / self.discrete.h()
        });
        Some(StepWork {
            forces,
            constraints,
        })
    }

    fn energy(&self, q: &SVector<f64, N>, _p: &SVector<f64, N>, v: &SVector<f64, N>) -> f64 {
        legendre::energy(self.discrete.system(), q, v)
    }

    fn momentum(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, DiracError> {
        let system = self.discrete.system();
        check_finite(system, "initial position", q)?;
        check_finite(system, "initial velocity", v)?;
        let p = legendre::momentum(system, q, v);
        check_finite(system, "initial momentum", &p)?;
        Ok(p)
    }

    fn check_finite(
        &self,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        guess: &SVector<f64, N>,
    ) -> Result<(), DiracError> {
        let system = self.discrete.system();
        check_finite(system, "initial position", q)?;
        check_finite(system, "initial momentum", p)?;
        check_finite(system, "velocity guess", guess)
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

    /// By the implicit function theorem on the step's rows `R(x; q_k, p_k, u) = 0` with
    /// `x = [ξ_1..ξ_s, μ, λ]` and Newton's factorised KKT matrix `J = ∂R/∂x`:
    /// `∂x/∂z = −J⁻¹ ∂R/∂z` for `z = (q_k, p_k, u)`. With `G_jm = ∂(∂L_d/∂ξ_j + f_j)/∂ξ_m`
    /// (`j, m = 0..=s`), moving `q_k` at fixed `ξ` moves every point of the step, so the
    /// Euler–Lagrange rows have `∂R_j/∂q_k = Σ_m G_jm`; row 0 also carries the constraint
    /// impulses `σ A(q_c)ᵀμ + dg(q_k)ᵀλ`, whose `q_k`-derivatives are `σ Σ μ_a ∂A_a` and
    /// `Σ λ_b ∂²g_b`; the one-form rows `A(q_c) ξ_s` give `ξ_sᵀ ∂A_a`, the holonomic rows
    /// `g(q_k + ξ_s)` give `dg`; `∂R_0/∂p_k = I`; the inputs enter through the forces,
    /// `∂R_j/∂u = ∂f_j/∂u`. Then `q_{k+1} = q_k + ξ_s` and
    /// `p_{k+1} = ∂L_d/∂ξ_s + f_s + (1 − σ) A(q_c)ᵀμ` are differentiated along. On `Rⁿ`;
    /// other spaces are refused with `Unsupported`.
    fn linearise(
        &self,
        state: &State<N>,
        x: &DVector<f64>,
        newton: &Newton,
    ) -> Result<StepDerivatives<N>, DiracError> {
        let Sensitivity {
            g,
            dx,
            force_u,
            end_rows,
            end_turning,
            theta,
            inputs,
            ..
        } = self.sensitivity(state, x, newton)?;
        if S::HOLONOMIC > 0 && self.holonomic_scheme == HolonomicScheme::Rattle {
            return Err(DiracError::Unsupported(
                "derivatives of the step map through RATTLE's momentum projection (use \
                 HolonomicScheme::Shake, which gives the same positions)"
                    .into(),
            ));
        }
        let layout = &self.layout;
        let s = layout.points();
        // The end point is projected along Z onto c = 0: dq ← (I − Z (dc Z)⁻¹ dc) dq, exact where
        // dc and Z are (constant forms, degenerate rows without velocities).
        let projection = if self.hidden().count() > 0 {
            if !self.hidden().is_fixed() {
                return Err(DiracError::Unsupported(
                    "derivatives of the step map through the projection onto hidden constraints \
                     whose constraint forms vary or whose rows contain velocities"
                        .into(),
                ));
            }
            let xi = x.fixed_rows::<N>(layout.end_point()).into_owned();
            let (h, end) = (self.discrete.h(), state.q + xi);
            let e = self
                .hidden()
                .evaluate(
                    self.discrete.system(),
                    &end,
                    &(xi / h),
                    state.t + h,
                    &self.inputs,
                )
                .map_err(DiracError::Unsupported)?;
            let free = e.free();
            let reduced = (&e.differential * free).try_inverse().ok_or_else(|| {
                DiracError::Unsupported(
                    "derivatives through a projection whose free directions do not move the \
                     hidden constraints"
                        .into(),
                )
            })?;
            let projector = free * reduced * &e.differential;
            Some(SMatrix::<f64, N, N>::from_fn(|i, j| projector[(i, j)]))
        } else {
            None
        };
        // p_{k+1} = ∂L_d/∂ξ_s + f_s + (1 − σ) A(q_c)ᵀμ moves with q_k at fixed points by
        // `Σ_m G_sm` and the end impulse's turning, and with point m by `G_sm` (q_c moves with
        // the end point by θ).
        let end_moving = g.row_sum(s) + end_turning;
        let mut end_blocks = [SMatrix::<f64, N, N>::zeros(); MAX_DEGREE];
        for (m, block) in end_blocks.iter_mut().take(s).enumerate() {
            *block = g.row(s)[m + 1];
        }
        end_blocks[s - 1] += end_turning * theta;
        let mut derivatives = StepDerivatives::<N>::zeros(inputs, newton.pivot_ratio());
        // Column by column (q_k, p_k, u): fixed-size products, no allocation.
        for c in 0..2 * N + inputs {
            // q_{k+1} = q_k + ξ_s.
            let mut dq = dx.fixed_view::<N, 1>(layout.end_point(), c).into_owned();
            let mut dp = SVector::<f64, N>::zeros();
            if c < N {
                dq[c] += 1.0;
                dp += end_moving.column(c);
            } else if c >= 2 * N
                && let Some(force) = force_u.get(s)
            {
                dp += force.column(c - 2 * N);
            }
            if let Some(projector) = &projection {
                dq -= projector * dq;
            }
            for (m, block) in end_blocks.iter().take(s).enumerate() {
                dp += block * dx.fixed_view::<N, 1>(layout.point(m + 1), c);
            }
            for (a, row) in end_rows.iter().enumerate() {
                dp += row * dx[(layout.one_form(a), c)];
            }
            derivatives.set_column(c, &dq, &dp);
        }
        derivatives.finite()
    }
}

/// What [`EulerLagrange::linearise`](StepEquations::linearise) and the second derivatives share:
/// the slot Hessian `G_jm` (forces included; its row sums are how `q_k`, moving every point,
/// moves each row), the step's points, the unknowns' derivatives `dx` (columns `q_k`, `p_k`,
/// `u`), and the end point's constraint terms.
struct Sensitivity<const N: usize> {
    g: SlotBlocks<N>,
    dx: DMatrix<f64>,
    /// The step's points `ξ_1..ξ_s` (first `s` entries).
    points: [SVector<f64, N>; MAX_DEGREE],
    force_u: Vec<DMatrix<f64>>,
    /// `(1 − σ) A_a(q_c)`: the end point's share of each one-form impulse direction.
    end_rows: Vec<SVector<f64, N>>,
    /// `(1 − σ) Σ_a μ_a ∂A_a(q_c)`.
    end_turning: SMatrix<f64, N, N>,
    theta: f64,
    inputs: usize,
}

/// A velocity, with the energy there where the solve that found it gives it.
type VelocityAndEnergy<const N: usize> = (SVector<f64, N>, Option<f64>);

/// The error for derivatives asked of a Newton solver that does not hold the factorisation at
/// the solution (no solve, a failed one since, or another point).
pub(crate) fn stale_factorisation() -> DiracError {
    DiracError::Dimension(
        "the Newton solver does not hold the factorisation at this solution (take the \
         derivatives right after the solve that produced it)"
            .into(),
    )
}

/// An inverted Legendre transform: the velocity, the constraints' multipliers `ν` (none for the
/// plain inversion), and the energy where the solve gave it on its way.
struct Legendre<const N: usize> {
    velocity: SVector<f64, N>,
    multipliers: DVector<f64>,
    energy: Option<f64>,
}

impl<const N: usize> Legendre<N> {
    fn plain(velocity: SVector<f64, N>, energy: Option<f64>) -> Self {
        Self {
            velocity,
            multipliers: DVector::zeros(0),
            energy,
        }
    }

    fn constrained((velocity, multipliers): (SVector<f64, N>, DVector<f64>)) -> Self {
        Self {
            velocity,
            multipliers,
            energy: None,
        }
    }
}

/// `Err(NonFinite)` naming the first coordinate of `x` that is not finite.
#[inline]
pub(crate) fn check_finite<S: DiracSystem<N>, const N: usize>(
    system: &S,
    what: &str,
    x: &SVector<f64, N>,
) -> Result<(), DiracError> {
    if x.as_slice().iter().all(|v| v.is_finite()) {
        return Ok(());
    }
    not_finite(system, what, x)
}

/// The error of [`check_finite`], off every step's path.
#[cold]
fn not_finite<S: DiracSystem<N>, const N: usize>(
    system: &S,
    what: &str,
    x: &SVector<f64, N>,
) -> Result<(), DiracError> {
    let i = x.iter().position(|v| !v.is_finite()).unwrap_or(0);
    Err(DiracError::NonFinite {
        what: format!("{what} of {}", system.coordinate_name(i)),
        value: x[i],
    })
}

/// `newton` if it is sized for `n` unknowns, else a solver with its options sized for `n`, kept
/// in `spare` (the stepper sizes the velocity solver for the run's constraints; a state before
/// the run, or a model whose rows are first-order equations, has others).
fn sized<'a>(
    newton: &'a mut Newton,
    n: usize,
    spare: &'a mut Option<Newton>,
) -> Result<&'a mut Newton, NewtonFailure> {
    if newton.unknowns() == n {
        return Ok(newton);
    }
    let fresh = Newton::new(n, *newton.options()).map_err(|_| NewtonFailure::Dimension {
        expected: n,
        got: newton.unknowns(),
    })?;
    Ok(spare.insert(fresh))
}
