//! The kepler scene with every tour quadrature: `cargo run --release --example kepler`.
//! Prints the table and writes one CSV trajectory per quadrature to `output/`.

fn main() -> Result<(), dirac::DiracError> {
    let reports = scenes::quadratures()
        .into_iter()
        .map(scenes::kepler::report)
        .collect::<Result<Vec<_>, _>>()?;
    scenes::print_table(&reports);
    Ok(())
}
