//! The state a step starts from and ends in: time, position and momentum.

use nalgebra::SVector;

use crate::space::manifold::{Manifold, Vectors};

/// The state a stepper advances: time, position and momentum, with a velocity near the one at
/// `(q, p)` and the round-off its compensated updates carry.
///
/// ```
/// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
/// struct Free;
/// impl DiracSystem<1> for Free {
///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 0.5
///     }
/// }
/// let mut stepper = Stepper::new(Free, Quadrature::midpoint(), 0.5)?;
/// stepper.start_from_velocity(vector![0.0], vector![2.0])?;
/// stepper.step()?;
/// let state = stepper.state().expect("started");
/// assert_eq!((state.t(), state.q()[0], state.p()[0]), (0.5, 1.0, 2.0));
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State<const N: usize, M: Manifold<N> = Vectors> {
    pub(crate) t: f64,
    pub(crate) q: M::Point<f64>,
    pub(crate) p: M::Tangent<f64>,
    /// A velocity near the one at `(q, p)`: the initial velocity, then the last step's velocity
    /// at its end. It seeds the first predictor and the Legendre inversion.
    pub(crate) velocity: M::Tangent<f64>,
    /// Round-off left out of `q` and `p` by compensated updates. A unit vector, projected
    /// onto its sphere rather than summed, lends its two entries of `q_carry` to its momentum:
    /// the first holds the component along `q` of its angular momentum that a tangent `p`
    /// cannot hold
    /// ([`advance_momentum_turned`](crate::space::configuration_space::ConfigurationSpace::advance_momentum_turned)).
    pub(crate) q_carry: SVector<f64, N>,
    pub(crate) p_carry: SVector<f64, N>,
}

impl<const N: usize, M: Manifold<N>> State<N, M> {
    /// The state at time `t`, position `q`, momentum `p`, with `velocity` a velocity near the
    /// one at `(q, p)` (exact or approximate: it seeds solves, it is never trusted).
    pub fn new(t: f64, q: M::Point<f64>, p: M::Tangent<f64>, velocity: M::Tangent<f64>) -> Self {
        Self {
            t,
            q,
            p,
            velocity,
            q_carry: SVector::zeros(),
            p_carry: SVector::zeros(),
        }
    }

    /// Time.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Position.
    pub fn q(&self) -> &M::Point<f64> {
        &self.q
    }

    /// Momentum.
    pub fn p(&self) -> &M::Tangent<f64> {
        &self.p
    }

    /// A velocity near the one at `(q, p)` (the last step's velocity at its end), the seed of
    /// the exact velocity [`Stepper::v`](crate::Stepper::v) solves for.
    pub fn velocity_hint(&self) -> &M::Tangent<f64> {
        &self.velocity
    }
}
