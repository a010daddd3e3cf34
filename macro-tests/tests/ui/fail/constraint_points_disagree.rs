use dirac::prelude::*;

/// A knife edge holding its one-form at the step's start.
#[dirac_system(
    coordinates(x, y, phi),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2) + dot(phi).powi(2)),
    constraints(sin(phi) * dx - cos(phi) * dy),
    constraint_at = start,
)]
struct Early;

/// The same at the step's end.
#[dirac_system(
    coordinates(x, y, phi),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2) + dot(phi).powi(2)),
    constraints(sin(phi) * dx - cos(phi) * dy),
    constraint_at = end,
)]
struct Late;

#[dirac_system(subsystems(early, late), junctions(early.dphi - late.dphi))]
struct Pair {
    early: Early,
    late: Late,
}

fn main() {}
