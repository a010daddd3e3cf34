//! The Lagrangian's derivatives that `#[dirac_system]` derives at compile time, against central
//! differences of the Lagrangian itself (no dual numbers involved), for every function of the
//! expression language; and which Lagrangians get them.

use dirac::nalgebra::{SMatrix, SVector};
use dirac::prelude::*;
use dirac::{LagrangianGradient, LagrangianHessian, closed_form};

/// Every trigonometric and hyperbolic function, a product with a velocity-dependent mass, a
/// quotient and unary minus.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) * (1.0 + 0.1 * sin(x) * cos(y))
        + tan(0.3 * x) + asin(0.2 * y) + acos(0.1 * x) + atan(x * y)
        + sinh(0.2 * x) * dot(y) + cosh(0.3 * y) - tanh(x - y) * dot(x)
        + asinh(x * dot(y)) + acosh(2.0 + y * y) + atanh(0.3 * x)
        - m * x / (2.0 + y * y) + -(dot(x) * dot(y)) / (3.0 + cos(x)),
)]
struct Trigonometric {
    m: f64,
}

/// Exponentials, logarithms, roots and powers, methods and functions, a path constant.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * dot(x).powi(2) * exp(0.1 * y) + 0.5 * sqrt(1.0 + dot(y).powi(2))
        + exp2(0.2 * x) + exp_m1(0.1 * y) * dot(x) + ln(2.0 + x * x) + ln_1p(y * y)
        + log2(3.0 + x) + log10(4.0 + y) + cbrt(2.0 + x) + recip(3.0 + y) + (x - 5.0).abs()
        + powf(1.5 + x * x, 1.5) + (2.0 + y * y).pow(0.7) + atan2(y + 3.0, x + 4.0)
        + powi(x, -2) + x.powi(3) * dot(y) - std::f64::consts::PI * y,
)]
struct Exponential;

/// Coordinate and parameter arrays.
#[dirac_system(
    coordinates(theta[3], s),
    lagrangian = 0.5 * (dot(theta[0]).powi(2) + dot(theta[1]).powi(2) + dot(theta[2]).powi(2))
        + dot(theta[0]) * dot(theta[1]) * cos(theta[0] - theta[1])
        + dot(theta[1]) * dot(theta[2]) * cos(theta[1] - theta[2])
        + 0.5 * dot(s).powi(2) - k[0] * cos(theta[0]) - k[1] * cos(theta[1])
        - k[2] * cos(theta[2]) - 0.5 * s * s * theta[2],
)]
struct Arrays {
    k: [f64; 3],
}

/// A Lagrangian given as a generic function has no closed form (the runtime uses dual numbers).
#[dirac_system(coordinates(x), lagrangian = by_function)]
struct ByFunction;

fn by_function<D: Scalar>(_: &ByFunction, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    (v[0] * v[0] - q[0] * q[0]) * 0.5
}

/// So does an expression that calls the user's own function.
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2) - potential(x))]
struct CallsUser;

fn potential<D: Scalar>(x: D) -> D {
    x * x * 0.5
}

/// `∂L/∂(q, v)` by central differences of `L` over `f64`.
fn differenced_gradient<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    let delta = 1e-5;
    let mut gq = SVector::zeros();
    let mut gv = SVector::zeros();
    for i in 0..N {
        let mut e = SVector::<f64, N>::zeros();
        e[i] = delta;
        gq[i] = (system.lagrangian(&(q + e), v) - system.lagrangian(&(q - e), v)) / (2.0 * delta);
        gv[i] = (system.lagrangian(q, &(v + e)) - system.lagrangian(q, &(v - e))) / (2.0 * delta);
    }
    (gq, gv)
}

/// The Hessian blocks by central differences of the closed-form gradient.
fn differenced_hessian<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> [SMatrix<f64, N, N>; 3] {
    let delta = 1e-5;
    let gradient = |q: &SVector<f64, N>, v: &SVector<f64, N>| {
        system.lagrangian_gradient(q, v).expect("closed form")
    };
    let mut qq = SMatrix::<f64, N, N>::zeros();
    let (mut qv, mut vv) = (qq, qq);
    for j in 0..N {
        let mut e = SVector::<f64, N>::zeros();
        e[j] = delta;
        let (up, down) = (gradient(&(q + e), v), gradient(&(q - e), v));
        qq.set_column(j, &((up.q - down.q) / (2.0 * delta)));
        let (up, down) = (gradient(q, &(v + e)), gradient(q, &(v - e)));
        qv.set_column(j, &((up.q - down.q) / (2.0 * delta)));
        vv.set_column(j, &((up.v - down.v) / (2.0 * delta)));
    }
    [qq, qv, vv]
}

fn close<const R: usize, const C: usize>(
    a: &SMatrix<f64, R, C>,
    b: &SMatrix<f64, R, C>,
    what: &str,
) {
    let scale = 1.0 + b.amax();
    let error = (a - b).amax();
    assert!(
        error <= 1e-7 * scale,
        "{what}: closed form {a} against central differences {b} (error {error:e})"
    );
}

/// The closed forms at `(q, v)` agree with central differences of `L`, the value is `L`
/// itself, both methods agree with each other, and the runtime's own check accepts them.
fn agrees<S: DiracSystem<N>, const N: usize>(system: &S, q: SVector<f64, N>, v: SVector<f64, N>) {
    let g: LagrangianGradient<N> = system.lagrangian_gradient(&q, &v).expect("closed gradient");
    let h: LagrangianHessian<N> = system.lagrangian_hessian(&q, &v).expect("closed Hessian");
    let l = system.lagrangian(&q, &v);
    assert!(
        (g.value - l).abs() <= 1e-14 * (1.0 + l.abs()),
        "{} against {l}",
        g.value
    );
    assert_eq!(g, h.gradient);
    let (gq, gv) = differenced_gradient(system, &q, &v);
    close(&g.q, &gq, "∂L/∂q");
    close(&g.v, &gv, "∂L/∂v");
    let [qq, qv, vv] = differenced_hessian(system, &q, &v);
    close(&h.qq, &qq, "∂²L/∂q²");
    close(&h.qv, &qv, "∂²L/∂q∂v");
    close(&h.vv, &vv, "∂²L/∂v²");
    assert_eq!(h.qq, h.qq.transpose());
    assert_eq!(h.vv, h.vv.transpose());
    closed_form::check(system, &q, &v).expect("the runtime's check accepts the closed forms");
}

#[test]
fn every_function_is_differentiated_exactly() {
    for (q, v) in [
        (vector![0.3, -0.4], vector![0.7, 1.1]),
        (vector![-1.2, 0.9], vector![-0.5, 0.2]),
        (vector![2.0, 1.7], vector![0.0, -2.5]),
    ] {
        agrees(&Trigonometric { m: 1.3 }, q, v);
        agrees(&Exponential, q, v);
    }
    agrees(
        &Arrays { k: [9.8, 4.1, 2.2] },
        vector![0.4, -0.3, 0.8, 1.5],
        vector![0.2, -0.9, 0.5, -0.1],
    );
}

#[test]
fn only_expressions_in_the_language_get_closed_forms() {
    let (q, v) = (vector![0.3], vector![0.2]);
    assert!(ByFunction.lagrangian_gradient(&q, &v).is_none());
    assert!(ByFunction.lagrangian_hessian(&q, &v).is_none());
    assert!(CallsUser.lagrangian_gradient(&q, &v).is_none());
    assert!(CallsUser.lagrangian_hessian(&q, &v).is_none());
}

/// A hand-written closed form that is wrong is refused at the start of a run, and the stepper
/// stays unstarted.
#[test]
fn a_wrong_closed_form_is_refused_at_the_start() {
    struct Wrong;
    impl DiracSystem<1> for Wrong {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
            (v[0] * v[0] - q[0] * q[0]) * 0.5
        }
        fn lagrangian_gradient(
            &self,
            q: &SVector<f64, 1>,
            v: &SVector<f64, 1>,
        ) -> Option<LagrangianGradient<1>> {
            // ∂L/∂q has the wrong sign.
            Some(LagrangianGradient {
                value: (v[0] * v[0] - q[0] * q[0]) * 0.5,
                q: *q,
                v: *v,
            })
        }
    }
    let mut stepper = Stepper::new(Wrong, Quadrature::midpoint(), 0.1).expect("stepper");
    let refused = stepper.start_from_velocity(vector![0.5], vector![0.1]);
    assert!(
        matches!(refused, Err(DiracError::InconsistentDerivatives(ref m)) if m.contains("gradient")),
        "{refused:?}"
    );
    assert!(matches!(stepper.step(), Err(DiracError::NotStarted)));
}
