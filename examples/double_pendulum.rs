//! The double pendulum scene with every tour quadrature: `cargo run --release --example double_pendulum`.
//! Prints the table and writes one CSV trajectory per quadrature to `output/`.

fn main() -> Result<(), dirac::DiracError> {
    let reports = scenes::quadratures()
        .into_iter()
        .map(scenes::double_pendulum::report)
        .collect::<Result<Vec<_>, _>>()?;
    scenes::print_table(&reports);
    Ok(())
}
