use dirac::prelude::*;

#[dirac_system(coordinates(x, y), lagrangian = 0.5 * dot(x + y).powi(2))]
struct Particle;

fn main() {}
