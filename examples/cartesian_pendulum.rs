//! The cartesian pendulum scene: `cargo run --release --example cartesian_pendulum`.

use dirac::Quadrature;

fn main() -> Result<(), dirac::DiracError> {
    let reports = vec![scenes::cartesian_pendulum::report(Quadrature::midpoint())?];
    scenes::print_table(&reports);
    Ok(())
}
