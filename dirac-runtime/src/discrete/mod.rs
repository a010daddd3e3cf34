//! The discrete model: the discrete Lagrangian a quadrature makes of the model and its slot
//! derivatives, discrete forces, the constraint rows and the layout of a step's unknowns,
//! Lagrangians linear in the velocities, hidden constraints, consistent initial states, and the
//! [`State`](crate::State) `(t, q, p)` a step starts from and ends in.
//!
//! Uses the layers below it: [`base`](crate::base), [`space`](crate::space),
//! [`solve`](crate::solve), [`quadrature`](crate::quadrature) and [`model`](crate::model).

pub mod constraint;
pub mod discrete_lagrangian;
pub(crate) mod first_order;
pub(crate) mod force;
pub(crate) mod group_slots;
pub(crate) mod hidden_constraint;
pub(crate) mod initial_state;
pub(crate) mod layout;
pub mod state;
