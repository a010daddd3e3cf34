//! Runtime of `dirac`: the traits a model implements, quadratures, the discrete Lagrangian and its
//! derivatives by dual numbers, Newton's method, the stepper and trajectories.
//!
//! The path from a model to a step is visible in the modules: [`system`] (the continuous
//! Lagrangian, one-forms, forces) on a [`configuration_space`] (a retraction and its charts) →
//! [`quadrature`] → [`discrete_lagrangian`] (slot derivatives in the chart), `force` (discrete
//! Lagrange–d'Alembert forces) and [`constraint`] (multiplier rows) → [`euler_lagrange`] (the
//! step's residual, unknowns and update, behind the [`step_equations`] seam) → [`newton`] →
//! [`stepper`] (over a [`run`], with [`dense_output`] and [`event`]s) → [`trajectory`], with
//! [`step_derivatives`] (the step map's derivatives by the implicit function theorem). Every derivative of the model's functions is taken in one
//! private module, `derivatives`: from the Lagrangian's [`closed_form`] derivatives where the
//! model has them (`#[dirac_system]` derives them at compile time), else by dual numbers.
#![warn(missing_docs)]

mod banded;
mod bordered;
pub mod closed_form;
pub mod configuration_space;
pub mod constraint;
mod constraint_point;
pub mod dense_output;
mod derivatives;
pub mod discrete_lagrangian;
pub mod error;
pub mod euler_lagrange;
pub mod event;
mod first_order;
mod first_order_scheme;
mod force;
pub mod group_euler_lagrange;
pub mod hamilton;
pub mod hamiltonian_system;
mod hidden_constraint;
mod holonomic_scheme;
mod initial_state;
mod input;
pub mod interconnection;
pub mod jacobian;
mod layout;
pub mod legendre;
mod lu;
pub mod manifold;
pub mod modular;
pub mod newton;
#[cfg(feature = "plot")]
pub mod plot;
mod predictor;
pub mod product;
pub mod quadrature;
pub mod repeated;
pub mod rotation;
pub mod run;
pub mod scalar;
pub mod slot;
pub mod sphere;
pub mod step_derivatives;
pub mod step_equations;
pub mod stepper;
pub mod system;
pub mod trajectory;
pub mod work_precision;

pub use closed_form::{HessianZeros, LagrangianGradient, LagrangianHessian};
pub use configuration_space::{ConfigurationSpace, Euclidean, Positive};
pub use constraint::ConstraintPoint;
pub use dense_output::Sample;
pub use discrete_lagrangian::DiscreteLagrangian;
pub use error::DiracError;
pub use event::{Crossing, Direction, Event};
pub use first_order_scheme::FirstOrderScheme;
pub use hamilton::Hamilton;
pub use hamiltonian_system::HamiltonianSystem;
pub use holonomic_scheme::HolonomicScheme;
pub use input::Input;
pub use interconnection::{Interconnected, Interconnection, Junction, Junctions, Ports};
pub use lu::SingularPivot;
pub use manifold::{Manifold, Vectors};
pub use modular::{Modular, PortWork};
pub use newton::{Newton, NewtonFailure, NewtonOptions, NewtonReport};
pub use product::{Configuration, Product, Rates};
pub use quadrature::{Quadrature, Rule};
pub use repeated::Repeated;
pub use rotation::Retraction;
pub use run::{Progress, Run, Solution, Status};
pub use scalar::Scalar;
pub use step_derivatives::{StepDerivatives, StepHessians};
pub use step_equations::{State, StepEquations};
pub use stepper::{ManifoldStepper, Stepper};
pub use system::DiracSystem;
pub use trajectory::{Interrupted, Metadata, Trajectory};
pub use work_precision::{Measurement, Study, WorkPrecision};

pub use nalgebra;
pub use num_dual;
pub use num_dual::DualNum;
