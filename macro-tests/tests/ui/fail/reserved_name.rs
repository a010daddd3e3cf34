use dirac::prelude::*;

#[dirac_system(coordinates(__q), lagrangian = 0.5 * __m * dot(__q).powi(2))]
struct Particle {
    __m: f64,
}

fn main() {}
