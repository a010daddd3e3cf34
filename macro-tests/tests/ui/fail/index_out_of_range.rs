use dirac::prelude::*;

#[dirac_system(
    coordinates(theta[3]),
    lagrangian = 0.5 * dot(theta[0]).powi(2) - theta[5],
    constraints(dtheta[0] - dtheta[3]),
)]
struct Chain;

fn main() {}
