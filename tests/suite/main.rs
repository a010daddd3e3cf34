//! The integration tests, one module per subject, linked into one binary so that the models they
//! define and the scenes they use compile once. `cargo test --test suite MODULE` runs one subject,
//! e.g. `cargo test --test suite convergence`. The allocation count (`tests/allocation.rs`) keeps a
//! binary of its own: it installs a global allocator.

mod support;

mod body_frame;
mod closed_form;
mod configuration_space;
mod constrained;
mod control;
mod convergence;
mod discrete_dirac;
mod energy_balance;
mod ensemble;
mod errors;
mod explicit;
mod extremes;
mod field;
mod first_order;
mod fixed_point;
mod golden;
mod group_derivatives;
mod hamiltonian;
mod interconnection;
mod invariants;
mod joints;
mod layers;
mod lie_group;
mod linear;
mod modular;
mod peers;
mod plane_field;
mod rigid_components;
mod roundoff;
mod run;
mod step_derivatives;
mod step_equations;
mod time_transformation;
mod vector_algebra;
mod work_precision;
