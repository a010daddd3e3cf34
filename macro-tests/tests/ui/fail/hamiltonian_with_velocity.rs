use dirac::prelude::*;

#[dirac_system(coordinates(x), hamiltonian = 0.5 * dot(x).powi(2) + 0.5 * k * x.powi(2))]
struct Spring {
    k: f64,
}

fn main() {}
