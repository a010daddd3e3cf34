use dirac::prelude::*;

#[dirac_system(coordinates(x, R: SO3), lagrangian = 0.5 * dot(omega(x), omega(R)))]
struct Body;

fn main() {}
