//! Errors are values: every failure of the runtime is a [`DiracError`], and a failed step leaves the
//! stepper's state as it was.

use thiserror::Error;

use crate::trajectory::Trajectory;

/// What went wrong, with enough context to act on it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DiracError {
    /// The step size is zero, negative or not finite.
    #[error("the step size must be positive and finite, got h = {h}")]
    InvalidStep {
        /// The rejected step size.
        h: f64,
    },
    /// A parameter, an initial value or a computed value is NaN or infinite.
    #[error("{what} is not finite ({value}); nothing was changed")]
    NonFinite {
        /// Which quantity, e.g. `parameter m` or `initial momentum of theta`.
        what: String,
        /// The offending value.
        value: f64,
    },
    /// The quadrature's description is inconsistent.
    #[error("invalid quadrature: {0}")]
    InvalidQuadrature(String),
    /// [`Stepper::step`](crate::Stepper::step) was called before the initial state was set.
    #[error(
        "the stepper has no initial state: call start_from_velocity or start_from_momentum first"
    )]
    NotStarted,
    /// Newton's method did not reach the tolerance within its iteration cap.
    #[error(
        "{problem} did not converge at step {step}: residual {residual:.3e} and last update \
         {update:.3e} after {iterations} iterations (relative tolerances {tolerance:.1e} on the \
         residual, {step_tolerance:.1e} on the update); try a smaller step or a larger \
         iteration cap"
    )]
    NoConvergence {
        /// What was being solved, e.g. `the discrete Euler–Lagrange equations`.
        problem: &'static str,
        /// Index of the step that failed (the number of steps taken before it).
        step: u64,
        /// Infinity norm of the last residual.
        residual: f64,
        /// Infinity norm of the last Newton update (infinite if none was taken).
        update: f64,
        /// The update tolerance that was not met.
        step_tolerance: f64,
        /// Newton iterations performed.
        iterations: usize,
        /// The residual tolerance that was not met.
        tolerance: f64,
    },
    /// Newton's method did not contract from the predictor (successive updates shrank too
    /// slowly or grew), so a root it would reach may not be the continuation of the trajectory:
    /// the step does not resolve the dynamics, or the Jacobian is nearly singular. The solve was
    /// abandoned and the state is unchanged.
    #[error(
        "{problem} at step {step}: Newton's updates did not contract (ratio {contraction:.3}, \
         at most {max_contraction} accepted), so the root it would reach may not continue the \
         trajectory; try a smaller step"
    )]
    UntrustedStep {
        /// What was being solved.
        problem: &'static str,
        /// Index of the step that failed.
        step: u64,
        /// The ratio of successive Newton updates that broke the bound.
        contraction: f64,
        /// The bound in force ([`NewtonOptions::max_contraction`](crate::NewtonOptions)).
        max_contraction: f64,
    },
    /// The Newton matrix is singular: the discrete equations do not determine the unknowns.
    #[error(
        "{problem} has a singular Jacobian at step {step}: the unknowns for {unknowns} are not \
         determined (is the Lagrangian degenerate in these velocities?)"
    )]
    SingularJacobian {
        /// What was being solved.
        problem: &'static str,
        /// Index of the step that failed.
        step: u64,
        /// The unknowns the elimination could not pivot on, by coordinate name.
        unknowns: String,
    },
    /// The initial state violates a constraint (possibly a hidden one).
    #[error("inconsistent initial state: {0}")]
    InconsistentInitialState(String),
    /// An input name that the system does not have, or the wrong number of input values.
    #[error("{0}")]
    UnknownInput(String),
    /// Solver options out of range.
    #[error("invalid Newton options: {0}")]
    InvalidOptions(String),
    /// A vector or a table index of the wrong size.
    #[error("{0}")]
    Dimension(String),
    /// Writing a trajectory failed.
    #[error("could not write the trajectory: {0}")]
    Io(String),
}

/// A run that stopped at a failing step: the trajectory up to the last good step, and why.
///
/// `?` converts it into its [`DiracError`] (dropping the trajectory); match on it to keep the
/// steps made.
///
/// ```
/// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
/// /// L = v²/2 − √(1 − q): the potential ends at q = 1.
/// struct Edge;
/// impl DiracSystem<1> for Edge {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 0.5 - (-q[0] + 1.0).sqrt()
///     }
/// }
/// let mut stepper = Stepper::new(Edge, Quadrature::midpoint(), 0.1)?;
/// stepper.start_from_velocity(vector![0.0], vector![1.0])?;
/// let interrupted = stepper.run(100).unwrap_err();
/// assert_eq!(interrupted.trajectory.len() as u64, stepper.steps() + 1);
/// assert!(stepper.q()[0] < 1.0);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Error)]
#[error("the run stopped after {} samples: {error}", trajectory.len())]
pub struct Interrupted<const N: usize> {
    /// Every sample recorded before the failing step.
    pub trajectory: Trajectory<N>,
    /// Why the step failed.
    #[source]
    pub error: DiracError,
}

impl<const N: usize> From<Box<Interrupted<N>>> for DiracError {
    fn from(interrupted: Box<Interrupted<N>>) -> Self {
        interrupted.error
    }
}
