//! Brouwer's law: round-off alone should make the energy error of a long run grow like `√t`.
//! Kepler's problem at e = 0.5, h = 0.01, where the methods' own energy error is far below
//! round-off, by the explicit composition of order 8 (Kahan–Li) and by the implicit Gauss
//! method of the same order (`galerkin(4)`, solved by Newton's method and by fixed-point
//! iteration): the root mean square of `E − E_0` over an ensemble
//! of turned starts, and a chart in `output/brouwer.png`. The exponent is fitted by least
//! squares in `log t` over the last two decades, and again with the floor taken out: the rms
//! adds in quadrature a floor that does not grow (evaluating `E`, the method's own bounded
//! error: the rms at the first checkpoint) and the walk, so the second fit takes
//! `√(rms² − floor²)` wherever the walk is at least the floor's size.
//!
//! `cargo run --release --example brouwer [STEPS] [RUNS] [IMPLICIT_STEPS]` (defaults 10⁷ steps
//! and 16 runs, the implicit method a tenth of the steps: about a minute on two cores;
//! `IMPLICIT_STEPS = 0` leaves it out).

use std::time::{Duration, Instant};

use dirac::plot::{Series, line_chart};
use dirac::prelude::*;
use scenes::roundoff::{Method, checkpoints, exponent, rms_energy_error};

/// `rms_energy_error` of `method` at step `h`, with the wall time it took.
fn timed(
    method: &Method,
    h: f64,
    runs: usize,
    at: &[u64],
) -> Result<(Vec<(f64, f64)>, Duration), DiracError> {
    let start = Instant::now();
    let points = rms_energy_error(method, h, runs, at)?;
    Ok((points, start.elapsed()))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let steps: u64 = args.next().map_or(Ok(10_000_000), |a| a.parse())?;
    let runs: usize = args.next().map_or(Ok(16), |a| a.parse())?;
    let implicit_steps: u64 = args.next().map_or(Ok(steps / 10), |a| a.parse())?;
    let h = 0.01;
    let per_decade = 10;
    let mut series = Vec::new();
    let mut csv = String::from("method,t,rms_energy_error\n");
    let mut record = |name: String, points: Vec<(f64, f64)>, wall: Duration| {
        let (first, last) = (points[0], points[points.len() - 1]);
        let walk: Vec<(f64, f64)> = points
            .iter()
            .filter(|(_, e)| e * e >= 2.0 * first.1 * first.1)
            .map(|&(t, e)| (t, (e * e - first.1 * first.1).sqrt()))
            .collect();
        let last_two_decades = &points[points.len().saturating_sub(2 * per_decade + 1)..];
        let fit = match walk.len() {
            0..=2 => "too short to fit an exponent".to_string(),
            _ => format!(
                "exponent {:.3} over the last two decades, {:.3} with the floor taken out \
                 (from t = {:.1})",
                exponent(last_two_decades),
                exponent(&walk),
                walk[0].0
            ),
        };
        println!(
            "{name}: {:.0e} steps x {runs} runs in {wall:.1?}; rms |E - E0| {:.2e} at t = {}, \
             {:.2e} at t = {}; {fit}",
            last.0 / h,
            first.1,
            first.0,
            last.1,
            last.0,
        );
        for &(t, e) in &points {
            // Quoted: a name may hold a comma.
            csv += &format!("\"{name}\",{t},{e}\n");
        }
        series.push(Series {
            label: name,
            points: points
                .iter()
                .map(|&(t, e)| (t.log10(), e.log10()))
                .collect(),
        });
    };
    let spread = |steps: u64| checkpoints(100, steps, per_decade as u32);
    let explicit = Method::Explicit(Composition::kahan_li_8());
    let (points, wall) = timed(&explicit, h, runs, &spread(steps))?;
    record(explicit.name(), points, wall);
    if implicit_steps > 0 {
        let gauss = Quadrature::galerkin(4)?;
        // The same step solved by Newton's method and by fixed-point iteration.
        for method in [Method::Lagrangian(gauss.clone()), Method::FixedPoint(gauss)] {
            let (points, wall) = timed(&method, h, runs, &spread(implicit_steps))?;
            record(method.name(), points, wall);
        }
    }
    // Guides from the first point: slopes 1/2 (a walk) and 1 (a drift).
    let (t0, e0) = series[0].points[0];
    let span = series[0].points[series[0].points.len() - 1].0 - t0;
    for alpha in [0.5, 1.0] {
        series.push(Series {
            label: format!("slope {alpha}"),
            points: vec![(t0, e0), (t0 + span, e0 + span * alpha)],
        });
    }
    std::fs::create_dir_all("output")?;
    std::fs::write("output/brouwer.csv", csv)?;
    line_chart(
        "output/brouwer.png",
        "Kepler e = 0.5, h = 0.01: round-off in the energy (rms over turned starts)",
        ("log10 t", "log10 rms |E - E0|"),
        &series,
    )?;
    println!("wrote output/brouwer.csv and output/brouwer.png");
    Ok(())
}
