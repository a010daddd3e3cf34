//! Hidden constraints of the coordinates without kinetic energy, and how they are held at the
//! step's nodes.
//!
//! A coordinate `q_i` without kinetic energy (`∂²L/∂v_i∂v = 0`: a capacitor's charge, a massless
//! port) has an Euler–Lagrange row without acceleration,
//!
//! ```text
//! R_i(q, v, t) + (Cᵀν)_i = 0,    R = ∂L/∂q + F − (∂²L/∂q∂v)ᵀ v,
//! ```
//!
//! where the rows of `C(q)` are the constraint one-forms and the holonomic constraints'
//! differentials, and `ν` their multipliers. Over the degenerate coordinates `D`, the
//! multipliers are eliminated by a basis `W` of the null space of `B = C[:, D]` (the
//! combinations of those rows no constraint force reaches): `Wᵀ R_D = 0`. The combinations of
//! these that contain no velocity (along the velocities the constraints allow) are algebraic
//! constraints on `q`, the hidden constraints `c(q) = 0`; the others are differential equations
//! of first order. Parallel capacitors give `q_c1/c1 − q_c3/c3 = 0`.
//!
//! A variational step imposes the Euler–Lagrange rows at its quadrature nodes, not at the step's
//! end points: the midpoint rule holds `c` at each step's midpoint, and the end points of the
//! degenerate coordinates are then fixed only through `q_{k+1} = 2 q̄ − q_k`. A deviation at a
//! node is reflected from step to step (a parasitic mode of root −1) and round-off accumulates
//! in it. The stepper holds `c(q_{k+1}) = 0` at every node by moving `q_{k+1}` along the free
//! directions `Z = ker B` (the degenerate coordinates' displacements that no constraint sees,
//! exactly the directions the step leaves undetermined at its nodes), by Newton's method on
//! `c(q_{k+1} + Z α) = 0` with the minimal-norm update. On a consistent trajectory the
//! correction is round-off for hidden constraints linear in `q` and of the method's order
//! otherwise; constraints the stepper imposes on `q_{k+1} − q_k` are unchanged where the
//! constraint forms are constant (circuits).
//!
//! The velocity at a node satisfies their velocity form `dc(q) v = 0` besides the constraints
//! (see [`legendre`](crate::model::legendre)). Where the combinations contain velocities (a resistor
//! beside a capacitor), the velocity solves them at the node instead, `Wᵀ R_D(q, v, t) = 0`,
//! with the constraints (models with both kinds among their rows keep the velocity's guess on
//! the degenerate coordinates). Hidden constraints that depend on time explicitly (a
//! force on a degenerate coordinate that depends on `t`) are refused at the start.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};

use crate::base::float::largest;
use crate::discrete::constraint;
use crate::model::derivatives::{Seed, degenerate, degenerate_at, force_jacobian, seeded};
use crate::model::system::DiracSystem;

/// The degenerate coordinates of a model and the number of its hidden constraints, found at the
/// start of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct HiddenConstraints {
    /// Coordinates without kinetic energy.
    dead: Vec<usize>,
    /// Number of algebraic combinations of their rows.
    count: usize,
    /// Number of combinations of their rows that contain velocities (first-order equations).
    dynamic: usize,
    /// The combinations `G` and free directions `W` found at the start, kept while the
    /// constraint forms are constant and the degenerate rows contain no velocity at all
    /// (circuits): then neither changes along the motion, and `dc` is exact.
    fixed: Option<(DMatrix<f64>, DMatrix<f64>)>,
}

/// The hidden constraints at a point: `c(q)`, its differential (rows), the free directions
/// `Z` (columns, in all coordinates), and the size of the terms summed into `c`.
pub(crate) struct Evaluation {
    pub value: DVector<f64>,
    pub differential: DMatrix<f64>,
    free: DMatrix<f64>,
    pub scale: f64,
}

impl Evaluation {
    /// The free directions `Z` (columns, in all coordinates).
    pub fn free(&self) -> &DMatrix<f64> {
        &self.free
    }
}

impl HiddenConstraints {
    /// No degenerate coordinates.
    pub const fn none() -> Self {
        Self {
            dead: Vec::new(),
            count: 0,
            dynamic: 0,
            fixed: None,
        }
    }

    /// The degenerate coordinates at `(q, v)` and the number of hidden constraints among their
    /// rows (velocity dependence is tested at `v` and at a second admissible velocity).
    pub fn find<S: DiracSystem<N>, const N: usize>(
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        inputs: &[f64],
    ) -> Self {
        let dead = degenerate(system, q, v);
        if dead.is_empty() {
            return Self::default();
        }
        let mut found = Self {
            dead,
            count: 0,
            dynamic: 0,
            fixed: None,
        };
        let (g, w, velocity_free) = found.combinations(system, q, v, t, inputs);
        found.count = g.ncols();
        found.dynamic = w.ncols() - g.ncols();
        if velocity_free && constant_forms(system, q) {
            found.fixed = Some((g, w));
        }
        found
    }

    /// Whether these are the degenerate coordinates at `(q, v)` (a run's hidden constraints
    /// serve another state of the same model only where they are).
    pub fn matches<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> bool {
        degenerate_at(system, q, v) == self.dead
    }

    /// The degenerate coordinates at `(q, v)`, their combinations not examined (`count` 0):
    /// enough for [`rows_in_velocity`](Self::rows_in_velocity).
    pub fn rows_of<S: DiracSystem<N>, const N: usize>(
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Self {
        Self {
            dead: degenerate(system, q, v),
            ..Self::none()
        }
    }

    /// The degenerate coordinates.
    pub fn coordinates(&self) -> &[usize] {
        &self.dead
    }

    /// For the velocity solve of degenerate rows that contain velocities: an orthonormal basis
    /// `P` (columns over `D`) of the combinations of those rows the constraint forces reach,
    /// and a basis `W` of those they do not (`W ⟂ P`, together all of `R^D`).
    pub fn reach<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
    ) -> (DMatrix<f64>, DMatrix<f64>) {
        let w = self.unreached(system, q);
        (null_space(&w.transpose()), w)
    }

    /// Their Euler–Lagrange rows without the multipliers, `R_D(q, v, t)`, with its Jacobian in
    /// `v` and the size of the terms summed into them.
    pub fn rows_in_velocity<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        inputs: &[f64],
    ) -> (DVector<f64>, DMatrix<f64>, f64) {
        let (value, by_v, _, scale) = self.rows(system, q, v, t, inputs);
        (value, by_v, scale)
    }

    /// A basis `W` (columns over `D`) of the null space of `B = C[:, D]`: the combinations of
    /// the degenerate rows no constraint force reaches.
    fn unreached<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
    ) -> DMatrix<f64> {
        let forms = Self::forms(system, q);
        let b = DMatrix::from_fn(forms.nrows(), self.dead.len(), |r, c| {
            forms[(r, self.dead[c])]
        });
        null_space(&b)
    }

    /// Number of hidden (algebraic) constraints.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Number of combinations of the degenerate rows that contain velocities.
    pub fn dynamic(&self) -> usize {
        self.dynamic
    }

    /// Whether `c`, its free directions and its differential are those found at the start, and
    /// exact (constant constraint forms, degenerate rows without velocities).
    pub fn is_fixed(&self) -> bool {
        self.fixed.is_some()
    }

    /// The names of the degenerate coordinates.
    pub fn names<S: DiracSystem<N>, const N: usize>(&self, system: &S) -> String {
        let names: Vec<String> = self
            .dead
            .iter()
            .map(|&i| system.coordinate_name(i))
            .collect();
        names.join(", ")
    }

    /// The rows of the constraint forms at `q` (one-forms, then holonomic differentials).
    pub fn forms<S: DiracSystem<N>, const N: usize>(
        system: &S,
        q: &SVector<f64, N>,
    ) -> DMatrix<f64> {
        let rows: Vec<SVector<f64, N>> = (0..S::ONE_FORMS)
            .map(|a| constraint::one_form(system, q, a).0)
            .chain((0..S::HOLONOMIC).map(|b| constraint::holonomic(system, q, b).1))
            .collect();
        DMatrix::from_fn(rows.len(), N, |r, c| rows[r][c])
    }

    /// `R_D` with its Jacobian in `v` (exact) and in `q` (without the third derivatives of `L`,
    /// which cancel in the algebraic combinations), and the size of its terms.
    fn rows<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        inputs: &[f64],
    ) -> (DVector<f64>, DMatrix<f64>, DMatrix<f64>, f64) {
        let qq = seeded(system, q, v, Seed::POSITION, Seed::POSITION);
        let qv = seeded(system, q, v, Seed::POSITION, Seed::VELOCITY).mixed;
        let (mut force, mut force_q, mut force_v) =
            (SVector::zeros(), SMatrix::zeros(), SMatrix::zeros());
        if S::FORCES {
            // The value as `rows_at` takes it (in f64), its Jacobians by dual numbers.
            force = system.force(q, v, t, inputs);
            force_q = force_jacobian(system, q, v, t, inputs, Seed::POSITION).1;
            force_v = force_jacobian(system, q, v, t, inputs, Seed::VELOCITY).1;
        }
        let d = &self.dead;
        let (value, scale) = self.terms(&qq.first, &qv, &force, v);
        let value = DVector::from_iterator(d.len(), value.iter().take(d.len()).copied());
        let by_v = DMatrix::from_fn(d.len(), N, |r, c| {
            qv[(d[r], c)] - qv[(c, d[r])] + force_v[(d[r], c)]
        });
        let by_q = DMatrix::from_fn(d.len(), N, |r, c| qq.mixed[(d[r], c)] + force_q[(d[r], c)]);
        (value, by_v, by_q, scale)
    }

    /// `R_D(q, v, t)` (its first `|D|` entries) and the size of its terms, as
    /// [`rows`](Self::rows) finds them, without their Jacobians: on the stack.
    fn rows_at<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        inputs: &[f64],
    ) -> (SVector<f64, N>, f64) {
        let l = seeded(system, q, v, Seed::POSITION, Seed::VELOCITY);
        let force = if S::FORCES {
            system.force(q, v, t, inputs)
        } else {
            SVector::zeros()
        };
        self.terms(&l.first, &l.mixed, &force, v)
    }

    /// `R_D = ∂L/∂q + F − (∂²L/∂q∂v)ᵀ v` on the degenerate coordinates (its first `|D|`
    /// entries) and the size of its terms.
    fn terms<const N: usize>(
        &self,
        lq: &SVector<f64, N>,
        qv: &SMatrix<f64, N, N>,
        force: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> (SVector<f64, N>, f64) {
        let transport = qv.transpose() * v;
        let mut value = SVector::zeros();
        let mut scale: f64 = 0.0;
        for (r, &i) in self.dead.iter().enumerate() {
            value[r] = lq[i] + force[i] - transport[i];
            scale = scale.max(lq[i].abs().max(force[i].abs()).max(transport[i].abs()));
        }
        (value, scale)
    }

    /// The algebraic combinations `G = W U` of the degenerate rows (columns), the free
    /// directions `W` (columns over `D`) at `(q, v)`, and whether the degenerate rows contain no
    /// velocity at all there.
    fn combinations<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        inputs: &[f64],
    ) -> (DMatrix<f64>, DMatrix<f64>, bool) {
        let forms = Self::forms(system, q);
        let w = self.unreached(system, q);
        let admissible = null_space(&forms);
        // A second admissible velocity: v moved by the sum of the admissible directions.
        let shift = &admissible * DVector::from_element(admissible.ncols(), 1.0);
        let other = v + SVector::<f64, N>::from_fn(|i, _| shift[i] * (1.0 + v.amax()));
        let mut dependence = DMatrix::zeros(w.ncols(), 2 * admissible.ncols());
        let mut velocity_free = true;
        for (k, velocity) in [v, &other].into_iter().enumerate() {
            let by_v = self.rows(system, q, velocity, t, inputs).1;
            velocity_free &= by_v.iter().all(|x| *x == 0.0);
            let j = w.transpose() * by_v * &admissible;
            dependence
                .columns_mut(k * admissible.ncols(), admissible.ncols())
                .copy_from(&j);
        }
        let u = null_space(&dependence.transpose());
        (&w * u, w, velocity_free)
    }

    /// `c(q)` at `(q, v, t)` with its differential and free directions.
    pub fn evaluate<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        inputs: &[f64],
    ) -> Result<Evaluation, String> {
        let computed;
        let (g, w) = match &self.fixed {
            Some((g, w)) if constant_forms(system, q) => (g, w),
            _ => {
                computed = self.combinations(system, q, v, t, inputs);
                (&computed.0, &computed.1)
            }
        };
        if g.ncols() != self.count {
            return Err(format!(
                "the number of hidden constraints of the coordinates without kinetic energy ({}) \
                 changed from {} to {} along the motion",
                self.names(system),
                self.count,
                g.ncols()
            ));
        }
        let (value, _, by_q, scale) = self.rows(system, q, v, t, inputs);
        let mut free = DMatrix::zeros(N, w.ncols());
        for (r, &i) in self.dead.iter().enumerate() {
            free.row_mut(i).copy_from(&w.row(r));
        }
        Ok(Evaluation {
            value: g.transpose() * value,
            differential: g.transpose() * by_q,
            free,
            scale,
        })
    }

    /// Moves `q` along the free directions until `c(q) = 0` to round-off: Newton's method with
    /// the minimal-norm update ([`hold`]). `v`, `t` and the inputs are those of the node.
    pub fn project<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &mut SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        inputs: &[f64],
    ) -> Result<(), String> {
        if self.count == 0 {
            return Ok(());
        }
        hold(&mut Node {
            hidden: self,
            system,
            q,
            v,
            t,
            inputs,
            free: DMatrix::zeros(0, 0),
        })
    }

    /// `max_k |c_k(q)|` and the size of the terms summed into `c`, as [`evaluate`](Self::evaluate)
    /// finds them, where `G` is fixed (else `None`): on the stack, without the differential and
    /// the free directions.
    fn fixed_residual<S: DiracSystem<N>, const N: usize>(
        &self,
        system: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        t: f64,
        inputs: &[f64],
    ) -> Option<(f64, f64)> {
        let (g, _) = self.fixed.as_ref()?;
        if g.ncols() != self.count || !constant_forms(system, q) {
            return None;
        }
        let (value, scale) = self.rows_at(system, q, v, t, inputs);
        // c = Gᵀ R_D, summed over the rows in order as the matrix product sums them.
        let residual = largest(g.column_iter().map(|column| {
            let mut c = 0.0;
            for (r, &x) in column.iter().enumerate() {
                c += x * value[r];
            }
            c
        }));
        Some((residual, scale))
    }
}

/// The Euler–Lagrange rows of the coordinates `dead` without their multipliers, `R_D(q, v, t)`
/// (see the [module](self) documentation), and the size of their terms; with `jacobians`, also
/// their Jacobians in `q` (without the third derivatives of `L`) and in `v` (rows over `dead`,
/// columns over all coordinates; else empty).
pub(crate) fn degenerate_rows<S: DiracSystem<N>, const N: usize>(
    system: &S,
    dead: &[usize],
    (q, v, t): (&SVector<f64, N>, &SVector<f64, N>, f64),
    inputs: &[f64],
    jacobians: bool,
) -> Rows {
    let these = HiddenConstraints {
        dead: dead.to_vec(),
        ..HiddenConstraints::none()
    };
    if jacobians {
        let (value, by_v, by_q, scale) = these.rows(system, q, v, t, inputs);
        Rows {
            value,
            by_q,
            by_v,
            scale,
        }
    } else {
        let (all, scale) = these.rows_at(system, q, v, t, inputs);
        Rows {
            value: DVector::from_iterator(dead.len(), all.iter().take(dead.len()).copied()),
            by_q: DMatrix::zeros(0, 0),
            by_v: DMatrix::zeros(0, 0),
            scale,
        }
    }
}

/// What [`degenerate_rows`] finds.
#[derive(Debug, Clone)]
pub(crate) struct Rows {
    pub value: DVector<f64>,
    pub by_q: DMatrix<f64>,
    pub by_v: DMatrix<f64>,
    pub scale: f64,
}

impl Rows {
    /// No rows, over `columns` coordinates.
    pub(crate) fn empty(columns: usize) -> Self {
        Self {
            value: DVector::zeros(0),
            by_q: DMatrix::zeros(0, columns),
            by_v: DMatrix::zeros(0, columns),
            scale: 0.0,
        }
    }
}

/// Hidden constraints `c(q) = 0` held by moving `q` along free directions `Z`: what [`hold`]
/// reads and moves. A model's own ([`HiddenConstraints::project`]) and an interconnection's
/// across its components (the modular step) are held alike.
pub(crate) trait Projection {
    /// `max_k |c_k(q)|` and the size of the terms summed into `c`, where that costs less than
    /// a [`linearise`](Self::linearise) (else `None`).
    fn residual(&mut self) -> Result<Option<(f64, f64)>, String> {
        Ok(None)
    }
    /// `c(q)`, its differential along the free directions `dc(q) Z` (rows: constraints,
    /// columns: directions) and the size of the terms summed into `c`.
    fn linearise(&mut self) -> Result<(DVector<f64>, DMatrix<f64>, f64), String>;
    /// Moves `q` by `Z α`.
    fn shift(&mut self, alpha: &DVector<f64>);
}

/// Newton's method on `c(q + Z α) = 0` with the minimal-norm update (singular values below
/// `1e-12` of the largest count as zero). It stops on a residual at round-off of its terms or
/// one that no longer halves, and accepts a residual within [`TOLERANCE`] of its terms; `Err`
/// says why not (a residual that is not finite, or too large). The projection is a trait object,
/// so this iteration is compiled once, not once per model.
pub(crate) fn hold(projection: &mut dyn Projection) -> Result<(), String> {
    let mut last = f64::INFINITY;
    let settled = |residual: f64, scale: f64, last: f64| {
        if !residual.is_finite() {
            return Err("a hidden constraint is not finite at the step's end".to_string());
        }
        Ok(residual <= ROUND_OFF * scale || residual >= 0.5 * last)
    };
    for _ in 0..MAX_ITERATIONS {
        // c alone first where that is cheaper: a step that holds c to round-off (a circuit's,
        // whose hidden constraints are linear) is accepted without the differential.
        if let Some((residual, scale)) = projection.residual()?
            && settled(residual, scale, last)?
        {
            return accept(residual, scale);
        }
        let (value, reduced, scale) = projection.linearise()?;
        let residual = largest(value.iter().copied());
        if settled(residual, scale, last)? {
            return accept(residual, scale);
        }
        last = residual;
        // nalgebra's SVD does not return on a matrix with an entry that is not finite.
        if !reduced.iter().all(|x| x.is_finite()) {
            return Err("the hidden constraints' differential is not finite".into());
        }
        let svd = reduced.svd(true, true);
        let cutoff = 1e-12 * svd.singular_values.amax();
        let alpha = svd.solve(&(-&value), cutoff).map_err(|m| m.to_string())?;
        projection.shift(&alpha);
    }
    let (value, _, scale) = projection.linearise()?;
    accept(largest(value.iter().copied()), scale)
}

/// A residual within [`TOLERANCE`] of its terms, or why not.
fn accept(residual: f64, scale: f64) -> Result<(), String> {
    if residual <= TOLERANCE * scale.max(f64::MIN_POSITIVE) {
        Ok(())
    } else {
        Err(format!(
            "the hidden constraints could not be held at the step's end (residual \
             {residual:.3e}, terms of size {scale:.3e})"
        ))
    }
}

/// A model's hidden constraints at a step's end node, held by [`hold`].
struct Node<'a, S: DiracSystem<N>, const N: usize> {
    hidden: &'a HiddenConstraints,
    system: &'a S,
    q: &'a mut SVector<f64, N>,
    v: &'a SVector<f64, N>,
    t: f64,
    inputs: &'a [f64],
    /// The free directions of the last linearisation.
    free: DMatrix<f64>,
}

impl<S: DiracSystem<N>, const N: usize> Projection for Node<'_, S, N> {
    fn residual(&mut self) -> Result<Option<(f64, f64)>, String> {
        Ok(self
            .hidden
            .fixed_residual(self.system, self.q, self.v, self.t, self.inputs))
    }

    fn linearise(&mut self) -> Result<(DVector<f64>, DMatrix<f64>, f64), String> {
        let e = self
            .hidden
            .evaluate(self.system, self.q, self.v, self.t, self.inputs)?;
        let reduced = &e.differential * &e.free;
        self.free = e.free;
        Ok((e.value, reduced, e.scale))
    }

    fn shift(&mut self, alpha: &DVector<f64>) {
        let step = &self.free * alpha;
        *self.q += SVector::<f64, N>::from_fn(|i, _| step[i]);
    }
}

/// Whether the constraint forms are constant at `q` (no holonomic constraint, one-forms with
/// zero derivative).
pub(crate) fn constant_forms<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
) -> bool {
    S::HOLONOMIC == 0
        && (0..S::ONE_FORMS).all(|a| {
            constraint::one_form(system, q, a)
                .1
                .is_none_or(|d| d.iter().all(|x| *x == 0.0))
        })
}

/// Iterations of the projection (a linear hidden constraint needs one).
const MAX_ITERATIONS: usize = 8;
/// A residual this far below its terms is round-off: the projection stops.
const ROUND_OFF: f64 = 16.0 * f64::EPSILON;
/// The largest residual, relative to its terms, a projection may end with.
const TOLERANCE: f64 = 1e-10;

/// An orthonormal basis (columns) of `{x : m x = 0}`, by the singular value decomposition of
/// `m` padded with zero rows to a square matrix: singular values below `1e-10` of the largest
/// count as zero. A matrix with an entry that is not finite (on which nalgebra's SVD does not
/// return) gives `n` columns of NaN, so that whatever is built from them is not finite and is
/// refused there.
pub(crate) fn null_space(m: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.ncols();
    if !m.iter().all(|x| x.is_finite()) {
        return DMatrix::from_element(n, n, f64::NAN);
    }
    if n == 0 || m.nrows() == 0 || m.amax() == 0.0 {
        return DMatrix::identity(n, n);
    }
    let rows = m.nrows().max(n);
    let padded = DMatrix::from_fn(rows, n, |r, c| if r < m.nrows() { m[(r, c)] } else { 0.0 });
    let svd = padded.svd(false, true);
    let v_t = svd.v_t.expect("requested");
    let largest = svd.singular_values.amax();
    let kept: Vec<usize> = (0..n)
        .filter(|&i| svd.singular_values[i] <= 1e-10 * largest)
        .collect();
    DMatrix::from_fn(n, kept.len(), |r, c| v_t[(kept[c], r)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::scalar::Scalar;
    use nalgebra::{dmatrix, vector};

    /// A mass `x` driving two capacitors in series with it and in parallel with each other,
    /// `ȧ + ḃ = ẋ`, one of them nonlinear with energy `(1 + b)^{3/2}`: the hidden constraint
    /// `∂L/∂a = ∂L/∂b`, `a = 1.5 √(1 + b)`, whose row is not finite for `b < −1`.
    struct Parallel;
    impl DiracSystem<3> for Parallel {
        const ONE_FORMS: usize = 1;
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
            v[0] * v[0] * 0.5 - q[1] * q[1] * 0.5 - (q[2] + 1.0).powf(1.5)
        }
        fn one_form<D: Scalar>(&self, _q: &SVector<D, 3>, _a: usize) -> SVector<D, 3> {
            SVector::from([D::from(-1.0), D::from(1.0), D::from(1.0)])
        }
        fn one_form_is_constant(&self, _a: usize) -> bool {
            true
        }
    }

    #[test]
    fn a_hidden_constraint_that_is_not_finite_is_refused_not_accepted() {
        let (q, v) = (vector![0.0, 1.5, 0.0], vector![1.0, 0.5, 0.5]);
        let hidden = HiddenConstraints::find(&Parallel, &q, &v, 0.0, &[]);
        assert_eq!((hidden.coordinates(), hidden.count()), (&[1, 2][..], 1));
        assert!(hidden.is_fixed());
        // On the constraint it is held as it is; off it, q moves onto it.
        let mut on = q;
        hidden.project(&Parallel, &mut on, &v, 0.0, &[]).unwrap();
        assert_eq!(on, q);
        let mut off = vector![0.0, 1.0, 0.0];
        hidden.project(&Parallel, &mut off, &v, 0.0, &[]).unwrap();
        assert!(
            (off[1] - 1.5 * (1.0 + off[2]).sqrt()).abs() < 1e-12,
            "{off:?}"
        );
        assert_eq!(off[0], 0.0);
        // Outside the Lagrangian's domain the constraint is NaN: an error, q as it was.
        let mut outside = vector![0.0, 1.5, -2.0];
        let err = hidden
            .project(&Parallel, &mut outside, &v, 0.0, &[])
            .unwrap_err();
        assert!(err.contains("not finite"), "{err}");
        assert_eq!(outside, vector![0.0, 1.5, -2.0]);
    }

    #[test]
    fn null_space_of_a_rank_one_matrix() {
        let m = dmatrix![1.0, 2.0, 0.0; 2.0, 4.0, 0.0];
        let z = null_space(&m);
        assert_eq!(z.ncols(), 2);
        assert!((&m * &z).amax() < 1e-14);
        assert!((z.transpose() * &z - DMatrix::identity(2, 2)).amax() < 1e-14);
        assert_eq!(null_space(&DMatrix::zeros(0, 3)).ncols(), 3);
        assert_eq!(null_space(&DMatrix::identity(2, 2)).ncols(), 0);
        assert_eq!(null_space(&DMatrix::zeros(2, 0)).ncols(), 0);
        // Not finite in, not finite out (the SVD would not return).
        let z = null_space(&dmatrix![f64::NAN, 1.0, 0.0; 2.0, 4.0, 0.0]);
        assert!(z.ncols() == 3 && z.iter().all(|x| x.is_nan()));
    }
}
