//! Studies over many runs: work–precision diagrams and their charts.
//!
//! The top layer: uses every layer below it.

#[cfg(feature = "plot")]
pub mod plot;
pub mod work_precision;
