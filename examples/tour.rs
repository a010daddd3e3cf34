//! Runs every scene with every tour quadrature, prints one table (scene, quadrature, h, steps,
//! max energy error, wall time, check against the known answer) and writes it to
//! `output/tour.csv`, beside one CSV trajectory per run.
//!
//! `cargo run --release --example tour`

mod scenes;

use dirac::{DiracError, Quadrature};
use scenes::Report;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    type Scene = fn(Quadrature) -> Result<Report, DiracError>;
    let scenes: [Scene; 5] = [
        scenes::oscillator::report,
        scenes::pendulum::report,
        scenes::double_pendulum::report,
        scenes::kepler::report,
        scenes::chain::report,
    ];
    let mut reports = Vec::new();
    for scene in scenes {
        for quadrature in scenes::quadratures() {
            reports.push(scene(quadrature)?);
        }
    }
    scenes::print_table(&reports);
    scenes::save_table(&reports, "output/tour.csv")?;
    println!("\nwrote output/tour.csv and one trajectory CSV per row to output/");
    Ok(())
}
