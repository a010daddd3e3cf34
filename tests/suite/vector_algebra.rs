//! The vector and matrix algebra of Lagrangians on rotations and unit vectors, checked against
//! the documented mathematics written out by hand in plain `f64` nalgebra code.
//!
//! Conventions (`docs/mathematics.md`, "Rotations and unit vectors"): `R: SO3` is the attitude (body to space
//! axes), `omega(R)` the body angular velocity `Ω` with `Ṙ = R Ω̂` (`Ω̂ y = Ω × y`), `dot(R)` the
//! matrix `R Ω̂`; `n: S2` is a unit vector, `dot(n)` its velocity `ṅ`, `omega(n) = n × ṅ`.
//! A parameter `p: [[f64; 3]; 3]` is the matrix whose row `i`, column `j` is `p[i][j]` (so `p[i]`
//! is row `i`): `scenes/src/rigid_body.rs` writes the same `j * omega(R)` by hand as
//! `Matrix3::from_fn(|a, b| j[a][b]) * w`, and `Matrix3::from_fn` fills entry (row `a`, column `b`).
//!
//! Every parameter matrix here is far from symmetric, every vector generic, and the points are
//! pseudo-random (a fixed seed), so a transposed matrix, a swapped index, a cross product of the
//! wrong sign, `−Ω̂` for `Ω̂`, `Rᵀ` for `R`, `ṅ × n` for `n × ṅ` or a wrong precedence each change
//! `L` by far more than the 1e-12 tolerance.

use dirac::nalgebra::Rotation3;
use dirac::prelude::*;

/// The matrix of a parameter: row `i`, column `j` is `p[i][j]`.
fn matrix(p: [[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| p[i][j])
}

fn vec3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// `ŵ`, with `ŵ y = w × y`.
fn hat(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w[2], w[1], w[2], 0.0, -w[0], -w[1], w[0], 0.0)
}

/// A fixed-seed generator (splitmix64) of numbers in `[lo, hi)`.
struct Numbers(u64);

impl Numbers {
    fn next(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
    }

    fn vector(&mut self) -> Vector3<f64> {
        Vector3::new(
            self.next(-1.5, 1.5),
            self.next(-1.5, 1.5),
            self.next(-1.5, 1.5),
        )
    }

    /// A rotation `exp(ξ̂)` with `ξ` of norm up to about 2.6 rad.
    fn rotation(&mut self) -> Matrix3<f64> {
        let r = Rotation3::from_scaled_axis(self.vector()).into_inner();
        assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-14);
        r
    }

    /// A unit vector and a velocity tangent to the sphere there.
    fn direction(&mut self) -> (Vector3<f64>, Vector3<f64>) {
        let n = self.vector().normalize();
        let u = self.vector();
        let velocity = u - n * n.dot(&u);
        assert!(n.dot(&velocity).abs() < 1e-14);
        (n, velocity)
    }
}

/// Asserts that the generated `L` equals the sum of the hand-computed `terms`, to 1e-12 relative
/// to the sum of the terms' sizes (so that cancellation between terms cannot hide an error).
fn agree(what: &str, point: usize, generated: f64, terms: &[f64]) {
    let expected: f64 = terms.iter().sum();
    let scale: f64 = terms.iter().map(|t| t.abs()).sum();
    assert!(
        scale > 0.1,
        "{what}, point {point}: degenerate terms {terms:?}"
    );
    let error = (generated - expected).abs();
    assert!(
        error <= 1e-12 * scale,
        "{what}, point {point}: generated L = {generated:.17e}, by hand {expected:.17e} \
         (difference {error:.3e}, terms {terms:?})"
    );
}

const POINTS: usize = 6;

// ---------------------------------------------------------------------------------------------
// One rotation: matrix × vector, matrix × matrix, transpose, trace, cross, M[i][j], dot(R).

/// `L = a·(M Ω) + (a × b)·(R Ω) + tr(M Rᵀ) + (Ṙ b)₂ − M₀₁ Ṙ₂₀ + (Rᵀ M R)[1][2]`
/// (indices from 0).
#[dirac_system(
    coordinates(R: SO3),
    lagrangian = dot(a, m * omega(R)) + dot(cross(a, b), R * omega(R))
        + trace(m * transpose(R)) + (dot(R) * b)[1] - m[0][1] * dot(R)[2][0]
        + (transpose(R) * m * R)[1][2],
)]
#[derive(Debug, Clone, Copy)]
struct Attitude {
    m: [[f64; 3]; 3],
    a: [f64; 3],
    b: [f64; 3],
}

const ATTITUDE: Attitude = Attitude {
    m: [[0.7, -1.3, 0.4], [2.1, 0.3, -0.9], [-0.6, 1.7, 1.1]],
    a: [0.8, -0.35, 1.25],
    b: [-0.45, 1.6, 0.55],
};

/// The matrix and rotation algebra on one attitude: catches a parameter matrix read transposed
/// (`a·MΩ`, `M[0][1]`), `Rᵀ` for `R` (`RΩ`, `tr(MRᵀ)`, `RᵀMR`), `cross(a, b)` of the wrong
/// sign, `dot(R)` taken as `−RΩ̂`, `Ω̂R` or `RΩ̂ᵀ` (`(Ṙb)₁`, `Ṙ[2][0]`), matrix products
/// multiplied in the wrong order (`RᵀMR`), and row/column swaps in `M[i][j]` on a parameter
/// and on computed matrices.
#[test]
fn one_attitude_matrix_algebra_matches_the_hand_computed_lagrangian() {
    let mut numbers = Numbers(0x5EED_0001);
    let model = ATTITUDE;
    let (m, a, b) = (matrix(model.m), vec3(model.a), vec3(model.b));
    for point in 0..POINTS {
        let r = numbers.rotation();
        let w = numbers.vector();
        let q = Configuration::<f64, 0, 1, 0>::of_rotation(r);
        let v = Rates::<f64, 0, 1, 0>::of_rotation(w);
        let generated = model.lagrangian(&q, &v);
        let r_dot = r * hat(&w);
        let terms = [
            a.dot(&(m * w)),
            a.cross(&b).dot(&(r * w)),
            (m * r.transpose()).trace(),
            (r_dot * b)[1],
            -model.m[0][1] * r_dot[(2, 0)],
            (r.transpose() * m * r)[(1, 2)],
        ];
        agree("Attitude", point, generated, &terms);
    }
}

// ---------------------------------------------------------------------------------------------
// One unit vector: omega(n), dot(n), norm, vector literals, n[i].

/// `L = k·(n × ṅ) + s |ṅ − n × k| − [n₁, −ṅ₀, 2]·k / s + n₂ ṅ₁`.
#[dirac_system(
    coordinates(n: S2),
    lagrangian = dot(k, omega(n)) + s * norm(dot(n) - cross(n, k))
        - dot([n[1], -dot(n)[0], 2.0], k) / s + n[2] * dot(n)[1],
)]
#[derive(Debug, Clone, Copy)]
struct Pointer {
    k: [f64; 3],
    s: f64,
}

const POINTER: Pointer = Pointer {
    k: [0.45, -1.15, 0.7],
    s: 1.35,
};

/// The unit vector's algebra: catches `omega(n)` taken as `ṅ × n`, `cross(n, k)` of the wrong
/// sign (under `norm`, `|ṅ − n×k| ≠ |ṅ + n×k|` for a generic `k`), `n` and `ṅ` mixed up,
/// swapped components of either, a vector literal with its entries in the wrong place or the
/// unary minus inside it lost, and `/ s` applied to the whole difference instead of its last
/// term.
#[test]
fn one_unit_vector_algebra_matches_the_hand_computed_lagrangian() {
    let mut numbers = Numbers(0x5EED_0002);
    let model = POINTER;
    let (k, s) = (vec3(model.k), model.s);
    for point in 0..POINTS {
        let (n, n_dot) = numbers.direction();
        let q = Configuration::<f64, 0, 0, 1>::of_direction(n);
        let v = Rates::<f64, 0, 0, 1>::of_direction(n_dot);
        let generated = model.lagrangian(&q, &v);
        let terms = [
            k.dot(&n.cross(&n_dot)),
            s * (n_dot - n.cross(&k)).norm(),
            -Vector3::new(n[1], -n_dot[0], 2.0).dot(&k) / s,
            n[2] * n_dot[1],
        ];
        agree("Pointer", point, generated, &terms);
    }
}

// ---------------------------------------------------------------------------------------------
// Precedence: unary minus, * and / against + and -, left associativity.

/// `L = −Ω₀² + c ẋ − (x/c)·2 − x − ẋ − 1.5 + u·((P − Pᵀ)Ω)/2/c + (−x) ẋ + u·(Ω x − u·3/c)
///      + ((P + Pᵀ/2) / x)[2][0]`.
#[dirac_system(
    coordinates(x, R: SO3),
    lagrangian = -omega(R)[0].powi(2) + c * dot(x) - x / c * 2.0 - x - dot(x) - 1.5
        + dot(u, (p - transpose(p)) * omega(R)) / 2.0 / c + -x * dot(x)
        + dot(u, omega(R) * x - u * 3.0 / c) + ((p + transpose(p) / 2.0) / x)[2][0],
)]
#[derive(Debug, Clone, Copy)]
struct Precedence {
    c: f64,
    u: [f64; 3],
    p: [[f64; 3]; 3],
}

const PRECEDENCE: Precedence = Precedence {
    c: 1.7,
    u: [-0.9, 0.55, 1.3],
    p: [[0.2, 1.4, -0.75], [-0.5, 0.9, 2.2], [1.9, -1.2, 0.35]],
};

/// Precedence and associativity: catches `-ω₀.powi(2)` read as `(−ω₀)²`, `x / c * 2` read as
/// `x / (c·2)`, `a − b − c` read as `a − (b − c)`, `/ 2 / c` read as `/ (2/c)`, `* ` not binding
/// tighter than `+`/`−` (`c * ẋ − …`), a vector times a number on the right (`Ω x`, `u * 3 / c`),
/// matrix `+ −` and `/` by a number (`P − Pᵀ` vanishes if the transpose is lost), and a plain
/// real coordinate and its velocity swapped.
#[test]
fn precedence_and_associativity_match_rust_arithmetic() {
    let mut numbers = Numbers(0x5EED_0003);
    let model = PRECEDENCE;
    let (c, u, p) = (model.c, vec3(model.u), matrix(model.p));
    for point in 0..POINTS {
        let r = numbers.rotation();
        let w = numbers.vector();
        let x = numbers.next(0.6, 2.0);
        let x_dot = numbers.next(-1.5, 1.5);
        let q = Configuration::<f64, 1, 1, 0>::new(vector![x], [r], []);
        let v = Rates::<f64, 1, 1, 0>::new(vector![x_dot], [w], []);
        let generated = model.lagrangian(&q, &v);
        let terms = [
            -(w[0] * w[0]),
            c * x_dot,
            -((x / c) * 2.0),
            -x,
            -x_dot,
            -1.5,
            (u.dot(&((p - p.transpose()) * w)) / 2.0) / c,
            (-x) * x_dot,
            u.dot(&(w * x - u * 3.0 / c)),
            ((p + p.transpose() / 2.0) / x)[(2, 0)],
        ];
        agree("Precedence", point, generated, &terms);
    }
}

// ---------------------------------------------------------------------------------------------
// A real coordinate, two rotations in an array and a unit vector.

/// `L = x (R₀ Ω₁)·n − (R₁ᵀ ṅ)·Ω₀ + ẋ (R₀ W R₁ᵀ)₂₀ + (Ṙ₁ e)·(n × ṅ)/x + tr((R₀ + R₁) W)
///      − |(n × ṅ) × e| ẋ`.
#[dirac_system(
    coordinates(x, links[2]: SO3, n: S2),
    lagrangian = x * dot(links[0] * omega(links[1]), n)
        - dot(transpose(links[1]) * dot(n), omega(links[0]))
        + dot(x) * (links[0] * w * transpose(links[1]))[2][0]
        + dot(dot(links[1]) * e, omega(n)) / x
        + trace((links[0] + links[1]) * w) - norm(cross(omega(n), e)) * dot(x),
)]
#[derive(Debug, Clone, Copy)]
struct Mixed {
    e: [f64; 3],
    w: [[f64; 3]; 3],
}

const MIXED: Mixed = Mixed {
    e: [1.05, 0.3, -0.85],
    w: [[-0.4, 0.95, 1.6], [0.25, -1.1, 0.5], [1.3, 0.15, 0.8]],
};

/// A real coordinate, `links[2]: SO3` and `n: S2` together: catches the two links or their
/// angular velocities swapped (`links[0]` against `omega(links[1])`), the real coordinate, the
/// rotations and the unit vector read from the wrong slots of `Configuration`/`Rates`, `R₁ᵀ`
/// for `R₁`, `dot(links[1])` of the wrong sign or order, `omega(n)` reversed, and the sum of
/// two rotations under `trace` with a non-symmetric `W`.
#[test]
fn a_real_coordinate_two_rotations_and_a_unit_vector_match_the_hand_computed_lagrangian() {
    let mut numbers = Numbers(0x5EED_0004);
    let model = MIXED;
    let (e, w) = (vec3(model.e), matrix(model.w));
    for point in 0..POINTS {
        let (r0, r1) = (numbers.rotation(), numbers.rotation());
        let (w0, w1) = (numbers.vector(), numbers.vector());
        let (n, n_dot) = numbers.direction();
        let x = numbers.next(0.6, 2.0);
        let x_dot = numbers.next(-1.5, 1.5);
        let q = Configuration::<f64, 1, 2, 1>::new(vector![x], [r0, r1], [n]);
        let v = Rates::<f64, 1, 2, 1>::new(vector![x_dot], [w0, w1], [n_dot]);
        let generated = model.lagrangian(&q, &v);
        let omega_n = n.cross(&n_dot);
        let terms = [
            x * (r0 * w1).dot(&n),
            -(r1.transpose() * n_dot).dot(&w0),
            x_dot * (r0 * w * r1.transpose())[(2, 0)],
            (r1 * hat(&w1) * e).dot(&omega_n) / x,
            ((r0 + r1) * w).trace(),
            -omega_n.cross(&e).norm() * x_dot,
        ];
        agree("Mixed", point, generated, &terms);
    }
}

/// The hand-written reference itself: `hat` is the cross product, and `Ṙ = RΩ̂` is the
/// derivative of `t ↦ R exp(tΩ̂)` (central difference), so the references above use the
/// documented `dot(R)` and not its transpose or negative.
#[test]
fn the_hand_written_reference_uses_the_documented_conventions() {
    let mut numbers = Numbers(0x5EED_0005);
    for _ in 0..POINTS {
        let (w, y) = (numbers.vector(), numbers.vector());
        assert!((hat(&w) * y - w.cross(&y)).amax() < 1e-14);
        let r = numbers.rotation();
        let h = 1e-5;
        let turned = |t: f64| r * Rotation3::from_scaled_axis(w * t).into_inner();
        let difference = (turned(h) - turned(-h)) / (2.0 * h);
        assert!((difference - r * hat(&w)).amax() < 1e-8);
    }
}
