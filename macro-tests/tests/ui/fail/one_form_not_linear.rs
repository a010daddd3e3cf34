use dirac::prelude::*;

#[dirac_system(
    coordinates(x, y, phi),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2) + dot(phi).powi(2)),
    constraints(sin(phi) * dx * dy, cos(dphi)),
)]
struct Skate;

fn main() {}
