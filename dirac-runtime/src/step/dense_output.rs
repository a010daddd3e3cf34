//! Dense output: the solution at any time inside a step.
//!
//! A step's path is the polynomial of degree `s` through `q_k`, the internal points and `q_{k+1}`
//! (in the chart centred at `q_k`, at the equispaced fractions `θ_j = j/s` of the step). Its
//! slopes at the ends differ from the velocities of the end states by `O(hˢ)`; the dense output
//! removes those defects `δ₀, δ₁` with a correction that vanishes at every point of the path,
//!
//! ```text
//! ξ(θ) = path(θ) + h ω(θ) (α + β θ),   ω(θ) = Π_j (θ − θ_j),
//! α = δ₀ / ω'(0),   α + β = δ₁ / ω'(1),
//! ```
//!
//! a polynomial of degree `s + 2` through the step's points with the end states' velocities as
//! its end slopes (for `s = 1`, the cubic Hermite interpolant). Positions pass through `q_k` and
//! `q_{k+1}`, velocities are their time derivative and equal the end states' velocities: the
//! interpolant is C¹ across steps. The momentum is `∂L/∂v` along it plus the linear blend of its
//! defects at the ends (zero for an unconstrained regular model), so it passes through `p_k` and
//! `p_{k+1}`.
//!
//! Measured orders (`tests/suite/run.rs`, oscillator, 7 points inside every step): positions 2, 4, 4
//! and velocities and momenta 2, 3, 3 for the midpoint rule, `galerkin(2)` and `galerkin(3)`. The
//! internal points are accurate to `O(h^{s+1})` only, so inside a step `galerkin(3)` is of order
//! 4, not 6 (ten times more accurate than `galerkin(2)` at the same step).

use nalgebra::SVector;

use crate::quadrature::{MAX_DEGREE, Quadrature};
use crate::space::configuration_space::ConfigurationSpace;
use crate::space::manifold::{Manifold, Vectors};

/// The solution at one time: position, velocity and momentum.
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
/// let sample = stepper.interpolate(0.25)?;
/// assert_eq!((sample.t, sample.q[0], sample.v[0], sample.p[0]), (0.25, 0.5, 2.0, 2.0));
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(bound(
        serialize = "M::Point<f64>: serde::Serialize, M::Tangent<f64>: serde::Serialize",
        deserialize = "M::Point<f64>: serde::Deserialize<'de>, \
                       M::Tangent<f64>: serde::Deserialize<'de>"
    ))
)]
pub struct Sample<const N: usize, M: Manifold<N> = Vectors> {
    /// Time.
    pub t: f64,
    /// Position.
    pub q: M::Point<f64>,
    /// Velocity.
    pub v: M::Tangent<f64>,
    /// Momentum.
    pub p: M::Tangent<f64>,
}

/// The dense output's path in the chart centred at the step's start `a`: its value and rate at
/// fraction `theta` of the step between the samples `a` and `b` whose internal points are
/// `internal` (chart coordinates at `a.q`), with the end slopes corrected to the samples'
/// velocities; also the end point's chart coordinates. `None` where a chart map fails.
pub(crate) fn chart_path<C: ConfigurationSpace<N>, const N: usize>(
    space: &C,
    quadrature: &Quadrature,
    h: f64,
    ends: [&Sample<N, C::Manifold>; 2],
    internal: impl Iterator<Item = SVector<f64, N>>,
    theta: f64,
) -> Option<ChartPath<N>> {
    let [a, b] = ends;
    let end = space.local(&a.q, &b.q)?;
    // The path's points, on the stack (a step has at most MAX_DEGREE).
    let mut stack = [SVector::<f64, N>::zeros(); MAX_DEGREE];
    let mut count = 0;
    for (slot, point) in stack.iter_mut().zip(internal.chain(std::iter::once(end))) {
        *slot = point;
        count += 1;
    }
    let points = &stack[..count];
    let (_, start_rate) = quadrature.path_through(0.0, points, h);
    let (_, end_rate) = quadrature.path_through(1.0, points, h);
    let d0 = space.chart_velocity(&a.q, &a.v)? - start_rate;
    let d1 = space.chart_rate(&a.q, &end, &b.v)? - end_rate;
    let (path, rate) = quadrature.path_through(theta, points, h);
    let (correction, rate_correction) = end_slope_correction(theta, h, points.len(), &d0, &d1);
    Some(ChartPath {
        xi: path + correction,
        xi_dot: rate + rate_correction,
        end,
    })
}

/// A point of the dense output's path in the chart at the step's start (see [`chart_path`]).
pub(crate) struct ChartPath<const N: usize> {
    pub xi: SVector<f64, N>,
    pub xi_dot: SVector<f64, N>,
    /// The chart coordinates of the step's end.
    pub end: SVector<f64, N>,
}

/// The correction at fraction `theta` of a step of size `h` whose path has degree `degree`, from
/// the defects `d0`, `d1` of the path's rates at the ends: its value (`h ω (α + β θ)`) and its
/// rate in time.
fn end_slope_correction<const N: usize>(
    theta: f64,
    h: f64,
    degree: usize,
    d0: &SVector<f64, N>,
    d1: &SVector<f64, N>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    let grid = |j: usize| j as f64 / degree as f64;
    let omega = |t: f64| (0..=degree).map(|j| t - grid(j)).product::<f64>();
    let omega_dot = |t: f64| {
        (0..=degree)
            .map(|l| {
                (0..=degree)
                    .filter(|&j| j != l)
                    .map(|j| t - grid(j))
                    .product::<f64>()
            })
            .sum::<f64>()
    };
    let alpha = d0 / omega_dot(0.0);
    let beta = d1 / omega_dot(1.0) - alpha;
    let linear = alpha + beta * theta;
    (
        linear * (h * omega(theta)),
        linear * omega_dot(theta) + beta * omega(theta),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::vector;

    /// The correction vanishes at every point of the path, with slope `d0` at the start and
    /// `d1` at the end, and its rate is the time derivative of its value.
    #[test]
    fn end_slope_correction_matches_the_end_defects() {
        let (d0, d1, h) = (vector![1.5, -2.0], vector![0.25, 3.0], 0.1);
        for degree in 1..=4 {
            for j in 0..=degree {
                let (x, _) = end_slope_correction(j as f64 / degree as f64, h, degree, &d0, &d1);
                assert!(x.amax() < 1e-15, "degree {degree}, point {j}: {x}");
            }
            let (_, r0) = end_slope_correction(0.0, h, degree, &d0, &d1);
            let (_, r1) = end_slope_correction(1.0, h, degree, &d0, &d1);
            assert!((r0 - d0).amax() < 1e-14 && (r1 - d1).amax() < 1e-14);
            let (theta, e) = (0.3, 1e-6);
            let (plus, _) = end_slope_correction(theta + e, h, degree, &d0, &d1);
            let (minus, _) = end_slope_correction(theta - e, h, degree, &d0, &d1);
            let (_, rate) = end_slope_correction(theta, h, degree, &d0, &d1);
            assert!(((plus - minus) / (2.0 * e * h) - rate).amax() < 1e-7);
        }
    }
}
