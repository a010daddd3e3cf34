//! trep's n-link chain in maximal coordinates: `n` unit point masses on unit rods
//! (`scenes::mechanism::point_chain`, joints held by the modular step, midpoint, h = 0.01),
//! straight, level and at rest at the start, as trep's benchmark starts its chain, over trep's
//! number of steps (`max(200, 4000/n)`; 50 above 1 000 links, where the falling chain's whip
//! asks for a smaller step after about 60). For each `n`: the time a step takes (the fastest of
//! three rounds from the start, after one round of warm-up), Newton's iterations a step, and
//! the largest rod-length error; then the growth exponent of the time between consecutive
//! sizes. trep's own times come from its script
//! (`chain.sh` of its peer folder), run beside this.
//!
//! `cargo run --release --example mechanism [N …]` (default 10, 20, 40, 100, 1 000, 10 000)

use std::time::{Duration, Instant};

use dirac::modular::Modular;
use scenes::mechanism;

type Failure = Box<dyn std::error::Error + Send + Sync>;

/// The chain of `n` links, started.
fn chain(n: usize) -> Result<Modular, Failure> {
    let mut chain = mechanism::point_chain(n, 1.0, 1.0, 9.81, 0.01)?;
    let theta = vec![std::f64::consts::FRAC_PI_2; n];
    let (q0, v0) = mechanism::point_chain_state(&theta, &vec![0.0; n], 1.0);
    chain.start_from_velocity(&q0, &v0)?;
    Ok(chain)
}

/// The largest `|ℓ − 1|` over the rods at positions `q`.
fn rod_error(q: &[f64]) -> f64 {
    let (mut x, mut y, mut worst) = (0.0, 0.0, 0.0_f64);
    for p in q.chunks(2) {
        worst = worst.max(((p[0] - x).hypot(p[1] - y) - 1.0).abs());
        (x, y) = (p[0], p[1]);
    }
    worst
}

fn main() -> Result<(), Failure> {
    let parsed: Result<Vec<usize>, _> = std::env::args().skip(1).map(|a| a.parse()).collect();
    let sizes = match parsed {
        Ok(sizes) if sizes.contains(&0) => return Err("a chain needs at least one link".into()),
        Ok(sizes) if !sizes.is_empty() => sizes,
        Ok(_) => vec![10, 20, 40, 100, 1_000, 10_000],
        Err(e) => return Err(format!("links must be whole numbers: {e}").into()),
    };
    println!("| links | per step | per link | Newton iterations a step | largest rod error |");
    println!("|---|---|---|---|---|");
    let mut previous: Option<(usize, Duration)> = None;
    let mut growth = Vec::new();
    for &n in &sizes {
        // trep's stretch; at 10 000 links 50 steps (the chain's whip needs a smaller step by
        // step 64).
        let steps = if n > 1_000 {
            50
        } else {
            (4_000 / n).max(200) as u64
        };
        let (mut fastest, mut evaluations, mut worst) = (Duration::MAX, 0, 0.0_f64);
        for round in 0..4 {
            let mut chain = chain(n)?;
            let clock = Instant::now();
            for _ in 0..steps {
                chain.step()?;
                if round == 3 {
                    evaluations += chain.report().map_or(0, |r| r.iterations);
                }
            }
            if round > 0 {
                fastest = fastest.min(clock.elapsed() / steps as u32);
            }
            worst = worst.max(rod_error(chain.q().as_slice()));
        }
        println!(
            "| {n} | {:.1} µs | {:.0} ns | {:.2} | {worst:.1e} |",
            fastest.as_secs_f64() * 1e6,
            fastest.as_secs_f64() * 1e9 / n as f64,
            evaluations as f64 / steps as f64,
        );
        if let Some((m, before)) = previous {
            let exponent =
                (fastest.as_secs_f64() / before.as_secs_f64()).ln() / (n as f64 / m as f64).ln();
            growth.push(format!("{m} → {n}: {exponent:.2}"));
        }
        previous = Some((n, fastest));
    }
    println!(
        "\ngrowth exponent of the time a step: {}",
        growth.join(", ")
    );
    Ok(())
}
