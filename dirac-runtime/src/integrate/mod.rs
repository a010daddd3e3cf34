//! Many steps in time: the [`Stepper`](crate::Stepper), runs over a time span with saved times,
//! events and observers, the trajectories they record, a field's snapshots in a compact binary
//! file, and the time-transformed runs of a
//! separable model ([`TimeTransformed`](crate::TimeTransformed): adaptive steps from a fixed
//! step of a fictive time).
//!
//! Uses every layer below it, up to [`step`](crate::step).

pub mod event;
pub mod run;
pub mod snapshots;
pub mod stepper;
pub mod time_transformation;
pub mod trajectory;

/// A configuration space's test that needs a stepper to drive it.
#[cfg(test)]
mod affine_chart;
