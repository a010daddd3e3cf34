//! The seed's LC circuit and its RLC variant: `cargo run --release --example lc_circuit`.
//! Kirchhoff's laws are constraint one-forms; the capacitor charges have no kinetic energy.

use dirac::Quadrature;

fn main() -> Result<(), dirac::DiracError> {
    let reports = vec![
        scenes::circuit::report(Quadrature::midpoint())?,
        scenes::circuit::rlc_report(Quadrature::midpoint())?,
    ];
    scenes::print_table(&reports);
    if let Err(error) = scenes::circuit::lc_at_10(Quadrature::trapezoid(), 0.01) {
        println!("\ntrapezoid: {error}");
    }
    Ok(())
}
