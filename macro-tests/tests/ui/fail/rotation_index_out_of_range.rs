use dirac::prelude::*;

#[dirac_system(
    coordinates(bodies[2]: SO3),
    lagrangian = 0.5 * dot(omega(bodies[0]), omega(bodies[2])),
)]
struct Pair;

fn main() {}
