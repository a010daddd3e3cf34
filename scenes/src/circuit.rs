//! The seed's LC circuit: an inductor in series with C2 and (C1 ∥ C3), currents constrained by
//! Kirchhoff's current law as one-forms; the capacitor charges carry no kinetic energy.
//! The RLC variant is the same circuit interconnected with a resistor and a voltage source on
//! its inductor branch, each a component of its own (`components.rs`); the LC circuit is also
//! built from its two subcircuits joined by KCL.

use dirac::prelude::*;

use super::components::{Capacitor, Inductor, Resistor, Source};
use super::{Report, timed};

/// q = (q_l, q_c1, q_c2, q_c3); L = (l/2) q̇_l² − Σ q_ci² / (2 c_i).
#[dirac_system(
    coordinates(q_l, q_c1, q_c2, q_c3),
    lagrangian = 0.5 * l * dot(q_l).powi(2)
        - q_c1.powi(2) / (2.0 * c1) - q_c2.powi(2) / (2.0 * c2) - q_c3.powi(2) / (2.0 * c3),
    constraints(-dq_l + dq_c2, -dq_c1 + dq_c2 - dq_c3),
)]
#[derive(Debug, Clone, Copy)]
pub struct LcCircuit {
    pub l: f64,
    pub c1: f64,
    pub c2: f64,
    pub c3: f64,
}

pub const LC: LcCircuit = LcCircuit {
    l: 1.0,
    c1: 1.0,
    c2: 1.0,
    c3: 1.0,
};
/// Charge 1 on C2, no current.
pub fn q0() -> SVector<f64, 4> {
    vector![0.0, 0.0, 1.0, 0.0]
}

/// The RLC scene's start: charge 1 on C2, no current (the drive's coordinates at 0).
pub fn rlc_q0() -> SVector<f64, 6> {
    vector![0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
}

/// q(10) of the LC circuit and the inductor current there.
pub const LC_Q10: [f64; 4] = [
    -0.033617333041,
    -0.016808666520,
    0.966382666959,
    -0.016808666520,
];
pub const LC_CURRENT10: f64 = 0.256006793778;
/// q(10) of the RLC circuit (R = 0.5, no source) and its current.
pub const RLC_Q10: [f64; 4] = [
    -0.627019297018,
    -0.313509648509,
    0.372980702982,
    -0.313509648509,
];
pub const RLC_CURRENT10: f64 = 0.037335786163;

/// Closed form of the LC circuit: q_c2(t) = 1/3 + (2/3) cos(√1.5 t).
pub fn lc_q_c2(t: f64) -> f64 {
    1.0 / 3.0 + 2.0 / 3.0 * (1.5f64.sqrt() * t).cos()
}

/// The LC circuit with step `h` to T = 10: the state there.
pub fn lc_at_10(
    quadrature: Quadrature,
    h: f64,
) -> Result<(SVector<f64, 4>, SVector<f64, 4>), DiracError> {
    let mut stepper = Stepper::new(LC, quadrature, h)?;
    stepper.start_from_velocity(q0(), SVector::zeros())?;
    for _ in 0..(10.0 / h).round() as usize {
        stepper.step()?;
    }
    Ok((stepper.q(), stepper.p()))
}

pub fn report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 10.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(LC, quadrature.clone(), h)?;
    stepper.start_from_velocity(q0(), SVector::zeros())?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    trajectory.save_csv(format!(
        "output/lc_circuit_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    let error = (stepper.q() - SVector::from(LC_Q10)).amax();
    Ok(Report {
        scene: "LC circuit",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!(
            "|q(10) − exact| = {error:.2e}, KCL residual ≤ {:.1e}",
            trajectory.max_constraint_violation()
        ),
    })
}

pub fn rlc_report(quadrature: Quadrature) -> Result<Report, DiracError> {
    let (h, t_end) = (0.01, 10.0);
    let name = quadrature.name();
    let mut stepper = Stepper::new(rlc(LC, R)?, quadrature, h)?;
    stepper.start_from_velocity(rlc_q0(), SVector::zeros())?;
    let (trajectory, wall) = timed(&mut stepper, t_end, 1)?;
    trajectory.save_csv(format!(
        "output/rlc_circuit_{}.csv",
        super::oscillator::file_name(&name)
    ))?;
    let error = (stepper.q().fixed_rows::<4>(0) - SVector::from(RLC_Q10)).amax();
    Ok(Report {
        scene: "RLC (LC+R+u)",
        quadrature: name,
        h,
        steps: stepper.steps(),
        max_energy_error: Some(trajectory.max_energy_error()),
        wall,
        check: format!("|q(10) − exact| = {error:.2e} (energy decays through R)"),
    })
}

/// The RLC driven by u(t) = sin(ωt), ω = 2, the input set before every step (at the step's
/// midpoint time). Returns the steady-state current amplitude, the phasor's U/|Z|, and the
/// largest error of the discrete energy balance `E_{k+1} − E_k = (u − R Δq_l/h) Δq_l` (the work
/// of the source and the resistor over the step).
pub fn driven_amplitude(h: f64) -> Result<(f64, f64, f64), DiracError> {
    let omega = 2.0;
    let (c, r) = (&LC, R);
    let inverse_c = 1.0 / c.c2 + 1.0 / (c.c1 + c.c3);
    let reactance = omega * c.l - inverse_c / omega;
    let phasor = 1.0 / (r * r + reactance * reactance).sqrt();
    let mut stepper = Stepper::new(rlc(*c, r)?, Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(rlc_q0(), SVector::zeros())?;
    let (mut peak, mut balance): (f64, f64) = (0.0, 0.0);
    let mut energy = stepper.energy()?;
    let source = stepper.input("drive.source.u")?;
    for k in 0..(80.0 / h).round() as usize {
        let u = (omega * (k as f64 + 0.5) * h).sin();
        stepper.set_input_value(source, u)?;
        let q_l = stepper.q()[0];
        stepper.step()?;
        let dq = stepper.q()[0] - q_l;
        let next = stepper.energy()?;
        balance = balance.max((next - energy - (u - r * dq / h) * dq).abs());
        energy = next;
        if stepper.t() > 70.0 {
            peak = peak.max((stepper.p()[0] / c.l).abs());
        }
    }
    Ok((peak, phasor, balance))
}

pub fn driven_report() -> Result<Report, DiracError> {
    let h = 0.005;
    let start = std::time::Instant::now();
    let (peak, phasor, balance) = driven_amplitude(h)?;
    Ok(Report {
        scene: "driven RLC",
        quadrature: "midpoint".into(),
        h,
        steps: (80.0 / h) as u64,
        max_energy_error: None,
        wall: start.elapsed(),
        check: format!(
            "steady amplitude {peak:.6} vs phasor {phasor:.6}; energy balance to {balance:.1e}"
        ),
    })
}

/// The LC circuit's left subcircuit: the inductor in series with C2.
pub type SeriesLoop = Interconnection<Inductor, Capacitor, 1, 1, 2, 1>;
/// C1 and C3 (a capacitor, or another model of one coordinate), joined only through the rest of
/// the circuit.
pub type CapacitorPair<C3 = Capacitor> = Interconnection<Capacitor, C3, 1, 1, 2, 0>;
/// The LC circuit built from its two subcircuits joined by Kirchhoff's current law.
pub type LcFromSubcircuits<C3 = Capacitor> =
    Interconnection<SeriesLoop, CapacitorPair<C3>, 2, 2, 4, 1>;

/// The loop's junction: the inductor and C2 carry one current.
fn series() -> Junction {
    Junction::new("series").flow("l.q", 1.0).flow("c2.q", -1.0)
}

/// KCL where C2's current splits into C1's and C3's, the loop and the pair included as `loop`
/// and `pair`.
fn kcl() -> Junction {
    Junction::new("kcl")
        .flow("loop.c2.q", 1.0)
        .flow("pair.c1.q", -1.0)
        .flow("pair.c3.q", -1.0)
}

/// The circuit `c` from five components: the loop (inductor and C2 carry one current), the pair
/// (C1, C3), and KCL at the node where C2's current splits into C1's and C3's. Coordinates:
/// `loop.l.q, loop.c2.q, pair.c1.q, pair.c3.q` (the monolithic circuit's `q_l, q_c2, q_c1,
/// q_c3`).
pub fn lc_from_subcircuits(c: &LcCircuit) -> Result<LcFromSubcircuits, DiracError> {
    lc_from_subcircuits_with(c, Capacitor { c: c.c3 })
}

/// [`lc_from_subcircuits`] with `c3` in C3's place (`c.c3` unused).
pub fn lc_from_subcircuits_with<C3: DiracSystem<1>>(
    c: &LcCircuit,
    c3: C3,
) -> Result<LcFromSubcircuits<C3>, DiracError> {
    let series = Interconnection::new(
        ("l", Inductor { l: c.l }),
        ("c2", Capacitor { c: c.c2 }),
        [series()],
    )?;
    let pair = Interconnection::new(("c1", Capacitor { c: c.c1 }), ("c3", c3), [])?;
    Interconnection::new(("loop", series), ("pair", pair), [kcl()])
}

/// The seed's circuit with unequal parallel capacitors (C3 = 2 C1).
pub const UNEQUAL: LcCircuit = LcCircuit {
    l: 1.0,
    c1: 1.0,
    c2: 1.0,
    c3: 2.0,
};

/// A start of [`UNEQUAL`] in the order of [`lc_by_parts`]'s coordinates `(l, c2, c1, c3)`:
/// equal voltages on C1 and C3, and a current 0.5 split 1 : 2 between them.
pub const UNEQUAL_START: ([f64; 4], [f64; 4]) =
    ([0.0, 1.0, 0.2, 0.4], [0.5, 0.5, 0.5 / 3.0, 1.0 / 3.0]);

/// The circuit `c` by parts ([`Modular`]): the loop (`l`, `c2` in series) and the pair (`c1`,
/// `c3`), each a `Modular` of its own, included as `loop` and `pair` and joined by KCL; the
/// coordinates as [`lc_from_subcircuits`]'s. C1 ∥ C3 is a hidden constraint across the
/// components, `q_c1/c1 = q_c3/c3`, held at every step's end.
pub fn lc_by_parts(c: &LcCircuit, h: f64) -> Result<Modular, DiracError> {
    lc_by_parts_with(c, Capacitor { c: c.c3 }, h)
}

/// [`lc_by_parts`] with `c3` in C3's place (`c.c3` unused).
pub fn lc_by_parts_with<C3: DiracSystem<1> + Send + 'static>(
    c: &LcCircuit,
    c3: C3,
    h: f64,
) -> Result<Modular, DiracError> {
    let mut series_loop = Modular::new(Quadrature::midpoint(), h)?;
    series_loop.add("l", Inductor { l: c.l })?;
    series_loop.add("c2", Capacitor { c: c.c2 })?;
    series_loop.join(series())?;
    let mut pair = Modular::new(Quadrature::midpoint(), h)?;
    pair.add("c1", Capacitor { c: c.c1 })?;
    pair.add("c3", c3)?;
    let mut circuit = Modular::new(Quadrature::midpoint(), h)?;
    circuit.include("loop", series_loop)?;
    circuit.include("pair", pair)?;
    circuit.join(kcl())?;
    Ok(circuit)
}

/// The LC circuit's loop, written with the attribute.
#[dirac_system(subsystems(l, c2), junctions(series = l.dq - c2.dq))]
#[derive(Debug, Clone, Copy)]
pub struct Loop {
    pub l: Inductor,
    pub c2: Capacitor,
}

/// C1 and C3, written with the attribute.
#[dirac_system(subsystems(c1, c3))]
#[derive(Debug, Clone, Copy)]
pub struct Pair {
    pub c1: Capacitor,
    pub c3: Capacitor,
}

/// The LC circuit from its subcircuits, written with the attribute (two levels).
#[dirac_system(subsystems(loop_, pair), junctions(kcl = loop_.c2.dq - pair.c1.dq - pair.c3.dq))]
#[derive(Debug, Clone, Copy)]
pub struct LcByAttribute {
    pub loop_: Loop,
    pub pair: Pair,
}

impl LcByAttribute {
    /// The circuit `c` from its parts.
    pub fn of(c: &LcCircuit) -> Self {
        Self {
            loop_: Loop {
                l: Inductor { l: c.l },
                c2: Capacitor { c: c.c2 },
            },
            pair: Pair {
                c1: Capacitor { c: c.c1 },
                c3: Capacitor { c: c.c3 },
            },
        }
    }
}

/// A resistor in series with a voltage source.
pub type Drive = Interconnection<Resistor, Source, 1, 1, 2, 1>;
/// The RLC circuit: the LC circuit with the drive on its inductor branch.
pub type Rlc = Interconnection<LcCircuit, Drive, 4, 2, 6, 1>;

/// The resistance of the RLC scene.
pub const R: f64 = 0.5;

/// The RLC circuit built as the LC circuit plus a resistor plus a source (input
/// `drive.source.u`), the drive carrying the inductor's current. Coordinates: the LC circuit's
/// four, then `drive.r.q` and `drive.source.q`.
pub fn rlc(lc: LcCircuit, r: f64) -> Result<Rlc, DiracError> {
    let drive = Interconnection::new(
        ("r", Resistor { r }),
        ("source", Source),
        [Junction::new("series")
            .flow("r.q", 1.0)
            .flow("source.q", -1.0)],
    )?;
    Interconnection::new(
        ("lc", lc),
        ("drive", drive),
        [Junction::new("branch")
            .flow("lc.q_l", 1.0)
            .flow("drive.r.q", -1.0)],
    )
}

/// The tour's row: the LC circuit from its subcircuits against the monolithic one to T = 10,
/// and its ports read at every step.
pub fn subcircuits_report() -> Result<Report, DiracError> {
    let joined = lc_from_subcircuits(&LC)?;
    let start = vector![0.0, 1.0, 0.0, 0.0];
    // The monolithic circuit's (q_l, q_c1, q_c2, q_c3) are the parts' 0, 2, 1, 3.
    let gap = super::ports::gap_to_whole(joined.clone(), LC, start, [0, 2, 1, 3])?;
    super::ports::report("LC (2 parts)", &joined, start, gap)
}

/// The tour's row: the seed's LC circuit by parts ([`lc_by_parts`], unequal capacitors) against
/// the monolithic circuit from the same subcircuits to T = 10: how far apart they end, the
/// hidden constraint `q_c1/c1 − q_c3/c3` across the components at every step's end, and
/// Tellegen's theorem on the parts' port work.
pub fn by_parts_report() -> Result<Report, DiracError> {
    let c = UNEQUAL;
    let (h, steps) = (0.01, 1000);
    let (q0, v0) = UNEQUAL_START;
    let start = std::time::Instant::now();
    let mut parts = lc_by_parts(&c, h)?;
    parts.start_from_velocity(&q0, &v0)?;
    let mut whole = Stepper::new(lc_from_subcircuits(&c)?, Quadrature::midpoint(), h)?;
    whole.start_from_velocity(SVector::from(q0), SVector::from(v0))?;
    let (mut apart, mut hidden, mut tellegen): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for _ in 0..steps {
        parts.step()?;
        whole.step()?;
        let q = parts.q();
        let gap = (0..4).map(|i| (q[i] - whole.q()[i]).abs());
        apart = gap.fold(apart, f64::max);
        hidden = hidden.max((q[2] / c.c1 - q[3] / c.c3).abs());
        let ports = parts.ports()?;
        tellegen = tellegen.max(ports.net_work().abs() / ports.scale.max(f64::MIN_POSITIVE));
    }
    Ok(Report {
        scene: "LC (C1 ∥ C3 unequal), by parts",
        quadrature: "midpoint".into(),
        h,
        steps,
        max_energy_error: None,
        wall: start.elapsed(),
        check: format!(
            "= monolithic to {apart:.0e}; C1 ∥ C3 across parts held to {hidden:.0e}; Tellegen {tellegen:.0e}"
        ),
    })
}
