use dirac::prelude::*;

#[dirac_system(
    coordinates(links[5000]: SO3),
    lagrangian = 0.5 * dot(omega(links[0]), omega(links[0])),
)]
struct Chain;

fn main() {}
