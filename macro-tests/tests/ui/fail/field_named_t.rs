use dirac::prelude::*;

#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2),
    forces(cos(t) * dx),
)]
struct Driven {
    t: f64,
}

fn main() {}
