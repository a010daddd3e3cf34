use dirac::prelude::*;

/// A parameter is a number of the model, not an index.
#[dirac_system(
    coordinates(theta[3]),
    lagrangian = 0.5 * dot(theta[0]).powi(2) - theta[m],
)]
struct Chain {
    m: f64,
}

fn main() {}
