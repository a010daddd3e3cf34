//! The ground floor: the error type, the scalar trait the model's functions are written over,
//! the settings a user names (where constraints hold, how first-order and holonomic models are
//! stepped, input handles), float helpers for error measures that a NaN cannot pass, and the
//! split of work on the runs of a vector across threads.
//!
//! Uses nothing else of the crate. A new setting or error variant goes here.

pub(crate) mod constraint_point;
pub mod error;
pub(crate) mod first_order_scheme;
pub(crate) mod float;
pub(crate) mod holonomic_scheme;
pub(crate) mod input;
pub(crate) mod runs;
pub mod scalar;
