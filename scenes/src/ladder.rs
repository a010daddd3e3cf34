//! Repeated cells closed into rings: an LC ladder (a transmission line of inductors and
//! capacitors) and a chain of masses on springs, each built from components joined by
//! junctions, and their discrete dispersion relation.
//!
//! **The ladder.** Cell `j` holds the inductor carrying the charge `q_l(j)` from node `j` to node
//! `j + 1` and the capacitor `q_c(j)` from node `j + 1` to the ground; KCL at node `j + 1` is the
//! junction `cell[j].dq_l − cell[j].dq_c − cell[j+1].dq_l = 0` (indices modulo `K`). With
//! `q_c(j) = q_l(j) − q_l(j+1)` (the junctions integrated from a consistent start),
//! `l q̈_l(j) = (q_l(j−1) − 2 q_l(j) + q_l(j+1)) / c`: the lattice wave equation, whose travelling
//! waves `cos(κ j − Ω t)`, `κ = 2π m / K`, have `Ω = 2 |sin(κ/2)| / √(l c)`.
//!
//! **The chain.** Cell `j` is a mass `x_j` with a spring to a massless end, joined to the next
//! mass by `cell[j].dend − cell[j+1].dx = 0`: `m ẍ_j = k (x_{j−1} − 2 x_j + x_{j+1})`,
//! `Ω = 2 √(k/m) |sin(κ/2)|`.
//!
//! **The discrete dispersion relation.** Both are linear, and on a linear model the midpoint
//! rule's discrete Euler–Lagrange equations are the implicit midpoint rule on `(q, p)`; on a
//! normal mode of frequency `Ω` it is the Cayley map of `h Ω J`, a rotation of the mode's phase
//! by `θ = 2 atan(h Ω / 2)` per step, exactly. A travelling wave of wave number `κ` therefore
//! moves with the discrete phase speed `c_h = θ / (h κ) = (2 / (h κ)) atan(h Ω / 2)`, which
//! approaches the lattice's `Ω / κ` at second order: `c_h / c − 1 = −(h Ω)² / 12 + O(h⁴)`.

use std::f64::consts::PI;

use dirac::prelude::*;

use super::components::{Capacitor, Inductor, Tethered};

/// The number of cells of both rings.
pub const CELLS: usize = 16;

/// One cell of the ladder: its inductor and its capacitor (joined only to the neighbours).
#[dirac_system(subsystems(l, c))]
#[derive(Debug, Clone, Copy)]
pub struct LadderCell {
    pub l: Inductor,
    pub c: Capacitor,
}

/// The ladder closed into a ring.
pub type Ladder = Repeated<LadderCell, CELLS, 2, { 2 * CELLS }, CELLS>;
/// The chain of masses closed into a ring.
pub type Chain = Repeated<Tethered, CELLS, 2, { 2 * CELLS }, CELLS>;

/// The ladder of `CELLS` cells of inductance `l` and capacitance `c`.
pub fn ladder(l: f64, c: f64) -> Result<Ladder, DiracError> {
    ring(l, c)
}

/// A ladder of `K` cells closed into a ring (`N = 2K` coordinates).
pub fn ring<const K: usize, const N: usize>(
    l: f64,
    c: f64,
) -> Result<Repeated<LadderCell, K, 2, N, K>, DiracError> {
    let kcl = |j: usize| {
        Junction::new(format!("kcl{}", (j + 1) % K))
            .flow(format!("cell[{j}].l.q"), 1.0)
            .flow(format!("cell[{j}].c.q"), -1.0)
            .flow(format!("cell[{}].l.q", (j + 1) % K), -1.0)
    };
    let cell = LadderCell {
        l: Inductor { l },
        c: Capacitor { c },
    };
    Repeated::new("cell", [cell; K], std::array::from_fn(kcl))
}

/// The chain of masses `m` and springs `k`.
pub fn chain(m: f64, k: f64) -> Result<Chain, DiracError> {
    let joint = |j: usize| {
        Junction::new(format!("joint{j}"))
            .flow(format!("cell[{j}].end"), 1.0)
            .flow(format!("cell[{}].x", (j + 1) % CELLS), -1.0)
    };
    Repeated::new(
        "cell",
        [Tethered { m, k }; CELLS],
        std::array::from_fn(joint),
    )
}

/// The chain of `cells` masses `m` and springs `k` as a [`Modular`] interconnection stepped by
/// `quadrature` with step `h`, joined as [`chain`] joins them: closed into a ring, or open, the
/// first mass free and the last spring's end held by a wall (the junction `wall`,
/// `cell[K−1].dend = 0`).
pub fn modular_chain(
    m: f64,
    k: f64,
    cells: usize,
    ring: bool,
    h: f64,
) -> Result<Modular, DiracError> {
    let mut chain = Modular::new(Quadrature::midpoint(), h)?;
    for j in 0..cells {
        chain.add(&format!("cell[{j}]"), Tethered { m, k })?;
    }
    for j in 0..cells {
        let joint = Junction::new(format!("joint{j}")).flow(format!("cell[{j}].end"), 1.0);
        chain.join(match (j + 1 < cells, ring) {
            (true, _) | (false, true) => joint.flow(format!("cell[{}].x", (j + 1) % cells), -1.0),
            (false, false) => Junction::new("wall").flow(format!("cell[{j}].end"), 1.0),
        })?;
    }
    Ok(chain)
}

/// The lattice's angular frequency of wave number `kappa` when `omega0² = 1/(l c)` or `k/m`.
pub fn lattice_frequency(omega0: f64, kappa: f64) -> f64 {
    2.0 * omega0 * (kappa / 2.0).sin().abs()
}

/// The midpoint rule's phase advance per step of size `h` on a mode of frequency `omega`.
pub fn discrete_phase_step(h: f64, omega: f64) -> f64 {
    2.0 * (h * omega / 2.0).atan()
}

/// The travelling wave `a cos(κ j − Ω t)` of mode `m` at `t = 0`, on the cells' first
/// coordinates (the inductors' charges, the masses), its velocity `a Ω sin(κ j)`, and each
/// cell's second coordinate from the junctions (`q_c(j) = q_l(j) − q_l(j+1)`, or
/// `end_j = x_{j+1}`; `sign` −1 or +1 for the two).
fn travelling_wave(
    mode: usize,
    omega: f64,
    amplitude: f64,
    second: impl Fn(f64, f64) -> f64,
) -> (SVector<f64, { 2 * CELLS }>, SVector<f64, { 2 * CELLS }>) {
    let kappa = 2.0 * PI * mode as f64 / CELLS as f64;
    let x = |j: usize| amplitude * (kappa * j as f64).cos();
    let v = |j: usize| amplitude * omega * (kappa * j as f64).sin();
    let mut q = SVector::zeros();
    let mut w = SVector::zeros();
    for j in 0..CELLS {
        let next = (j + 1) % CELLS;
        q[2 * j] = x(j);
        w[2 * j] = v(j);
        q[2 * j + 1] = second(x(j), x(next));
        w[2 * j + 1] = second(v(j), v(next));
    }
    (q, w)
}

/// The ladder's travelling wave of mode `m`.
pub fn ladder_wave(
    mode: usize,
    omega: f64,
) -> (SVector<f64, { 2 * CELLS }>, SVector<f64, { 2 * CELLS }>) {
    travelling_wave(mode, omega, 0.1, |here, next| here - next)
}

/// The chain's travelling wave of mode `m`.
pub fn chain_wave(
    mode: usize,
    omega: f64,
) -> (SVector<f64, { 2 * CELLS }>, SVector<f64, { 2 * CELLS }>) {
    travelling_wave(mode, omega, 0.1, |_, next| next)
}

/// The wave's phase `φ` in `Σ_j x_j e^{iκj} = (K a / 2) e^{iφ}` (the cells' first coordinates)
/// and that sum's modulus.
pub fn phase(mode: usize, q: &SVector<f64, { 2 * CELLS }>) -> (f64, f64) {
    let kappa = 2.0 * PI * mode as f64 / CELLS as f64;
    let (mut re, mut im) = (0.0, 0.0);
    for j in 0..CELLS {
        re += q[2 * j] * (kappa * j as f64).cos();
        im += q[2 * j] * (kappa * j as f64).sin();
    }
    (im.atan2(re), re.hypot(im))
}

/// Steps the wave of mode `m` started at `(q0, v0)` with step `h` for `steps` steps: the mean
/// phase advance per step (unwrapped) and the largest relative change of the wave's amplitude.
pub fn measured_phase_step<S: DiracSystem<{ 2 * CELLS }>>(
    system: S,
    mode: usize,
    (q0, v0): (SVector<f64, { 2 * CELLS }>, SVector<f64, { 2 * CELLS }>),
    h: f64,
    steps: usize,
) -> Result<(f64, f64), DiracError> {
    let mut stepper = Stepper::new(system, Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(q0, v0)?;
    let (mut last, amplitude) = phase(mode, &q0);
    let (mut total, mut drift): (f64, f64) = (0.0, 0.0);
    for _ in 0..steps {
        stepper.step()?;
        let (now, size) = phase(mode, &stepper.q());
        // The phase grows by less than π per step; unwrap it.
        let mut advance = now - last;
        if advance < -PI {
            advance += 2.0 * PI;
        } else if advance > PI {
            advance -= 2.0 * PI;
        }
        total += advance;
        last = now;
        drift = drift.max((size / amplitude - 1.0).abs());
    }
    Ok((total / steps as f64, drift))
}

/// The tour's row: a travelling wave of mode 3 on the ladder, its phase advance per step
/// against the discrete dispersion relation, and its cells' port balance.
pub fn report() -> Result<super::Report, DiracError> {
    let (mode, h, steps) = (3, 0.05, 400);
    let kappa = 2.0 * PI * mode as f64 / CELLS as f64;
    let omega = lattice_frequency(1.0, kappa);
    let start = std::time::Instant::now();
    let (theta, _) =
        measured_phase_step(ladder(1.0, 1.0)?, mode, ladder_wave(mode, omega), h, steps)?;
    let found = super::ports::balance(&ladder(1.0, 1.0)?, ladder_wave(mode, omega), h, steps)?;
    Ok(super::Report {
        scene: "LC ladder (16)",
        quadrature: "midpoint".into(),
        h,
        steps: steps as u64,
        max_energy_error: None,
        wall: start.elapsed(),
        check: format!(
            "phase/step = 2 atan(hΩ/2) to {:.0e}; Tellegen {:.0e}, cells' ΔE = port work to {:.0e}",
            (theta / discrete_phase_step(h, omega) - 1.0).abs(),
            found.tellegen,
            found.energy
        ),
    })
}

/// The tour's row: the ring of 16 tethered masses stepped by parts ([`Modular`]) against the
/// same ring stepped monolithically, a travelling wave of mode 3 over 400 steps: how far apart
/// they end, the wave's phase advance per step against the discrete dispersion relation, and
/// Tellegen's theorem on the parts' port work.
pub fn modular_report() -> Result<super::Report, DiracError> {
    let (m, k, mode, h, steps) = (1.5, 0.6, 3, 0.05, 400);
    let kappa = 2.0 * PI * mode as f64 / CELLS as f64;
    let omega = lattice_frequency((k / m).sqrt(), kappa);
    let (q0, v0) = chain_wave(mode, omega);
    let start = std::time::Instant::now();
    let mut parts = modular_chain(m, k, CELLS, true, h)?;
    parts.start_from_velocity(q0.as_slice(), v0.as_slice())?;
    let mut whole = Stepper::new(chain(m, k)?, Quadrature::midpoint(), h)?;
    whole.start_from_velocity(q0, v0)?;
    let (mut apart, mut tellegen): (f64, f64) = (0.0, 0.0);
    let (mut last, _) = phase(mode, &q0);
    let mut turned = 0.0;
    for _ in 0..steps {
        parts.step()?;
        whole.step()?;
        let q = SVector::<f64, { 2 * CELLS }>::from_column_slice(parts.q().as_slice());
        apart = apart.max((q - whole.q()).amax());
        let ports = parts.ports()?;
        tellegen = tellegen.max(ports.net_work().abs() / ports.scale.max(f64::MIN_POSITIVE));
        let (now, _) = phase(mode, &q);
        turned += (now - last + 3.0 * PI).rem_euclid(2.0 * PI) - PI;
        last = now;
    }
    let per_step = turned / steps as f64;
    Ok(super::Report {
        scene: "mass ring (16), by parts",
        quadrature: "midpoint".into(),
        h,
        steps: steps as u64,
        max_energy_error: None,
        wall: start.elapsed(),
        check: format!(
            "= monolithic to {apart:.0e}; phase/step = 2 atan(hΩ/2) to {:.0e}; Tellegen {tellegen:.0e}",
            (per_step / discrete_phase_step(h, omega) - 1.0).abs(),
        ),
    })
}
