use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x) ^ 2)]
struct Particle;

fn main() {}
