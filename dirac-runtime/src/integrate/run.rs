//! What a run of a [`Stepper`](crate::Stepper) does: how far it goes, what it saves, which
//! events it looks for and who watches it; and what it returns.
//!
//! The step size is fixed, so a run covers whole steps: [`Run::until`] takes the fewest steps
//! that reach `t_end` (exactly `(t_end − t)/h` of them when that is a whole number to 1e-9).
//! Samples are the states the stepper reaches (every step, or every `k`-th, and always the last)
//! or, with [`Run::saveat`], the [dense output](crate::step::dense_output) at the given times.
//!
//! A [controller](Run::control) closes a loop inside the run: before each step it reads the
//! state the step starts from and sets the inputs, which are then held over the step (a
//! zero-order hold). The step's discrete forces are the quadrature of `F(q, q̇, t, u)` along
//! the step with `u` constant; on Rⁿ, for the midpoint rule, `f⁻ = f⁺ = (h/2) F(q_{k+½},
//! (q_{k+1} − q_k)/h, t_{k+½}, u_k)`.

use std::ops::ControlFlow;

use crate::base::error::DiracError;
use crate::integrate::event::{Crossing, Event};
use crate::integrate::trajectory::Trajectory;
use crate::solve::newton::NewtonReport;
use crate::space::manifold::{Manifold, Vectors};
use crate::step::dense_output::Sample;
use crate::step::step_equations::State;

/// How far a run goes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Horizon {
    Steps(u64),
    Until(f64),
}

/// The controller of a run.
type Controller<'a, const N: usize, M> = Box<dyn FnMut(&Feedback<'_, N, M>, &mut [f64]) + 'a>;

/// The watcher of a run.
type Observer<'a, const N: usize, M> = Box<dyn FnMut(&Progress<'_, N, M>) -> ControlFlow<()> + 'a>;

/// A run: its horizon, the samples to save, the events to locate and an observer called after
/// every step. Built by chaining, handed to [`Stepper::solve`](crate::Stepper::solve).
///
/// ```
/// use std::ops::ControlFlow;
/// use dirac_runtime::{DiracSystem, Quadrature, Run, Scalar, Status, Stepper};
/// use nalgebra::{SVector, vector};
/// struct Oscillator;
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
/// }
/// let mut stepper = Stepper::new(Oscillator, Quadrature::galerkin(2)?, 0.1)?.with_start_time(1.0);
/// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
/// let mut seen = 0;
/// let run = Run::until(3.0).saveat([1.0, 1.25, 2.5]).observe(|progress| {
///     seen = progress.steps;
///     ControlFlow::Continue(())
/// });
/// let solution = stepper.solve(run)?;
/// assert_eq!((solution.status, seen), (Status::Reached, 20));
/// assert_eq!(solution.trajectory.t(), &[1.0, 1.25, 2.5]);
/// assert!((solution.trajectory.q()[2][0] - 1.5_f64.cos()).abs() < 1e-5);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
pub struct Run<'a, const N: usize, M: Manifold<N> = Vectors> {
    horizon: Horizon,
    saveat: Option<Vec<f64>>,
    every: usize,
    pub(crate) events: Vec<Event<'a, N, M>>,
    pub(crate) observer: Option<Observer<'a, N, M>>,
    pub(crate) controller: Option<Controller<'a, N, M>>,
}

impl<const N: usize, M: Manifold<N>> std::fmt::Debug for Run<'_, N, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Run")
            .field("horizon", &self.horizon)
            .field("saveat", &self.saveat)
            .field("every", &self.every)
            .field("events", &self.events)
            .field("observer", &self.observer.is_some())
            .field("controller", &self.controller.is_some())
            .finish()
    }
}

impl<'a, const N: usize, M: Manifold<N>> Run<'a, N, M> {
    /// A run to time `t_end`: the fewest whole steps that reach it.
    pub fn until(t_end: f64) -> Self {
        Self::new(Horizon::Until(t_end))
    }

    /// A run of `steps` steps.
    pub fn steps(steps: u64) -> Self {
        Self::new(Horizon::Steps(steps))
    }

    fn new(horizon: Horizon) -> Self {
        Self {
            horizon,
            saveat: None,
            every: 1,
            events: Vec::new(),
            observer: None,
            controller: None,
        }
    }

    /// Saves the dense output at these times (ascending, inside the run's span) instead of the
    /// states the stepper reaches.
    pub fn saveat(self, times: impl IntoIterator<Item = f64>) -> Self {
        Self {
            saveat: Some(times.into_iter().collect()),
            ..self
        }
    }

    /// Saves the state of every `k`-th step (and the first and last); 1 by default, 0 is 1.
    pub fn every(self, k: usize) -> Self {
        Self {
            every: k.max(1),
            ..self
        }
    }

    /// Locates the sign changes of `event` (events are numbered in the order they are added).
    pub fn event(mut self, event: Event<'a, N, M>) -> Self {
        self.events.push(event);
        self
    }

    /// Calls `observer` after every step; [`ControlFlow::Break`] ends the run there.
    pub fn observe(
        self,
        observer: impl FnMut(&Progress<'_, N, M>) -> ControlFlow<()> + 'a,
    ) -> Self {
        Self {
            observer: Some(Box::new(observer)),
            ..self
        }
    }

    /// Calls `controller` before every step with the state the step starts from and the
    /// system's inputs (indexed as its `inputs(...)`, see [`Input::index`]), holding at their
    /// current values; the values it leaves are held over the step (a zero-order hold, see the
    /// [module](self)) and stay set after the run. The velocity it sees is solved, not
    /// estimated, so a controlled run solves it at every step. Events, save times, recording
    /// and partial results are as without a controller. A value that is not finite ends the run
    /// with an error before that step is taken, the inputs unchanged; a step that fails ends it
    /// with the controller's inputs set. On Rⁿ the closure's argument types are inferred once
    /// the run's dimension is named: `Run::<N>::steps(..)`.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Quadrature, Run, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// /// A unit mass pushed by the input u.
    /// struct Pushed;
    /// impl DiracSystem<1> for Pushed {
    ///     const FORCES: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([u[0]])
    ///     }
    ///     fn input_name(&self, _i: usize) -> String {
    ///         "u".into()
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Pushed, Quadrature::midpoint(), 0.01)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// let u = stepper.input("u")?.index();
    /// // A spring and a damper in the loop: u = −x − ẋ, held over each step.
    /// let damped = Run::<1>::until(20.0).every(100).control(|now, inputs| {
    ///     inputs[u] = -now.sample.q[0] - now.sample.v[0];
    /// });
    /// let solution = stepper.solve(damped)?;
    /// assert_eq!(solution.trajectory.len(), 21);
    /// assert!(stepper.q()[0].abs() < 1e-4); // ẍ + ẋ + x = 0 decays as e^{−t/2}
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    ///
    /// [`Input::index`]: crate::Input::index
    pub fn control(self, controller: impl FnMut(&Feedback<'_, N, M>, &mut [f64]) + 'a) -> Self {
        Self {
            controller: Some(Box::new(controller)),
            ..self
        }
    }

    /// Every `k`-th step is saved.
    pub(crate) fn stride(&self) -> usize {
        self.every
    }

    /// Whether the run needs the dense output.
    pub(crate) fn dense(&self) -> bool {
        self.saveat.is_some() || !self.events.is_empty()
    }

    /// Whether every step's velocity is needed: for the dense output, or for a controller.
    pub(crate) fn exact(&self) -> bool {
        self.dense() || self.controller.is_some()
    }

    /// The number of steps from time `t` with step `h`, and the save times checked against the
    /// span they cover.
    pub(crate) fn plan(&self, t: f64, h: f64) -> Result<(u64, Option<&[f64]>), DiracError> {
        let steps = match self.horizon {
            Horizon::Steps(steps) => steps,
            Horizon::Until(end) => {
                if !end.is_finite() || end < t {
                    return Err(DiracError::InvalidRun(format!(
                        "the run ends at t = {end}, before the stepper's time {t}"
                    )));
                }
                let exact = (end - t) / h;
                let whole = exact.round();
                let steps = if (exact - whole).abs() <= 1e-9 * exact.max(1.0) {
                    whole
                } else {
                    exact.ceil()
                };
                if steps > 1e15 {
                    return Err(DiracError::InvalidRun(format!(
                        "reaching t = {end} from {t} takes {steps:e} steps of {h}"
                    )));
                }
                steps as u64
            }
        };
        let last = t + steps as f64 * h;
        let slack = 1e-12 * (t.abs() + last.abs() + h);
        if let Some(times) = &self.saveat {
            let descending = |pair: &&[f64]| pair[0] > pair[1] || pair.iter().any(|t| t.is_nan());
            if let Some(pair) = times.windows(2).find(descending) {
                return Err(DiracError::InvalidRun(format!(
                    "save times must be ascending: {} comes before {}",
                    pair[0], pair[1]
                )));
            }
            if let Some(outside) = times
                .iter()
                .find(|&&s| !(s >= t - slack && s <= last + slack))
            {
                return Err(DiracError::InvalidRun(format!(
                    "the save time {outside} lies outside the run's span [{t}, {last}]"
                )));
            }
        }
        Ok((steps, self.saveat.as_deref()))
    }
}

/// What the observer of a run sees after each step.
#[derive(Debug, Clone, Copy)]
pub struct Progress<'s, const N: usize, M: Manifold<N> = Vectors> {
    /// Steps taken in this run.
    pub steps: u64,
    /// Steps the run will take if nothing stops it.
    pub total: u64,
    /// The state reached.
    pub state: &'s State<N, M>,
    /// How Newton's method went on the step.
    pub newton: NewtonReport,
}

/// What a controller sees before each step of a run: the state the step starts from.
#[derive(Debug, Clone, Copy)]
pub struct Feedback<'s, const N: usize, M: Manifold<N> = Vectors> {
    /// Steps taken in this run before the coming one.
    pub steps: u64,
    /// The state the step starts from: time, position, velocity and momentum.
    pub sample: &'s Sample<N, M>,
    /// The Lagrange multipliers of the last step (zeros before the stepper's first step; empty
    /// without constraints).
    pub multipliers: &'s [f64],
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// It took every step of its horizon.
    Reached,
    /// The terminal event with this index was located in its last step.
    Event(usize),
    /// The observer asked it to stop.
    Stopped,
}

/// What a run returns: the saved trajectory, the located events and how it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution<const N: usize, M: Manifold<N> = Vectors> {
    /// The saved samples.
    pub trajectory: Trajectory<N, M>,
    /// The located event crossings, in time order.
    pub events: Vec<Crossing<N, M>>,
    /// How the run ended.
    pub status: Status,
}

/// The sample at time `t` of the step from `before`'s time over `h`: the fraction of the step.
pub(crate) fn fraction<const N: usize, M: Manifold<N>>(
    before: &Sample<N, M>,
    t: f64,
    h: f64,
) -> f64 {
    ((t - before.t) / h).clamp(0.0, 1.0)
}
