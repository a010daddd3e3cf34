//! The trade between speed and accuracy, measured for the user's own model: a grid of
//! methods (quadratures, also by their step map where the step equations are linear with
//! constant coefficients and by fixed-point iteration where the model is unconstrained on `Rⁿ`;
//! for a separable model the explicit compositions, at a fixed step or time-transformed) ×
//! steps run to a horizon, each run's error against a reference, its energy error,
//! constraint violation, Newton iterations and wall time per unit of simulated time; and the
//! cheapest run meeting a target.
//!
//! The reference is the user's ([`Study::reference`]) or a converged run the study makes: the
//! highest-order Gauss rule the model accepts, at a quarter of the smallest step of the grid and
//! at half that. The two differ by the reference's own error estimate
//! ([`WorkPrecision::reference_error`]); a target below ten times it is refused, since the
//! study cannot tell whether a run meets it.
//!
//! Each run is measured twice: once recording every step (energy, constraint violation, Newton
//! iterations, the error at the horizon by [dense output](crate::step::dense_output)), and
//! [`Study::repetitions`] times recording nothing but its ends, for the wall time (the fastest
//! of the repetitions is kept).

use std::io::Write;
use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

use crate::base::error::DiracError;
use crate::base::float::largest;
use crate::integrate::run::Run;
use crate::integrate::stepper::Stepper;
use crate::integrate::time_transformation::TimeTransformed;
use crate::integrate::trajectory;
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;
use crate::space::manifold::Vectors;
use crate::step::composition::Composition;
use crate::step::dense_output::Sample;
use crate::step::step_equations::StepEquations;
use crate::step::verlet::Verlet;

/// How a study starts each of its steppers (e.g. `|s| s.start_from_velocity(q0, v0)`).
type Start<'a, S, const N: usize> = Box<dyn Fn(&mut Stepper<S, N>) -> Result<(), DiracError> + 'a>;

/// A speed/accuracy study of one model from one initial state to one horizon.
///
/// ```
/// use dirac_runtime::{DiracSystem, Quadrature, Sample, Scalar, work_precision::Study};
/// use nalgebra::{SVector, vector};
/// #[derive(Clone)]
/// struct Oscillator;
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
/// }
/// let exact = Sample { t: 10.0, q: vector![10f64.cos()], v: vector![-10f64.sin()], p: vector![-10f64.sin()] };
/// let study = Study::new(Oscillator, 10.0, |s| s.start_from_velocity(vector![1.0], vector![0.0]))
///     .steps([0.1, 0.05, 0.025])
///     .reference(exact)
///     .run()?;
/// // midpoint, galerkin(2), galerkin(3) × 3 steps, by Newton's method and by fixed-point iteration
/// assert_eq!(study.measurements.len(), 18);
/// let choice = study.cheapest(1e-6)?;
/// assert!(choice.error <= 1e-6);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
pub struct Study<'a, S: DiracSystem<N>, const N: usize> {
    system: S,
    horizon: f64,
    start: Start<'a, S, N>,
    quadratures: Vec<Quadrature>,
    compositions: Vec<Composition>,
    /// Whether the compositions are the default ones (not asked for).
    compositions_by_default: bool,
    steps: Vec<f64>,
    /// The offset `c` and the fictive steps of the time-transformed compositions, where asked.
    time_transformed: Option<(f64, Vec<f64>)>,
    repetitions: usize,
    /// The given reference and its error estimate.
    reference: Option<(Sample<N>, f64)>,
}

impl<S: DiracSystem<N>, const N: usize> std::fmt::Debug for Study<'_, S, N> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Study")
            .field("horizon", &self.horizon)
            .field("quadratures", &self.quadratures)
            .field("compositions", &self.compositions)
            .field("steps", &self.steps)
            .field("time_transformed", &self.time_transformed)
            .field("repetitions", &self.repetitions)
            .field("reference", &self.reference)
            .finish_non_exhaustive()
    }
}

/// One run of a study.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Measurement {
    /// The method's name: the quadrature's, or the composition's for an explicit step (followed
    /// by `, time-transformed` for a [`TimeTransformed`] one).
    pub quadrature: String,
    /// The step size (the fictive step `δs` of a time-transformed run).
    pub h: f64,
    /// Steps taken to the horizon.
    pub steps: u64,
    /// `max(|q(T) − q_ref(T)|, |p(T) − p_ref(T)|)` (∞-norms) at the horizon `T`.
    pub error: f64,
    /// `max_k |E_k − E_0|` over every step.
    pub energy_error: f64,
    /// The largest constraint violation of a step (0 for an unconstrained model).
    pub constraint_violation: f64,
    /// Newton iterations per step, on average.
    pub newton_iterations: f64,
    /// Steps of a run by fixed-point iteration that it handed to Newton's method, where the
    /// iteration did not settle (see [`Stepper::handed_over`]); 0 for every other run.
    pub handed_over: u64,
    /// Wall time per unit of simulated time, in seconds (the fastest repetition).
    pub seconds_per_unit_time: f64,
}

/// A run of the grid that could not be measured, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// The method's name: the quadrature's, or the composition's.
    pub quadrature: String,
    /// The step size.
    pub h: f64,
    /// Why (a refused quadrature, a step that failed, …).
    pub error: DiracError,
}

/// The measurements of a [`Study`].
#[derive(Debug, Clone, PartialEq)]
pub struct WorkPrecision<const N: usize> {
    /// The solution at the horizon the errors are measured against.
    pub reference: Sample<N>,
    /// How the reference was obtained (`given`, or the quadrature and step of the converged run).
    pub reference_method: String,
    /// The reference's own error estimate (the difference of the two converged runs, or the
    /// one given with the reference, 0 by default).
    pub reference_error: f64,
    /// One per run of the grid that could be measured, in grid order.
    pub measurements: Vec<Measurement>,
    /// The runs of the grid that could not be measured.
    pub failures: Vec<Failure>,
}

impl<'a, S: DiracSystem<N> + Clone, const N: usize> Study<'a, S, N> {
    /// A study of `system` to time `horizon`, each stepper started by `start`; by default
    /// `midpoint`, `galerkin(2)` and `galerkin(3)` (for a model on `Rⁿ` without constraints each
    /// also by fixed-point iteration, at every step whose first step the iteration settles;
    /// by the step map where the step equations are linear), and for a separable model without
    /// constraints or forces that read the velocity ([`DiracSystem::SEPARABLE`]) the explicit compositions of orders 2,
    /// 4, 6 and 8 ([`Composition::of_order`]), at `h = horizon/16, /32, /64, /128`, three timing
    /// repetitions, and a converged reference. An explicit step starts from the state and the
    /// inputs `start` gives a `midpoint` stepper; the default compositions are left out where
    /// the explicit step refuses the model's start (a singular mass matrix). Errors at a horizon
    /// inside a step come from dense output, of order 4 for the explicit steps: give steps that
    /// divide the horizon.
    pub fn new(
        system: S,
        horizon: f64,
        start: impl Fn(&mut Stepper<S, N>) -> Result<(), DiracError> + 'a,
    ) -> Self {
        let quadratures = [1, 2, 3]
            .iter()
            .filter_map(|&s| Quadrature::galerkin(s).ok())
            .collect();
        let explicit = S::SEPARABLE
            && S::ONE_FORMS + S::HOLONOMIC == 0
            && (!S::FORCES || S::FORCES_FREE_OF_VELOCITY);
        let compositions = match explicit {
            true => [2, 4, 6, 8]
                .iter()
                .filter_map(|&order| Composition::of_order(order).ok())
                .collect(),
            false => Vec::new(),
        };
        Self {
            system,
            horizon,
            start: Box::new(start),
            quadratures,
            compositions,
            compositions_by_default: true,
            steps: [16.0, 32.0, 64.0, 128.0].map(|n| horizon / n).to_vec(),
            time_transformed: None,
            repetitions: 3,
            reference: None,
        }
    }

    /// The quadratures of the grid.
    pub fn quadratures(self, quadratures: impl IntoIterator<Item = Quadrature>) -> Self {
        Self {
            quadratures: quadratures.into_iter().collect(),
            ..self
        }
    }

    /// The explicit compositions of the grid (none: quadratures only). A model the explicit step
    /// does not cover has each of its runs refused, reported in [`WorkPrecision::failures`].
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracSystem, Scalar, work_precision::Study};
    /// use nalgebra::{SVector, vector};
    /// #[derive(Clone)]
    /// struct Pendulum;
    /// impl DiracSystem<1> for Pendulum {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5 + q[0].cos()
    ///     }
    /// }
    /// let study = Study::new(Pendulum, 5.0, |s| s.start_from_velocity(vector![1.0], vector![0.0]))
    ///     .steps([0.1, 0.05])
    ///     .compositions([Composition::kahan_li_8()])
    ///     .run()?;
    /// // midpoint, galerkin(2), galerkin(3) (by Newton's method and by fixed-point iteration)
    /// // and Kahan–Li 8, at two steps.
    /// assert_eq!(study.measurements.len(), 14);
    /// let explicit = study.measurements.iter().find(|m| m.quadrature.starts_with("Kahan–Li 8"));
    /// assert_eq!(explicit.map(|m| m.newton_iterations), Some(0.0));
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn compositions(self, compositions: impl IntoIterator<Item = Composition>) -> Self {
        Self {
            compositions: compositions.into_iter().collect(),
            compositions_by_default: false,
            ..self
        }
    }

    /// The step sizes of the grid.
    pub fn steps(self, steps: impl IntoIterator<Item = f64>) -> Self {
        Self {
            steps: steps.into_iter().collect(),
            ..self
        }
    }

    /// Adds the grid's compositions time-transformed ([`TimeTransformed`]: `dt/ds = 1/(c − V(q))`
    /// with `c = offset`) at the fictive steps `fictive_steps`. Each run lands on the horizon;
    /// its energy error is measured at every step.
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracSystem, Sample, Scalar, work_precision::Study};
    /// use nalgebra::{SVector, vector};
    /// /// Kepler's problem, V = −1/|q|.
    /// #[derive(Clone)]
    /// struct Kepler;
    /// impl DiracSystem<2> for Kepler {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1]) * 0.5 + (q[0] * q[0] + q[1] * q[1]).sqrt().recip()
    ///     }
    /// }
    /// // One revolution of an orbit of eccentricity 0.9 from its pericentre.
    /// let (q0, v0) = (vector![0.1, 0.0], vector![0.0, 19f64.sqrt()]);
    /// let period = 2.0 * std::f64::consts::PI;
    /// let exact = Sample { t: period, q: q0, v: v0, p: v0 };
    /// let study = Study::new(Kepler, period, |s| s.start_from_velocity(q0, v0))
    ///     .quadratures([])
    ///     .compositions([Composition::kahan_li_8()])
    ///     .steps([period / 1000.0])
    ///     .time_transformed(0.0, [period / 25.0])
    ///     .reference(exact)
    ///     .run()?;
    /// let adaptive = study.cheapest(1e-8)?;
    /// assert_eq!(adaptive.quadrature, "Kahan–Li 8 (17 stages), time-transformed");
    /// assert!(adaptive.steps < 30);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn time_transformed(
        self,
        offset: f64,
        fictive_steps: impl IntoIterator<Item = f64>,
    ) -> Self {
        Self {
            time_transformed: Some((offset, fictive_steps.into_iter().collect())),
            ..self
        }
    }

    /// How many times each run is timed (the fastest counts; at least 1).
    pub fn repetitions(self, repetitions: usize) -> Self {
        Self {
            repetitions: repetitions.max(1),
            ..self
        }
    }

    /// The solution at the horizon to measure errors against (a closed form, or a run of
    /// another integrator), instead of a converged run.
    pub fn reference(self, reference: Sample<N>) -> Self {
        self.reference_with_error(reference, 0.0)
    }

    /// A reference of known accuracy, e.g. another integrator at a tight tolerance with `error`
    /// its difference from a run at a looser one: error targets below ten times `error` are
    /// refused, as for the converged reference.
    ///
    /// ```
    /// # use dirac_runtime::{DiracSystem, Sample, Scalar, work_precision::Study};
    /// # use nalgebra::{SVector, vector};
    /// # #[derive(Clone)]
    /// # struct Oscillator;
    /// # impl DiracSystem<1> for Oscillator {
    /// #     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    /// #         (v[0] * v[0] - q[0] * q[0]) * 0.5
    /// #     }
    /// # }
    /// // A reference known to about 1e-7 only.
    /// let rough = Sample { t: 1.0, q: vector![1f64.cos() + 1e-7], v: vector![-1f64.sin()], p: vector![-1f64.sin()] };
    /// let study = Study::new(Oscillator, 1.0, |s| s.start_from_velocity(vector![1.0], vector![0.0]))
    ///     .steps([0.1, 0.05])
    ///     .reference_with_error(rough, 1e-7)
    ///     .run()?;
    /// assert_eq!(study.reference_error, 1e-7);
    /// assert!(study.cheapest(1e-4).is_ok());
    /// assert!(study.cheapest(1e-7).is_err()); // below what the reference resolves
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn reference_with_error(self, reference: Sample<N>, error: f64) -> Self {
        Self {
            reference: Some((reference, error)),
            ..self
        }
    }

    /// Runs the grid. An error when the study itself is invalid (no quadrature or step, a step
    /// that is not positive, a horizon that is not, a reference at another time) or when no
    /// reference can be computed; a run of the grid that fails is reported in
    /// [`WorkPrecision::failures`].
    pub fn run(&self) -> Result<WorkPrecision<N>, DiracError> {
        self.check()?;
        let (reference, reference_method, reference_error) = match &self.reference {
            Some((given, error)) => (*given, "given".to_string(), *error),
            None => self.converged_reference()?,
        };
        let mut measurements = Vec::new();
        let mut failures = Vec::new();
        let mut record =
            |name: String, h: f64, measured: Result<Measurement, DiracError>| match measured {
                Ok(measurement) => measurements.push(measurement),
                Err(error) => failures.push(Failure {
                    quadrature: name,
                    h,
                    error,
                }),
            };
        for quadrature in &self.quadratures {
            for &h in &self.steps {
                let stepper = || self.stepper(quadrature, h);
                record(quadrature.name(), h, self.measure(&stepper, h, &reference));
            }
            // The same steps solved otherwise, named by `how`, at the steps `keep` takes.
            let mut solved_by = |how: &str,
                                 make: &dyn Fn(f64) -> Result<Stepper<S, N>, DiracError>,
                                 keep: &dyn Fn(f64) -> bool| {
                for &h in self.steps.iter().filter(|&&h| keep(h)) {
                    let name = format!("{}, {how}", quadrature.name());
                    let measured = self.measure(&|| make(h), h, &reference);
                    let named = measured.map(|m| Measurement {
                        quadrature: name.clone(),
                        ..m
                    });
                    record(name, h, named);
                }
            };
            // By fixed-point iteration, at each step whose first step the iteration settles (left
            // out, without failures, where the model is refused or that step is handed to
            // Newton's method: a mass matrix that is singular, as a circuit's, or a step too
            // large for the iteration to contract).
            let iterated = |h| {
                self.stepper(quadrature, h)
                    .and_then(Stepper::with_fixed_point)
            };
            let settles = |h| {
                iterated(h)
                    .is_ok_and(|mut trial| trial.step().is_ok() && trial.handed_over().0 == 0)
            };
            solved_by("fixed point", &iterated, &settles);
            // Where the model's step equations are linear with constant coefficients, by their
            // step map (left out, without failures, where they are not).
            let mapped = |h| self.stepper(quadrature, h).and_then(Stepper::with_step_map);
            if mapped(self.steps[0]).is_ok() {
                solved_by("step map", &mapped, &|_| true);
            }
        }
        // The default compositions are left out, without failures, for a separable model the
        // explicit step refuses at its start (a singular mass matrix: a circuit's capacitors).
        let refused = self.compositions_by_default
            && self.compositions.first().is_some_and(|c| {
                matches!(
                    self.explicit(c, self.steps[0]),
                    Err(DiracError::Unsupported(_))
                )
            });
        let compositions: &[Composition] = if refused { &[] } else { &self.compositions };
        for composition in compositions {
            for &h in &self.steps {
                let stepper = || self.explicit(composition, h);
                let name = composition.name().to_string();
                record(name, h, self.measure(&stepper, h, &reference));
            }
        }
        if let Some((offset, fictive_steps)) = &self.time_transformed {
            for composition in compositions {
                for &ds in fictive_steps {
                    let name = format!("{}, time-transformed", composition.name());
                    let measured =
                        self.measure_time_transformed(composition, *offset, ds, &reference);
                    record(name, ds, measured);
                }
            }
        }
        Ok(WorkPrecision {
            reference,
            reference_method,
            reference_error,
            measurements,
            failures,
        })
    }

    fn check(&self) -> Result<(), DiracError> {
        let invalid = |why: String| Err(DiracError::InvalidRun(why));
        if !(self.horizon.is_finite() && self.horizon > 0.0) {
            return invalid(format!(
                "the horizon must be positive, got {}",
                self.horizon
            ));
        }
        if self.quadratures.is_empty() && self.compositions.is_empty() || self.steps.is_empty() {
            return invalid("the grid needs at least one method and one step".into());
        }
        if let Some((offset, _)) = self
            .time_transformed
            .as_ref()
            .filter(|(c, _)| !c.is_finite())
        {
            return invalid(format!(
                "the offset of the time transformation must be finite, got {offset}"
            ));
        }
        let fictive = self.time_transformed.iter().flat_map(|(_, steps)| steps);
        if let Some(h) = self
            .steps
            .iter()
            .chain(fictive)
            .find(|h| !(h.is_finite() && **h > 0.0))
        {
            return invalid(format!("steps must be positive and finite, got {h}"));
        }
        if let Some((reference, error)) = &self.reference {
            if !(error.is_finite() && *error >= 0.0) {
                return invalid(format!(
                    "the reference's error estimate must be finite and not negative, got {error}"
                ));
            }
            if !reference
                .q
                .iter()
                .chain(&reference.p)
                .all(|x| x.is_finite())
            {
                return invalid(format!(
                    "the reference state must be finite, got q = {}, p = {}",
                    reference.q, reference.p
                ));
            }
            // The start function sets the time the horizon counts from.
            let t0 = self.stepper(&Quadrature::midpoint(), self.steps[0])?.t();
            let t_end = t0 + self.horizon;
            if (reference.t - t_end).abs() > 1e-12 * t_end.abs().max(1.0) {
                return invalid(format!(
                    "the reference is at t = {}, the horizon at {t_end}",
                    reference.t
                ));
            }
        }
        Ok(())
    }

    /// A started stepper with `quadrature` and step `h`.
    fn stepper(&self, quadrature: &Quadrature, h: f64) -> Result<Stepper<S, N>, DiracError> {
        let mut stepper = Stepper::new(self.system.clone(), quadrature.clone(), h)?;
        (self.start)(&mut stepper)?;
        Ok(stepper)
    }

    /// A started explicit stepper with `composition` and step `h`, from the state `start` gives
    /// a midpoint stepper.
    fn explicit(
        &self,
        composition: &Composition,
        h: f64,
    ) -> Result<Stepper<S, N, Verlet<S, N>>, DiracError> {
        let mut stepper = Stepper::explicit(self.system.clone(), composition.clone(), h)?;
        let start = self.stepper(&Quadrature::midpoint(), h)?;
        let state = start.state().ok_or(DiracError::NotStarted)?;
        // The inputs `start` set, held as the implicit runs hold them.
        stepper.set_inputs(start.inputs())?;
        stepper.start_from_state(*state)?;
        Ok(stepper)
    }

    /// The solution at the horizon by `quadrature` and step `h` (dense output when the horizon
    /// falls inside a step).
    fn solution(&self, quadrature: &Quadrature, h: f64) -> Result<Sample<N>, DiracError> {
        let mut stepper = self.stepper(quadrature, h)?;
        let t_end = stepper.t() + self.horizon;
        stepper.run_until(t_end)?;
        stepper.interpolate(t_end)
    }

    /// The highest-order Gauss rule the model accepts, at a quarter of the smallest step and at
    /// an eighth: the finer run, how it was made, and the difference of the two.
    fn converged_reference(&self) -> Result<(Sample<N>, String, f64), DiracError> {
        let smallest = self.steps.iter().cloned().fold(f64::INFINITY, f64::min);
        let mut refusal = None;
        for degree in [3, 2, 1] {
            let quadrature = Quadrature::galerkin(degree)?;
            let (coarse, fine) = (smallest / 4.0, smallest / 8.0);
            let runs = self
                .solution(&quadrature, coarse)
                .and_then(|a| Ok((a, self.solution(&quadrature, fine)?)));
            match runs {
                Ok((a, b)) => {
                    let difference = distance(&a, &b);
                    let method = format!("{} at h = {fine}", quadrature.name());
                    return Ok((b, method, difference));
                }
                Err(error) => refusal = Some(error),
            }
        }
        Err(refusal.expect("three rules were tried"))
    }

    /// One run of the grid, each of its steppers made (and started) by `make`.
    fn measure<E: StepEquations<N, System = S, Manifold = Vectors>>(
        &self,
        make: &dyn Fn() -> Result<Stepper<S, N, E>, DiracError>,
        h: f64,
        reference: &Sample<N>,
    ) -> Result<Measurement, DiracError> {
        let mut stepper = make()?;
        let t_end = stepper.t() + self.horizon;
        let mut iterations = 0;
        let run = Run::until(t_end).observe(|progress| {
            iterations += progress.newton.iterations;
            ControlFlow::Continue(())
        });
        let solution = stepper.solve(run)?;
        let end = stepper.interpolate(t_end)?;
        let error = distance(&end, reference);
        let trajectory = &solution.trajectory;
        let steps = stepper.steps();
        let fastest = self.fastest(make, |timed| {
            timed.solve(Run::until(t_end).every(usize::MAX))?;
            Ok(())
        })?;
        Ok(Measurement {
            quadrature: stepper.equations().method(),
            h,
            steps,
            error,
            energy_error: trajectory.max_energy_error(),
            constraint_violation: trajectory.max_constraint_violation(),
            newton_iterations: iterations as f64 / steps.max(1) as f64,
            handed_over: stepper.handed_over().0,
            seconds_per_unit_time: fastest / self.horizon,
        })
    }
}

impl<S: DiracSystem<N> + Clone, const N: usize> Study<'_, S, N> {
    /// The least wall time, in seconds, of [`Study::repetitions`] runs `run` of steppers `make`
    /// makes (the making not timed).
    fn fastest<T>(
        &self,
        make: impl Fn() -> Result<T, DiracError>,
        run: impl Fn(&mut T) -> Result<(), DiracError>,
    ) -> Result<f64, DiracError> {
        let mut fastest = f64::INFINITY;
        for _ in 0..self.repetitions {
            let mut timed = make()?;
            let clock = Instant::now();
            run(&mut timed)?;
            fastest = fastest.min(clock.elapsed().as_secs_f64());
        }
        Ok(fastest)
    }

    /// A started time-transformed stepper, from the state `start` gives a midpoint stepper.
    fn time_transformed_stepper(
        &self,
        composition: &Composition,
        offset: f64,
        ds: f64,
    ) -> Result<TimeTransformed<S, N>, DiracError> {
        let start = self.stepper(&Quadrature::midpoint(), self.steps[0])?;
        let state = start.state().ok_or(DiracError::NotStarted)?;
        let mut stepper = TimeTransformed::new(self.system.clone(), composition.clone(), ds)?
            .with_offset(offset)?
            .with_start_time(state.t);
        stepper.start_from_momentum(state.q, state.p)?;
        Ok(stepper)
    }

    /// One time-transformed run of the grid: recorded at every step, then timed.
    fn measure_time_transformed(
        &self,
        composition: &Composition,
        offset: f64,
        ds: f64,
        reference: &Sample<N>,
    ) -> Result<Measurement, DiracError> {
        let mut stepper = self.time_transformed_stepper(composition, offset, ds)?;
        let t_end = stepper.t() + self.horizon;
        let trajectory = stepper.trajectory_until(t_end)?;
        let end = stepper.sample().ok_or(DiracError::NotStarted)?;
        let fastest = self.fastest(
            || self.time_transformed_stepper(composition, offset, ds),
            |timed| timed.run_until(t_end),
        )?;
        Ok(Measurement {
            quadrature: format!("{}, time-transformed", composition.name()),
            h: ds,
            steps: stepper.steps(),
            error: distance(&end, reference),
            energy_error: trajectory.max_energy_error(),
            constraint_violation: 0.0,
            newton_iterations: 0.0,
            handed_over: 0,
            seconds_per_unit_time: fastest / self.horizon,
        })
    }
}

/// The largest difference between two states' positions and momenta (NaN where one is: a
/// run that left its domain cannot meet a target).
fn distance<const N: usize>(a: &Sample<N>, b: &Sample<N>) -> f64 {
    largest((a.q - b.q).iter().chain((a.p - b.p).iter()).copied())
}

impl<const N: usize> WorkPrecision<N> {
    /// The cheapest run (least wall time per unit time) whose error at the horizon is at most
    /// `target`; an error naming the most accurate run when none is, or when the target is below
    /// what the reference resolves (ten times its error estimate).
    pub fn cheapest(&self, target: f64) -> Result<&Measurement, DiracError> {
        self.cheapest_by("error at the horizon", target, |m| m.error)
    }

    /// The cheapest run whose largest energy error is at most `target` (the reference plays no
    /// part); an error naming the run with the smallest energy error when none is.
    pub fn cheapest_in_energy(&self, target: f64) -> Result<&Measurement, DiracError> {
        self.cheapest_by("energy error", target, |m| m.energy_error)
    }

    fn cheapest_by(
        &self,
        what: &str,
        target: f64,
        value: impl Fn(&Measurement) -> f64,
    ) -> Result<&Measurement, DiracError> {
        if what.starts_with("error") && target < 10.0 * self.reference_error {
            return Err(DiracError::InvalidRun(format!(
                "a target {what} of {target:e} is below what the reference resolves (its error \
                 is estimated at {:e}); pass a reference of your own",
                self.reference_error
            )));
        }
        let meeting = self.measurements.iter().filter(|m| value(m) <= target);
        if let Some(best) =
            meeting.min_by(|a, b| a.seconds_per_unit_time.total_cmp(&b.seconds_per_unit_time))
        {
            return Ok(best);
        }
        let closest = self
            .measurements
            .iter()
            .min_by(|a, b| value(a).total_cmp(&value(b)));
        Err(DiracError::InvalidRun(match closest {
            Some(m) => format!(
                "no run reaches a {what} of {target:e}: the smallest is {:e} ({}, h = {}); add \
                 smaller steps or a higher-order quadrature",
                value(m),
                m.quadrature,
                m.h
            ),
            None => "no run of the grid could be measured".into(),
        }))
    }

    /// Draws the work–precision chart to the PNG file `path`: `log₁₀` of the error at the
    /// horizon against `log₁₀` of the wall time per unit of simulated time, one line per
    /// quadrature (feature `plot`).
    #[cfg(feature = "plot")]
    pub fn save_png(&self, path: impl AsRef<Path>, title: &str) -> Result<(), DiracError> {
        use crate::study::plot::{Series, line_chart};
        let series = Series::by_label(self.measurements.iter().map(|m| {
            let point = (m.seconds_per_unit_time.log10(), m.error.log10());
            (&m.quadrature, point)
        }));
        let axes = (
            "log10 wall seconds per unit of simulated time",
            "log10 error at the horizon",
        );
        line_chart(path, title, axes, &series)
    }

    /// Writes one row per measurement as CSV with a header row.
    pub fn write_csv<W: Write>(&self, writer: W) -> Result<(), DiracError> {
        let io = |e: csv::Error| DiracError::Io(e.to_string());
        let mut w = csv::Writer::from_writer(writer);
        w.write_record([
            "quadrature",
            "h",
            "steps",
            "error",
            "energy_error",
            "constraint_violation",
            "newton_iterations",
            "handed_over",
            "seconds_per_unit_time",
        ])
        .map_err(io)?;
        for m in &self.measurements {
            w.write_record([
                m.quadrature.clone(),
                m.h.to_string(),
                m.steps.to_string(),
                m.error.to_string(),
                m.energy_error.to_string(),
                m.constraint_violation.to_string(),
                m.newton_iterations.to_string(),
                m.handed_over.to_string(),
                m.seconds_per_unit_time.to_string(),
            ])
            .map_err(io)?;
        }
        w.flush().map_err(|e| DiracError::Io(e.to_string()))
    }

    /// Writes the CSV to a file, creating its directory if needed.
    pub fn save_csv(&self, path: impl AsRef<Path>) -> Result<(), DiracError> {
        self.write_csv(trajectory::create(path.as_ref())?)
    }
}
