use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), quadrature = explicit(leapfrog))]
struct Particle;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), quadrature = explicit(3))]
struct OddOrder;

fn main() {}
