use dirac::prelude::*;

/// A named length and a named index past it, in a velocity of the Lagrangian.
const N: usize = 3;
const LAST: usize = N;

#[dirac_system(
    coordinates(theta[N]),
    lagrangian = 0.5 * dot(theta[LAST]).powi(2),
)]
struct Chain;

fn main() {}
