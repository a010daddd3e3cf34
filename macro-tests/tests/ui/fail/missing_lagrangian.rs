use dirac::prelude::*;

#[dirac_system(coordinates(x, y))]
struct Particle;

fn main() {}
