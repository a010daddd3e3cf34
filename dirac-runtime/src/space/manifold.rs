//! The kinds of points a model's configuration takes: vectors of `Rⁿ` ([`Vectors`]), or products
//! of vectors, rotations and unit vectors ([`Product`](crate::space::product::Product)).
//!
//! A [`Manifold`] fixes how a model sees its configuration and velocity: the types of a point and
//! of a tangent vector over any scalar, so that the model's Lagrangian, one-forms and forces are
//! written once and differentiated exactly by dual numbers. Covectors (momenta, forces,
//! constraint one-forms) are held in the same representation as tangent vectors and paired with
//! them by [`pair`](Manifold::pair). A step works in `N` chart coordinates (the manifold's
//! dimension) through a [`ConfigurationSpace`](crate::ConfigurationSpace) on the manifold: its
//! retraction maps chart coordinates to points and chart velocities to tangent vectors.
//!
//! A model names its variables (a coordinate of `Rⁿ`, a rotation, a unit vector); the manifold
//! names the numbers that represent a point, a tangent vector and the chart coordinates after
//! them, for trajectories and messages.

use std::fmt::Debug;

use nalgebra::SVector;

use crate::base::scalar::Scalar;

/// The points and tangent vectors of a configuration manifold of dimension `N`, over any
/// [`Scalar`].
///
/// ```
/// use dirac_runtime::manifold::{Manifold, Vectors};
/// use nalgebra::vector;
///
/// // On Rⁿ a point and a tangent vector are vectors, and covectors pair by the dot product.
/// let (p, v) = (vector![1.0, 2.0], vector![3.0, -1.0]);
/// assert_eq!(<Vectors as Manifold<2>>::pair(&p, &v), 1.0);
/// let names = <Vectors as Manifold<2>>::point_names(&["x".into(), "y".into()]);
/// assert_eq!(names, ["x", "y"]);
/// ```
pub trait Manifold<const N: usize>:
    Copy + Debug + Default + PartialEq + Send + Sync + 'static
{
    /// A point over the scalar `D`.
    type Point<D: Scalar>: Copy + Debug + PartialEq + Send + Sync;
    /// A tangent vector over `D` as the model reads velocities; covectors are held in the same
    /// representation.
    type Tangent<D: Scalar>: Copy + Debug + PartialEq + Send + Sync;

    /// Number of the model's variables (named by
    /// [`DiracSystem::coordinate_name`](crate::DiracSystem::coordinate_name)).
    const VARIABLES: usize;

    /// The zero tangent vector.
    fn zero<D: Scalar>() -> Self::Tangent<D>;

    /// A point to report before there is one (the origin, the identity attitude, `e₃`).
    fn origin() -> Self::Point<f64>;

    /// `last + fraction (last − before)`: a tangent vector extrapolated from two (a guess for a
    /// solve; the two may sit at nearby points).
    fn extrapolate(
        last: &Self::Tangent<f64>,
        before: &Self::Tangent<f64>,
        fraction: f64,
    ) -> Self::Tangent<f64>;

    /// `⟨α, v⟩`: the covector `α` on the tangent vector `v`.
    fn pair<D: Scalar>(covector: &Self::Tangent<D>, vector: &Self::Tangent<D>) -> D;

    /// The numbers that represent `point` (for trajectories), in the order of
    /// [`point_names`](Self::point_names).
    fn point_components(point: &Self::Point<f64>) -> Vec<f64> {
        Self::point_entries(point)
    }

    /// [`point_components`](Self::point_components) over any scalar (a point's numbers and
    /// their derivatives).
    fn point_entries<D: Scalar>(point: &Self::Point<D>) -> Vec<D>;

    /// The numbers that represent a tangent vector or covector, in the order of
    /// [`tangent_names`](Self::tangent_names).
    fn tangent_components(vector: &Self::Tangent<f64>) -> Vec<f64>;

    /// The point the numbers `values` represent (the inverse of
    /// [`point_components`](Self::point_components)); `None` for the wrong count. The point
    /// may lie off the manifold: [`violation`](Self::violation) says whether it does.
    fn point_from_components(values: &[f64]) -> Option<Self::Point<f64>>;

    /// Names of the numbers of a point, from the names of the model's variables.
    fn point_names(variables: &[String]) -> Vec<String>;

    /// Names of the numbers of a tangent vector, from the names of the model's variables.
    fn tangent_names(variables: &[String]) -> Vec<String>;

    /// Names of the `N` chart coordinates, from the names of the model's variables.
    fn chart_names(variables: &[String]) -> Vec<String>;

    /// `None` when `point` lies on the manifold (finite, and orthogonal or of unit length where
    /// it must be, to the relative `tolerance`), else the variable that does not and why.
    fn violation(point: &Self::Point<f64>, tolerance: f64) -> Option<(usize, String)>;

    /// `None` when `vector` is a finite tangent vector (a velocity or a momentum) at `point`
    /// (tangent to the sphere where it must be, to the relative `tolerance`), else the variable
    /// whose part is not and why.
    fn tangent_violation(
        point: &Self::Point<f64>,
        vector: &Self::Tangent<f64>,
        tolerance: f64,
    ) -> Option<(usize, String)>;
}

/// `Rⁿ`: points and tangent vectors are vectors of `N` numbers, one variable per coordinate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Vectors;

impl<const N: usize> Manifold<N> for Vectors {
    type Point<D: Scalar> = SVector<D, N>;
    type Tangent<D: Scalar> = SVector<D, N>;

    const VARIABLES: usize = N;

    #[inline]
    fn zero<D: Scalar>() -> SVector<D, N> {
        SVector::from_element(D::from(0.0))
    }

    fn origin() -> SVector<f64, N> {
        SVector::zeros()
    }

    fn extrapolate(
        last: &SVector<f64, N>,
        before: &SVector<f64, N>,
        fraction: f64,
    ) -> SVector<f64, N> {
        last + (last - before) * fraction
    }

    #[inline]
    fn pair<D: Scalar>(covector: &SVector<D, N>, vector: &SVector<D, N>) -> D {
        covector.dot(vector)
    }

    fn point_entries<D: Scalar>(point: &SVector<D, N>) -> Vec<D> {
        point.iter().copied().collect()
    }

    fn tangent_components(vector: &SVector<f64, N>) -> Vec<f64> {
        vector.iter().copied().collect()
    }

    fn point_from_components(values: &[f64]) -> Option<SVector<f64, N>> {
        (values.len() == N).then(|| SVector::from_column_slice(values))
    }

    fn point_names(variables: &[String]) -> Vec<String> {
        variables.to_vec()
    }

    fn tangent_names(variables: &[String]) -> Vec<String> {
        variables.to_vec()
    }

    fn chart_names(variables: &[String]) -> Vec<String> {
        variables.to_vec()
    }

    fn violation(point: &SVector<f64, N>, _tolerance: f64) -> Option<(usize, String)> {
        let i = point.iter().position(|x| !x.is_finite())?;
        Some((i, format!("is not finite ({})", point[i])))
    }

    fn tangent_violation(
        _point: &SVector<f64, N>,
        vector: &SVector<f64, N>,
        _tolerance: f64,
    ) -> Option<(usize, String)> {
        let i = vector.iter().position(|x| !x.is_finite())?;
        Some((i, format!("is not finite ({})", vector[i])))
    }
}
