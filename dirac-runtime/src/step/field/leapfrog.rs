//! What the explicit steps of fields on a line and on a plane share: the state at the nodes, the
//! composed kick–drift–kick over it, and the checks of a start.
//!
//! A grid with node masses `m_j` and a potential `Φ(u)` is stepped by compositions of
//! Störmer–Verlet: each stage a kick `p += ½ γΔt f`, a drift `u += γΔt p/m` and a kick, where
//! `f = −∂Φ/∂u`. A grid says how it computes `f` ([`Grid::force_and_kick`]); the rest is here.

use nalgebra::SVector;
use rayon::prelude::*;

use crate::base::error::DiracError;
use crate::step::composition::Composition;

/// Nodes per block of a pass, and per parallel task: a pass over this many takes tens of
/// microseconds.
pub(super) const GRAIN: usize = 4096;

/// Blocks a field needs for its passes to be split across threads: with fewer, handing blocks
/// to threads costs more than it gains (measured on 2 cores: 10⁴ nodes in three blocks stepped
/// slower in parallel than on one thread).
pub(super) const PARALLEL_BLOCKS: usize = 4;

/// A field, its momenta and its force at the nodes.
#[derive(Debug, Clone, Default)]
pub(super) struct Level<const C: usize> {
    /// The field at the nodes.
    pub u: Vec<SVector<f64, C>>,
    /// The momenta `m_j u̇_j` of the nodes.
    pub p: Vec<SVector<f64, C>>,
    /// `−∂Φ/∂u_j` at `u`.
    pub force: Vec<SVector<f64, C>>,
}

/// The state of a run, the buffers a step writes into before it is accepted, and the grid's
/// own scratch for its force.
#[derive(Debug, Clone)]
pub(super) struct Running<const C: usize, S> {
    /// The state.
    pub now: Level<C>,
    /// The step being taken.
    pub next: Level<C>,
    /// The grid's buffers for the force.
    pub scratch: S,
    pub steps: u64,
}

/// A grid of nodes whose force an explicit step needs.
pub(super) trait Grid<const C: usize> {
    /// The buffers the force's passes write into, kept over a run.
    type Scratch;

    /// The node masses `m_j` (zero at a node that does not move).
    fn mass(&self) -> &[SVector<f64, C>];

    /// Whether the passes are split across threads.
    fn in_parallel(&self) -> bool;

    /// `f = −∂Φ/∂u` at `u` (zero at a node that does not move), then `p += kick · f`.
    fn force_and_kick(
        &self,
        u: &[SVector<f64, C>],
        f: &mut [SVector<f64, C>],
        p: &mut [SVector<f64, C>],
        scratch: &mut Self::Scratch,
        kick: f64,
    );

    /// `p += kick · f` (where `kick` is not zero) and `u += tau · p/m` at every node that moves:
    /// a kick by the force `f` and the drift that follows it.
    fn kick_and_drift(
        &self,
        u: &mut [SVector<f64, C>],
        p: &mut [SVector<f64, C>],
        f: &[SVector<f64, C>],
        (kick, tau): (f64, f64),
    ) {
        let block = |((u, p), (f, m))| kick_and_drift(u, p, f, m, kick, tau);
        if self.in_parallel() {
            let nodes = u.par_chunks_mut(GRAIN).zip(p.par_chunks_mut(GRAIN));
            let forces = f.par_chunks(GRAIN).zip(self.mass().par_chunks(GRAIN));
            nodes.zip(forces).for_each(block);
        } else {
            block(((u, p), (f, self.mass())));
        }
    }

    /// [`Grid::kick_and_drift`] from the state `from` into `to`'s field and momenta, in one
    /// pass (no copy of `from` first); `to`'s force is left as it was.
    fn kick_and_drift_from(&self, from: &Level<C>, to: &mut Level<C>, (kick, tau): (f64, f64)) {
        let block =
            |((u, p), ((u0, p0), (f, m)))| kick_and_drift_from(u, p, [u0, p0, f, m], kick, tau);
        let (u, p) = (&mut to.u, &mut to.p);
        if self.in_parallel() {
            let nodes = u.par_chunks_mut(GRAIN).zip(p.par_chunks_mut(GRAIN));
            let state = from.u.par_chunks(GRAIN).zip(from.p.par_chunks(GRAIN));
            let forces = from
                .force
                .par_chunks(GRAIN)
                .zip(self.mass().par_chunks(GRAIN));
            nodes.zip(state.zip(forces)).for_each(block);
        } else {
            block(((u, p), ((&from.u, &from.p), (&from.force, self.mass()))));
        }
    }
}

/// The masses `mass(k)` of `count` nodes, held in a vector of exactly that many: `Dimension`
/// where so many cannot be held, else the first error of `mass`.
pub(super) fn node_masses<const C: usize>(
    count: usize,
    mut mass: impl FnMut(usize) -> Result<SVector<f64, C>, DiracError>,
) -> Result<Vec<SVector<f64, C>>, DiracError> {
    let mut masses = Vec::new();
    masses.try_reserve_exact(count).map_err(|_| {
        DiracError::Dimension(format!(
            "a field of {count} nodes: more than memory can hold"
        ))
    })?;
    for k in 0..count {
        masses.push(mass(k)?);
    }
    Ok(masses)
}

/// Checks a start's field `u` and rates `u_t` (one value per node, finite, at rest where the
/// mass is zero) and makes its state: momenta `m u_t` and the force at `u`. Refused with nothing
/// changed: `Dimension`, `NonFinite`, `InconsistentInitialState` (a node held fixed that moves).
pub(super) fn start<G: Grid<C>, const C: usize>(
    grid: &G,
    u: &[SVector<f64, C>],
    ut: &[SVector<f64, C>],
    mut scratch: G::Scratch,
) -> Result<Running<C, G::Scratch>, DiracError> {
    let nodes = grid.mass().len();
    for (what, values) in [("u", u), ("u_t", ut)] {
        if values.len() != nodes {
            return Err(DiracError::Dimension(format!(
                "{what} has {} values, the field has {nodes} nodes",
                values.len()
            )));
        }
        if let Some((j, bad)) = first_not_finite(values) {
            return Err(DiracError::NonFinite {
                what: format!("{what} at node {j}"),
                value: bad,
            });
        }
    }
    let mut fixed = grid.mass().iter().zip(ut).enumerate();
    if let Some((j, (_, rate))) = fixed.find(|(_, (m, v))| is_zero(m) && !is_zero(v)) {
        return Err(DiracError::InconsistentInitialState(format!(
            "node {j} is held fixed, but its u_t is {:?}",
            rate.as_slice()
        )));
    }
    let p = ut.iter().zip(grid.mass()).map(|(v, m)| v.component_mul(m));
    let mut now = Level {
        u: u.to_vec(),
        p: p.collect(),
        force: vec![SVector::zeros(); nodes],
    };
    // The force alone: a kick by nothing.
    grid.force_and_kick(&now.u, &mut now.force, &mut now.p, &mut scratch, 0.0);
    if let Some((j, bad)) = first_not_finite(&now.force) {
        return Err(DiracError::NonFinite {
            what: format!("the force on node {j} of the initial field"),
            value: bad,
        });
    }
    Ok(Running {
        next: now.clone(),
        now,
        scratch,
        steps: 0,
    })
}

/// One step of `composition` with step `dt` from `run.now`; accepted into `run.now` only where
/// every value it reaches is finite, else `NonFinite` and `run.now` as it was.
pub(super) fn advance<G: Grid<C>, const C: usize>(
    grid: &G,
    composition: &Composition,
    dt: f64,
    run: &mut Running<C, G::Scratch>,
) -> Result<(), DiracError> {
    let mut next = std::mem::take(&mut run.next);
    // Each stage a kick, a drift and a kick; a stage's closing kick and the next one's opening
    // kick are one, by the sum of their halves. The first stage's kick and drift read the state
    // and write the step being taken; every force is written before it is read.
    let coefficients = composition.coefficients();
    for (i, &gamma) in coefficients.iter().enumerate() {
        let tau = gamma * dt;
        match i {
            0 => grid.kick_and_drift_from(&run.now, &mut next, (0.5 * tau, tau)),
            _ => grid.kick_and_drift(&mut next.u, &mut next.p, &next.force, (0.0, tau)),
        }
        let later = coefficients.get(i + 1).map_or(0.0, |g| g * dt);
        let Level { u, p, force: f } = &mut next;
        grid.force_and_kick(u, f, p, &mut run.scratch, 0.5 * (tau + later));
    }
    let Level { u, p, force: f } = &next;
    let bad = [("field", u), ("momentum", p), ("force", f)]
        .into_iter()
        .find_map(|(what, values)| first_not_finite(values).map(|(j, v)| (what, j, v)));
    if let Some((what, j, value)) = bad {
        run.next = next;
        return Err(DiracError::NonFinite {
            what: format!(
                "the {what} at node {j} at step {} (try a smaller step)",
                run.steps
            ),
            value,
        });
    }
    run.next = std::mem::replace(&mut run.now, next);
    run.steps += 1;
    Ok(())
}

/// `steps` steps by `advance`, stopping at the first error; where `parallel`, handed out from
/// inside rayon's pool: one hand-off for the run, not one a pass.
pub(super) fn run_steps(
    parallel: bool,
    steps: u64,
    mut advance: impl FnMut() -> Result<(), DiracError> + Send,
) -> Result<(), DiracError> {
    if parallel {
        rayon::scope(|_| (0..steps).try_for_each(|_| advance()))
    } else {
        (0..steps).try_for_each(|_| advance())
    }
}

/// The kinetic energy `Σ_j |p_j|²_{m_j⁻¹}/2` over the nodes that move.
pub(super) fn kinetic<const C: usize>(p: &[SVector<f64, C>], mass: &[SVector<f64, C>]) -> f64 {
    (p.iter().zip(mass))
        .filter(|(_, m)| !is_zero(m))
        .map(|(p, m)| 0.5 * p.component_mul(&p.component_div(m)).sum())
        .sum()
}

/// The rates `p_j / m_j` (zero where the mass is).
pub(super) fn rates<const C: usize>(
    p: &[SVector<f64, C>],
    mass: &[SVector<f64, C>],
) -> Vec<SVector<f64, C>> {
    let rate = |(p, m): (&SVector<f64, C>, &SVector<f64, C>)| match is_zero(m) {
        true => SVector::zeros(),
        false => p.component_div(m),
    };
    p.iter().zip(mass).map(rate).collect()
}

/// The first entry that is not finite, with its node.
pub(super) fn first_not_finite<const C: usize>(values: &[SVector<f64, C>]) -> Option<(usize, f64)> {
    values
        .iter()
        .enumerate()
        .find_map(|(j, v)| v.iter().find(|x| !x.is_finite()).map(|&x| (j, x)))
}

/// `p += kick · f` (where `kick` is not zero) and `u += tau · p/m` at each node that moves.
fn kick_and_drift<const C: usize>(
    u: &mut [SVector<f64, C>],
    p: &mut [SVector<f64, C>],
    f: &[SVector<f64, C>],
    mass: &[SVector<f64, C>],
    kick: f64,
    tau: f64,
) {
    for (((u, p), f), m) in u.iter_mut().zip(p.iter_mut()).zip(f).zip(mass) {
        if kick != 0.0 {
            *p += f * kick;
        }
        if !is_zero(m) {
            *u += p.component_div(m) * tau;
        }
    }
}

/// `p = p0 + kick · f` and `u = u0 + tau · p/m` at each node that moves (`u = u0` elsewhere),
/// from `[u0, p0, f, m]`.
fn kick_and_drift_from<const C: usize>(
    u: &mut [SVector<f64, C>],
    p: &mut [SVector<f64, C>],
    [u0, p0, f, mass]: [&[SVector<f64, C>]; 4],
    kick: f64,
    tau: f64,
) {
    let from = u0.iter().zip(p0).zip(f.iter().zip(mass));
    for ((u, p), ((u0, p0), (f, m))) in u.iter_mut().zip(p.iter_mut()).zip(from) {
        *p = p0 + f * kick;
        *u = match is_zero(m) {
            true => *u0,
            false => u0 + p.component_div(m) * tau,
        };
    }
}

/// Whether every entry of `v` is zero (the mass of a node held fixed).
pub(super) fn is_zero<const C: usize>(v: &SVector<f64, C>) -> bool {
    v.iter().all(|x| *x == 0.0)
}
