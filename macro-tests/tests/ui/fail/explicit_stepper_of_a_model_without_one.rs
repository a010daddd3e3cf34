use dirac::prelude::*;

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x)]
struct Oscillator;

fn main() {
    let _ = Stepper::explicit_from_system(Oscillator, 0.1);
}
