//! Solving a step's equations: Newton's method, the Jacobian's shapes (dense, banded, bordered)
//! with their LU factorisations, the acceleration of fixed-point iterations, and the predictor
//! of the next step's unknowns.
//!
//! Uses [`base`](crate::base). A new solver or Jacobian shape goes here.

pub(crate) mod anderson;
pub(crate) mod banded;
pub(crate) mod bordered;
pub mod jacobian;
pub(crate) mod lu;
pub mod newton;
pub(crate) mod predictor;
