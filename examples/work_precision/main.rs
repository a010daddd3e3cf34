//! The speed/accuracy study: dirac's quadratures against the integrators users would otherwise
//! pick, on seven scenes, to T = 10 and T = 10⁴, measured in one run.
//!
//! Per scene and horizon: a reference, the closed form where the scene has one, else Dop853 at
//! `rtol = atol = 1e-13` (its error estimated by the run at 1e-12); dirac's `midpoint`,
//! `galerkin(2)` and `galerkin(3)` at the scene's steps (to `galerkin(5)` at T = 10⁴ on the
//! circuit), also by their step maps where the model is linear (the circuit), for a separable model the explicit
//! compositions of orders 2 to 8 as well, and on Kepler's orbits those compositions
//! time-transformed (`dt/ds = |q|`) at the scene's fictive steps, measured by `Study`; Dop853
//! and Dopri5 (ode_solvers) at tolerances 1e-4 … 1e-12 on the hand-derived first-order form;
//! and BDF (diffsol) on the index-1 DAE of the circuit and of the
//! knife edge, in a build with `--features scenes/bdf` (as `scripts/performance.sh` runs
//! it). Every run's error at the horizon, largest energy error over every step and wall
//! time per unit of simulated time go to `output/work_precision/study.csv`, with two PNGs per
//! scene and horizon (error and energy error against cost); the summary prints, for each error
//! and energy error target, the cheapest run of dirac and of the peers and their cost ratio.
//! Constraint violations are printed but not compared: dirac records its discrete constraint
//! `A(q_c)(q_{k+1} − q_k)`, the peers' forms the velocity constraint at each state.
//!
//! `cargo run --release --example work_precision --features scenes/bdf` (16 minutes here; `-- 10`
//! runs T = 10 only, `-- 10000 Kepler` the scenes whose name contains `Kepler` at T = 10⁴)

use std::fmt::Write as _;

use dirac::prelude::*;
use scenes::first_order::FirstOrder;
use scenes::study::{self, Row, Scene, Visitor};

/// A bound on one measure of a run.
struct Target {
    what: &'static str,
    value: fn(&Row) -> f64,
    at_most: f64,
}

/// Runs every scene at each horizon and collects the rows.
struct Runner {
    horizons: Vec<f64>,
    /// Runs only the scenes whose name contains this (all: empty).
    only: String,
    rows: Vec<Row>,
    /// Per scene and horizon: the reference's own error estimate.
    references: Vec<(&'static str, f64, f64)>,
}

impl Visitor for Runner {
    fn visit<S, F, G, const Y: usize, const Z: usize, const N: usize>(
        &mut self,
        scene: Scene<S, F, G, Y, Z, N>,
    ) -> Result<(), String>
    where
        S: DiracSystem<N> + Clone,
        F: FirstOrder<Y, N>,
        G: FirstOrder<Z, N>,
    {
        if !scene.name.contains(self.only.as_str()) {
            return Ok(());
        }
        for horizon in self.horizons.clone() {
            println!("{} to T = {horizon}", scene.name);
            let (rows, estimate, failures) = study::measure(&scene, horizon)?;
            for failure in failures {
                println!("  {failure}");
            }
            self.rows.extend(rows);
            self.references.push((scene.name, horizon, estimate));
            self.print_and_draw(scene.name, horizon, estimate)?;
        }
        Ok(())
    }
}

impl Runner {
    /// The rows of one scene and horizon.
    fn of(&self, scene: &str, horizon: f64) -> Vec<&Row> {
        let same = |r: &&Row| r.scene == scene && r.horizon == horizon;
        self.rows.iter().filter(same).collect()
    }

    fn print_and_draw(&self, scene: &str, horizon: f64, estimate: f64) -> Result<(), String> {
        if estimate == 0.0 {
            println!("  reference: the closed form");
        } else {
            println!("  reference: Dop853 at 1e-13, estimated error {estimate:.1e}");
        }
        println!(
            "  {:<12} {:>12} {:>10} {:>10} {:>10} {:>10} {:>14}",
            "method", "setting", "steps", "error", "|ΔE|", "violation", "µs per unit t"
        );
        let rows = self.of(scene, horizon);
        for r in &rows {
            // A fixed-point run's steps that its iteration handed to Newton's method.
            let handed = match r.handed_over {
                0 => String::new(),
                n => format!(" ({n} steps by Newton)"),
            };
            println!(
                "  {:<12} {:>12} {:>10} {:>10.2e} {:>10.2e} {:>10.1e} {:>14.2}{handed}",
                r.method,
                r.setting,
                r.steps,
                r.error,
                r.energy_error,
                r.violation,
                r.seconds_per_unit_time * 1e6
            );
        }
        // "Kepler e = 0.5" → kepler_e0.5, "chain (8 links)" → chain_8_links.
        let file = scene
            .to_lowercase()
            .replace(" = ", "")
            .replace(['(', ')'], "")
            .replace(' ', "_");
        for (what, value, label) in [
            (
                "error",
                (|r: &Row| r.error) as fn(&Row) -> f64,
                "error at the horizon",
            ),
            ("energy", |r: &Row| r.energy_error, "largest energy error"),
        ] {
            study::draw(
                &format!("output/work_precision/{file}_T{horizon}_{what}.png"),
                &format!("{scene} to T = {horizon}: {label} against cost"),
                label,
                &rows,
                value,
            )?;
        }
        Ok(())
    }

    /// The cheapest row of `rows` whose `value` is at most `target`.
    fn cheapest<'r>(
        rows: impl Iterator<Item = &'r Row>,
        value: fn(&Row) -> f64,
        target: f64,
    ) -> Option<&'r Row> {
        rows.filter(|r| value(r) <= target)
            .min_by(|a, b| a.seconds_per_unit_time.total_cmp(&b.seconds_per_unit_time))
    }

    /// Per scene, horizon and target: dirac's cheapest run against the peers' cheapest.
    fn summary(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "| scene | T | target | dirac's cheapest | peers' cheapest | peer cost / dirac cost |"
        );
        let _ = writeln!(out, "|---|---|---|---|---|---|");
        let describe = |r: Option<&Row>| match r {
            Some(r) => format!(
                "{} {} ({:.2} µs per unit t)",
                r.method,
                r.setting,
                r.seconds_per_unit_time * 1e6
            ),
            None => "none meets it".into(),
        };
        let mut seen: Vec<(&str, f64)> = Vec::new();
        for r in &self.rows {
            if seen.contains(&(r.scene, r.horizon)) {
                continue;
            }
            seen.push((r.scene, r.horizon));
            let rows = self.of(r.scene, r.horizon);
            let estimate = self
                .references
                .iter()
                .find(|(s, h, _)| *s == r.scene && *h == r.horizon)
                .map_or(0.0, |x| x.2);
            let mut targets: Vec<Target> = Vec::new();
            for at_most in [1e-4, 1e-8] {
                if at_most >= 10.0 * estimate {
                    targets.push(Target {
                        what: "error",
                        value: |r| r.error,
                        at_most,
                    });
                }
            }
            for at_most in [1e-3, 1e-6, 1e-9] {
                targets.push(Target {
                    what: "|ΔE|",
                    value: |r| r.energy_error,
                    at_most,
                });
            }
            for Target {
                what,
                value,
                at_most: target,
            } in targets
            {
                let dirac =
                    Self::cheapest(rows.iter().copied().filter(|r| r.is_dirac()), value, target);
                let peer = Self::cheapest(
                    rows.iter().copied().filter(|r| !r.is_dirac()),
                    value,
                    target,
                );
                let ratio = match (dirac, peer) {
                    (Some(d), Some(p)) => {
                        format!("{:.2}", p.seconds_per_unit_time / d.seconds_per_unit_time)
                    }
                    (Some(_), None) => "only dirac meets it".into(),
                    (None, Some(_)) => "only a peer meets it".into(),
                    (None, None) => "neither".into(),
                };
                let _ = writeln!(
                    out,
                    "| {} | {} | {} ≤ {target:e} | {} | {} | {ratio} |",
                    r.scene,
                    r.horizon,
                    // A `|` inside a cell would end it.
                    what.replace('|', "\\|"),
                    describe(dirac),
                    describe(peer)
                );
            }
        }
        out
    }

    fn save_csv(&self, path: &str) -> Result<(), String> {
        let io = |e: csv::Error| e.to_string();
        let mut w = csv::Writer::from_path(path).map_err(io)?;
        w.write_record([
            "scene",
            "horizon",
            "method",
            "setting",
            "steps",
            "error",
            "energy_error",
            "violation",
            "handed_over",
            "seconds_per_unit_time",
        ])
        .map_err(io)?;
        for r in &self.rows {
            w.write_record([
                r.scene.to_string(),
                r.horizon.to_string(),
                r.method.clone(),
                r.setting.clone(),
                r.steps.to_string(),
                r.error.to_string(),
                r.energy_error.to_string(),
                r.violation.to_string(),
                r.handed_over.to_string(),
                r.seconds_per_unit_time.to_string(),
            ])
            .map_err(io)?;
        }
        w.flush().map_err(|e| e.to_string())
    }
}

fn main() -> Result<(), String> {
    let horizons = match std::env::args().nth(1) {
        Some(t) => vec![t.parse::<f64>().map_err(|e| format!("a horizon: {e}"))?],
        None => vec![10.0, 1e4],
    };
    std::fs::create_dir_all("output/work_precision").map_err(|e| e.to_string())?;
    if !scenes::peers::Peer::Bdf.is_built() {
        println!("BDF is left out: it is built with `--features scenes/bdf`");
    }
    let only = std::env::args().nth(2).unwrap_or_default();
    let mut runner = Runner {
        horizons,
        only,
        rows: Vec::new(),
        references: Vec::new(),
    };
    study::visit_all(&mut runner)?;
    runner.save_csv("output/work_precision/study.csv")?;
    let summary = runner.summary();
    println!("\n{summary}");
    std::fs::write("output/work_precision/summary.md", summary).map_err(|e| e.to_string())?;
    println!("wrote output/work_precision/study.csv, summary.md and the PNGs");
    Ok(())
}
