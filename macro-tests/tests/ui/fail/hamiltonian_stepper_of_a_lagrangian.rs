use dirac::prelude::*;

/// A pendulum given by its Lagrangian.
#[dirac_system(coordinates(theta), lagrangian = 0.5 * dot(theta).powi(2) + cos(theta))]
struct Pendulum;

fn main() {
    // The Hamiltonian route takes models given by a Hamiltonian.
    let _ = Stepper::hamiltonian(Pendulum, Quadrature::midpoint(), 0.1);
}
