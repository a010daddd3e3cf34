//! What crosses the ports of an interconnected model, step by step: Tellegen's theorem and each
//! component's discrete energy balance (the tests and the tour read the same measurement).

use std::time::Instant;

use dirac::prelude::*;

use super::Report;

/// The largest values over a run of the port readings' two identities.
#[derive(Debug, Clone, Copy)]
pub struct Balance {
    /// `|W_A + W_B|` relative to the size of the work's terms (Tellegen: zero to round-off).
    pub tellegen: f64,
    /// `|E_c(k+1) − E_c(k) − W_c|` over the components `c`, relative to the largest of the
    /// components' energies and the work's terms.
    pub energy: f64,
    /// The largest port work on a component over a step (the identities are not vacuous).
    pub largest_work: f64,
}

/// Steps `system` from `(q0, v0)` with the midpoint rule `steps` times, reading the ports.
pub fn balance<S, const N: usize, const K: usize, const C: usize>(
    system: &S,
    (q0, v0): (SVector<f64, N>, SVector<f64, N>),
    h: f64,
    steps: usize,
) -> Result<Balance, DiracError>
where
    S: Interconnected<N, K, C> + Clone,
{
    let mut stepper = Stepper::new(system.clone(), Quadrature::midpoint(), h)?;
    stepper.start_from_velocity(q0, v0)?;
    let mut found = Balance {
        tellegen: 0.0,
        energy: 0.0,
        largest_work: 0.0,
    };
    let mut e = system.energies(&q0, &stepper.v()?);
    for _ in 0..steps {
        let q = stepper.q();
        stepper.step()?;
        let ports = system.ports(&q, &stepper.q(), stepper.multipliers(), h)?;
        found.tellegen = found
            .tellegen
            .max(ports.net_work().abs() / ports.scale.max(f64::MIN_POSITIVE));
        let next = system.energies(&stepper.q(), &stepper.v()?);
        // Relative to the energies in play and the work's terms: the ports move energy between
        // the parts, so a part's balance carries the round-off of the others' (a capacitor's
        // energy passes 0 while the inductor's is large).
        let scale = e
            .iter()
            .chain(&next)
            .fold(ports.scale, |m, x| m.max(x.abs()));
        for c in 0..K {
            found.energy = found
                .energy
                .max((next[c] - e[c] - ports.work[c]).abs() / scale);
            found.largest_work = found.largest_work.max(ports.work[c].abs());
        }
        e = next;
    }
    Ok(found)
}

/// The tour's row: `scene` built from components, started at rest at `q0`, its ports read
/// over `t_end / h` steps; `gap` is its distance to the monolithic model.
pub fn report<S, const N: usize, const K: usize, const C: usize>(
    scene: &'static str,
    system: &S,
    q0: SVector<f64, N>,
    gap: f64,
) -> Result<Report, DiracError>
where
    S: Interconnected<N, K, C> + Clone,
{
    let (h, t_end) = (0.01, 10.0);
    let steps = (t_end / h) as usize;
    let start = Instant::now();
    let found = balance(system, (q0, SVector::zeros()), h, steps)?;
    Ok(Report {
        scene,
        quadrature: "midpoint".into(),
        h,
        steps: steps as u64,
        max_energy_error: None,
        wall: start.elapsed(),
        check: format!(
            "= monolithic to {gap:.0e}; Tellegen {:.0e}, each part's ΔE = port work to {:.0e}",
            found.tellegen, found.energy
        ),
    })
}

/// The largest distance, over the steps to T = 10 (midpoint, h = 0.01, from rest), between the
/// model built from `parts` started at `q0` and the same model written `whole`, its coordinate
/// `i` the parts' coordinate `order[i]`.
pub fn gap_to_whole<P: DiracSystem<N>, W: DiracSystem<N>, const N: usize>(
    parts: P,
    whole: W,
    q0: SVector<f64, N>,
    order: [usize; N],
) -> Result<f64, DiracError> {
    let h = 0.01;
    let mut parts = Stepper::new(parts, Quadrature::midpoint(), h)?;
    let mut whole = Stepper::new(whole, Quadrature::midpoint(), h)?;
    parts.start_from_velocity(q0, SVector::zeros())?;
    whole.start_from_velocity(SVector::from_fn(|i, _| q0[order[i]]), SVector::zeros())?;
    let mut gap: f64 = 0.0;
    for _ in 0..(10.0 / h) as usize {
        parts.step()?;
        whole.step()?;
        let (a, b) = (parts.q(), whole.q());
        gap = (0..N).fold(gap, |gap, i| gap.max((a[order[i]] - b[i]).abs()));
    }
    Ok(gap)
}
