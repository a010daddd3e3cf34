use dirac::prelude::*;

#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces(-c * dot(x) * dx),
    quadrature = explicit(kahan_li_6),
)]
struct Damped {
    c: f64,
}

fn main() {}
