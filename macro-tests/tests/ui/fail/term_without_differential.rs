use dirac::prelude::*;

#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)),
    forces(-0.1 * dot(x) * dx - 9.81),
)]
struct Particle;

fn main() {}
