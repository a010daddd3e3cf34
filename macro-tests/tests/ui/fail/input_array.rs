use dirac::prelude::*;

#[dirac_system(
    coordinates(R: SO3),
    lagrangian = 0.5 * dot(omega(R), omega(R)),
    forces(dot([u_x, u_y, u_z], dR)),
    inputs(u[3]),
)]
struct Body;

fn main() {}
