use dirac::prelude::*;

/// An index expression past a named length, in a coordinate of the Lagrangian.
const N: usize = 3;

#[dirac_system(
    coordinates(theta[N]),
    lagrangian = 0.5 * dot(theta[0]).powi(2) - theta[N + 1],
)]
struct Chain;

fn main() {}
