//! The step map of step equations that are linear with constant coefficients, read off the
//! step itself.
//!
//! Where `L` is a quadratic polynomial in `(q, v)` on `Rⁿ`, its one-forms are constant and
//! nothing else (forces, holonomic constraints, a coupling) enters a step, the step equations in
//! the chart at `q_k` are `J x + R q_k + P p_k + r₀ = 0` with `J`, `R`, `P`, `r₀` fixed by `h`:
//! the step's unknowns `x` are affine in the state `z = (q_k, p_k)`, and so is everything the
//! step hands on, each linear in `(z, x)`: the increments `q_{k+1} − q_k` and `p_{k+1} − p_k`
//! (after any projection onto hidden constraints, itself linear), the constraints' impulse.
//! Stacked as `y`,
//!
//! ```text
//! y(z) = y₀ + M z,      y₀ = y(0),   M e_i = (y(s_i e_i) − y₀) / s_i   (i = 1..2N)
//! ```
//!
//! read off from `2N + 1` solves of the step with one factorised `J`. A step then costs the
//! product `M z` (`(m + 3N) × 2N` multiply–adds, `m` unknowns) and the compensated sums of the
//! new state, whatever the quadrature's degree: the equations' residual is never assembled.
//!
//! **Round-off.** Each of `M`'s entries carries the round-off of its solve, and a fixed map
//! applies the same error at every step: the energy then drifts by about `ε` a step (measured
//! 3.5e-11 over 10⁶ steps of the LC circuit, where Newton's method stays at 1.5e-14). So the
//! map is read again every 1 024 steps, from probes scaled by `s_i ∈ [1, 2)` that
//! change with every reading: each reading's round-off is then another, and the energy's
//! round-off walks at random over the readings instead of drifting (2.0e-12 after 10⁶ steps of
//! the LC circuit: a walk of about 1 000 readings, each of which drifts for 1 024 steps).
//! A reading costs about `2N + 2` Newton steps, about a tenth of the steps it serves.
//!
//! **Checked at every reading.** That the equations are linear is the model's claim
//! ([`DiracSystem::QUADRATIC`](crate::DiracSystem::QUADRATIC), derived by `#[dirac_system]`
//! from the Lagrangian's expression). Every reading checks it: each probe, solved by an update
//! of `x = 0` and one refinement, must be a root to round-off (the Newton correction left at
//! most 1e-9 of `1 + ‖x‖∞`), and the map must give the solve from the current state to 1e-9 of
//! the outputs' size. A reading that fails stops the run with
//! [`DiracError::InconsistentDerivatives`](crate::DiracError), and so does every later step of
//! the run. Between readings the claim is trusted: a model that wrongly claims to be quadratic
//! can take up to 1 024 wrong steps before a reading stops it.

use nalgebra::{DMatrix, DVector};

use crate::base::float::exceeds;
use crate::solve::jacobian::{Dense, Jacobian};

/// The largest Newton correction at a probe's solution, relative to `1 + ‖x‖∞`, that still
/// counts as a root (a linear solve leaves round-off, about `ε κ(J)`), and the largest gap
/// between the map and a solve, relative to the size of their outputs.
pub(crate) const ROOT_TOLERANCE: f64 = 1e-9;

/// How many steps one reading of the map serves.
pub(crate) const READ_EVERY: u32 = 1024;

/// The stacked outputs `y = y₀ + M z` of a step from the state `z = (q_k, p_k)` (see the module
/// documentation).
#[derive(Debug, Clone)]
pub(crate) struct AffineStep {
    map: DMatrix<f64>,
    offset: DVector<f64>,
    /// `y` of the step being taken (workspace).
    output: DVector<f64>,
    /// Which reading this is (0 for the first of a run): it sets the probes' scales.
    reading: u64,
    /// Steps served since the reading.
    served: u32,
}

impl AffineStep {
    /// Reading `reading` of the map: `probe` solves the step from state `z` (2N entries) and
    /// returns its stacked outputs `y(z)` (or why it cannot); the map is checked against the
    /// solve from `start`. `Err` says why the map cannot be used.
    pub(crate) fn read(
        start: &[f64],
        reading: u64,
        mut probe: impl FnMut(&[f64]) -> Result<DVector<f64>, String>,
    ) -> Result<Self, String> {
        let n = start.len();
        let mut z = vec![0.0; n];
        let offset = probe(&z)?;
        let mut map = DMatrix::zeros(offset.len(), n);
        for i in 0..n {
            let scale = probe_scale(reading * n as u64 + i as u64);
            z[i] = scale;
            let column = (probe(&z)? - &offset) / scale;
            map.set_column(i, &column);
            z[i] = 0.0;
        }
        let mut step = Self {
            output: offset.clone(),
            map,
            offset,
            reading,
            served: 0,
        };
        let solved = probe(start)?;
        // The size of the terms of `y₀ + M z`, whose round-off the gap may hold.
        let size_z = start.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let terms = step.offset.amax() + step.map.amax() * size_z * n as f64;
        let read = step.apply(&start[..n / 2], &start[n / 2..]);
        let size = solved.amax().max(read.amax()).max(terms).max(1.0);
        let miss = (&solved - read).amax();
        if exceeds(miss, ROOT_TOLERANCE * size) {
            return Err(format!(
                "the step read off scaled unit states misses the step from the current state \
                 by {miss:.1e} (of {size:.1e}): the step equations are not linear"
            ));
        }
        Ok(step)
    }

    /// `y` of the step from `(q, p)`: `y₀ + M z`, column by column, the first column writing
    /// over the output (no copy of `y₀` or of the state on the way).
    #[inline]
    pub(crate) fn apply(&mut self, q: &[f64], p: &[f64]) -> &DVector<f64> {
        let rows = self.offset.len();
        let output = self.output.as_mut_slice();
        let mut columns = self
            .map
            .as_slice()
            .chunks_exact(rows)
            .zip(q.iter().chain(p));
        if let Some((column, &z)) = columns.next() {
            for ((y, &y0), &m) in output.iter_mut().zip(self.offset.as_slice()).zip(column) {
                *y = y0 + m * z;
            }
        }
        for (column, &z) in columns {
            for (y, &m) in output.iter_mut().zip(column) {
                *y += m * z;
            }
        }
        &self.output
    }

    /// Counts a step; the number of the next reading where this one has served its steps.
    pub(crate) fn serve(&mut self) -> Option<u64> {
        self.served += 1;
        (self.served >= READ_EVERY).then_some(self.reading + 1)
    }
}

/// The scale of probe `k` of a run, in `[1, 2)`: the fractional parts of `k` times the golden
/// ratio, a sequence that does not repeat, so that each reading rounds differently.
fn probe_scale(k: u64) -> f64 {
    const GOLDEN: f64 = 0.618_033_988_749_894_9;
    1.0 + ((k + 1) as f64 * GOLDEN).fract()
}

/// Whether the Newton correction `correction` at the solution `x` leaves `x` a root (see
/// [`ROOT_TOLERANCE`]).
pub(crate) fn is_root(x: &[f64], correction: &[f64]) -> bool {
    if !x.iter().chain(correction).all(|v| v.is_finite()) {
        return false;
    }
    let size = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let update = correction.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    update <= ROOT_TOLERANCE * (1.0 + size)
}

/// The Newton correction `J⁻¹ r` of a residual by the factorised `jacobian`, in place.
pub(crate) fn correction(jacobian: &Dense, residual: &mut DVector<f64>) {
    jacobian.solve(residual.as_mut_slice());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_affine_map_is_read_off_exactly_and_a_curved_one_refused() {
        let affine = |z: &[f64]| Ok(DVector::from_vec(vec![1.0 + 2.0 * z[0] - z[1], 3.0 * z[1]]));
        let mut step = AffineStep::read(&[0.3, -1.5], 0, affine).unwrap();
        let y = step.apply(&[2.0], &[5.0]).clone();
        assert!((y - DVector::from_vec(vec![0.0, 15.0])).amax() < 1e-14);
        let curved = |z: &[f64]| Ok(DVector::from_vec(vec![z[0] * z[0], z[1]]));
        let refused = AffineStep::read(&[0.3, -1.5], 0, curved).unwrap_err();
        assert!(refused.contains("not linear"), "{refused}");
        // Each reading probes at scales of its own, in [1, 2).
        let probed = |reading| {
            let mut states = Vec::new();
            AffineStep::read(&[0.3, -1.5], reading, |z: &[f64]| {
                states.push(z.to_vec());
                affine(z)
            })
            .unwrap();
            states
        };
        let (first, second) = (probed(0), probed(1));
        assert_eq!(first.len(), 4); // the origin, two unit directions, the start
        for (a, b) in first[1..3].iter().zip(&second[1..3]) {
            let (sa, sb) = (a[0] + a[1], b[0] + b[1]);
            assert!((1.0..2.0).contains(&sa) && (1.0..2.0).contains(&sb));
            assert_ne!(sa, sb);
        }
    }
}
