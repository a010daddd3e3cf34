//! Newton's method with an exact Jacobian and an LU solve, on a preallocated workspace.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::base::error::DiracError;
use crate::solve::jacobian::{Dense, Jacobian};
use crate::solve::lu::SingularPivot;

/// Tolerances, iteration cap and root-acceptance rule of Newton's method.
///
/// A solve has converged when the residual's infinity norm is at most
/// `residual_tolerance · scale`, where `scale` is the size of the terms summed into the residual
/// (so the tolerance sits a fixed distance above its round-off floor), and the correction at the
/// point (the update the factorised Jacobian gives there) is at round-off, `64 ε (1 + |x|∞)`,
/// or has stopped shrinking below `step_tolerance · (1 + |x|∞)`. The tolerance never asks for
/// less than the round-off floor `64 ε ‖J‖∞ ‖x‖∞`. The returned point is always one whose residual was checked.
///
/// **Root acceptance.** A root is accepted only if the iteration reached it while contracting:
/// as long as the residual is above tolerance, every full update above the step tolerance is at
/// most `max_contraction` (default ¼) times the one before. This is a monotonicity test in the
/// spirit of Deuflhard's: from a good predictor Newton converges quadratically at once, so the
/// ratio `θ` of successive updates is small (measured below 1.3e-3 on the double pendulum at
/// h = 0.01, below 0.2 at h = 0.1). A larger `θ` says quadratic convergence had not set in: the
/// predictor is not where Kantorovich's theorem vouches for a unique root nearby (its
/// `h_K = βLη` is at least about `2θ`, and it needs `h_K ≤ ½`), so a root reached from there may
/// not be the continuation of the trajectory (a near-singular Jacobian, a step too large for the
/// dynamics). Such a step is refused with [`NewtonFailure::NotContracting`]. The bound is a
/// policy, not a proof: it can refuse a step whose root was the right one, and it measures the
/// ∞-norm over all unknowns (multipliers included). Linear equations pass at any step: their
/// second update is round-off. `f64::INFINITY` turns the check off.
///
/// `line_search` halves each update until the residual is finite and decreases (Armijo
/// backtracking): a globalised solve for well-posed but strongly nonlinear equations, used by
/// the Legendre inversion. Only full updates enter the contraction ratio.
///
/// ```
/// let options = dirac_runtime::NewtonOptions { max_iterations: 50, ..Default::default() };
/// assert_eq!(options.residual_tolerance, 1e-12);
/// assert!(options.validate().is_ok());
/// let nan = dirac_runtime::NewtonOptions { residual_tolerance: f64::NAN, ..Default::default() };
/// assert!(nan.validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct NewtonOptions {
    /// Relative tolerance on the residual, in `[0, 1)`.
    pub residual_tolerance: f64,
    /// Relative tolerance on the last update, in `[0, 1)`.
    pub step_tolerance: f64,
    /// Most iterations (evaluations of the residual, with or without its Jacobian) before giving
    /// up, at least 1. A point is accepted where its correction is at round-off, so a nonlinear
    /// solve takes three or more (Newton's method: two with the Jacobian, the last without).
    pub max_iterations: usize,
    /// A pivot below this fraction of the largest entry of its row of the Jacobian counts as
    /// zero, in `[0, 1)`.
    pub singular_tolerance: f64,
    /// Largest accepted ratio of successive updates: positive; `f64::INFINITY` turns the
    /// root-acceptance check off.
    pub max_contraction: f64,
    /// Backtrack each update until the residual decreases (globalised Newton; every
    /// evaluation then brings its Jacobian).
    pub line_search: bool,
    /// Largest contraction ratio at which a Jacobian evaluated at an earlier iterate, or in an
    /// earlier solve, is kept (simplified Newton), in `[0, 1]` (above `max_contraction` it acts
    /// as `max_contraction`); `Some(0.0)` evaluates it at every iteration (Newton's method).
    /// `None` (the default) decides from what a Jacobian costs against a residual alone, and
    /// keeps one for step equations that are linear with constant coefficients (see
    /// [`Newton::solve`]).
    pub jacobian_reuse: Option<f64>,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-12,
            step_tolerance: 1e-9,
            max_iterations: 25,
            singular_tolerance: 1e-13,
            max_contraction: 0.25,
            line_search: false,
            jacobian_reuse: None,
        }
    }
}

impl NewtonOptions {
    /// Checks every field's range; the error names the field and its value.
    pub fn validate(&self) -> Result<(), DiracError> {
        let unit = |name: &str, value: f64| {
            if (0.0..1.0).contains(&value) {
                Ok(())
            } else {
                Err(DiracError::InvalidOptions(format!(
                    "{name} must be in [0, 1), got {value}"
                )))
            }
        };
        unit("residual_tolerance", self.residual_tolerance)?;
        unit("step_tolerance", self.step_tolerance)?;
        unit("singular_tolerance", self.singular_tolerance)?;
        if self.max_contraction.is_nan() || self.max_contraction <= 0.0 {
            return Err(DiracError::InvalidOptions(format!(
                "max_contraction must be positive (infinity turns the check off), got {}",
                self.max_contraction
            )));
        }
        if let Some(reuse) = self.jacobian_reuse
            && !(0.0..=1.0).contains(&reuse)
        {
            return Err(DiracError::InvalidOptions(format!(
                "jacobian_reuse must be in [0, 1], got {reuse}"
            )));
        }
        if self.max_iterations == 0 {
            return Err(DiracError::InvalidOptions(
                "max_iterations must be at least 1".into(),
            ));
        }
        Ok(())
    }
}

/// How a successful solve went.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NewtonReport {
    /// Residual evaluations performed.
    pub iterations: usize,
    /// Jacobians evaluated (and factorised) among them: 0 when an earlier solve's served.
    pub jacobians: usize,
    /// Infinity norm of the residual at the returned point.
    pub residual: f64,
    /// Largest ratio of successive updates above the step tolerance (0 when there was only one):
    /// how far from quadratic the convergence was.
    pub contraction: f64,
}

/// Why a solve failed.
#[derive(Debug, Clone, PartialEq)]
pub enum NewtonFailure {
    /// The tolerance was not met within the cap.
    NoConvergence {
        /// Residual norm at the last iterate.
        residual: f64,
        /// Size of the last update (infinite if none was taken).
        update: f64,
        /// Iterations performed.
        iterations: usize,
    },
    /// The iteration did not contract: an update exceeded `max_contraction` times the previous
    /// one, so a root it reached might not be the one nearest the initial guess.
    NotContracting {
        /// The ratio of successive updates that broke the bound.
        contraction: f64,
        /// Iterations performed.
        iterations: usize,
    },
    /// The Jacobian could not be factorised.
    Singular(SingularPivot),
    /// The residual or the Jacobian contained NaN or infinity.
    NonFinite,
    /// The unknowns' vector does not have the solver's size.
    Dimension {
        /// The solver's number of unknowns.
        expected: usize,
        /// The length of the vector passed.
        got: usize,
    },
}

impl NewtonFailure {
    /// The error of a solve of `problem` (what is solved, for the message) that failed at step
    /// `step` with `options`; a singular Jacobian names its unknowns by `name`.
    pub(crate) fn into_error(
        self,
        problem: &'static str,
        step: u64,
        options: &NewtonOptions,
        name: &dyn Fn(usize) -> String,
    ) -> DiracError {
        match self {
            NewtonFailure::NoConvergence {
                residual,
                update,
                iterations,
            } => DiracError::NoConvergence {
                problem,
                step,
                residual,
                update,
                iterations,
                tolerance: options.residual_tolerance,
                step_tolerance: options.step_tolerance,
            },
            NewtonFailure::Singular(pivot) => DiracError::SingularJacobian {
                problem,
                step,
                unknowns: pivot
                    .involved
                    .iter()
                    .map(|&column| name(column))
                    .collect::<Vec<_>>()
                    .join(", "),
            },
            NewtonFailure::NotContracting { contraction, .. } => DiracError::UntrustedStep {
                problem,
                step,
                contraction,
                max_contraction: options.max_contraction,
            },
            NewtonFailure::NonFinite => DiracError::NonFinite {
                what: format!(
                    "the residual of {problem} at step {step} (the iterate left the Lagrangian's \
                     domain; try a smaller step)"
                ),
                value: f64::NAN,
            },
            NewtonFailure::Dimension { expected, got } => DiracError::Dimension(format!(
                "{problem}: {got} unknowns where the solver has {expected}"
            )),
        }
    }
}

/// Newton's method for `F(x) = 0` on `R^n`, reusing its buffers across solves.
///
/// The caller's closure fills the residual at `x`, adds the Jacobian into the zeroed matrix
/// when one is asked for (`Some`), and returns the residual's scale: the size of the terms it
/// sums, against which the tolerance is relative. Nothing is allocated per iteration.
///
/// ```
/// use dirac_runtime::{Newton, NewtonOptions};
/// use nalgebra::DVector;
/// // x² = 2
/// let mut newton = Newton::new(1, NewtonOptions::default())?;
/// let mut x = DVector::from_element(1, 1.0);
/// newton.solve(&mut x, |x, r, j| {
///     r[0] = x[0] * x[0] - 2.0;
///     if let Some(j) = j {
///         j[(0, 0)] = 2.0 * x[0]; // asked for only when a Jacobian is due
///     }
///     2.0 // the size of the terms of the residual
/// }).unwrap();
/// assert!((x[0] - 2f64.sqrt()).abs() < 1e-15);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
///
/// The Jacobian is [`Dense`] unless named: a solve by blocks (a [`Jacobian`] of another shape,
/// e.g. [`Bordered`](crate::solve::jacobian::Bordered)) takes the same iteration, tolerances and
/// root-acceptance rule.
#[derive(Debug, Clone)]
pub struct Newton<J: Jacobian = Dense> {
    options: NewtonOptions,
    residual: DVector<f64>,
    /// The Jacobian, factorised in place.
    jacobian: J,
    /// The Newton update `J⁻¹ F`, kept apart from the residual for the line search.
    update: DVector<f64>,
    /// The trial point of the line search.
    trial: DVector<f64>,
    /// The root of the last successful solve, where `jacobian` holds the factorisation.
    root: DVector<f64>,
    /// `jacobian` holds the factorisation at `root`.
    at_root: bool,
    /// `jacobian` holds a factorisation (of an earlier iterate's Jacobian) that may be reused.
    factorised: bool,
    /// `‖J‖∞` of the last Jacobian evaluated: the residual's round-off floor scales with it.
    jacobian_norm: f64,
    /// What an evaluation with the Jacobian costs, in evaluations of the residual alone.
    jacobian_cost: f64,
    /// The equations are linear with constant coefficients (see
    /// [`set_constant_jacobian`](Newton::set_constant_jacobian)).
    constant_jacobian: bool,
    /// The factorisation a solve began with, kept aside while it evaluates its own: a failed
    /// solve puts it back, so that a failure changes nothing a later solve would see.
    kept: Kept<J>,
    /// `(‖J‖∞, factorised)` of the factorisation parked in `kept` while `jacobian` holds the
    /// one at the last root (see [`Newton::factorise_at`]).
    parked: Option<(f64, bool)>,
    /// Newton's method evaluates the Jacobian at the point it accepts (for the implicit
    /// function theorem's solves that follow) instead of checking it with the residual alone.
    jacobian_at_root: bool,
    /// The contraction ratio is measured on the first this many unknowns (all where `None`).
    measured: Option<usize>,
    /// The iterate of [`solve_from`](Newton::solve_from) (reused: no allocation per solve).
    iterate: DVector<f64>,
}

/// The residual's closure as the iteration sees it: behind a reference, so that the iteration is
/// compiled once per Jacobian shape.
type Residual<'a, M> = dyn FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut M>) -> f64 + 'a;

/// A factorised Jacobian set aside (see [`Newton::solve`]).
#[derive(Debug, Clone)]
struct Kept<J> {
    jacobian: J,
    norm: f64,
    /// The solve in progress began with a reusable factorisation that is still in `jacobian`
    /// of the solver (not yet set aside).
    pending: bool,
    /// The solve in progress set one aside here.
    holding: bool,
}

/// The residual's norm at a point and the tolerance it is held to there.
#[derive(Debug, Clone, Copy)]
struct Evaluation {
    residual: f64,
    tolerance: f64,
}

impl Newton {
    /// A solver for `n` unknowns with a dense Jacobian; fails on options out of range.
    pub fn new(n: usize, options: NewtonOptions) -> Result<Self, DiracError> {
        Self::with_jacobian(Dense::new(n), options)
    }

    /// `max |u_ii| / min |u_ii|` over the pivots of the Jacobian factorised at the last
    /// successful solve's root: a lower bound of its condition number (infinite before any).
    pub(crate) fn pivot_ratio(&self) -> f64 {
        if !self.at_root {
            return f64::INFINITY;
        }
        self.jacobian.pivot_ratio()
    }
}

impl<J: Jacobian> Newton<J> {
    /// A solver whose Jacobian has the shape of `jacobian` (its size is the number of
    /// unknowns); fails on options out of range.
    pub fn with_jacobian(jacobian: J, options: NewtonOptions) -> Result<Self, DiracError> {
        options.validate()?;
        let n = jacobian.size();
        Ok(Self {
            options,
            residual: DVector::zeros(n),
            kept: Kept {
                jacobian: jacobian.clone(),
                norm: 0.0,
                pending: false,
                holding: false,
            },
            jacobian,
            update: DVector::zeros(n),
            trial: DVector::zeros(n),
            root: DVector::zeros(n),
            at_root: false,
            factorised: false,
            jacobian_norm: 0.0,
            jacobian_cost: 1.0,
            constant_jacobian: false,
            parked: None,
            jacobian_at_root: false,
            measured: None,
            iterate: DVector::zeros(n),
        })
    }

    /// Judges convergence (the update at the step tolerance) and the contraction ratio of the
    /// root-acceptance test on the first `m` unknowns only (`None`: on all): the positions of a
    /// step whose other unknowns are multipliers that the next step does not read (SHAKE's
    /// impulses), on another scale and known only as well as their equations' conditioning
    /// allows (the residual is still held on every equation). A chain of `n` masses on rods, released straight and level,
    /// moves each mass by `g h²/2` in the first update and corrects the rods' second-order
    /// length error in the next, a shift of the whole chain that the top rod's impulse carries
    /// `n` times: the updates' ratio over all unknowns grows as `n` (25 at `n` = 1 000) while
    /// the positions' is 2e-4.
    pub(crate) fn measure_contraction_on(&mut self, m: Option<usize>) {
        self.measured = m.map(|m| m.min(self.residual.len()));
    }

    /// Solves `J y = b` in place with the Jacobian factorised at `root`, which must be the root
    /// of the last successful [`solve`](Self::solve) (the implicit function theorem's solves
    /// reuse it); `None` otherwise (no solve yet, a failed one since, or another point).
    pub(crate) fn solve_factorised(&self, root: &DVector<f64>, b: &mut DVector<f64>) -> Option<()> {
        (self.at_root && &self.root == root).then(|| self.jacobian.solve(b.as_mut_slice()))
    }

    /// The implicit function theorem's `∂x/∂z = −J⁻¹ ∂R/∂z`, in place of `∂R/∂z` (`n` rows, a
    /// column per parameter), with the Jacobian factorised at `root` (see
    /// [`solve_factorised`](Self::solve_factorised)); `None` where it is not held there.
    pub(crate) fn implicit_derivatives(
        &self,
        root: &DVector<f64>,
        b: &mut DMatrix<f64>,
    ) -> Option<()> {
        let n = self.jacobian.size();
        if !(self.at_root && &self.root == root) || b.nrows() != n {
            return None;
        }
        for column in b.as_mut_slice().chunks_exact_mut(n.max(1)) {
            column.iter_mut().for_each(|v| *v = -*v);
            self.jacobian.solve(column);
        }
        Some(())
    }

    /// The number of unknowns the solver is sized for.
    pub(crate) fn unknowns(&self) -> usize {
        self.residual.len()
    }

    /// The options in force.
    pub fn options(&self) -> &NewtonOptions {
        &self.options
    }

    /// The residual at `x` into its buffer, with the Jacobian when `with_jacobian` (then
    /// factorised in place): the residual's norm and the tolerance it is held to there. Fails
    /// when an entry of the residual or the Jacobian is not finite, when the Jacobian is singular,
    /// or when the closure resized a buffer (the buffers are then restored for the next solve).
    fn evaluate(
        &mut self,
        x: &DVector<f64>,
        evaluate: &mut Residual<'_, J::Matrix>,
        with_jacobian: bool,
    ) -> Result<Evaluation, NewtonFailure> {
        let n = x.len();
        let scale = if with_jacobian {
            if std::mem::take(&mut self.kept.pending) {
                // Set the factorisation the solve began with aside (buffers swap, no copy).
                std::mem::swap(&mut self.jacobian, &mut self.kept.jacobian);
                self.kept.norm = self.jacobian_norm;
                self.kept.holding = true;
            }
            // The buffer no longer holds a factorisation, whatever happens next.
            self.factorised = false;
            self.jacobian.clear();
            evaluate(x, &mut self.residual, Some(self.jacobian.matrix()))
        } else {
            evaluate(x, &mut self.residual, None)
        };
        if self.residual.len() != n || !self.jacobian.fits(n) {
            let got = self.residual.len();
            self.residual = DVector::zeros(n);
            self.jacobian.restore(n);
            self.factorised = false;
            self.kept.holding = false;
            return Err(NewtonFailure::Dimension { expected: n, got });
        }
        // `amax` skips a NaN that a later entry follows: test every entry.
        let grain = self.jacobian.vector_grain();
        if !all_finite(&self.residual, grain) {
            return Err(NewtonFailure::NonFinite);
        }
        if with_jacobian {
            self.jacobian_norm = self.jacobian.norm();
            // A norm that is not finite has an entry that is not, or overflowed.
            if !self.jacobian_norm.is_finite() && !self.jacobian.is_finite() {
                return Err(NewtonFailure::NonFinite);
            }
            self.jacobian
                .factorise(self.options.singular_tolerance)
                .map_err(NewtonFailure::Singular)?;
            self.factorised = true;
        }
        Ok(Evaluation {
            residual: amax(&self.residual, grain),
            tolerance: self.tolerance(scale, self.jacobian_norm, amax(x, grain)),
        })
    }

    /// The tolerance of a residual whose terms have size `scale`, at a point of size `x_max`:
    /// the relative tolerance, plus the round-off floor (what perturbing `x` by a few ulps does
    /// to the residual, measured with a Jacobian of norm `jacobian_norm`).
    fn tolerance(&self, scale: f64, jacobian_norm: f64, x_max: f64) -> f64 {
        let floor = 64.0 * f64::EPSILON * jacobian_norm * x_max;
        self.options.residual_tolerance * scale + floor
    }

    /// Whether a point of size `x_max` is accepted as a root where its residual has norm
    /// `residual` (terms of size `scale`) and the correction a Jacobian evaluated at another
    /// point (of norm `jacobian_norm`) gives there has norm `update`: the residual within
    /// tolerance and the correction at round-off. [`solve`](Self::solve) asks that much and,
    /// with a Jacobian from an earlier iterate, that the update that led to the point was at
    /// round-off too (its correction left out would bias every step alike); this test is for a
    /// single solve outside the solver (a chord step in fixed size), not a step's.
    pub(crate) fn accepts(
        &self,
        residual: f64,
        scale: f64,
        jacobian_norm: f64,
        x_max: f64,
        update: f64,
    ) -> bool {
        residual <= self.tolerance(scale, jacobian_norm, x_max) && update <= round_off(x_max)
    }

    /// Armijo backtracking along the update: halves the step from `x` until the residual is
    /// finite and its norm decreases sufficiently (or is within tolerance, where round-off admits
    /// no decrease). Leaves the accepted point in `trial`; `None` when the step became negligible.
    /// The trial points' Jacobians are evaluated: the accepted one is the next iteration's.
    fn backtrack(
        &mut self,
        x: &DVector<f64>,
        at_x: Evaluation,
        evaluate: &mut Residual<'_, J::Matrix>,
    ) -> Result<Option<(Evaluation, f64)>, NewtonFailure> {
        let mut length = 1.0;
        while length >= 1e-10 {
            let grain = self.jacobian.vector_grain();
            subtracted(&mut self.trial, x, length, &self.update, grain);
            let trial = std::mem::take(&mut self.trial);
            let at_trial = self.evaluate(&trial, evaluate, true);
            self.trial = trial;
            match at_trial {
                Ok(e)
                    if e.residual <= (1.0 - 1e-4 * length) * at_x.residual
                        || e.residual <= e.tolerance =>
                {
                    return Ok(Some((e, length)));
                }
                Ok(_) | Err(NewtonFailure::NonFinite) => length *= 0.5,
                Err(failure) => return Err(failure),
            }
        }
        Ok(None)
    }

    /// Tells the solver what an evaluation with the Jacobian costs, in evaluations of the
    /// residual alone (1 until told: Newton's method unless the options say otherwise).
    pub(crate) fn set_jacobian_cost(&mut self, cost: f64) {
        self.jacobian_cost = cost;
    }

    /// Tells the solver that the equations are linear with constant coefficients (the same
    /// Jacobian at every point and in every solve): by default it then keeps a factorised
    /// Jacobian however cheap one is, for as long as it contracts as the cost rule asks (a
    /// linear system's own Jacobian contracts to round-off), and accepts a point only after a
    /// refining update, as Newton's method does.
    pub(crate) fn set_constant_jacobian(&mut self, constant: bool) {
        self.constant_jacobian = constant;
    }

    /// The largest contraction ratio at which an earlier solve's Jacobian is kept: the option,
    /// or, by default, none (Newton's method) where a Jacobian costs `c < 2` residuals and the
    /// equations are not said linear, and
    /// `exp(−20 / (c + 2))` otherwise (up to `max_contraction`). A solve that starts with a
    /// Jacobian of its own takes about `c + 2` residuals; one that keeps an older Jacobian
    /// contracting by `θ` takes about `ln(e₀/tol) / ln(1/θ)`, with `ln(e₀/tol) ≈ 20` from a
    /// predictor `1e-5` off to a tolerance `1e-14`: the limit equates the two.
    fn reuse_limit(&self) -> f64 {
        let options = &self.options;
        if options.line_search {
            return 0.0;
        }
        let limit = match options.jacobian_reuse {
            Some(limit) => limit,
            None if self.jacobian_cost < 2.0 && !self.constant_jacobian => 0.0,
            None => (-20.0 / (self.jacobian_cost + 2.0)).exp(),
        };
        limit.min(options.max_contraction)
    }

    /// Whether Newton's method (where the Jacobian is not kept) also evaluates the Jacobian at
    /// the point it accepts, as [`factorise_at`](Self::factorise_at) would after the solve.
    pub(crate) fn set_jacobian_at_root(&mut self, on: bool) {
        self.jacobian_at_root = on;
    }

    /// [`solve`](Self::solve) from `start` in the solver's own iterate buffer (no allocation):
    /// the solution on success.
    pub(crate) fn solve_from<F>(
        &mut self,
        start: &[f64],
        mut evaluate: F,
    ) -> Result<&DVector<f64>, NewtonFailure>
    where
        F: FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut J::Matrix>) -> f64,
    {
        let mut x = std::mem::take(&mut self.iterate);
        if x.len() != start.len() {
            x = DVector::zeros(start.len());
        }
        x.copy_from_slice(start);
        let solved = self.solve_with(&mut x, &mut evaluate);
        self.iterate = x;
        solved.map(|_| &self.iterate)
    }

    /// Drops the factorised Jacobian: the next solve evaluates its own.
    pub(crate) fn forget_jacobian(&mut self) {
        self.unpark();
        self.factorised = false;
        self.at_root = false;
    }

    /// Evaluates the Jacobian at `x` and factorises it, so that the implicit function theorem's
    /// solves ([`StepEquations::linearise`](crate::StepEquations::linearise)) can use it at `x`,
    /// the root of the last successful solve (a solve that ended without a Jacobian at its root leaves none).
    /// The factorisation the solver keeps for its next solve is parked meanwhile and taken up
    /// again by it: differentiating a step does not change the steps that follow.
    ///
    /// ```
    /// use dirac_runtime::{Newton, NewtonOptions};
    /// use nalgebra::{DMatrix, DVector};
    /// let f = |x: &DVector<f64>, r: &mut DVector<f64>, j: Option<&mut DMatrix<f64>>| {
    ///     r[0] = x[0] * x[0] - 2.0;
    ///     if let Some(j) = j {
    ///         j[(0, 0)] = 2.0 * x[0];
    ///     }
    ///     2.0
    /// };
    /// let mut newton = Newton::new(1, NewtonOptions::default())?;
    /// let mut x = DVector::from_element(1, 1.0);
    /// newton.solve(&mut x, f).unwrap();
    /// newton.factorise_at(&x, f).unwrap(); // J(√2) = 2√2, ready for implicit derivatives
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn factorise_at<F>(
        &mut self,
        x: &DVector<f64>,
        mut evaluate: F,
    ) -> Result<(), NewtonFailure>
    where
        F: FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut J::Matrix>) -> f64,
    {
        self.factorise_at_with(x, &mut evaluate)
    }

    /// [`factorise_at`](Self::factorise_at) with the closure behind a reference: compiled once
    /// per Jacobian shape, not once per closure.
    fn factorise_at_with(
        &mut self,
        x: &DVector<f64>,
        evaluate: &mut Residual<'_, J::Matrix>,
    ) -> Result<(), NewtonFailure> {
        if x.len() != self.root.len() {
            return Err(NewtonFailure::Dimension {
                expected: self.root.len(),
                got: x.len(),
            });
        }
        if self.at_root && &self.root == x {
            return Ok(());
        }
        self.unpark();
        std::mem::swap(&mut self.jacobian, &mut self.kept.jacobian);
        self.parked = Some((self.jacobian_norm, self.factorised));
        if let Err(failure) = self.evaluate(x, evaluate, true) {
            self.unpark();
            return Err(failure);
        }
        self.root.copy_from(x);
        self.at_root = true;
        Ok(())
    }

    /// Takes the factorisation parked by [`factorise_at`](Self::factorise_at) up again.
    fn unpark(&mut self) {
        if let Some((norm, factorised)) = self.parked.take() {
            std::mem::swap(&mut self.jacobian, &mut self.kept.jacobian);
            self.jacobian_norm = norm;
            self.factorised = factorised;
            self.at_root = false;
        }
    }

    /// Solves `F(x) = 0` from the initial guess in `x`; `x` holds the solution on success and an
    /// unspecified iterate on failure.
    ///
    /// A point is accepted when its residual is within tolerance and the correction at it (the
    /// update the factorised Jacobian gives there, the estimate of its distance from the root)
    /// is at round-off or has stopped shrinking below the step tolerance; with a Jacobian older
    /// than the iterate before, the update that led to the point must have been at round-off
    /// too (a chord iteration's last correction, left out, would bias every step alike). Accepting needs no
    /// Jacobian at the point itself: after an update below the step tolerance the next point is
    /// evaluated without one. The returned point is the one whose residual was
    /// evaluated last, so whatever the closure computed alongside belongs to it.
    ///
    /// **Jacobians.** The closure is asked for the Jacobian (`Some`) only when one is due; with
    /// `None` it fills the residual alone. Where the reuse limit is 0
    /// ([`jacobian_reuse`](NewtonOptions::jacobian_reuse), or by default a Jacobian that costs
    /// less than two residuals, unless the equations are linear with constant coefficients)
    /// every evaluation brings its Jacobian: Newton's method. Otherwise
    /// the factorised Jacobian is kept across iterations and across solves (simplified Newton:
    /// the solves of successive steps are nearby problems). A solve evaluates its own at its
    /// start when the last solve found the kept one contracting by more than the limit (or there
    /// is none), and in the middle where an update leads out of the residual's domain or
    /// successive updates fail the contraction test. The measured ratio estimates the chord
    /// map's Lipschitz constant `‖I − J₀⁻¹ J(x)‖`; below 1, `J(x)` is invertible near the root,
    /// which is therefore isolated. The contraction test judges the Jacobian of the iterate
    /// before the update or of the iterate itself; an older one that fails it is refreshed
    /// instead.
    pub fn solve<F>(
        &mut self,
        x: &mut DVector<f64>,
        mut evaluate: F,
    ) -> Result<NewtonReport, NewtonFailure>
    where
        F: FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut J::Matrix>) -> f64,
    {
        self.solve_with(x, &mut evaluate)
    }

    /// [`solve`](Self::solve) with the closure behind a reference: the iteration is compiled
    /// once per Jacobian shape, not once per closure (a model's steppers call it from many).
    fn solve_with(
        &mut self,
        x: &mut DVector<f64>,
        evaluate: &mut Residual<'_, J::Matrix>,
    ) -> Result<NewtonReport, NewtonFailure> {
        if x.len() != self.residual.len() {
            return Err(NewtonFailure::Dimension {
                expected: self.residual.len(),
                got: x.len(),
            });
        }
        self.unpark();
        self.at_root = false;
        let options = self.options;
        let reuse_limit = self.reuse_limit();
        let newton = reuse_limit == 0.0;
        // How many updates had been taken when the factorised Jacobian was evaluated in this
        // solve (`None`: an earlier solve's).
        let mut jacobian_at: Option<usize> = None;
        let mut jacobians = 0;
        let reused = !newton && self.factorised;
        self.kept.pending = reused;
        self.kept.holding = false;
        let mut at_x = match self.evaluate(x, evaluate, !reused) {
            Ok(e) => e,
            Err(failure) => return Err(self.failed(failure)),
        };
        if !reused {
            jacobian_at = Some(0);
            jacobians += 1;
        }
        let mut evaluations = 1;
        let mut updates = 0;
        // The last full (undamped) update's size: convergence and the contraction ratio use it.
        let mut previous: Option<(f64, f64)> = None;
        let mut contraction: f64 = 0.0;
        // The largest ratio of successive updates with an earlier solve's Jacobian.
        let mut kept_ratio: f64 = 0.0;
        loop {
            // The correction at x, with the factorised Jacobian: x's distance from the root.
            let grain = self.jacobian.vector_grain();
            copy(&mut self.update, &self.residual, grain);
            self.jacobian.solve(self.update.as_mut_slice());
            if !all_finite(&self.update, grain) {
                return Err(self.failed(NewtonFailure::NonFinite));
            }
            let update = amax(&self.update, grain);
            let x_max = amax(x, grain);
            // The unknowns convergence and contraction are judged on (see
            // `measure_contraction_on`): the update's and the point's size there.
            let (measured, x_measured) = match self.measured {
                Some(m) => (self.update.rows(0, m).amax(), x.rows(0, m).amax()),
                None => (update, x_max),
            };
            // Below this an update is round-off: never asked for, never measured.
            let noise = options.step_tolerance.max(64.0 * f64::EPSILON) * (1.0 + x_measured);
            let within = at_x.residual <= at_x.tolerance;
            // The Jacobian of the iterate before the last update, or of this one.
            let current = jacobian_at.is_some_and(|at| at + 1 >= updates);
            // x is the root to round-off: a Newton step (with the Jacobian of the iterate it
            // started from) below the step tolerance led to it, which leaves x about the square
            // of that step off (and that last step refines x: the midpoint rule keeps a stiff
            // spring's energy to round-off over 10⁶ steps only with it); or, with an older
            // Jacobian (a linear rate), its own correction is at round-off and so was the update
            // that led to it. A chord iteration nears its root from one side, alike step after
            // step: a correction left out, though at round-off of the largest unknown, is
            // hundreds of ulps of a small one and biases every step the same way (the energy's
            // round-off then drifts like t^0.9 on Kepler's Gauss steps of order 8), so the point
            // a round-off correction gives is taken, a contraction factor nearer the root. A
            // kept Jacobian of linear equations is their Jacobian: as Newton's, its point is
            // accepted after a refining step (without it the stiff spring's energy drifts 20
            // times further).
            let round_off = round_off(x_measured);
            let refined = previous.is_some_and(|(_, before)| before <= noise);
            let settled = at_x.residual == 0.0
                || if current {
                    refined
                } else if self.constant_jacobian {
                    measured <= round_off && refined
                } else {
                    measured <= round_off && previous.is_some_and(|(_, before)| before <= round_off)
                };
            if within && settled {
                self.kept.pending = false;
                self.kept.holding = false;
                // An earlier solve's Jacobian that contracted slowly is not kept for the next:
                // it evaluates its own at its predictor.
                if jacobian_at.is_none() && kept_ratio > reuse_limit {
                    self.factorised = false;
                }
                if jacobian_at == Some(updates) {
                    self.root.copy_from(x);
                    self.at_root = true;
                }
                return Ok(NewtonReport {
                    iterations: evaluations,
                    jacobians,
                    residual: at_x.residual,
                    contraction,
                });
            }
            if evaluations >= options.max_iterations {
                break;
            }
            if let Some((full, before)) = previous {
                // The chord's rate on every unknown decides whether to keep an older Jacobian;
                // the measured unknowns' whether the iteration contracts toward its root.
                let chord = update / full;
                let ratio = measured / before;
                let slow = chord.max(ratio) > options.max_contraction;
                if !current && slow && update > self::round_off(x_max) {
                    // An older Jacobian does not contract: evaluate it here and start the
                    // measurement again.
                    at_x = self.refresh(x, evaluate)?;
                    (jacobian_at, previous) = (Some(updates), None);
                    (jacobians, evaluations) = (jacobians + 1, evaluations + 1);
                    continue;
                }
                // The contraction of full steps, while the iteration is still converging.
                if !within && measured > noise {
                    if ratio > options.max_contraction {
                        return Err(self.failed(NewtonFailure::NotContracting {
                            contraction: ratio,
                            iterations: evaluations,
                        }));
                    }
                    contraction = contraction.max(ratio);
                }
                if jacobian_at.is_none() && measured > round_off {
                    kept_ratio = kept_ratio.max(chord);
                }
            }
            let length = if options.line_search {
                let Some((at_trial, length)) = self
                    .backtrack(x, at_x, evaluate)
                    .map_err(|f| self.failed(f))?
                else {
                    return Err(self.failed(NewtonFailure::NoConvergence {
                        residual: at_x.residual,
                        update,
                        iterations: evaluations,
                    }));
                };
                at_x = at_trial;
                x.copy_from(&self.trial);
                evaluations += 1;
                jacobians += 1;
                jacobian_at = Some(updates + 1);
                length
            } else {
                subtract(x, 1.0, &self.update, grain);
                evaluations += 1;
                // After an update below the step tolerance the next point is the root to
                // round-off: its correction needs no Jacobian of its own.
                let with_jacobian = newton && (measured > noise || self.jacobian_at_root);
                match self.evaluate(x, evaluate, with_jacobian) {
                    Ok(e) => at_x = e,
                    Err(NewtonFailure::NonFinite)
                        if !with_jacobian && jacobian_at != Some(updates) =>
                    {
                        // An update of an older Jacobian left the residual's domain: back to
                        // the iterate it came from, with its own Jacobian.
                        subtract(x, -1.0, &self.update, grain);
                        at_x = self.refresh(x, evaluate)?;
                        (jacobian_at, previous) = (Some(updates), None);
                        (jacobians, evaluations) = (jacobians + 1, evaluations + 1);
                        continue;
                    }
                    Err(failure) => return Err(self.failed(failure)),
                }
                if with_jacobian {
                    jacobians += 1;
                    jacobian_at = Some(updates + 1);
                }
                1.0
            };
            updates += 1;
            previous = (length == 1.0).then_some((update, measured));
        }
        Err(self.failed(NewtonFailure::NoConvergence {
            residual: at_x.residual,
            update: previous.map_or(f64::INFINITY, |(update, _)| update),
            iterations: options.max_iterations,
        }))
    }

    /// The residual and a new Jacobian at `x` in the middle of a solve (a failure ends it).
    fn refresh(
        &mut self,
        x: &DVector<f64>,
        evaluate: &mut Residual<'_, J::Matrix>,
    ) -> Result<Evaluation, NewtonFailure> {
        self.evaluate(x, evaluate, true).map_err(|f| self.failed(f))
    }

    /// A failed solve leaves the factorisation it began with, as if it had not run.
    fn failed(&mut self, failure: NewtonFailure) -> NewtonFailure {
        if std::mem::take(&mut self.kept.holding) {
            std::mem::swap(&mut self.jacobian, &mut self.kept.jacobian);
            self.jacobian_norm = self.kept.norm;
            self.factorised = true;
        } else if !std::mem::take(&mut self.kept.pending) {
            // It began without one, or evaluated its own over it.
            self.factorised = false;
        }
        failure
    }
}

/// `max |x_i|` (nalgebra's `amax`, over the slice: the iterations here are on every solve's path).
fn amax(x: &DVector<f64>, grain: usize) -> f64 {
    let largest = |x: &[f64]| x.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
    match grain < x.len() {
        true => x
            .as_slice()
            .par_chunks(grain)
            .map(largest)
            .reduce(|| 0.0, f64::max),
        false => largest(x.as_slice()),
    }
}

/// Whether every entry of `x` is finite (`amax` skips a NaN that a later entry follows).
fn all_finite(x: &DVector<f64>, grain: usize) -> bool {
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    match grain < x.len() {
        true => x.as_slice().par_chunks(grain).all(finite),
        false => finite(x.as_slice()),
    }
}

/// `to = from`, entry by entry.
fn copy(to: &mut DVector<f64>, from: &DVector<f64>, grain: usize) {
    match grain < to.len() {
        true => {
            let pieces = to.as_mut_slice().par_chunks_mut(grain);
            pieces
                .zip(from.as_slice().par_chunks(grain))
                .for_each(|(to, from)| to.copy_from_slice(from));
        }
        false => to.copy_from_slice(from.as_slice()),
    }
}

/// `x − length · update`, entry by entry.
fn subtract(x: &mut DVector<f64>, length: f64, update: &DVector<f64>, grain: usize) {
    let step = |(x, u): (&mut [f64], &[f64])| {
        for (x, u) in x.iter_mut().zip(u) {
            *x -= length * u;
        }
    };
    match grain < x.len() {
        true => {
            let pieces = x.as_mut_slice().par_chunks_mut(grain);
            pieces
                .zip(update.as_slice().par_chunks(grain))
                .for_each(step);
        }
        false => step((x.as_mut_slice(), update.as_slice())),
    }
}

/// `to = x − length · update`, entry by entry.
fn subtracted(
    to: &mut DVector<f64>,
    x: &DVector<f64>,
    length: f64,
    update: &DVector<f64>,
    grain: usize,
) {
    copy(to, x, grain);
    subtract(to, length, update, grain);
}

/// Below this an update of a point of size `x_max` is round-off.
fn round_off(x_max: f64) -> f64 {
    4.0 * f64::EPSILON * (1.0 + x_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converges_quadratically_on_a_coupled_system() {
        // x + y = 3, x y = 2 from (0.5, 2.8): the root (1, 2).
        let mut newton = Newton::new(2, NewtonOptions::default()).unwrap();
        let mut x = DVector::from_vec(vec![0.5, 2.8]);
        let report = newton
            .solve(&mut x, |x, r, j| {
                r[0] = x[0] + x[1] - 3.0;
                r[1] = x[0] * x[1] - 2.0;
                if let Some(j) = j {
                    j.copy_from_slice(&[1.0, x[1], 1.0, x[0]]);
                }
                3.0
            })
            .unwrap();
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 2.0).abs() < 1e-15);
        assert!(report.iterations <= 7, "{report:?}");
    }

    #[test]
    fn reports_no_convergence_and_singularity() {
        let mut newton = Newton::new(
            1,
            NewtonOptions {
                max_iterations: 3,
                max_contraction: f64::INFINITY,
                ..Default::default()
            },
        )
        .unwrap();
        let mut x = DVector::from_element(1, 0.3);
        // x² + 1 = 0 has no real root.
        let err = newton.solve(&mut x, |x, r, j| {
            r[0] = x[0] * x[0] + 1.0;
            if let Some(j) = j {
                j[(0, 0)] = 2.0 * x[0];
            }
            1.0
        });
        assert!(matches!(
            err,
            Err(NewtonFailure::NoConvergence { iterations: 3, .. })
        ));
        let mut x = DVector::from_element(1, 0.0);
        let err = newton.solve(&mut x, |x, r, j| {
            r[0] = x[0] * x[0] + 1.0;
            if let Some(j) = j {
                j[(0, 0)] = 2.0 * x[0];
            }
            1.0
        });
        assert_eq!(
            err,
            Err(NewtonFailure::Singular(SingularPivot {
                column: 0,
                involved: vec![0]
            }))
        );
    }

    /// A residual with a NaN before a finite entry: `amax` alone would skip the NaN.
    #[test]
    fn a_nan_anywhere_in_the_residual_is_refused() {
        let mut newton = Newton::new(2, NewtonOptions::default()).unwrap();
        let mut x = DVector::from_vec(vec![1.0, 1.0]);
        let err = newton.solve(&mut x, |_, r, j| {
            r[0] = f64::NAN;
            r[1] = 1.0;
            if let Some(j) = j {
                j.fill_with_identity();
            }
            1.0
        });
        assert_eq!(err, Err(NewtonFailure::NonFinite));
    }

    /// atan(x) = 0 from x0 = 1.5: Newton's iterates grow (1.5 → −1.69 → 2.32 → …), the
    /// classic divergent case. The contraction test stops it at the second update, whose ratio
    /// is above 1; from x0 = 0.5 it converges with ratios far below ¼.
    #[test]
    fn a_non_contracting_iteration_is_refused() {
        let atan = |x: &DVector<f64>, r: &mut DVector<f64>, j: Option<&mut DMatrix<f64>>| {
            r[0] = x[0].atan();
            if let Some(j) = j {
                j[(0, 0)] = 1.0 / (1.0 + x[0] * x[0]);
            }
            1.0
        };
        let mut newton = Newton::new(1, NewtonOptions::default()).unwrap();
        let mut x = DVector::from_element(1, 1.5);
        match newton.solve(&mut x, atan) {
            Err(NewtonFailure::NotContracting {
                contraction,
                iterations: 2,
            }) => assert!(contraction > 1.0, "{contraction}"),
            other => panic!("expected NotContracting, got {other:?}"),
        }
        let mut x = DVector::from_element(1, 0.5);
        let report = newton.solve(&mut x, atan).unwrap();
        assert!(
            x[0].abs() < 1e-15 && report.contraction < 0.25,
            "{report:?}"
        );
        // With the check off, the same start diverges until the Jacobian 1/(1 + x²) underflows.
        let options = NewtonOptions {
            max_contraction: f64::INFINITY,
            ..Default::default()
        };
        let mut newton = Newton::new(1, options).unwrap();
        let mut x = DVector::from_element(1, 1.5);
        assert!(matches!(
            newton.solve(&mut x, atan),
            Err(NewtonFailure::Singular(_)
                | NewtonFailure::NonFinite
                | NewtonFailure::NoConvergence { .. })
        ));
        // The line search globalises it: atan's residual decreases along every Newton direction.
        let options = NewtonOptions {
            line_search: true,
            max_contraction: f64::INFINITY,
            ..Default::default()
        };
        let mut newton = Newton::new(1, options).unwrap();
        let mut x = DVector::from_element(1, 1.5);
        newton.solve(&mut x, atan).unwrap();
        assert!(x[0].abs() < 1e-15);
    }

    /// A linear system is solved at any scale: its second update is round-off and no ratio
    /// is measured on it.
    #[test]
    fn linear_equations_pass_the_contraction_test() {
        let mut newton = Newton::new(2, NewtonOptions::default()).unwrap();
        let mut x = DVector::from_vec(vec![1e6, -3e5]);
        let report = newton
            .solve(&mut x, |x, r, j| {
                r[0] = 1e8 * x[0] + x[1] - 1.0;
                r[1] = x[0] - 2.0 * x[1];
                if let Some(j) = j {
                    j.copy_from_slice(&[1e8, 1.0, 1.0, -2.0]);
                }
                1e8 * x[0].abs() + x[1].abs() + 1.0
            })
            .unwrap();
        assert_eq!(report.contraction, 0.0);
        assert!(report.iterations <= 3, "{report:?}");
    }

    #[test]
    fn a_closure_that_resizes_the_buffers_is_an_error() {
        let mut newton = Newton::new(2, NewtonOptions::default()).unwrap();
        let mut x = DVector::zeros(2);
        let err = newton.solve(&mut x, |_, r, _| {
            *r = DVector::zeros(3);
            1.0
        });
        assert_eq!(
            err,
            Err(NewtonFailure::Dimension {
                expected: 2,
                got: 3
            })
        );
        // The solver is whole again.
        newton
            .solve(&mut x, |x, r, j| {
                r.copy_from(x);
                if let Some(j) = j {
                    j.fill_with_identity();
                }
                1.0
            })
            .unwrap();
    }
}
