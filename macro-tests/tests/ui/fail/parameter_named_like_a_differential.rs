use dirac::prelude::*;

// The field `damp` would read as the differential of `amp` in forces(...).
#[dirac_system(
    coordinates(amp),
    lagrangian = 0.5 * dot(amp) * dot(amp) - 0.5 * amp * amp,
    forces(-c * dot(amp) * damp),
)]
struct Damped {
    c: f64,
    damp: f64,
}

fn main() {}
