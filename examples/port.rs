//! The port scene: `cargo run --release --example port`.

use dirac::Quadrature;

fn main() -> Result<(), dirac::DiracError> {
    let reports = vec![scenes::port::report(Quadrature::midpoint())?];
    scenes::print_table(&reports);
    Ok(())
}
