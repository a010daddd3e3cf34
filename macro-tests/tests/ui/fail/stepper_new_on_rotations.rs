use dirac::prelude::*;

/// A free rigid body: its configuration space is SO(3), not R³.
#[dirac_system(
    coordinates(r: SO3),
    lagrangian = 0.5 * dot(omega(r), omega(r)),
)]
struct Body;

fn main() {
    // Models with rotations are stepped by `Stepper::on_manifold`.
    let _ = Stepper::new(Body, Quadrature::midpoint(), 0.1);
}
