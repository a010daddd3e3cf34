//! A component of a modular interconnection: a model's step equations and state behind a
//! type-erased face ([`Part`]), for models on `Rⁿ` ([`EulerLagrange`]) and on spaces of
//! rotations ([`GroupEulerLagrange`]) alike.
//!
//! Every number a component shows the interconnection but its positions is read in the chart
//! at its current point, `ξ = 0`: its coordinates (a junction's terms) are the chart's, its
//! velocities the chart velocities `ξ̇`, its momenta `(T_0 R)ᵀ p`, its step `ξ`. On `Rⁿ` these
//! are the model's own coordinates, velocities, momenta and `q_{k+1} − q_k`; on a rotation the
//! body angular velocity, the body angular momentum and the step's rotation in the body's
//! axes. Its positions are the numbers of its point (a rotation's nine entries, row by row).

use nalgebra::{Const, U1};
use nalgebra::{DMatrix, DVector, SVector};
use num_dual::{Derivative, DualSVec64};

use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::discrete::hidden_constraint::{
    HiddenConstraints, Rows, constant_forms, degenerate_rows,
};
use crate::model::derivatives::{Seed, degenerate, seeded};
use crate::model::system::DiracSystem;
use crate::space::configuration_space::{ConfigurationSpace, Euclidean, Point, Tangent};
use crate::space::manifold::Manifold;
use crate::step::euler_lagrange::EulerLagrange;
use crate::step::group_euler_lagrange::GroupEulerLagrange;
use crate::step::step_equations::{State, StepEquations, StepWork};

/// A component's Legendre rows at its position: `∂L/∂v`, `∂²L/∂v²` and its own constraint
/// forms (one-forms, then holonomic differentials; rows over its coordinates), in its chart.
pub(super) struct Legendre {
    pub momentum: Vec<f64>,
    pub hessian: DMatrix<f64>,
    pub forms: DMatrix<f64>,
}

/// What [`Part::degenerate`] finds at a start.
pub(super) struct Degenerate {
    /// The coordinates without kinetic energy.
    pub coordinates: Vec<usize>,
    /// Their momenta `∂L/∂v` (must be zero).
    pub momenta: Vec<(usize, f64)>,
    /// One of them whose momentum depends on the position, if any.
    pub turning: Option<usize>,
    /// The component's one-forms and holonomic differentials (rows over its coordinates).
    pub forms: DMatrix<f64>,
}

/// A component's step equations and state, behind a type-erased face: components of different
/// models, sizes and spaces sit in one interconnection (see the [module](self) for what its
/// numbers are).
pub(super) trait Part: Send + std::fmt::Debug {
    fn coordinates(&self) -> usize;
    fn coordinate_name(&self, i: usize) -> String;
    /// The number of numbers of its point.
    fn positions(&self) -> usize;
    fn position_name(&self, i: usize) -> String;
    fn one_forms(&self) -> bool;
    fn point(&self) -> ConstraintPoint;
    fn inputs(&self) -> usize;
    fn input_name(&self, i: usize) -> String;
    /// Sets input `i` (finite); whether it changed.
    fn set_input(&mut self, i: usize, value: f64) -> bool;
    /// The value of input `i`.
    fn input(&self, i: usize) -> f64;
    /// The number of unknowns of a step (after [`begin`](Self::begin)).
    fn unknowns(&self) -> usize;
    fn unknown_name(&self, column: usize) -> String;
    /// The checked state at positions `q` with chart velocity `v` (its momentum `∂L/∂v`), at
    /// time 0.
    fn checked_start(&self, q: &[f64], v: &[f64], tolerance: f64) -> Result<Started, DiracError>;
    /// The degenerate coordinates at `(q, v)` (positions, chart velocity).
    fn degenerate(&self, q: &[f64], v: &[f64]) -> Degenerate;
    /// Begins a run from a state [`checked_start`](Self::checked_start) returned.
    fn begin(&mut self, state: Started);
    /// Forgets the run (a start that failed after `begin`).
    fn stop(&mut self);
    /// Prepares the step and writes its predictor (read by
    /// [`unknowns_of_step`](Self::unknowns_of_step)) from its part of the previous solutions'
    /// extrapolation, where there is one.
    fn predict(&mut self, previous: Option<&[f64]>);
    /// The unknowns of the step last predicted or assembled.
    fn unknowns_of_step(&self) -> &[f64];
    /// The residual at `x` with the junctions' impulse (into its own buffer), the Jacobian
    /// into `jacobian`; the size of the residual's terms.
    fn assemble(
        &mut self,
        impulse: &[f64],
        share: f64,
        x: &[f64],
        jacobian: Option<&mut DMatrix<f64>>,
    ) -> f64;
    fn residual(&self) -> &[f64];
    /// Proposes the state after the step solved by `x`; its constraint violation.
    fn advance(&mut self, x: &[f64], step: u64) -> Result<f64, DiracError>;
    /// Coordinate `i` of the proposed step (0 without one).
    fn proposed_step(&self, i: usize) -> f64;
    /// Makes the proposed state current, at time `t`.
    fn accept(&mut self, t: f64);
    /// Drops a proposed state.
    fn discard(&mut self);
    /// Coordinate `i` of the last step taken (0 before one).
    fn last_step(&self, i: usize) -> f64;
    /// The work done on it since the run began by its own forces and inputs, and by the
    /// constraint forces (its own and the junctions') where that is known (see [`StepWork`]);
    /// `None` where its steps do not report their work.
    fn work(&self) -> Option<(f64, Option<f64>)>;
    /// Its positions (its point's numbers; the origin before a start).
    fn q(&self) -> Vec<f64>;
    /// The position numbers of the point its chart at `q` (at its current position where
    /// `None`) reaches with `xi` into `positions`, and their derivatives in `xi` (positions ×
    /// coordinates) into `jacobian`: what a joint reads of it.
    fn chart_positions(
        &self,
        q: Option<&[f64]>,
        xi: &[f64],
        positions: &mut [f64],
        jacobian: &mut DMatrix<f64>,
    );
    /// Its momenta, read in the chart.
    fn p(&self) -> Vec<f64>;
    /// The number of its own constraints (one-forms and holonomic).
    fn constraints(&self) -> usize;
    /// The chart velocity of the last step at its end (the initial velocity before one).
    fn velocity_hint(&self) -> Vec<f64>;
    /// The Legendre rows at its position with chart velocity `v`.
    fn legendre(&self, v: &[f64]) -> Legendre;
    /// The energy at its position with chart velocity `v`.
    fn energy(&self, v: &[f64]) -> f64;
    /// The rows of its coordinates `dead` without their multipliers at `(q, v, t)`, with its
    /// inputs (see [`degenerate_rows`]).
    fn degenerate_rows(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        dead: &[usize],
        jacobians: bool,
    ) -> Rows;
    /// Whether its constraint forms are constant at `q`.
    fn constant_forms(&self, q: &[f64]) -> bool;
    /// The proposed state's position and velocity as coordinates (after
    /// [`advance`](Self::advance); on `Rⁿ`, where coordinates without kinetic energy are).
    fn proposed(&self) -> Option<(&[f64], &[f64])>;
    /// Moves coordinate `i` of the proposed position by `delta` (on `Rⁿ`).
    fn shift_proposed(&mut self, i: usize, delta: f64);
    /// The Lagrangian finite at the proposed state (after it was moved).
    fn check_proposed(&self, step: u64) -> Result<(), DiracError>;
}

/// A checked initial state, type-erased.
pub(super) type Started = Box<dyn std::any::Any + Send>;

/// What the modular step needs of a component's step equations besides [`StepEquations`].
pub(super) trait ComponentEquations<const N: usize>: StepEquations<N> + Send {
    /// The configuration space the equations step on.
    type Space: ConfigurationSpace<N, Manifold = Self::Manifold>;

    fn space(&self) -> &Self::Space;
    /// Refuses the end of step `step` where the Lagrangian is not finite.
    fn check_end(
        &self,
        q: &Point<Self::Space, N, f64>,
        v: &Tangent<Self::Space, N, f64>,
        step: u64,
    ) -> Result<(), DiracError>;
    fn constraint_point(&self) -> ConstraintPoint;
    /// The number of its one-forms.
    fn one_forms(&self) -> usize;
    /// The number of its own constraints (one-forms and holonomic).
    fn constraints(&self) -> usize;
    /// The checks of a start as a component (its degenerate rows are the interconnection's).
    fn check_component_start(
        &self,
        state: &State<N, Self::Manifold>,
        tolerance: f64,
    ) -> Result<(), DiracError>;
    fn begin_as_component(&mut self, state: &State<N, Self::Manifold>);
    /// The junctions' impulse on it over the next step and its share on `p_k`'s equation.
    fn set_coupling(&mut self, impulse: &SVector<f64, N>, share: f64);
    /// The coordinates without kinetic energy at `(q, v)` and what the interconnection asks of
    /// them.
    fn degenerate(&self, q: &Point<Self::Space, N, f64>, v: &SVector<f64, N>) -> Degenerate;
    /// The Legendre rows at `q` with chart velocity `v`.
    fn legendre(&self, q: &Point<Self::Space, N, f64>, v: &SVector<f64, N>) -> Legendre;
    /// A state's position and velocity as coordinates, on `Rⁿ` (`None` elsewhere: there are no
    /// coordinates without kinetic energy there).
    fn as_coordinates<'a>(
        q: &'a Point<Self::Space, N, f64>,
        v: &'a Tangent<Self::Space, N, f64>,
    ) -> Option<(&'a SVector<f64, N>, &'a SVector<f64, N>)>;
    /// A position as coordinates to move, on `Rⁿ`.
    fn as_coordinates_mut(q: &mut Point<Self::Space, N, f64>) -> Option<&mut SVector<f64, N>>;
    /// The rows of coordinates `dead` (see [`degenerate_rows`]), on `Rⁿ`.
    fn degenerate_rows(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        dead: &[usize],
        jacobians: bool,
    ) -> Rows;
    /// Whether its constraint forms are constant at `q`, on `Rⁿ`.
    fn constant_forms(&self, q: &SVector<f64, N>) -> bool;
}

impl<S: DiracSystem<N> + Send, const N: usize> ComponentEquations<N>
    for EulerLagrange<S, N, Euclidean>
{
    type Space = Euclidean;

    fn space(&self) -> &Euclidean {
        self.discrete().space()
    }

    fn check_end(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        step: u64,
    ) -> Result<(), DiracError> {
        self.discrete().check_end(q, v, step)
    }

    fn constraint_point(&self) -> ConstraintPoint {
        EulerLagrange::constraint_point(self)
    }

    fn one_forms(&self) -> usize {
        S::ONE_FORMS
    }

    fn constraints(&self) -> usize {
        S::ONE_FORMS + S::HOLONOMIC
    }

    fn check_component_start(&self, state: &State<N>, tolerance: f64) -> Result<(), DiracError> {
        EulerLagrange::check_component_start(self, state, tolerance)
    }

    fn begin_as_component(&mut self, state: &State<N>) {
        EulerLagrange::begin_as_component(self, state);
    }

    fn set_coupling(&mut self, impulse: &SVector<f64, N>, share: f64) {
        EulerLagrange::set_coupling(self, impulse, share);
    }

    fn degenerate(&self, q: &SVector<f64, N>, v: &SVector<f64, N>) -> Degenerate {
        let system = self.discrete().system();
        let coordinates = degenerate(system, q, v);
        let p = crate::model::legendre::momentum(system, q, v);
        let turning = Self::turning(system, q, v, &coordinates);
        Degenerate {
            turning,
            momenta: coordinates.iter().map(|&i| (i, p[i])).collect(),
            coordinates,
            forms: HiddenConstraints::forms(system, q),
        }
    }

    fn legendre(&self, q: &SVector<f64, N>, v: &SVector<f64, N>) -> Legendre {
        let system = self.discrete().system();
        let l = seeded(system, q, v, Seed::VELOCITY, Seed::VELOCITY);
        Legendre {
            momentum: l.first.as_slice().to_vec(),
            hessian: DMatrix::from_column_slice(N, N, l.mixed.as_slice()),
            forms: HiddenConstraints::forms(system, q),
        }
    }

    fn as_coordinates<'a>(
        q: &'a SVector<f64, N>,
        v: &'a SVector<f64, N>,
    ) -> Option<(&'a SVector<f64, N>, &'a SVector<f64, N>)> {
        Some((q, v))
    }

    fn as_coordinates_mut(q: &mut SVector<f64, N>) -> Option<&mut SVector<f64, N>> {
        Some(q)
    }

    fn degenerate_rows(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        dead: &[usize],
        jacobians: bool,
    ) -> Rows {
        let system = self.discrete().system();
        degenerate_rows(system, dead, (q, v, t), self.inputs(), jacobians)
    }

    fn constant_forms(&self, q: &SVector<f64, N>) -> bool {
        constant_forms(self.discrete().system(), q)
    }
}

impl<S, C, const N: usize> ComponentEquations<N> for GroupEulerLagrange<S, N, C>
where
    S: DiracSystem<N, C::Manifold> + Send,
    C: ConfigurationSpace<N> + Send,
{
    type Space = C;

    fn space(&self) -> &C {
        self.discrete().space()
    }

    fn check_end(
        &self,
        q: &Point<C, N, f64>,
        v: &Tangent<C, N, f64>,
        step: u64,
    ) -> Result<(), DiracError> {
        self.discrete().check_end(q, v, step)
    }

    fn constraint_point(&self) -> ConstraintPoint {
        GroupEulerLagrange::constraint_point(self)
    }

    fn one_forms(&self) -> usize {
        S::ONE_FORMS
    }

    fn constraints(&self) -> usize {
        S::ONE_FORMS
    }

    /// [`StepEquations::check_start`], and kinetic energy in every coordinate: coordinates
    /// without it are held across components on `Rⁿ` only.
    fn check_component_start(
        &self,
        state: &State<N, C::Manifold>,
        tolerance: f64,
    ) -> Result<(), DiracError> {
        self.check_start(state, tolerance)?;
        let space = GroupEulerLagrange::discrete(self).space();
        let xi_dot = space
            .chart_velocity(&state.q, &state.velocity)
            .unwrap_or_else(SVector::zeros);
        // Probed at the velocity and at one moved by uneven amounts (a kinetic term can vanish
        // at one velocity).
        let moved = SVector::<f64, N>::from_fn(|i, _| {
            xi_dot[i] + 0.291 * (1.0 + 0.1 * i as f64) * (1.0 + xi_dot[i].abs())
        });
        let (_, here) = self.legendre_in_chart(&state.q, &xi_dot);
        let (_, there) = self.legendre_in_chart(&state.q, &moved);
        let without = (0..N).find(|&i| {
            here.column(i).iter().all(|x| *x == 0.0) && there.column(i).iter().all(|x| *x == 0.0)
        });
        match without {
            Some(i) => {
                let variables: Vec<String> = (0..<C::Manifold as Manifold<N>>::VARIABLES)
                    .map(|v| self.coordinate_name(v))
                    .collect();
                let names = <C::Manifold as Manifold<N>>::chart_names(&variables);
                Err(DiracError::Unsupported(format!(
                    "the modular step on {}, a coordinate without kinetic energy on a space of \
                     rotations (coordinates without kinetic energy are held across components \
                     on Rⁿ only)",
                    names[i]
                )))
            }
            None => Ok(()),
        }
    }

    fn begin_as_component(&mut self, state: &State<N, C::Manifold>) {
        self.begin(state);
    }

    fn set_coupling(&mut self, impulse: &SVector<f64, N>, share: f64) {
        GroupEulerLagrange::set_coupling(self, impulse, share);
    }

    /// None: refused at the start ([`check_component_start`](Self::check_component_start)).
    fn degenerate(&self, q: &Point<C, N, f64>, _v: &SVector<f64, N>) -> Degenerate {
        Degenerate {
            coordinates: Vec::new(),
            momenta: Vec::new(),
            turning: None,
            forms: self.forms(q),
        }
    }

    fn legendre(&self, q: &Point<C, N, f64>, v: &SVector<f64, N>) -> Legendre {
        let (momentum, hessian) = self.legendre_in_chart(q, v);
        Legendre {
            momentum: momentum.as_slice().to_vec(),
            hessian: DMatrix::from_column_slice(N, N, hessian.as_slice()),
            forms: self.forms(q),
        }
    }

    fn as_coordinates<'a>(
        _q: &'a Point<C, N, f64>,
        _v: &'a Tangent<C, N, f64>,
    ) -> Option<(&'a SVector<f64, N>, &'a SVector<f64, N>)> {
        None
    }

    fn as_coordinates_mut(_q: &mut Point<C, N, f64>) -> Option<&mut SVector<f64, N>> {
        None
    }

    /// No rows: it has no coordinates without kinetic energy.
    fn degenerate_rows(
        &self,
        _q: &SVector<f64, N>,
        _v: &SVector<f64, N>,
        _t: f64,
        dead: &[usize],
        _jacobians: bool,
    ) -> Rows {
        debug_assert!(
            dead.is_empty(),
            "no coordinates without kinetic energy here"
        );
        Rows::empty(N)
    }

    fn constant_forms(&self, _q: &SVector<f64, N>) -> bool {
        S::ONE_FORMS == 0
    }
}

/// A model's step equations `E` as a component.
pub(super) struct Model<E: ComponentEquations<N>, const N: usize> {
    equations: E,
    /// The chart coordinates' names.
    names: Vec<String>,
    /// The names of its point's numbers.
    position_names: Vec<String>,
    state: Option<State<N, E::Manifold>>,
    proposed: Option<State<N, E::Manifold>>,
    /// The work of the proposed step, and of the steps taken since the run began.
    proposed_work: Option<StepWork<N>>,
    work: Option<StepWork<N>>,
    /// The proposed step and the last one taken, in the chart at their start.
    step: SVector<f64, N>,
    last: SVector<f64, N>,
    x: DVector<f64>,
    residual: DVector<f64>,
    previous: DVector<f64>,
}

impl<E: ComponentEquations<N>, const N: usize> std::fmt::Debug for Model<E, N> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("coordinates", &self.names)
            .field("state", &self.state)
            .finish()
    }
}

impl<E: ComponentEquations<N>, const N: usize> Model<E, N> {
    pub(super) fn new(equations: E) -> Self {
        let n = equations.unknowns();
        let variables: Vec<String> = (0..<E::Manifold as Manifold<N>>::VARIABLES)
            .map(|i| equations.coordinate_name(i))
            .collect();
        Self {
            names: <E::Manifold as Manifold<N>>::chart_names(&variables),
            position_names: <E::Manifold as Manifold<N>>::point_names(&variables),
            equations,
            state: None,
            proposed: None,
            proposed_work: None,
            work: None,
            step: SVector::zeros(),
            last: SVector::zeros(),
            x: DVector::zeros(n),
            residual: DVector::zeros(n),
            previous: DVector::zeros(n),
        }
    }

    fn state(&self) -> &State<N, E::Manifold> {
        self.state
            .as_ref()
            .expect("a component steps only in a run")
    }

    fn space(&self) -> &E::Space {
        self.equations.space()
    }

    /// The model's velocity at `q` along the chart velocity `v`.
    fn tangent(&self, q: &Point<E::Space, N, f64>, v: &[f64]) -> Tangent<E::Space, N, f64> {
        let zero = SVector::zeros();
        self.space()
            .push_forward(q, &zero, &SVector::from_column_slice(v))
    }

    /// The proposed step `ξ` from the current state (on `Rⁿ` read off the positions, which a
    /// projection may have moved).
    fn measured_step(&self, solved: SVector<f64, N>) -> SVector<f64, N> {
        let (Some(now), Some(next)) = (&self.state, &self.proposed) else {
            return solved;
        };
        match (
            E::as_coordinates(&now.q, &now.velocity),
            E::as_coordinates(&next.q, &next.velocity),
        ) {
            (Some((q0, _)), Some((q1, _))) => q1 - q0,
            _ => solved,
        }
    }
}

impl<E: ComponentEquations<N> + 'static, const N: usize> Part for Model<E, N> {
    fn coordinates(&self) -> usize {
        N
    }

    fn coordinate_name(&self, i: usize) -> String {
        self.names[i].clone()
    }

    fn positions(&self) -> usize {
        self.position_names.len()
    }

    fn position_name(&self, i: usize) -> String {
        self.position_names[i].clone()
    }

    fn one_forms(&self) -> bool {
        self.equations.one_forms() > 0
    }

    fn point(&self) -> ConstraintPoint {
        self.equations.constraint_point()
    }

    fn inputs(&self) -> usize {
        self.equations.inputs().len()
    }

    fn input_name(&self, i: usize) -> String {
        self.equations.input_name(i)
    }

    fn set_input(&mut self, i: usize, value: f64) -> bool {
        let changed = self.equations.inputs()[i] != value;
        self.equations.inputs_mut()[i] = value;
        changed
    }

    fn input(&self, i: usize) -> f64 {
        self.equations.inputs()[i]
    }

    fn unknowns(&self) -> usize {
        self.equations.unknowns()
    }

    fn unknown_name(&self, column: usize) -> String {
        self.equations.unknown_name(column)
    }

    fn checked_start(&self, q: &[f64], v: &[f64], tolerance: f64) -> Result<Started, DiracError> {
        let q = <E::Manifold as Manifold<N>>::point_from_components(q).ok_or_else(|| {
            DiracError::Dimension(format!(
                "{} position numbers for a point of {}",
                q.len(),
                self.positions()
            ))
        })?;
        let v = self.tangent(&q, v);
        let p = self.equations.momentum(&q, &v)?;
        let state = State::<N, E::Manifold>::new(0.0, q, p, v);
        self.equations.check_component_start(&state, tolerance)?;
        Ok(Box::new(state))
    }

    fn degenerate(&self, q: &[f64], v: &[f64]) -> Degenerate {
        let q = <E::Manifold as Manifold<N>>::point_from_components(q)
            .expect("positions checked at the start");
        self.equations
            .degenerate(&q, &SVector::from_column_slice(v))
    }

    fn begin(&mut self, state: Started) {
        let state = *state
            .downcast::<State<N, E::Manifold>>()
            .expect("this component's state");
        self.equations.begin_as_component(&state);
        let n = self.equations.unknowns();
        (self.x, self.residual, self.previous) =
            (DVector::zeros(n), DVector::zeros(n), DVector::zeros(n));
        self.state = Some(state);
        self.proposed = None;
        self.work = Some(StepWork::zero());
        (self.step, self.last) = (SVector::zeros(), SVector::zeros());
    }

    fn stop(&mut self) {
        (self.state, self.proposed) = (None, None);
    }

    fn predict(&mut self, previous: Option<&[f64]>) {
        let state = *self.state();
        let previous = previous.map(|p| {
            self.previous.copy_from_slice(p);
            &self.previous
        });
        self.equations.predict(&state, previous, &mut self.x);
    }

    fn unknowns_of_step(&self) -> &[f64] {
        self.x.as_slice()
    }

    fn assemble(
        &mut self,
        impulse: &[f64],
        share: f64,
        x: &[f64],
        jacobian: Option<&mut DMatrix<f64>>,
    ) -> f64 {
        let state = *self.state();
        self.equations
            .set_coupling(&SVector::from_column_slice(impulse), share);
        self.x.copy_from_slice(x);
        self.equations
            .assemble(&state, &self.x, &mut self.residual, jacobian)
    }

    fn residual(&self) -> &[f64] {
        self.residual.as_slice()
    }

    fn advance(&mut self, x: &[f64], step: u64) -> Result<f64, DiracError> {
        let state = *self.state();
        self.x.copy_from_slice(x);
        let next = self.equations.advance(&state, &self.x, step)?;
        let violation = self.equations.violation(&state, &next, &self.x);
        self.proposed_work = self.equations.work(&state, &self.x);
        self.proposed = Some(next);
        // The step's end point is the first unknowns (degree 1).
        self.step = self.measured_step(SVector::from_column_slice(&x[..N]));
        Ok(violation)
    }

    fn proposed_step(&self, i: usize) -> f64 {
        if self.proposed.is_some() {
            self.step[i]
        } else {
            0.0
        }
    }

    fn accept(&mut self, t: f64) {
        if let Some(mut next) = self.proposed.take() {
            next.t = t;
            self.state = Some(next);
            self.last = self.step;
            self.work = self.work.zip(self.proposed_work).map(|(a, b)| a + b);
        }
    }

    fn discard(&mut self) {
        self.proposed = None;
    }

    fn last_step(&self, i: usize) -> f64 {
        self.last[i]
    }

    fn work(&self) -> Option<(f64, Option<f64>)> {
        self.work
            .map(|w| (w.total(), w.constraints.map(|c| c.sum())))
    }

    fn q(&self) -> Vec<f64> {
        let origin = <E::Manifold as Manifold<N>>::origin();
        let q = self.state.as_ref().map_or(&origin, |s| &s.q);
        <E::Manifold as Manifold<N>>::point_components(q)
    }

    fn chart_positions(
        &self,
        q: Option<&[f64]>,
        xi: &[f64],
        positions: &mut [f64],
        jacobian: &mut DMatrix<f64>,
    ) {
        let given = q.map(|q| {
            <E::Manifold as Manifold<N>>::point_from_components(q)
                .expect("a component's own position numbers")
        });
        let point = given.as_ref().unwrap_or_else(|| &self.state().q);
        let unit = |i: usize| SVector::<f64, N>::from_fn(|r, _| if r == i { 1.0 } else { 0.0 });
        let seeded: SVector<DualSVec64<N>, N> =
            SVector::from_fn(|k, _| DualSVec64::new(xi[k], Derivative::some(unit(k))));
        let moved = self.space().retract(point, &seeded);
        let entries = <E::Manifold as Manifold<N>>::point_entries(&moved);
        for (r, entry) in entries.iter().enumerate() {
            positions[r] = entry.re;
            let row = entry.eps.unwrap_generic(Const::<N>, U1);
            for i in 0..N {
                jacobian[(r, i)] = row[i];
            }
        }
    }

    fn p(&self) -> Vec<f64> {
        self.state.as_ref().map_or(vec![0.0; N], |s| {
            let zero = SVector::zeros();
            self.space()
                .pull_back(&s.q, &zero, &s.p)
                .as_slice()
                .to_vec()
        })
    }

    fn constraints(&self) -> usize {
        self.equations.constraints()
    }

    fn velocity_hint(&self) -> Vec<f64> {
        let state = self.state();
        let v = self.space().chart_velocity(&state.q, &state.velocity);
        v.unwrap_or_else(SVector::zeros).as_slice().to_vec()
    }

    fn legendre(&self, v: &[f64]) -> Legendre {
        self.equations
            .legendre(&self.state().q, &SVector::from_column_slice(v))
    }

    fn energy(&self, v: &[f64]) -> f64 {
        let state = self.state();
        let v = self.tangent(&state.q, v);
        self.equations.energy(&state.q, &state.p, &v)
    }

    fn degenerate_rows(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        dead: &[usize],
        jacobians: bool,
    ) -> Rows {
        // Coordinates without kinetic energy are on Rⁿ, where positions are coordinates.
        let Some(q) = coordinates::<N>(q) else {
            return Rows::empty(N);
        };
        let v = SVector::from_column_slice(v);
        self.equations.degenerate_rows(&q, &v, t, dead, jacobians)
    }

    fn constant_forms(&self, q: &[f64]) -> bool {
        coordinates::<N>(q).is_some_and(|q| self.equations.constant_forms(&q))
    }

    fn proposed(&self) -> Option<(&[f64], &[f64])> {
        let next = self.proposed.as_ref()?;
        let (q, v) = E::as_coordinates(&next.q, &next.velocity)?;
        Some((q.as_slice(), v.as_slice()))
    }

    fn shift_proposed(&mut self, i: usize, delta: f64) {
        if let Some(q) = self
            .proposed
            .as_mut()
            .and_then(|n| E::as_coordinates_mut(&mut n.q))
        {
            q[i] += delta;
            self.step[i] = self.measured_step(self.step)[i];
        }
    }

    fn check_proposed(&self, step: u64) -> Result<(), DiracError> {
        match &self.proposed {
            Some(next) => self.equations.check_end(&next.q, &next.velocity, step),
            None => Ok(()),
        }
    }
}

/// Positions as coordinates, where they are (on `Rⁿ`).
fn coordinates<const N: usize>(q: &[f64]) -> Option<SVector<f64, N>> {
    (q.len() == N).then(|| SVector::from_column_slice(q))
}
