use dirac::prelude::*;

// A pendulum on a cart: its mass matrix turns with the angle.
#[dirac_system(
    coordinates(x, theta),
    lagrangian = 0.5 * dot(x).powi(2) + dot(x) * dot(theta) * cos(theta) + 0.5 * dot(theta).powi(2),
    quadrature = explicit(8),
)]
struct CartPendulum;

fn main() {}
