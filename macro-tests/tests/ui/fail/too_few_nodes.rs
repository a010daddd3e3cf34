use dirac::prelude::*;

#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2),
    quadrature = galerkin(3, gauss_legendre(2)),
)]
struct Particle;

fn main() {}
