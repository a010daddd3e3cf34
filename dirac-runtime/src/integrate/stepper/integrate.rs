//! Runs: many steps with what a run saves, the events it locates and its observer, and the
//! dense output of the last step.

use std::ops::ControlFlow;

use super::Stepper;
use crate::base::error::DiracError;
use crate::integrate::event::{self, Crossing};
use crate::integrate::run::{self, Feedback, Progress, Run, Solution, Status};
use crate::integrate::trajectory::{Interrupted, Trajectory};
use crate::space::manifold::Manifold;
use crate::step::dense_output::Sample;
use crate::step::step_equations::{State, StepEquations};

impl<E: StepEquations<N>, const N: usize> Stepper<E::System, N, E> {
    /// Runs `steps` steps and returns the trajectory of every state, starting with the current
    /// one ([`solve`](Self::solve) with [`Run::steps`]).
    ///
    /// A step that fails (or whose energy cannot be computed) ends the run with
    /// [`Interrupted`], which keeps the trajectory up to the last good step, where the stepper
    /// stays; `?` turns it into its [`DiracError`].
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
    /// let mut stepper = Stepper::new(Free, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![0.0], vector![1.0])?;
    /// let trajectory = stepper.run(10)?;
    /// assert_eq!((trajectory.len(), stepper.steps()), (11, 10));
    /// assert!((trajectory.q()[10][0] - 1.0).abs() < 1e-15);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn run(
        &mut self,
        steps: u64,
    ) -> Result<Trajectory<N, E::Manifold>, Box<Interrupted<N, E::Manifold>>> {
        self.solve(Run::steps(steps))
            .map(|solution| solution.trajectory)
    }

    /// Runs to time `t_end` (the fewest whole steps that reach it; see [`Run::until`]) and
    /// returns the trajectory of every state, starting with the current one. Failures as for
    /// [`run`](Self::run).
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
    /// let mut stepper = Stepper::new(Free, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![0.0], vector![1.0])?;
    /// let trajectory = stepper.run_until(1.05)?; // 11 steps: the first time ≥ 1.05 is 1.1
    /// assert_eq!(stepper.steps(), 11);
    /// assert!((stepper.t() - 1.1).abs() < 1e-15);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn run_until(
        &mut self,
        t_end: f64,
    ) -> Result<Trajectory<N, E::Manifold>, Box<Interrupted<N, E::Manifold>>> {
        self.solve(Run::until(t_end))
            .map(|solution| solution.trajectory)
    }

    /// Carries out `run` from the current state: its steps, saved samples, events, observer and
    /// controller (see [`Run`]). A failing step ends it with [`Interrupted`], which keeps the samples and
    /// events up to the last good step, where the stepper stays; a sampled step is made
    /// current only once its energy could be computed. An invalid run (a span that ends
    /// before the current time, save times outside it) is refused before the first step.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Event, Quadrature, Run, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// struct Oscillator;
    /// impl DiracSystem<1> for Oscillator {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::galerkin(3)?, 0.2)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// // q = cos t crosses zero at π/2 + kπ.
    /// let zero = Event::new("q = 0", |_t, q: &SVector<f64, 1>, _v: &SVector<f64, 1>| q[0]);
    /// let solution = stepper.solve(Run::until(10.0).every(10).event(zero))?;
    /// let times: Vec<f64> = solution.events.iter().map(|c| c.sample.t).collect();
    /// assert_eq!(times.len(), 3);
    /// assert!((times[1] - 1.5 * std::f64::consts::PI).abs() < 1e-6);
    /// assert_eq!(solution.trajectory.len(), 6); // t = 0, 2, 4, 6, 8, 10
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn solve(
        &mut self,
        run: Run<'_, N, E::Manifold>,
    ) -> Result<Solution<N, E::Manifold>, Box<Interrupted<N, E::Manifold>>> {
        let mut solution = Solution {
            trajectory: self.trajectory(),
            events: Vec::new(),
            status: Status::Reached,
        };
        match self.carry_out(run, &mut solution) {
            Ok(()) => Ok(solution),
            Err(error) => Err(Box::new(Interrupted {
                trajectory: solution.trajectory,
                events: solution.events,
                error,
            })),
        }
    }

    /// The solution at time `t` inside the last step (dense output, see
    /// [`dense_output`](crate::step::dense_output)): its velocity is the time derivative of its
    /// position, and at the step's ends it is the stepper's state. An error before the first
    /// step of a run, for a time outside the last step, or for step equations without dense
    /// output.
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
    /// let mut stepper = Stepper::new(Oscillator, Quadrature::galerkin(2)?, 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.step()?;
    /// let inside = stepper.interpolate(0.05)?;
    /// assert!((inside.q[0] - 0.05_f64.cos()).abs() < 1e-6);
    /// assert!((inside.v[0] + 0.05_f64.sin()).abs() < 1e-5);
    /// assert!(stepper.interpolate(0.2).is_err());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn interpolate(&self, t: f64) -> Result<Sample<N, E::Manifold>, DiracError> {
        let Some(after) = self.state else {
            return Err(DiracError::NotStarted);
        };
        let before = self.before.ok_or_else(|| {
            DiracError::InvalidRun("dense output needs a step: none was taken yet".into())
        })?;
        let h = self.h();
        let slack = 1e-12 * (after.t.abs() + h);
        if !(t >= before.t - slack && t <= after.t + slack) {
            return Err(DiracError::InvalidRun(format!(
                "t = {t} lies outside the last step [{}, {}]",
                before.t, after.t
            )));
        }
        let ends = [before, after].map(|state| {
            let v = self.velocity_at(state.t, &state.q, &state.p, &state.velocity, true)?;
            Ok::<_, DiracError>(sample(&state, v))
        });
        let [a, b] = ends;
        let (a, b) = (a?, b?);
        let mut inside = self.dense_sample(&a, &b, run::fraction(&a, t, h))?;
        inside.t = t;
        Ok(inside)
    }

    /// The dense output at fraction `theta` of the last step, between the samples `a` and `b`.
    fn dense_sample(
        &self,
        a: &Sample<N, E::Manifold>,
        b: &Sample<N, E::Manifold>,
        theta: f64,
    ) -> Result<Sample<N, E::Manifold>, DiracError> {
        let x = self.predictor.last().ok_or(DiracError::NotStarted)?;
        let sample = self
            .equations
            .dense([a, b], x, theta)
            .ok_or_else(|| DiracError::Unsupported(format!("dense output of {}", E::NAME)))?;
        // The path between two good steps can leave the Lagrangian's domain, where the momentum
        // ∂L/∂v is not finite. Without allocating: paired with zero, a tangent vector gives
        // exactly 0 where its entries are finite and NaN where one is not.
        let pairing = |x: &<E::Manifold as Manifold<N>>::Tangent<f64>| {
            E::Manifold::pair(x, &E::Manifold::zero())
        };
        let (v, p) = (pairing(&sample.v), pairing(&sample.p));
        if v != 0.0 || p != 0.0 {
            return Err(DiracError::NonFinite {
                what: format!(
                    "the {} of the dense output at fraction {theta} of the step ending at t = {}",
                    if v != 0.0 { "velocity" } else { "momentum" },
                    b.t
                ),
                value: if v != 0.0 { v } else { p },
            });
        }
        Ok(sample)
    }

    /// The run's loop; `solution` keeps what was saved whatever happens.
    fn carry_out(
        &mut self,
        mut run: Run<'_, N, E::Manifold>,
        solution: &mut Solution<N, E::Manifold>,
    ) -> Result<(), DiracError> {
        let Some(start) = self.state else {
            return Err(DiracError::NotStarted);
        };
        let h = self.h();
        let (total, saveat) = run.plan(start.t, h)?;
        let saveat = saveat.map(<[f64]>::to_vec);
        let (every, exact) = (run.stride() as u64, run.exact());
        let trajectory = &mut solution.trajectory;
        // Room for the samples the run will save, up to 2²⁰ (a run that an event or observer
        // may stop early should not claim memory it might never use): recording allocates
        // nothing per sample, and past that size the buffers double a few times.
        let samples = match &saveat {
            Some(times) => times.len(),
            None => usize::try_from(total / every)
                .unwrap_or(usize::MAX)
                .saturating_add(2),
        };
        trajectory.reserve(samples.min(1 << 20));
        let (v, _) = self.sample_velocity(&start, &start.velocity)?;
        let mut current = sample(&start, v);
        let mut saved = 0;
        match &saveat {
            None => self.save(trajectory, &current, None)?,
            Some(times) => {
                while saved < times.len() && times[saved] <= start.t {
                    let at = Sample {
                        t: times[saved],
                        ..current
                    };
                    self.save(trajectory, &at, None)?;
                    saved += 1;
                }
            }
        }
        let mut signs = run
            .events
            .iter_mut()
            .map(|event| event.value(&current))
            .collect::<Result<Vec<f64>, _>>()?;
        // The controller's buffer: the inputs held over the last step, set from it after each call.
        let mut inputs = run.controller.as_ref().map(|_| self.inputs().to_vec());
        for k in 1..=total {
            let last = k == total;
            if let (Some(controller), Some(inputs)) = (&mut run.controller, &mut inputs) {
                let feedback = Feedback {
                    steps: k - 1,
                    sample: &current,
                    multipliers: &self.multipliers,
                };
                controller(&feedback, inputs);
                self.set_inputs(inputs)?;
            }
            let proposal = self.solve_step()?;
            let sampled = saveat.is_none() && (k % every == 0 || last);
            // The velocity is solved where it is used; otherwise the state's hint stands in.
            let exact = sampled || exact;
            let (reached, energy) = if exact {
                // The step's velocity hint is its mean velocity, half a step behind its end:
                // extrapolated by half the change since the last one, it is O(h²) off.
                let hint = proposal.next.velocity;
                let guess = <E::Manifold as Manifold<N>>::extrapolate(&hint, &current.v, 0.5);
                let (v, solved) = self.sample_velocity(&proposal.next, &guess)?;
                let energy = match (sampled, solved) {
                    (true, Some(energy)) if energy.is_finite() => Some(energy),
                    (true, _) => Some(self.energy_at(&proposal.next, &v, self.steps + 1)?),
                    (false, _) => None,
                };
                (sample(&proposal.next, v), energy)
            } else {
                (sample(&proposal.next, proposal.next.velocity), None)
            };
            self.accept(proposal);
            let previous = std::mem::replace(&mut current, reached);
            if let Some(times) = &saveat {
                while saved < times.len() && (times[saved] <= current.t || last) {
                    let theta = run::fraction(&previous, times[saved], h);
                    let inside = self.dense_sample(&previous, &current, theta)?;
                    self.save(
                        trajectory,
                        &Sample {
                            t: times[saved],
                            ..inside
                        },
                        None,
                    )?;
                    saved += 1;
                }
            }
            let mut stop = None;
            if !run.events.is_empty() {
                let found = solution.events.len();
                for (index, event) in run.events.iter_mut().enumerate() {
                    let sign = event.value(&current)?;
                    if let Some(direction) = event.crossing(signs[index], sign) {
                        let theta = event::locate(
                            |theta| {
                                let inside = self.dense_sample(&previous, &current, theta)?;
                                event.value(&inside)
                            },
                            signs[index],
                            sign,
                        )?;
                        solution.events.push(Crossing {
                            event: index,
                            name: event.name().to_string(),
                            direction,
                            sample: self.dense_sample(&previous, &current, theta)?,
                        });
                    }
                    signs[index] = sign;
                }
                solution.events[found..].sort_by(|a, b| a.sample.t.total_cmp(&b.sample.t));
                // The step's earliest terminal crossing is the one that ends the run.
                stop = solution.events[found..]
                    .iter()
                    .find(|c| run.events[c.event].is_terminal())
                    .map(|c| Status::Event(c.event));
            }
            if let Some(observer) = &mut run.observer {
                let state = self.state.as_ref().ok_or(DiracError::NotStarted)?;
                let newton = self.report.ok_or(DiracError::NotStarted)?;
                let progress = Progress {
                    steps: k,
                    total,
                    state,
                    newton,
                };
                if let ControlFlow::Break(()) = observer(&progress) {
                    stop = stop.or(Some(Status::Stopped));
                }
            }
            if sampled {
                self.save(trajectory, &current, energy)?;
            }
            if let Some(status) = stop {
                if saveat.is_none() && !sampled {
                    if !exact {
                        let Some(state) = self.state else {
                            return Err(DiracError::NotStarted);
                        };
                        current.v = self.sample_velocity(&state, &current.v)?.0;
                    }
                    self.save(trajectory, &current, None)?;
                }
                solution.status = status;
                return Ok(());
            }
        }
        Ok(())
    }

    /// Appends `sample` to `trajectory` with its `energy` (computed when `None`) and the last
    /// step's multipliers.
    fn save(
        &self,
        trajectory: &mut Trajectory<N, E::Manifold>,
        sample: &Sample<N, E::Manifold>,
        energy: Option<f64>,
    ) -> Result<(), DiracError> {
        let state = State::new(sample.t, sample.q, sample.p, sample.v);
        let energy = match energy {
            Some(energy) => energy,
            None => self.energy_at(&state, &sample.v, self.steps)?,
        };
        // A sample between steps (saveat) has no work of its own: the column is dropped.
        let work = self
            .work
            .filter(|_| self.state.map(|s| s.t) == Some(sample.t))
            .map(|work| work.total());
        let constraint = (!self.multipliers.is_empty())
            .then(|| (self.constraint_violation(), self.multipliers()));
        trajectory.record(sample, energy, work, constraint)
    }
}

/// The sample of `state` with velocity `v`.
fn sample<const N: usize, M: Manifold<N>>(state: &State<N, M>, v: M::Tangent<f64>) -> Sample<N, M> {
    Sample {
        t: state.t,
        q: state.q,
        v,
        p: state.p,
    }
}
