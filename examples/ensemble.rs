//! A Monte Carlo of the double pendulum's divergence time over a grid of initial angles, run on
//! one thread and then on all cores (rayon), each timed as the fastest of three, with the speedup
//! and a check that both give the same numbers bit for bit.
//!
//! `cargo run --release --example ensemble`

use std::time::{Duration, Instant};

use dirac::prelude::*;
use scenes::ensemble;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (h, horizon) = (0.01, 50.0);
    let members = ensemble::grid(8);
    let quadrature = Quadrature::galerkin(2)?;
    let mut timings = Vec::new();
    let mut results = Vec::new();
    let cores = std::thread::available_parallelism()?.get();
    for threads in [1, cores] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        // The fastest of three: this machine's cores are shared, and single runs vary by 2×.
        let mut fastest = Duration::MAX;
        let mut times = Vec::new();
        for _ in 0..3 {
            let clock = Instant::now();
            times = pool
                .install(|| ensemble::divergence_times(quadrature.clone(), h, &members, horizon))?;
            fastest = fastest.min(clock.elapsed());
        }
        timings.push(fastest);
        results.push(times);
    }
    assert_eq!(
        results[0], results[1],
        "the ensemble depends on the thread count"
    );
    let times = &results[0];
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let diverged = times.iter().filter(|&&t| t < horizon).count();
    println!(
        "{} double pendulums ({} at h = {h}, T = {horizon}): {diverged} diverged, median \
         divergence time {median:.2}",
        members.len(),
        quadrature.name()
    );
    println!(
        "1 thread {:.2?}, {cores} threads {:.2?}: speedup {:.2}",
        timings[0],
        timings[1],
        timings[0].as_secs_f64() / timings[1].as_secs_f64()
    );
    Ok(())
}
