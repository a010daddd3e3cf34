use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(y).powi(2) - 0.5 * k * x.powi(2))]
struct Spring {
    k: f64,
}

fn main() {}
