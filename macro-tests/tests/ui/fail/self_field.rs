use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * self.m * dot(x).powi(2))]
struct Particle {
    m: f64,
}

fn main() {}
