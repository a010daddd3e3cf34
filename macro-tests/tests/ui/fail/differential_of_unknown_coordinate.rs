use dirac::prelude::*;

#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)),
    constraints(dx - dz),
)]
struct Particle;

fn main() {}
