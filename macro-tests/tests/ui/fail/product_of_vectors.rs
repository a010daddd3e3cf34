use dirac::prelude::*;

#[dirac_system(coordinates(n: S2), lagrangian = 0.5 * dot(n) * dot(n) - n[2])]
struct Pendulum;

fn main() {}
