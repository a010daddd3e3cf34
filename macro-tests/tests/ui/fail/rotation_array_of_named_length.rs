use dirac::prelude::*;

const LINKS: usize = 3;

#[dirac_system(coordinates(bodies[LINKS]: SO3), lagrangian = 0.5 * dot(omega(bodies[0]), omega(bodies[0])))]
struct Chain;

fn main() {}
