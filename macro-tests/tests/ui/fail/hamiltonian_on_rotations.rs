use dirac::prelude::*;

#[dirac_system(coordinates(R: SO3), hamiltonian = 0.5 * dot(p(R), p(R)))]
struct Body;

fn main() {}
