//! Configuration spaces: the manifold a model's coordinates live on — vectors, the positive
//! orthant, rotations `SO(3)`, unit vectors `S²` and products of them — with its retraction,
//! charts and the maps a step takes through them.
//!
//! Uses [`base`](crate::base). A new manifold goes here.

pub mod configuration_space;
pub mod manifold;
pub mod product;
pub mod rotation;
pub mod sphere;
