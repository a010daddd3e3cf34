//! Energy balances component by component: what each component of an interconnection stores,
//! what its own forces and inputs did to it, and what came in through its ports, summed over
//! the steps of a run ([`Stepper::ledger`](crate::Stepper::ledger),
//! [`Modular::ledger`](crate::Modular::ledger)).

use std::fmt;

/// One component's energy balance since the start of a run.
///
/// Over each step the component's energy changes by the work of its own forces and inputs
/// plus the work done on it through its ports (the junctions' constraint forces, see
/// [`StepWork`](crate::StepWork)): `defect` is what this bookkeeping misses, zero to round-off
/// for the midpoint rule on components with quadratic energies, the scheme's energy error
/// otherwise.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ComponentBalance {
    /// The component's instance name.
    pub name: String,
    /// Its energy at the start.
    pub initial: f64,
    /// Its energy now.
    pub energy: f64,
    /// The work of its own forces and inputs since the start (negative: dissipated; positive:
    /// supplied).
    pub forces: f64,
    /// The work done on it through its ports since the start (and by its own constraints,
    /// whose work is zero on the steps that hold them at the constraint point).
    pub ports: f64,
}

impl ComponentBalance {
    /// `E − E_0 − W_forces − W_ports`.
    pub fn defect(&self) -> f64 {
        self.energy - self.initial - self.forces - self.ports
    }
}

/// Every component's energy balance since the stepper's start, printed as a table
/// ([`Stepper::ledger`](crate::Stepper::ledger)).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Ledger {
    /// The components, in the model's order.
    pub components: Vec<ComponentBalance>,
}

impl Ledger {
    /// The net work through all ports, `Σ_c W_ports,c`: zero by Tellegen's theorem (to
    /// round-off where the junctions hold).
    pub fn net_port_work(&self) -> f64 {
        self.components.iter().map(|c| c.ports).sum()
    }

    /// The largest component defect, `max_c |defect_c|`.
    pub fn max_defect(&self) -> f64 {
        self.components
            .iter()
            .fold(0.0, |m, c| m.max(c.defect().abs()))
    }
}

impl fmt::Display for Ledger {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let width = self
            .components
            .iter()
            .map(|c| c.name.chars().count())
            .chain([9])
            .max()
            .unwrap_or(9);
        writeln!(
            f,
            "{:<width$}  {:>13}  {:>13}  {:>13}  {:>13}  {:>13}  {:>8}",
            "component", "energy at 0", "energy now", "stored", "own forces", "ports", "defect"
        )?;
        let row = |f: &mut fmt::Formatter<'_>, name: &str, e0: f64, e: f64, w: f64, p: f64| {
            writeln!(
                f,
                "{name:<width$}  {e0:>13.6e}  {e:>13.6e}  {:>+13.6e}  {w:>+13.6e}  {p:>+13.6e}  {:>8.1e}",
                e - e0,
                e - e0 - w - p
            )
        };
        for c in &self.components {
            row(f, &c.name, c.initial, c.energy, c.forces, c.ports)?;
        }
        let sum = |part: fn(&ComponentBalance) -> f64| self.components.iter().map(part).sum();
        row(
            f,
            "total",
            sum(|c| c.initial),
            sum(|c| c.energy),
            sum(|c| c.forces),
            sum(|c| c.ports),
        )
    }
}
