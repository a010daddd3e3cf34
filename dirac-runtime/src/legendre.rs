//! The Legendre transform: momentum from velocity, velocity from momentum, and the energy.

use nalgebra::{DVector, SVector};

use crate::derivatives::{Seed, degenerate, seeded};
use crate::newton::{Newton, NewtonFailure};
use crate::system::DiracSystem;

/// `p = ∂L/∂v (q, v)`.
///
/// ```
/// use dirac_runtime::{DiracSystem, Scalar, legendre};
/// use nalgebra::{SVector, vector};
/// struct Particle;
/// impl DiracSystem<1> for Particle {
///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 1.5 // mass 3
///     }
/// }
/// assert_eq!(legendre::momentum(&Particle, &vector![0.0], &vector![2.0])[0], 6.0);
/// ```
pub fn momentum<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> SVector<f64, N> {
    seeded(system, q, v, Seed::VELOCITY, Seed::NONE).first
}

/// The energy `E = ⟨p, v⟩ − L(q, v)`.
///
/// ```
/// use dirac_runtime::{DiracSystem, Scalar, legendre};
/// use nalgebra::{SVector, vector};
/// struct Spring;
/// impl DiracSystem<1> for Spring {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         (v[0] * v[0] - q[0] * q[0]) * 0.5
///     }
/// }
/// assert_eq!(legendre::energy(&Spring, &vector![1.0], &vector![1.0]), 1.0);
/// ```
pub fn energy<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> f64 {
    let l = seeded(system, q, v, Seed::VELOCITY, Seed::NONE);
    l.first.dot(v) - l.value
}

/// Inverts the Legendre transform: solves `∂L/∂v (q, v) = p` for `v` by Newton's method from
/// `guess`, with the exact Hessian `∂²L/∂v²`. `newton` must be sized for `N` unknowns.
///
/// Velocities without kinetic energy (rows of `∂²L/∂v²` that vanish at the guess) are not
/// determined by `p`; they keep their guess, and the energy does not depend on them.
pub(crate) fn velocity<S: DiracSystem<N>, const N: usize>(
    system: &S,
    newton: &mut Newton,
    q: &SVector<f64, N>,
    p: &SVector<f64, N>,
    guess: &SVector<f64, N>,
) -> Result<SVector<f64, N>, NewtonFailure> {
    let dead = degenerate(system, q, guess);
    let mut x = DVector::from_column_slice(guess.as_slice());
    newton.solve(&mut x, |x, r, j| {
        let v = SVector::<f64, N>::from_column_slice(x.as_slice());
        let l = seeded(system, q, &v, Seed::VELOCITY, Seed::VELOCITY);
        r.copy_from(&(l.first - p));
        j.copy_from(&l.mixed);
        for &i in &dead {
            r[i] = x[i] - guess[i];
            j.row_mut(i).fill(0.0);
            j[(i, i)] = 1.0;
        }
        l.first.abs().sup(&p.abs()).amax()
    })?;
    Ok(SVector::from_column_slice(x.as_slice()))
}
