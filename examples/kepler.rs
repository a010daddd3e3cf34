//! The kepler scene with every tour quadrature, and an orbit of eccentricity 0.9 at a fixed step
//! and time-transformed (`dt/ds = |q|`): `cargo run --release --example kepler`.
//! Prints the table and writes one CSV trajectory per quadrature to `output/`.

fn main() -> Result<(), dirac::DiracError> {
    let mut reports = scenes::quadratures()
        .into_iter()
        .map(scenes::kepler::report)
        .collect::<Result<Vec<_>, _>>()?;
    reports.extend(scenes::kepler::eccentric_reports()?);
    scenes::print_table(&reports);
    Ok(())
}
