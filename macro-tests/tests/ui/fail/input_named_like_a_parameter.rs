use dirac::prelude::*;

#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * m * dot(x).powi(2),
    forces(m * dx),
    inputs(m, t),
)]
struct Driven {
    m: f64,
}

fn main() {}
