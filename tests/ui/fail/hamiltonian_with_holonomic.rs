use dirac::prelude::*;

#[dirac_system(
    coordinates(x, y),
    hamiltonian = 0.5 * (p(x).powi(2) + p(y).powi(2)) + g * y,
    holonomic(x * x + y * y - 1.0),
)]
struct Pendulum {
    g: f64,
}

fn main() {}
