//! The sine-Gordon kink–antikink collision, a field stepped explicitly on a grid
//! (`dirac::Field`): an antikink and a kink at half the speed of light pass through each other
//! at `t = 0`, on `[−20, 20]` with free ends, from `t = −10` to `10`. The run is checked against
//! the closed form of Perring and Skyrme; the field over space and time is drawn to
//! `output/sine_gordon.png` and its snapshots written to `output/sine_gordon.csv` (one row per
//! snapshot: `t`, then `u` at every picked node, the nodes' positions in the header) and, every
//! node to the last bit, to `output/sine_gordon.snapshots` (`dirac::snapshots`).
//!
//! `cargo run --release --example sine_gordon [CELLS]` (default 4 000 cells; Δt = 0.4 Δx)

use std::io::Write as _;

use dirac::nalgebra::SVector;
use dirac::plot::space_time_chart;
use dirac::snapshots::SnapshotWriter;
use scenes::field::collision_run;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cells: usize = std::env::args().nth(1).map_or(Ok(4_000), |a| a.parse())?;
    let run = collision_run(cells, 10.0, 400)?;
    let (e0, energy_error) = (run.energy[0], run.energy_error());
    println!(
        "{cells} cells, {} steps in {:.2?} ({:.2?} a step)",
        run.steps,
        run.wall,
        run.wall / run.steps as u32
    );
    println!("|u(10) − Perring–Skyrme| = {:.2e}", run.error);
    println!("energy {e0:.6}, largest error {energy_error:.2e}");
    std::fs::create_dir_all("output")?;
    // At most 500 columns of the CSV: every k-th node.
    let stride = run.x.len().div_ceil(500);
    let picked: Vec<usize> = (0..run.x.len()).step_by(stride).collect();
    let mut csv = std::io::BufWriter::new(std::fs::File::create("output/sine_gordon.csv")?);
    let header: Vec<String> = picked
        .iter()
        .map(|&j| format!("u({:.4})", run.x[j]))
        .collect();
    writeln!(csv, "t,{}", header.join(","))?;
    for (t, u) in &run.snapshots {
        let row: Vec<String> = picked.iter().map(|&j| format!("{:.9e}", u[j])).collect();
        writeln!(csv, "{t:.6},{}", row.join(","))?;
    }
    csv.flush()?;
    let file = std::io::BufWriter::new(std::fs::File::create("output/sine_gordon.snapshots")?);
    let mut snapshots = SnapshotWriter::<_, 1>::new(file, &run.x)?;
    for (t, u) in &run.snapshots {
        let u: Vec<SVector<f64, 1>> = u.iter().map(|&u| SVector::from([u])).collect();
        snapshots.write(*t, &u)?;
    }
    snapshots.finish()?;
    space_time_chart(
        "output/sine_gordon.png",
        "sine-Gordon kink–antikink collision",
        ("x", "t"),
        &run.x,
        &run.snapshots,
    )?;
    println!(
        "wrote output/sine_gordon.png, output/sine_gordon.csv and output/sine_gordon.snapshots"
    );
    Ok(())
}
