use dirac::prelude::*;

#[dirac_system(coordinates(R: SO3), lagrangian = 0.5 * omega(R))]
struct Body;

fn main() {}
