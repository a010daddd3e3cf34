use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2))]
struct Particle(f64);

fn main() {}
