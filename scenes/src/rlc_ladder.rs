//! An RLC ladder built from components and charged by a voltage source, its energy booked
//! component by component.
//!
//! Section `j` is an inductor `l` in series with a resistor `r` from node `j` to node `j + 1`,
//! and a capacitor `c` from node `j + 1` to the ground. The source drives node 0; KCL at node
//! `j + 1` splits the section's current between its capacitor and the next section.
//!
//! **The known answer.** Charging capacitors from a constant voltage `V` through resistors
//! dissipates exactly the energy it stores, whatever the resistors and inductors: at rest again
//! every capacitor holds `c V`, the source has supplied `V · Σ c V = V² Σ c`, the capacitors store
//! `½ V² Σ c`, so the resistors have taken the other half. The midpoint rule books each step's
//! work so that this holds step by step to round-off, and at the discrete rest point exactly.

use dirac::prelude::*;

use super::components::{Capacitor, Inductor, Resistor, Source};

/// One section: the series inductor and resistor carry one current.
#[dirac_system(subsystems(l, r, c), junctions(series = l.dq - r.dq))]
#[derive(Debug, Clone, Copy)]
pub struct Section {
    pub l: Inductor,
    pub r: Resistor,
    pub c: Capacitor,
}

/// Three sections driven by the source `v` (its input `v.u`, the voltage): KCL at node 0 joins
/// the source to the first section, at node `i + 1` each section's current to its capacitor's
/// and the next section's, and the last section's current all goes to its capacitor.
#[dirac_system(
    subsystems(v, s),
    junctions(
        source = v.dq - s[0].l.dq,
        for i in 0..2 { node = s[i].l.dq - s[i].c.dq - s[i + 1].l.dq },
        last = s[2].l.dq - s[2].c.dq,
    ),
)]
#[derive(Debug, Clone, Copy)]
pub struct RlcLadder {
    pub v: Source,
    pub s: [Section; 3],
}

/// The ladder of three equal sections.
pub fn ladder(l: f64, r: f64, c: f64) -> RlcLadder {
    let section = Section {
        l: Inductor { l },
        r: Resistor { r },
        c: Capacitor { c },
    };
    RlcLadder {
        v: Source,
        s: [section; 3],
    }
}

/// The ladder charged from rest by the constant voltage `voltage` to `t_end` with the midpoint
/// rule and step `h`, every `every`-th step saved: the solution and the components' balance.
pub fn charged(
    ladder: RlcLadder,
    voltage: f64,
    h: f64,
    t_end: f64,
    every: usize,
) -> Result<(Solution<10>, dirac::Ledger), DiracError> {
    let mut stepper = Stepper::new(ladder, Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(SVector::zeros(), SVector::zeros())?;
    stepper.set_input("v.u", voltage)?;
    let solution = stepper.solve(Run::until(t_end).every(every))?;
    let ledger = stepper.ledger()?;
    Ok((solution, ledger))
}
