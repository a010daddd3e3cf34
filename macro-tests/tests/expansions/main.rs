//! `#[dirac_system]` on valid inputs: each module's models compile, and its test runs them and
//! checks what they compute. One test binary, built with the workspace's dependencies.

mod arrays_and_constants;
mod atoms_of_like_names;
mod dirac_features;
mod explicit_step;
mod generic_chain;
mod hamiltonian_models;
mod hamiltonian_with_holonomic;
mod hand_written_impl;
mod named_indices;
mod paths_and_methods;
mod rotations_and_directions;
mod runtime_path;
mod scalar_coordinates;
mod subsystems;

/// A model with a 10 000-term Lagrangian and force (the program the build script writes).
mod long_lagrangian {
    include!(concat!(env!("OUT_DIR"), "/terms_10000.rs"));

    #[test]
    fn compiles_and_evaluates_term_by_term() {
        main();
    }
}
