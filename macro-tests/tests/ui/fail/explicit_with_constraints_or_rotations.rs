use dirac::prelude::*;

#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)),
    constraints(dx - dy),
    quadrature = explicit(2),
)]
struct Rail;

#[dirac_system(
    coordinates(R: SO3),
    lagrangian = 0.5 * dot(omega(R), omega(R)),
    quadrature = explicit(2),
)]
struct Body;

#[dirac_system(coordinates(q), hamiltonian = 0.5 * p(q).powi(2), quadrature = explicit(2))]
struct Free;

fn main() {}
