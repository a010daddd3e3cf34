//! Runtime of `dirac`: the traits a model implements, quadratures, the discrete Lagrangian and its
//! derivatives, Newton's method, the stepper and trajectories.
//!
//! The folders are layers, each using only those below it (`tests/suite/layers.rs` checks it):
//!
//! | layer | folder | what it owns |
//! |---|---|---|
//! | 0 | [`base`] | errors, scalars, settings, float helpers |
//! | 1 | [`space`], [`solve`], [`quadrature`] | manifolds and charts; Newton, LU, Jacobian shapes, predictor; quadrature rules |
//! | 2 | [`model`] | the model's traits, derivatives, closed forms, Legendre transform, interconnection |
//! | 3 | [`discrete`] | discrete Lagrangian, forces, constraint rows, first-order and hidden-constraint handling, the state |
//! | 4 | [`step`] | step equations (Euler–Lagrange, Lie group, Hamiltonian, modular), dense output, step-map derivatives |
//! | 5 | [`integrate`] | stepper, runs, events, trajectories |
//! | 6 | [`study`] | work–precision studies and charts |
//!
//! The path from a model to a step reads down the table and back up: a [`DiracSystem`] on a
//! [`ConfigurationSpace`] → a [`Quadrature`] → the [`DiscreteLagrangian`], discrete forces and
//! constraint rows → the [`StepEquations`] → [`Newton`] → the [`Stepper`] over a [`Run`] →
//! a [`Trajectory`]. Every module keeps the public path it had before the folders (e.g.
//! `dirac_runtime::newton`), re-exported here.
#![warn(missing_docs)]

pub mod base;
pub mod discrete;
pub mod integrate;
pub mod model;
pub mod quadrature;
pub mod solve;
pub mod space;
pub mod step;
pub mod study;

pub use base::{error, scalar};
pub use discrete::{constraint, discrete_lagrangian};
pub use integrate::{event, run, snapshots, stepper, time_transformation, trajectory};
pub use model::{
    body_frame, closed_form, hamiltonian_system, interconnection, joint, legendre, repeated, slot,
    system,
};
pub use solve::{jacobian, newton};
pub use space::{configuration_space, manifold, product, rotation, sphere};
pub use step::{
    composition, dense_output, euler_lagrange, field, group_euler_lagrange, hamilton, modular,
    step_derivatives, step_equations, verlet,
};
#[cfg(feature = "plot")]
pub use study::plot;
pub use study::work_precision;

pub use base::constraint_point::ConstraintPoint;
pub use base::error::DiracError;
pub use base::first_order_scheme::FirstOrderScheme;
pub use base::holonomic_scheme::HolonomicScheme;
pub use base::input::Input;
pub use base::scalar::Scalar;
pub use discrete::discrete_lagrangian::DiscreteLagrangian;
pub use integrate::event::{Crossing, Direction, Event};
pub use integrate::run::{Feedback, Progress, Run, Solution, Status};
pub use integrate::stepper::{ManifoldStepper, Solver, Stepper};
pub use integrate::time_transformation::TimeTransformed;
pub use integrate::trajectory::{EnergyBalance, Interrupted, Metadata, Trajectory};
pub use model::closed_form::{HessianZeros, LagrangianGradient, LagrangianHessian};
pub use model::density::{PlaneDensity, SeparableDensity};
pub use model::hamiltonian_system::HamiltonianSystem;
pub use model::interconnection::{Interconnected, Interconnection, Junction, Junctions, Ports};
pub use model::joint::{Anchor, Joint};
pub use model::repeated::Repeated;
pub use model::system::DiracSystem;
pub use quadrature::{Quadrature, Rule};
pub use solve::lu::SingularPivot;
pub use solve::newton::{Newton, NewtonFailure, NewtonOptions, NewtonReport};
pub use space::configuration_space::{ConfigurationSpace, Euclidean, Positive};
pub use space::manifold::{Manifold, Vectors};
pub use space::product::{Configuration, Product, Rates};
pub use space::rotation::Retraction;
pub use step::composition::Composition;
pub use step::dense_output::Sample;
pub use step::field::plane::PlaneField;
pub use step::field::{Boundary, Field};
pub use step::hamilton::Hamilton;
pub use step::ledger::{ComponentBalance, Ledger};
pub use step::modular::{Modular, ModularFeedback, PortWork};
pub use step::step_derivatives::{StepDerivatives, StepHessians};
pub use step::step_equations::{State, StepEquations, StepWork};
pub use step::verlet::{ExplicitSystem, Verlet};
pub use study::work_precision::{Measurement, Study, WorkPrecision};

pub use nalgebra;
pub use num_dual;
pub use num_dual::DualNum;
