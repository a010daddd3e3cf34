//! The stepper: drives the [`StepEquations`] of a model with Newton's method on the exact
//! Jacobian, one step at a time. For a Lagrangian model these are the discrete Euler–Lagrange
//! equations in position–momentum form ([`EulerLagrange`]),
//!
//! ```text
//! p_k + D_1 L_d(q_k, q_{k+1}) = 0          (solved for q_{k+1} and the internal points)
//! p_{k+1} = D_2 L_d(q_k, q_{k+1})
//! ```
//!
//! A failed step returns an error and changes nothing. Runs over a time span, with saved
//! times, events and an observer, are in `stepper/integrate.rs` ([`Stepper::solve`]).

use std::marker::PhantomData;

mod balance;
mod integrate;

use nalgebra::{DVector, SVector};

use crate::base::error::DiracError;
use crate::base::first_order_scheme::FirstOrderScheme;
use crate::base::holonomic_scheme::HolonomicScheme;
use crate::base::input::Input;
use crate::discrete::constraint::ConstraintPoint;
use crate::discrete::discrete_lagrangian::DiscreteLagrangian;
use crate::integrate::trajectory::{Metadata, Trajectory};
use crate::model::hamiltonian_system::HamiltonianSystem;
use crate::model::legendre;
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;
use crate::solve::newton::{Newton, NewtonFailure, NewtonOptions, NewtonReport};
use crate::solve::predictor::Predictor;
use crate::space::configuration_space::{ConfigurationSpace, Euclidean};
use crate::space::manifold::{Manifold, Vectors};
use crate::step::composition::Composition;
use crate::step::euler_lagrange::{EulerLagrange, check_finite};
use crate::step::group_euler_lagrange::GroupEulerLagrange;
use crate::step::hamilton::Hamilton;
use crate::step::step_derivatives::{StepDerivatives, StepHessians};
use crate::step::step_equations::{Point, State, StepEquations, StepWork, Tangent};
use crate::step::verlet::{ExplicitSystem, Verlet};

/// The relative consistency an initial state must have with the model's constraints, at the
/// default solver tolerance.
const START_TOLERANCE: f64 = 1e-9;

/// Which solve a Newton failure comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Problem {
    /// The step equations.
    Step,
    /// The velocity at a state (the Legendre inversion).
    Velocity,
}

/// How a [`Stepper`]'s steps are solved ([`Stepper::solver`]). More ways may come: a `match`
/// needs a wildcard arm.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Solver {
    /// In closed form: an explicit step has no equations to solve.
    Explicit,
    /// By the step map of equations linear with constant coefficients, read off the step
    /// ([`Stepper::with_step_map`]): a matrix–vector product a step.
    StepMap,
    /// By fixed-point iteration without a Jacobian ([`Stepper::with_fixed_point`]), Newton's
    /// method where it does not settle.
    FixedPoint,
    /// By Newton's method, for the reason given (why there is no step map).
    Newton(String),
}

/// A solved step, not yet current: the new state and how Newton went.
#[derive(Debug, Clone, Copy)]
struct Proposal<const N: usize, M: Manifold<N>> {
    next: State<N, M>,
    report: NewtonReport,
    /// The step's work, where the equations know it.
    work: Option<StepWork<N>>,
}

/// A variational integrator for one system, one quadrature and one step size: Newton's method on
/// the model's [`StepEquations`] (`E`, the discrete Euler–Lagrange equations on `Rⁿ` unless
/// chosen otherwise).
///
/// Each step of a Lagrangian model solves for the chart coordinates `ξ_j` of the `s` points of
/// the step (the internal points and `q_{k+1}`) in the chart centred at `q_k`; on `Rⁿ` these are
/// the increments `Q_j − q_k`, so velocities carry no cancellation. On `Rⁿ` the momentum is
/// advanced by the impulse `Σ_j ∂L_d/∂Q_j = h Σ_i b_i ∂_q L`, which equals `D_2 L_d` at the
/// solution; both updates are compensated sums.
///
/// ```
/// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
///
/// struct Oscillator { m: f64, k: f64 }
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * (0.5 * self.m) - q[0] * q[0] * (0.5 * self.k)
///     }
/// }
///
/// let mut stepper = Stepper::new(Oscillator { m: 1.0, k: 0.5 }, Quadrature::galerkin(2)?, 0.1)?;
/// stepper.start_from_momentum(vector![0.5], vector![0.0])?;
/// let trajectory = stepper.run(10)?;
/// let exact = 0.5 * 0.5_f64.sqrt().cos();
/// assert!((trajectory.q()[10][0] - exact).abs() < 1e-6);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Stepper<S, const N: usize, E: StepEquations<N> = EulerLagrange<S, N, Euclidean>> {
    equations: E,
    newton: Newton,
    /// The workspaces of the velocity solves of recorded samples (reused: no allocation per
    /// sample).
    velocity: VelocitySolver,
    state: Option<State<N, E::Manifold>>,
    /// The state the last step started from (none before the first step of a run).
    before: Option<State<N, E::Manifold>>,
    /// The time the next start from a position, velocity or momentum begins at.
    initial_time: f64,
    /// Time of the initial state.
    start: f64,
    /// The initial state, which the equations examined when the run began.
    origin: Option<State<N, E::Manifold>>,
    steps: u64,
    /// Newton unknowns (the iterate), laid out by the equations.
    unknowns: DVector<f64>,
    /// The unknowns of the last accepted steps, extrapolated into the next step's predictor.
    predictor: Predictor,
    report: Option<NewtonReport>,
    /// Constraint violation of the last step where it is settled (0 at a start; measured
    /// before the equations' settings change), else measured on request from `before`, `state`
    /// and the predictor's last solution: a step does not pay for it.
    violation: Option<f64>,
    /// Multipliers of the last step (zeros before the first).
    multipliers: Vec<f64>,
    /// The work done since the start by the forces and inputs and by the constraints, summed
    /// over the steps ([`StepWork`]); `None` once a step's work is unknown.
    work: Option<StepWork<N>>,
    /// Steps are taken by the step map ([`with_step_map`](Self::with_step_map)).
    step_map: bool,
    /// Steps are solved by fixed-point iteration ([`with_fixed_point`](Self::with_fixed_point)).
    fixed_point: bool,
    /// The steps of the run that the fixed-point iteration handed to Newton's method, and why
    /// the last one was.
    handed_over: (u64, Option<String>),
    /// Why the step being solved was handed over (taken into `handed_over` when it is accepted).
    handing_over: Option<String>,
    system: PhantomData<fn() -> S>,
}

impl<S: DiracSystem<N>, const N: usize> Stepper<S, N> {
    /// A stepper for `system` on `Rⁿ` with `quadrature` and step `h`. Fails on a non-positive
    /// or non-finite step, a non-finite parameter, or a constrained system with a quadrature of
    /// degree above 1 (constraints are imposed on the step's end points only).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let stepper = Stepper::new(Oscillator, Quadrature::galerkin(2)?, 0.1)?;
    /// assert_eq!((stepper.h(), stepper.quadrature().name()), (0.1, "galerkin(2)".to_string()));
    /// assert!(Stepper::new(Oscillator, Quadrature::midpoint(), -0.1).is_err());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn new(system: S, quadrature: Quadrature, h: f64) -> Result<Self, DiracError> {
        Self::on_space(system, Euclidean, quadrature, h)
    }

    /// A stepper with the system's own quadrature (the one named in `#[dirac_system]`). A model
    /// whose attribute names an explicit step (`quadrature = explicit(...)`) is refused with
    /// `InvalidQuadrature`, naming [`explicit_from_system`](Stepper::explicit_from_system).
    ///
    /// ```
    /// # use dirac_runtime::{DiracError, DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::SVector;
    /// struct Oscillator;
    /// impl DiracSystem<1> for Oscillator {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn quadrature(&self) -> Result<Quadrature, DiracError> {
    ///         Quadrature::galerkin(3)
    ///     }
    /// }
    /// let stepper = Stepper::from_system(Oscillator, 0.1)?;
    /// assert_eq!(stepper.quadrature().name(), "galerkin(3)");
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn from_system(system: S, h: f64) -> Result<Self, DiracError> {
        let quadrature = system.quadrature()?;
        Self::new(system, quadrature, h)
    }
}

impl<S: HamiltonianSystem<N>, const N: usize> Stepper<S, N, Hamilton<S, N>> {
    /// A stepper for a model given by its Hamiltonian, on the discrete Hamiltonian route
    /// ([`Hamilton`]: the Galerkin discrete Hamiltonian `H_d⁺` of `quadrature`) with step `h`.
    /// Fails as [`Hamilton::new`] does.
    ///
    /// ```
    /// use dirac_runtime::{HamiltonianSystem, Quadrature, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// /// A pendulum, H = p²/2 − cos q.
    /// struct Pendulum;
    /// impl HamiltonianSystem<1> for Pendulum {
    ///     fn hamiltonian<D: Scalar>(&self, q: &SVector<D, 1>, p: &SVector<D, 1>) -> D {
    ///         p[0] * p[0] * 0.5 - q[0].cos()
    ///     }
    /// }
    /// let mut stepper = Stepper::hamiltonian(Pendulum, Quadrature::midpoint(), 0.01)?;
    /// stepper.start_from_momentum(vector![1.0], vector![0.0])?;
    /// let trajectory = stepper.run(1000)?;
    /// assert!(trajectory.max_energy_error() < 1e-4);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn hamiltonian(system: S, quadrature: Quadrature, h: f64) -> Result<Self, DiracError> {
        Self::with_equations(Hamilton::new(system, quadrature, h)?)
    }

    /// A stepper with the system's own quadrature (the one named in `#[dirac_system]`), on the
    /// discrete Hamiltonian route.
    pub fn hamiltonian_from_system(system: S, h: f64) -> Result<Self, DiracError> {
        let quadrature = system.quadrature()?;
        Self::hamiltonian(system, quadrature, h)
    }

    /// The quadrature of the phase-space action.
    pub fn quadrature(&self) -> &Quadrature {
        self.equations.quadrature()
    }
}

impl<S: DiracSystem<N>, const N: usize> Stepper<S, N, Verlet<S, N>> {
    /// An explicit stepper for a separable model ([`DiracSystem::SEPARABLE`]): Störmer–Verlet
    /// or one of its symmetric compositions ([`Verlet`]), one gradient of the potential per
    /// stage and no Newton iteration. Refused (`Unsupported`) for a model not known to be
    /// separable, with constraints, or with forces that may read the velocity; a singular mass
    /// matrix is refused at the start.
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracSystem, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// struct Pendulum;
    /// impl DiracSystem<1> for Pendulum {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5 + q[0].cos()
    ///     }
    /// }
    /// let mut stepper = Stepper::explicit(Pendulum, Composition::of_order(6)?, 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// let e0 = stepper.energy()?;
    /// stepper.run(1000)?;
    /// assert!((stepper.energy()? - e0).abs() < 1e-9);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn explicit(system: S, composition: Composition, h: f64) -> Result<Self, DiracError> {
        Self::with_equations(Verlet::new(system, composition, h)?)
    }

    /// The explicit stepper of the composition the model's attribute names
    /// (`quadrature = explicit(...)`, [`ExplicitSystem`]), with step `h`; refused as
    /// [`explicit`](Self::explicit) is. [`Stepper::from_system`] refuses such a model, naming
    /// this constructor.
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracSystem, ExplicitSystem, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// struct Oscillator;
    /// impl DiracSystem<1> for Oscillator {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    /// }
    /// impl ExplicitSystem<1> for Oscillator {
    ///     fn composition(&self) -> Composition {
    ///         Composition::kahan_li_8()
    ///     }
    /// }
    /// let mut stepper = Stepper::explicit_from_system(Oscillator, 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run(10)?;
    /// assert!((stepper.q()[0] - 1f64.cos()).abs() < 1e-11);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn explicit_from_system(system: S, h: f64) -> Result<Self, DiracError>
    where
        S: ExplicitSystem<N>,
    {
        let composition = system.composition();
        Self::explicit(system, composition, h)
    }

    /// The composition the stepper takes.
    pub fn composition(&self) -> &Composition {
        self.equations.composition()
    }
}

impl<S: DiracSystem<N>, C: ConfigurationSpace<N, Manifold = Vectors>, const N: usize>
    Stepper<S, N, EulerLagrange<S, N, C>>
{
    /// [`step_linearised`](Self::step_linearised) in positions and velocities: advances one
    /// step and returns `A = ∂(q_{k+1}, v_{k+1})/∂(q_k, v_k)` and `B = ∂(q_{k+1}, v_{k+1})/∂u`
    /// (the blocks named `p` read `v`; see [`StepDerivatives::in_velocities`]), for a feedback on
    /// the velocities without rescaling momentum weights. Refused with `Unsupported`, the state
    /// unchanged, for a constrained model (its velocity is solved with the constraints'
    /// multipliers, not from `p = ∂L/∂v` alone) and where `∂²L/∂v²` is singular at the step's
    /// end (a degenerate Lagrangian); it exists on `Rⁿ` and its charts.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// A mass 2 on a unit spring: p = 2v.
    /// #[derive(Clone)]
    /// struct Heavy;
    /// impl DiracSystem<1> for Heavy {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] - q[0] * q[0] * 0.5
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Heavy, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// let in_momenta = stepper.clone().step_linearised()?;
    /// let in_velocities = stepper.step_linearised_in_velocities()?;
    /// // ∂q_{k+1}/∂v_k = ∂q_{k+1}/∂p_k · ∂p/∂v = 2 ∂q_{k+1}/∂p_k.
    /// assert!((in_velocities.q_p[(0, 0)] - 2.0 * in_momenta.q_p[(0, 0)]).abs() < 1e-15);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn step_linearised_in_velocities(&mut self) -> Result<StepDerivatives<N>, DiracError> {
        let Some(state) = self.state else {
            return Err(DiracError::NotStarted);
        };
        if !self.multipliers.is_empty() {
            return Err(DiracError::Unsupported(
                "derivatives of the step map in (q, v) of a constrained model (its velocity \
                 comes with the constraints' multipliers): take them in (q, p) with \
                 step_linearised"
                    .into(),
            ));
        }
        let legendre = |system: &S, q: &SVector<f64, N>, v: &SVector<f64, N>| {
            let h = crate::model::derivatives::hessian(system, q, v);
            (h.qv.transpose(), h.vv)
        };
        let v = self.v()?;
        let start = legendre(self.equations.system(), &state.q, &v);
        let proposal = self.solve_step_at_root()?;
        let at = self.factorise_at_root()?;
        let derivatives = self
            .equations
            .linearise(&at, &self.unknowns, &self.newton)?;
        let next = proposal.next;
        let v_next = self.velocity_at(next.t, &next.q, &next.p, &next.velocity, true)?;
        let end = legendre(self.equations.system(), &next.q, &v_next);
        let in_velocities = derivatives
            .in_velocities((&start.0, &start.1), (&end.0, &end.1))
            .ok_or_else(|| {
                DiracError::Unsupported(
                    "derivatives of the step map in (q, v) where ∂²L/∂v² is singular (a \
                     degenerate Lagrangian): take them in (q, p) with step_linearised"
                        .into(),
                )
            })?;
        self.accept(proposal);
        Ok(in_velocities)
    }

    /// A stepper for `system` whose steps work in the charts of `space` (see
    /// [`configuration_space`](crate::space::configuration_space)); otherwise as [`Stepper::new`].
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// use dirac_runtime::Positive;
    /// // Every point of every step stays positive.
    /// let mut stepper = Stepper::on_space(Oscillator, Positive, Quadrature::galerkin(2)?, 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run(10)?;
    /// assert!((stepper.q()[0] - 1.0_f64.cos()).abs() < 1e-5); // order 4
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn on_space(
        system: S,
        space: C,
        quadrature: Quadrature,
        h: f64,
    ) -> Result<Self, DiracError> {
        let discrete = DiscreteLagrangian::on_space(system, space, quadrature, h);
        Self::with_equations(EulerLagrange::new(discrete)?)
    }

    /// Evaluates the constraint one-forms at `point` of each step instead of the system's default.
    ///
    /// ```
    /// # use dirac_runtime::{ConstraintPoint, DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// A knife edge in the plane: it moves only along its heading, sin φ ẋ − cos φ ẏ = 0.
    /// struct KnifeEdge;
    /// impl DiracSystem<3> for KnifeEdge {
    ///     const ONE_FORMS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * 0.5
    ///     }
    ///     fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, _a: usize) -> SVector<D, 3> {
    ///         SVector::from([q[2].sin(), -q[2].cos(), D::from(0.0)])
    ///     }
    /// }
    /// let stepper = Stepper::new(KnifeEdge, Quadrature::midpoint(), 0.1)?
    ///     .with_constraint_point(ConstraintPoint::Start);
    /// assert_eq!(stepper.constraint_point(), ConstraintPoint::Start);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_constraint_point(mut self, point: ConstraintPoint) -> Self {
        self.settle_violation();
        self.equations.set_constraint_point(point);
        // The constraint rows change: a Jacobian kept for linear equations no longer fits.
        self.newton.forget_jacobian();
        self
    }

    /// Starts a Lagrangian linear in the velocities, `L = ϑ(q)·v − H(q)`, from its position
    /// alone at the [start time](Self::with_start_time): its momentum is `ϑ(q0)` and its velocity solves its first-order
    /// equations `(ϑ'ᵀ − ϑ') v = ∇H`. Fails for a model with kinetic energy (whose state needs a
    /// velocity or momentum too) or with constraints.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// /// A particle in the plane in a unit magnetic field, without mass: it drifts along the
    /// /// level sets of the potential, q̇ = (−∂V/∂y, ∂V/∂x) with V = (x² + y²)/2.
    /// struct Drift;
    /// impl DiracSystem<2> for Drift {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
    ///         (q[0] * v[1] - q[1] * v[0]) * 0.5 - (q[0] * q[0] + q[1] * q[1]) * 0.5
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Drift, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_position(vector![1.0, 0.0])?;
    /// assert!((stepper.v()? - vector![0.0, 1.0]).amax() < 1e-14);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn start_from_position(&mut self, q0: SVector<f64, N>) -> Result<(), DiracError> {
        check_finite(self.system(), "initial position", &q0)?;
        let zero = SVector::zeros();
        if !crate::discrete::first_order::is_first_order(self.system(), &q0, &zero) {
            return Err(DiracError::InconsistentInitialState(
                "the position alone is the state of a Lagrangian linear in the velocities \
                 without constraints; this model needs a velocity or a momentum too"
                    .into(),
            ));
        }
        let theta = legendre::momentum(self.system(), &q0, &zero);
        let t0 = self.initial_time;
        let v0 = self.velocity_at(t0, &q0, &theta, &zero, false)?;
        let p0 = legendre::momentum(self.system(), &q0, &v0);
        check_finite(self.system(), "initial momentum", &p0)?;
        self.start_from_state(State::new(t0, q0, p0, v0))
    }

    /// Advances one step and returns the first and second derivatives of the step map at the
    /// state it started from (see [`StepHessians`]); for models on `Rⁿ` without constraints
    /// (with forces and inputs), others are refused with `Unsupported`. On error the state is
    /// unchanged.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// let (first, second) = stepper.step_second_order()?;
    /// // A linear model: the step map is linear, its second derivatives vanish.
    /// assert!(first.symplecticity_defect() < 1e-14);
    /// assert!(second.q.iter().chain(&second.p).all(|h| h.amax() < 1e-12));
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn step_second_order(
        &mut self,
    ) -> Result<(StepDerivatives<N>, StepHessians<N>), DiracError> {
        let proposal = self.solve_step_at_root()?;
        let state = self.factorise_at_root()?;
        let first = self
            .equations
            .linearise(&state, &self.unknowns, &self.newton)?;
        let second = self
            .equations
            .second_derivatives(&state, &self.unknowns, &self.newton)?;
        self.accept(proposal);
        Ok((first, second))
    }

    /// Chooses what a step does with the momentum of a model with holonomic constraints
    /// (default [`HolonomicScheme::Shake`]).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, HolonomicScheme, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// A pendulum in Cartesian coordinates: x² + y² = 1.
    /// struct Pendulum;
    /// impl DiracSystem<2> for Pendulum {
    ///     const HOLONOMIC: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1]) * 0.5 - q[1]
    ///     }
    ///     fn holonomic<D: Scalar>(&self, q: &SVector<D, 2>, _b: usize) -> D {
    ///         q[0] * q[0] + q[1] * q[1] - 1.0
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Pendulum, Quadrature::midpoint(), 0.01)?
    ///     .with_holonomic_scheme(HolonomicScheme::Rattle);
    /// stepper.start_from_velocity(vector![1.0, 0.0], vector![0.0, 0.0])?;
    /// stepper.run(100)?;
    /// assert!((stepper.q().norm() - 1.0).abs() < 1e-12);
    /// // RATTLE keeps the velocity tangent to the circle too.
    /// assert!(stepper.q().dot(&stepper.v()?).abs() < 1e-10);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_holonomic_scheme(mut self, scheme: HolonomicScheme) -> Self {
        self.equations.set_holonomic_scheme(scheme);
        self
    }

    /// Chooses which step a Lagrangian linear in the velocities is advanced by (default
    /// [`FirstOrderScheme::Collocation`]); taken up by the next start.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, FirstOrderScheme, Quadrature, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// /// Lotka–Volterra, L = ϑ(q)·v − H(q) with ϑ = (ln q2 / q1, 0).
    /// struct LotkaVolterra;
    /// impl DiracSystem<2> for LotkaVolterra {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
    ///         q[1].ln() / q[0] * v[0] - (q[0] + q[1] - q[0].ln() - q[1].ln() * 2.0)
    ///     }
    /// }
    /// let h = |q: &SVector<f64, 2>| q[0] + q[1] - q[0].ln() - 2.0 * q[1].ln();
    /// let mut stepper = Stepper::new(LotkaVolterra, Quadrature::galerkin(2)?, 0.05)?
    ///     .with_first_order_scheme(FirstOrderScheme::SymmetricProjection);
    /// let q0 = vector![2.0, 1.0];
    /// stepper.start_from_position(q0)?;
    /// stepper.run(200)?;
    /// assert!((h(&stepper.q()) - h(&q0)).abs() < 1e-5);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_first_order_scheme(mut self, scheme: FirstOrderScheme) -> Self {
        self.settle_violation();
        self.equations.set_first_order_scheme(scheme);
        self
    }

    /// Where the constraint one-forms are evaluated on a step.
    ///
    /// ```
    /// # use dirac_runtime::{ConstraintPoint, DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// A knife edge in the plane: it moves only along its heading, sin φ ẋ − cos φ ẏ = 0.
    /// struct KnifeEdge;
    /// impl DiracSystem<3> for KnifeEdge {
    ///     const ONE_FORMS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * 0.5
    ///     }
    ///     fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, _a: usize) -> SVector<D, 3> {
    ///         SVector::from([q[2].sin(), -q[2].cos(), D::from(0.0)])
    ///     }
    /// }
    /// let stepper = Stepper::new(KnifeEdge, Quadrature::midpoint(), 0.1)?;
    /// assert_eq!(stepper.constraint_point(), ConstraintPoint::Midpoint);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn constraint_point(&self) -> ConstraintPoint {
        self.equations.constraint_point()
    }

    /// The configuration space whose charts the steps work in.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// use dirac_runtime::Euclidean;
    /// let stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// assert_eq!(stepper.space(), &Euclidean);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn space(&self) -> &C {
        self.equations.discrete().space()
    }

    /// The quadrature.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let stepper = Stepper::new(Oscillator, Quadrature::galerkin(2)?, 0.1)?;
    /// assert_eq!(stepper.quadrature().degree(), 2);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn quadrature(&self) -> &Quadrature {
        self.equations.discrete().quadrature()
    }
}

/// A [`Stepper`] of a model on rotations and unit vectors whose steps work in the charts of `C`
/// (see [`Stepper::on_manifold`]).
pub type ManifoldStepper<S, const N: usize, C> = Stepper<S, N, GroupEulerLagrange<S, N, C>>;

impl<S: DiracSystem<N, C::Manifold>, C: ConfigurationSpace<N>, const N: usize>
    Stepper<S, N, GroupEulerLagrange<S, N, C>>
{
    /// A stepper for a model on rotations and unit vectors (a [`Product`](crate::Product) of
    /// them with ordinary coordinates) whose steps work in the charts of `space`, with
    /// `quadrature` and step `h` (see [`GroupEulerLagrange`]). Fails as
    /// [`GroupEulerLagrange::new`] does.
    ///
    /// ```
    /// use dirac_runtime::{Configuration, DiracSystem, Product, Quadrature, Rates, Scalar, Stepper};
    /// use nalgebra::{Matrix3, vector};
    ///
    /// /// A free rigid body with principal moments of inertia (1, 2, 3).
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
    /// let mut stepper = Stepper::on_manifold(Body, Product::cayley(), Quadrature::midpoint(), 0.05)?;
    /// let start = Configuration { vector: vector![], rotation: [Matrix3::identity()], direction: [] };
    /// let spin = Rates { vector: vector![], rotation: [vector![0.3, 1.0, 0.2]], direction: [] };
    /// stepper.start_from_velocity(start, spin)?;
    /// let before = stepper.q().spatial(&stepper.p(), 0);
    /// stepper.run(200)?;
    /// let after = stepper.q().spatial(&stepper.p(), 0);
    /// assert!((after - before).amax() < 1e-13); // discrete Noether
    /// let r = stepper.q().rotation[0];
    /// assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-15);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn on_manifold(
        system: S,
        space: C,
        quadrature: Quadrature,
        h: f64,
    ) -> Result<Self, DiracError> {
        let discrete = DiscreteLagrangian::on_space(system, space, quadrature, h);
        Self::with_equations(GroupEulerLagrange::new(discrete)?)
    }

    /// Evaluates the constraint one-forms at `point` of each step instead of the system's default.
    pub fn with_constraint_point(mut self, point: ConstraintPoint) -> Self {
        self.settle_violation();
        self.equations.set_constraint_point(point);
        // The constraint rows change: a Jacobian kept from them no longer fits.
        self.newton.forget_jacobian();
        self
    }

    /// Where the constraint one-forms are evaluated on a step.
    pub fn constraint_point(&self) -> ConstraintPoint {
        self.equations.constraint_point()
    }

    /// The configuration space whose charts the steps work in.
    pub fn space(&self) -> &C {
        self.equations.discrete().space()
    }

    /// The quadrature.
    pub fn quadrature(&self) -> &Quadrature {
        self.equations.discrete().quadrature()
    }
}

impl<E: StepEquations<N>, const N: usize> Stepper<E::System, N, E> {
    /// A stepper that solves `equations` on each step, with default Newton options.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// use dirac_runtime::{DiscreteLagrangian, euler_lagrange::EulerLagrange};
    /// let discrete = DiscreteLagrangian::new(Oscillator, Quadrature::midpoint(), 0.1);
    /// let mut stepper = Stepper::with_equations(EulerLagrange::new(discrete)?)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.step()?;
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_equations(equations: E) -> Result<Self, DiracError> {
        let unknowns = equations.unknowns();
        if equations.first_multiplier() + equations.multipliers() > unknowns {
            return Err(DiracError::Dimension(format!(
                "{}: multipliers {}..{} outside the {unknowns} unknowns",
                E::NAME,
                equations.first_multiplier(),
                equations.first_multiplier() + equations.multipliers()
            )));
        }
        let newton = Newton::new(unknowns, NewtonOptions::default())?;
        let velocity = VelocitySolver::new(equations.velocity_unknowns(), newton.options())?;
        Ok(Self {
            velocity,
            multipliers: vec![0.0; equations.multipliers()],
            equations,
            newton,
            state: None,
            before: None,
            initial_time: 0.0,
            start: 0.0,
            origin: None,
            steps: 0,
            unknowns: DVector::zeros(unknowns),
            predictor: Predictor::new(unknowns),
            report: None,
            violation: Some(0.0),
            work: Some(StepWork::zero()),
            step_map: false,
            fixed_point: false,
            handed_over: (0, None),
            handing_over: None,
            system: PhantomData,
        })
    }

    /// Sets the time the next start from a position, velocity or momentum begins at (0 by
    /// default; [`start_from_state`](Self::start_from_state) takes the state's own time).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Free;
    /// # impl DiracSystem<1> for Free {
    /// #     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         v[0] * v[0] * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Free, Quadrature::midpoint(), 0.25)?.with_start_time(10.0);
    /// stepper.start_from_velocity(vector![0.0], vector![1.0])?;
    /// let trajectory = stepper.run_until(11.0)?;
    /// assert_eq!(trajectory.t().last(), Some(&11.0));
    /// assert_eq!(trajectory.len(), 5);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_start_time(mut self, t0: f64) -> Self {
        self.initial_time = t0;
        self
    }

    /// Replaces the Newton options (tolerances, iteration cap, root acceptance); fails on
    /// options out of range.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// use dirac_runtime::NewtonOptions;
    /// let tight = NewtonOptions { residual_tolerance: 1e-14, ..NewtonOptions::default() };
    /// let stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?.with_newton_options(tight)?;
    /// let negative = NewtonOptions { residual_tolerance: -1.0, ..NewtonOptions::default() };
    /// assert!(stepper.with_newton_options(negative).is_err());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_newton_options(mut self, options: NewtonOptions) -> Result<Self, DiracError> {
        self.newton = Newton::new(self.unknowns.len(), options)?;
        self.velocity = VelocitySolver::new(self.equations.velocity_unknowns(), &options)?;
        Ok(self)
    }

    /// Takes the steps by the step map of the model's step equations rather than by Newton's
    /// method, where they are linear with constant coefficients (`L` quadratic on `Rⁿ`,
    /// [`DiracSystem::QUADRATIC`]; constant one-forms; no forces or holonomic constraints): the
    /// map is read off the step at the start of a run and again every 1 024 steps, and a step
    /// costs a matrix–vector product whatever the quadrature's degree (see
    /// [`affine_step`](crate::step::affine_step)). The steps are Newton's to round-off, but the
    /// energy's round-off is larger: a random walk of about 2e-12 over 10⁶ steps of the LC
    /// circuit, where Newton's method stays at 1.5e-14. Fails with `Unsupported`, saying why,
    /// for equations that are not linear with constant coefficients (holonomic constraints and
    /// forces included). A reading that finds a model's claim to be quadratic wrong fails its
    /// step, and every later step of the run, with `InconsistentDerivatives`; between readings
    /// the claim is trusted, so a hand-written model that claims `QUADRATIC` wrongly can take
    /// up to 1 024 wrong steps first (the attribute derives the claim from the Lagrangian).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Solver, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// struct Oscillator;
    /// impl DiracSystem<1> for Oscillator {
    ///     const QUADRATIC: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::galerkin(3)?, 0.1)?.with_step_map()?;
    /// assert_eq!(stepper.solver(), Solver::StepMap);
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run(500)?;
    /// assert!((stepper.q()[0] - 50.0_f64.cos()).abs() < 1e-8);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_step_map(mut self) -> Result<Self, DiracError> {
        self.equations
            .step_map_refusal()
            .map_err(|why| DiracError::Unsupported(format!("a step map: {why}")))?;
        self.step_map = true;
        Ok(self)
    }

    /// Solves each step by fixed-point iteration, without a Jacobian, for a model on `Rⁿ`
    /// without constraints (see [`fixed_point`](crate::step::fixed_point)). Where the model is
    /// separable (`L = ½ vᵀ M v + bᵀ v − V(q)` with constant `M` and `b`,
    /// [`DiracSystem::SEPARABLE`]) and its forces (if any) are free of the velocity, the
    /// positions at the rule's nodes are iterated, each iteration one gradient of `L` per node;
    /// a run whose mass matrix is not constant or not invertible is handed over at its first
    /// step. Other models (a mass matrix `M(q)`, a velocity coupled to the position, forces of
    /// the velocity) are iterated on their assembled rows with the mass matrix of the step,
    /// accelerated by the iteration's history, also one gradient of `L` per node an iteration;
    /// a degenerate Lagrangian is handed over at its first step. Either way the iteration runs
    /// from the extrapolation of the last steps until its update is at round-off, so the
    /// solution is the same discrete Euler–Lagrange equations' root as Newton's, to round-off,
    /// without a bias that would drift the invariants, and is checked by its residual. A step
    /// where the iteration does not settle (an update that grows twice running; on the rows a
    /// second update above half the first, or two running that shrink by less than half; 40
    /// iterations; a residual left) is solved by
    /// Newton's method instead:
    /// [`handed_over`](Self::handed_over) counts those steps and says why the last one was.
    /// Which is cheaper depends on the model: the iteration wins where a Jacobian costs many
    /// gradients (many coordinates, high degree), Newton's method where its few iterations
    /// cost little (the double pendulum below degree 6). Fails with `Unsupported`, saying why,
    /// on a manifold, with constraints, or for a component of an interconnection.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Solver, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// struct Pendulum;
    /// impl DiracSystem<1> for Pendulum {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5 + q[0].cos()
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Pendulum, Quadrature::galerkin(6)?, 0.5)?.with_fixed_point()?;
    /// assert_eq!(stepper.solver(), Solver::FixedPoint);
    /// stepper.start_from_momentum(vector![1.0], vector![0.0])?;
    /// stepper.run(10)?;
    /// assert_eq!(stepper.handed_over(), (0, None));
    /// assert_eq!(stepper.last_report().map(|r| r.jacobians), Some(0));
    /// // A bead whose mass moves with its position: iterated on its rows.
    /// struct Bead;
    /// impl DiracSystem<1> for Bead {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (q[0] * q[0] + 1.0) * v[0] * v[0] * 0.5 - q[0] * q[0] * 0.5
    ///     }
    /// }
    /// let mut bead = Stepper::new(Bead, Quadrature::galerkin(4)?, 0.1)?.with_fixed_point()?;
    /// bead.start_from_velocity(vector![1.0], vector![0.0])?;
    /// bead.run(20)?;
    /// assert_eq!(bead.handed_over(), (0, None));
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_fixed_point(mut self) -> Result<Self, DiracError> {
        self.equations
            .fixed_point_refusal()
            .map_err(|why| DiracError::Unsupported(format!("a fixed-point iteration: {why}")))?;
        self.fixed_point = true;
        Ok(self)
    }

    /// The steps since the start that a stepper [`with_fixed_point`](Self::with_fixed_point)
    /// solved by Newton's method because the iteration did not settle, and why the last one
    /// did not (`(0, None)` for every other stepper). A step that failed is not counted.
    pub fn handed_over(&self) -> (u64, Option<&str>) {
        (self.handed_over.0, self.handed_over.1.as_deref())
    }

    /// Starts from position `q0` and velocity `v0` at the [start time](Self::with_start_time), with `p0 = ∂L/∂v(q0, v0)`.
    /// Fails if `(q0, v0)` violates a constraint, including the hidden constraints of
    /// coordinates without kinetic energy.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.5])?;
    /// assert_eq!((stepper.t(), stepper.p()[0]), (0.0, 0.5));
    /// assert!(stepper.start_from_velocity(vector![f64::NAN], vector![0.0]).is_err());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn start_from_velocity(
        &mut self,
        q0: Point<E, N>,
        v0: Tangent<E, N>,
    ) -> Result<(), DiracError> {
        let p0 = self.equations.momentum(&q0, &v0)?;
        self.start_from_state(State::new(self.initial_time, q0, p0, v0))
    }

    /// Starts from position `q0` and momentum `p0` at the [start time](Self::with_start_time). The velocity is found by a
    /// globalised Newton solve of `∂L/∂v(q0, v) = p0` from `v = 0`; when that fails (several
    /// velocities share the momentum, or `v = 0` is far from the answer), use
    /// [`start_from_momentum_near`](Self::start_from_momentum_near).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_momentum(vector![1.0], vector![0.5])?;
    /// assert!((stepper.v()?[0] - 0.5).abs() < 1e-15);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn start_from_momentum(
        &mut self,
        q0: Point<E, N>,
        p0: Tangent<E, N>,
    ) -> Result<(), DiracError> {
        self.start_from_momentum_near(q0, p0, <E::Manifold as Manifold<N>>::zero())
    }

    /// Starts from position `q0` and momentum `p0` at the [start time](Self::with_start_time), solving for the velocity from
    /// the guess `v_guess`.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_momentum_near(vector![1.0], vector![0.5], vector![0.4])?;
    /// assert!((stepper.v()?[0] - 0.5).abs() < 1e-15);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn start_from_momentum_near(
        &mut self,
        q0: Point<E, N>,
        p0: Tangent<E, N>,
        v_guess: Tangent<E, N>,
    ) -> Result<(), DiracError> {
        self.equations.check_finite(&q0, &p0, &v_guess)?;
        let t0 = self.initial_time;
        let v0 = self.velocity_at(t0, &q0, &p0, &v_guess, false)?;
        self.start_from_state(State::new(t0, q0, p0, v0))
    }

    /// Sets the input called `name` (held constant over the following steps until set again).
    /// In a loop, resolve the name once with [`input`](Self::input) and use
    /// [`set_input_value`](Self::set_input_value).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// An oscillator driven by the force `u`.
    /// struct Driven;
    /// impl DiracSystem<1> for Driven {
    ///     const FORCES: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([u[0]])
    ///     }
    ///     fn input_name(&self, _i: usize) -> String {
    ///         "u".into()
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Driven, Quadrature::midpoint(), 0.1)?;
    /// stepper.set_input("u", 2.0)?;
    /// assert_eq!(stepper.inputs(), &[2.0]);
    /// assert!(stepper.set_input("v", 1.0).is_err());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn set_input(&mut self, name: &str, value: f64) -> Result<(), DiracError> {
        let input = self.input(name)?;
        self.set_input_value(input, value)
    }

    /// The input called `name`, or `UnknownInput` naming the system's inputs.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// An oscillator driven by the force `u`.
    /// struct Driven;
    /// impl DiracSystem<1> for Driven {
    ///     const FORCES: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([u[0]])
    ///     }
    ///     fn input_name(&self, _i: usize) -> String {
    ///         "u".into()
    ///     }
    /// }
    /// let stepper = Stepper::new(Driven, Quadrature::midpoint(), 0.1)?;
    /// assert_eq!(stepper.input("u")?.index(), 0);
    /// assert!(stepper.input("v").is_err());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn input(&self, name: &str) -> Result<Input, DiracError> {
        let count = self.equations.inputs().len();
        (0..count)
            .find(|&i| self.equations.input_name(i) == name)
            .map(Input::new)
            .ok_or_else(|| {
                let names: Vec<String> = (0..count).map(|i| self.equations.input_name(i)).collect();
                DiracError::UnknownInput(format!(
                    "no input called `{name}`; the inputs are {names:?}"
                ))
            })
    }

    /// Sets `input` (held constant over the following steps until set again); a value that is
    /// not finite is refused and changes nothing.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// An oscillator driven by the force `u`.
    /// struct Driven;
    /// impl DiracSystem<1> for Driven {
    ///     const FORCES: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([u[0]])
    ///     }
    ///     fn input_name(&self, _i: usize) -> String {
    ///         "u".into()
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Driven, Quadrature::midpoint(), 0.01)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// let u = stepper.input("u")?; // resolved once, outside the loop
    /// for _ in 0..100 {
    ///     let feedback = -stepper.q()[0]; // a second spring, held over each step
    ///     stepper.set_input_value(u, feedback)?;
    ///     stepper.step()?;
    /// }
    /// assert!((stepper.q()[0] - 2.0_f64.sqrt().cos()).abs() < 0.05);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn set_input_value(&mut self, input: Input, value: f64) -> Result<(), DiracError> {
        let index = input.index();
        let count = self.equations.inputs().len();
        if index >= count {
            return Err(DiracError::UnknownInput(format!(
                "input {index} of a system with {count} input(s)"
            )));
        }
        if !value.is_finite() {
            return Err(DiracError::NonFinite {
                what: format!("input {}", self.equations.input_name(index)),
                value,
            });
        }
        if self.equations.inputs()[index] != value {
            // A step after a change of inputs is predicted from the last one alone.
            self.predictor.restart();
        }
        self.equations.inputs_mut()[index] = value;
        Ok(())
    }

    /// Sets every input at once, in the order of the system's `inputs(...)`.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// An oscillator driven by the force `u`.
    /// struct Driven;
    /// impl DiracSystem<1> for Driven {
    ///     const FORCES: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([u[0]])
    ///     }
    ///     fn input_name(&self, _i: usize) -> String {
    ///         "u".into()
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Driven, Quadrature::midpoint(), 0.1)?;
    /// stepper.set_inputs(&[1.5])?;
    /// assert_eq!(stepper.inputs(), &[1.5]);
    /// assert!(stepper.set_inputs(&[1.0, 2.0]).is_err());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn set_inputs(&mut self, values: &[f64]) -> Result<(), DiracError> {
        let count = self.equations.inputs().len();
        if values.len() != count {
            return Err(DiracError::UnknownInput(format!(
                "the system has {count} input(s), got {} value(s)",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(DiracError::NonFinite {
                what: format!("input {}", self.equations.input_name(i)),
                value: values[i],
            });
        }
        let changed = self.equations.inputs() != values;
        self.equations.inputs_mut().copy_from_slice(values);
        if changed {
            // A step after a change of inputs is predicted from the last one alone.
            self.predictor.restart();
        }
        Ok(())
    }

    /// Current input values.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// An oscillator driven by the force `u`.
    /// struct Driven;
    /// impl DiracSystem<1> for Driven {
    ///     const FORCES: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([u[0]])
    ///     }
    ///     fn input_name(&self, _i: usize) -> String {
    ///         "u".into()
    ///     }
    /// }
    /// let stepper = Stepper::new(Driven, Quadrature::midpoint(), 0.1)?;
    /// assert_eq!(stepper.inputs(), &[0.0]); // inputs start at zero
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn inputs(&self) -> &[f64] {
        self.equations.inputs()
    }

    /// The system.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// assert_eq!(stepper.system().coordinate_name(0), "q0");
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn system(&self) -> &E::System {
        self.equations.system()
    }

    /// The step equations.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// use dirac_runtime::StepEquations;
    /// let stepper = Stepper::new(Oscillator, Quadrature::galerkin(2)?, 0.1)?;
    /// assert_eq!(stepper.equations().unknowns(), 2); // the internal point and the end point
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn equations(&self) -> &E {
        &self.equations
    }

    /// The velocity at `(q, p)` by the Legendre inversion from `guess`; `in_run`
    /// when the state is the running one (see [`StepEquations::velocity_in_run`]).
    fn velocity_at(
        &self,
        t: f64,
        q: &Point<E, N>,
        p: &Tangent<E, N>,
        guess: &Tangent<E, N>,
        in_run: bool,
    ) -> Result<Tangent<E, N>, DiracError> {
        // As a recorded sample's velocity is solved, in a workspace of its own.
        let mut solver =
            VelocitySolver::new(self.equations.velocity_unknowns(), self.newton.options())?;
        let solved = solver.solve(|newton| match in_run {
            true => self.equations.velocity_in_run(newton, t, q, p, guess),
            false => self.equations.velocity(newton, t, q, p, guess),
        });
        solved.map_err(|f| self.failure(Problem::Velocity, f))
    }

    /// The velocity of a recorded `state`, solved from `guess` in the stepper's own workspace,
    /// with the energy there where the solve gives it on its way.
    fn sample_velocity(
        &mut self,
        state: &State<N, E::Manifold>,
        guess: &Tangent<E, N>,
    ) -> Result<(Tangent<E, N>, Option<f64>), DiracError> {
        let unknowns = self.equations.velocity_unknowns();
        if self.velocity.fast.unknowns() != unknowns {
            self.velocity = VelocitySolver::new(unknowns, self.newton.options())?;
        }
        let (t, q, p) = (state.t, &state.q, &state.p);
        let equations = &self.equations;
        let solved = self
            .velocity
            .solve(|newton| equations.velocity_and_energy_in_run(newton, t, q, p, guess));
        solved.map_err(|f| self.failure(Problem::Velocity, f))
    }

    /// Starts from `state` after the equations have checked it (see
    /// [`StepEquations::check_start`]) and the first step's equations have been found
    /// nonsingular there (a singular Jacobian is `SingularJacobian`, naming the unknowns the
    /// rule does not determine); on error nothing changes.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// use dirac_runtime::State;
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_state(State::new(2.0, vector![1.0], vector![0.0], vector![0.0]))?;
    /// assert_eq!((stepper.t(), stepper.steps()), (2.0, 0));
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn start_from_state(&mut self, state: State<N, E::Manifold>) -> Result<(), DiracError> {
        if !state.t.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the initial time".into(),
                value: state.t,
            });
        }
        // Consistency to a relative 1e-9, or looser where the solver is asked for less: a state
        // this stepper (or another) produced is always accepted.
        let tolerance = START_TOLERANCE.max(100.0 * self.newton.options().residual_tolerance);
        self.equations.check_start(&state, tolerance)?;
        // A refused start keeps the last step's violation, which the trial below may no longer
        // be able to measure (`begin` may clear the predictor's solutions).
        self.settle_violation();
        self.begin(&state)?;
        // A rule that does not determine the model's motion (the first step's Jacobian is
        // singular) is refused here, before the first step, naming the undetermined unknowns.
        if self.unknowns.is_empty() {
            // An explicit step: nothing to solve, no rule to find singular.
            self.reset(state);
            return Ok(());
        }
        let equations = &mut self.equations;
        equations.predict(&state, None, &mut self.unknowns);
        // The start's own Jacobian decides, not one reused from another run.
        self.newton.forget_jacobian();
        let trial = self.newton.solve(&mut self.unknowns, |x, r, j| {
            equations.assemble(&state, x, r, j)
        });
        if let Err(failure @ NewtonFailure::Singular(_)) = trial {
            let steps = std::mem::replace(&mut self.steps, 0);
            let error = self.failure(Problem::Step, failure);
            self.steps = steps;
            // The equations examine the running start again: they find what they found then.
            if let Some(origin) = self.origin {
                self.begin(&origin)?;
            }
            return Err(error);
        }
        self.reset(state);
        Ok(())
    }

    /// Lets the equations examine the start of a run, and sizes the solver for the unknowns
    /// they then have.
    fn begin(&mut self, state: &State<N, E::Manifold>) -> Result<(), DiracError> {
        self.equations.begin(state);
        let unknowns = self.equations.unknowns();
        if unknowns != self.unknowns.len() {
            self.newton = Newton::new(unknowns, *self.newton.options())?;
            self.unknowns = DVector::zeros(unknowns);
            self.predictor.clear(unknowns);
        }
        Ok(())
    }

    fn reset(&mut self, state: State<N, E::Manifold>) {
        self.violation = Some(0.0);
        self.multipliers.fill(0.0);
        self.start = state.t;
        self.origin = Some(state);
        self.state = Some(state);
        self.before = None;
        self.steps = 0;
        self.predictor.clear(self.unknowns.len());
        self.report = None;
        self.work = Some(StepWork::zero());
        self.handed_over = (0, None);
    }

    /// Advances one step. On error the state is unchanged.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// use dirac_runtime::DiracError;
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// assert!(matches!(stepper.step(), Err(DiracError::NotStarted)));
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.step()?;
    /// assert_eq!((stepper.steps(), stepper.t()), (1, 0.1));
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn step(&mut self) -> Result<(), DiracError> {
        let proposal = self.solve_step()?;
        self.accept(proposal);
        Ok(())
    }

    /// Advances one step and returns the derivatives of the step map at the state it started
    /// from: `A = ∂(q_{k+1}, p_{k+1})/∂(q_k, p_k)` and `B = ∂(q_{k+1}, p_{k+1})/∂u` (see
    /// [`StepDerivatives`]). On error (including
    /// `Unsupported` for models the derivatives do not cover yet) the state is unchanged.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// let a = stepper.step_linearised()?;
    /// // One degree of freedom: symplectic means det A = 1.
    /// assert!((a.matrix().determinant() - 1.0).abs() < 1e-14);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn step_linearised(&mut self) -> Result<StepDerivatives<N>, DiracError> {
        let proposal = self.solve_step_at_root()?;
        let state = self.factorise_at_root()?;
        let derivatives = self
            .equations
            .linearise(&state, &self.unknowns, &self.newton)?;
        self.accept(proposal);
        Ok(derivatives)
    }

    /// [`solve_step`](Self::solve_step) ending, where Newton's method runs, with the Jacobian
    /// at the root (the derivatives that follow need it).
    fn solve_step_at_root(&mut self) -> Result<Proposal<N, E::Manifold>, DiracError> {
        self.newton.set_jacobian_at_root(true);
        let proposal = self.solve_step();
        self.newton.set_jacobian_at_root(false);
        proposal
    }

    /// Factorises the Jacobian at the root of the step just solved (the implicit function
    /// theorem needs it there; the solve may have ended with an earlier one) and returns the
    /// state the step started from.
    fn factorise_at_root(&mut self) -> Result<State<N, E::Manifold>, DiracError> {
        let Some(state) = self.state else {
            return Err(DiracError::NotStarted);
        };
        if self.unknowns.is_empty() {
            // An explicit step: no equations to factorise.
            return Ok(state);
        }
        let equations = &mut self.equations;
        self.newton
            .factorise_at(&self.unknowns, |x, r, j| {
                equations.assemble(&state, x, r, j)
            })
            .map_err(|f| self.failure(Problem::Step, f))?;
        Ok(state)
    }

    /// Solves the next step without making it current: the state is unchanged whatever happens.
    fn solve_step(&mut self) -> Result<Proposal<N, E::Manifold>, DiracError> {
        self.handing_over = None;
        let Some(state) = &self.state else {
            return Err(DiracError::NotStarted);
        };
        if let Some(taken) = self.equations.explicit_step(state, self.steps) {
            let (mut next, work) = taken?;
            next.t = self.start + (self.steps + 1) as f64 * self.equations.h();
            return Ok(Proposal {
                next,
                report: NewtonReport::default(),
                work,
            });
        }
        if self.step_map
            && let Some(taken) = self
                .equations
                .affine_step(state, &mut self.unknowns, self.steps)
        {
            let mut next = taken?;
            next.t = self.start + (self.steps + 1) as f64 * self.equations.h();
            let work = self.equations.work(state, &self.unknowns);
            return Ok(Proposal {
                next,
                report: NewtonReport::default(),
                work,
            });
        }
        // The last solutions extrapolated (see `predictor`).
        let predictor = self.predictor.predict();
        let equations = &mut self.equations;
        equations.predict(state, predictor, &mut self.unknowns);
        if self.fixed_point {
            let tolerance = self.newton.options().residual_tolerance;
            match equations.fixed_point_step(state, &mut self.unknowns, tolerance) {
                Some(Ok(report)) => {
                    let mut next = equations.advance(state, &self.unknowns, self.steps)?;
                    next.t = self.start + (self.steps + 1) as f64 * equations.h();
                    let work = equations.work(state, &self.unknowns);
                    return Ok(Proposal { next, report, work });
                }
                Some(Err(why)) => {
                    // Newton's method from the predictor; counted if the step is accepted.
                    self.handing_over = Some(why);
                    equations.predict(state, predictor, &mut self.unknowns);
                }
                None => {}
            }
        }
        let report = if self.unknowns.is_empty() {
            // An explicit step: `advance` takes it.
            NewtonReport::default()
        } else {
            self.newton.set_jacobian_cost(equations.jacobian_cost());
            self.newton
                .set_constant_jacobian(equations.constant_jacobian());
            let result = self.newton.solve(&mut self.unknowns, |x, r, j| {
                equations.assemble(state, x, r, j)
            });
            result.map_err(|f| self.failure(Problem::Step, f))?
        };
        let mut next = self.equations.advance(state, &self.unknowns, self.steps)?;
        next.t = self.start + (self.steps + 1) as f64 * self.equations.h();
        let work = self.equations.work(state, &self.unknowns);
        Ok(Proposal { next, report, work })
    }

    /// Makes a solved step current; its solution is still in `unknowns`.
    fn accept(&mut self, proposal: Proposal<N, E::Manifold>) {
        let first = self.equations.first_multiplier();
        let count = self.multipliers.len();
        self.multipliers
            .copy_from_slice(&self.unknowns.as_slice()[first..first + count]);
        self.predictor.record(&self.unknowns);
        if let Some(state) = &self.state
            && !self.equations.charts_continue(&state.q, &proposal.next.q)
        {
            // The solutions so far are coordinates in charts that the next one does not continue.
            self.predictor.detach();
        }
        self.violation = None;
        self.work = self
            .work
            .zip(proposal.work)
            .map(|(total, step)| total + step);
        if let Some(why) = self.handing_over.take() {
            self.handed_over = (self.handed_over.0 + 1, Some(why));
        }
        self.steps += 1;
        self.before = self.state;
        self.state = Some(proposal.next);
        self.report = Some(proposal.report);
    }

    /// How the steps are solved: explicit steps in closed form; the steps of a stepper
    /// [`with_step_map`](Self::with_step_map) by the step map, of one
    /// [`with_fixed_point`](Self::with_fixed_point) by fixed-point iteration; every other step
    /// by Newton's method, with why there is no step map (or that one can be asked for).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Solver, Stepper};
    /// # use nalgebra::SVector;
    /// struct Pendulum;
    /// impl DiracSystem<1> for Pendulum {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5 + q[0].cos()
    ///     }
    /// }
    /// let stepper = Stepper::new(Pendulum, Quadrature::midpoint(), 0.1)?;
    /// let Solver::Newton(why) = stepper.solver() else { unreachable!() };
    /// assert!(why.contains("not quadratic"));
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn solver(&self) -> Solver {
        if self.equations.unknowns() == 0 {
            return Solver::Explicit;
        }
        if self.step_map {
            return Solver::StepMap;
        }
        if self.fixed_point {
            return Solver::FixedPoint;
        }
        Solver::Newton(match self.equations.step_map_refusal() {
            Ok(()) => "Newton's method is the default; with_step_map takes the step map".into(),
            Err(why) => why,
        })
    }

    /// Multipliers of the last step: one per constraint one-form, then one per holonomic
    /// constraint. `Ãᵀ μ + dg̃ᵀ λ` is the constraint impulse over the step (the constraint force
    /// times `h`) in the chart at `q_k`; on `Rⁿ`, `A(q_c)ᵀ μ + dg(q_k)ᵀ λ`. Empty for an
    /// unconstrained system; zeros before the first step.
    ///
    /// ```
    /// # use dirac_runtime::{ConstraintPoint, DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// A knife edge in the plane: it moves only along its heading, sin φ ẋ − cos φ ẏ = 0.
    /// struct KnifeEdge;
    /// impl DiracSystem<3> for KnifeEdge {
    ///     const ONE_FORMS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * 0.5
    ///     }
    ///     fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, _a: usize) -> SVector<D, 3> {
    ///         SVector::from([q[2].sin(), -q[2].cos(), D::from(0.0)])
    ///     }
    /// }
    /// let mut stepper = Stepper::new(KnifeEdge, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![0.0, 0.0, 0.0], vector![1.0, 0.0, 1.0])?;
    /// assert_eq!(stepper.multipliers(), &[0.0]);
    /// stepper.step()?;
    /// assert!(stepper.multipliers()[0] != 0.0); // the blade pushes sideways as it turns
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn multipliers(&self) -> &[f64] {
        &self.multipliers
    }

    /// Largest constraint violation of the last step: `|Ã(ξ_c) ξ|` over the one-forms, with
    /// `ξ = R_{q_k}⁻¹(q_{k+1})` the stored step in the chart (on `Rⁿ`, `|A(q_c)(q_{k+1} − q_k)|`),
    /// and `|g(q_{k+1})|` over the holonomic constraints (0 before the first step).
    ///
    /// ```
    /// # use dirac_runtime::{ConstraintPoint, DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// A knife edge in the plane: it moves only along its heading, sin φ ẋ − cos φ ẏ = 0.
    /// struct KnifeEdge;
    /// impl DiracSystem<3> for KnifeEdge {
    ///     const ONE_FORMS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * 0.5
    ///     }
    ///     fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, _a: usize) -> SVector<D, 3> {
    ///         SVector::from([q[2].sin(), -q[2].cos(), D::from(0.0)])
    ///     }
    /// }
    /// let mut stepper = Stepper::new(KnifeEdge, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![0.0, 0.0, 0.0], vector![1.0, 0.0, 1.0])?;
    /// stepper.run(10)?;
    /// assert!(stepper.constraint_violation() < 1e-12);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn constraint_violation(&self) -> f64 {
        if let Some(violation) = self.violation {
            return violation;
        }
        match (&self.before, &self.state, self.predictor.last()) {
            (Some(from), Some(to), Some(x)) => self.equations.violation(from, to, x),
            _ => 0.0,
        }
    }

    /// Measures the last step's constraint violation now, before the equations' settings change.
    fn settle_violation(&mut self) {
        self.violation = Some(self.constraint_violation());
    }

    /// The step size.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// assert_eq!(Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?.h(), 0.1);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn h(&self) -> f64 {
        self.equations.h()
    }

    /// Steps taken since the start.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run(3)?;
    /// assert_eq!(stepper.steps(), 3);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The current state (`None` before the start).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// assert!(stepper.state().is_none());
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// assert_eq!(stepper.state().map(|s| s.q()[0]), Some(1.0));
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn state(&self) -> Option<&State<N, E::Manifold>> {
        self.state.as_ref()
    }

    /// Current time (0 before the start).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run_until(1.0)?;
    /// assert!((stepper.t() - 1.0).abs() < 1e-15);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn t(&self) -> f64 {
        self.state.map_or(0.0, |s| s.t)
    }

    /// Current position (zeros before the start).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run_until(1.0)?;
    /// assert!((stepper.q()[0] - 1.0_f64.cos()).abs() < 1e-2);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn q(&self) -> Point<E, N> {
        self.state
            .map_or_else(<E::Manifold as Manifold<N>>::origin, |s| s.q)
    }

    /// Current momentum (zeros before the start).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run_until(1.0)?;
    /// assert!((stepper.p()[0] + 1.0_f64.sin()).abs() < 1e-2);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn p(&self) -> Tangent<E, N> {
        self.state
            .map_or_else(<E::Manifold as Manifold<N>>::zero, |s| s.p)
    }

    /// Current velocity: the solution `v` of `∂L/∂v(q, v) = p` (Newton's method with the exact
    /// Hessian, seeded with the last step's velocity).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.step()?;
    /// assert_eq!(stepper.v()?, stepper.p()); // L = (v² − q²)/2: p = v
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn v(&self) -> Result<Tangent<E, N>, DiracError> {
        let Some(state) = self.state else {
            return Err(DiracError::NotStarted);
        };
        self.velocity_at(state.t, &state.q, &state.p, &state.velocity, true)
    }

    /// Energy `⟨p, v⟩ − L(q, v)` of the current state, with `v` from [`v`](Self::v); an error,
    /// never NaN, where it is not finite.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run(1000)?;
    /// // The midpoint rule keeps this quadratic energy exactly, up to round-off.
    /// assert!((stepper.energy()? - 0.5).abs() < 1e-13);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn energy(&self) -> Result<f64, DiracError> {
        let Some(state) = self.state else {
            return Err(DiracError::NotStarted);
        };
        self.energy_of(&state, self.steps)
    }

    /// The work `Σ_k W_k` done on the model since the start by its forces and inputs, each
    /// step's in the discrete form the scheme uses (see [`StepWork`]): with the energy,
    /// `E − E_0 − Σ_k W_k` is the energy balance's defect
    /// ([`energy_balance_error`](Self::energy_balance_error)). `Unsupported` for equations that
    /// do not report their work (equations written outside the library that leave
    /// [`StepEquations::work`] as it is).
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// /// An oscillator pushed by a constant force u: L = (v² − q²)/2, F = u dq.
    /// struct Pushed;
    /// impl DiracSystem<1> for Pushed {
    ///     const FORCES: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([u[0]])
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Pushed, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![0.0], vector![0.0])?;
    /// stepper.set_inputs(&[0.5])?;
    /// stepper.run(100)?;
    /// // The work of a constant force is u Δq, and the midpoint rule balances it exactly.
    /// assert!((stepper.work()? - 0.5 * stepper.q()[0]).abs() < 1e-14);
    /// assert!(stepper.energy_balance_error()?.abs() < 1e-14);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn work(&self) -> Result<f64, DiracError> {
        self.work_by_coordinate().map(|work| work.total())
    }

    /// The work since the start on each chart coordinate, of the forces and inputs and of the
    /// constraint forces (see [`StepWork`]; on a group, each step's in its own chart at `q_k`).
    /// `NotStarted` before a start; `Unsupported` as for [`work`](Self::work).
    pub fn work_by_coordinate(&self) -> Result<StepWork<N>, DiracError> {
        if self.state.is_none() {
            return Err(DiracError::NotStarted);
        }
        self.work.ok_or_else(|| {
            DiracError::Unsupported(format!(
                "the work of forces and inputs on a step of {}",
                E::NAME
            ))
        })
    }

    /// The energy balance's defect since the start, `E − E_0 − Σ_k W_k` (see
    /// [`work`](Self::work)): zero to round-off where the unforced scheme keeps the energy
    /// exactly (the midpoint rule and Gauss–Galerkin steps on a quadratic energy, with any
    /// forces and inputs), and of the order of the scheme's energy error otherwise.
    pub fn energy_balance_error(&self) -> Result<f64, DiracError> {
        let work = self.work()?;
        let Some(origin) = self.origin else {
            return Err(DiracError::NotStarted);
        };
        Ok(self.energy()? - self.energy_of(&origin, 0)? - work)
    }

    /// The energy of `state`, reached after `steps` steps (for the error message).
    fn energy_of(&self, state: &State<N, E::Manifold>, steps: u64) -> Result<f64, DiracError> {
        let v = self.velocity_at(state.t, &state.q, &state.p, &state.velocity, true)?;
        self.energy_at(state, &v, steps)
    }

    /// The energy of `state` with velocity `v`, reached after `steps` steps; an error where it
    /// is not finite.
    fn energy_at(
        &self,
        state: &State<N, E::Manifold>,
        v: &Tangent<E, N>,
        steps: u64,
    ) -> Result<f64, DiracError> {
        let energy = self.equations.energy(&state.q, &state.p, v);
        if !energy.is_finite() {
            return Err(DiracError::NonFinite {
                what: format!("the energy after {steps} steps"),
                value: energy,
            });
        }
        Ok(energy)
    }

    /// How Newton's method went on the last step.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// assert!(stepper.last_report().is_none());
    /// stepper.step()?;
    /// assert!(stepper.last_report().is_some_and(|r| r.iterations <= 3));
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn last_report(&self) -> Option<NewtonReport> {
        self.report
    }

    /// An empty trajectory with this system's coordinate (and multiplier) columns.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// let trajectory = stepper.trajectory();
    /// assert!(trajectory.is_empty());
    /// assert_eq!(trajectory.column_names(), ["t", "q0", "v_q0", "p_q0", "energy"]);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn trajectory(&self) -> Trajectory<N, E::Manifold> {
        let names = self.coordinate_names();
        let options = self.newton.options();
        let model = std::any::type_name::<E::System>();
        let metadata = Metadata {
            model: model.rsplit("::").next().unwrap_or(model).to_string(),
            quadrature: self.equations.method(),
            h: self.h(),
            t0: self.state.map_or(self.initial_time, |s| s.t),
            residual_tolerance: options.residual_tolerance,
            step_tolerance: options.step_tolerance,
        };
        if self.multipliers.is_empty() {
            Trajectory::new(names)
        } else {
            Trajectory::with_multipliers(names, self.equations.multiplier_names())
        }
        .expect("one name per coordinate, from coordinate_names")
        .with_metadata(metadata)
        .with_forces(E::FORCED)
    }

    /// Coordinate names, from the system.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// # use nalgebra::{SVector, vector};
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// let stepper = Stepper::new(Oscillator, Quadrature::midpoint(), 0.1)?;
    /// assert_eq!(stepper.coordinate_names(), ["q0"]);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn coordinate_names(&self) -> Vec<String> {
        (0..<E::Manifold as Manifold<N>>::VARIABLES)
            .map(|i| self.equations.coordinate_name(i))
            .collect()
    }

    /// Turns a Newton failure into an error naming the step and, if singular, the unknowns.
    fn failure(&self, which: Problem, failure: NewtonFailure) -> DiracError {
        let problem = match which {
            Problem::Step => E::NAME,
            Problem::Velocity => E::VELOCITY,
        };
        let options = self.newton.options();
        if which == Problem::Step {
            return failure.into_error(problem, self.steps, options, &|column| {
                self.equations.unknown_name(column)
            });
        }
        match failure {
            NewtonFailure::NonFinite => DiracError::NonFinite {
                what: format!(
                    "the residual of {problem} after {} steps (the velocity iterate left the \
                     Lagrangian's domain; start_from_momentum_near takes a guess inside it)",
                    self.steps
                ),
                value: f64::NAN,
            },
            failure => failure.into_error(problem, self.steps, options, &|column| {
                if column < N {
                    format!("{} (velocity)", self.equations.coordinate_name(column))
                } else {
                    format!("the multiplier of velocity constraint {}", column - N)
                }
            }),
        }
    }
}

/// The velocity solves of recorded samples: a simplified Newton solve with the Hessian at the
/// guess (one Hessian per sample: exact for a Lagrangian quadratic in the velocities), and,
/// where it fails, a globalised one (line search, no contraction test, at least 50 iterations), both
/// with the stepper's tolerances.
#[derive(Debug, Clone)]
struct VelocitySolver {
    fast: Newton,
    globalised: Newton,
}

impl VelocitySolver {
    fn new(unknowns: usize, options: &NewtonOptions) -> Result<Self, DiracError> {
        let fast = NewtonOptions {
            line_search: false,
            jacobian_reuse: Some(options.max_contraction.min(1.0)),
            ..*options
        };
        Ok(Self {
            fast: Newton::new(unknowns, fast)?,
            globalised: Newton::new(unknowns, velocity_options(options))?,
        })
    }

    /// `solve` run by the fast solver, with the Hessian at its guess (none kept from an earlier
    /// sample), and where that fails by the globalised one, from the same guess.
    fn solve<T>(
        &mut self,
        solve: impl Fn(&mut Newton) -> Result<T, NewtonFailure>,
    ) -> Result<T, NewtonFailure> {
        self.fast.forget_jacobian();
        solve(&mut self.fast).or_else(|_| solve(&mut self.globalised))
    }
}

/// The Newton options of a globalised velocity solve: the stepper's, with a line search, no
/// contraction test and at least 50 iterations.
fn velocity_options(options: &NewtonOptions) -> NewtonOptions {
    NewtonOptions {
        line_search: true,
        max_contraction: f64::INFINITY,
        max_iterations: options.max_iterations.max(50),
        ..*options
    }
}
