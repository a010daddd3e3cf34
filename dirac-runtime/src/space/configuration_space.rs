//! Configuration spaces: where a step's "base + increment" happens.
//!
//! A step from `q_k` works in a chart centred at `q_k` given by a retraction `R`
//! (`R_q(0) = q`): the points of the step are `R_{q_k}(ξ)` and the velocity of a chart path
//! `ξ(t)` is `T_ξ R_{q_k} · ξ̇` in the model's velocity coordinates. The discrete Lagrangian is
//! the model's Lagrangian read in the chart,
//!
//! ```text
//! ℓ(ξ, ξ̇) = L(R_{q_k}(ξ), T_ξR_{q_k} ξ̇),
//! ```
//!
//! and covectors (momenta, forces, constraint one-forms) enter the chart by the pull-back
//! `(T_ξ R_{q_k})ᵀ`. After a step `ξ_k`, `q_{k+1} = R_{q_k}(ξ_k)` and the end-point covector
//! `∂L_d/∂ξ_k` becomes the momentum at `q_{k+1}` by `(T_{ξ_k} R_{q_k})^{-ᵀ}`: the momentum carried
//! from the chart at `q_k` to the model's coordinates at `q_{k+1}`.
//!
//! [`Euclidean`] (`Q = Rⁿ`, `R_q(ξ) = q + ξ`) is the default: every map is the identity, the
//! momentum advances by the step's total impulse, and both sums are compensated. [`Positive`]
//! (`R₊ⁿ`, `R_q(ξ) = q ⊙ exp ξ`) keeps every point positive. Both have affine chart transitions.
//! The [`Product`](crate::space::product::Product) spaces of vectors, rotations and unit vectors do
//! not: their steps differentiate the discrete Lagrangian through the moving chart (see
//! [`ConfigurationSpace`]). The trait is sealed.

use std::fmt::Debug;

use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector3};

use crate::base::scalar::Scalar;
use crate::space::manifold::{Manifold, Vectors};
use crate::space::rotation::Retraction;

/// The covectors a solved step hands to the configuration space to advance the momentum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepCovectors<const N: usize> {
    /// `Σ_j ∂/∂ξ_j` of the step's action (the discrete Lagrangian, forces and constraint
    /// impulses) over every point of the step: on `Rⁿ`, `p_{k+1} − p_k`, free of the cancellation
    /// between `p_k` and `∂L_d/∂ξ_0`.
    pub impulse: SVector<f64, N>,
    /// The covector on the end point, in the chart at `q_k`: `p_{k+1}` pulled back by
    /// `T_{ξ_k} R_{q_k}`.
    pub end: SVector<f64, N>,
}

impl<const N: usize> StepCovectors<N> {
    /// No impulse and no end covector.
    pub fn zero() -> Self {
        Self {
            impulse: SVector::zeros(),
            end: SVector::zeros(),
        }
    }
}

impl<const N: usize> std::ops::AddAssign for StepCovectors<N> {
    fn add_assign(&mut self, other: Self) {
        self.impulse += other.impulse;
        self.end += other.end;
    }
}

/// The point of a configuration space `C` over the scalar `D`.
pub type Point<C, const N: usize, D> =
    <<C as ConfigurationSpace<N>>::Manifold as Manifold<N>>::Point<D>;

/// A tangent vector (or covector) of a configuration space `C` over the scalar `D`.
pub type Tangent<C, const N: usize, D> =
    <<C as ConfigurationSpace<N>>::Manifold as Manifold<N>>::Tangent<D>;

/// The shape of a configuration space that is `Rᴷ × SO(3)ᴬ` with the chart `q τ(ξ)` on each
/// rotation: the vectors' chart coordinates first, then each rotation's three
/// ([`ConfigurationSpace::group_chart`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GroupChart {
    /// `K`, the number of ordinary coordinates.
    pub reals: usize,
    /// `A`, the number of rotations.
    pub rotations: usize,
    /// The retraction `τ`.
    pub retraction: Retraction,
}

/// A configuration space of dimension `N` on a [`Manifold`], with a retraction `R_q(ξ)` whose
/// charts a step works in.
///
/// The maps are generic over the [`Scalar`] so that the runtime differentiates through them
/// exactly. A retraction must satisfy `R_q(0) = q` and have an invertible tangent map near
/// `ξ = 0`.
///
/// **Sealed: the spaces are the library's.** A step from `q_k` solves for chart coordinates in
/// the chart centred at `q_k`, and the discrete Euler–Lagrange equation of `q_k` is the derivative
/// of the discrete Lagrangian in its first point. Where the chart transitions
/// `R_{q'}⁻¹ ∘ R_q` are affine in `ξ` ([`AFFINE`](Self::AFFINE): `Euclidean`, `Positive`, an
/// abelian group with `exp`), `L_d` does not depend on where its chart is centred and that
/// derivative is `∂L_d/∂ξ_0` in the fixed chart. Otherwise (a rotation, a unit vector: the
/// [`Product`](crate::space::product::Product) spaces) it is taken through the moving chart centred at
/// `R_{q_k}(η)` ([`retract_moved`](Self::retract_moved), [`transition`](Self::transition)), which
/// keeps the step symplectic; the fixed chart there would give a consistent step that is not
/// (measured on `R_q(ξ) = q + sinh ξ`: `det A − 1 = O(h³)` per step and a drifting energy).
///
/// ```
/// use dirac_runtime::configuration_space::{ConfigurationSpace, Euclidean};
/// use nalgebra::vector;
///
/// let q = vector![1.0, 2.0];
/// let moved = Euclidean.retract(&q, &vector![0.5, -0.5]);
/// assert_eq!(moved, vector![1.5, 1.5]);
/// assert_eq!(Euclidean.local(&q, &moved), Some(vector![0.5, -0.5]));
/// ```
pub trait ConfigurationSpace<const N: usize>: sealed::Sealed + Clone + Debug {
    /// The points and tangent vectors the model is written over.
    type Manifold: Manifold<N>;

    /// Whether `R_q(ξ) = q + ξ` with `T_ξR_q` the identity (`Rⁿ`): the Lagrangian in the chart is
    /// then the model's at `q + ξ`, and the runtime adds `q` before it seeds the dual numbers
    /// rather than after (the same values, with no dual-number arithmetic for the chart).
    const TRANSLATION: bool = false;

    /// Whether the chart transitions `R_{R_q(η)}⁻¹ ∘ R_q` are `ξ ↦ ξ − η`: then the moving-chart
    /// maps are the fixed chart's, and a step needs no moving chart.
    const AFFINE: bool = true;

    /// Whether `q` is a point of the space (a start outside it is refused).
    fn contains(&self, q: &Point<Self, N, f64>) -> bool;

    /// `R_q(ξ)`: the point at chart coordinates `ξ` of the chart centred at `q`.
    fn retract<D: Scalar>(&self, q: &Point<Self, N, f64>, xi: &SVector<D, N>) -> Point<Self, N, D>;

    /// `T_ξ R_q · ξ̇`: the model's velocity along the chart velocity `ξ̇` at `ξ`.
    fn push_forward<D: Scalar>(
        &self,
        q: &Point<Self, N, f64>,
        xi: &SVector<D, N>,
        xi_dot: &SVector<D, N>,
    ) -> Tangent<Self, N, D>;

    /// `R_q⁻¹(q1)`: the chart coordinates of `q1` in the chart centred at `q`, `None` outside
    /// the chart.
    fn local(&self, q: &Point<Self, N, f64>, q1: &Point<Self, N, f64>) -> Option<SVector<f64, N>>;

    /// Where `ξ` lies outside the chart's domain, the region where `R_q` is one-to-one and
    /// [`local`](Self::local) inverts it (the index of the variable and why); `None` inside. A
    /// step whose points leave the domain is refused: past it the chart transitions, and so the
    /// step's equations, belong to another branch. The default: the chart covers every `ξ`.
    fn outside_chart(&self, _xi: &SVector<f64, N>) -> Option<(usize, String)> {
        None
    }

    /// Whether the charts at `from` and at `to` are close to each other, so that chart
    /// coordinates at one continue those at the other: the stepper extrapolates the last steps'
    /// solutions (each in its own step's chart) into the next step's first guess only while
    /// they do. By default always: the charts move with their centre continuously.
    fn charts_continue(&self, _from: &Point<Self, N, f64>, _to: &Point<Self, N, f64>) -> bool {
        true
    }

    /// Where the space is `Rᴷ × SO(3)ᴬ` (vectors and rotations, no unit vectors): its shape. A
    /// degree-1 step then takes its slot derivatives by the chain rule through the retraction
    /// rather than by dual numbers through the moving chart. `None` by default.
    fn group_chart(&self) -> Option<GroupChart> {
        None
    }

    /// `(T_ξ R_q)ᵀ α`: the covector `α` at `R_q(ξ)` read in the chart.
    fn pull_back<D: Scalar>(
        &self,
        q: &Point<Self, N, f64>,
        xi: &SVector<D, N>,
        covector: &Tangent<Self, N, D>,
    ) -> SVector<D, N> {
        SVector::from_fn(|j, _| {
            let e = SVector::<D, N>::from_fn(|i, _| D::from(if i == j { 1.0 } else { 0.0 }));
            Self::Manifold::pair(covector, &self.push_forward(q, xi, &e))
        })
    }

    /// The chart velocity `ξ̇` at `ξ = 0` whose push-forward is the model's velocity `v`, `None`
    /// where the tangent map is singular.
    fn chart_velocity(
        &self,
        q: &Point<Self, N, f64>,
        v: &Tangent<Self, N, f64>,
    ) -> Option<SVector<f64, N>> {
        self.chart_rate(q, &SVector::zeros(), v)
    }

    /// The chart velocity `ξ̇` at `ξ` whose push-forward is the model's velocity `v` at
    /// `R_q(ξ)`, `None` where the tangent map is singular.
    fn chart_rate(
        &self,
        q: &Point<Self, N, f64>,
        xi: &SVector<f64, N>,
        v: &Tangent<Self, N, f64>,
    ) -> Option<SVector<f64, N>>;

    /// Moves `q` to `R_q(ξ)`. `carry` is for spaces that compensate round-off over many steps
    /// (on `Rⁿ`, a Kahan sum); the default ignores it.
    fn advance(
        &self,
        q: &mut Point<Self, N, f64>,
        carry: &mut SVector<f64, N>,
        xi: &SVector<f64, N>,
    ) {
        let _ = carry;
        *q = self.retract(q, xi);
    }

    /// The covector at `R_q(ξ)` whose pull-back to the chart at `q` is `covector`: solves
    /// `(T_ξ R_q)ᵀ α = covector`. `None` where the tangent map is singular.
    fn push_covector(
        &self,
        q: &Point<Self, N, f64>,
        xi: &SVector<f64, N>,
        covector: &SVector<f64, N>,
    ) -> Option<Tangent<Self, N, f64>>;

    /// The momentum at `R_q(ξ)` after a step from `(q, p)` (`p` is overwritten): by default
    /// [`push_covector`](Self::push_covector) of `covectors.end`. `None` where the tangent map
    /// is singular.
    fn advance_momentum(
        &self,
        q: &Point<Self, N, f64>,
        xi: &SVector<f64, N>,
        p: &mut Tangent<Self, N, f64>,
        carry: &mut SVector<f64, N>,
        covectors: &StepCovectors<N>,
    ) -> Option<()> {
        let _ = carry;
        *p = self.push_covector(q, xi, &covectors.end)?;
        Some(())
    }

    /// The number of unit-vector factors (`S²`) of a point: none by default.
    fn unit_vectors(&self) -> usize {
        0
    }

    /// `(q, v)` with unit vector `b` and its velocity turned by the infinitesimal rotation `ω`,
    /// `(q_b + ω × q_b, v_b + ω × v_b)`, the other factors as they are: the derivative of a
    /// function of `(q, v)` in `ω` at `ω = 0` is its torque about the origin. `None` where the
    /// space has no unit vector `b`.
    fn turned<D: Scalar>(
        &self,
        q: &Point<Self, N, f64>,
        v: &Tangent<Self, N, f64>,
        b: usize,
        omega: &Vector3<D>,
    ) -> Option<(Point<Self, N, D>, Tangent<Self, N, D>)> {
        let _ = (q, v, b, omega);
        None
    }

    /// The momentum at `next = R_q(ξ)` after a step from `(q, p)` of a model whose action is its
    /// discrete Lagrangian alone, given the step's torque `torque(b)` on each unit vector `b`
    /// (`h Σ_i b_i (X_i × ∂L/∂X + Ẋ_i × ∂L/∂Ẋ)` over the nodes): each unit vector's angular
    /// momentum advances by its torque, `m_{k+1} = m_k + T`, and `p_{k+1} = m_{k+1} × q_{k+1}`
    /// (discrete Noether: turning the whole step by `I + ω̂` changes `L_d` by `ω · T`, so a
    /// rotation the Lagrangian is invariant under keeps its component of `m`). `spin` (the
    /// position's carry, whose unit-vector entries the position does not use) carries what `p`
    /// cannot hold of `m` from step to step. The other factors advance as in
    /// [`advance_momentum`](Self::advance_momentum), which this is by default.
    #[allow(clippy::too_many_arguments)]
    fn advance_momentum_turned(
        &self,
        q: &Point<Self, N, f64>,
        xi: &SVector<f64, N>,
        next: &Point<Self, N, f64>,
        p: &mut Tangent<Self, N, f64>,
        carry: &mut SVector<f64, N>,
        spin: &mut SVector<f64, N>,
        covectors: &StepCovectors<N>,
        torque: impl Fn(usize) -> Vector3<f64>,
    ) -> Option<()> {
        let _ = (next, spin, torque);
        self.advance_momentum(q, xi, p, carry, covectors)
    }

    /// `R_{R_q(η)}(ζ)`: the point at `ζ` of the chart centred at `R_q(η)`.
    ///
    /// The three moving-chart maps are only differentiated once in `η`, at `η = 0` (the step's
    /// first point moved infinitesimally): a space may give them to first order in `η` (with
    /// dual numbers, whose `η`-parts square to zero, that is exact).
    fn retract_moved<D: Scalar>(
        &self,
        q: &Point<Self, N, f64>,
        eta: &SVector<D, N>,
        zeta: &SVector<D, N>,
    ) -> Point<Self, N, D> {
        self.retract(q, &(eta + zeta))
    }

    /// `T_ζ R_{R_q(η)} ζ̇`: the velocity along `ζ̇` at `ζ` of the chart centred at `R_q(η)`.
    fn push_forward_moved<D: Scalar>(
        &self,
        q: &Point<Self, N, f64>,
        eta: &SVector<D, N>,
        zeta: &SVector<D, N>,
        zeta_dot: &SVector<D, N>,
    ) -> Tangent<Self, N, D> {
        self.push_forward(q, &(eta + zeta), zeta_dot)
    }

    /// `R_{R_q(η)}⁻¹(R_q(ξ))`: the point at `ξ` of the chart at `q` read in the chart centred at
    /// `R_q(η)` (for the `η` and `ξ` of one step, inside both charts; to first order in `η`).
    /// Its value at `η = 0` must be `ξ` itself, not its round trip through the retraction: the
    /// step's first derivative is then taken at the very points whose end covector advances the
    /// momentum (a round trip's round-off makes the momentum maps drift).
    fn transition<D: Scalar>(
        &self,
        q: &Point<Self, N, f64>,
        eta: &SVector<D, N>,
        xi: &SVector<D, N>,
    ) -> SVector<D, N> {
        let _ = q;
        xi - eta
    }

    /// `(g x, g v)`: the point `x` and a tangent vector `v` at it moved by the motion `g(δ)`
    /// that carries the chart centred at `q` to a chart centred at `R_q(δ)`,
    /// `R_{R_q(δ)}(ζ) = g(δ) R_q(ζ)`, to first order in `δ` (the step map's derivatives move
    /// the start of a step so; with dual numbers whose `δ`-parts square to zero, exactly). On
    /// vectors a translation by `δ`; on a rotation the turn `q τ(δ) qᵀ` on the left (body
    /// velocities unchanged); on a unit vector the carrier `τ(q × Bδ)`, whose chart at `R_q(δ)`
    /// has the frame `τ(q × Bδ) B` (a step does not see its chart's frame). First order only:
    /// with plain numbers the result is off the manifold by `O(|δ|²)`; it is meant for dual
    /// numbers. `None` where the space's charts are not carried so (the default).
    fn carried<D: Scalar>(
        &self,
        q: &Point<Self, N, f64>,
        delta: &SVector<D, N>,
        x: &Point<Self, N, D>,
        v: &Tangent<Self, N, D>,
    ) -> Option<(Point<Self, N, D>, Tangent<Self, N, D>)> {
        let _ = (q, delta, x, v);
        None
    }

    /// [`local`](Self::local) of a point over dual numbers: `R_q⁻¹(y)`, `None` outside the chart
    /// or where the space does not offer it (the default).
    fn local_over<D: Scalar>(
        &self,
        q: &Point<Self, N, f64>,
        y: &Point<Self, N, D>,
    ) -> Option<SVector<D, N>> {
        let _ = (q, y);
        None
    }
}

pub(crate) mod sealed {
    /// Implemented by the library's spaces only (see [`ConfigurationSpace`](super::ConfigurationSpace)).
    pub trait Sealed {}
    impl Sealed for super::Euclidean {}
    impl Sealed for super::Positive {}
}

/// The matrix of `T_ξ R_q` (columns: the push-forwards of the chart's unit vectors) of a space
/// of vectors.
fn tangent_map<C: ConfigurationSpace<N, Manifold = Vectors>, const N: usize>(
    space: &C,
    q: &SVector<f64, N>,
    xi: &SVector<f64, N>,
) -> SMatrix<f64, N, N> {
    let mut map = SMatrix::<f64, N, N>::zeros();
    for j in 0..N {
        let e = SVector::<f64, N>::from_fn(|i, _| if i == j { 1.0 } else { 0.0 });
        map.set_column(j, &space.push_forward(q, xi, &e));
    }
    map
}

/// [`ConfigurationSpace::chart_rate`] of a space of vectors from its tangent map.
pub(crate) fn chart_rate_by_tangent_map<
    C: ConfigurationSpace<N, Manifold = Vectors>,
    const N: usize,
>(
    space: &C,
    q: &SVector<f64, N>,
    xi: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> Option<SVector<f64, N>> {
    solve(&tangent_map(space, q, xi), v)
}

/// [`ConfigurationSpace::push_covector`] of a space of vectors from its tangent map.
pub(crate) fn covector_by_tangent_map<
    C: ConfigurationSpace<N, Manifold = Vectors>,
    const N: usize,
>(
    space: &C,
    q: &SVector<f64, N>,
    xi: &SVector<f64, N>,
    covector: &SVector<f64, N>,
) -> Option<SVector<f64, N>> {
    solve(&tangent_map(space, q, xi).transpose(), covector)
}

/// `x` with `a x = b`, `None` where `a` is singular or the answer is not finite.
fn solve<const N: usize>(a: &SMatrix<f64, N, N>, b: &SVector<f64, N>) -> Option<SVector<f64, N>> {
    let a = DMatrix::from_column_slice(N, N, a.as_slice());
    let x = a.lu().solve(&DVector::from_column_slice(b.as_slice()))?;
    x.iter()
        .all(|v| v.is_finite())
        .then(|| SVector::from_column_slice(x.as_slice()))
}

/// `Q = Rⁿ` with `R_q(ξ) = q + ξ`: the default space, at no cost. Positions and momenta advance
/// by compensated (Kahan) sums, so over millions of steps they carry the round-off of each
/// increment, not of each sum.
///
/// ```
/// use dirac_runtime::configuration_space::{ConfigurationSpace, Euclidean};
/// use nalgebra::vector;
///
/// // A million steps of 0.1 from 0: the compensated sum is exact to the last bit of 10⁵.
/// let (mut q, mut carry) = (vector![0.0], vector![0.0]);
/// for _ in 0..1_000_000 {
///     Euclidean.advance(&mut q, &mut carry, &vector![0.1]);
/// }
/// assert_eq!(q[0], 100_000.0);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Euclidean;

impl<const N: usize> ConfigurationSpace<N> for Euclidean {
    type Manifold = Vectors;

    const TRANSLATION: bool = true;

    fn contains(&self, q: &SVector<f64, N>) -> bool {
        q.iter().all(|x| x.is_finite())
    }

    #[inline]
    fn retract<D: Scalar>(&self, q: &SVector<f64, N>, xi: &SVector<D, N>) -> SVector<D, N> {
        SVector::from_fn(|i, _| xi[i] + q[i])
    }

    #[inline]
    fn push_forward<D: Scalar>(
        &self,
        _q: &SVector<f64, N>,
        _xi: &SVector<D, N>,
        xi_dot: &SVector<D, N>,
    ) -> SVector<D, N> {
        *xi_dot
    }

    fn local(&self, q: &SVector<f64, N>, q1: &SVector<f64, N>) -> Option<SVector<f64, N>> {
        Some(q1 - q)
    }

    #[inline]
    fn pull_back<D: Scalar>(
        &self,
        _q: &SVector<f64, N>,
        _xi: &SVector<D, N>,
        covector: &SVector<D, N>,
    ) -> SVector<D, N> {
        *covector
    }

    fn chart_rate(
        &self,
        _q: &SVector<f64, N>,
        _xi: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<SVector<f64, N>> {
        Some(*v)
    }

    fn advance(&self, q: &mut SVector<f64, N>, carry: &mut SVector<f64, N>, xi: &SVector<f64, N>) {
        compensated_add(q, carry, xi);
    }

    fn push_covector(
        &self,
        _q: &SVector<f64, N>,
        _xi: &SVector<f64, N>,
        covector: &SVector<f64, N>,
    ) -> Option<SVector<f64, N>> {
        Some(*covector)
    }

    fn advance_momentum(
        &self,
        _q: &SVector<f64, N>,
        _xi: &SVector<f64, N>,
        p: &mut SVector<f64, N>,
        carry: &mut SVector<f64, N>,
        covectors: &StepCovectors<N>,
    ) -> Option<()> {
        compensated_add(p, carry, &covectors.impulse);
        Some(())
    }

    fn carried<D: Scalar>(
        &self,
        _q: &SVector<f64, N>,
        delta: &SVector<D, N>,
        x: &SVector<D, N>,
        v: &SVector<D, N>,
    ) -> Option<(SVector<D, N>, SVector<D, N>)> {
        Some((x + delta, *v))
    }

    fn local_over<D: Scalar>(
        &self,
        q: &SVector<f64, N>,
        y: &SVector<D, N>,
    ) -> Option<SVector<D, N>> {
        Some(SVector::from_fn(|i, _| y[i] - q[i]))
    }
}

/// The positive orthant as the multiplicative group `R₊ⁿ`, with `R_q(ξ) = q ⊙ exp(ξ)` (left
/// trivialised, abelian): every point of every step is positive, whatever the step size, for
/// models whose coordinates must stay positive (concentrations, populations, radii). A start
/// outside the orthant is refused. It defines the three maps a space must; the pull-back, chart
/// velocity and momentum update are the trait's defaults.
///
/// ```
/// use dirac_runtime::configuration_space::{ConfigurationSpace, Positive};
/// use nalgebra::vector;
///
/// let q = vector![2.0, 0.5];
/// let moved = Positive.retract(&q, &vector![-30.0, 0.0]);
/// assert!(moved[0] > 0.0 && moved[1] == 0.5);
/// let back = Positive.local(&q, &moved).expect("positive points");
/// assert!((back[0] + 30.0).abs() < 1e-12);
/// assert_eq!(Positive.local(&q, &vector![-1.0, 1.0]), None);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Positive;

impl<const N: usize> ConfigurationSpace<N> for Positive {
    type Manifold = Vectors;

    fn contains(&self, q: &SVector<f64, N>) -> bool {
        q.iter().all(|x| *x > 0.0 && x.is_finite())
    }

    fn retract<D: Scalar>(&self, q: &SVector<f64, N>, xi: &SVector<D, N>) -> SVector<D, N> {
        SVector::from_fn(|i, _| xi[i].exp() * q[i])
    }

    fn push_forward<D: Scalar>(
        &self,
        q: &SVector<f64, N>,
        xi: &SVector<D, N>,
        xi_dot: &SVector<D, N>,
    ) -> SVector<D, N> {
        SVector::from_fn(|i, _| xi[i].exp() * xi_dot[i] * q[i])
    }

    fn local(&self, q: &SVector<f64, N>, q1: &SVector<f64, N>) -> Option<SVector<f64, N>> {
        let ratio = q1.component_div(q);
        ratio
            .iter()
            .all(|r| *r > 0.0 && r.is_finite())
            .then(|| ratio.map(f64::ln))
    }

    fn chart_rate(
        &self,
        q: &SVector<f64, N>,
        xi: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<SVector<f64, N>> {
        chart_rate_by_tangent_map(self, q, xi, v)
    }

    fn push_covector(
        &self,
        q: &SVector<f64, N>,
        xi: &SVector<f64, N>,
        covector: &SVector<f64, N>,
    ) -> Option<SVector<f64, N>> {
        covector_by_tangent_map(self, q, xi, covector)
    }

    /// `R_{R_q(δ)}(ζ) = exp(δ) ⊙ R_q(ζ)`: points and velocities scale by `exp δ`.
    fn carried<D: Scalar>(
        &self,
        _q: &SVector<f64, N>,
        delta: &SVector<D, N>,
        x: &SVector<D, N>,
        v: &SVector<D, N>,
    ) -> Option<(SVector<D, N>, SVector<D, N>)> {
        let scale = delta.map(|d| d.exp());
        Some((x.component_mul(&scale), v.component_mul(&scale)))
    }

    fn local_over<D: Scalar>(
        &self,
        q: &SVector<f64, N>,
        y: &SVector<D, N>,
    ) -> Option<SVector<D, N>> {
        let ratio = SVector::<D, N>::from_fn(|i, _| y[i] / q[i]);
        ratio
            .iter()
            .all(|r| r.re() > 0.0 && r.re().is_finite())
            .then(|| ratio.map(|r| r.ln()))
    }
}

/// `sum += increment` with Kahan compensation.
pub(crate) fn compensated_add<const N: usize>(
    sum: &mut SVector<f64, N>,
    carry: &mut SVector<f64, N>,
    increment: &SVector<f64, N>,
) {
    for i in 0..N {
        let y = increment[i] - carry[i];
        let t = sum[i] + y;
        carry[i] = (t - sum[i]) - y;
        sum[i] = t;
    }
}
