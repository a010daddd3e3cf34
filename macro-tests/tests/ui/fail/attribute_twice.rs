use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2))]
#[dirac_system(coordinates(y), lagrangian = 0.5 * dot(y).powi(2))]
struct Particle;

fn main() {
    let _ = Stepper::new(Particle, Quadrature::midpoint(), 0.1);
}
