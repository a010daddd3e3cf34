//! Lowering: the expressions of a model rewritten into code generic over the scalar (`expression`,
//! with vectors and matrices in `vector_algebra` and the names they bind in `atom`), one-forms
//! split by differential (`one_form`), closed-form derivatives (`symbolic`) and the quadrature
//! (`quadrature`). Uses `internals`.

pub mod atom;
pub mod expression;
pub mod one_form;
pub mod quadrature;
pub mod symbolic;
pub mod vector_algebra;
