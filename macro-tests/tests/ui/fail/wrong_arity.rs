use dirac::prelude::*;

#[dirac_system(coordinates(x, y), lagrangian = 0.5 * dot(x).powi(2) + sin(x, y) + powi(y))]
struct Particle;

fn main() {}
