//! The scalar type a Lagrangian is written over.

use num_dual::DualNum;

/// A real number or a dual number over `f64`: the type a [`DiracSystem`](crate::DiracSystem)'s
/// Lagrangian is generic over, so that the same code yields values and exact derivatives.
///
/// It is implemented for `f64` and for every num-dual type whose primitive is `f64`; users never
/// implement it. The elementary functions (`sin`, `cos`, `exp`, `sqrt`, `powi`, ...) are methods of
/// [`DualNum`].
///
/// ```
/// use dirac_runtime::Scalar;
/// fn spring_energy<D: Scalar>(k: f64, x: D) -> D {
///     x.powi(2) * (0.5 * k)
/// }
/// assert_eq!(spring_energy(2.0, 3.0_f64), 9.0);
/// ```
pub trait Scalar: DualNum<Primitive = f64> + Copy + Send + Sync {}

impl<T: DualNum<Primitive = f64> + Copy + Send + Sync> Scalar for T {}
