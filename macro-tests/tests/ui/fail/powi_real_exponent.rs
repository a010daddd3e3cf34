use dirac::prelude::*;

#[dirac_system(coordinates(x, y), lagrangian = 0.5 * dot(x).powi(2.5) + powi(dot(y), x))]
struct Particle;

fn main() {}
