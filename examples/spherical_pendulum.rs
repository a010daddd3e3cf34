//! The spherical pendulum on the unit sphere `S²` beside the same pendulum in Cartesian
//! coordinates with a holonomic constraint, both against a Dop853 reference:
//! `cargo run --release --example spherical_pendulum`.

mod scenes;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    scenes::print_table(&scenes::spherical_pendulum::reports()?);
    Ok(())
}
