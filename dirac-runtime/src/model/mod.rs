//! The continuous model: the traits a model implements (a Lagrangian or a Hamiltonian,
//! one-forms, holonomic constraints, forces) and the Lagrangian densities of fields, its
//! derivatives (closed forms from `#[dirac_system]`, else dual numbers) and its Legendre
//! transform, and models built from components joined by junctions (interconnection) and
//! joints.
//!
//! Uses [`base`](crate::base), [`space`](crate::space), [`solve`](crate::solve) and
//! [`quadrature`](crate::quadrature). A new kind of model term goes here.

pub mod body_frame;
pub mod closed_form;
pub mod density;
pub(crate) mod derivatives;
pub mod hamiltonian_system;
pub mod interconnection;
pub mod joint;
pub mod legendre;
pub mod repeated;
pub mod slot;
pub mod system;
