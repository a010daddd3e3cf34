//! Nothing to use: this package holds the `#[dirac_system]` attribute's compile-time tests
//! (`tests/ui.rs`: the compile-fail and pass cases and a 10 000-term model;
//! `tests/runtime_path.rs`: the attribute on `dirac-runtime` alone). They are not tests of
//! `dirac-macros` itself because cargo builds the dependencies of a proc-macro crate's tests for
//! the host, a second copy of the runtime and its dependencies in every clean build.
