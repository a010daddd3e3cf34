//! The seam between a discretisation and the [`Stepper`](crate::Stepper): the equations of one
//! step, their unknowns, and how a solution advances the state.
//!
//! A step from the [`State`] `(t_k, q_k, p_k)` is a square system `F(x) = 0` in unknowns `x`
//! whose layout belongs to the equations. The stepper asks the equations for a predictor, hands
//! [`assemble`](StepEquations::assemble) to Newton's method, and, once Newton has accepted a
//! root, asks [`advance`](StepEquations::advance) for the next state. It never looks inside `x`:
//! the discrete Euler–Lagrange equations ([`EulerLagrange`](crate::step::euler_lagrange::EulerLagrange))
//! are one implementation; the discrete Hamiltonian route and interconnected systems are others.

use nalgebra::{DMatrix, DVector, SVector};

use crate::base::error::DiracError;
use crate::solve::newton::{Newton, NewtonFailure, NewtonReport};
use crate::space::manifold::Manifold;
use crate::step::dense_output::Sample;
use crate::step::step_derivatives::StepDerivatives;

pub use crate::discrete::state::State;

/// The point type of the step equations `E` (on `Rⁿ`, `SVector<f64, N>`).
pub type Point<E, const N: usize> = <<E as StepEquations<N>>::Manifold as Manifold<N>>::Point<f64>;

/// The tangent vector (and covector) type of the step equations `E`.
pub type Tangent<E, const N: usize> =
    <<E as StepEquations<N>>::Manifold as Manifold<N>>::Tangent<f64>;

/// The work done on each coordinate over one step, in the discrete form the step equations use.
///
/// `forces` is the work of the forces and inputs along the step's path by the quadrature,
/// `h Σ_i b_i F̃(q_i, v_i, t_i, u)_r ξ̇_{i,r}` for each chart coordinate `r` (the force read in
/// the chart at `q_k` times the node's chart velocity; on `Rⁿ`, `F_r q̇_r`; for the midpoint rule
/// `F(q̄, Δq/h)_r Δq_r`). Its sum is the work `W_k` for which the energy balance
/// `E_{k+1} − E_k = W_k` holds wherever the unforced scheme keeps the energy exactly.
/// `constraints` is the work of the constraint forces, `μ̃_r ξ_r / h` for the constraint impulse
/// `μ̃` (junctions included), where the step holds its constraints with one impulse (degree-1
/// steps without a projection); `None` otherwise. Its sum is zero wherever the constraints are
/// one-forms held at the step's constraint point; its parts on a component are the work
/// through that component's ports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepWork<const N: usize> {
    /// The work of the forces and inputs on each chart coordinate.
    pub forces: SVector<f64, N>,
    /// The work of the constraint forces on each chart coordinate, where it is known.
    pub constraints: Option<SVector<f64, N>>,
}

impl<const N: usize> StepWork<N> {
    /// No work (the constraints' known to be zero).
    pub fn zero() -> Self {
        Self {
            forces: SVector::zeros(),
            constraints: Some(SVector::zeros()),
        }
    }

    /// The work of the forces and inputs, summed over the coordinates: `W_k`.
    pub fn total(&self) -> f64 {
        self.forces.sum()
    }
}

impl<const N: usize> std::ops::Add for StepWork<N> {
    type Output = Self;

    /// The work of two stretches of steps, one after the other (the constraints' known only
    /// where both know it).
    fn add(self, other: Self) -> Self {
        Self {
            forces: self.forces + other.forces,
            constraints: self.constraints.zip(other.constraints).map(|(a, b)| a + b),
        }
    }
}

/// The equations of one step of an integrator on a state of `N` coordinates.
///
/// Implemented by [`EulerLagrange`](crate::step::euler_lagrange::EulerLagrange); a
/// [`Stepper`](crate::Stepper) drives any implementation ([`Stepper::with_equations`]) with the
/// same Newton solve, error handling, trajectories and guarantees (a failed step changes
/// nothing). `tests/suite/step_equations.rs` drives the implicit midpoint rule of a Hamiltonian this
/// way. The guarantee holds as long as `predict`, `assemble` and `explicit_step` keep only
/// per-step scratch (or caches keyed by the state) in `&mut self`: anything that must survive a
/// step belongs in the [`State`].
///
/// [`Stepper::with_equations`]: crate::Stepper::with_equations
pub trait StepEquations<const N: usize> {
    /// The model the equations discretise.
    type System;

    /// The points and tangent vectors of the model's configuration.
    type Manifold: Manifold<N>;

    /// The model.
    fn system(&self) -> &Self::System;

    /// What the equations are, for error messages ("the discrete Euler–Lagrange equations").
    const NAME: &'static str;
    /// What the velocity solve is, for error messages.
    const VELOCITY: &'static str;
    /// Whether the model has forces (and inputs) that can do work: a trajectory shows its
    /// `work` column only then (by default, yes).
    const FORCED: bool = true;

    /// The step size.
    fn h(&self) -> f64;

    /// The method, for a trajectory's metadata (by default [`NAME`](Self::NAME)).
    fn method(&self) -> String {
        Self::NAME.to_string()
    }

    /// Number of unknowns of a step (read again after [`begin`](Self::begin): it may depend on
    /// what the equations find at the start of a run).
    fn unknowns(&self) -> usize;

    /// Number of multipliers among the unknowns (constraint impulses).
    fn multipliers(&self) -> usize;

    /// Names of the multipliers, for trajectories.
    fn multiplier_names(&self) -> Vec<String>;

    /// The name of coordinate `i`.
    fn coordinate_name(&self, i: usize) -> String;

    /// Checks that `state` is a valid initial state (finite, in the model's domain, consistent
    /// with its constraints to the relative `tolerance`, which the stepper scales to its solver
    /// tolerance): the error says what is violated.
    fn check_start(
        &self,
        state: &State<N, Self::Manifold>,
        tolerance: f64,
    ) -> Result<(), DiracError>;

    /// Called once a checked `state` becomes the start of a run, before its first step: what the
    /// equations find out about the model there (e.g. which coordinates carry no kinetic
    /// energy) they keep for the run.
    fn begin(&mut self, state: &State<N, Self::Manifold>) {
        let _ = state;
    }

    /// Whether the chart of a step from `to` continues that of a step from `from` (see
    /// [`ConfigurationSpace::charts_continue`](crate::space::configuration_space::ConfigurationSpace::charts_continue)):
    /// where it does not, the stepper predicts the next step afresh rather than from the last
    /// solutions. Always, by default.
    fn charts_continue(
        &self,
        from: &<Self::Manifold as Manifold<N>>::Point<f64>,
        to: &<Self::Manifold as Manifold<N>>::Point<f64>,
    ) -> bool {
        let _ = (from, to);
        true
    }

    /// Prepares the step from `state` and writes the predictor into `x`. `previous` holds the
    /// stepper's prediction from the accepted steps, when there is one: the last solution, or
    /// the last two or three extrapolated (the line `2 x_k − x_{k−1}`, the parabola
    /// `3 x_k − 3 x_{k−1} + x_{k−2}`; not across a start or a change of inputs).
    fn predict(
        &mut self,
        state: &State<N, Self::Manifold>,
        previous: Option<&DVector<f64>>,
        x: &mut DVector<f64>,
    );

    /// Writes the residual `F(x)` and, when one is asked for, adds its Jacobian into
    /// `jacobian` (zeroed by the caller; Newton asks only when a Jacobian is due, see
    /// [`Newton::solve`]); returns the size of the terms summed into the residual (its round-off
    /// floor is a few ulps of this). What [`advance`](Self::advance) needs must not depend on
    /// whether the Jacobian was asked for.
    fn assemble(
        &mut self,
        state: &State<N, Self::Manifold>,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        jacobian: Option<&mut DMatrix<f64>>,
    ) -> f64;

    /// What assembling with the Jacobian costs against assembling the residual alone: Newton
    /// keeps a Jacobian across iterations and steps the longer, the more it costs (see
    /// [`Newton::solve`]). By default 1 (Newton's method).
    fn jacobian_cost(&self) -> f64 {
        1.0
    }

    /// Whether the equations are linear with constant coefficients, the same at every step (see
    /// [`DiracSystem::QUADRATIC`](crate::DiracSystem::QUADRATIC)): Newton then keeps one
    /// factorised Jacobian from step to step. `false` by default.
    fn constant_jacobian(&self) -> bool {
        false
    }

    /// The state after the step from `state` solved by `x` (the point assembled last), without
    /// its time. `step` counts the steps before this one, for error messages.
    fn advance(
        &self,
        state: &State<N, Self::Manifold>,
        x: &DVector<f64>,
        step: u64,
    ) -> Result<State<N, Self::Manifold>, DiracError>;

    /// The step from `state` taken in closed form, for equations without unknowns: the state
    /// [`advance`](Self::advance) would return after [`predict`](Self::predict), with the
    /// step's [`work`](Self::work), or the error `advance` would give. The stepper then takes
    /// no predictor and keeps no proposal (an explicit step costs its arithmetic). `None`, the
    /// default: the step is predicted, solved and advanced. The stepper asks for it first, so
    /// equations with unknowns keep the default.
    #[allow(clippy::type_complexity)]
    fn explicit_step(
        &mut self,
        state: &State<N, Self::Manifold>,
        step: u64,
    ) -> Option<Result<(State<N, Self::Manifold>, Option<StepWork<N>>), DiracError>> {
        let _ = (state, step);
        None
    }

    /// The step from `state` by the step map of equations linear with constant coefficients,
    /// read off the step (see [`affine_step`](crate::step::affine_step)), for a stepper
    /// [`with_step_map`](crate::Stepper::with_step_map): writes the
    /// step's solution into `x` and returns the state [`advance`](Self::advance) would give,
    /// or the error of a step that fails. `None` (the default) where the equations give no
    /// step map (and so refuse it in [`step_map_refusal`](Self::step_map_refusal)): the step
    /// is then predicted, solved by Newton's method and advanced. `step` counts the steps
    /// before this one.
    fn affine_step(
        &mut self,
        state: &State<N, Self::Manifold>,
        x: &mut DVector<f64>,
        step: u64,
    ) -> Option<Result<State<N, Self::Manifold>, DiracError>> {
        let _ = (state, x, step);
        None
    }

    /// `Ok(())` where the steps are taken by a step map ([`affine_step`](Self::affine_step)),
    /// else why not. By default the equations give none.
    fn step_map_refusal(&self) -> Result<(), String> {
        Err(format!("{} give no step map", Self::NAME))
    }

    /// Solves the step from `state` by fixed-point iteration from the predictor in `x`, for a
    /// stepper [`with_fixed_point`](crate::Stepper::with_fixed_point): writes the solution into
    /// `x`, assembled as Newton's last evaluation would leave it (so that
    /// [`advance`](Self::advance) takes it), its residual at most `tolerance` times the size of
    /// its terms, and returns how the iteration went (no Jacobians). `Err` with why where it
    /// does not settle: the stepper then solves the step by Newton's method. `None` (the
    /// default) where the equations are not iterated (and so refuse it in
    /// [`fixed_point_refusal`](Self::fixed_point_refusal)).
    fn fixed_point_step(
        &mut self,
        state: &State<N, Self::Manifold>,
        x: &mut DVector<f64>,
        tolerance: f64,
    ) -> Option<Result<NewtonReport, String>> {
        let _ = (state, x, tolerance);
        None
    }

    /// `Ok(())` where the steps can be solved by fixed-point iteration
    /// ([`fixed_point_step`](Self::fixed_point_step)), else why not. By default they cannot.
    fn fixed_point_refusal(&self) -> Result<(), String> {
        Err(format!(
            "{} are not solved by fixed-point iteration",
            Self::NAME
        ))
    }

    /// The constraint violation of the step from `from` to `to` that `x` solved (`to` as
    /// [`advance`](Self::advance) returned it): 0 for equations without constraints. A
    /// [`Stepper`](crate::Stepper) measures it only when asked
    /// ([`Stepper::constraint_violation`](crate::Stepper::constraint_violation), a recorded
    /// sample), so a step does not pay for it; it must therefore depend on nothing but its
    /// arguments and the equations' settings.
    fn violation(
        &self,
        from: &State<N, Self::Manifold>,
        to: &State<N, Self::Manifold>,
        x: &DVector<f64>,
    ) -> f64;

    /// Where in `x` the multipliers are: they are `x[first..first + multipliers()]`.
    fn first_multiplier(&self) -> usize;

    /// The name of unknown `column` of a step (a coordinate of a point of the step, or a
    /// multiplier).
    fn unknown_name(&self, column: usize) -> String;

    /// Number of unknowns of the velocity solve (`N` unless the velocity comes with
    /// multipliers).
    fn velocity_unknowns(&self) -> usize {
        N
    }

    /// The velocity of a state of the running run (after [`begin`](Self::begin)): the
    /// equations may rely on what they found when it began. By default,
    /// [`velocity`](Self::velocity).
    fn velocity_in_run(
        &self,
        newton: &mut Newton,
        t: f64,
        q: &Point<Self, N>,
        p: &Tangent<Self, N>,
        guess: &Tangent<Self, N>,
    ) -> Result<Tangent<Self, N>, NewtonFailure> {
        self.velocity(newton, t, q, p, guess)
    }

    /// [`velocity_in_run`](Self::velocity_in_run) with the energy at the velocity found, where
    /// the solve gives it on its way with the numbers [`energy`](Self::energy) would (`None`:
    /// the caller asks `energy`). By default `None`.
    fn velocity_and_energy_in_run(
        &self,
        newton: &mut Newton,
        t: f64,
        q: &Point<Self, N>,
        p: &Tangent<Self, N>,
        guess: &Tangent<Self, N>,
    ) -> Result<(Tangent<Self, N>, Option<f64>), NewtonFailure> {
        self.velocity_in_run(newton, t, q, p, guess)
            .map(|v| (v, None))
    }

    /// The velocity at `(q, p)` at time `t`, solved from `guess` by `newton` (sized for
    /// [`velocity_unknowns`](Self::velocity_unknowns)) where it is implicit.
    fn velocity(
        &self,
        newton: &mut Newton,
        t: f64,
        q: &Point<Self, N>,
        p: &Tangent<Self, N>,
        guess: &Tangent<Self, N>,
    ) -> Result<Tangent<Self, N>, NewtonFailure>;

    /// The momentum `∂L/∂v` at position `q` with velocity `v`, for a start from a velocity; an
    /// error names the first of the position, the velocity and the momentum that is not finite.
    fn momentum(
        &self,
        q: &Point<Self, N>,
        v: &Tangent<Self, N>,
    ) -> Result<Tangent<Self, N>, DiracError>;

    /// Fails naming the first of the position `q`, the momentum `p` and the velocity guess that
    /// is not finite (a start from a momentum).
    fn check_finite(
        &self,
        q: &Point<Self, N>,
        p: &Tangent<Self, N>,
        guess: &Tangent<Self, N>,
    ) -> Result<(), DiracError> {
        let point = <Self::Manifold as Manifold<N>>::point_components(q);
        let tangent = <Self::Manifold as Manifold<N>>::tangent_components;
        [
            ("initial position", point),
            ("initial momentum", tangent(p)),
            ("velocity guess", tangent(guess)),
        ]
        .into_iter()
        .find_map(|(what, values)| {
            let value = values.into_iter().find(|x| !x.is_finite())?;
            Some(DiracError::NonFinite {
                what: what.into(),
                value,
            })
        })
        .map_or(Ok(()), Err)
    }

    /// Current values of the model's inputs (none by default).
    fn inputs(&self) -> &[f64] {
        &[]
    }

    /// The inputs' values, to be set (in range and finite: the stepper checks them).
    fn inputs_mut(&mut self) -> &mut [f64] {
        &mut []
    }

    /// The name of input `i`.
    fn input_name(&self, i: usize) -> String {
        format!("u{i}")
    }

    /// Dense output: the solution at fraction `theta ∈ [0, 1]` of the step between `ends` (the
    /// state it started from and the one it reached, with their exact velocities) solved by `x`
    /// (see [`dense_output`](crate::step::dense_output)). `None` where the equations have no path to
    /// interpolate (the default): the stepper then refuses dense output with `Unsupported`.
    fn dense(
        &self,
        ends: [&Sample<N, Self::Manifold>; 2],
        x: &DVector<f64>,
        theta: f64,
    ) -> Option<Sample<N, Self::Manifold>> {
        let _ = (ends, x, theta);
        None
    }

    /// The work done over the step from `state` solved by `x` (the point assembled last) by the
    /// forces, inputs and constraints ([`StepWork`]). `None` where the equations do not know it
    /// (the default): the stepper then refuses the energy balance with `Unsupported`.
    fn work(&self, state: &State<N, Self::Manifold>, x: &DVector<f64>) -> Option<StepWork<N>> {
        let _ = (state, x);
        None
    }

    /// The energy at position `q` with velocity `v` and momentum `p`.
    fn energy(&self, q: &Point<Self, N>, p: &Tangent<Self, N>, v: &Tangent<Self, N>) -> f64;

    /// The derivatives of the step from `state` solved by `x` (the point assembled last) with
    /// respect to `(q_k, p_k)` and the inputs `u`; `newton` must hold the Jacobian factorised at
    /// `x`, the root of its last solve ([`Newton::factorise_at`]; otherwise an error). The
    /// default refuses: equations that can differentiate their step override it.
    fn linearise(
        &self,
        state: &State<N, Self::Manifold>,
        x: &DVector<f64>,
        newton: &Newton,
    ) -> Result<StepDerivatives<N>, DiracError> {
        let _ = (state, x, newton);
        Err(DiracError::Unsupported(format!(
            "derivatives of the step map of {}",
            Self::NAME
        )))
    }
}
