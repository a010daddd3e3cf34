//! The bottom layer: the attribute's syntax as parsed (`ast`) and the error collector every
//! stage pushes into (`errors`). Uses nothing else of the crate.

pub mod ast;
pub mod errors;
