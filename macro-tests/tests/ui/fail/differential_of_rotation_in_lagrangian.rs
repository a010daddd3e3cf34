use dirac::prelude::*;

#[dirac_system(coordinates(R: SO3), lagrangian = 0.5 * dot(omega(R), dR))]
struct Body;

fn main() {}
