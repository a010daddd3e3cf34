use dirac::prelude::*;

/// An `f64` constant as the exponent of `powi`: rustc's type error points at it.
const EXPONENT: f64 = 2.0;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(EXPONENT) - 0.5 * k * x.powi(2))]
struct Spring {
    k: f64,
}

fn main() {}
