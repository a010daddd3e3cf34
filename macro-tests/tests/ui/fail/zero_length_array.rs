use dirac::prelude::*;

#[dirac_system(coordinates(x, theta[0]), lagrangian = 0.5 * dot(x).powi(2))]
struct Chain;

fn main() {}
