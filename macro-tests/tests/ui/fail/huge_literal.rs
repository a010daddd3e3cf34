use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2) - 1e400 * x)]
struct Particle;

fn main() {}
