//! Derivatives of the model's functions by dual numbers, in one place: the Lagrangian's
//! gradients and second derivatives along seeded directions in `(q, v)` (hyper-dual numbers),
//! first derivatives of position functions (one-forms, holonomic constraints, forces) by
//! first-order duals, and the coordinates without kinetic energy that the mass matrix reveals.
//!
//! The Lagrangian is differentiated either in the model's coordinates or read in a chart of the
//! configuration space ([`InChart`]), through the same [`PhaseFunction`].

use nalgebra::{Const, SMatrix, SVector, U1};
use num_dual::{Derivative, DualSVec64, HyperDualSVec64, HyperHyperDual64};

use crate::base::scalar::Scalar;
use crate::model::closed_form::{LagrangianGradient, LagrangianHessian};
use crate::model::hamiltonian_system::HamiltonianSystem;
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;
use crate::space::configuration_space::{ConfigurationSpace, Point};

/// A function of `(q, v)` over any scalar: the model's Lagrangian, or the Lagrangian in a chart.
pub(crate) trait PhaseFunction<const N: usize> {
    fn value<D: Scalar>(&self, q: &SVector<D, N>, v: &SVector<D, N>) -> D;

    /// The value and gradient in closed form, where known.
    fn closed_gradient(
        &self,
        _q: &SVector<f64, N>,
        _v: &SVector<f64, N>,
    ) -> Option<LagrangianGradient<N>> {
        None
    }

    /// The value, gradient and Hessian in closed form, where known.
    fn closed_hessian(
        &self,
        _q: &SVector<f64, N>,
        _v: &SVector<f64, N>,
    ) -> Option<LagrangianHessian<N>> {
        None
    }
}

impl<S: DiracSystem<N>, const N: usize> PhaseFunction<N> for S {
    #[inline]
    fn value<D: Scalar>(&self, q: &SVector<D, N>, v: &SVector<D, N>) -> D {
        self.lagrangian(q, v)
    }

    #[inline]
    fn closed_gradient(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<LagrangianGradient<N>> {
        self.lagrangian_gradient(q, v)
    }

    #[inline]
    fn closed_hessian(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<LagrangianHessian<N>> {
        self.lagrangian_hessian(q, v)
    }
}

/// A model's Hamiltonian as a function of `(q, p)`: the second slot holds the momentum, so the
/// Lagrangian's derivative machinery gives `∂H/∂q`, `∂H/∂p` and the blocks of `D²H`.
pub(crate) struct Hamiltonian<'a, S>(pub &'a S);

impl<S: HamiltonianSystem<N>, const N: usize> PhaseFunction<N> for Hamiltonian<'_, S> {
    #[inline]
    fn value<D: Scalar>(&self, q: &SVector<D, N>, p: &SVector<D, N>) -> D {
        self.0.hamiltonian(q, p)
    }
}

/// The model's Lagrangian read in the chart centred at `base`: `ℓ(ξ, ξ̇) = L(R(ξ), TR(ξ) ξ̇)`.
/// On a translation chart (`Rⁿ`) its closed-form derivatives are the model's at `base + ξ`.
pub(crate) struct InChart<'a, S, C: ConfigurationSpace<N>, const N: usize> {
    pub system: &'a S,
    pub space: &'a C,
    pub base: &'a Point<C, N, f64>,
}

impl<S: DiracSystem<N, C::Manifold>, C: ConfigurationSpace<N>, const N: usize> PhaseFunction<N>
    for InChart<'_, S, C, N>
{
    #[inline]
    fn value<D: Scalar>(&self, xi: &SVector<D, N>, xi_dot: &SVector<D, N>) -> D {
        let q = self.space.retract(self.base, xi);
        let v = self.space.push_forward(self.base, xi, xi_dot);
        self.system.lagrangian(&q, &v)
    }

    #[inline]
    fn closed_gradient(
        &self,
        xi: &SVector<f64, N>,
        xi_dot: &SVector<f64, N>,
    ) -> Option<LagrangianGradient<N>> {
        if !C::TRANSLATION {
            return None;
        }
        let q = self.space.retract(self.base, xi);
        let v = self.space.push_forward(self.base, xi, xi_dot);
        self.system.lagrangian_gradient(&q, &v)
    }

    #[inline]
    fn closed_hessian(
        &self,
        xi: &SVector<f64, N>,
        xi_dot: &SVector<f64, N>,
    ) -> Option<LagrangianHessian<N>> {
        if !C::TRANSLATION {
            return None;
        }
        let q = self.space.retract(self.base, xi);
        let v = self.space.push_forward(self.base, xi, xi_dot);
        self.system.lagrangian_hessian(&q, &v)
    }
}

/// `D1 L_d` of a step through the moving chart, with what the same passes give besides: for
/// `Λ(η; ξ_1..ξ_s) = h Σ_i b_i ℓ^{R_q(η)}(ζ_i, ζ̇_i)`, the discrete Lagrangian in the chart
/// centred at the moved first point `R_q(η)` with the step's other points held where they are on
/// the manifold (`ζ_j = R_{R_q(η)}⁻¹(R_q(ξ_j))`, `ζ_i` and `ζ̇_i` the path through them at node
/// `i`), `row = ∂Λ/∂η` at `η = 0`.
pub(crate) struct MovingRow<const N: usize> {
    /// `∂Λ/∂η` at `η = 0`: `D1 L_d` read in the chart at `q`.
    pub row: SVector<f64, N>,
    /// `Σ_i |∂Λ_i/∂η|` over the nodes' terms: the size of what `row` sums.
    pub magnitude: SVector<f64, N>,
    /// `∂L_d/∂ξ_m` (`m = 1..=s`) in the chart at `q`, where the mixed derivatives were asked for.
    pub slots: Vec<SVector<f64, N>>,
    /// `∂²Λ/∂η∂ξ_m` (`m = 1..=s`; rows: `η`), where asked for.
    pub blocks: Vec<SMatrix<f64, N, N>>,
}

/// [`MovingRow`] of the model `system` on `space` from `base` with the step's points `points`
/// (`ξ_1..ξ_s` in the chart at `base`): by first-order duals in `η` alone, or, with `mixed`, by
/// one hyper-dual pass per point seeded along `η` and `ξ_m`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn moving_row<S, C, const N: usize>(
    system: &S,
    space: &C,
    base: &Point<C, N, f64>,
    quadrature: &Quadrature,
    h: f64,
    points: &[SVector<f64, N>],
    mixed: bool,
) -> MovingRow<N>
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    let unit = |i: usize| SVector::<f64, N>::from_fn(|r, _| if r == i { 1.0 } else { 0.0 });
    let mut out = MovingRow {
        row: SVector::zeros(),
        magnitude: SVector::zeros(),
        slots: Vec::new(),
        blocks: Vec::new(),
    };
    if !mixed {
        let eta =
            SVector::<Dual<N>, N>::from_fn(|i, _| Dual::<N>::new(0.0, Derivative::some(unit(i))));
        let lifted: Vec<SVector<Dual<N>, N>> =
            points.iter().map(|x| x.map(Dual::<N>::from)).collect();
        // Without a moved start every node is evaluated: `Some` always.
        let _ = moving_action(
            system,
            space,
            base,
            quadrature,
            h,
            &eta,
            &lifted,
            None,
            |term| {
                let g = gradient(&term);
                out.row += g;
                out.magnitude += g.abs();
            },
        );
        return out;
    }
    type H<const N: usize> = HyperDualSVec64<N, N>;
    for m in 0..points.len() {
        let eta = SVector::<H<N>, N>::from_fn(|i, _| {
            H::<N>::new(
                0.0,
                Derivative::some(unit(i)),
                Derivative::none(),
                Derivative::none(),
            )
        });
        let seeded: Vec<SVector<H<N>, N>> = points
            .iter()
            .enumerate()
            .map(|(j, x)| {
                SVector::from_fn(|c, _| {
                    let eps2 = (j == m).then(|| {
                        SMatrix::<f64, 1, N>::from_fn(|_, i| if i == c { 1.0 } else { 0.0 })
                    });
                    H::<N>::new(
                        x[c],
                        Derivative::none(),
                        Derivative::new(eps2),
                        Derivative::none(),
                    )
                })
            })
            .collect();
        let (mut slot, mut block) = (SVector::zeros(), SMatrix::zeros());
        let _ = moving_action(
            system,
            space,
            base,
            quadrature,
            h,
            &eta,
            &seeded,
            None,
            |term| {
                let g = term.eps1.unwrap_generic(Const::<N>, U1);
                if m == 0 {
                    out.row += g;
                    out.magnitude += g.abs();
                }
                slot += term.eps2.unwrap_generic(U1, Const::<N>).transpose();
                block += term.eps1eps2.unwrap_generic(Const::<N>, Const::<N>);
            },
        );
        out.slots.push(slot);
        out.blocks.push(block);
    }
    out
}

/// The second derivatives of a step's action that its step-map derivatives need beyond
/// Newton's Jacobian, for the model `system` on `space` from `base` with the step's points
/// `points` (`ξ_1..ξ_s` in the chart at `base`). With rows `r_0 = ∂Λ/∂η` at `η = 0` (see
/// [`MovingRow`]) and `r_j = ∂L_d/∂ξ_j` (`j = 1..=s`), and the start moved to `R_q(δ)` with the
/// chart carried there by `g(δ)` ([`ConfigurationSpace::carried`]), one hyper-dual pass per
/// block.
pub(crate) struct StartBlocks<const N: usize> {
    /// `∂r_j/∂δ` (`j = 0..=s`; rows: `r_j`'s components).
    pub start: Vec<SMatrix<f64, N, N>>,
    /// `r_s = ∂L_d/∂ξ_s`, the end covector.
    pub end: SVector<f64, N>,
    /// `∂r_s/∂ξ_m` (`m = 1..=s`).
    pub end_blocks: Vec<SMatrix<f64, N, N>>,
}

/// [`StartBlocks`] of a step (`None` where the space's charts are not carried).
pub(crate) fn start_blocks<S, C, const N: usize>(
    system: &S,
    space: &C,
    base: &Point<C, N, f64>,
    quadrature: &Quadrature,
    h: f64,
    points: &[SVector<f64, N>],
) -> Option<StartBlocks<N>>
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    type H<const N: usize> = HyperDualSVec64<N, N>;
    let unit = |i: usize| SVector::<f64, N>::from_fn(|r, _| if r == i { 1.0 } else { 0.0 });
    // A number seeded along component `first` of the first direction and `second` of the second.
    let seeded = |re: f64, first: Option<usize>, second: Option<usize>| {
        H::<N>::new(
            re,
            Derivative::new(first.map(unit)),
            Derivative::new(second.map(|c| unit(c).transpose())),
            Derivative::none(),
        )
    };
    // Row `row` (0: η; j: ξ_j) against `column` (0: δ; m: ξ_m): `(r_row, ∂r_row/∂column)`.
    let pass = |row: usize, column: usize| -> Option<(SVector<f64, N>, SMatrix<f64, N, N>)> {
        let eta = SVector::<H<N>, N>::from_fn(|i, _| seeded(0.0, (row == 0).then_some(i), None));
        let delta = SVector::<H<N>, N>::from_fn(|i, _| seeded(0.0, None, Some(i)));
        let moved: Vec<SVector<H<N>, N>> = points
            .iter()
            .enumerate()
            .map(|(j, x)| {
                SVector::from_fn(|c, _| {
                    seeded(
                        x[c],
                        (row == j + 1).then_some(c),
                        (column == j + 1).then_some(c),
                    )
                })
            })
            .collect();
        let start = (column == 0).then_some(&delta);
        let (mut value, mut block) = (SVector::zeros(), SMatrix::zeros());
        moving_action(
            system,
            space,
            base,
            quadrature,
            h,
            &eta,
            &moved,
            start,
            |term| {
                value += term.eps1.unwrap_generic(Const::<N>, U1);
                block += term.eps1eps2.unwrap_generic(Const::<N>, Const::<N>);
            },
        )?;
        Some((value, block))
    };
    let s = points.len();
    let start = (0..=s)
        .map(|j| pass(j, 0).map(|(_, block)| block))
        .collect::<Option<Vec<_>>>()?;
    let mut end = SVector::zeros();
    let mut end_blocks = Vec::with_capacity(s);
    for m in 1..=s {
        let (value, block) = pass(s, m)?;
        end = value;
        end_blocks.push(block);
    }
    Some(StartBlocks {
        start,
        end,
        end_blocks,
    })
}

/// The terms `h b_i ℓ^{R_q(η)}(ζ_i, ζ̇_i)` of `Λ(η; ξ_1..ξ_s)` (see [`MovingRow`]), handed to
/// `term` node by node; with `start`, of the step whose chart is carried by `g(δ)` to a start
/// at `R_q(δ)` ([`ConfigurationSpace::carried`]: every point and velocity moved by `g(δ)`), and
/// `None` where the space does not carry its charts.
#[allow(clippy::too_many_arguments)]
fn moving_action<S, C, D, const N: usize>(
    system: &S,
    space: &C,
    base: &Point<C, N, f64>,
    quadrature: &Quadrature,
    h: f64,
    eta: &SVector<D, N>,
    points: &[SVector<D, N>],
    start: Option<&SVector<D, N>>,
    mut term: impl FnMut(D),
) -> Option<()>
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
    D: Scalar,
{
    let moved: Vec<SVector<D, N>> = points
        .iter()
        .map(|xi| space.transition(base, eta, xi))
        .collect();
    let zero = D::from(0.0);
    for (i, &b) in quadrature.weights().iter().enumerate() {
        let mut zeta = SVector::<D, N>::from_element(zero);
        let mut rate = SVector::<D, N>::from_element(zero);
        for (j, z) in moved.iter().enumerate() {
            let (a, d) = (quadrature.ell(i, j + 1), quadrature.ell_prime(i, j + 1) / h);
            for k in 0..N {
                zeta[k] += z[k] * a;
                rate[k] += z[k] * d;
            }
        }
        let q = space.retract_moved(base, eta, &zeta);
        let v = space.push_forward_moved(base, eta, &zeta, &rate);
        let value = match start {
            Some(delta) => {
                let (q, v) = space.carried(base, delta, &q, &v)?;
                system.lagrangian(&q, &v)
            }
            None => system.lagrangian(&q, &v),
        };
        term(value * (h * b));
    }
    Some(())
}

/// A direction in `(q, v)`: moving the seeded variable by `δ` moves `q` by `position · δ` and `v`
/// by `velocity · δ`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Seed {
    pub position: f64,
    pub velocity: f64,
}

impl Seed {
    pub const POSITION: Seed = Seed {
        position: 1.0,
        velocity: 0.0,
    };
    pub const VELOCITY: Seed = Seed {
        position: 0.0,
        velocity: 1.0,
    };
    pub const NONE: Seed = Seed {
        position: 0.0,
        velocity: 0.0,
    };
}

/// `L` with its gradients along two seeded directions and the mixed second derivative.
pub(crate) struct Seeded<const N: usize> {
    pub value: f64,
    /// `∂L/∂x` along the first seed.
    pub first: SVector<f64, N>,
    /// `∂L/∂y` along the second seed.
    pub second: SVector<f64, N>,
    /// `∂²L/∂x∂y` (rows: first seed, columns: second seed).
    pub mixed: SMatrix<f64, N, N>,
}

/// `L(q, v)` seeded along `x` and `y`: from the closed forms where the function has them (the
/// gradient alone when `y` is [`Seed::NONE`]), else by hyper-dual numbers.
#[inline]
pub(crate) fn seeded<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
    x: Seed,
    y: Seed,
) -> Seeded<N> {
    // Terms of weight zero are left out, not multiplied by zero: a derivative that is not
    // finite (outside the Lagrangian's domain) must not reach a direction that does not see it.
    let along = |g: &LagrangianGradient<N>, s: Seed| {
        weighted(&g.q, s.position) + weighted(&g.v, s.velocity)
    };
    if y == Seed::NONE
        && let Some(g) = lagrangian.closed_gradient(q, v)
    {
        return Seeded {
            value: g.value,
            first: along(&g, x),
            second: SVector::zeros(),
            mixed: SMatrix::zeros(),
        };
    }
    match lagrangian.closed_hessian(q, v) {
        Some(h) => seeded_from_hessian(&h, x, y),
        None => seeded_by_duals(lagrangian, q, v, x, y),
    }
}

/// [`Seeded`] along `x` and `y` from a closed-form Hessian. Terms of weight zero are left out,
/// not multiplied by zero (see [`seeded`]); where no weight is zero, as at every interior node
/// of a step, the products are plain, without the selects that leaving terms out costs.
#[inline(always)]
fn seeded_from_hessian<const N: usize>(h: &LagrangianHessian<N>, x: Seed, y: Seed) -> Seeded<N> {
    let g = &h.gradient;
    if ![x.position, x.velocity, y.position, y.velocity].contains(&0.0) {
        return seeded_without_zero_weights(h, x, y);
    }
    let along = |s: Seed| weighted(&g.q, s.position) + weighted(&g.v, s.velocity);
    Seeded {
        value: g.value,
        first: along(x),
        second: along(y),
        mixed: weighted(&h.qq, x.position * y.position)
            + weighted(&h.qv, x.position * y.velocity)
            + weighted(&h.qv.transpose(), x.velocity * y.position)
            + weighted(&h.vv, x.velocity * y.velocity),
    }
}

/// [`seeded_from_hessian`] where no weight of `x` and `y` is zero: the plain products.
#[inline(always)]
fn seeded_without_zero_weights<const N: usize>(
    h: &LagrangianHessian<N>,
    x: Seed,
    y: Seed,
) -> Seeded<N> {
    let g = &h.gradient;
    Seeded {
        value: g.value,
        first: g.q * x.position + g.v * x.velocity,
        second: g.q * y.position + g.v * y.velocity,
        mixed: h.qq * (x.position * y.position)
            + h.qv * (x.position * y.velocity)
            + h.qv.transpose() * (x.velocity * y.position)
            + h.vv * (x.velocity * y.velocity),
    }
}

/// `w · m`, or zeros when `w` is zero (whatever `m` holds).
#[inline]
fn weighted<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>, w: f64) -> SMatrix<f64, R, C> {
    if w == 0.0 { SMatrix::zeros() } else { m * w }
}

/// `L(q, v)`, its gradient and its three Hessian blocks `(∂²L/∂q², ∂²L/∂q∂v, ∂²L/∂v²)`: in
/// closed form where known, else by three hyper-dual passes.
#[inline]
pub(crate) fn hessian<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> LagrangianHessian<N> {
    if let Some(h) = lagrangian.closed_hessian(q, v) {
        return h;
    }
    let qv = seeded_by_duals(lagrangian, q, v, Seed::POSITION, Seed::VELOCITY);
    LagrangianHessian {
        gradient: LagrangianGradient {
            value: qv.value,
            q: qv.first,
            v: qv.second,
        },
        qq: seeded_by_duals(lagrangian, q, v, Seed::POSITION, Seed::POSITION).mixed,
        qv: qv.mixed,
        vv: seeded_by_duals(lagrangian, q, v, Seed::VELOCITY, Seed::VELOCITY).mixed,
    }
}

/// `∂²L/∂v²` at `(q, v)`: in closed form where known, else by one hyper-dual pass.
#[inline]
pub(crate) fn velocity_hessian<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> SMatrix<f64, N, N> {
    match lagrangian.closed_hessian(q, v) {
        Some(h) => h.vv,
        None => seeded_by_duals(lagrangian, q, v, Seed::VELOCITY, Seed::VELOCITY).mixed,
    }
}

/// The side of the square blocks in which [`seeded_by_duals`] takes a mixed second derivative
/// of more than this many coordinates.
///
/// One pass over hyper-dual numbers with `N` directions on each side carries `N² + 2N + 1`
/// numbers through every operation of `L`, and past about 300 bytes each operation's
/// temporaries are copied by `memcpy` rather than kept in registers: on the n-link chain the
/// copies were a third of all instructions. Passes over 5 × 5 blocks (36 numbers; `⌈N/5⌉²` of
/// them, those on and above the diagonal where the derivative is symmetric, one row of them
/// for a gradient alone) do on every entry the arithmetic of the single pass, so they give its
/// numbers up to the order in which two cross terms are added in the mirrored blocks (which are
/// then exactly symmetric); and a derivative that is not finite along one coordinate no longer
/// reaches the blocks that do not see that coordinate. Measured on the chain's Lagrangian they
/// take 1.0, 0.50, 0.31, 0.19, 0.16 and 0.13 of the time of the single pass at N = 5, 8, 10,
/// 20, 40 and 64 (blocks of 2, 3, 4 and 6 were slower).
pub(crate) const HESSIAN_BLOCK: usize = 5;

/// Evaluates `L(q, v)` over hyper-dual numbers seeded along `x` and `y`: in one pass up to
/// [`HESSIAN_BLOCK`] coordinates, else block by block.
pub(crate) fn seeded_by_duals<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
    x: Seed,
    y: Seed,
) -> Seeded<N> {
    if N <= HESSIAN_BLOCK {
        by_blocks::<F, N, N>(lagrangian, q, v, x, y)
    } else {
        by_blocks::<F, N, HESSIAN_BLOCK>(lagrangian, q, v, x, y)
    }
}

/// [`seeded_by_duals`] in passes over `S × S` blocks of the mixed derivative: `x` seeded on
/// the `S` coordinates from a block's first row, `y` on those from its first column (none
/// past `N`). Where `x = y` the mixed derivative is symmetric and only the blocks on and
/// above the diagonal are evaluated; a seed without weights ([`Seed::NONE`]) seeds nothing,
/// and one block spans its side.
fn by_blocks<F: PhaseFunction<N>, const N: usize, const S: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
    x: Seed,
    y: Seed,
) -> Seeded<N> {
    type H<const S: usize> = HyperDualSVec64<S, S>;
    let symmetric = x == y;
    let mut out: Seeded<N> = Seeded {
        value: 0.0,
        first: SVector::zeros(),
        second: SVector::zeros(),
        mixed: SMatrix::zeros(),
    };
    let side = |seed: Seed| if seed == Seed::NONE { N } else { S }.max(1);
    for rows in (0..N).step_by(side(x)) {
        let columns_from = if symmetric { rows } else { 0 };
        for columns in (columns_from..N).step_by(side(y)) {
            let unit =
                |from: usize, c: usize, i: usize, w: f64| if from + i == c { w } else { 0.0 };
            let lift = |value: &SVector<f64, N>, wx: f64, wy: f64| {
                SVector::<H<S>, N>::from_fn(|c, _| {
                    let eps1 = if wx == 0.0 || !(rows..rows + S).contains(&c) {
                        Derivative::none()
                    } else {
                        Derivative::some(SVector::<f64, S>::from_fn(|i, _| unit(rows, c, i, wx)))
                    };
                    let eps2 = if wy == 0.0 || !(columns..columns + S).contains(&c) {
                        Derivative::none()
                    } else {
                        Derivative::some(SMatrix::<f64, 1, S>::from_fn(|_, i| {
                            unit(columns, c, i, wy)
                        }))
                    };
                    H::<S>::new(value[c], eps1, eps2, Derivative::none())
                })
            };
            let l = lagrangian.value(
                &lift(q, x.position, y.position),
                &lift(v, x.velocity, y.velocity),
            );
            let (r, c) = (S.min(N - rows), S.min(N - columns));
            out.value = l.re;
            if columns == columns_from {
                let first = l.eps1.unwrap_generic(Const::<S>, U1);
                out.first.rows_mut(rows, r).copy_from(&first.rows(0, r));
            }
            if rows == 0 {
                let second = l.eps2.unwrap_generic(U1, Const::<S>);
                out.second
                    .rows_mut(columns, c)
                    .copy_from(&second.columns(0, c).transpose());
            }
            let mixed = l.eps1eps2.unwrap_generic(Const::<S>, Const::<S>);
            let mixed = mixed.view((0, 0), (r, c));
            out.mixed
                .view_mut((rows, columns), (r, c))
                .copy_from(&mixed);
            if symmetric && columns != rows {
                out.mixed
                    .view_mut((columns, rows), (c, r))
                    .copy_from(&mixed.transpose());
            }
        }
    }
    if symmetric {
        out.second = out.first;
    }
    out
}

/// The Hessian `∂²g_b/∂q²` of holonomic constraint `b` at `q`, by hyper-dual numbers.
pub(crate) fn holonomic_hessian<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    b: usize,
) -> SMatrix<f64, N, N> {
    scalar_hessian(q, |q| system.holonomic(q, b)).2
}

/// A scalar function of `q` with its gradient and Hessian at `q`, by one hyper-dual pass.
pub(crate) fn scalar_hessian<const N: usize>(
    q: &SVector<f64, N>,
    f: impl Fn(&SVector<HyperDualSVec64<N, N>, N>) -> HyperDualSVec64<N, N>,
) -> (f64, SVector<f64, N>, SMatrix<f64, N, N>) {
    type H<const N: usize> = HyperDualSVec64<N, N>;
    let lifted = SVector::<H<N>, N>::from_fn(|c, _| {
        let eps1 = SVector::<f64, N>::from_fn(|i, _| if i == c { 1.0 } else { 0.0 });
        let eps2 = SMatrix::<f64, 1, N>::from_fn(|_, i| if i == c { 1.0 } else { 0.0 });
        H::<N>::new(
            q[c],
            Derivative::some(eps1),
            Derivative::some(eps2),
            Derivative::none(),
        )
    });
    let g = f(&lifted);
    (
        g.re,
        g.eps1.unwrap_generic(Const::<N>, U1),
        g.eps1eps2.unwrap_generic(Const::<N>, Const::<N>),
    )
}

/// `D³L(q, v)` along three directions `(δq, δv)`, by hyper-hyper-dual numbers.
pub(crate) fn third_derivative<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
    directions: [(SVector<f64, N>, SVector<f64, N>); 3],
) -> f64 {
    let [(q1, v1), (q2, v2), (q3, v3)] = directions;
    let lift =
        |x: &SVector<f64, N>, d1: &SVector<f64, N>, d2: &SVector<f64, N>, d3: &SVector<f64, N>| {
            SVector::<HyperHyperDual64, N>::from_fn(|i, _| {
                HyperHyperDual64::new(x[i], d1[i], d2[i], d3[i], 0.0, 0.0, 0.0, 0.0)
            })
        };
    system
        .lagrangian(&lift(q, &q1, &q2, &q3), &lift(v, &v1, &v2, &v3))
        .eps1eps2eps3
}

/// `(∂L/∂q, ∂L/∂v)` at `(q, v)`: two passes of first-order duals, no second derivatives.
pub(crate) fn gradients<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    if let Some(g) = lagrangian.closed_gradient(q, v) {
        return (g.q, g.v);
    }
    let constant = |x: &SVector<f64, N>| x.map(Dual::<N>::from);
    let lq = lagrangian.value(&lift(q, 1.0), &constant(v));
    let lv = lagrangian.value(&constant(q), &lift(v, 1.0));
    (gradient(&lq), gradient(&lv))
}

/// `L(q, v)` and `∂L/∂q` at `(q, v)`: the closed form where the model has one, else one pass of
/// first-order duals.
pub(crate) fn value_and_position_gradient<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> (f64, SVector<f64, N>) {
    if let Some(g) = lagrangian.closed_gradient(q, v) {
        return (g.value, g.q);
    }
    let l = lagrangian.value(&lift(q, 1.0), &v.map(Dual::<N>::from));
    (l.re, gradient(&l))
}

/// The gradient of `L` along `seed` at `(q, v)`: `∂L/∂x_i` where moving `x_i` moves `q_i` by
/// `seed.position` and `v_i` by `seed.velocity` (one pass of first-order duals).
pub(crate) fn directional_gradient<F: PhaseFunction<N>, const N: usize>(
    lagrangian: &F,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
    seed: Seed,
) -> SVector<f64, N> {
    if let Some(g) = lagrangian.closed_gradient(q, v) {
        return weighted(&g.q, seed.position) + weighted(&g.v, seed.velocity);
    }
    gradient(&lagrangian.value(&lift(q, seed.position), &lift(v, seed.velocity)))
}

/// First-order dual numbers with `N` directions.
pub(crate) type Dual<const N: usize> = DualSVec64<N>;

/// `x` as first-order duals whose component `i` moves with `weight` along direction `i`:
/// functions of it return their value and their derivative along `weight · δx`.
pub(crate) fn lift<const N: usize>(x: &SVector<f64, N>, weight: f64) -> SVector<Dual<N>, N> {
    SVector::from_fn(|i, _| {
        let eps = SVector::<f64, N>::from_fn(|j, _| if i == j { weight } else { 0.0 });
        Dual::<N>::new(x[i], Derivative::some(eps))
    })
}

pub(crate) fn gradient<const N: usize>(x: &Dual<N>) -> SVector<f64, N> {
    x.eps.unwrap_generic(Const::<N>, U1)
}

/// `f(x)` and its Jacobian `∂f/∂x` at `x`, by one pass of first-order duals.
pub(crate) fn jacobian<const N: usize>(
    x: &SVector<f64, N>,
    f: impl FnOnce(&SVector<Dual<N>, N>) -> SVector<Dual<N>, N>,
) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
    let y = f(&lift(x, 1.0));
    (
        y.map(|y| y.re),
        SMatrix::from_fn(|r, c| y[r].eps.unwrap_generic(Const::<N>, U1)[c]),
    )
}

/// Coordinates whose rows of `∂²L/∂v²` vanish at `(q, v)` (one probe: enough to check that a
/// known classification holds at a state; [`degenerate`] classifies).
pub(crate) fn degenerate_at<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> Vec<usize> {
    // Dual numbers, whose zeros are structural, as they are for any model.
    let vv = seeded_by_duals(system, q, v, Seed::VELOCITY, Seed::VELOCITY).mixed;
    (0..N)
        .filter(|&i| vv.row(i).iter().all(|x| *x == 0.0))
        .collect()
}

/// How far [`moved`] takes a position and a velocity to a second probe of a property claimed
/// everywhere.
pub(crate) const POSITION_SHIFT: f64 = 0.0137;
pub(crate) const VELOCITY_SHIFT: f64 = 0.291;

/// `x` moved by uneven amounts, `shift (1 + i/10)(1 + |x_i|)` in coordinate `i`: a second
/// probe of a property a term could hold at one state by accident (`ẏ⁴` vanishes at `ẏ = 0`).
pub(crate) fn moved<const N: usize>(x: &SVector<f64, N>, shift: f64) -> SVector<f64, N> {
    SVector::from_fn(|i, _| x[i] + shift * (1.0 + 0.1 * i as f64) * (1.0 + x[i].abs()))
}

/// Coordinates with no kinetic term: rows of `∂²L/∂v²` that vanish at `(q, v)` and at a second
/// state near it (none where neither can be evaluated).
pub(crate) fn degenerate<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> Vec<usize> {
    // Probed at (q, v) and at a point moved by uneven amounts: a kinetic term can vanish at one
    // state (ẏ⁴ at ẏ = 0). A probe outside the Lagrangian's domain (not finite) is skipped.
    let probes = [
        (*q, *v),
        (moved(q, POSITION_SHIFT), moved(v, VELOCITY_SHIFT)),
    ];
    let hessians: Vec<_> = probes
        .iter()
        .map(|(q, v)| seeded_by_duals(system, q, v, Seed::VELOCITY, Seed::VELOCITY).mixed)
        .filter(|vv| vv.iter().all(|x| x.is_finite()))
        .collect();
    if hessians.is_empty() {
        return Vec::new();
    }
    (0..N)
        .filter(|&i| {
            hessians
                .iter()
                .all(|vv| vv.row(i).iter().all(|x| *x == 0.0))
        })
        .collect()
}

/// The force `F(q, v, t, u)` with its Jacobians `∂F/∂q` and `∂F/∂v` at one point, by dual
/// numbers (`x` moves `q` by `position · δ` and `v` by `velocity · δ`).
pub(crate) fn force_jacobian<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
    t: f64,
    inputs: &[f64],
    x: Seed,
) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
    let inputs: Vec<Dual<N>> = inputs.iter().map(|&u| Dual::from(u)).collect();
    let f = system.force(&lift(q, x.position), &lift(v, x.velocity), t, &inputs);
    (
        f.map(|x| x.re),
        SMatrix::from_fn(|r, c| f[r].eps.unwrap_generic(Const::<N>, U1)[c]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::scalar::Scalar;

    /// `L = ẋ²/2 + ẏ⁴/4 − z²/2`: y has kinetic energy though `∂²L/∂ẏ² = 3ẏ²` vanishes at ẏ = 0;
    /// z has none anywhere.
    struct Quartic;
    impl DiracSystem<3> for Quartic {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
            v[0] * v[0] * 0.5 + v[1].powi(4) * 0.25 - q[2] * q[2] * 0.5
        }
    }

    #[test]
    fn a_kinetic_term_that_vanishes_at_the_start_is_not_degenerate() {
        let q = SVector::<f64, 3>::from([0.0, 1.0, 0.5]);
        assert_eq!(
            degenerate(&Quartic, &q, &SVector::<f64, 3>::from([1.0, 0.0, 0.0])),
            vec![2]
        );
        assert_eq!(
            degenerate(&Quartic, &q, &SVector::<f64, 3>::from([1.0, 2.0, 0.0])),
            vec![2]
        );
    }

    /// `L = ½ vᵀAv + qᵀBv + ½ qᵀCq + Σ_j (sin(q_j) v_j + ½ v_j² cos q_j) + Σ_j sin(q_j) cos(q_{j+1})`
    /// on 12 coordinates (more than two Hessian blocks, the last one partial), with all three
    /// second-derivative blocks full and products of factors that both have second derivatives.
    struct Coupled;
    const M: usize = 12;
    fn entry(i: usize, j: usize, k: f64) -> f64 {
        ((i * 7 + j * 3) as f64 * k).sin()
    }
    fn a(i: usize, j: usize) -> f64 {
        entry(i.min(j), i.max(j), 0.37) + if i == j { 3.0 } else { 0.0 }
    }
    fn b(i: usize, j: usize) -> f64 {
        entry(i, j, 0.91)
    }
    fn c(i: usize, j: usize) -> f64 {
        entry(i.min(j), i.max(j), 1.3)
    }
    impl DiracSystem<M> for Coupled {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, M>, v: &SVector<D, M>) -> D {
            let mut l = D::from(0.0);
            for i in 0..M {
                l += q[i].sin() * v[i] + v[i] * v[i] * q[i].cos() * 0.5;
                if i + 1 < M {
                    l += q[i].sin() * q[i + 1].cos();
                }
                for j in 0..M {
                    l += v[i] * v[j] * (0.5 * a(i, j)) + q[i] * v[j] * b(i, j);
                    l += q[i] * q[j] * (0.5 * c(i, j));
                }
            }
            l
        }
    }

    #[test]
    fn hessian_blocks_match_the_closed_form_and_the_single_pass() {
        let q = SVector::<f64, M>::from_fn(|i, _| 0.3 * i as f64 - 1.0);
        let v = SVector::<f64, M>::from_fn(|i, _| 0.7 - 0.2 * i as f64);
        // ∂L/∂q, ∂L/∂v and the blocks qq, qv (rows q, columns v), vv.
        let (s, co) = (q.map(f64::sin), q.map(f64::cos));
        // The chain term Σ sin(q_j) cos(q_{j+1}): its gradient and Hessian.
        let chain = |i: usize| {
            let ahead = if i + 1 < M { co[i] * co[i + 1] } else { 0.0 };
            let behind = if i > 0 { s[i - 1] * s[i] } else { 0.0 };
            ahead - behind
        };
        let chain2 = |i: usize, j: usize| {
            if i == j {
                let ahead = if i + 1 < M { s[i] * co[i + 1] } else { 0.0 };
                let behind = if i > 0 { s[i - 1] * co[i] } else { 0.0 };
                -ahead - behind
            } else if j == i + 1 {
                -co[i] * s[j]
            } else if i == j + 1 {
                -co[j] * s[i]
            } else {
                0.0
            }
        };
        let lq = SVector::<f64, M>::from_fn(|i, _| {
            co[i] * v[i] - 0.5 * v[i] * v[i] * s[i]
                + chain(i)
                + (0..M).map(|j| b(i, j) * v[j] + c(i, j) * q[j]).sum::<f64>()
        });
        let lv = SVector::<f64, M>::from_fn(|i, _| {
            s[i] + v[i] * co[i] + (0..M).map(|j| a(i, j) * v[j] + b(j, i) * q[j]).sum::<f64>()
        });
        let diagonal = |i: usize, j: usize, x: f64| if i == j { x } else { 0.0 };
        let qq = SMatrix::<f64, M, M>::from_fn(|i, j| {
            c(i, j) + chain2(i, j) - diagonal(i, j, s[i] * v[i] + 0.5 * v[i] * v[i] * co[i])
        });
        let qv =
            SMatrix::<f64, M, M>::from_fn(|i, j| b(i, j) + diagonal(i, j, co[i] - v[i] * s[i]));
        let vv = SMatrix::<f64, M, M>::from_fn(|i, j| a(i, j) + diagonal(i, j, co[i]));
        let h = 0.01;
        let seeds = [
            (Seed::POSITION, Seed::VELOCITY),
            (Seed::VELOCITY, Seed::POSITION),
            (Seed::POSITION, Seed::POSITION),
            (Seed::VELOCITY, Seed::VELOCITY),
            (Seed::POSITION, Seed::NONE),
            (
                Seed {
                    position: 0.5,
                    velocity: -1.0 / h,
                },
                Seed {
                    position: 0.5,
                    velocity: 1.0 / h,
                },
            ),
            (
                Seed {
                    position: 0.5,
                    velocity: 1.0 / h,
                },
                Seed {
                    position: 0.5,
                    velocity: 1.0 / h,
                },
            ),
        ];
        for (x, y) in seeds {
            let blocks = seeded_by_duals(&Coupled, &q, &v, x, y);
            let mixed = qq * (x.position * y.position)
                + qv * (x.position * y.velocity)
                + qv.transpose() * (x.velocity * y.position)
                + vv * (x.velocity * y.velocity);
            let scale = 1.0 + mixed.amax();
            assert!(
                (blocks.mixed - mixed).amax() <= 1e-13 * scale,
                "{x:?} {y:?}"
            );
            let first = lq * x.position + lv * x.velocity;
            let second = lq * y.position + lv * y.velocity;
            assert!((blocks.first - first).amax() <= 1e-12 * (1.0 + first.amax()));
            assert!((blocks.second - second).amax() <= 1e-12 * (1.0 + second.amax()));
            // The blocks do each entry's arithmetic as the single pass does, up to the order
            // of two cross terms in the mirrored blocks of a symmetric derivative.
            let single = by_blocks::<_, M, M>(&Coupled, &q, &v, x, y);
            let round_off = 4.0 * f64::EPSILON * scale;
            assert!(
                (blocks.mixed - single.mixed).amax() <= round_off,
                "{x:?} {y:?}"
            );
            if x == y {
                assert_eq!(blocks.mixed, blocks.mixed.transpose());
            } else {
                assert_eq!(blocks.mixed, single.mixed, "{x:?} {y:?}");
            }
            assert_eq!(blocks.first, single.first);
            assert_eq!(blocks.second, single.second);
            assert_eq!(blocks.value, single.value);
        }
    }
}
