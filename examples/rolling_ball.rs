//! A ball rolling without slipping on a plane (`R² × SO(3)`, two rolling one-forms) with the
//! one-forms at q_k, the midpoint and q_{k+1}, against its closed form:
//! `cargo run --release --example rolling_ball`.

use dirac::ConstraintPoint;

fn main() -> Result<(), dirac::DiracError> {
    let reports = [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ]
    .into_iter()
    .map(scenes::rolling_ball::report)
    .collect::<Result<Vec<_>, _>>()?;
    scenes::print_table(&reports);
    Ok(())
}
