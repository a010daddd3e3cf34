use dirac::prelude::*;

#[dirac_system(coordinates(R: SO3), lagrangian = dot(omega(R), R) + trace(R + omega(R)))]
struct Body;

fn main() {}
