use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), quadrature = simpson)]
struct Particle;

fn main() {}
