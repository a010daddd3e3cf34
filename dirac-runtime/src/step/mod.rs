//! One step: the [`StepEquations`](crate::StepEquations) seam and its implementations — the
//! discrete Euler–Lagrange equations on vector spaces and on Lie groups, the discrete Hamiltonian
//! route, the modular step of an interconnection, the explicit Störmer–Verlet step of a separable
//! Lagrangian and its compositions, the fixed-point iteration of its Galerkin steps, the explicit multisymplectic step of a field — with the interpolant inside a step (dense
//! output), the step map's derivatives and the work of the steps booked by component (ledger).
//!
//! Uses every layer below it, up to [`discrete`](crate::discrete). A new scheme goes here.

pub mod affine_step;
pub mod composition;
pub mod dense_output;
pub mod euler_lagrange;
pub mod field;
pub mod fixed_point;
pub mod group_euler_lagrange;
pub(crate) mod group_linearisation;
pub mod hamilton;
pub mod ledger;
pub mod modular;
pub mod step_derivatives;
pub mod step_equations;
pub mod verlet;
