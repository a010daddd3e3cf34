//! The explicit variational step of a Lagrangian `L = ½ vᵀ M v + bᵀ v − V(q)` with constant `M`
//! and `b` ([`DiracSystem::SEPARABLE`]), and its symmetric compositions.
//!
//! For such a Lagrangian the trapezoidal discrete Lagrangian
//! `L_d(q_0, q_1) = (h/2) [L(q_0, v̄) + L(q_1, v̄)]`, `v̄ = (q_1 − q_0)/h`, has discrete
//! Euler–Lagrange equations that are solved in closed form: with `g(q) = ∂L/∂q = −∇V(q)`,
//!
//! ```text
//! p_{1/2} = p_0 + (h/2) g(q_0),   q_1 = q_0 + h M⁻¹ (p_{1/2} − b),   p_1 = p_{1/2} + (h/2) g(q_1),
//! ```
//!
//! the Störmer–Verlet step: one gradient of the potential per step (the last of a step is the
//! first of the next), no Newton iteration, no Jacobian. It is the same map as the implicit
//! step of [`Quadrature::trapezoid`](crate::Quadrature::trapezoid), to round-off
//! (`tests/suite/explicit.rs`). A [`Composition`] of such steps of sizes `γ_i h` keeps the
//! discrete variational structure (each factor is the flow of a discrete Lagrangian) and raises
//! the order to 4, 6, 8 or 10.
//!
//! Forces that do not depend on the velocity ([`DiracSystem::FORCES_FREE_OF_VELOCITY`]: sources,
//! actuators, inputs held over the step) join the kicks as the trapezoidal rule's discrete forces
//! `f⁻ = (h/2) F(q_0, t_0, u)`, `f⁺ = (h/2) F(q_1, t_1, u)`, and each stage books the work
//! `½ (F(q_a) + F(q_b)) · (q_b − q_a)`: the step stays explicit.
//!
//! `M` and `b` are read at the start of a run; the claim that they are constant (and that
//! `∂²L/∂q∂v = 0`) is checked there at the start and at a second state, the forces' claim at the
//! start, and `M` must be invertible. Positions and momenta are summed with compensation, as in
//! the implicit steps. Models with constraints, or with forces that read the velocity (a damper,
//! a resistor), are refused: their steps are not explicit.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

use crate::base::error::DiracError;
use crate::base::float::{folded, row_sum_norm, two_sum_add};
use crate::discrete::discrete_lagrangian::DiscreteLagrangian;
use crate::discrete::state::State;
use crate::model::derivatives::{self, Seed};
use crate::model::legendre;
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;
use crate::solve::newton::{Newton, NewtonFailure};
use crate::space::manifold::Vectors;
use crate::step::composition::Composition;
use crate::step::dense_output::Sample;
use crate::step::euler_lagrange::check_finite;
use crate::step::step_equations::{StepEquations, StepWork};

/// A model whose attribute names its explicit step, `quadrature = explicit(kahan_li_8)` or
/// `explicit(8)` in `#[dirac_system]` (the attribute refuses it, at compile time, for a
/// Lagrangian that is not separable, for constraints and for forces that read a velocity):
/// [`Stepper::explicit_from_system`](crate::Stepper::explicit_from_system) takes that step.
///
/// ```
/// use dirac_runtime::{Composition, DiracSystem, ExplicitSystem, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
/// struct Pendulum;
/// impl DiracSystem<1> for Pendulum {
///     const SEPARABLE: bool = true;
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 0.5 + q[0].cos()
///     }
/// }
/// impl ExplicitSystem<1> for Pendulum {
///     fn composition(&self) -> Composition {
///         Composition::suzuki()
///     }
/// }
/// let stepper = Stepper::explicit_from_system(Pendulum, 0.1)?;
/// assert_eq!(stepper.composition().order(), 4);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[diagnostic::on_unimplemented(
    message = "`{Self}` names no explicit step",
    label = "the attribute names no explicit step for this model",
    note = "name one in the attribute, `quadrature = explicit(kahan_li_8)` or `explicit(8)`, or \
            pass one: `Stepper::explicit(model, Composition::kahan_li_8(), h)`"
)]
pub trait ExplicitSystem<const N: usize>: DiracSystem<N> {
    /// The composition the attribute names.
    fn composition(&self) -> Composition;
}

/// Why `S` has no explicit step, where it has none: not declared separable, constraints, or
/// the caller's `forces` refusal (those of velocity for the fixed step, any for the
/// time-transformed one).
pub(crate) fn not_explicit<S: DiracSystem<N>, const N: usize>(
    forces: Option<&'static str>,
) -> Option<&'static str> {
    if !S::SEPARABLE {
        Some(
            "not known to be separable: it needs L = ½ vᵀ M v + bᵀ v − V(q) with constant M and b \
             (DiracSystem::SEPARABLE, which #[dirac_system] derives from the Lagrangian)",
        )
    } else if S::ONE_FORMS + S::HOLONOMIC > 0 {
        Some("with constraints")
    } else {
        forces
    }
}

/// Relative size of a disagreement between the two probes of the kinetic energy that refuses a
/// model's claim to be separable.
const PROBE_TOLERANCE: f64 = 1e-8;

/// The explicit step of a separable Lagrangian: Störmer–Verlet or one of its compositions.
///
/// ```
/// use dirac_runtime::{Composition, DiracSystem, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
///
/// /// L = v²/2 − q²/2: M = 1, V = q²/2.
/// struct Oscillator;
/// impl DiracSystem<1> for Oscillator {
///     const SEPARABLE: bool = true;
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
/// }
/// let mut stepper = Stepper::explicit(Oscillator, Composition::kahan_li_8(), 0.1)?;
/// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
/// stepper.run(10)?;
/// assert!((stepper.q()[0] - 1f64.cos()).abs() < 1e-11);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Verlet<S, const N: usize> {
    /// The trapezoidal discrete Lagrangian whose flow each stage is (the model and `h`).
    discrete: DiscreteLagrangian<S, N>,
    composition: Composition,
    /// `M⁻¹` and `b` of the run (read when it begins).
    kinetic: Option<Kinetic<N>>,
    /// The last gradient taken, with the position it was taken at: the next step's first.
    memo: Option<(SVector<f64, N>, SVector<f64, N>)>,
    /// The inputs' values, held over each step.
    inputs: Vec<f64>,
    /// The step [`predict`](StepEquations::predict) took, from the state it took it from.
    proposal: Option<(State<N>, Taken<N>)>,
}

/// A step taken: the state it reached (not yet checked to be finite), the gradient of the
/// potential at its end, and the work of its forces on each coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Taken<const N: usize> {
    next: State<N>,
    gradient: SVector<f64, N>,
    work: SVector<f64, N>,
}

impl<const N: usize> Taken<N> {
    /// The step's work: its forces', by stage; no constraints.
    fn step_work(&self) -> StepWork<N> {
        StepWork {
            forces: self.work,
            constraints: Some(SVector::zeros()),
        }
    }
}

/// The constant kinetic terms: `v = M⁻¹ (p − b)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Kinetic<const N: usize> {
    mass: SMatrix<f64, N, N>,
    inverse_mass: SMatrix<f64, N, N>,
    offset: SVector<f64, N>,
    /// `M = I` and `b = 0` exactly: `v = p`.
    unit: bool,
}

impl<const N: usize> Kinetic<N> {
    /// `M⁻¹` and `b` at `(q, v)`, checked against a second state: `∂²L/∂q∂v = 0` at both, the
    /// same `∂²L/∂v² = M` and `∂L/∂v − M v = b` at both, `M` invertible.
    pub(crate) fn of<S: DiracSystem<N>>(
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Result<Self, DiracError> {
        let at = |q: &SVector<f64, N>, v: &SVector<f64, N>| {
            let h = derivatives::hessian(system, q, v);
            (h.vv, h.gradient.v - h.vv * v, h.qv)
        };
        let (mass, offset, mixed) = at(q, v);
        if !(mass.iter().chain(offset.iter()).all(|x| x.is_finite())) {
            return Err(DiracError::NonFinite {
                what: "∂²L/∂v² or ∂L/∂v at the start".into(),
                value: mass
                    .iter()
                    .chain(offset.iter())
                    .copied()
                    .find(|x| !x.is_finite())
                    .unwrap_or(f64::NAN),
            });
        }
        // A second state, moved by uneven amounts (a term may vanish at one state).
        let q2 = derivatives::moved(q, derivatives::POSITION_SHIFT);
        let v2 = derivatives::moved(v, derivatives::VELOCITY_SHIFT);
        let (mass2, offset2, mixed2) = at(&q2, &v2);
        let scale = 1.0 + mass.amax() + offset.amax();
        let differs = |a: f64, b: f64| (a - b).abs() > PROBE_TOLERANCE * scale;
        let probe_finite = mass2.iter().chain(offset2.iter()).all(|x| x.is_finite());
        let inconsistent = mixed.iter().any(|&x| differs(x, 0.0))
            || (probe_finite
                && (mixed2.iter().any(|&x| differs(x, 0.0))
                    || mass.iter().zip(mass2.iter()).any(|(&a, &b)| differs(a, b))
                    || offset
                        .iter()
                        .zip(offset2.iter())
                        .any(|(&a, &b)| differs(a, b))));
        if inconsistent {
            return Err(DiracError::InconsistentDerivatives(format!(
                "the model declares SEPARABLE, but its ∂²L/∂q∂v is not zero or its ∂²L/∂v² or \
                 ∂L/∂v − (∂²L/∂v²) v changes between (q, v) = ({q:?}, {v:?}) and ({q2:?}, \
                 {v2:?})"
            )));
        }
        let kinetic = Self::frozen(mass).ok_or_else(|| {
            DiracError::Unsupported(format!(
                "the explicit step of a model whose mass matrix ∂²L/∂v² is singular ({} carries \
                 no kinetic energy of its own); Stepper::new steps it with a quadrature",
                (0..N)
                    .find(|&i| mass.row(i).iter().all(|&x| x == 0.0))
                    .map_or_else(
                        || "some combination of the velocities".to_string(),
                        |i| system.coordinate_name(i)
                    )
            ))
        })?;
        Ok(Kinetic {
            unit: mass == SMatrix::<f64, N, N>::identity() && offset == SVector::<f64, N>::zeros(),
            offset,
            ..kinetic
        })
    }

    /// The kinetic terms of a mass matrix `mass` (`b = 0`): also those of one step, for the
    /// iteration on the rows of a model that is not separable; `None` where `mass` has no finite
    /// inverse.
    pub(crate) fn frozen(mass: SMatrix<f64, N, N>) -> Option<Self> {
        let inverse_mass = mass
            .try_inverse()
            .filter(|inverse| inverse.iter().all(|x| x.is_finite()))?;
        Some(Kinetic {
            unit: false,
            mass,
            inverse_mass,
            offset: SVector::zeros(),
        })
    }

    /// The largest row sum of `|M⁻¹|`: how much `M⁻¹` may enlarge a vector's round-off.
    pub(crate) fn inverse_mass_norm(&self) -> f64 {
        match self.unit {
            true => 1.0,
            false => row_sum_norm(&self.inverse_mass, &mut [0.0; N]),
        }
    }

    /// `v = M⁻¹ (p − b)` and the kinetic energy `T(p) = ½ vᵀ M v = ½ v · (p − b)`.
    #[inline]
    pub(crate) fn velocity_and_energy(&self, p: &SVector<f64, N>) -> (SVector<f64, N>, f64) {
        let v = self.velocity(p);
        let energy = match self.unit {
            true => 0.5 * v.dot(&v),
            false => 0.5 * v.dot(&(p - self.offset)),
        };
        (v, energy)
    }

    /// `M x`.
    #[inline]
    pub(crate) fn momentum_times(&self, x: &SVector<f64, N>) -> SVector<f64, N> {
        match self.unit {
            true => *x,
            false => self.mass * x,
        }
    }

    /// `M⁻¹ x`.
    #[inline]
    pub(crate) fn inverse_mass_times(&self, x: &SVector<f64, N>) -> SVector<f64, N> {
        match self.unit {
            true => *x,
            false => self.inverse_mass * x,
        }
    }

    /// `v = M⁻¹ (p − b)`.
    #[inline]
    pub(crate) fn velocity(&self, p: &SVector<f64, N>) -> SVector<f64, N> {
        match self.unit {
            true => *p,
            false => self.inverse_mass * (p - self.offset),
        }
    }
}

impl<S: DiracSystem<N>, const N: usize> Verlet<S, N> {
    /// The explicit step of `system` by `composition` with step `h`. Refused (`Unsupported`)
    /// for a model that does not declare [`DiracSystem::SEPARABLE`], that has constraints, or
    /// forces that are not [`FORCES_FREE_OF_VELOCITY`](DiracSystem::FORCES_FREE_OF_VELOCITY);
    /// `InvalidStep` and `NonFinite` as for any stepper.
    ///
    /// ```
    /// use dirac_runtime::{Composition, DiracError, DiracSystem, Scalar, Verlet};
    /// use nalgebra::SVector;
    ///
    /// /// A pendulum on a cart: its mass matrix depends on the angle.
    /// struct CartPendulum;
    /// impl DiracSystem<2> for CartPendulum {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
    ///         v[0] * v[0] + v[0] * v[1] * q[1].cos() + v[1] * v[1] * 0.5 + q[1].cos()
    ///     }
    /// }
    /// let refused = Verlet::new(CartPendulum, Composition::verlet(), 0.1);
    /// assert!(matches!(refused, Err(DiracError::Unsupported(_))));
    /// ```
    pub fn new(system: S, composition: Composition, h: f64) -> Result<Self, DiracError> {
        let discrete = DiscreteLagrangian::new(system, Quadrature::trapezoid(), h);
        discrete.check()?;
        let forces = (S::FORCES && !S::FORCES_FREE_OF_VELOCITY).then_some(
            "with forces that may depend on the velocity (DiracSystem::FORCES_FREE_OF_VELOCITY \
             is not declared: a force reading dot(x) makes the step implicit)",
        );
        if let Some(why) = not_explicit::<S, N>(forces) {
            return Err(DiracError::Unsupported(format!(
                "the explicit step ({}) of a model {why}; Stepper::new steps it with a quadrature",
                composition.name()
            )));
        }
        Ok(Self {
            discrete,
            composition,
            kinetic: None,
            memo: None,
            inputs: vec![0.0; S::INPUTS],
            proposal: None,
        })
    }

    /// The composition the step takes.
    pub fn composition(&self) -> &Composition {
        &self.composition
    }

    /// `g(q) = ∂L/∂q`, which does not depend on the velocity (taken at zero).
    fn gradient(&self, q: &SVector<f64, N>) -> SVector<f64, N> {
        derivatives::directional_gradient(
            self.discrete.system(),
            q,
            &SVector::zeros(),
            Seed::POSITION,
        )
    }

    /// The force `F(q, t, u)` with the held inputs (zero for a model without forces), read at
    /// zero velocity.
    fn force(&self, q: &SVector<f64, N>, t: f64) -> SVector<f64, N> {
        match S::FORCES {
            true => self
                .discrete
                .system()
                .force(q, &SVector::zeros(), t, &self.inputs),
            false => SVector::zeros(),
        }
    }

    /// Checks at `q` that the forces do not read the velocity: the same force at rest, at `v`
    /// and at a velocity moved from `v` by uneven amounts (a start at rest proves nothing).
    fn check_forces(
        &self,
        t: f64,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Result<(), DiracError> {
        if !S::FORCES {
            return Ok(());
        }
        let at_rest = self.force(q, t);
        let scale = 1.0 + at_rest.amax();
        for velocity in [*v, derivatives::moved(v, derivatives::VELOCITY_SHIFT)] {
            let moving = self.discrete.system().force(q, &velocity, t, &self.inputs);
            if (at_rest - moving).amax() > PROBE_TOLERANCE * scale {
                return Err(DiracError::InconsistentDerivatives(format!(
                    "the model declares FORCES_FREE_OF_VELOCITY, but its force at q = {q:?} is \
                     {at_rest:?} at rest and {moving:?} at v = {velocity:?}"
                )));
            }
        }
        Ok(())
    }

    /// The step from `state` with the run's kinetic terms, starting from the gradient `first`
    /// at `state.q` where it is known. The last half kick of a stage and the first of the next
    /// act at the same point: they are one kick `(γ_i + γ_{i+1}) h/2`.
    fn take_step(
        &self,
        state: &State<N>,
        kinetic: &Kinetic<N>,
        first: Option<SVector<f64, N>>,
    ) -> Taken<N> {
        let h = self.discrete.h();
        let coefficients = self.composition.coefficients();
        let mut next = *state;
        let mut g = first.unwrap_or_else(|| self.gradient(&state.q));
        let mut t = state.t;
        let mut force = self.force(&state.q, t);
        let mut work = SVector::zeros();
        // `∂L/∂q + F`: the force's zeros are not added where there is none.
        let pull = |g: &SVector<f64, N>, force: &SVector<f64, N>| match S::FORCES {
            true => g + force,
            false => *g,
        };
        // Within the step each sum is held in two parts, `x + lo` (the state's carry is `−lo`):
        // the rounding error of every addition into `x` is found exactly (TwoSum) and gathered
        // in `lo`, folded back at the step's end. On the chain from one stage's gradient to the
        // next there is then one addition per sum, where compensating each addition puts two.
        let (mut p_lo, mut q_lo) = (-next.p_carry, -next.q_carry);
        let mut kick = 0.5 * coefficients[0] * h;
        for (i, &gamma) in coefficients.iter().enumerate() {
            two_sum_add(&mut next.p, &mut p_lo, &(pull(&g, &force) * kick));
            let increment = kinetic.velocity(&next.p) * (gamma * h);
            two_sum_add(&mut next.q, &mut q_lo, &increment);
            if i + 1 == coefficients.len() {
                // The end position is the state's: the gradient and force carried to the next
                // step's first kick are taken at it, so a step depends on its state alone.
                (next.q, next.q_carry) = folded(&next.q, &q_lo);
            }
            t += gamma * h;
            g = self.gradient(&next.q);
            if S::FORCES {
                let end = self.force(&next.q, t);
                work += ((force + end) * 0.5).component_mul(&increment);
                force = end;
            }
            kick = match coefficients.get(i + 1) {
                Some(&following) => 0.5 * gamma * h + 0.5 * following * h,
                None => 0.5 * gamma * h,
            };
        }
        two_sum_add(&mut next.p, &mut p_lo, &(pull(&g, &force) * kick));
        (next.p, next.p_carry) = folded(&next.p, &p_lo);
        next.velocity = kinetic.velocity(&next.p);
        Taken {
            next,
            gradient: g,
            work,
        }
    }

    /// `next` where its position and momentum are finite, else the error naming the first
    /// coordinate that is not.
    fn finite(&self, next: State<N>, step: u64) -> Result<State<N>, DiracError> {
        for (what, x) in [("position", &next.q), ("momentum", &next.p)] {
            // The message is written only for a step that left the finite numbers.
            if !x.iter().all(|v| v.is_finite()) {
                check_finite(self.system(), &format!("the {what} after step {step}"), x)?;
            }
        }
        Ok(next)
    }

    /// The step from `state` with the run's kinetic terms, its first gradient the last one
    /// taken where the step before ended at `state.q`; that step's last gradient is kept for
    /// the next.
    fn step_from(&mut self, state: &State<N>) -> Result<Taken<N>, DiracError> {
        let kinetic = self.kinetic_at(state)?;
        let first = self.memo.filter(|(q, _)| *q == state.q).map(|(_, g)| g);
        let taken = self.take_step(state, &kinetic, first);
        self.memo = Some((taken.next.q, taken.gradient));
        Ok(taken)
    }

    /// The step from `state`: the one [`predict`](StepEquations::predict) took, or taken again.
    fn taken(&self, state: &State<N>) -> Result<Taken<N>, DiracError> {
        match &self.proposal {
            Some((from, taken)) if from == state => Ok(*taken),
            _ => Ok(self.take_step(state, &self.kinetic_at(state)?, None)),
        }
    }

    /// The run's kinetic terms, or those at `state` before a run.
    fn kinetic_at(&self, state: &State<N>) -> Result<Kinetic<N>, DiracError> {
        match self.kinetic {
            Some(kinetic) => Ok(kinetic),
            None => Kinetic::of(self.discrete.system(), &state.q, &state.velocity),
        }
    }
}

impl<S: DiracSystem<N>, const N: usize> StepEquations<N> for Verlet<S, N> {
    type System = S;
    type Manifold = Vectors;

    fn system(&self) -> &S {
        self.discrete.system()
    }

    const NAME: &'static str = "the explicit variational step";
    const VELOCITY: &'static str = "the Legendre transform (velocity from momentum)";
    const FORCED: bool = S::FORCES;

    fn h(&self) -> f64 {
        self.discrete.h()
    }

    fn method(&self) -> String {
        self.composition.name().to_string()
    }

    fn unknowns(&self) -> usize {
        0
    }

    fn multipliers(&self) -> usize {
        0
    }

    fn multiplier_names(&self) -> Vec<String> {
        Vec::new()
    }

    fn coordinate_name(&self, i: usize) -> String {
        self.discrete.system().coordinate_name(i)
    }

    /// A finite start at which `L` is finite and the kinetic terms are constant and invertible.
    fn check_start(&self, state: &State<N>, _tolerance: f64) -> Result<(), DiracError> {
        StepEquations::check_finite(self, &state.q, &state.p, &state.velocity)?;
        let value = self.discrete.system().lagrangian(&state.q, &state.velocity);
        if !value.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the Lagrangian at the initial state".into(),
                value,
            });
        }
        self.check_forces(state.t, &state.q, &state.velocity)?;
        Kinetic::of(self.discrete.system(), &state.q, &state.velocity).map(|_| ())
    }

    fn begin(&mut self, state: &State<N>) {
        self.kinetic = Kinetic::of(self.discrete.system(), &state.q, &state.velocity).ok();
        self.memo = None;
        self.proposal = None;
    }

    /// Takes the step (there is nothing to predict): [`advance`](Self::advance) returns it.
    fn predict(
        &mut self,
        state: &State<N>,
        _previous: Option<&DVector<f64>>,
        _x: &mut DVector<f64>,
    ) {
        // A state the run's check refused: advance reports it again.
        if let Ok(taken) = self.step_from(state) {
            self.proposal = Some((*state, taken));
        }
    }

    fn assemble(
        &mut self,
        _state: &State<N>,
        _x: &DVector<f64>,
        _residual: &mut DVector<f64>,
        _jacobian: Option<&mut DMatrix<f64>>,
    ) -> f64 {
        0.0
    }

    fn advance(
        &self,
        state: &State<N>,
        _x: &DVector<f64>,
        step: u64,
    ) -> Result<State<N>, DiracError> {
        self.finite(self.taken(state)?.next, step)
    }

    /// The step in closed form: the same step as [`predict`](Self::predict) then
    /// [`advance`](Self::advance), with its work.
    fn explicit_step(
        &mut self,
        state: &State<N>,
        step: u64,
    ) -> Option<Result<(State<N>, Option<StepWork<N>>), DiracError>> {
        let step = self
            .step_from(state)
            .and_then(|taken| Ok((self.finite(taken.next, step)?, Some(taken.step_work()))));
        Some(step)
    }

    fn violation(&self, _from: &State<N>, _to: &State<N>, _x: &DVector<f64>) -> f64 {
        0.0
    }

    fn first_multiplier(&self) -> usize {
        0
    }

    fn unknown_name(&self, column: usize) -> String {
        format!("unknown {column} (an explicit step has none)")
    }

    /// `v = M⁻¹ (p − b)` with `M` and `b` at `(q, guess)`: one Newton step of the Legendre
    /// inversion, exact for a Lagrangian quadratic in the velocity.
    fn velocity(
        &self,
        _newton: &mut Newton,
        _t: f64,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        guess: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, NewtonFailure> {
        let h = derivatives::hessian(self.discrete.system(), q, guess);
        let v =
            h.vv.try_inverse()
                .map(|inverse| guess + inverse * (p - h.gradient.v))
                .ok_or(NewtonFailure::NonFinite)?;
        match v.iter().all(|x| x.is_finite()) {
            true => Ok(v),
            false => Err(NewtonFailure::NonFinite),
        }
    }

    /// `v = M⁻¹ (p − b)` with the run's `M` and `b`.
    fn velocity_in_run(
        &self,
        newton: &mut Newton,
        t: f64,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        guess: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, NewtonFailure> {
        match &self.kinetic {
            Some(kinetic) => Ok(kinetic.inverse_mass * (p - kinetic.offset)),
            None => self.velocity(newton, t, q, p, guess),
        }
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

    /// The cubic Hermite interpolant of the positions through the step's ends with their
    /// velocities (positions of order 4, velocities and momenta of order 3, whatever the
    /// composition's order).
    fn dense(&self, ends: [&Sample<N>; 2], _x: &DVector<f64>, theta: f64) -> Option<Sample<N>> {
        let [a, b] = ends;
        let h = self.discrete.h();
        let (t2, t3) = (theta * theta, theta * theta * theta);
        let q = a.q * (2.0 * t3 - 3.0 * t2 + 1.0)
            + a.v * (h * (t3 - 2.0 * t2 + theta))
            + b.q * (-2.0 * t3 + 3.0 * t2)
            + b.v * (h * (t3 - t2));
        let v = (a.q - b.q) * ((6.0 * t2 - 6.0 * theta) / h)
            + a.v * (3.0 * t2 - 4.0 * theta + 1.0)
            + b.v * (3.0 * t2 - 2.0 * theta);
        let kinetic = self.kinetic?;
        Some(Sample {
            t: a.t + theta * h,
            q,
            v,
            p: kinetic.mass * v + kinetic.offset,
        })
    }

    /// The forces' work, stage by stage `½ (F(q_a) + F(q_b)) · (q_b − q_a)`; no constraints.
    fn work(&self, state: &State<N>, _x: &DVector<f64>) -> Option<StepWork<N>> {
        Some(self.taken(state).ok()?.step_work())
    }

    fn inputs(&self) -> &[f64] {
        &self.inputs
    }

    /// The inputs, to be set: the step taken with the old ones is forgotten.
    fn inputs_mut(&mut self) -> &mut [f64] {
        self.proposal = None;
        &mut self.inputs
    }

    fn input_name(&self, i: usize) -> String {
        self.discrete.system().input_name(i)
    }

    fn energy(&self, q: &SVector<f64, N>, _p: &SVector<f64, N>, v: &SVector<f64, N>) -> f64 {
        legendre::energy(self.discrete.system(), q, v)
    }
}
