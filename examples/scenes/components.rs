//! Components written once: circuit elements and mechanical parts, each an ordinary
//! `#[dirac_system]` model, joined into larger models by
//! [`Interconnection`](dirac::interconnection::Interconnection) (`circuit.rs`, `port.rs`).
//! Each element's coordinate is its charge (electrical) or its position (mechanical); a
//! two-terminal mechanical part has one coordinate per end.

use dirac::prelude::*;

/// An inductor: L = ½ l q̇² (its flux linkage is the momentum).
#[dirac_system(coordinates(q), lagrangian = 0.5 * l * dot(q).powi(2))]
#[derive(Debug, Clone, Copy)]
pub struct Inductor {
    pub l: f64,
}

/// A capacitor: L = −q²/(2c) (no kinetic energy: its charge is a degenerate coordinate).
#[dirac_system(coordinates(q), lagrangian = -q.powi(2) / (2.0 * c))]
#[derive(Debug, Clone, Copy)]
pub struct Capacitor {
    pub c: f64,
}

/// A resistor: no energy, the force −r q̇ dq.
#[dirac_system(coordinates(q), lagrangian = 0.0 * q, forces(-r * dot(q) * dq))]
#[derive(Debug, Clone, Copy)]
pub struct Resistor {
    pub r: f64,
}

/// A voltage source: no energy, the force u dq of its input voltage `u`.
#[dirac_system(coordinates(q), lagrangian = 0.0 * q, forces(u * dq), inputs(u))]
#[derive(Debug, Clone, Copy)]
pub struct Source;

/// A mass on a spring to the ground: L = ½ m ẋ² − ½ k x².
#[dirac_system(coordinates(x), lagrangian = 0.5 * m * dot(x).powi(2) - 0.5 * k * x.powi(2))]
#[derive(Debug, Clone, Copy)]
pub struct MassSpring {
    pub m: f64,
    pub k: f64,
}

/// A mass tethered by a spring whose far end is a free, massless port:
/// L = ½ m ẋ² − ½ k (x − end)².
#[dirac_system(
    coordinates(x, end),
    lagrangian = 0.5 * m * dot(x).powi(2) - 0.5 * k * (x - end).powi(2),
)]
#[derive(Debug, Clone, Copy)]
pub struct Tethered {
    pub m: f64,
    pub k: f64,
}
