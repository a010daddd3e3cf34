//! The RLC circuit written as one struct: the model the interconnection (LC + resistor +
//! source, `scenes/src/circuit.rs`) replaced in the scenes, kept as the reference it must
//! reproduce and as a constrained, driven model whose step map has derivatives.

use dirac::prelude::*;

/// An inductor in series with C2 and (C1 ∥ C3), a resistor and a source `u` on the inductor's
/// branch; KCL as one-forms.
#[dirac_system(
    coordinates(q_l, q_c1, q_c2, q_c3),
    lagrangian = 0.5 * l * dot(q_l).powi(2)
        - q_c1.powi(2) / (2.0 * c1) - q_c2.powi(2) / (2.0 * c2) - q_c3.powi(2) / (2.0 * c3),
    constraints(-dq_l + dq_c2, -dq_c1 + dq_c2 - dq_c3),
    forces((u - r * dot(q_l)) * dq_l),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
pub struct MonolithicRlc {
    pub l: f64,
    pub c1: f64,
    pub c2: f64,
    pub c3: f64,
    pub r: f64,
}
