//! Ten million midpoint steps of the pendulum (h = 0.1, T = 10⁶, ~160 000 periods), sampled every
//! 1 000 steps: the energy error stays flat, and the trajectory holds 10⁴ samples.
//!
//! `cargo run --release --example long_run`

use std::time::Instant;

use dirac::prelude::*;
use scenes::pendulum;

fn main() -> Result<(), DiracError> {
    let (h, t_end, every) = (0.1, 1e6, 1_000);
    let steps = (t_end / h) as u64;
    let mut stepper = Stepper::new(pendulum::SCENE, Quadrature::midpoint(), h)?;
    stepper.start_from_momentum(vector![1.0], vector![0.0])?;
    let bar = scenes::progress::bar(0.0, t_end, h);
    let start = Instant::now();
    let run = Run::until(t_end)
        .every(every)
        .observe(scenes::progress::observer(&bar));
    let trajectory = stepper.solve(run)?.trajectory;
    bar.finish_and_clear();
    let wall = start.elapsed();
    let energy = trajectory.energy();
    let e0 = energy[0];
    let tenth = energy.len() / 10;
    let max_error = |part: &[f64]| part.iter().fold(0.0_f64, |m, e| m.max((e - e0).abs()));
    let (first, last) = (
        max_error(&energy[..tenth]),
        max_error(&energy[energy.len() - tenth..]),
    );
    // t, q, v, p and the energy per sample (N = 1), in f64.
    let bytes = trajectory.len() * 5 * std::mem::size_of::<f64>();
    println!("{steps} midpoint steps of the pendulum at h = 0.1 in {wall:.2?}");
    println!(
        "max |E − E0|: first tenth {first:.3e}, last tenth {last:.3e} (ratio {:.3})",
        last / first
    );
    println!(
        "{} samples, {:.2} MB of trajectory",
        trajectory.len(),
        bytes as f64 / 1e6
    );
    Ok(())
}
