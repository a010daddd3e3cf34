//! Many steps in time: the [`Stepper`](crate::Stepper), runs over a time span with saved times,
//! events and observers, and the trajectories they record.
//!
//! Uses every layer below it, up to [`step`](crate::step).

pub mod event;
pub mod run;
pub mod stepper;
pub mod trajectory;

/// A configuration space's test that needs a stepper to drive it.
#[cfg(test)]
mod affine_chart;
