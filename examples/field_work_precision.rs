//! The field's explicit multisymplectic step against the method of lines on the same grid: the
//! sine-Gordon breather (ω = 0.5) on `[−20, 20]` with free ends, 800 cells, to T = 100. dirac's
//! `Field` (Störmer–Verlet and its compositions of orders 4, 6 and 8) and Dop853 and Dopri5 on the
//! field's semi-discrete equations (`scenes::field_lines`) share the spatial discretisation, so
//! the errors are the time integrators' alone, against Dop853 at 1e-13 on that grid. Prints every
//! run and, for each target, the cheapest run that meets it; writes the table to
//! `output/field_work_precision/summary.md`.
//!
//! `cargo run --release --example field_work_precision [CELLS] [T]`

use std::fmt::Write as _;

use dirac::Composition;
use scenes::field_lines::{LinesRun, SineGordonLines, distance, field_run, integrate};
use scenes::peers::Peer;

/// One run: who, with what setting, and what it measured.
struct Row {
    method: String,
    setting: String,
    dirac: bool,
    run: LinesRun,
    error: f64,
}

/// What a target bounds: a run's error or its energy error.
type Measure = fn(&Row) -> f64;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cells: usize = args.next().map_or(Ok(800), |a| a.parse())?;
    let horizon: f64 = args.next().map_or(Ok(100.0), |a| a.parse())?;
    let omega = 0.5;
    let lines = SineGordonLines::new((-20.0, 20.0), cells)?;
    let y0 = lines.breather(omega, 0.0);
    let fine = integrate(&lines, Peer::Dop853, &y0, horizon, 1e-13)?;
    let coarse = integrate(&lines, Peer::Dop853, &y0, horizon, 1e-12)?;
    let reference_error = distance(&fine.end, &coarse.end);
    println!(
        "sine-Gordon breather ω = {omega}, {cells} cells (Δx = {:.3}), T = {horizon}: reference \
         Dop853 at 1e-13 ({} steps), estimated error {reference_error:.1e}",
        lines.dx, fine.steps
    );
    let mut rows = Vec::new();
    // A run kept as a row, or reported where it failed.
    let mut record =
        |method: &str, setting: String, dirac: bool, run: Result<LinesRun, String>| match run {
            Ok(run) => rows.push(Row {
                method: method.to_string(),
                error: distance(&run.end, &fine.end),
                setting,
                dirac,
                run,
            }),
            Err(why) => println!("  {method} {setting}: {why}"),
        };
    let compositions = [
        Composition::verlet(),
        Composition::suzuki(),
        Composition::kahan_li_6(),
        Composition::kahan_li_8(),
    ];
    for composition in &compositions {
        // Steps that divide the horizon, about the leapfrog's stability limit (Δt < Δx) and
        // beyond: a composition's own limit differs, and a run that fails is reported.
        for dt in [1.6, 1.2, 0.8, 0.6, 0.4, 0.2, 0.1].map(|k| k * lines.dx) {
            let dt = horizon / (horizon / dt).ceil();
            let run = field_run(&lines, composition, dt, &y0, horizon).map_err(|e| e.to_string());
            record(composition.name(), format!("Δt = {dt:.4}"), true, run);
        }
    }
    for peer in [Peer::Dopri5, Peer::Dop853] {
        for tolerance in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
            let run = integrate(&lines, peer, &y0, horizon, tolerance);
            record(peer.name(), format!("tol = {tolerance:e}"), false, run);
        }
    }
    // The reference checked apart from Dop853: the order-8 composition at its smallest step.
    let independent = rows
        .iter()
        .filter(|r| r.dirac && r.method.starts_with("Kahan–Li 8"))
        .max_by_key(|r| r.run.steps)
        .map_or(f64::NAN, |r| r.error);
    println!(
        "  {:<26} {:>14} {:>8} {:>10} {:>10} {:>14}",
        "method", "setting", "steps", "error", "|ΔE|", "ms per unit t"
    );
    for r in &rows {
        println!(
            "  {:<26} {:>14} {:>8} {:>10.2e} {:>10.2e} {:>14.3}",
            r.method,
            r.setting,
            r.run.steps,
            r.error,
            r.run.energy_error,
            1e3 * r.run.seconds / horizon
        );
    }
    let mut summary = String::new();
    writeln!(
        summary,
        "The sine-Gordon breather (ω = {omega}) on [−20, 20], {cells} cells, free ends, to T = \
         {horizon}: dirac's `Field` against the method of lines on the same grid \
         (`cargo run --release --example field_work_precision`). Errors are against Dop853 at \
         1e-13 on that grid (estimated error {reference_error:.1e} from its distance to 1e-12; \
         Kahan–Li 8 at Δt = Δx/10 ends {independent:.1e} from it); the energy is read at every \
         step of every run (the peers' accepted steps, stored as they go). Cost is wall time \
         per unit of simulated time; ratio = the peers' cost / dirac's.\n"
    )?;
    writeln!(
        summary,
        "| target | dirac's cheapest | peers' cheapest | ratio |\n|---|---|---|---|"
    )?;
    // The floor under which a target is not resolved: the reference's error for the error
    // targets, none for the energy's (each run's own).
    let targets: [(&str, f64, Measure, f64); 5] = [
        ("error ≤ 1e-4", 1e-4, |r| r.error, reference_error),
        ("error ≤ 1e-6", 1e-6, |r| r.error, reference_error),
        ("error ≤ 1e-8", 1e-8, |r| r.error, reference_error),
        ("\\|ΔE\\| ≤ 1e-6", 1e-6, |r| r.run.energy_error, 0.0),
        ("\\|ΔE\\| ≤ 1e-9", 1e-9, |r| r.run.energy_error, 0.0),
    ];
    for (name, target, measure, floor) in targets {
        if target <= floor {
            writeln!(
                summary,
                "| {name} | below the reference's error ({floor:.1e}) | | |"
            )?;
            continue;
        }
        let cheapest = |dirac: bool| {
            rows.iter()
                .filter(|r| r.dirac == dirac && measure(r) <= target)
                .min_by(|a, b| a.run.seconds.total_cmp(&b.run.seconds))
        };
        let shown = |r: Option<&Row>| match r {
            Some(r) => format!(
                "{} {} ({:.3} ms per unit t)",
                r.method,
                r.setting,
                1e3 * r.run.seconds / horizon
            ),
            None => "none meets it".to_string(),
        };
        let (ours, theirs) = (cheapest(true), cheapest(false));
        let ratio = match (ours, theirs) {
            (Some(a), Some(b)) => format!("{:.2}", b.run.seconds / a.run.seconds),
            (Some(_), None) => "dirac only".to_string(),
            (None, Some(_)) => "peers only".to_string(),
            (None, None) => "neither".to_string(),
        };
        writeln!(
            summary,
            "| {name} | {} | {} | {ratio} |",
            shown(ours),
            shown(theirs)
        )?;
    }
    println!("\n{summary}");
    std::fs::create_dir_all("output/field_work_precision")?;
    std::fs::write("output/field_work_precision/summary.md", &summary)?;
    println!("wrote output/field_work_precision/summary.md");
    Ok(())
}
