use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).squared())]
struct Particle;

fn main() {}
