//! Errors are values: every failure of the runtime is a [`DiracError`], and a failed step leaves the
//! stepper's state as it was.

use thiserror::Error;

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
        "{problem} at step {step}: singular Jacobian, the unknowns for {unknowns} are not \
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
    /// A capability that does not cover this model yet (the message says which and why).
    #[error("not supported: {0}")]
    Unsupported(String),
    /// A step left the region where the configuration space's chart is defined or invertible.
    #[error("{0}; nothing was changed (try a smaller step)")]
    OutsideChart(String),
    /// A step's end could not be put back on a constraint the method holds there (hidden
    /// constraints of coordinates without kinetic energy, the velocity form of holonomic
    /// constraints).
    #[error("step {step}: {why}; nothing was changed (try a smaller step)")]
    Projection {
        /// Index of the step that failed.
        step: u64,
        /// What could not be held.
        why: String,
    },
    /// A step left the region where its method is defined (for a time-transformed step, where
    /// `c − V(q) > 0` and time runs forward); the message says where.
    #[error("step {step}: {why}; nothing was changed (try a smaller step)")]
    OutsideDomain {
        /// Index of the step that failed.
        step: u64,
        /// Where the step went and why the method is not defined there.
        why: String,
    },
    /// A run's time span, save times or events do not fit the stepper (the message says how).
    #[error("invalid run: {0}")]
    InvalidRun(String),
    /// A model's closed-form derivatives of its Lagrangian disagree with its Lagrangian (the
    /// message names the derivative and the point).
    #[error("{0}")]
    InconsistentDerivatives(String),
    /// An [`Interconnection`](crate::model::interconnection::Interconnection) that cannot be built
    /// (the message names the junctions or instances involved and why).
    #[error("invalid interconnection: {0}")]
    InvalidInterconnection(String),
    /// Writing a trajectory or snapshots failed, or a snapshot file could not be read.
    #[error("input or output failed: {0}")]
    Io(String),
}
