//! The Galerkin step of a separable Lagrangian solved by fixed-point iteration, without a
//! Jacobian.
//!
//! For `L = ½ vᵀ M v + bᵀ v − V(q)` with constant `M` and `b` ([`DiracSystem::SEPARABLE`](crate::DiracSystem::SEPARABLE)) and
//! `g(q) = ∂L/∂q` (plus a force that does not read the velocity, `F(q, t, u)`), the rows
//! `R_j = δ_j0 p_k + ∂L_d/∂Q_j + f_j = 0` (`j = 0..s−1`) of a degree-`s` Galerkin step are
//!
//! ```text
//! δ_j0 (p_k − b) + (1/h) M Σ_m K_jm ξ_m + h Σ_i b_i ℓ_j(c_i) G_i = 0,   K_jm = Σ_i b_i ℓ'_j(c_i) ℓ'_m(c_i),
//! ```
//!
//! with `ξ_m = Q_m − q_k` (`m = 1..s`) and `G_i = g(Y_i) + F(Y_i, t_k + c_i h)` at the positions
//! `Y_i = q_k + Σ_m ℓ_m(c_i) ξ_m` of the rule's nodes (the rule integrates `ℓ'_j` exactly, so
//! `b` enters row 0 alone). `K` (rows `j = 0..s−1`, columns `m = 1..s`) is invertible, so
//!
//! ```text
//! ξ_m = h β_m v_0 + h² Σ_i U_mi M⁻¹ G_i,     Y_l = q_k + h α_l v_0 + h² Σ_i W_li M⁻¹ G_i,
//! ```
//!
//! with `v_0 = M⁻¹ (p_k − b)`, `β_m = −(K⁻¹)_m0`, `U_mi = −Σ_j (K⁻¹)_mj b_i ℓ_j(c_i)`,
//! `α_l = Σ_m ℓ_m(c_l) β_m` and `W_li = Σ_m ℓ_m(c_l) U_mi`. With `s` Gauss nodes this is the
//! `s`-stage Gauss collocation method in Runge–Kutta–Nyström form (`α = c`, `W = A²`). The node
//! positions are iterated, `Y ← q_k + h α v_0 + h² W M⁻¹ G(Y)`: each iteration takes the
//! gradient at the nodes and no Jacobian. It contracts by about `h² ‖W‖ ‖M⁻¹ ∇²V‖` per
//! iteration, so it serves non-stiff models at moderate steps. Started from the stepper's
//! extrapolation of the last steps, it runs until its update is at round-off (a solution to
//! round-off, not to a tolerance: an estimate of the error left from the ratio of the last
//! updates stopped it early, since that ratio misjudges the contraction on the way in), and
//! gives up where its update grows twice running above round-off or after
//! 40 iterations; the stepper then solves that step by Newton's method.
//!
//! The tables carry the round-off of inverting `K` (up to `10⁻¹³` of the increments at degree
//! 8, where the equispaced points make `K` ill-conditioned), which would bias every step alike.
//! So the solution is refined on the rows themselves, assembled as Newton's method assembles
//! them: `ξ ← ξ − h (K⁻¹ ⊗ M⁻¹) R(ξ)`, once where the iteration contracts below `10⁻³`, twice above, and the rows assembled
//! at the last point must be a root to the solver's tolerance. The root is then Newton's to
//! round-off.
//!
//! **Models that are not separable** (a mass matrix `M(q)` that moves with the position, a
//! velocity coupled to the position, forces that read the velocity), unconstrained on `Rⁿ`, are
//! iterated on their assembled rows instead: `ξ ← ξ − h (K⁻¹ ⊗ M̄⁻¹) R(ξ)`, with `M̄ = ∂²L/∂v²`
//! taken once per step at the middle of the predicted step, each iteration one assembly of the
//! rows (a gradient of `L` per node) and no Jacobian. `h (K⁻¹ ⊗ M̄⁻¹)` inverts the rows' part
//! `(1/h) (K ⊗ M̄) ξ`, so the iteration contracts by how far the rest moves with `ξ`: the
//! change of `M` over the step and the velocity in `∂L/∂q` give `O(h |v| |∂M/∂q| / |M|)`, the
//! potential `O(h² |M⁻¹ ∇²V|)`. On the double pendulum at h = 0.02 that is about 0.02 an
//! iteration. The updates are mixed with the last three by Anderson's method (a least-squares
//! combination of the last iterates' differences), and the iteration runs until its update is
//! below an ulp of the largest increment or stops shrinking at round-off, its last correction
//! taken and the rows assembled again there (a stop at `4 ε` of the increments left a bias that
//! drifted the invariants): 7 to 11 iterations a step on the double pendulum at h = 0.01 to
//! 0.05. A second update more than ½ times the first (the plain iteration's contraction from
//! the predictor), or two updates running above round-off that shrink by less, hand the step to
//! Newton's method; a degenerate Lagrangian is handed over for the whole run (`M̄` has no
//! inverse where coordinates carry no kinetic energy of their own), and so is a run whose mass
//! matrix is singular at its start. The solution's rows are checked against the solver's
//! tolerance, as Newton's are.

use nalgebra::{DMatrix, SVector};

use crate::quadrature::Quadrature;
use crate::solve::anderson::Anderson;
use crate::step::verlet::Kinetic;

/// Most iterations of one step before it is handed to Newton's method: at a contraction of
/// ½ an iteration, enough to reach round-off from a predictor off by `10⁻³` of the increments.
pub(crate) const MAX_ITERATIONS: usize = 40;

/// Largest ratio of successive updates above round-off at which the iteration on the rows goes
/// on: the first ratio above it (the plain iteration's, from the predictor), or two running
/// above it, hand the step to Newton's method, which is then the cheaper, and
/// whose own test of its contraction then decides whether the step is trusted. A policy, as
/// Newton's bound is: the mixed updates need not shrink monotonically, so one ratio above it is
/// let pass.
pub(crate) const MAX_ROW_CONTRACTION: f64 = 0.5;

/// Differences of past iterates the iteration on the rows mixes into each update.
pub(crate) const ACCELERATION_DEPTH: usize = 3;

/// Refinements of a solution on the assembled rows (see [`FixedPoint::correct`]) where the
/// iteration contracts by `θ`: each removes all but `θ` of what is left of the tables'
/// round-off (up to 1e-13 of the increments), so one serves below `θ = 10⁻³` and two above (on
/// the oscillator at `ω h = 1.4` the error of `galerkin(8)` falls from 7e-14 with one to 3e-15
/// with two).
pub(crate) fn refinements(theta: f64) -> usize {
    if theta < 1e-3 { 1 } else { 2 }
}

/// The iteration's tables for one quadrature and the run's kinetic terms, with its buffers.
#[derive(Debug, Clone)]
pub(crate) struct FixedPoint<const N: usize> {
    kinetic: Kinetic<N>,
    /// `c_i`.
    nodes: Vec<f64>,
    /// `α_l`.
    alpha: Vec<f64>,
    /// `W_li`, row-major (`r × r`).
    w: Vec<f64>,
    /// `β_m`, `m = 1..s`.
    beta: Vec<f64>,
    /// `U_mi`, row-major (`s × r`).
    u: Vec<f64>,
    /// `ℓ_m(c_l)`, `m = 1..s`, row-major (`r × s`).
    basis: Vec<f64>,
    /// `K⁻¹`, row-major (`s × s`): `h (K⁻¹ ⊗ M⁻¹)` inverts the rows' kinetic part.
    inverse: Vec<f64>,
    /// `Y_l − q_k`.
    offsets: Vec<SVector<f64, N>>,
    /// `M⁻¹ G_i` at the last offsets.
    pulls: Vec<SVector<f64, N>>,
    /// The acceleration of the iteration on the rows, and its `f`, the last correction negated.
    acceleration: Anderson,
    update: Vec<f64>,
}

/// How a solve went: its iterations and the largest ratio of successive updates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Settled {
    pub(crate) iterations: usize,
    pub(crate) contraction: f64,
}

impl<const N: usize> FixedPoint<N> {
    /// The tables of `quadrature` with the run's `kinetic` terms; `None` where `K` is singular
    /// (no Galerkin step has such a `K`: its rows combine, row 0 with the sum of the others,
    /// into the stiffness matrix of the path's polynomials with `ξ_0 = 0`, which is positive
    /// definite).
    pub(crate) fn new(quadrature: &Quadrature, kinetic: Kinetic<N>) -> Option<Self> {
        let (s, nodes, weights) = (
            quadrature.degree(),
            quadrature.nodes().to_vec(),
            quadrature.weights(),
        );
        let r = nodes.len();
        let ell = |i: usize, j: usize| quadrature.basis(i, j).unwrap_or(0.0);
        let dell = |i: usize, j: usize| quadrature.basis_derivative(i, j).unwrap_or(0.0);
        let k = DMatrix::from_fn(s, s, |j, m| {
            (0..r)
                .map(|i| weights[i] * dell(i, j) * dell(i, m + 1))
                .sum::<f64>()
        });
        let inverse = k.try_inverse()?;
        let beta: Vec<f64> = (0..s).map(|m| -inverse[(m, 0)]).collect();
        let mut u = vec![0.0; s * r];
        for m in 0..s {
            for i in 0..r {
                u[m * r + i] = -(0..s)
                    .map(|j| inverse[(m, j)] * weights[i] * ell(i, j))
                    .sum::<f64>();
            }
        }
        let basis: Vec<f64> = (0..r)
            .flat_map(|l| (1..=s).map(move |m| (l, m)))
            .map(|(l, m)| ell(l, m))
            .collect();
        let alpha = (0..r)
            .map(|l| (0..s).map(|m| basis[l * s + m] * beta[m]).sum())
            .collect();
        let mut w = vec![0.0; r * r];
        for l in 0..r {
            for i in 0..r {
                w[l * r + i] = (0..s).map(|m| basis[l * s + m] * u[m * r + i]).sum();
            }
        }
        let all_finite = [&alpha, &w, &beta, &u, &inverse.as_slice().to_vec()]
            .iter()
            .all(|table: &&Vec<f64>| table.iter().all(|x| x.is_finite()));
        all_finite.then(|| Self {
            kinetic,
            nodes,
            alpha,
            w,
            beta,
            u,
            basis,
            inverse: inverse.transpose().as_slice().to_vec(),
            offsets: vec![SVector::zeros(); r],
            pulls: vec![SVector::zeros(); r],
            acceleration: Anderson::new(ACCELERATION_DEPTH),
            update: vec![0.0; s * N],
        })
    }

    /// The correction `h (K⁻¹ ⊗ M⁻¹) R` of the increments for the residual rows `rows(j)`
    /// (`j = 0..s−1`), kept for [`apply`](Self::apply): one step of the iteration on the
    /// assembled rows, which refines the solution of the tables (whose entries carry the
    /// round-off of inverting `K`, up to `10⁻¹³` of the increments at degree 8) towards the
    /// root of the rows. Returns its size.
    pub(crate) fn correct(&mut self, h: f64, rows: impl Fn(usize) -> SVector<f64, N>) -> f64 {
        let s = self.beta.len();
        for (j, row) in self.pulls[..s].iter_mut().enumerate() {
            *row = self.kinetic.inverse_mass_times(&rows(j));
        }
        let mut size: f64 = 0.0;
        for m in 0..s {
            let mut correction = SVector::<f64, N>::zeros();
            for j in 0..s {
                correction += self.pulls[j] * (h * self.inverse[m * s + j]);
            }
            size = size.max(correction.amax());
            self.offsets[m] = correction;
        }
        size
    }

    /// Begins the acceleration of an iteration on the rows afresh (a new step).
    pub(crate) fn restart_acceleration(&mut self) {
        self.acceleration.reset(self.update.len());
    }

    /// The increments `ξ_1, …, ξ_s` (`x`, in order) moved by the last
    /// [`correct`](Self::correct)ion, accelerated by the iteration's history (see
    /// [`anderson`](crate::solve::anderson)).
    pub(crate) fn accelerate(&mut self, x: &mut [f64]) {
        for (f, c) in self.update.iter_mut().zip(
            self.offsets[..self.beta.len()]
                .iter()
                .flat_map(|c| c.iter()),
        ) {
            *f = -c;
        }
        self.acceleration.advance(x, &self.update);
    }

    /// Puts `kinetic` in the place of the run's kinetic terms: the mass matrix of the step
    /// being iterated on its rows.
    pub(crate) fn set_kinetic(&mut self, kinetic: Kinetic<N>) {
        self.kinetic = kinetic;
    }

    /// How much [`correct`](Self::correct) may enlarge the round-off of the rows: `h ‖K⁻¹‖
    /// ‖M⁻¹‖` in the norm of the largest row sum.
    pub(crate) fn correction_gain(&self, h: f64) -> f64 {
        let s = self.beta.len();
        let rows = (0..s)
            .map(|m| {
                self.inverse[m * s..(m + 1) * s]
                    .iter()
                    .map(|x| x.abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max);
        h * rows * self.kinetic.inverse_mass_norm()
    }

    /// Subtracts the last [`correct`](Self::correct)ion from `increments`.
    pub(crate) fn apply(&self, increments: &mut [SVector<f64, N>]) {
        for (xi, correction) in increments.iter_mut().zip(&self.offsets) {
            *xi -= correction;
        }
    }

    /// The size of the momentum terms `M ξ_s / h` of the rows at the step `increments`: with
    /// `p_k`, a floor under the size of the rows' terms.
    pub(crate) fn momentum_size(&self, h: f64, increments: &[SVector<f64, N>]) -> f64 {
        increments
            .last()
            .map_or(0.0, |end| self.kinetic.momentum_times(&(end / h)).amax())
    }

    /// Solves the step from `(q, p)` at time `t` with step `h`, `pull(Y, t)` giving `G`:
    /// `increments` (`ξ_1, …, ξ_s`) holds the start on entry and the solution on return. `Err`
    /// with why where the iteration does not settle (the increments are then unchanged).
    pub(crate) fn solve(
        &mut self,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        t: f64,
        h: f64,
        increments: &mut [SVector<f64, N>],
        mut pull: impl FnMut(&SVector<f64, N>, f64) -> SVector<f64, N>,
    ) -> Result<Settled, String> {
        let (r, s) = (self.nodes.len(), self.beta.len());
        debug_assert_eq!(increments.len(), s);
        let v0 = self.kinetic.velocity(p);
        for (l, offset) in self.offsets.iter_mut().enumerate() {
            *offset = SVector::zeros();
            for (m, xi) in increments.iter().enumerate() {
                *offset += xi * self.basis[l * s + m];
            }
        }
        let h2 = h * h;
        let mut previous: Option<f64> = None;
        let mut grown = false;
        let mut contraction: f64 = 0.0;
        for iteration in 1..=MAX_ITERATIONS {
            for i in 0..r {
                let g = pull(&(q + self.offsets[i]), t + self.nodes[i] * h);
                self.pulls[i] = self.kinetic.inverse_mass_times(&g);
            }
            let (mut update, mut size, mut finite) = (0.0f64, 0.0f64, true);
            for l in 0..r {
                let mut next = v0 * (h * self.alpha[l]);
                for i in 0..r {
                    next += self.pulls[i] * (h2 * self.w[l * r + i]);
                }
                // `max` drops a NaN: finiteness is tested apart.
                finite &= next.iter().all(|x| x.is_finite());
                update = update.max((next - self.offsets[l]).amax());
                size = size.max(next.amax());
                self.offsets[l] = next;
            }
            if !finite {
                return Err(format!(
                    "the fixed-point iteration left the finite numbers at iteration {iteration}"
                ));
            }
            // This update's ratio to the last: the iteration's contraction, as far as it shows.
            let ratio = previous
                .filter(|&before| before > 0.0)
                .map(|before| update / before);
            contraction = contraction.max(ratio.unwrap_or(0.0));
            // The update's round-off: that of the sums (`size`), and the gradients' at `q_k + η`,
            // rounded to `q_k`'s ulps, carried by the iteration's contraction.
            let floor = 4.0 * f64::EPSILON * (size + contraction.min(1.0) * q.amax());
            let grew = previous.is_some_and(|before| update > before);
            if update <= floor || (grew && update <= 64.0 * floor) {
                // The solution: the increments from the pulls that gave the last offsets.
                for (m, xi) in increments.iter_mut().enumerate() {
                    let mut value = v0 * (h * self.beta[m]);
                    for i in 0..r {
                        value += self.pulls[i] * (h2 * self.u[m * r + i]);
                    }
                    *xi = value;
                }
                return Ok(Settled {
                    iterations: iteration,
                    contraction,
                });
            }
            // An update above round-off that grew twice running: the iteration does not contract
            // (the ∞-norm of one update may grow on the way in).
            if grew && grown {
                return Err(format!(
                    "the fixed-point iteration does not contract: its update grew twice running, \
                     to {update:.1e} at iteration {iteration}"
                ));
            }
            grown = grew;
            previous = Some(update);
        }
        Err(format!(
            "the fixed-point iteration did not settle in {MAX_ITERATIONS} iterations (largest \
             ratio of successive updates {contraction:.2})"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::scalar::Scalar;
    use crate::model::system::DiracSystem;

    /// `L = v²/2 − q²/2`.
    struct Oscillator;
    impl DiracSystem<1> for Oscillator {
        const SEPARABLE: bool = true;
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
            (v[0] * v[0] - q[0] * q[0]) * 0.5
        }
    }

    /// With `s` Gauss nodes the tables are the Gauss collocation method's: `α = c`, and
    /// `Σ_i W_li = c_l²/2` from `s = 2` (`W = A²` integrates a constant twice, exactly where
    /// the collocation polynomial's degree reaches 2); the midpoint rule's `W` is `A² = ¼`.
    #[test]
    fn gauss_tables_are_collocation() {
        let kinetic =
            Kinetic::of(&Oscillator, &SVector::<f64, 1>::zeros(), &SVector::zeros()).unwrap();
        for s in 1..=8 {
            let quadrature = Quadrature::galerkin(s).unwrap();
            let tables = FixedPoint::new(&quadrature, kinetic).unwrap();
            for (l, &c) in quadrature.nodes().iter().enumerate() {
                assert!((tables.alpha[l] - c).abs() < 1e-12, "s = {s}");
                let row: f64 = (0..s).map(|i| tables.w[l * s + i]).sum();
                let twice = if s == 1 { 0.25 } else { c * c / 2.0 };
                assert!((row - twice).abs() < 1e-12, "s = {s}: {row}");
            }
        }
    }
}
