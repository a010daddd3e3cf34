use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2))]
enum Particle {
    Free,
}

fn main() {}
