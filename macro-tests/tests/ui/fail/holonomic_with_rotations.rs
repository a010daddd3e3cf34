use dirac::prelude::*;

#[dirac_system(
    coordinates(x, R: SO3),
    lagrangian = 0.5 * dot(x).powi(2) + 0.5 * dot(omega(R), omega(R)),
    holonomic(x - R[0][0]),
)]
struct Body;

fn main() {}
