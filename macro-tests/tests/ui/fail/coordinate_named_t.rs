use dirac::prelude::*;

#[dirac_system(coordinates(t), lagrangian = 0.5 * dot(t).powi(2))]
struct Particle;

fn main() {}
