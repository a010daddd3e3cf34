//! The unit sphere `S²` through the rotations that move its points: a tangent vector `w` at `q`
//! is the infinitesimal rotation `ω = q × w`, and the retraction is that rotation's Cayley or
//! exponential map acting on `q`,
//!
//! ```text
//! R_q(w) = τ(q × w) q = ((4 − |w|²) q + 4w) / (4 + |w|²)      (Cayley)
//!                     = cos|w| q + (sin|w| / |w|) w             (exp: the great circle)
//! R_q⁻¹(y) = 2 (y − (y·q) q) / (1 + y·q)                        (Cayley)
//!          = (θ / sin θ) (y − (y·q) q),  θ = ∠(q, y)            (exp)
//! ```
//!
//! A chart at `q` reads `w = B(q) ξ` in an orthonormal frame `B(q) = [b₁ b₂]` of the tangent
//! plane. The rotation `F = τ(q × B η)` carries `q` to `R_q(Bη)` and the frame with it, so the
//! chart at a moved point is the chart at `q` turned by `F`: `R_{Fq}(ζ) = F R_q(Bζ)`. Velocities
//! along a chart path are the time derivatives of the rotated point, `F τ(ω) (dτ_ω ω̇ × q)` with
//! `ω = q × Bζ` (see [`rotation`](crate::space::rotation)).

use nalgebra::{Matrix3, Matrix3x2, Vector2, Vector3};

use crate::base::scalar::Scalar;
use crate::space::rotation::{
    Retraction, angle_over_sine, sine_defect_ratio, sine_ratio, versine_ratio,
};

/// An orthonormal frame `(b₁, b₂)` of the tangent plane at the unit vector `q`, with
/// `b₁ × b₂ = q` (Duff et al.'s branch-free construction; it depends on `q` alone).
///
/// ```
/// use dirac_runtime::sphere::frame;
/// use nalgebra::vector;
/// let q = vector![0.0, 0.6, -0.8];
/// let b = frame(&q);
/// assert!((b.transpose() * b - nalgebra::Matrix2::identity()).amax() < 1e-15);
/// assert!((b.column(0).cross(&b.column(1)) - q).amax() < 1e-15);
/// ```
pub fn frame(q: &Vector3<f64>) -> Matrix3x2<f64> {
    let sign = 1.0_f64.copysign(q[2]);
    let a = -1.0 / (sign + q[2]);
    let b = q[0] * q[1] * a;
    Matrix3x2::new(
        1.0 + sign * q[0] * q[0] * a,
        b,
        sign * b,
        sign + q[1] * q[1] * a,
        -sign * q[0],
        -q[1],
    )
}

/// The rotation `τ(q × w)` that carries `q` along the tangent vector `w` (`R_q(w) = τ(q × w) q`).
pub fn carrier<D: Scalar>(retraction: Retraction, q: &Vector3<f64>, w: &Vector3<D>) -> Matrix3<D> {
    retraction.map(&turn(q, w))
}

/// The infinitesimal rotation `ω = q × w` that moves `q` along `w` (the carrier to first order:
/// `τ(ω) ≈ I + ω̂`).
pub fn turn<D: Scalar>(q: &Vector3<f64>, w: &Vector3<D>) -> Vector3<D> {
    Vector3::new(
        w[2] * q[1] - w[1] * q[2],
        w[0] * q[2] - w[2] * q[0],
        w[1] * q[0] - w[0] * q[1],
    )
}

/// `B z`: the tangent vector with coordinates `z` in the frame `B` (a known frame: products
/// with numbers alone).
pub(crate) fn in_frame<D: Scalar>(frame: &Matrix3x2<f64>, z: &Vector2<D>) -> Vector3<D> {
    Vector3::from_fn(|r, _| z[0] * frame[(r, 0)] + z[1] * frame[(r, 1)])
}

/// `Bᵀ w`: the coordinates of `w` in the frame `B`.
pub(crate) fn frame_coordinates<D: Scalar>(frame: &Matrix3x2<f64>, w: &Vector3<D>) -> Vector2<D> {
    Vector2::from_fn(|c, _| w[0] * frame[(0, c)] + w[1] * frame[(1, c)] + w[2] * frame[(2, c)])
}

/// `s q` for the known vector `q`.
fn scaled<D: Scalar>(q: &Vector3<f64>, s: D) -> Vector3<D> {
    Vector3::from_fn(|r, _| s * q[r])
}

/// `q · w` for the known vector `q`.
fn along<D: Scalar>(q: &Vector3<f64>, w: &Vector3<D>) -> D {
    w[0] * q[0] + w[1] * q[1] + w[2] * q[2]
}

/// `R_q(w)` for a tangent vector `w` at `q`.
///
/// ```
/// use dirac_runtime::rotation::Retraction;
/// use dirac_runtime::sphere::{local, retract};
/// use nalgebra::vector;
/// let q = vector![0.0, 0.0, 1.0];
/// for retraction in [Retraction::Cayley, Retraction::Exp] {
///     let y = retract(retraction, &q, &vector![0.3_f64, -0.4, 0.0]);
///     assert!((y.norm() - 1.0).abs() < 1e-15);
///     let w = local(retraction, &q, &y).expect("not antipodal");
///     assert!((w - vector![0.3, -0.4, 0.0]).amax() < 1e-15);
/// }
/// // The exponential follows the great circle: |w| is the angle.
/// let y = retract(Retraction::Exp, &q, &vector![0.5_f64, 0.0, 0.0]);
/// assert!((y[2] - 0.5_f64.cos()).abs() < 1e-16);
/// ```
pub fn retract<D: Scalar>(retraction: Retraction, q: &Vector3<f64>, w: &Vector3<D>) -> Vector3<D> {
    let w = tangent(q, w);
    let x = w.dot(&w);
    match retraction {
        Retraction::Cayley => cayley(q, &w, x),
        Retraction::Exp => scaled(q, -x * versine_ratio(x) + 1.0) + w * sine_ratio(x),
    }
}

/// `((4 − x) q + 4w) / (4 + x)`: the Cayley retraction at the tangent `w` with `x = |w|²`.
fn cayley<D: Scalar>(q: &Vector3<f64>, w: &Vector3<D>, x: D) -> Vector3<D> {
    (scaled(q, -x + 4.0) + w * D::from(4.0)) * (x + 4.0).recip()
}

/// The part of `w` tangent to the sphere at the unit vector `q`: the retraction reads no other
/// (`τ(q × w)` does not see `w`'s component along `q`).
fn tangent<D: Scalar>(q: &Vector3<f64>, w: &Vector3<D>) -> Vector3<D> {
    w - scaled(q, along(q, w))
}

/// `R_q⁻¹(y)`: the tangent vector at `q` that the retraction takes to the unit vector `y`, `None`
/// at the antipode (outside the chart).
pub fn local<D: Scalar>(
    retraction: Retraction,
    q: &Vector3<f64>,
    y: &Vector3<D>,
) -> Option<Vector3<D>> {
    let c = along(q, y);
    let tangent = y - scaled(q, c);
    match retraction {
        Retraction::Cayley => {
            let denominator = c + 1.0;
            (denominator.re() > 1e-12).then(|| tangent * (denominator.recip() * 2.0))
        }
        Retraction::Exp => angle_over_sine(tangent.dot(&tangent), c).map(|f| tangent * f),
    }
}

/// The velocity of `R_q(w(t))` for `w(t) = B ζ(t)` with `ẇ = B ζ̇`, the time derivative of
/// [`retract`]'s closed form (`x = |w|²`, `θ = |w|`, `y = R_q(w)`):
///
/// ```text
/// Cayley: ẏ = (4ẇ − 2(w·ẇ)(q + y)) / (4 + x)
/// exp:    ẏ = (sin θ/θ) ẇ − (w·ẇ) ((sin θ/θ) q + ((1 − cos θ)/θ² − (θ − sin θ)/θ³) w)
/// ```
///
/// (equal to `τ(ω) (dτ_ω ω̇ × q)` with `ω = q × w`, `ω̇ = q × ẇ`).
pub fn velocity<D: Scalar>(
    retraction: Retraction,
    q: &Vector3<f64>,
    w: &Vector3<D>,
    w_dot: &Vector3<D>,
) -> Vector3<D> {
    let (w, w_dot) = (tangent(q, w), tangent(q, w_dot));
    let (x, rate) = (w.dot(&w), w.dot(&w_dot));
    match retraction {
        Retraction::Cayley => {
            let y = cayley(q, &w, x);
            (w_dot * D::from(4.0) - (scaled(q, D::from(1.0)) + y) * (rate * 2.0))
                * (x + 4.0).recip()
        }
        Retraction::Exp => {
            let sinc = sine_ratio(x);
            w_dot * sinc - (scaled(q, sinc) + w * (versine_ratio(x) - sine_defect_ratio(x))) * rate
        }
    }
}

/// The chart velocities `ζ̇` at `ζ` (chart at `q` with frame `B`) whose velocity is the tangent
/// vector `v` at `R_q(Bζ)`: the least-squares solution of `M ζ̇ = v` with `M` the velocity map's
/// two columns (exact for a tangent `v`). `None` where `M` is singular.
pub fn chart_rate(
    retraction: Retraction,
    q: &Vector3<f64>,
    b: &Matrix3x2<f64>,
    zeta: &Vector2<f64>,
    v: &Vector3<f64>,
) -> Option<Vector2<f64>> {
    let m = velocity_map(retraction, q, b, zeta);
    (m.transpose() * m)
        .try_inverse()
        .map(|g| g * m.transpose() * v)
}

/// The covector at `R_q(Bζ)` (as a vector of the tangent plane there) whose pull-back to the
/// chart is `end`: `p = M (MᵀM)⁻¹ end`, for the point [`normalised`]: the radial projection
/// `y ↦ y/|y|` shrinks tangent vectors by `|y|`, so covectors grow by it (and `q × p`, the
/// angular momentum, is the same before and after). `None` where `M` is singular.
pub fn push_covector(
    retraction: Retraction,
    q: &Vector3<f64>,
    b: &Matrix3x2<f64>,
    zeta: &Vector2<f64>,
    end: &Vector2<f64>,
) -> Option<Vector3<f64>> {
    let m = velocity_map(retraction, q, b, zeta);
    let radius = retract(retraction, q, &(b * zeta)).norm();
    (m.transpose() * m)
        .try_inverse()
        .map(|g| m * g * end * radius)
}

/// `M`: the velocities of the chart's two coordinate directions at `ζ`.
fn velocity_map(
    retraction: Retraction,
    q: &Vector3<f64>,
    b: &Matrix3x2<f64>,
    zeta: &Vector2<f64>,
) -> Matrix3x2<f64> {
    let w = b * zeta;
    Matrix3x2::from_columns(&[
        velocity(retraction, q, &w, &b.column(0).into_owned()),
        velocity(retraction, q, &w, &b.column(1).into_owned()),
    ])
}

/// `q` normalised: the stepper applies it after every step so that `|q| = 1` holds to round-off
/// however long the run.
pub fn normalised(q: &Vector3<f64>) -> Vector3<f64> {
    q / q.norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::vector;

    #[test]
    fn velocities_are_the_derivatives_of_the_retraction() {
        let q = vector![0.36, -0.48, 0.8];
        let b = frame(&q);
        for retraction in [Retraction::Cayley, Retraction::Exp] {
            for zeta in [vector![0.0, 0.0], vector![0.3, -0.2], vector![1.2, 0.5]] {
                let w = b * zeta;
                for k in 0..2 {
                    let e = b.column(k).into_owned();
                    let eps = 1e-6;
                    let fd = (retract(retraction, &q, &(w + e * eps))
                        - retract(retraction, &q, &(w - e * eps)))
                        / (2.0 * eps);
                    let exact = velocity(retraction, &q, &w, &e);
                    assert!((fd - exact).amax() < 1e-9, "{retraction:?} {zeta} {k}");
                    // The closed form is the carrier's turn: τ(ω) (dτ_ω ω̇ × q).
                    let (omega, omega_dot) = (q.cross(&w), q.cross(&e));
                    let turning = retraction.differential(&omega) * omega_dot;
                    let carried = retraction.map(&omega) * turning.cross(&q);
                    assert!(
                        (carried - exact).amax() < 1e-15,
                        "{retraction:?} {zeta} {k}"
                    );
                    // Tangent at the moved point.
                    assert!(exact.dot(&retract(retraction, &q, &w)).abs() < 1e-15);
                }
                let y = retract(retraction, &q, &w);
                assert!((local(retraction, &q, &y).unwrap() - w).amax() < 1e-14);
                let v = velocity(retraction, &q, &w, &(b * vector![0.7, -1.1]));
                let rate = chart_rate(retraction, &q, &b, &zeta, &v).unwrap();
                assert!((rate - vector![0.7, -1.1]).amax() < 1e-13);
            }
        }
        assert!(local(Retraction::Cayley, &q, &(-q)).is_none());
    }

    #[test]
    fn the_carrier_moves_the_frame_with_the_point() {
        let q = vector![0.0, 0.6, 0.8];
        let w = frame(&q) * vector![0.4, 0.3];
        for retraction in [Retraction::Cayley, Retraction::Exp] {
            let f = carrier(retraction, &q, &w);
            assert!((f * q - retract(retraction, &q, &w)).amax() < 1e-15);
            assert!((f.transpose() * f - Matrix3::identity()).amax() < 1e-15);
        }
        for q in [
            vector![0.0, 0.0, -1.0],
            vector![1.0, 0.0, 0.0],
            vector![0.0, 0.0, 1.0],
        ] {
            let b = frame(&q);
            assert!((b.column(0).cross(&b.column(1)) - q).amax() < 1e-15);
        }
    }
}
