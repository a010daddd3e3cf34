//! Adaptive steps that keep the structure: the explicit variational step of a separable model
//! taken at a fixed step `δs` of a fictive time `s`, the physical time `t` a coordinate of the
//! extended phase space advancing by `dt/ds = 1/(c − V(q))` along the motion — short steps where
//! the potential is deep (a comet at pericentre), long ones where it is shallow.
//!
//! For `L = ½ vᵀ M v + bᵀ v − V(q)` with constant `M` and `b` ([`DiracSystem::SEPARABLE`]), let
//! `T(p) = ½ (p − b)ᵀ M⁻¹ (p − b)`, `E` the energy of the start, `U(q) = c − V(q)` (positive
//! along the motion, `c` the offset) and `p_t = c − E` the momentum conjugate to `t`, shifted by
//! the offset. The logarithmic Hamiltonian of the extended phase space `(q, t; p, p_t)`
//! (Mikkola & Tanikawa 1999; Preto & Tremaine 1999)
//!
//! ```text
//! Γ(q, t, p, p_t) = ln(T(p) + p_t) − ln U(q)
//! ```
//!
//! is zero along the motion (`T + p_t = T + c − E = c − V`) and generates it in `s`:
//!
//! ```text
//! dq/ds = M⁻¹ (p − b) / W,   dt/ds = 1 / W,   dp/ds = −∇V(q) / U(q),   W = T(p) + p_t,
//! ```
//!
//! which on `Γ = 0` are Lagrange's equations with `dt/ds = 1/U(q)`. `Γ` is a function of the
//! momenta plus one of the positions, so its Störmer–Verlet step in `s` is explicit: a drift by
//! half a step (the momenta, and so `W`, fixed), a kick by a whole step, a drift by half. That
//! step is the flow of a discrete Lagrangian of the extended system, symplectic in
//! `(q, t; p, p_t)`: the energy error stays bounded over long runs as with a fixed step.
//! [`Composition`]s raise its order in `δs` as they do a fixed step's; adjacent drifts are one.
//!
//! With `V = −μ/|q|` and `c = 0` the time transformation is Sundman's, `dt/ds = |q|/μ`, and the
//! step follows Kepler's orbit exactly: energy, angular momentum and the Runge–Lenz vector are
//! kept to round-off (tested from 8 to 100 steps a revolution), and only the time along the
//! orbit has an error, of the composition's order (`tests/suite/time_transformation.rs`).
//!
//! A run to a time `t_end` ends with a step of the fictive size that lands on it, found by the
//! Illinois method (`t` grows with the step). Positions, momenta and time are summed with
//! compensation. Constraints and forces are refused: the extended Hamiltonian holds neither.

use nalgebra::SVector;

use crate::base::error::DiracError;
use crate::base::float::{folded, two_sum, two_sum_add};
use crate::integrate::event;
use crate::integrate::trajectory::Trajectory;
use crate::model::derivatives;
use crate::model::legendre;
use crate::model::system::DiracSystem;
use crate::step::composition::Composition;
use crate::step::dense_output::Sample;
use crate::step::euler_lagrange::check_finite;
use crate::step::verlet::{Kinetic, not_explicit};

/// The explicit variational step of a separable model in a fictive time `s` with
/// `dt/ds = 1/(c − V(q))` (see the [module](self)): adaptive in `t`, symplectic in the extended
/// phase space.
///
/// ```
/// use dirac_runtime::{Composition, DiracSystem, Scalar, TimeTransformed};
/// use nalgebra::{SVector, vector};
///
/// /// Kepler's problem, V = −1/|q|.
/// struct Kepler;
/// impl DiracSystem<2> for Kepler {
///     const SEPARABLE: bool = true;
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
///         (v[0] * v[0] + v[1] * v[1]) * 0.5 + (q[0] * q[0] + q[1] * q[1]).sqrt().recip()
///     }
/// }
/// // An orbit of eccentricity 0.9 from its pericentre, 40 steps of s a revolution.
/// let mut comet = TimeTransformed::new(Kepler, Composition::kahan_li_8(), 0.157)?;
/// comet.start_from_velocity(vector![0.1, 0.0], vector![0.0, 19f64.sqrt()])?;
/// let energy = comet.energy()?;
/// comet.run_until(2.0 * std::f64::consts::PI)?; // one period
/// assert_eq!(comet.t(), 2.0 * std::f64::consts::PI);
/// assert!((comet.q() - vector![0.1, 0.0]).amax() < 1e-9);
/// assert!((comet.energy()? - energy).abs() < 1e-13);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct TimeTransformed<S, const N: usize> {
    system: S,
    composition: Composition,
    ds: f64,
    /// `c` in `U(q) = c − V(q)`.
    offset: f64,
    start_time: f64,
    /// The run's constants and state, from the start.
    motion: Option<Motion<N>>,
}

/// A run: its constants and where it is.
#[derive(Debug, Clone, Copy)]
struct Motion<const N: usize> {
    kinetic: Kinetic<N>,
    /// The energy of the start, `E`.
    energy: f64,
    at: Phase<N>,
}

/// A point of the extended phase space (`p_t` is the run's constant), with the carries of its
/// compensated sums and the steps taken to it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Phase<const N: usize> {
    t: f64,
    t_carry: f64,
    q: SVector<f64, N>,
    q_carry: SVector<f64, N>,
    p: SVector<f64, N>,
    p_carry: SVector<f64, N>,
    steps: u64,
}

impl<S: DiracSystem<N>, const N: usize> TimeTransformed<S, N> {
    /// The time-transformed step of `system` by `composition`, `ds` the fictive step, offset
    /// `c = 0` (`dt/ds = −1/V(q)`: for potentials negative along the motion, such as gravity's).
    /// Refused (`Unsupported`) for a model that does not declare [`DiracSystem::SEPARABLE`], or
    /// that has constraints or forces; `InvalidStep` for a `ds` that is not positive and finite.
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracError, DiracSystem, Scalar, TimeTransformed};
    /// use nalgebra::SVector;
    ///
    /// /// A damped oscillator: its force is not held by the extended Hamiltonian.
    /// struct Damped;
    /// impl DiracSystem<1> for Damped {
    ///     const SEPARABLE: bool = true;
    ///     const FORCES: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>, _t: f64, _u: &[D]) -> SVector<D, 1> {
    ///         SVector::from([v[0] * -0.1])
    ///     }
    /// }
    /// let refused = TimeTransformed::new(Damped, Composition::verlet(), 0.1);
    /// assert!(matches!(refused, Err(DiracError::Unsupported(_))));
    /// ```
    pub fn new(system: S, composition: Composition, ds: f64) -> Result<Self, DiracError> {
        if !(ds.is_finite() && ds > 0.0) {
            return Err(DiracError::InvalidStep { h: ds });
        }
        let forces = S::FORCES.then_some(
            "with forces or inputs (the extended Hamiltonian holds neither; Stepper::explicit \
             takes forces of the position, time and inputs at a fixed step)",
        );
        if let Some(why) = not_explicit::<S, N>(forces) {
            return Err(DiracError::Unsupported(format!(
                "the time-transformed step ({}) of a model {why}",
                composition.name()
            )));
        }
        for (name, value) in system.parameters() {
            if !value.is_finite() {
                return Err(DiracError::NonFinite {
                    what: format!("parameter {name}"),
                    value,
                });
            }
        }
        Ok(Self {
            system,
            composition,
            ds,
            offset: 0.0,
            start_time: 0.0,
            motion: None,
        })
    }

    /// The offset `c` in `dt/ds = 1/(c − V(q))`: a constant above the potential along the
    /// motion (the potential's largest value, or more: a larger `c` makes the steps more
    /// even). Refused where not finite, or, in a run, where `c − V(q) ≤ 0` at its state (nothing
    /// is changed then).
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracSystem, Scalar, TimeTransformed};
    /// use nalgebra::{SVector, vector};
    ///
    /// /// A pendulum, V = −cos q ≤ 1: with c = 2, dt/ds = 1/(2 + cos q).
    /// struct Pendulum;
    /// impl DiracSystem<1> for Pendulum {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5 + q[0].cos()
    ///     }
    /// }
    /// let mut pendulum = TimeTransformed::new(Pendulum, Composition::suzuki(), 0.1)?.with_offset(2.0)?;
    /// pendulum.start_from_velocity(vector![1.0], vector![0.0])?;
    /// pendulum.run_until(10.0)?;
    /// assert_eq!(pendulum.t(), 10.0);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_offset(mut self, offset: f64) -> Result<Self, DiracError> {
        if !offset.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the offset c of the time transformation".into(),
                value: offset,
            });
        }
        if let Some(motion) = &self.motion {
            self.check_potential(&motion.at.q, offset)?;
        }
        self.offset = offset;
        Ok(self)
    }

    /// Starts the next run at `t0` instead of 0.
    pub fn with_start_time(mut self, t0: f64) -> Self {
        self.start_time = t0;
        self
    }

    /// Starts a run from position `q0` and velocity `v0` at the start time. Fails, changing
    /// nothing, on a state that is not finite, kinetic terms that are not constant or not
    /// invertible (the claim of [`DiracSystem::SEPARABLE`] is checked here), or `c − V(q0) ≤ 0`.
    pub fn start_from_velocity(
        &mut self,
        q0: SVector<f64, N>,
        v0: SVector<f64, N>,
    ) -> Result<(), DiracError> {
        check_finite(&self.system, "initial position", &q0)?;
        check_finite(&self.system, "initial velocity", &v0)?;
        let kinetic = Kinetic::of(&self.system, &q0, &v0)?;
        let p0 = legendre::momentum(&self.system, &q0, &v0);
        self.start(kinetic, q0, p0)
    }

    /// Starts a run from position `q0` and momentum `p0 = ∂L/∂v` at the start time (fails as
    /// [`start_from_velocity`](Self::start_from_velocity) does).
    pub fn start_from_momentum(
        &mut self,
        q0: SVector<f64, N>,
        p0: SVector<f64, N>,
    ) -> Result<(), DiracError> {
        check_finite(&self.system, "initial position", &q0)?;
        check_finite(&self.system, "initial momentum", &p0)?;
        let kinetic = Kinetic::of(&self.system, &q0, &SVector::zeros())?;
        let v0 = kinetic.velocity(&p0);
        // The claim of constant kinetic terms is checked at the velocity too.
        Kinetic::of(&self.system, &q0, &v0)?;
        self.start(kinetic, q0, p0)
    }

    fn start(
        &mut self,
        kinetic: Kinetic<N>,
        q0: SVector<f64, N>,
        p0: SVector<f64, N>,
    ) -> Result<(), DiracError> {
        check_finite(&self.system, "initial momentum", &p0)?;
        if !self.start_time.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the start time".into(),
                value: self.start_time,
            });
        }
        self.check_potential(&q0, self.offset)?;
        let at = Phase {
            t: self.start_time,
            t_carry: 0.0,
            q: q0,
            q_carry: SVector::zeros(),
            p: p0,
            p_carry: SVector::zeros(),
            steps: 0,
        };
        let energy = self.energy_at(&kinetic, &at);
        if !energy.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the initial energy".into(),
                value: energy,
            });
        }
        self.motion = Some(Motion {
            kinetic,
            energy,
            at,
        });
        Ok(())
    }

    /// `c − V(q) > 0`, or the error that says it is not.
    fn check_potential(&self, q: &SVector<f64, N>, offset: f64) -> Result<(), DiracError> {
        let u = offset + self.system.lagrangian(q, &SVector::zeros());
        match u > 0.0 {
            true => Ok(()),
            false => Err(DiracError::Unsupported(format!(
                "the time transformation dt/ds = 1/(c − V(q)) where c − V(q) = {u:.3e} ≤ 0 (at \
                 q = {q:?}, c = {offset}): choose an offset c above the potential along the \
                 motion (with_offset)"
            ))),
        }
    }

    /// `T(p) + V(q)`.
    fn energy_at(&self, kinetic: &Kinetic<N>, at: &Phase<N>) -> f64 {
        let (_, kinetic_energy) = kinetic.velocity_and_energy(&at.p);
        kinetic_energy - self.system.lagrangian(&at.q, &SVector::zeros())
    }

    /// The step of fictive size `ds` from `from`: drifts and kicks of the composition.
    #[inline]
    fn advance(
        &self,
        motion: &Motion<N>,
        from: &Phase<N>,
        ds: f64,
    ) -> Result<Phase<N>, DiracError> {
        let coefficients = self.composition.coefficients();
        let p_t = self.offset - motion.energy;
        let mut next = *from;
        // Each sum in two parts, `x + lo`, folded back at the step's end (as in the fixed step).
        let (mut q_lo, mut p_lo, mut t_lo) = (-from.q_carry, -from.p_carry, -from.t_carry);
        let zero = SVector::zeros();
        let mut drift = 0.5 * coefficients[0] * ds;
        for (i, &gamma) in coefficients.iter().enumerate() {
            self.drift(
                &motion.kinetic,
                p_t,
                &mut next,
                (&mut q_lo, &mut t_lo),
                drift,
            )?;
            let (minus_v, force) =
                derivatives::value_and_position_gradient(&self.system, &next.q, &zero);
            let u = self.offset + minus_v;
            if u.is_nan() || u <= 0.0 {
                return Err(DiracError::OutsideDomain {
                    step: from.steps,
                    why: format!(
                        "the step reached q = {:?}, where c − V(q) = {u:.3e} is not positive \
                         and the time transformation dt/ds = 1/(c − V) is not defined",
                        next.q
                    ),
                });
            }
            two_sum_add(&mut next.p, &mut p_lo, &(force * (gamma * ds / u)));
            drift = match coefficients.get(i + 1) {
                Some(&following) => 0.5 * (gamma + following) * ds,
                None => 0.5 * gamma * ds,
            };
        }
        self.drift(
            &motion.kinetic,
            p_t,
            &mut next,
            (&mut q_lo, &mut t_lo),
            drift,
        )?;
        (next.q, next.q_carry) = folded(&next.q, &q_lo);
        (next.p, next.p_carry) = folded(&next.p, &p_lo);
        let (t, error) = two_sum(next.t, t_lo);
        (next.t, next.t_carry) = (t, -error);
        next.steps += 1;
        for (what, x) in [("position", &next.q), ("momentum", &next.p)] {
            if !x.iter().all(|v| v.is_finite()) {
                check_finite(
                    &self.system,
                    &format!("the {what} after step {}", from.steps),
                    x,
                )?;
            }
        }
        Ok(next)
    }

    /// Moves `q` and `t` by `ds` of the fictive time with the momenta fixed:
    /// `q += ds M⁻¹(p − b)/W`, `t += ds/W`, `W = T(p) + p_t`.
    #[inline(always)]
    fn drift(
        &self,
        kinetic: &Kinetic<N>,
        p_t: f64,
        next: &mut Phase<N>,
        (q_lo, t_lo): (&mut SVector<f64, N>, &mut f64),
        ds: f64,
    ) -> Result<(), DiracError> {
        let (v, kinetic_energy) = kinetic.velocity_and_energy(&next.p);
        let w = kinetic_energy + p_t;
        if w.is_nan() || w <= 0.0 {
            return Err(DiracError::OutsideDomain {
                step: next.steps,
                why: format!(
                    "the step reached T(p) + c − E = {w:.3e} ≤ 0 at p = {:?}, where time would \
                     stop or run backward",
                    next.p
                ),
            });
        }
        let rate = ds / w;
        two_sum_add(&mut next.q, q_lo, &(v * rate));
        let (t, error) = two_sum(next.t, rate);
        next.t = t;
        *t_lo += error;
        Ok(())
    }

    fn motion(&self) -> Result<&Motion<N>, DiracError> {
        self.motion.as_ref().ok_or(DiracError::NotStarted)
    }

    /// One step of the fictive time. A failed step changes nothing.
    pub fn step(&mut self) -> Result<(), DiracError> {
        let motion = self.motion()?;
        let next = self.advance(motion, &motion.at, self.ds)?;
        self.set(next);
        Ok(())
    }

    fn set(&mut self, at: Phase<N>) {
        if let Some(motion) = &mut self.motion {
            motion.at = at;
        }
    }

    /// `steps` steps; on a failed step the state is the last step's before it, and the error
    /// says which step failed.
    pub fn run(&mut self, steps: u64) -> Result<(), DiracError> {
        for _ in 0..steps {
            self.step()?;
        }
        Ok(())
    }

    /// Steps to `t_end` exactly: whole steps while they end before it, then one step of the
    /// fictive size that lands on it (`t` is then `t_end`). `InvalidRun` for an end before the
    /// current time; on a failed step the state is the last step's before it.
    pub fn run_until(&mut self, t_end: f64) -> Result<(), DiracError> {
        self.drive(&[t_end], |_, _, _| Ok(()))
    }

    /// [`run_until`](Self::run_until), recording the start and every step's end.
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracSystem, Scalar, TimeTransformed};
    /// use nalgebra::{SVector, vector};
    ///
    /// struct Kepler;
    /// impl DiracSystem<2> for Kepler {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1]) * 0.5 + (q[0] * q[0] + q[1] * q[1]).sqrt().recip()
    ///     }
    /// }
    /// let mut comet = TimeTransformed::new(Kepler, Composition::verlet(), 0.1)?;
    /// comet.start_from_velocity(vector![0.1, 0.0], vector![0.0, 19f64.sqrt()])?;
    /// let trajectory = comet.trajectory_until(1.0)?;
    /// // The steps are short at the pericentre, long at the apocentre.
    /// let dt: Vec<f64> = trajectory.t().windows(2).map(|w| w[1] - w[0]).collect();
    /// let longest = dt.iter().copied().fold(0.0, f64::max);
    /// assert!(dt[0] < 0.02 && longest > 5.0 * dt[0]);
    /// assert!(trajectory.max_energy_error() < 1e-13);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn trajectory_until(&mut self, t_end: f64) -> Result<Trajectory<N>, DiracError> {
        let start = self.motion()?.at;
        let mut trajectory = self.trajectory()?;
        self.record(&mut trajectory, &start)?;
        // Every step's end; an end at the start time is the start, recorded already.
        self.drive(&[t_end], |this, phase, _| match phase.steps > start.steps {
            true => this.record(&mut trajectory, phase),
            false => Ok(()),
        })?;
        Ok(trajectory)
    }

    /// An empty trajectory with the model's coordinate names.
    fn trajectory(&self) -> Result<Trajectory<N>, DiracError> {
        Trajectory::new((0..N).map(|i| self.system.coordinate_name(i)).collect())
    }

    /// Appends `phase` (of the current run) to `trajectory`, with its energy.
    fn record(&self, trajectory: &mut Trajectory<N>, phase: &Phase<N>) -> Result<(), DiracError> {
        let motion = self.motion()?;
        let sample = Sample {
            t: phase.t,
            q: phase.q,
            v: motion.kinetic.velocity(&phase.p),
            p: phase.p,
        };
        trajectory.push(&sample, self.energy_at(&motion.kinetic, phase))
    }

    /// Steps to the last of `times` (finite, increasing, none before now), landing on it, and
    /// calls `each(self, phase, saved)`: after every whole step (`saved` false, `phase` the
    /// state), and at each of `times` (`saved` true): a time equal to the current one with the
    /// state, a time inside a step with the step of fictive size that lands on it from the step's
    /// start, taken aside (the run goes on from the whole step), the last with the state it
    /// lands on.
    fn drive(
        &mut self,
        times: &[f64],
        mut each: impl FnMut(&Self, &Phase<N>, bool) -> Result<(), DiracError>,
    ) -> Result<(), DiracError> {
        let motion = *self.motion()?;
        if let Some(t) = times.iter().find(|t| !t.is_finite()) {
            return Err(DiracError::InvalidRun(format!(
                "the time {t} is not finite"
            )));
        }
        if let Some(pair) = times.windows(2).find(|w| w[1] <= w[0]) {
            return Err(DiracError::InvalidRun(format!(
                "times must increase, got {} then {}",
                pair[0], pair[1]
            )));
        }
        let Some(&last) = times.last() else {
            return Ok(());
        };
        if times[0] < motion.at.t {
            return Err(DiracError::InvalidRun(format!(
                "the time {} is before the current time {}",
                times[0], motion.at.t
            )));
        }
        let mut pending = times.iter().copied().peekable();
        while pending.next_if(|&t| t == motion.at.t).is_some() {
            each(self, &motion.at, true)?;
        }
        while pending.peek().is_some() {
            let at = self.motion()?.at;
            let next = self.whole_step(&motion, &at)?;
            while let Some(t) = pending.next_if(|&t| t <= next.t) {
                let landed = self.land(&motion, &at, next, t)?;
                if t == last {
                    self.set(landed);
                }
                each(self, &landed, true)?;
            }
            if next.t >= last {
                return Ok(());
            }
            self.set(next);
            each(self, &next, false)?;
        }
        Ok(())
    }

    /// The whole step from `at`, refused where it does not advance time (a composition with
    /// negative coefficients could turn time back over a large step: a run would never end).
    fn whole_step(&self, motion: &Motion<N>, at: &Phase<N>) -> Result<Phase<N>, DiracError> {
        let next = self.advance(motion, at, self.ds)?;
        if (next.t - at.t) - (next.t_carry - at.t_carry) <= 0.0 {
            return Err(DiracError::OutsideDomain {
                step: at.steps,
                why: format!(
                    "time did not advance over the step (from t = {}): the fictive step is too \
                     large for this composition",
                    at.t
                ),
            });
        }
        Ok(next)
    }

    /// Runs to the last of `times` (increasing, none before the current time), landing on it as
    /// [`run_until`](Self::run_until) does, and records the state at each of `times`. A time
    /// inside a step is reached by a step of the fictive size that lands on it from the step's
    /// start, taken aside: the run goes on from the whole step, so what is saved does not change
    /// the run; a time equal to the current one is saved without a step. `InvalidRun` for times
    /// that are not finite, not increasing or before now; on a failed step the state is the
    /// last step's before it and the states saved are dropped with the error.
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracSystem, Scalar, TimeTransformed};
    /// use nalgebra::{SVector, vector};
    ///
    /// struct Kepler;
    /// impl DiracSystem<2> for Kepler {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1]) * 0.5 + (q[0] * q[0] + q[1] * q[1]).sqrt().recip()
    ///     }
    /// }
    /// let mut comet = TimeTransformed::new(Kepler, Composition::kahan_li_8(), 0.2)?;
    /// comet.start_from_velocity(vector![0.1, 0.0], vector![0.0, 19f64.sqrt()])?;
    /// let times: Vec<f64> = (0..=10).map(|i| i as f64).collect();
    /// let saved = comet.trajectory_at(&times)?;
    /// assert_eq!(saved.t(), &times[..]);
    /// assert_eq!(comet.t(), 10.0);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn trajectory_at(&mut self, times: &[f64]) -> Result<Trajectory<N>, DiracError> {
        let mut trajectory = self.trajectory()?;
        self.drive(times, |this, phase, saved| match saved {
            true => this.record(&mut trajectory, phase),
            false => Ok(()),
        })?;
        Ok(trajectory)
    }

    /// The step from `at` of the fictive size that ends at `t_end`, given the whole step
    /// `beyond` that passes it: the Illinois method ([`event::illinois`]) on
    /// `u ↦ t(u δs) − t_end` over `(0, 1]`, keeping the last step that reaches `t_end`. The step
    /// found ends within a few ulps of `t_end`, and its time is set to `t_end`.
    fn land(
        &self,
        motion: &Motion<N>,
        at: &Phase<N>,
        beyond: Phase<N>,
        t_end: f64,
    ) -> Result<Phase<N>, DiracError> {
        let mut best = beyond;
        let reach = |u: f64| {
            let trial = self.advance(motion, at, u * self.ds)?;
            let f = trial.t - t_end;
            if f >= 0.0 {
                best = trial;
            }
            Ok(f)
        };
        event::illinois(reach, at.t - t_end, beyond.t - t_end)?;
        let miss = best.t - t_end;
        if miss.abs() > 64.0 * f64::EPSILON * t_end.abs().max(at.t.abs()).max(1.0) {
            return Err(DiracError::InvalidRun(format!(
                "the last step could not land on t = {t_end} (it ends {miss:.3e} away)"
            )));
        }
        best.t = t_end;
        best.t_carry = 0.0;
        Ok(best)
    }

    /// The model.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// The composition each step takes.
    pub fn composition(&self) -> &Composition {
        &self.composition
    }

    /// The fictive step `δs`.
    pub fn ds(&self) -> f64 {
        self.ds
    }

    /// The offset `c` in `dt/ds = 1/(c − V(q))`.
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// Current time (the start time before the start).
    pub fn t(&self) -> f64 {
        self.motion.map_or(self.start_time, |m| m.at.t)
    }

    /// Current position (zeros before the start).
    pub fn q(&self) -> SVector<f64, N> {
        self.motion.map_or_else(SVector::zeros, |m| m.at.q)
    }

    /// Current momentum `p = ∂L/∂v` (zeros before the start).
    pub fn p(&self) -> SVector<f64, N> {
        self.motion.map_or_else(SVector::zeros, |m| m.at.p)
    }

    /// Current velocity `v = M⁻¹ (p − b)` (zeros before the start).
    pub fn v(&self) -> SVector<f64, N> {
        self.motion
            .map_or_else(SVector::zeros, |m| m.kinetic.velocity(&m.at.p))
    }

    /// Fictive steps taken since the start.
    pub fn steps(&self) -> u64 {
        self.motion.map_or(0, |m| m.at.steps)
    }

    /// The energy `T(p) + V(q)` of the current state.
    pub fn energy(&self) -> Result<f64, DiracError> {
        let motion = self.motion()?;
        Ok(self.energy_at(&motion.kinetic, &motion.at))
    }

    /// `dt/ds = 1/(T(p) + c − E)` at the current state: a step of the fictive time `δs` covers
    /// about `δs · dt/ds` of time here.
    pub fn time_rate(&self) -> Result<f64, DiracError> {
        let motion = self.motion()?;
        let (_, kinetic_energy) = motion.kinetic.velocity_and_energy(&motion.at.p);
        Ok(1.0 / (kinetic_energy + self.offset - motion.energy))
    }

    /// The current state as a sample (`None` before the start).
    pub fn sample(&self) -> Option<Sample<N>> {
        self.motion.map(|m| Sample {
            t: m.at.t,
            q: m.at.q,
            v: m.kinetic.velocity(&m.at.p),
            p: m.at.p,
        })
    }
}
