//! A satellite slewed to a target attitude by a proportional-derivative torque on its inputs:
//! `cargo run --release --example satellite`.

mod scenes;

fn main() -> Result<(), dirac::DiracError> {
    scenes::print_table(&[scenes::satellite::report()?]);
    Ok(())
}
