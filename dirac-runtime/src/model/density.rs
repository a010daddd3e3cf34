//! Lagrangian densities of fields `u(t, x) ∈ Rᶜ` on an interval of the line
//! ([`SeparableDensity`]) and on a rectangle of the plane ([`PlaneDensity`]).
//!
//! A field's action is `∫∫ ℒ(x, u, u_t, u_x) dx dt`. The class held here is the separable one,
//! `ℒ = ½ Σ_c ρ_c(x) u_{t,c}² − U(x, u, u_x)`: a kinetic energy density with a positive inertia
//! per component, and a potential energy density of the field and its slope. It holds the
//! nonlinear wave equations `ρ u_tt = ∂_x U_{u_x} − U_u`: the string and the elastic bar, the
//! Klein–Gordon, sine-Gordon and φ⁴ fields, chains of coupled components. Its space–time cells
//! give an explicit step ([`Field`](crate::step::field::Field)). On the plane the slope is the
//! gradient `(u_x, u_y)`: the membrane, anisotropic and nonlinear media, the Klein–Gordon and
//! sine-Gordon fields in two dimensions ([`PlaneField`](crate::step::field::plane::PlaneField)).

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

/// The Lagrangian density `ℒ = ½ Σ_c ρ_c(x, y) u_{t,c}² − U((x, y), u, u_x, u_y)` of a field
/// with `C` components on the plane.
///
/// [`potential`](Self::potential) is generic over the scalar, so that the same code yields the
/// density's value and, through dual numbers, its exact derivatives.
///
/// ```
/// use dirac_runtime::nalgebra::SVector;
/// use dirac_runtime::{PlaneDensity, Scalar};
///
/// /// A membrane under tension `κ`: `ℒ = ½ u_t² − ½ κ (u_x² + u_y²)`.
/// struct Membrane {
///     kappa: f64,
/// }
/// impl PlaneDensity<1> for Membrane {
///     fn inertia(&self, _at: [f64; 2]) -> SVector<f64, 1> {
///         SVector::from([1.0])
///     }
///     fn potential<S: Scalar>(
///         &self,
///         _at: [f64; 2],
///         _u: &SVector<S, 1>,
///         ux: &SVector<S, 1>,
///         uy: &SVector<S, 1>,
///     ) -> S {
///         (ux[0] * ux[0] + uy[0] * uy[0]) * (0.5 * self.kappa)
///     }
/// }
/// let (zero, one) = (SVector::from([0.0]), SVector::from([1.0]));
/// assert_eq!(Membrane { kappa: 2.0 }.potential([0.0, 0.0], &zero, &one, &one), 2.0);
/// ```
pub trait PlaneDensity<const C: usize>: Send + Sync {
    /// The inertia `ρ_c(x, y)` of each component at `at = [x, y]`, each positive and finite.
    fn inertia(&self, at: [f64; 2]) -> SVector<f64, C>;

    /// The potential energy density `U` at `at = [x, y]`, of the field `u` and its slopes `u_x`
    /// and `u_y`.
    fn potential<S: Scalar>(
        &self,
        at: [f64; 2],
        u: &SVector<S, C>,
        ux: &SVector<S, C>,
        uy: &SVector<S, C>,
    ) -> S;
}
