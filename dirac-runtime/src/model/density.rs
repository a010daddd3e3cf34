//! Lagrangian densities of fields `u(t, x) ∈ Rᶜ` on an interval of the line.
//!
//! A field's action is `∫∫ ℒ(x, u, u_t, u_x) dx dt`. The class held here is the separable one,
//! `ℒ = ½ Σ_c ρ_c(x) u_{t,c}² − U(x, u, u_x)`: a kinetic energy density with a positive inertia
//! per component, and a potential energy density of the field and its slope. It holds the
//! nonlinear wave equations `ρ u_tt = ∂_x U_{u_x} − U_u`: the string and the elastic bar, the
//! Klein–Gordon, sine-Gordon and φ⁴ fields, chains of coupled components. Its space–time cells
//! give an explicit step ([`Field`](crate::step::field::Field)).

use nalgebra::SVector;

use crate::base::scalar::Scalar;

/// The Lagrangian density `ℒ = ½ Σ_c ρ_c(x) u_{t,c}² − U(x, u, u_x)` of a field with `C`
/// components.
///
/// [`potential`](Self::potential) is generic over the scalar, so that the same code yields the
/// density's value and, through dual numbers, its exact derivatives.
///
/// ```
/// use dirac_runtime::nalgebra::SVector;
/// use dirac_runtime::{Scalar, SeparableDensity};
///
/// /// The sine-Gordon field: `ℒ = ½ u_t² − ½ u_x² − (1 − cos u)`.
/// struct SineGordon;
/// impl SeparableDensity<1> for SineGordon {
///     fn inertia(&self, _x: f64) -> SVector<f64, 1> {
///         SVector::from([1.0])
///     }
///     fn potential<S: Scalar>(&self, _x: f64, u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
///         ux[0] * ux[0] * 0.5 - u[0].cos() + 1.0
///     }
/// }
/// let u = SVector::from([std::f64::consts::PI]);
/// assert_eq!(SineGordon.potential(0.0, &u, &SVector::from([0.0])), 2.0);
/// ```
pub trait SeparableDensity<const C: usize>: Send + Sync {
    /// The inertia `ρ_c(x)` of each component at `x`, each positive and finite.
    fn inertia(&self, x: f64) -> SVector<f64, C>;

    /// The potential energy density `U(x, u, u_x)` at `x`, of the field `u` and its slope `u_x`.
    fn potential<S: Scalar>(&self, x: f64, u: &SVector<S, C>, ux: &SVector<S, C>) -> S;
}
