//! How the modular step of a long chain scales with threads: an open chain of `K` tethered
//! masses (`scenes::ladder::modular_chain`, midpoint, h = 0.01), stepped one component after
//! another and then in parallel on pools of 1, 2, 4, … threads up to the cores there are. Each
//! time is the fastest of three rounds of steps; the parallel steps are checked to give the
//! sequential ones' state bit for bit.
//!
//! `cargo run --release --example modular_scaling [CELLS …]` (default 1 000, 10 000 and 100 000)

use std::time::{Duration, Instant};

use dirac::modular::Modular;
use scenes::ladder;

type Failure = Box<dyn std::error::Error + Send + Sync>;

/// A chain of `cells` masses started on a wave 100 masses long, stepped in parallel or not.
fn chain(cells: usize, parallel: bool) -> Result<Modular, Failure> {
    let x = |j: usize| 0.1 * (std::f64::consts::TAU * j as f64 / 100.0).sin();
    let q0: Vec<f64> = (0..cells).flat_map(|j| [x(j), x(j + 1)]).collect();
    let mut chain = ladder::modular_chain(1.0, 1.0, cells, false, 0.01)?.with_parallel(parallel);
    chain.start_from_velocity(&q0, &vec![0.0; 2 * cells])?;
    Ok(chain)
}

/// The fastest of three rounds of `steps` steps, per step, and the state after them.
fn timed(chain: &mut Modular, steps: u64) -> Result<(Duration, Vec<f64>), Failure> {
    let mut fastest = Duration::MAX;
    for _ in 0..3 {
        let clock = Instant::now();
        chain.run(steps)?;
        fastest = fastest.min(clock.elapsed() / steps as u32);
    }
    Ok((fastest, chain.q().as_slice().to_vec()))
}

fn main() -> Result<(), Failure> {
    let parsed: Result<Vec<usize>, _> = std::env::args().skip(1).map(|a| a.parse()).collect();
    let sizes = match parsed {
        Ok(sizes) if sizes.contains(&0) => return Err("a chain needs at least one mass".into()),
        Ok(sizes) if !sizes.is_empty() => sizes,
        Ok(_) => vec![1_000, 10_000, 100_000],
        Err(e) => return Err(format!("cells must be whole numbers: {e}").into()),
    };
    let cores = std::thread::available_parallelism()?.get();
    let threads: Vec<usize> = (0..)
        .map(|k| 1 << k)
        .take_while(|&t| t < cores)
        .chain([cores])
        .collect();
    println!(
        "| cells | one after another | {} |",
        threads
            .iter()
            .map(|t| format!("{t} threads"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!("|---|---|{}", "---|".repeat(threads.len()));
    for &cells in &sizes {
        // About a second of work a round for the sequential step (1 µs a mass a step).
        let steps = (1_000_000 / cells).clamp(3, 1_000) as u64;
        let (sequential, reference) = timed(&mut chain(cells, false)?, steps)?;
        let mut row = format!("| {cells} | {sequential:.2?} |");
        for &t in &threads {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
            let (time, state) = pool.install(|| timed(&mut chain(cells, true)?, steps))?;
            if state != reference {
                return Err(
                    format!("{cells} cells on {t} threads: not the sequential state").into(),
                );
            }
            let speedup = sequential.as_secs_f64() / time.as_secs_f64();
            row += &format!(" {time:.2?} ({speedup:.2}×) |");
        }
        println!("{row}");
    }
    Ok(())
}
