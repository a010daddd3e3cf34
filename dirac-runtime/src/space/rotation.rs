//! Rotations `SO(3)`: the hat map, the Cayley and exponential retractions `τ: so(3) → SO(3)`,
//! their inverses (the charts) and their left-trivialised differentials, generic over the
//! [`Scalar`] so that dual numbers differentiate through them.
//!
//! A vector `ξ ∈ R³` stands for the skew matrix `ξ̂` (`ξ̂ y = ξ × y`), and `vee(M)` is the axial
//! vector of `M − Mᵀ` (`vee(ξ̂) = 2ξ`). For a path `ξ(t)` the
//! rotation `τ(ξ(t))` turns with the body angular velocity `Ω = dτ_ξ ξ̇`, where
//! `τ(ξ)ᵀ d/dt τ(ξ) = Ω̂` defines the left-trivialised differential `dτ_ξ`:
//!
//! ```text
//! Cayley:  τ(ξ) = (I − ξ̂/2)⁻¹ (I + ξ̂/2) = I + α (ξ̂ + ξ̂²/2),   α = 4/(4 + |ξ|²)
//!          dτ_ξ = α (I − ξ̂/2),          dτ_ξ⁻¹ = I + ξ̂/2 + ξξᵀ/4,
//!          τ⁻¹(F) = 2 vee(F) / (1 + tr F)
//! exp:     τ(ξ) = I + a ξ̂ + b ξ̂²,   a = sin θ/θ,  b = (1 − cos θ)/θ²,  θ = |ξ|
//!          dτ_ξ = I − b ξ̂ + c ξ̂²,   c = (θ − sin θ)/θ³,
//!          dτ_ξ⁻¹ = I + ξ̂/2 + e ξ̂², e = (1 − (θ/2) cot(θ/2))/θ²,
//!          τ⁻¹(F) = (θ/sin θ) vee(F)/2,  θ = atan2(|vee(F)|/2, (tr F − 1)/2)
//! ```
//!
//! The functions of `θ` are evaluated as functions of `θ²` with their Taylor series near 0, so
//! their derivatives stay finite at `ξ = 0` (a body at rest).

use nalgebra::{Matrix3, Vector3};

use crate::base::scalar::Scalar;

/// The retraction from the Lie algebra: the Cayley map (rational, the default) or the
/// exponential map.
///
/// ```
/// use dirac_runtime::rotation::Retraction;
/// use nalgebra::vector;
///
/// let xi = vector![0.3, -0.2, 0.5];
/// for retraction in [Retraction::Cayley, Retraction::Exp] {
///     let f = retraction.map(&xi);
///     assert!((f.transpose() * f - nalgebra::Matrix3::identity()).amax() < 1e-15);
///     let back = retraction.inverse(&f).expect("inside the chart");
///     assert!((back - xi).amax() < 1e-15);
/// }
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Retraction {
    /// `τ(ξ) = (I − ξ̂/2)⁻¹(I + ξ̂/2)`: rational, no trigonometric functions.
    #[default]
    Cayley,
    /// `τ(ξ) = exp(ξ̂)`: one-parameter subgroups, `τ(tξ)` turns at the constant rate `ξ`.
    Exp,
}

impl Retraction {
    /// `τ(ξ)`.
    pub fn map<D: Scalar>(self, xi: &Vector3<D>) -> Matrix3<D> {
        let x = xi.dot(xi);
        let one = D::from(1.0);
        match self {
            Retraction::Cayley => {
                let alpha = (x + 4.0).recip() * 4.0;
                combination(xi, one, alpha, alpha * 0.5)
            }
            Retraction::Exp => combination(xi, one, sine_ratio(x), versine_ratio(x)),
        }
    }

    /// `τ⁻¹(F)` for a rotation `F` within the chart (rotation angle below π), `None` outside it.
    pub fn inverse<D: Scalar>(self, f: &Matrix3<D>) -> Option<Vector3<D>> {
        let trace = f[(0, 0)] + f[(1, 1)] + f[(2, 2)];
        let w = vee(f);
        match self {
            Retraction::Cayley => {
                let denominator = trace + 1.0;
                (denominator.re() > 1e-12).then(|| w * (denominator.recip() * 2.0))
            }
            Retraction::Exp => {
                let half = w * D::from(0.5);
                let cosine = (trace - 1.0) * 0.5;
                angle_over_sine(half.dot(&half), cosine).map(|f| half * f)
            }
        }
    }

    /// The left-trivialised differential `dτ_ξ`: `Ω = dτ_ξ ξ̇` along a path `ξ(t)`.
    pub fn differential<D: Scalar>(self, xi: &Vector3<D>) -> Matrix3<D> {
        let x = xi.dot(xi);
        match self {
            Retraction::Cayley => {
                let alpha = (x + 4.0).recip() * 4.0;
                combination(xi, alpha, alpha * -0.5, D::from(0.0))
            }
            Retraction::Exp => {
                combination(xi, D::from(1.0), -versine_ratio(x), sine_defect_ratio(x))
            }
        }
    }

    /// `(ψ, κ)` with `dτ_ξ ξ = ψ(ξ) ξ` and `∇ψ(ξ) = κ ξ`: the angular velocity along the ray
    /// `t ξ` is `ψ(tξ) ξ`. Cayley: `ψ = 4/(4 + |ξ|²)`, `κ = −ψ²/2`; exp: `ψ = 1`, `κ = 0`.
    ///
    /// ```
    /// use dirac_runtime::rotation::Retraction;
    /// use nalgebra::vector;
    /// let xi = vector![0.3, -0.2, 0.5];
    /// for retraction in [Retraction::Cayley, Retraction::Exp] {
    ///     let (psi, _) = retraction.rate_factor(&xi);
    ///     assert!((retraction.differential(&xi) * xi - xi * psi).amax() < 1e-15);
    /// }
    /// ```
    pub fn rate_factor<D: Scalar>(self, xi: &Vector3<D>) -> (D, D) {
        match self {
            Retraction::Cayley => {
                let psi = (xi.dot(xi) + 4.0).recip() * 4.0;
                (psi, psi * psi * -0.5)
            }
            Retraction::Exp => (D::from(1.0), D::from(0.0)),
        }
    }

    /// `dτ_ξ⁻ᵀ π`: the body momentum at `R τ(ξ)` whose pull-back to the chart at `R` is `π`
    /// (`dτ_ξᵀ` inverted numerically; `None` where it is singular). The step's end momentum and
    /// its first slot read it the same way: without forces, one-forms or junctions the two then
    /// agree to the last bit, and the momentum maps are kept without drift (a closed form of
    /// `dτ_ξ⁻ᵀ` on one side rounds differently, and made the free body's spatial momentum drift).
    pub fn body_momentum(self, xi: &Vector3<f64>, pi: &Vector3<f64>) -> Option<Vector3<f64>> {
        Some(self.differential(xi).transpose().try_inverse()? * pi)
    }

    /// `dτ_ξ⁻¹`: the chart velocity `ξ̇` of the angular velocity `Ω`.
    pub fn differential_inverse<D: Scalar>(self, xi: &Vector3<D>) -> Matrix3<D> {
        let x = xi.dot(xi);
        let half = D::from(0.5);
        match self {
            // I + ξ̂/2 + ξξᵀ/4, with ξξᵀ = ξ̂² + |ξ|² I.
            Retraction::Cayley => combination(xi, x * 0.25 + 1.0, half, D::from(0.25)),
            Retraction::Exp => combination(xi, D::from(1.0), half, cotangent_defect_ratio(x)),
        }
    }
}

/// `c₀ I + c₁ ξ̂ + c₂ ξ̂²` entry by entry (`ξ̂² = ξξᵀ − |ξ|² I`), without matrix products: the
/// maps above are all of this form.
fn combination<D: Scalar>(xi: &Vector3<D>, c0: D, c1: D, c2: D) -> Matrix3<D> {
    let x = xi.dot(xi);
    let diagonal = c0 - c2 * x;
    let (a, b, c) = (xi[0] * c1, xi[1] * c1, xi[2] * c1);
    let (ab, ac, bc) = (xi[0] * xi[1] * c2, xi[0] * xi[2] * c2, xi[1] * xi[2] * c2);
    Matrix3::new(
        diagonal + xi[0] * xi[0] * c2,
        ab - c,
        ac + b,
        ab + c,
        diagonal + xi[1] * xi[1] * c2,
        bc - a,
        ac - b,
        bc + a,
        diagonal + xi[2] * xi[2] * c2,
    )
}

/// `a b` entry by entry (nalgebra's generic product clones every dual number several times).
pub(crate) fn product<D: Scalar>(a: &Matrix3<D>, b: &Matrix3<D>) -> Matrix3<D> {
    Matrix3::from_fn(|i, j| a[(i, 0)] * b[(0, j)] + a[(i, 1)] * b[(1, j)] + a[(i, 2)] * b[(2, j)])
}

/// `a b` for a rotation `a` known in `f64`.
pub(crate) fn product_known<D: Scalar>(a: &Matrix3<f64>, b: &Matrix3<D>) -> Matrix3<D> {
    Matrix3::from_fn(|i, j| b[(0, j)] * a[(i, 0)] + b[(1, j)] * a[(i, 1)] + b[(2, j)] * a[(i, 2)])
}

/// `a v` entry by entry.
pub(crate) fn apply<D: Scalar>(a: &Matrix3<D>, v: &Vector3<D>) -> Vector3<D> {
    Vector3::from_fn(|i, _| a[(i, 0)] * v[0] + a[(i, 1)] * v[1] + a[(i, 2)] * v[2])
}

/// `ξ̂`, the skew matrix with `ξ̂ y = ξ × y`.
///
/// ```
/// use dirac_runtime::rotation::{hat, vee};
/// use nalgebra::vector;
/// let (a, b) = (vector![1.0, 2.0, 3.0], vector![-1.0, 0.5, 2.0]);
/// assert_eq!(hat(&a) * b, a.cross(&b));
/// assert_eq!(vee(&hat(&a)), a * 2.0); // vee reads the skew part of M − Mᵀ
/// ```
pub fn hat<D: Scalar>(xi: &Vector3<D>) -> Matrix3<D> {
    let zero = D::from(0.0);
    Matrix3::new(
        zero, -xi[2], xi[1], //
        xi[2], zero, -xi[0], //
        -xi[1], xi[0], zero,
    )
}

/// `(M₃₂ − M₂₃, M₁₃ − M₃₁, M₂₁ − M₁₂)`: `vee(ξ̂) = 2ξ`, the axial vector of `M − Mᵀ`.
pub fn vee<D: Scalar>(m: &Matrix3<D>) -> Vector3<D> {
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    )
}

/// The attitude `R` (body to space) as a unit quaternion `[w, x, y, z]` with `w ≥ 0`:
/// `R = (w² − |v|²) I + 2 v vᵀ + 2 w v̂`, `v = (x, y, z)`; a rotation by `θ` about the unit axis
/// `a` is `[cos(θ/2), sin(θ/2) a]`.
///
/// ```
/// use dirac_runtime::rotation::{Retraction, quaternion};
/// use nalgebra::Vector3;
/// let r = Retraction::Exp.map(&Vector3::new(0.0, 0.0, 1.0)); // 1 rad about z
/// let q = quaternion(&r);
/// assert!((q[0] - 0.5_f64.cos()).abs() < 1e-15 && (q[3] - 0.5_f64.sin()).abs() < 1e-15);
/// ```
pub fn quaternion(r: &Matrix3<f64>) -> [f64; 4] {
    let rotation = nalgebra::Rotation3::from_matrix_unchecked(*r);
    let q = nalgebra::UnitQuaternion::from_rotation_matrix(&rotation);
    let sign = if q.w < 0.0 { -1.0 } else { 1.0 };
    [q.w, q.i, q.j, q.k].map(|c| c * sign)
}

/// The attitude `R` (body to space) as Euler angles `[roll, pitch, yaw]` about the body's
/// `x`, `y` and `z` axes in that order of rotation (`R = R_z(yaw) R_y(pitch) R_x(roll)`, the
/// aerospace z-y-x convention), with `pitch ∈ [−π/2, π/2]`.
///
/// ```
/// use dirac_runtime::rotation::euler_angles;
/// use nalgebra::{Rotation3, Vector3};
/// let r = Rotation3::from_euler_angles(0.1, -0.2, 0.3).into_inner();
/// let [roll, pitch, yaw] = euler_angles(&r);
/// assert!((roll - 0.1).abs() < 1e-15 && (pitch + 0.2).abs() < 1e-15 && (yaw - 0.3).abs() < 1e-15);
/// ```
pub fn euler_angles(r: &Matrix3<f64>) -> [f64; 3] {
    let (roll, pitch, yaw) = nalgebra::Rotation3::from_matrix_unchecked(*r).euler_angles();
    [roll, pitch, yaw]
}

/// `R (3I − RᵀR)/2`: one Newton step of the polar decomposition, which takes a matrix within
/// `ε` of a rotation to within `O(ε²)`; the stepper applies it after every step so that `RᵀR = I`
/// holds to round-off however long the run.
pub fn orthonormalised(r: &Matrix3<f64>) -> Matrix3<f64> {
    r * (Matrix3::identity() * 3.0 - r.transpose() * r) * 0.5
}

/// Where the series of a function of `θ²` takes over from its closed form. Below it the series'
/// first omitted term is below 1e-19 of the value; above it the closed forms of
/// `(θ − sin θ)/θ³` and `(1 − (θ/2) cot(θ/2))/θ²` cancel by factors of at most 6 and 12. Both
/// are within 2e-15 (relative) of long series that do not cancel for `θ² ≤ 4` (`tests` below).
const SERIES: f64 = 1.0;

/// `Σ_k c_k x^k` by Horner's rule.
fn series<D: Scalar>(x: D, coefficients: &[f64]) -> D {
    coefficients
        .iter()
        .rev()
        .fold(D::from(0.0), |sum, &c| sum * x + c)
}

/// `sin θ / θ` as a function of `x = θ²`.
pub(crate) fn sine_ratio<D: Scalar>(x: D) -> D {
    if x.re() < SERIES {
        // (−1)^k / (2k + 1)!
        series(
            x,
            &[
                1.0,
                -1.0 / 6.0,
                1.0 / 120.0,
                -1.0 / 5040.0,
                1.0 / 362880.0,
                -1.0 / 39916800.0,
                1.0 / 6227020800.0,
                -1.0 / 1307674368000.0,
                1.0 / 355687428096000.0,
                -1.0 / 121645100408832000.0,
            ],
        )
    } else {
        let theta = x.sqrt();
        theta.sin() / theta
    }
}

/// `(1 − cos θ)/θ² = ½ (sin(θ/2)/(θ/2))²` as a function of `x = θ²` (no cancellation).
pub(crate) fn versine_ratio<D: Scalar>(x: D) -> D {
    let half = sine_ratio(x * 0.25);
    half * half * 0.5
}

/// `(θ − sin θ)/θ³` as a function of `x = θ²`.
pub(crate) fn sine_defect_ratio<D: Scalar>(x: D) -> D {
    if x.re() < SERIES {
        // (−1)^k / (2k + 3)!
        series(
            x,
            &[
                1.0 / 6.0,
                -1.0 / 120.0,
                1.0 / 5040.0,
                -1.0 / 362880.0,
                1.0 / 39916800.0,
                -1.0 / 6227020800.0,
                1.0 / 1307674368000.0,
                -1.0 / 355687428096000.0,
                1.0 / 121645100408832000.0,
            ],
        )
    } else {
        let theta = x.sqrt();
        (theta - theta.sin()) / (x * theta)
    }
}

/// `(1 − (θ/2) cot(θ/2))/θ²` as a function of `x = θ²`.
fn cotangent_defect_ratio<D: Scalar>(x: D) -> D {
    if x.re() < SERIES {
        // |B_{2n}| / (2n)! for n = 1, 2, ... (Bernoulli numbers).
        series(
            x,
            &[
                1.0 / 12.0,
                1.0 / 720.0,
                1.0 / 30240.0,
                1.0 / 1209600.0,
                1.0 / 47900160.0,
                691.0 / 1307674368000.0,
                7.0 / 523069747200.0,
                3617.0 / 10670622842880000.0,
                43867.0 / 5109094217170944000.0,
                174611.0 / 802857662698291200000.0,
                77683.0 / 14101100039391805440000.0,
                236364091.0 / 1693824136731743669452800000.0,
            ],
        )
    } else {
        let half = x.sqrt() * 0.5;
        (-(half / half.tan()) + 1.0) / x
    }
}

/// `θ / sin θ` for the angle `θ = atan2(s, c)` given `s² = sin²θ · r²` and `c = cos θ · r`
/// (`r > 0`, so that `θ` is the angle of the point `(c, s)`), divided by `r`: the factor that
/// turns `s · axis` into `θ · axis`. `None` at the chart's boundary (`θ` near π, where the axis is
/// lost). A series in `(s/c)²` near `θ = 0` keeps the derivatives finite there.
pub(crate) fn angle_over_sine<D: Scalar>(s2: D, c: D) -> Option<D> {
    let (s2_re, c_re) = (s2.re(), c.re());
    if c_re > 0.0 && s2_re < 0.01 * c_re * c_re {
        // atan(√y)/√y = Σ (−1)^k y^k / (2k + 1), y = (s/c)² < 0.01.
        let y = s2 / (c * c);
        let g = series(
            y,
            &[
                1.0,
                -1.0 / 3.0,
                1.0 / 5.0,
                -1.0 / 7.0,
                1.0 / 9.0,
                -1.0 / 11.0,
                1.0 / 13.0,
                -1.0 / 15.0,
                1.0 / 17.0,
            ],
        );
        return Some(g / c);
    }
    let s = s2.sqrt();
    // Beyond ~179.9° the axis is lost in round-off: outside the chart.
    if s.re() <= 1e-3 * c_re.abs() && c_re < 0.0 {
        return None;
    }
    Some(s.atan2(c) / s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::vector;
    use num_dual::{Derivative, DualSVec64};

    const BOTH: [Retraction; 2] = [Retraction::Cayley, Retraction::Exp];

    /// Central difference of `f` along `d` at `x`.
    fn fd<F: Fn(&Vector3<f64>) -> Matrix3<f64>>(
        f: F,
        x: &Vector3<f64>,
        d: &Vector3<f64>,
    ) -> Matrix3<f64> {
        let eps = 1e-6;
        (f(&(x + d * eps)) - f(&(x - d * eps))) / (2.0 * eps)
    }

    #[test]
    fn maps_are_rotations_and_the_charts_invert_them() {
        for retraction in BOTH {
            for xi in [
                vector![0.0_f64, 0.0, 0.0],
                vector![1e-9, -2e-9, 0.5e-9],
                vector![0.1, 0.2, -0.3],
                vector![1.0, -2.0, 0.7],
            ] {
                let f = retraction.map(&xi);
                assert!((f.transpose() * f - Matrix3::identity()).amax() < 1e-15);
                assert!((f.determinant() - 1.0).abs() < 1e-15);
                let back = retraction.inverse(&f).unwrap();
                assert!(
                    (back - xi).amax() < 1e-14 * (1.0 + xi.amax()),
                    "{back} {xi}"
                );
            }
        }
        // The exponential of a rotation vector is the rotation about it by its length.
        let f = Retraction::Exp.map(&vector![0.0, 0.0, 0.4]);
        assert!((f[(0, 0)] - 0.4_f64.cos()).abs() < 1e-16);
        assert!((f[(1, 0)] - 0.4_f64.sin()).abs() < 1e-16);
        // Cayley: tan(angle/2) = |ξ|/2.
        let f = Retraction::Cayley.map(&vector![0.0, 0.0, 0.4]);
        assert!((f[(1, 0)] - (2.0 * 0.2_f64.atan()).sin()).abs() < 1e-16);
    }

    #[test]
    fn differentials_are_the_left_trivialised_derivatives() {
        for retraction in BOTH {
            for xi in [
                vector![0.0_f64, 0.0, 0.0],
                vector![0.2, -0.1, 0.3],
                vector![0.7, 0.9, -1.1],
            ] {
                let d = retraction.differential(&xi);
                let inverse = retraction.differential_inverse(&xi);
                assert!((d * inverse - Matrix3::identity()).amax() < 1e-14);
                for k in 0..3 {
                    let e = Vector3::from_fn(|i, _| if i == k { 1.0 } else { 0.0 });
                    let rate = fd(|x| retraction.map(x), &xi, &e);
                    let omega = retraction.map(&xi).transpose() * rate;
                    let expected = hat(&d.column(k).into_owned());
                    assert!((omega - expected).amax() < 1e-9, "{retraction:?} {xi} {k}");
                }
            }
        }
    }

    #[test]
    fn derivatives_at_rest_are_finite_and_exact() {
        // Dual numbers through τ and τ⁻¹ at ξ = 0: the derivative of τ⁻¹(τ(ξ)) is the identity.
        type D = DualSVec64<3>;
        let seeded = |x: &Vector3<f64>| {
            Vector3::<D>::from_fn(|i, _| {
                D::new(
                    x[i],
                    Derivative::some(Vector3::from_fn(|j, _| if i == j { 1.0 } else { 0.0 })),
                )
            })
        };
        for retraction in BOTH {
            for xi in [vector![0.0, 0.0, 0.0], vector![0.3, 0.1, -0.2]] {
                let back = retraction.inverse(&retraction.map(&seeded(&xi))).unwrap();
                for i in 0..3 {
                    let gradient = back[i].eps.unwrap_generic(nalgebra::U3, nalgebra::U1);
                    for j in 0..3 {
                        let expected = if i == j { 1.0 } else { 0.0 };
                        assert!((gradient[j] - expected).abs() < 1e-13, "{retraction:?}");
                    }
                }
            }
        }
    }

    /// `Σ_k sign^k x^k / (2k + shift)!` over 40 terms: a reference without cancellation.
    fn long_series(x: f64, shift: u32, sign: f64) -> f64 {
        let factorial = |n: u32| (1..=n).map(f64::from).product::<f64>();
        (0..40)
            .map(|k: u32| (sign * x).powi(k as i32) / factorial(2 * k + shift))
            .sum()
    }

    /// Both branches of each function of `θ²`, on both sides of the switch and on a grid to
    /// `θ² = 4`, against long series that do not cancel: `sin θ/θ`, `(θ − sin θ)/θ³`, and
    /// `(1 − (θ/2) cot(θ/2))/θ² = (sin η − η cos η)/(θ² sin η)` (`η = θ/2`) with
    /// `sin η − η cos η = Σ_{k≥1} (−1)^{k+1} 2k η^{2k+1}/(2k+1)!`.
    #[test]
    fn the_series_meet_the_closed_forms() {
        let grid = (1..=400).map(|i| f64::from(i) * 0.01);
        for x in grid.chain([1e-6, 0.9999999, 1.0000001]) {
            let relative = |got: f64, want: f64| ((got - want) / want).abs();
            let sine = long_series(x, 1, -1.0);
            assert!(relative(sine_ratio(x), sine) < 2e-15, "sin θ/θ at {x}");
            let defect = long_series(x, 3, -1.0);
            assert!(
                relative(sine_defect_ratio(x), defect) < 2e-15,
                "(θ − sin θ)/θ³ at {x}"
            );
            let eta2 = x / 4.0;
            let eta = eta2.sqrt();
            let factorial = |n: u32| (1..=n).map(f64::from).product::<f64>();
            let numerator: f64 = (1..40u32)
                .map(|k| {
                    let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
                    sign * f64::from(2 * k) * eta.powi(2 * k as i32 + 1) / factorial(2 * k + 1)
                })
                .sum();
            let cot = numerator / (x * eta * long_series(eta2, 1, -1.0));
            assert!(
                relative(cotangent_defect_ratio(x), cot) < 2e-15,
                "cot defect at {x}"
            );
        }
        // The angle's series (y = (s/c)² < 0.01) and closed form on both sides of its switch,
        // against atan's own series Σ (−1)^k y^k/(2k + 1) summed over 200 terms.
        for (s, c) in [
            (0.099, 0.995),
            (0.0997, 0.997),
            (0.1001, 0.9999),
            (0.101, 0.995),
        ] {
            let y: f64 = (s / c) * (s / c);
            let atan_ratio: f64 = (0..200)
                .map(|k: i32| (-y).powi(k) / f64::from(2 * k + 1))
                .sum();
            let expected = atan_ratio / c;
            let got = angle_over_sine(s * s, c).unwrap();
            assert!(((got - expected) / expected).abs() < 2e-15, "({s}, {c})");
        }
        // Obtuse angles (the closed form alone) against θ = π − atan(s/|c|).
        let (s, c) = (0.5_f64, -0.8_f64);
        let expected = (std::f64::consts::PI - (s / -c).atan()) / s;
        assert!((angle_over_sine(s * s, c).unwrap() - expected).abs() < 1e-15);
        assert_eq!(angle_over_sine(1e-12, -1.0), None);
    }

    #[test]
    fn orthonormalising_squares_the_defect() {
        let r = Retraction::Exp.map(&vector![0.3, -1.0, 2.0]) * (1.0 + 1e-8);
        let fixed = orthonormalised(&r);
        assert!((fixed.transpose() * fixed - Matrix3::identity()).amax() < 1e-15);
        assert!((fixed - r).amax() < 2e-8);
    }
}
