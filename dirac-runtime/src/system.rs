//! The trait a model implements: its Lagrangian, coordinate names, parameters and default quadrature.

use nalgebra::SVector;

use crate::quadrature::Quadrature;
use crate::scalar::Scalar;

/// A mechanical or electrical model on `Q = R^N`, described by its continuous Lagrangian `L(q, v)`.
///
/// `#[dirac_system(...)]` implements this trait; writing the `impl` by hand works the same way.
/// Only [`lagrangian`](Self::lagrangian) is required; it must be generic over the [`Scalar`] so the
/// runtime can differentiate it exactly with dual numbers.
///
/// ```
/// use dirac_runtime::{DiracSystem, Scalar, Quadrature, Stepper};
/// use nalgebra::{SVector, vector};
///
/// /// A harmonic oscillator, L = m v²/2 − k q²/2.
/// struct Oscillator { m: f64, k: f64 }
///
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * (0.5 * self.m) - q[0] * q[0] * (0.5 * self.k)
///     }
/// }
///
/// let mut stepper = Stepper::new(Oscillator { m: 1.0, k: 1.0 }, Quadrature::midpoint(), 0.1)?;
/// stepper.start_from_momentum(vector![1.0], vector![0.0])?;
/// stepper.step()?;
/// assert!((stepper.q()[0] - 0.1_f64.cos()).abs() < 1e-3);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
pub trait DiracSystem<const N: usize> {
    /// The continuous Lagrangian `L(q, v)` at position `q` and velocity `v`.
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, N>, v: &SVector<D, N>) -> D;

    /// The name of coordinate `i` (`0 <= i < N`), used in CSV headers and error messages.
    fn coordinate_name(&self, i: usize) -> String {
        format!("q{i}")
    }

    /// The model's parameters by name, checked to be finite when a stepper is built.
    fn parameters(&self) -> Vec<(String, f64)> {
        Vec::new()
    }

    /// The quadrature a stepper uses when none is named ([`Stepper::from_system`](crate::Stepper::from_system)).
    fn quadrature(&self) -> Quadrature {
        Quadrature::midpoint()
    }
}
