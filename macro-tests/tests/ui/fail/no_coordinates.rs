use dirac::prelude::*;

#[dirac_system(coordinates(), lagrangian = 1.0)]
struct Nothing;

fn main() {}
