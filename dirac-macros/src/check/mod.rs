//! Checking: the attribute and the struct validated into a [`Model`](model::Model) (or a model
//! of subsystems), every error collected with its span. Uses `internals` and `lower`; the
//! expansion of both is `expand`'s.

pub mod model;
pub mod subsystems;
pub mod validate;
