//! Rigid bodies on `SO(3)`: the heavy top with both retractions (vertical momentum and `RᵀR − I`
//! checked) and the 3D pendulum against a quaternion Dop853 reference with two quadratures:
//! `cargo run --release --example rigid_body`.

mod scenes;

use dirac::{Product, Quadrature};
use scenes::rigid_body;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut reports = Vec::new();
    for space in [Product::cayley(), Product::exp()] {
        reports.push(rigid_body::report(space)?);
    }
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2)?] {
        reports.push(rigid_body::pendulum_report(quadrature)?);
    }
    scenes::print_table(&reports);
    Ok(())
}
