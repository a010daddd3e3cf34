use dirac::prelude::*;

#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2),
    hamiltonian = 0.5 * p(x).powi(2),
)]
struct Free;

fn main() {}
