//! The `#[dirac_system]` attribute's tests. Nothing to use: this package is not published.
//!
//! - `tests/ui.rs`: every malformed input is a compile error on the user's tokens: rustc checks
//!   each case of `tests/ui/fail` (one diagnostic per file) against the workspace's own build of
//!   `dirac` and compares its diagnostics with the `.stderr` beside it.
//! - `tests/expansions/main.rs`: valid inputs compile and run, one module per case, among them a
//!   model with a 10 000-term Lagrangian (written by the build script) and the attribute on
//!   `dirac-runtime` alone.
//!
//! They are not tests of `dirac-macros` itself because cargo builds the dependencies of a
//! proc-macro crate's tests for the host, a second copy of the runtime and its dependencies in
//! every clean build. The valid cases are modules of one test binary rather than programs checked
//! one by one: they must also run.
