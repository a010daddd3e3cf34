//! Components written once: circuit elements and mechanical parts, each an ordinary
//! `#[dirac_system]` model, joined into larger models by
//! [`dirac::interconnection::Interconnection`] (`circuit.rs`, `port.rs`).
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
#[dirac_system(coordinates(q), forces(-r * dot(q) * dq))]
#[derive(Debug, Clone, Copy)]
pub struct Resistor {
    pub r: f64,
}

/// A voltage source: no energy, the force u dq of its input voltage `u`.
#[dirac_system(coordinates(q), forces(u * dq), inputs(u))]
#[derive(Debug, Clone, Copy)]
pub struct Source;

/// A mass: L = ½ m ẋ² (its momentum is m ẋ).
#[dirac_system(coordinates(x), lagrangian = 0.5 * m * dot(x).powi(2))]
#[derive(Debug, Clone, Copy)]
pub struct Mass {
    pub m: f64,
}

/// A spring, its coordinate its elongation: L = −½ k x² (no kinetic energy, as a capacitor of
/// capacitance 1/k).
#[dirac_system(coordinates(x), lagrangian = -0.5 * k * x.powi(2))]
#[derive(Debug, Clone, Copy)]
pub struct Spring {
    pub k: f64,
}

/// A damper, its coordinate its elongation: no energy, the force −c ẋ dx (as a resistor).
#[dirac_system(coordinates(x), forces(-c * dot(x) * dx))]
#[derive(Debug, Clone, Copy)]
pub struct Damper {
    pub c: f64,
}

/// A flywheel on a shaft, its coordinate its angle: L = ½ i θ̇².
#[dirac_system(coordinates(theta), lagrangian = 0.5 * i * dot(theta).powi(2))]
#[derive(Debug, Clone, Copy)]
pub struct Flywheel {
    pub i: f64,
}

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

/// A DC motor: armature inductance `l` and resistance `r`, rotor inertia `j`, and the gyrator
/// of torque constant `k` between its charge `q` and its rotor angle `theta` (back-EMF
/// `k θ̇` against the current, torque `k q̇` on the rotor), driven by the voltage input `u`.
#[dirac_system(
    coordinates(q, theta),
    lagrangian = 0.5 * l * dot(q).powi(2) + 0.5 * j * dot(theta).powi(2),
    forces((u - r * dot(q) - k * dot(theta)) * dq + k * dot(q) * dtheta),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
pub struct DcMotor {
    pub l: f64,
    pub r: f64,
    pub k: f64,
    pub j: f64,
}

/// A pendulum arm about a horizontal pivot: inertia `inertia` about the pivot and the moment
/// `mgd` of its weight, L = ½ I φ̇² + m g d cos φ (φ = 0 hanging down).
#[dirac_system(
    coordinates(phi),
    lagrangian = 0.5 * inertia * dot(phi).powi(2) + mgd * cos(phi),
)]
#[derive(Debug, Clone, Copy)]
pub struct Arm {
    pub inertia: f64,
    pub mgd: f64,
}

/// A capacitor whose voltage is modulated in time: `L = −q²/2` and the force `cos(t) q`, so the
/// voltage is `q − cos(t) q`. The modulation vanishes at `q = 0`: a test that the time
/// dependence of a hidden constraint is found away from the start.
#[derive(Debug, Clone, Copy)]
pub struct Modulated;

impl DiracSystem<1> for Modulated {
    const FORCES: bool = true;

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, _v: &SVector<D, 1>) -> D {
        -(q[0] * q[0]) * 0.5
    }

    fn force<D: Scalar>(
        &self,
        q: &SVector<D, 1>,
        _v: &SVector<D, 1>,
        t: f64,
        _u: &[D],
    ) -> SVector<D, 1> {
        SVector::from([q[0] * t.cos()])
    }

    fn coordinate_name(&self, _i: usize) -> String {
        "q".into()
    }
}
