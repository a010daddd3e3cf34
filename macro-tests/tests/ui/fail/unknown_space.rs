use dirac::prelude::*;

#[dirac_system(coordinates(R: SO4), lagrangian = 0.5 * dot(omega(R), omega(R)))]
struct Body;

fn main() {}
