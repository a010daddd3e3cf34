//! Runtime of `dirac`: the traits a model implements, quadratures, the discrete Lagrangian and its
//! derivatives by dual numbers, Newton's method, the stepper and trajectories.
//!
//! The path from a model to a step is visible in the modules: [`system`] (the continuous
//! Lagrangian, one-forms, forces) → [`quadrature`] → [`discrete_lagrangian`] (slot derivatives),
//! `force` (discrete Lagrange–d'Alembert forces) and [`constraint`] (multiplier rows) →
//! [`newton`] → [`stepper`] → [`trajectory`].
#![warn(missing_docs)]

pub mod constraint;
pub mod discrete_lagrangian;
pub mod error;
mod force;
mod initial_state;
pub mod legendre;
mod lu;
pub mod newton;
pub mod quadrature;
pub mod scalar;
pub mod stepper;
pub mod system;
pub mod trajectory;

pub use constraint::ConstraintPoint;
pub use discrete_lagrangian::DiscreteLagrangian;
pub use error::{DiracError, Interrupted};
pub use lu::SingularPivot;
pub use newton::{Newton, NewtonFailure, NewtonOptions, NewtonReport};
pub use quadrature::{Quadrature, Rule};
pub use scalar::Scalar;
pub use stepper::Stepper;
pub use system::DiracSystem;
pub use trajectory::Trajectory;

pub use nalgebra;
pub use num_dual;
pub use num_dual::DualNum;
