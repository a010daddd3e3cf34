use dirac::prelude::*;

#[dirac_system(coordinates(q), lagrangian = 0.5 * dot(q).powi(2))]
struct Inductor;

#[dirac_system(subsystems(l), lagrangian = 0.5)]
struct Circuit {
    l: Inductor,
}

fn main() {}
