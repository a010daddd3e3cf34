use dirac::prelude::*;

#[dirac_system(
    coordinates(R: SO3),
    lagrangian = 0.5 * dot(omega(R), omega(R)),
    constraints(omega(R)[2] * dR[0]),
)]
struct Suslov;

fn main() {}
