//! Products of vectors, rotations and unit vectors: `Rᴷ × SO(3)ᴬ × (S²)ᴮ`, the configuration
//! spaces of rigid bodies (`SO(3) × R³` for a free body, `SO(3)ᴬ` for a chain of them), spherical
//! pendulums and their couplings with ordinary coordinates.
//!
//! A point ([`Configuration`]) holds `K` numbers, `A` rotation matrices (attitudes, body to
//! space) and `B` unit vectors. A tangent vector ([`Rates`]) holds the `K` velocities, each body's
//! angular velocity `Ω` in body axes (left-trivialised: `Ṙ = R Ω̂`), and each unit vector's
//! velocity `q̇` (a vector of `R³` orthogonal to `q`). Covectors use the same representation:
//! momenta are `∂L/∂v`, `∂L/∂Ω` (the body angular momentum `Π`) and `∂L/∂q̇`, forces are forces,
//! body torques and forces on the unit vectors.
//!
//! A step works in `N = K + 3A + 2B` chart coordinates, in that order: `x + ξ` for the vectors,
//! `R τ(ξ)` for each rotation and `τ(q × B(q)ξ) q` for each unit vector (see [`rotation`] and
//! [`sphere`]), with `τ` the chosen [`Retraction`]. The charts of a rotation at `R` and at `R τ(η)` differ by the non-affine
//! transition `ξ ↦ τ⁻¹(τ(η)⁻¹ τ(ξ))`: the step equations take the derivative of the discrete
//! Lagrangian in its first point through that moving chart (see
//! [`GroupEulerLagrange`](crate::step::group_euler_lagrange::GroupEulerLagrange)).

use std::ops::{Index, IndexMut};

use nalgebra::{Matrix3, SVector, Vector2, Vector3};

use crate::base::scalar::Scalar;
use crate::space::configuration_space::{ConfigurationSpace, GroupChart, StepCovectors, sealed};
use crate::space::manifold::Manifold;
use crate::space::rotation::{self, Retraction};
use crate::space::sphere;

/// A point of `Rᴷ × SO(3)ᴬ × (S²)ᴮ` over the scalar `D`.
///
/// ```
/// use dirac_runtime::product::Configuration;
/// use nalgebra::{Matrix3, vector};
/// // A rigid body at rest in the identity attitude, its centre of mass at (0, 0, 1).
/// let pose = Configuration::<f64, 3, 1, 0> {
///     vector: vector![0.0, 0.0, 1.0],
///     rotation: [Matrix3::identity()],
///     direction: [],
/// };
/// assert_eq!(pose.rotation[0] * vector![1.0, 0.0, 0.0], vector![1.0, 0.0, 0.0]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Configuration<D, const K: usize, const A: usize, const B: usize> {
    /// The ordinary coordinates.
    pub vector: SVector<D, K>,
    /// The rotations (attitudes: body axes to space axes).
    pub rotation: [Matrix3<D>; A],
    /// The unit vectors.
    pub direction: [Vector3<D>; B],
}

/// A tangent vector (or covector) of `Rᴷ × SO(3)ᴬ × (S²)ᴮ` over the scalar `D`: velocities,
/// body angular velocities and unit vectors' velocities (or forces, body torques and forces on
/// the unit vectors).
///
/// ```
/// use dirac_runtime::product::Rates;
/// use nalgebra::vector;
/// // A body spinning about its third axis at 2 rad/s.
/// let rates = Rates::<f64, 0, 1, 0> {
///     vector: vector![],
///     rotation: [vector![0.0, 0.0, 2.0]],
///     direction: [],
/// };
/// assert_eq!(rates.rotation[0].norm(), 2.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rates<D, const K: usize, const A: usize, const B: usize> {
    /// Velocities of the ordinary coordinates.
    pub vector: SVector<D, K>,
    /// Body angular velocities `Ω` (`Ṙ = R Ω̂`).
    pub rotation: [Vector3<D>; A],
    /// Velocities of the unit vectors (orthogonal to them).
    pub direction: [Vector3<D>; B],
}

impl<D: Scalar, const K: usize, const A: usize, const B: usize> Rates<D, K, A, B> {
    /// Zero rates.
    pub fn zero() -> Self {
        let zero = D::from(0.0);
        Self {
            vector: SVector::from_element(zero),
            rotation: [Vector3::from_element(zero); A],
            direction: [Vector3::from_element(zero); B],
        }
    }
}

/// The numbers of a tangent vector in one row: the `K` velocities, then three per rotation
/// (`Ω_x, Ω_y, Ω_z`), then three per unit vector; the order of
/// [`Manifold::tangent_components`] (generated one-forms and forces write their terms this way).
///
/// ```
/// use dirac_runtime::product::Rates;
/// let mut rates = Rates::<f64, 1, 1, 1>::zero();
/// rates[0] = 1.0; // the coordinate's velocity
/// rates[3] = 2.0; // Ω_z
/// rates[6] = 3.0; // the unit vector's z velocity
/// assert_eq!((rates.vector[0], rates.rotation[0][2], rates.direction[0][2]), (1.0, 2.0, 3.0));
/// ```
impl<D, const K: usize, const A: usize, const B: usize> Index<usize> for Rates<D, K, A, B> {
    type Output = D;

    fn index(&self, i: usize) -> &D {
        match i {
            i if i < K => &self.vector[i],
            i if i < K + 3 * A => &self.rotation[(i - K) / 3][(i - K) % 3],
            i => &self.direction[(i - K - 3 * A) / 3][(i - K - 3 * A) % 3],
        }
    }
}

impl<D, const K: usize, const A: usize, const B: usize> IndexMut<usize> for Rates<D, K, A, B> {
    fn index_mut(&mut self, i: usize) -> &mut D {
        match i {
            i if i < K => &mut self.vector[i],
            i if i < K + 3 * A => &mut self.rotation[(i - K) / 3][(i - K) % 3],
            i => &mut self.direction[(i - K - 3 * A) / 3][(i - K - 3 * A) % 3],
        }
    }
}

impl<D: Scalar, const K: usize, const A: usize, const B: usize> Configuration<D, K, A, B> {
    /// The point with these parts.
    pub fn new(
        vector: SVector<D, K>,
        rotation: [Matrix3<D>; A],
        direction: [Vector3<D>; B],
    ) -> Self {
        Self {
            vector,
            rotation,
            direction,
        }
    }
}

impl<const K: usize, const A: usize, const B: usize> Configuration<f64, K, A, B> {
    /// Rotation `i`'s attitude as a unit quaternion `[w, x, y, z]`, `w ≥ 0` (see
    /// [`rotation::quaternion`]); `None` past the last rotation.
    ///
    /// ```
    /// use dirac_runtime::product::Configuration;
    /// use nalgebra::Matrix3;
    /// let at_rest = Configuration::of_rotation(Matrix3::identity());
    /// assert_eq!(at_rest.quaternion(0), Some([1.0, 0.0, 0.0, 0.0]));
    /// assert_eq!(at_rest.euler_angles(0), Some([0.0, 0.0, 0.0]));
    /// assert_eq!(at_rest.quaternion(1), None);
    /// ```
    pub fn quaternion(&self, i: usize) -> Option<[f64; 4]> {
        self.rotation.get(i).map(rotation::quaternion)
    }

    /// Rotation `i`'s attitude as Euler angles `[roll, pitch, yaw]` (z-y-x, see
    /// [`rotation::euler_angles`]); `None` past the last rotation.
    pub fn euler_angles(&self, i: usize) -> Option<[f64; 3]> {
        self.rotation.get(i).map(rotation::euler_angles)
    }
}

impl<D: Scalar> Configuration<D, 0, 1, 0> {
    /// A rigid body's attitude `R` as a point of `SO(3)`.
    ///
    /// ```
    /// use dirac_runtime::product::Configuration;
    /// use nalgebra::Matrix3;
    /// assert_eq!(Configuration::of_rotation(Matrix3::<f64>::identity()).rotation[0], Matrix3::identity());
    /// ```
    pub fn of_rotation(r: Matrix3<D>) -> Self {
        Self::new(SVector::from_element(D::from(0.0)), [r], [])
    }
}

impl<D: Scalar> Configuration<D, 0, 0, 1> {
    /// A unit vector `q` as a point of `S²`.
    pub fn of_direction(q: Vector3<D>) -> Self {
        Self::new(SVector::from_element(D::from(0.0)), [], [q])
    }
}

impl<D: Scalar, const K: usize, const A: usize, const B: usize> Rates<D, K, A, B> {
    /// The tangent vector with these parts.
    pub fn new(
        vector: SVector<D, K>,
        rotation: [Vector3<D>; A],
        direction: [Vector3<D>; B],
    ) -> Self {
        Self {
            vector,
            rotation,
            direction,
        }
    }
}

impl<D: Scalar> Rates<D, 0, 1, 0> {
    /// A rigid body's body angular velocity `Ω` (or momentum `Π`).
    pub fn of_rotation(omega: Vector3<D>) -> Self {
        Self::new(SVector::from_element(D::from(0.0)), [omega], [])
    }
}

impl<D: Scalar> Rates<D, 0, 0, 1> {
    /// A unit vector's velocity `q̇` (or momentum).
    pub fn of_direction(v: Vector3<D>) -> Self {
        Self::new(SVector::from_element(D::from(0.0)), [], [v])
    }
}

impl<const K: usize, const A: usize, const B: usize> Configuration<f64, K, A, B> {
    /// Body `a`'s angular momentum in space axes, `R_a Π_a`, from the body momenta `p`
    /// (conserved for a body free of torques about it).
    pub fn spatial(&self, p: &Rates<f64, K, A, B>, a: usize) -> Vector3<f64> {
        self.rotation[a] * p.rotation[a]
    }
}

/// `Rᴷ × SO(3)ᴬ × (S²)ᴮ` with the retraction its steps use for the rotations and unit vectors
/// (the Cayley map unless chosen otherwise).
///
/// It is both the [`Manifold`] a model is written on (`impl DiracSystem<N, Product<K, A, B>>`,
/// `N = K + 3A + 2B`) and the [`ConfigurationSpace`] its steps work in.
///
/// ```
/// use dirac_runtime::product::Product;
/// use dirac_runtime::rotation::Retraction;
/// assert_eq!(Product::<0, 1, 0>::default().retraction(), Retraction::Cayley);
/// assert_eq!(Product::<3, 1, 0>::exp().retraction(), Retraction::Exp);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Product<const K: usize, const A: usize, const B: usize> {
    retraction: Retraction,
}

impl<const K: usize, const A: usize, const B: usize> Product<K, A, B> {
    /// The space whose rotations and unit vectors move by `retraction`.
    pub fn new(retraction: Retraction) -> Self {
        Self { retraction }
    }

    /// Steps by the Cayley map.
    pub fn cayley() -> Self {
        Self::new(Retraction::Cayley)
    }

    /// Steps by the exponential map.
    pub fn exp() -> Self {
        Self::new(Retraction::Exp)
    }

    /// The retraction.
    pub fn retraction(&self) -> Retraction {
        self.retraction
    }

    /// Where rotation `a`'s chart coordinates start.
    const fn rotation_at(a: usize) -> usize {
        K + 3 * a
    }

    /// Where unit vector `b`'s chart coordinates start.
    const fn direction_at(b: usize) -> usize {
        K + 3 * A + 2 * b
    }
}

/// Refuses, at compile time, a dimension other than `K + 3A + 2B`.
const fn dimension<const N: usize, const K: usize, const A: usize, const B: usize>() {
    assert!(
        N == K + 3 * A + 2 * B,
        "a model on Product<K, A, B> has N = K + 3A + 2B chart coordinates"
    );
}

fn rows3<D: Scalar, const N: usize>(x: &SVector<D, N>, at: usize) -> Vector3<D> {
    Vector3::new(x[at], x[at + 1], x[at + 2])
}

fn rows2<D: Scalar, const N: usize>(x: &SVector<D, N>, at: usize) -> Vector2<D> {
    Vector2::new(x[at], x[at + 1])
}

impl<const N: usize, const K: usize, const A: usize, const B: usize> Manifold<N>
    for Product<K, A, B>
{
    type Point<D: Scalar> = Configuration<D, K, A, B>;
    type Tangent<D: Scalar> = Rates<D, K, A, B>;

    const VARIABLES: usize = K + A + B;

    fn zero<D: Scalar>() -> Rates<D, K, A, B> {
        Rates::zero()
    }

    fn origin() -> Configuration<f64, K, A, B> {
        Configuration {
            vector: SVector::zeros(),
            rotation: [Matrix3::identity(); A],
            direction: [Vector3::z(); B],
        }
    }

    fn extrapolate(
        last: &Rates<f64, K, A, B>,
        before: &Rates<f64, K, A, B>,
        fraction: f64,
    ) -> Rates<f64, K, A, B> {
        let step = |a: &Vector3<f64>, b: &Vector3<f64>| a + (a - b) * fraction;
        Rates {
            vector: last.vector + (last.vector - before.vector) * fraction,
            rotation: std::array::from_fn(|a| step(&last.rotation[a], &before.rotation[a])),
            direction: std::array::from_fn(|b| step(&last.direction[b], &before.direction[b])),
        }
    }

    fn pair<D: Scalar>(covector: &Rates<D, K, A, B>, vector: &Rates<D, K, A, B>) -> D {
        let mut sum = covector.vector.dot(&vector.vector);
        for a in 0..A {
            sum += covector.rotation[a].dot(&vector.rotation[a]);
        }
        for b in 0..B {
            sum += covector.direction[b].dot(&vector.direction[b]);
        }
        sum
    }

    fn point_entries<D: Scalar>(point: &Configuration<D, K, A, B>) -> Vec<D> {
        let mut out: Vec<D> = point.vector.iter().copied().collect();
        for r in &point.rotation {
            // Row by row: R_11, R_12, ..., R_33.
            out.extend(r.transpose().iter());
        }
        for q in &point.direction {
            out.extend(q.iter());
        }
        out
    }

    fn tangent_components(vector: &Rates<f64, K, A, B>) -> Vec<f64> {
        let mut out: Vec<f64> = vector.vector.iter().copied().collect();
        for w in vector.rotation.iter().chain(&vector.direction) {
            out.extend(w.iter());
        }
        out
    }

    fn point_from_components(values: &[f64]) -> Option<Configuration<f64, K, A, B>> {
        if values.len() != K + 9 * A + 3 * B {
            return None;
        }
        let rotations = &values[K..K + 9 * A];
        let directions = &values[K + 9 * A..];
        Some(Configuration {
            vector: SVector::from_column_slice(&values[..K]),
            // Row by row, as `point_components` writes them.
            rotation: std::array::from_fn(|a| {
                Matrix3::from_row_slice(&rotations[9 * a..9 * a + 9])
            }),
            direction: std::array::from_fn(|b| {
                Vector3::from_column_slice(&directions[3 * b..3 * b + 3])
            }),
        })
    }

    fn point_names(variables: &[String]) -> Vec<String> {
        let mut names: Vec<String> = variables[..K].to_vec();
        for r in &variables[K..K + A] {
            names.extend((1..=3).flat_map(|i| (1..=3).map(move |j| format!("{r}_{i}{j}"))));
        }
        for q in &variables[K + A..] {
            names.extend(["x", "y", "z"].map(|c| format!("{q}_{c}")));
        }
        names
    }

    fn tangent_names(variables: &[String]) -> Vec<String> {
        let mut names: Vec<String> = variables[..K].to_vec();
        for name in &variables[K..] {
            names.extend(["x", "y", "z"].map(|c| format!("{name}_{c}")));
        }
        names
    }

    fn chart_names(variables: &[String]) -> Vec<String> {
        let mut names: Vec<String> = variables[..K].to_vec();
        for r in &variables[K..K + A] {
            names.extend(["x", "y", "z"].map(|c| format!("{r}_{c}")));
        }
        for q in &variables[K + A..] {
            names.extend(["1", "2"].map(|c| format!("{q}_{c}")));
        }
        names
    }

    fn violation(point: &Configuration<f64, K, A, B>, tolerance: f64) -> Option<(usize, String)> {
        if let Some(i) = point.vector.iter().position(|x| !x.is_finite()) {
            return Some((i, format!("is not finite ({})", point.vector[i])));
        }
        for (a, r) in point.rotation.iter().enumerate() {
            if !r.iter().all(|x| x.is_finite()) {
                return Some((K + a, "has an entry that is not finite".into()));
            }
            let defect = (r.transpose() * r - Matrix3::identity()).amax();
            if defect > tolerance {
                return Some((
                    K + a,
                    format!(
                        "is not a rotation: |RᵀR − I| = {defect:.3e} (tolerance {tolerance:.0e})"
                    ),
                ));
            }
            if r.determinant() < 0.0 {
                return Some((K + a, "is a reflection, not a rotation: det R = −1".into()));
            }
        }
        for (b, q) in point.direction.iter().enumerate() {
            let defect = (q.norm() - 1.0).abs();
            if defect.is_nan() || defect > tolerance {
                return Some((
                    K + A + b,
                    format!(
                        "is not a unit vector: |q| − 1 = {:.3e} (tolerance {tolerance:.0e})",
                        q.norm() - 1.0
                    ),
                ));
            }
        }
        None
    }

    fn tangent_violation(
        point: &Configuration<f64, K, A, B>,
        vector: &Rates<f64, K, A, B>,
        tolerance: f64,
    ) -> Option<(usize, String)> {
        if let Some(i) = vector.vector.iter().position(|x| !x.is_finite()) {
            return Some((i, format!("is not finite ({})", vector.vector[i])));
        }
        for (a, w) in vector.rotation.iter().enumerate() {
            if !w.iter().all(|x| x.is_finite()) {
                return Some((K + a, "is not finite".into()));
            }
        }
        for (b, (v, q)) in vector.direction.iter().zip(&point.direction).enumerate() {
            if !v.iter().all(|x| x.is_finite()) {
                return Some((K + A + b, "is not finite".into()));
            }
            let radial = v.dot(q);
            if radial.abs() > tolerance * v.norm().max(f64::MIN_POSITIVE) {
                return Some((
                    K + A + b,
                    format!(
                        "leaves the sphere: q·w = {radial:.3e} for w of norm {:.3e}",
                        v.norm()
                    ),
                ));
            }
        }
        None
    }
}

impl<const K: usize, const A: usize, const B: usize> Product<K, A, B> {
    /// `R_{R_q(η)}(ζ)`, or `R_q(ζ)` without `η`.
    fn moved<D: Scalar, const N: usize>(
        &self,
        q: &Configuration<f64, K, A, B>,
        eta: Option<&SVector<D, N>>,
        zeta: &SVector<D, N>,
    ) -> Configuration<D, K, A, B> {
        const { dimension::<N, K, A, B>() };
        let tau = self.retraction;
        let vector = SVector::<D, K>::from_fn(|i, _| match eta {
            Some(eta) => eta[i] + zeta[i] + q.vector[i],
            None => zeta[i] + q.vector[i],
        });
        let rotation = std::array::from_fn(|a| {
            let at = Self::rotation_at(a);
            let step = tau.map(&rows3(zeta, at));
            // To first order in η (see `retract_moved`): τ(η) = I + η̂.
            let relative = match eta {
                Some(eta) => step + rotation::product(&rotation::hat(&rows3(eta, at)), &step),
                None => step,
            };
            rotation::product_known(&q.rotation[a], &relative)
        });
        let direction = std::array::from_fn(|b| {
            let at = Self::direction_at(b);
            let base = &q.direction[b];
            let frame = sphere::frame(base);
            let point = sphere::retract(tau, base, &sphere::in_frame(&frame, &rows2(zeta, at)));
            match eta {
                Some(eta) => {
                    point
                        + sphere::turn(base, &sphere::in_frame(&frame, &rows2(eta, at)))
                            .cross(&point)
                }
                None => point,
            }
        });
        Configuration {
            vector,
            rotation,
            direction,
        }
    }

    /// The vectors' and rotations' part of [`push_covector`](ConfigurationSpace::push_covector)
    /// into `p` (the unit vectors' left as they are): `None` where a rotation's tangent map is
    /// singular.
    fn push_vectors_and_rotations<const N: usize>(
        &self,
        xi: &SVector<f64, N>,
        covector: &SVector<f64, N>,
        p: &mut Rates<f64, K, A, B>,
    ) -> Option<()> {
        const { dimension::<N, K, A, B>() };
        for i in 0..K {
            p.vector[i] = covector[i];
        }
        for a in 0..A {
            let at = Self::rotation_at(a);
            p.rotation[a] = self
                .retraction
                .body_momentum(&rows3(xi, at), &rows3(covector, at))?;
        }
        Some(())
    }

    /// `T_ζ R_{R_q(η)} ζ̇`, or `T_ζ R_q ζ̇` without `η`.
    fn moved_velocity<D: Scalar, const N: usize>(
        &self,
        q: &Configuration<f64, K, A, B>,
        eta: Option<&SVector<D, N>>,
        zeta: &SVector<D, N>,
        zeta_dot: &SVector<D, N>,
    ) -> Rates<D, K, A, B> {
        const { dimension::<N, K, A, B>() };
        let tau = self.retraction;
        let vector = SVector::<D, K>::from_fn(|i, _| zeta_dot[i]);
        // Left-trivialised: a rotation's angular velocity does not see where its chart is
        // centred.
        let rotation = std::array::from_fn(|a| {
            let at = Self::rotation_at(a);
            rotation::apply(&tau.differential(&rows3(zeta, at)), &rows3(zeta_dot, at))
        });
        let direction = std::array::from_fn(|b| {
            let at = Self::direction_at(b);
            let base = &q.direction[b];
            let frame = sphere::frame(base);
            let velocity = sphere::velocity(
                tau,
                base,
                &sphere::in_frame(&frame, &rows2(zeta, at)),
                &sphere::in_frame(&frame, &rows2(zeta_dot, at)),
            );
            match eta {
                Some(eta) => {
                    velocity
                        + sphere::turn(base, &sphere::in_frame(&frame, &rows2(eta, at)))
                            .cross(&velocity)
                }
                None => velocity,
            }
        });
        Rates {
            vector,
            rotation,
            direction,
        }
    }
}

impl<const K: usize, const A: usize, const B: usize> sealed::Sealed for Product<K, A, B> {}

impl<const N: usize, const K: usize, const A: usize, const B: usize> ConfigurationSpace<N>
    for Product<K, A, B>
{
    type Manifold = Self;

    const AFFINE: bool = A + B == 0;

    fn group_chart(&self) -> Option<GroupChart> {
        (B == 0).then_some(GroupChart {
            reals: K,
            rotations: A,
            retraction: self.retraction,
        })
    }

    fn contains(&self, q: &Configuration<f64, K, A, B>) -> bool {
        <Self as Manifold<N>>::violation(q, 1e-9).is_none()
    }

    fn retract<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        xi: &SVector<D, N>,
    ) -> Configuration<D, K, A, B> {
        self.moved(q, None, xi)
    }

    fn push_forward<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        xi: &SVector<D, N>,
        xi_dot: &SVector<D, N>,
    ) -> Rates<D, K, A, B> {
        self.moved_velocity(q, None, xi, xi_dot)
    }

    fn local(
        &self,
        q: &Configuration<f64, K, A, B>,
        q1: &Configuration<f64, K, A, B>,
    ) -> Option<SVector<f64, N>> {
        self.local_over(q, q1)
    }

    /// The exponential chart of a rotation or a unit vector is one-to-one for turns below π
    /// (`|ξ| < π`); the Cayley chart covers every `ξ` (turns approach π as `|ξ| → ∞`).
    ///
    /// ```
    /// use dirac_runtime::configuration_space::ConfigurationSpace;
    /// use dirac_runtime::product::Product;
    /// use nalgebra::vector;
    /// let half_turn = vector![0.0, 0.0, 3.2];
    /// assert!(ConfigurationSpace::<3>::outside_chart(&Product::<0, 1, 0>::exp(), &half_turn).is_some());
    /// assert!(ConfigurationSpace::<3>::outside_chart(&Product::<0, 1, 0>::cayley(), &half_turn).is_none());
    /// ```
    fn outside_chart(&self, xi: &SVector<f64, N>) -> Option<(usize, String)> {
        const { dimension::<N, K, A, B>() };
        if self.retraction == Retraction::Cayley {
            return None;
        }
        // A NaN turn is beyond too.
        let beyond = |turn: f64| turn.is_nan() || turn >= std::f64::consts::PI;
        for a in 0..A {
            let turn = rows3(xi, Self::rotation_at(a)).norm();
            if beyond(turn) {
                return Some((
                    K + a,
                    format!(
                        "turns by {turn:.3} rad in one step, past π, where the chart of the \
                     exponential map ends"
                    ),
                ));
            }
        }
        for b in 0..B {
            let turn = rows2(xi, Self::direction_at(b)).norm();
            if beyond(turn) {
                return Some((
                    K + A + b,
                    format!(
                        "turns by {turn:.3} rad in one step, past π, where the chart of the \
                     exponential map ends"
                    ),
                ));
            }
        }
        None
    }

    /// A unit vector's chart frame changes branch where its third component changes sign (see
    /// [`sphere::frame`]): chart coordinates on either side do not continue each other there.
    fn charts_continue(
        &self,
        from: &Configuration<f64, K, A, B>,
        to: &Configuration<f64, K, A, B>,
    ) -> bool {
        from.direction
            .iter()
            .zip(&to.direction)
            .all(|(a, b)| a[2].is_sign_negative() == b[2].is_sign_negative())
    }

    fn pull_back<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        xi: &SVector<D, N>,
        covector: &Rates<D, K, A, B>,
    ) -> SVector<D, N> {
        const { dimension::<N, K, A, B>() };
        let tau = self.retraction;
        let mut out = SVector::<D, N>::from_element(D::from(0.0));
        for i in 0..K {
            out[i] = covector.vector[i];
        }
        for a in 0..A {
            let at = Self::rotation_at(a);
            let d = tau.differential(&rows3(xi, at));
            out.fixed_rows_mut::<3>(at)
                .copy_from(&(d.transpose() * covector.rotation[a]));
        }
        for b in 0..B {
            let at = Self::direction_at(b);
            let base = &q.direction[b];
            let frame = sphere::frame(base).map(D::from);
            let w = frame * rows2(xi, at);
            for k in 0..2 {
                let e = frame.column(k).into_owned();
                out[at + k] = covector.direction[b].dot(&sphere::velocity(tau, base, &w, &e));
            }
        }
        out
    }

    fn chart_rate(
        &self,
        q: &Configuration<f64, K, A, B>,
        xi: &SVector<f64, N>,
        v: &Rates<f64, K, A, B>,
    ) -> Option<SVector<f64, N>> {
        const { dimension::<N, K, A, B>() };
        let tau = self.retraction;
        let mut out = SVector::<f64, N>::zeros();
        for i in 0..K {
            out[i] = v.vector[i];
        }
        for a in 0..A {
            let at = Self::rotation_at(a);
            let rate = tau.differential_inverse(&rows3(xi, at)) * v.rotation[a];
            out.fixed_rows_mut::<3>(at).copy_from(&rate);
        }
        for b in 0..B {
            let at = Self::direction_at(b);
            let base = &q.direction[b];
            let rate = sphere::chart_rate(
                tau,
                base,
                &sphere::frame(base),
                &rows2(xi, at),
                &v.direction[b],
            )?;
            out.fixed_rows_mut::<2>(at).copy_from(&rate);
        }
        out.iter().all(|x| x.is_finite()).then_some(out)
    }

    fn advance(
        &self,
        q: &mut Configuration<f64, K, A, B>,
        carry: &mut SVector<f64, N>,
        xi: &SVector<f64, N>,
    ) {
        let mut next = self.retract(q, xi);
        // The vectors by compensated sums; the rotations and unit vectors projected back onto
        // their manifolds (their round-off would otherwise accumulate over millions of steps).
        for i in 0..K {
            let y = xi[i] - carry[i];
            let t = q.vector[i] + y;
            carry[i] = (t - q.vector[i]) - y;
            next.vector[i] = t;
        }
        for r in &mut next.rotation {
            *r = rotation::orthonormalised(r);
        }
        for d in &mut next.direction {
            *d = sphere::normalised(d);
        }
        *q = next;
    }

    fn push_covector(
        &self,
        q: &Configuration<f64, K, A, B>,
        xi: &SVector<f64, N>,
        covector: &SVector<f64, N>,
    ) -> Option<Rates<f64, K, A, B>> {
        let tau = self.retraction;
        let mut p = Rates::zero();
        self.push_vectors_and_rotations(xi, covector, &mut p)?;
        for b in 0..B {
            let at = Self::direction_at(b);
            let base = &q.direction[b];
            p.direction[b] = sphere::push_covector(
                tau,
                base,
                &sphere::frame(base),
                &rows2(xi, at),
                &rows2(covector, at),
            )?;
        }
        Some(p)
    }

    fn unit_vectors(&self) -> usize {
        B
    }

    fn turned<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        v: &Rates<f64, K, A, B>,
        b: usize,
        omega: &Vector3<D>,
    ) -> Option<(Configuration<D, K, A, B>, Rates<D, K, A, B>)> {
        if b >= B {
            return None;
        }
        let lift3 = |x: &Vector3<f64>| x.map(D::from);
        let turn = |x: &Vector3<f64>| lift3(x) + omega.cross(&lift3(x));
        let mut point = Configuration {
            vector: q.vector.map(D::from),
            rotation: q.rotation.map(|r| r.map(D::from)),
            direction: q.direction.map(|d| lift3(&d)),
        };
        let mut rates = Rates {
            vector: v.vector.map(D::from),
            rotation: v.rotation.map(|w| lift3(&w)),
            direction: v.direction.map(|d| lift3(&d)),
        };
        point.direction[b] = turn(&q.direction[b]);
        rates.direction[b] = turn(&v.direction[b]);
        Some((point, rates))
    }

    /// Each unit vector's angular momentum is `m = q × p + F c + r q`, with `c = carry`'s two
    /// numbers in the frame `F` of `q`'s tangent plane (the round-off of `m → p → q × p`) and
    /// `r = spin`'s first (the component along `q` that a tangent `p` cannot hold; `spin` is
    /// the position's carry, which [`advance`](ConfigurationSpace::advance) uses on the
    /// vectors alone). Without
    /// them the spherical pendulum's vertical momentum drifts by 2e-17 of itself a step.
    fn advance_momentum_turned(
        &self,
        q: &Configuration<f64, K, A, B>,
        xi: &SVector<f64, N>,
        next: &Configuration<f64, K, A, B>,
        p: &mut Rates<f64, K, A, B>,
        carry: &mut SVector<f64, N>,
        spin: &mut SVector<f64, N>,
        covectors: &StepCovectors<N>,
        torque: impl Fn(usize) -> Vector3<f64>,
    ) -> Option<()> {
        let m: [Vector3<f64>; B] = std::array::from_fn(|b| {
            let (base, at) = (&q.direction[b], Self::direction_at(b));
            let kept = sphere::frame(base) * rows2(carry, at) + base * spin[at];
            base.cross(&p.direction[b]) + kept + torque(b)
        });
        self.push_vectors_and_rotations(xi, &covectors.end, p)?;
        for (b, m) in m.iter().enumerate() {
            let (n, at) = (&next.direction[b], Self::direction_at(b));
            p.direction[b] = m.cross(n) / n.norm_squared();
            let lost = m - n.cross(&p.direction[b]);
            spin[at] = lost.dot(n) / n.norm_squared();
            let tangential = sphere::frame(n).transpose() * (lost - n * spin[at]);
            carry.fixed_rows_mut::<2>(at).copy_from(&tangential);
        }
        Some(())
    }

    fn retract_moved<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        eta: &SVector<D, N>,
        zeta: &SVector<D, N>,
    ) -> Configuration<D, K, A, B> {
        self.moved(q, Some(eta), zeta)
    }

    fn push_forward_moved<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        eta: &SVector<D, N>,
        zeta: &SVector<D, N>,
        zeta_dot: &SVector<D, N>,
    ) -> Rates<D, K, A, B> {
        self.moved_velocity(q, Some(eta), zeta, zeta_dot)
    }

    fn transition<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        eta: &SVector<D, N>,
        xi: &SVector<D, N>,
    ) -> SVector<D, N> {
        const { dimension::<N, K, A, B>() };
        let tau = self.retraction;
        let mut out = SVector::<D, N>::from_element(D::from(0.0));
        for i in 0..K {
            out[i] = xi[i] - eta[i];
        }
        for a in 0..A {
            // τ(ξ') = τ(η)ᵀ τ(ξ), with τ(η)ᵀ = I − η̂ to first order in η. (The first-order
            // expansion of ξ' itself, ξ − dτ_ξ⁻¹ τ(ξ)ᵀ η, is the same derivative but rounds
            // with a bias: measured, a heavy top's vertical momentum then drifts by 2e-16 per
            // step, and not through the chart's inverse.)
            let at = Self::rotation_at(a);
            let xi = rows3(xi, at);
            let back = Matrix3::identity() - rotation::hat(&rows3(eta, at));
            let relative = rotation::product(&back, &tau.map(&xi));
            let moved = tau
                .inverse(&relative)
                .unwrap_or_else(|| Vector3::from_element(D::from(f64::NAN)));
            // Exactly ξ at η = 0: the round trip's round-off is left out of the value.
            for k in 0..3 {
                out[at + k] = moved[k] + (xi[k].re() - moved[k].re());
            }
        }
        for b in 0..B {
            let at = Self::direction_at(b);
            let base = &q.direction[b];
            let frame = sphere::frame(base);
            let point = sphere::retract(tau, base, &sphere::in_frame(&frame, &rows2(xi, at)));
            // To first order in η the carrier turns the point back by −ω × point.
            let turned = point
                - sphere::turn(base, &sphere::in_frame(&frame, &rows2(eta, at))).cross(&point);
            let w = sphere::local(tau, base, &turned)
                .unwrap_or_else(|| Vector3::from_element(D::from(f64::NAN)));
            let moved = sphere::frame_coordinates(&frame, &w);
            // Exactly ξ at η = 0: the round trip's round-off is left out of the value.
            let own = rows2(xi, at);
            for k in 0..2 {
                out[at + k] = moved[k] + (own[k].re() - moved[k].re());
            }
        }
        out
    }

    fn carried<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        delta: &SVector<D, N>,
        x: &Configuration<D, K, A, B>,
        v: &Rates<D, K, A, B>,
    ) -> Option<(Configuration<D, K, A, B>, Rates<D, K, A, B>)> {
        const { dimension::<N, K, A, B>() };
        let (mut x, mut v) = (*x, *v);
        for i in 0..K {
            x.vector[i] += delta[i];
        }
        for a in 0..A {
            // q τ(δ) qᵀ = I + (q δ)^ to first order: the turn δ read in space.
            let turn = rows3(delta, Self::rotation_at(a));
            let spatial = Vector3::from_fn(|r, _| {
                turn[0] * q.rotation[a][(r, 0)]
                    + turn[1] * q.rotation[a][(r, 1)]
                    + turn[2] * q.rotation[a][(r, 2)]
            });
            x.rotation[a] += rotation::product(&rotation::hat(&spatial), &x.rotation[a]);
        }
        for b in 0..B {
            let base = &q.direction[b];
            let turn = sphere::turn(
                base,
                &sphere::in_frame(&sphere::frame(base), &rows2(delta, Self::direction_at(b))),
            );
            x.direction[b] += turn.cross(&x.direction[b]);
            v.direction[b] += turn.cross(&v.direction[b]);
        }
        Some((x, v))
    }

    fn local_over<D: Scalar>(
        &self,
        q: &Configuration<f64, K, A, B>,
        y: &Configuration<D, K, A, B>,
    ) -> Option<SVector<D, N>> {
        const { dimension::<N, K, A, B>() };
        let tau = self.retraction;
        let mut xi = SVector::<D, N>::from_element(D::from(0.0));
        for i in 0..K {
            xi[i] = y.vector[i] - q.vector[i];
        }
        for a in 0..A {
            let relative = rotation::product_known(&q.rotation[a].transpose(), &y.rotation[a]);
            let x = tau.inverse(&relative)?;
            for k in 0..3 {
                xi[Self::rotation_at(a) + k] = x[k];
            }
        }
        for b in 0..B {
            let base = &q.direction[b];
            let w = sphere::local(tau, base, &y.direction[b])?;
            let z = sphere::frame_coordinates(&sphere::frame(base), &w);
            for k in 0..2 {
                xi[Self::direction_at(b) + k] = z[k];
            }
        }
        Some(xi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point's numbers give the point back, and the wrong count gives none.
    #[test]
    fn a_point_is_its_numbers() {
        let space = Product::<1, 2, 1>::cayley();
        let xi = SVector::<f64, 9>::from_fn(|i, _| 0.1 * (i as f64 + 1.0) - 0.45);
        let q = space.retract(&<Product<1, 2, 1> as Manifold<9>>::origin(), &xi);
        let numbers = <Product<1, 2, 1> as Manifold<9>>::point_components(&q);
        assert_eq!(numbers.len(), 1 + 18 + 3);
        let back = <Product<1, 2, 1> as Manifold<9>>::point_from_components(&numbers);
        assert_eq!(back, Some(q));
        assert_eq!(
            <Product<1, 2, 1> as Manifold<9>>::point_from_components(&numbers[1..]),
            None
        );
    }

    /// The chart maps of `R × SO(3) × S²` keep the pairing of momenta and velocities: a chart
    /// covector pushed to the manifold pairs with the pushed velocity as it paired in the chart,
    /// and `pull_back` is the adjoint of `push_forward`. Checked at a point and increment away
    /// from the identity, for both retractions.
    #[test]
    fn chart_maps_keep_the_pairing() {
        for space in [Product::<1, 1, 1>::cayley(), Product::<1, 1, 1>::exp()] {
            let q = space.retract(
                &<Product<1, 1, 1> as Manifold<6>>::origin(),
                &SVector::<f64, 6>::from_column_slice(&[0.2, 0.3, -0.5, 0.8, 0.4, -0.6]),
            );
            let xi = SVector::<f64, 6>::from_column_slice(&[0.1, 0.4, 0.2, -0.3, 0.25, 0.35]);
            let rate = SVector::<f64, 6>::from_column_slice(&[0.7, -0.2, 0.5, 0.3, -0.6, 0.4]);
            let chart = SVector::<f64, 6>::from_column_slice(&[-0.3, 0.9, 0.1, -0.5, 0.2, 0.8]);
            let velocity = space.push_forward(&q, &xi, &rate);
            let momentum = space.push_covector(&q, &xi, &chart).unwrap();
            let paired = <Product<1, 1, 1> as Manifold<6>>::pair(&momentum, &velocity);
            let expected = chart.dot(&rate);
            assert!((paired - expected).abs() < 1e-14, "{paired} vs {expected}");
            let pulled = space.pull_back(&q, &xi, &momentum);
            assert!((pulled - chart).amax() < 1e-14, "{pulled} vs {chart}");
            // The adjoint on any covector, tangent or not.
            let any = Rates {
                vector: SVector::<f64, 1>::new(0.4),
                rotation: [Vector3::new(-0.2, 0.6, 0.3)],
                direction: [Vector3::new(0.5, -0.1, 0.9)],
            };
            let left = space.pull_back(&q, &xi, &any).dot(&rate);
            let right = <Product<1, 1, 1> as Manifold<6>>::pair(&any, &velocity);
            assert!((left - right).abs() < 1e-14, "{left} vs {right}");
            // The velocity read back through the chart is the chart rate.
            let back = space.chart_rate(&q, &xi, &velocity).unwrap();
            assert!((back - rate).amax() < 1e-14, "{back} vs {rate}");
        }
    }
}
