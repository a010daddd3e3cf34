use dirac::prelude::*;

#[dirac_system(coordinates(R: SO3), lagrangian = 0.5 * dot(omega(R), j * omega(R)))]
struct Body {
    j: [f64; 3],
}

fn main() {}
