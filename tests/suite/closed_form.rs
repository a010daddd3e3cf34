//! The Lagrangian's derivatives that `#[dirac_system]` derives at compile time, against central
//! differences of the Lagrangian itself (no dual numbers involved), for every function of the
//! expression language; and which Lagrangians get them. The same for the one-forms' rows and
//! derivatives.

use dirac::nalgebra::{SMatrix, SVector};
use dirac::prelude::*;
use dirac::{HessianZeros, LagrangianGradient, LagrangianHessian, closed_form};

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

/// A one-form that calls the user's own function: its derivative is left to dual numbers.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)),
    constraints(potential(x) * dx - dy),
)]
struct FormCallsUser;

/// The Hessian entries that vanish identically are read off the expression, and a claim that an
/// entry vanishes where it does not is refused at the start of a run.
#[test]
fn vanishing_hessian_entries_are_known_and_checked() {
    let all = [[true; 3]; 3];
    let diagonal = [
        [false, true, true],
        [true, false, true],
        [true, true, false],
    ];
    // L = T(v) on a flat plane: only the diagonal of ∂²L/∂v² is left.
    let blade = <KnifeEdgeScene as DiracSystem<3>>::LAGRANGIAN_HESSIAN_ZEROS;
    assert_eq!((blade.qq, blade.qv, blade.vv), (all, all, diagonal));
    assert!(blade.vanishes(0, 1) && !blade.vanishes(2, 2));
    // A mass that depends on the position couples every entry.
    let coupled = <Trigonometric as DiracSystem<2>>::LAGRANGIAN_HESSIAN_ZEROS;
    assert_eq!(coupled, HessianZeros::NONE);
    struct Claims;
    impl DiracSystem<1> for Claims {
        const LAGRANGIAN_HESSIAN_ZEROS: HessianZeros<1> = HessianZeros {
            qv: [[true]],
            ..HessianZeros::NONE
        };
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
            // ∂²L/∂q∂v = 2 q v: not zero.
            v[0] * v[0] * (q[0] * q[0] + 1.0) * 0.5
        }
    }
    let mut stepper = Stepper::new(Claims, Quadrature::midpoint(), 0.1).expect("stepper");
    let refused = stepper.start_from_velocity(vector![0.5], vector![0.3]);
    assert!(
        matches!(refused, Err(DiracError::InconsistentDerivatives(ref m)) if m.contains("∂²L/∂q_0∂v_0")),
        "{refused:?}"
    );
    // One entry off the diagonal claimed in a block whose others do vanish.
    struct OffDiagonal;
    impl DiracSystem<2> for OffDiagonal {
        const LAGRANGIAN_HESSIAN_ZEROS: HessianZeros<2> = HessianZeros {
            qq: [[true; 2]; 2],
            qv: [[true; 2]; 2],
            vv: [[false, true], [true, false]],
        };
        fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
            // ∂²L/∂v₀∂v₁ = 0.1.
            (v[0] * v[0] + v[1] * v[1]) * 0.5 + v[0] * v[1] * 0.1
        }
    }
    let mut stepper = Stepper::new(OffDiagonal, Quadrature::midpoint(), 0.1).expect("stepper");
    let refused = stepper.start_from_velocity(vector![0.5, 0.1], vector![0.3, 0.2]);
    assert!(
        matches!(refused, Err(DiracError::InconsistentDerivatives(ref m)) if m.contains("∂²L/∂v_0∂v_1")),
        "{refused:?}"
    );
}

#[test]
fn only_expressions_in_the_language_get_closed_forms() {
    const { assert!(!<FormCallsUser as DiracSystem<2>>::ONE_FORM_DERIVATIVES) };
    const { assert!(<KnifeEdgeScene as DiracSystem<3>>::ONE_FORM_DERIVATIVES) };
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

/// One-forms with trigonometric, exponential and rational coefficients, a coordinate array, a
/// parameter, a differential named twice and a constant one-form beside them.
#[dirac_system(
    coordinates(x, y, theta[2]),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2) + dot(theta[0]).powi(2)
        + dot(theta[1]).powi(2)),
    constraints(
        sin(theta[0]) * dx - cos(theta[0]) * dy + r * x * y * dtheta[1],
        exp(0.1 * x) * dtheta[0] - dy / (2.0 + y * y) + atan(x) * dx + 3.0 * dx,
        dx - dy,
    ),
)]
struct Forms {
    r: f64,
}

/// `(A_a(q), ∂A_a/∂q)` by central differences of the one-form over `f64`.
fn differenced_form<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    a: usize,
) -> (SVector<f64, N>, SMatrix<f64, N, N>) {
    let h = 1e-6;
    let mut derivative = SMatrix::<f64, N, N>::zeros();
    for j in 0..N {
        let mut e = SVector::<f64, N>::zeros();
        e[j] = h;
        let column =
            (system.one_form::<f64>(&(q + e), a) - system.one_form::<f64>(&(q - e), a)) / (2.0 * h);
        derivative.set_column(j, &column);
    }
    (system.one_form::<f64>(q, a), derivative)
}

/// The closed form of one-form `a` at `q`: its row and its derivative, the entries not given
/// being zero.
fn closed_form_of<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    a: usize,
) -> (SVector<f64, N>, SMatrix<f64, N, N>, Vec<(usize, usize)>) {
    let mut derivative = SMatrix::<f64, N, N>::zeros();
    let mut given = Vec::new();
    let row = system.one_form_with_derivative(q, a, |i, j, x| {
        derivative[(i, j)] += x;
        given.push((i, j));
    });
    (row, derivative, given)
}

#[test]
fn one_forms_get_their_rows_and_derivatives_in_closed_form() {
    let forms = Forms { r: 0.7 };
    const { assert!(<Forms as DiracSystem<4>>::ONE_FORM_DERIVATIVES) };
    for q in [
        vector![0.3, -0.4, 0.7, 1.1],
        vector![-1.2, 0.9, -0.5, 0.2],
        vector![2.0, 1.7, 0.0, -2.5],
    ] {
        for a in 0..3 {
            let (row, derivative, given) = closed_form_of(&forms, &q, a);
            let (reference_row, reference) = differenced_form(&forms, &q, a);
            let off = (row - reference_row).amax();
            assert!(
                off <= 4.0 * f64::EPSILON * (1.0 + reference_row.amax()),
                "row {a}: {off:e}"
            );
            close(&derivative, &reference, "derivative");
            // Only entries that are not identically zero, each once.
            let mut unique = given.clone();
            unique.sort();
            unique.dedup();
            assert_eq!(unique.len(), given.len(), "form {a}: {given:?}");
            let expected: &[(usize, usize)] = match a {
                0 => &[(0, 2), (1, 2), (3, 0), (3, 1)],
                1 => &[(0, 0), (1, 1), (2, 0)],
                _ => &[],
            };
            assert_eq!(unique, expected, "form {a}");
        }
    }
    // Beside a coordinate named `dx`, `dx` in a form is `x`'s differential (as `one_form` reads
    // it), and `ddx` that coordinate's.
    for q in [vector![0.7, 0.2], vector![-1.3, 2.0]] {
        let (row, derivative, given) = closed_form_of(&Shadowed, &q, 0);
        let (reference_row, reference) = differenced_form(&Shadowed, &q, 0);
        assert_eq!(row, reference_row);
        close(&derivative, &reference, "derivative");
        assert_eq!(given, [(0, 0)]);
    }
    // The scene's knife edge: two entries, the blade's angle moving the row.
    let q = vector![0.1, 0.2, 0.5];
    let (row, derivative, given) = closed_form_of(&KnifeEdgeScene, &q, 0);
    assert_eq!(given, [(0, 2), (1, 2)]);
    assert_eq!(row, vector![0.5f64.sin(), -0.5f64.cos(), 0.0]);
    assert_eq!(
        (derivative[(0, 2)], derivative[(1, 2)]),
        (0.5f64.cos(), 0.5f64.sin())
    );
}

#[dirac_system(
    coordinates(x, y, phi),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2) + dot(phi).powi(2)),
    constraints(sin(phi) * dx - cos(phi) * dy),
)]
struct KnifeEdgeScene;

/// A coordinate whose name is another's differential.
#[dirac_system(
    coordinates(x, dx),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(dx).powi(2)),
    constraints(x * x * dx + ddx),
)]
struct Shadowed;

/// A model whose one-forms the runtime differentiates by dual numbers: the knife edge's, with
/// `one_form` alone.
struct KnifeEdgeByDuals;
impl DiracSystem<3> for KnifeEdgeByDuals {
    const ONE_FORMS: usize = 1;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
        KnifeEdgeScene.lagrangian(q, v)
    }
    fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, a: usize) -> SVector<D, 3> {
        KnifeEdgeScene.one_form(q, a)
    }
}

/// A step with the closed-form one-form solves the same equations as one with dual numbers:
/// the two trajectories agree to round-off over 2 000 steps, at each constraint point.
#[test]
fn closed_form_one_forms_step_as_dual_numbers_do() {
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        let (q0, v0) = (vector![0.0, 0.0, 0.3], vector![1.0, 0.3f64.tan(), 1.0]);
        let mut closed = Stepper::new(KnifeEdgeScene, Quadrature::midpoint(), 0.01)
            .expect("stepper")
            .with_constraint_point(point);
        let mut duals = Stepper::new(KnifeEdgeByDuals, Quadrature::midpoint(), 0.01)
            .expect("stepper")
            .with_constraint_point(point);
        closed.start_from_velocity(q0, v0).expect("start");
        duals.start_from_velocity(q0, v0).expect("start");
        for _ in 0..2000 {
            closed.step().expect("step");
            duals.step().expect("step");
        }
        let apart = (closed.q() - duals.q())
            .amax()
            .max((closed.p() - duals.p()).amax());
        assert!(apart < 1e-12, "{point:?}: {apart:e}");
        assert!(
            (closed.q() - q0).fixed_rows::<2>(0).amax() > 0.5,
            "the blade moved"
        );
    }
}

/// A one-form's hand-written closed form that is wrong, in its derivative or in its row, is
/// refused at the start of a run.
#[test]
fn a_wrong_one_form_closed_form_is_refused_at_the_start() {
    struct Wrong {
        row_off: f64,
        entry_off: f64,
    }
    impl DiracSystem<3> for Wrong {
        const ONE_FORMS: usize = 1;
        const ONE_FORM_DERIVATIVES: bool = true;
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
            KnifeEdgeScene.lagrangian(q, v)
        }
        fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, a: usize) -> SVector<D, 3> {
            KnifeEdgeScene.one_form(q, a)
        }
        fn one_form_with_derivative(
            &self,
            q: &SVector<f64, 3>,
            _a: usize,
            mut entry: impl FnMut(usize, usize, f64),
        ) -> SVector<f64, 3> {
            let (sin, cos) = q[2].sin_cos();
            entry(0, 2, cos + self.entry_off);
            entry(1, 2, sin);
            vector![sin + self.row_off, -cos, 0.0]
        }
    }
    for (wrong, what) in [
        (
            Wrong {
                row_off: 0.0,
                entry_off: 0.0,
            },
            None,
        ),
        (
            Wrong {
                row_off: 0.0,
                entry_off: 1e-3,
            },
            Some("derivative"),
        ),
        (
            Wrong {
                row_off: 1e-3,
                entry_off: 0.0,
            },
            Some("row"),
        ),
    ] {
        let mut stepper = Stepper::new(wrong, Quadrature::midpoint(), 0.1).expect("stepper");
        let started = stepper.start_from_velocity(
            vector![0.0, 0.0, 0.4],
            vector![0.4f64.cos(), 0.4f64.sin(), 1.0],
        );
        match what {
            None => assert!(started.is_ok(), "{started:?}"),
            Some(what) => {
                assert!(
                    matches!(started, Err(DiracError::InconsistentDerivatives(ref m)) if m.contains(what)),
                    "{started:?}"
                );
                assert!(matches!(stepper.step(), Err(DiracError::NotStarted)));
            }
        }
    }
}
