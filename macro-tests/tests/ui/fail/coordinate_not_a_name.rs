use dirac::prelude::*;

#[dirac_system(coordinates(x, fn), lagrangian = 0.5 * dot(x).powi(2))]
struct Particle;

fn main() {}
