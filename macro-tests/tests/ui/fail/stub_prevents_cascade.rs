use dirac::prelude::*;

// The attribute's error is the only one: the stub implementation keeps the use below compiling.
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(z).powi(2))]
struct Particle;

fn main() {
    let _ = Stepper::new(Particle, Quadrature::midpoint(), 0.1);
}
