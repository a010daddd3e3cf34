//! Writes `docs/performance.md` from the last bench run: every criterion result under
//! `target/criterion` (`cargo bench --bench step`), grouped as the bench groups them, with the
//! ratios of paired steps (generated / hand-written, modular / monolithic, Hamiltonian /
//! Lagrangian, run / step loop), the work–precision study's summary where one is named
//! (`output/work_precision/summary.md`) and the field's against the method of lines
//! (`output/field_work_precision/summary.md`). Run by `scripts/performance.sh`; the file is
//! never edited by hand.
//!
//! `cargo run --example performance [CRITERION_DIR] [OUT] [STUDY_SUMMARY] [FIELD_SUMMARY]`

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

/// What each bench group measures, in one sentence.
const GROUPS: &[(&str, &str)] = &[
    (
        "generated_vs_hand_written",
        "The generated step against a hand-written one with analytic derivatives, the same Newton \
         solver and predictor (`scenes/src/hand_written.rs`; `tests/suite/golden.rs` checks they \
         follow the same trajectories).",
    ),
    (
        "double_pendulum_step_by_quadrature",
        "One double-pendulum step (h = 0.01) for each quadrature.",
    ),
    (
        "chain_trep_scene",
        "The n-link chain of trep's benchmark, by number of links (trep's own times come from its \
         scripts, run beside the bench).",
    ),
    (
        "mechanism_chain",
        "trep's n-link chain in maximal coordinates: point masses on rods held by joints, stepped \
         by the modular step, by number of links (over trep's stretch of the fall, as \
         `chain_trep_scene`).",
    ),
    (
        "constrained_midpoint_step",
        "Midpoint steps of constrained and degenerate models.",
    ),
    (
        "model_class_step",
        "Steps of Lagrangians linear in the velocities and of the knife edge, by quadrature.",
    ),
    (
        "double_pendulum_trep_scene",
        "trep's double-pendulum scene: a step, a step with the step map's first derivatives, and \
         with its second derivatives.",
    ),
    (
        "double_pendulum_100_steps",
        "`run(100)`, which records every sample, against 100 calls of `step()`.",
    ),
    (
        "pendulum_3d_step",
        "The 3D pendulum on SO(3): the generated Lie group step against a hand-written one, and \
         the generated midpoint step with its derivatives `A` in the tangent chart \
         (`step_linearised`).",
    ),
    (
        "spherical_pendulum_step",
        "The spherical pendulum on S² (the Cayley and the exponential chart) against the same \
         pendulum in Cartesian coordinates held on the sphere by a holonomic constraint.",
    ),
    (
        "route_step",
        "The discrete Hamiltonian route against the Lagrangian route on the same models.",
    ),
    (
        "interconnection_step",
        "Models built from components against the same models written as one struct.",
    ),
    (
        "explicit_step",
        "The explicit variational step of a separable Lagrangian (Störmer–Verlet and its \
         compositions) against the implicit step of the same order, solved by Newton's method \
         and by fixed-point iteration, on Kepler's problem (h = 0.01).",
    ),
    (
        "fixed_point_step",
        "Gauss steps of models that are not separable (the double pendulum at h = 0.02, the \
         8-link chain at h = 0.01), solved by Newton's method and by fixed-point iteration on \
         their rows, over the first 500 steps from the start.",
    ),
    (
        "time_transformed_step",
        "One time-transformed step (dt/ds = |q|, the logarithmic Hamiltonian) on Kepler's orbit \
         of eccentricity 0.9, 32 fictive steps a revolution, against the same composition \
         written by hand.",
    ),
    (
        "forced_step",
        "Steps of forced models (an input, a resistor, body torques on SO(3)) with the work of \
         their forces booked.",
    ),
    (
        "modular_step",
        "The modular step (components by parts, Schur complement on the junctions) against the \
         monolithic step, and its cost by number of components.",
    ),
    (
        "plane_field_step",
        "One step of the membrane (Störmer–Verlet, square cells, periodic) by number of nodes: \
         `PlaneField` row by row on one thread and (from 10⁵ nodes) in parallel, cells of \
         degree 3 (99² and 315² nodes, named by the box cells' count beside them; one thread, a \
         fifth of the step), against a hand-written \
         five-point leapfrog of the same scheme.",
    ),
    (
        "field_step",
        "One step of the sine-Gordon field (Störmer–Verlet, Δx = 0.05, Δt = 0.02, periodic) by \
         number of nodes: `Field` one cell after another and in parallel, cells of degree 3 \
         (10⁴ and 10⁵ nodes), against a hand-written leapfrog of the same scheme.",
    ),
];

/// Paired path segments: a benchmark naming the first is divided by its twin naming the second.
const PAIRS: &[(&str, &str)] = &[
    ("generated", "hand_written"),
    ("modular", "monolithic"),
    ("modular", "one_model"),
    ("hamiltonian", "lagrangian"),
    ("run", "step_loop"),
    ("explicit", "implicit"),
    ("explicit", "hand_written"),
    ("fixed_point", "implicit"),
    ("fixed_point", "explicit"),
    ("time_transformed", "hand_written"),
    ("sequential", "hand_written"),
    ("parallel", "sequential"),
    ("degree_3", "sequential"),
];

/// Groups whose every benchmark is divided by one of them.
const BASELINES: &[(&str, &str)] = &[
    ("pendulum_3d_step", "hand_written_lgvi"),
    ("spherical_pendulum_step", "cartesian_holonomic"),
    ("interconnection_step", "lc_monolithic"),
];

/// One criterion result: its id within the group and the median time with its 95 % interval, ns.
struct Result {
    id: String,
    median: f64,
    lower: f64,
    upper: f64,
}

fn number(value: &Value, path: &[&str]) -> Option<f64> {
    path.iter().try_fold(value, |v, key| v.get(key))?.as_f64()
}

/// Every result under `dir`, by group.
fn read(dir: &Path, groups: &mut BTreeMap<String, Vec<Result>>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if !path.is_dir() {
            continue;
        }
        let new = path.join("new");
        if new.join("benchmark.json").is_file() {
            let benchmark: Value =
                serde_json::from_str(&std::fs::read_to_string(new.join("benchmark.json"))?)?;
            let estimates: Value =
                serde_json::from_str(&std::fs::read_to_string(new.join("estimates.json"))?)?;
            let text = |key: &str| {
                benchmark
                    .get(key)
                    .and_then(Value::as_str)
                    .map(str::to_owned)
            };
            let (Some(group), Some(median), Some(lower), Some(upper)) = (
                text("group_id"),
                number(&estimates, &["median", "point_estimate"]),
                number(
                    &estimates,
                    &["median", "confidence_interval", "lower_bound"],
                ),
                number(
                    &estimates,
                    &["median", "confidence_interval", "upper_bound"],
                ),
            ) else {
                eprintln!("skipped {}: not a criterion result", new.display());
                continue;
            };
            let id = [text("function_id"), text("value_str")]
                .into_iter()
                .flatten()
                .collect::<Vec<_>>()
                .join("/");
            groups.entry(group).or_default().push(Result {
                id,
                median,
                lower,
                upper,
            });
        } else {
            read(&path, groups)?;
        }
    }
    Ok(())
}

/// A time in ns, in the unit that keeps three significant digits.
fn time(ns: f64) -> String {
    match ns {
        t if t < 1e3 => format!("{t:.0} ns"),
        t if t < 1e6 => format!("{:.3} µs", t / 1e3),
        t if t < 1e9 => format!("{:.3} ms", t / 1e6),
        t => format!("{:.3} s", t / 1e9),
    }
}

/// For each series of benchmarks whose ids end in a size (`name/N`, at least three sizes over a
/// decade or more), the exponent `a` of the least-squares fit `median ∝ Nᵃ`, one table row each.
fn growth(results: &[&Result]) -> String {
    let mut series: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    for r in results {
        let (name, size) = r.id.rsplit_once('/').unwrap_or(("", &r.id));
        if let Ok(size) = size.parse::<f64>() {
            let points = series.entry(name.to_owned()).or_default();
            points.push((size.ln(), r.median.ln()));
        }
    }
    let mut rows = String::new();
    for (name, points) in series {
        let (low, high) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p.0), h.max(p.0))
            });
        if points.len() < 3 || high - low < std::f64::consts::LN_10 {
            continue;
        }
        let n = points.len() as f64;
        let (mx, my) = points
            .iter()
            .fold((0.0, 0.0), |(x, y), p| (x + p.0 / n, y + p.1 / n));
        let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let name = if name.is_empty() { "all" } else { &name };
        let _ = writeln!(
            rows,
            "| {name} | {:.2} | {:.0} to {:.0} |",
            sxy / sxx,
            low.exp(),
            high.exp()
        );
    }
    rows
}

/// The id of `id`'s twin under the pair `(from, to)`, if `id` names `from` as a path segment.
fn twin(id: &str, from: &str, to: &str) -> Option<String> {
    let segments: Vec<&str> = id.split('/').collect();
    segments.contains(&from).then(|| {
        let swapped: Vec<&str> = segments
            .iter()
            .map(|s| if *s == from { to } else { s })
            .collect();
        swapped.join("/")
    })
}

fn write(
    groups: &BTreeMap<String, Vec<Result>>,
    study: Option<String>,
    field: Option<String>,
) -> String {
    let mut out = String::new();
    let machine = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_owned())
        })
        .unwrap_or_else(|| "an unknown processor".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let _ = writeln!(out, "# Performance\n");
    let _ = writeln!(
        out,
        "> Written by `scripts/performance.sh` from one bench run; do not edit by hand. Run the \
         script again to renew it.\n"
    );
    let _ = writeln!(
        out,
        "Criterion medians of `cargo bench --bench step` with their 95 % intervals, on {machine} \
         ({cores} cores). Timings on a shared machine move by up to 30 % between runs: compare \
         within a table, where every figure comes from the same run. The bench profile uses \
         `codegen-units = 1` and `lto = \"fat\"`. A ratio divides the first of a pair by its \
         twin (generated / hand-written, modular / monolithic, Hamiltonian / Lagrangian, run / \
         step loop) or a benchmark by its group's baseline.\n"
    );
    let described = |name: &str| GROUPS.iter().find(|(g, _)| *g == name).map(|(_, d)| *d);
    let mut names: Vec<&String> = groups.keys().collect();
    names.sort_by_key(|n| {
        GROUPS
            .iter()
            .position(|(g, _)| g == n)
            .unwrap_or(usize::MAX)
    });
    for name in names {
        let results = &groups[name];
        let _ = writeln!(out, "## `{name}`\n");
        if let Some(description) = described(name) {
            let _ = writeln!(out, "{description}\n");
        }
        let _ = writeln!(out, "| benchmark | median | 95 % interval |\n|---|---|---|");
        let mut sorted: Vec<&Result> = results.iter().collect();
        sorted.sort_by_key(|r| natural(&r.id));
        for r in &sorted {
            let _ = writeln!(
                out,
                "| {} | {} | {} – {} |",
                r.id,
                time(r.median),
                time(r.lower),
                time(r.upper)
            );
        }
        let mut ratios = String::new();
        let baseline = BASELINES
            .iter()
            .find(|(g, _)| g == name)
            .and_then(|(_, id)| sorted.iter().find(|r| r.id == *id));
        let mut row = |r: &Result, d: &Result| {
            let _ = writeln!(
                ratios,
                "| {} / {} | {:.2} |",
                r.id,
                d.id,
                r.median / d.median
            );
        };
        for r in &sorted {
            if let Some(d) = baseline.filter(|d| d.id != r.id) {
                row(r, d);
            }
            for (from, to) in PAIRS {
                let Some(other) = twin(&r.id, from, to) else {
                    continue;
                };
                if let Some(d) = sorted.iter().find(|d| d.id == other) {
                    row(r, d);
                }
            }
        }
        if !ratios.is_empty() {
            let _ = writeln!(out, "\n| ratio | medians |\n|---|---|\n{ratios}");
        } else {
            out.push('\n');
        }
        let growth = growth(&sorted);
        if !growth.is_empty() {
            let _ = writeln!(
                out,
                "| growth with the size | fitted exponent | sizes |\n|---|---|---|\n{growth}"
            );
        }
    }
    if let Some(study) = study {
        let _ = writeln!(
            out,
            "## Against other integrators\n\nThe work–precision study \
             (`cargo run --release --example work_precision --features scenes/bdf`): the cost of each integrator to \
             reach each target, as the study wrote it.\n\n{}",
            study.trim()
        );
    }
    if let Some(field) = field {
        let _ = writeln!(
            out,
            "\n## A field against the method of lines\n\n{}",
            field.trim()
        );
    }
    let _ = writeln!(
        out,
        "\n## Reproduce\n\n```text\nscripts/performance.sh             # every bench, then the \
         study, then this file\nscripts/performance.sh --no-study  # the benches only\n\
         cargo test --test allocation       # allocations per step and per recorded sample\n\
         cargo run --release --example long_run   # ten million pendulum steps\n\
         cargo run --release --example ensemble   # ensembles across cores\n\
         scripts/compile_times.sh           # build times of 100 to 10 000-term models\n```"
    );
    out
}

/// A sort key that orders the numbers inside ids by value (`ladder_cells/8` before `/16`).
fn natural(id: &str) -> Vec<(String, u64)> {
    id.split('/')
        .map(|s| match s.parse::<u64>() {
            Ok(n) => (String::new(), n),
            Err(_) => (s.to_owned(), 0),
        })
        .collect()
}

fn main() -> std::result::Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let criterion = PathBuf::from(args.next().unwrap_or_else(|| "target/criterion".into()));
    let target = PathBuf::from(args.next().unwrap_or_else(|| "docs/performance.md".into()));
    let mut groups = BTreeMap::new();
    read(&criterion, &mut groups).map_err(|e| {
        format!(
            "reading {}: {e} (run the benches first)",
            criterion.display()
        )
    })?;
    if groups.is_empty() {
        return Err(format!("no criterion results under {}", criterion.display()).into());
    }
    let mut summary = || match args.next() {
        Some(path) => std::fs::read_to_string(&path)
            .map(Some)
            .map_err(|e| format!("reading {path}: {e}")),
        None => Ok(None),
    };
    let (study, field) = (summary()?, summary()?);
    std::fs::write(&target, write(&groups, study, field))?;
    let count: usize = groups.values().map(Vec::len).sum();
    println!(
        "wrote {} ({count} results in {} groups)",
        target.display(),
        groups.len()
    );
    Ok(())
}
