//! A satellite slewed to a target attitude by a proportional-derivative torque on its inputs:
//! `cargo run --release --example satellite`.

fn main() -> Result<(), dirac::DiracError> {
    scenes::print_table(&[scenes::satellite::report()?]);
    Ok(())
}
