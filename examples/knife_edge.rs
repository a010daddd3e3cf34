//! The knife edge on an incline with the one-form evaluated at q_k, the midpoint and q_{k+1}:
//! `cargo run --release --example knife_edge`.

use dirac::ConstraintPoint;

fn main() -> Result<(), dirac::DiracError> {
    let reports = [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ]
    .into_iter()
    .map(scenes::knife_edge::report_point)
    .collect::<Result<Vec<_>, _>>()?;
    scenes::print_table(&reports);
    Ok(())
}
