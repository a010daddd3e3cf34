use dirac::prelude::*;

/// A named length: rustc checks the constant index against it.
const N: usize = 3;

#[dirac_system(
    coordinates(theta[N], x),
    lagrangian = 0.5 * dot(theta[0]).powi(2) + 0.5 * dot(x).powi(2),
    constraints(dtheta[0] - dtheta[N]),
)]
struct Chain;

fn main() {}
