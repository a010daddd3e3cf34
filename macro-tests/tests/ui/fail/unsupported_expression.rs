use dirac::prelude::*;

#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * { dot(x) * dot(x) } - dbg!(x) + if x > 0.0 { x } else { -x },
)]
struct Particle;

fn main() {}
