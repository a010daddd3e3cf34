use dirac::prelude::*;

#[dirac_system(coordinates(q), lagrangian = 0.5 * dot(q).powi(2))]
struct Inductor;

#[dirac_system(subsystems(l))]
struct Circuit {
    l: Inductor,
    r: f64,
}

fn main() {}
