//! The seam for configuration spaces, exercised by a space with a nonlinear retraction: the
//! positive orthant as the multiplicative group `R₊ⁿ`, `R_q(ξ) = q ⊙ exp(ξ)` (`Positive`, left
//! trivialised, abelian), which defines only the three maps a space must (`retract`,
//! `push_forward`, `local`); the pull-back, the chart velocity and the momentum update are the
//! trait's defaults.
//!
//! On this space every step's points are positive by construction, and the charts differ from
//! `Rⁿ`'s at second order, so a scheme that ignored the retraction anywhere (the Lagrangian's
//! nodes, the forces, the one-forms, the holonomic constraints, the momentum carried to the next
//! chart) would not converge to the closed form, or would lose its order. Orders are measured as
//! least-squares slopes over four step sizes (tolerance ±0.3, as in `tests/suite/convergence.rs`).

use crate::support;

use dirac::prelude::*;
use support::slope;

/// A particle against an inverse-square wall, `L = v²/2 − 1/(2q²)`, with optional damping
/// `F = −c v`. Undamped, `q(t)² = q0² + 2 q0 v0 t + 2E t²` (since `(q²)'' = 4E`).
struct Wall {
    c: f64,
}

impl DiracSystem<1> for Wall {
    const FORCES: bool = true;

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        v[0] * v[0] * 0.5 - (q[0] * q[0]).recip() * 0.5
    }

    fn force<D: Scalar>(
        &self,
        _q: &SVector<D, 1>,
        v: &SVector<D, 1>,
        _t: f64,
        _inputs: &[D],
    ) -> SVector<D, 1> {
        v.map(|x| x * (-self.c))
    }
}

const Q0: f64 = 1.0;
const V0: f64 = -2.0;

/// Position and velocity of the undamped wall particle at `t` (it bounces at t = 0.4, q = 0.447).
fn wall_exact(t: f64) -> (f64, f64) {
    let energy = 0.5 * V0 * V0 + 0.5 / (Q0 * Q0);
    let q = (Q0 * Q0 + 2.0 * Q0 * V0 * t + 2.0 * energy * t * t).sqrt();
    (q, (Q0 * V0 + 2.0 * energy * t) / q)
}

/// `(q, p)` at `t_end` from `(Q0, V0)` with step `h` on `space`.
fn wall_run<C: ConfigurationSpace<1, Manifold = dirac::Vectors>>(
    space: C,
    c: f64,
    quadrature: Quadrature,
    h: f64,
    t_end: f64,
) -> (f64, f64) {
    let mut stepper = Stepper::on_space(Wall { c }, space, quadrature, h).expect("valid scene");
    stepper
        .start_from_velocity(vector![Q0], vector![V0])
        .expect("finite start");
    let steps = (t_end / h).round() as usize;
    for _ in 0..steps {
        stepper.step().expect("step");
    }
    (stepper.q()[0], stepper.p()[0])
}

#[test]
fn a_nonlinear_retraction_converges_to_the_closed_form_with_the_quadratures_order() {
    let t_end = 1.0;
    let (q_exact, p_exact) = wall_exact(t_end);
    // Step counts over [0, 1]: each set spans errors from about 1e-5 (1e-10 for the order 6)
    // down to well above round-off.
    for (quadrature, order, counts) in [
        (Quadrature::midpoint(), 2.0, [50, 100, 200, 400]),
        (Quadrature::galerkin(2).unwrap(), 4.0, [20, 40, 80, 160]),
        (Quadrature::galerkin(3).unwrap(), 6.0, [20, 24, 30, 40]),
    ] {
        let hs: Vec<f64> = counts.iter().map(|&n| t_end / f64::from(n)).collect();
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let (q, p) = wall_run(Positive, 0.0, quadrature.clone(), h, t_end);
                (q - q_exact).abs().max((p - p_exact).abs())
            })
            .collect();
        let measured = slope(&hs, &errors);
        assert!(
            (measured - order).abs() < 0.3,
            "{}: slope {measured:.2} (errors {errors:?})",
            quadrature.name()
        );
    }
}

#[test]
fn the_chart_changes_the_scheme_but_not_the_solution() {
    // Same model, same quadrature: the two spaces give different discrete trajectories whose
    // difference shrinks with the order of the method (both converge to the same solution).
    let differences: Vec<f64> = [0.02, 0.01, 0.005]
        .iter()
        .map(|&h| {
            let (q_positive, _) = wall_run(Positive, 0.3, Quadrature::midpoint(), h, 1.0);
            let (q_euclidean, _) = wall_run(Euclidean, 0.3, Quadrature::midpoint(), h, 1.0);
            (q_positive - q_euclidean).abs()
        })
        .collect();
    assert!(
        differences[2] > 1e-9,
        "the retraction is not used: {differences:?}"
    );
    let measured = slope(&[0.02, 0.01, 0.005], &differences);
    assert!((measured - 2.0).abs() < 0.3, "slope {measured:.2}");
}

#[test]
fn forces_are_read_in_the_chart() {
    // Damped wall particle against a Euclidean reference at a step 64 times smaller.
    let reference = wall_run(Euclidean, 0.3, Quadrature::galerkin(3).unwrap(), 0.005, 1.0);
    let hs = [0.04, 0.02, 0.01, 0.005];
    let errors: Vec<f64> = hs
        .iter()
        .map(|&h| {
            let (q, p) = wall_run(Positive, 0.3, Quadrature::galerkin(2).unwrap(), h, 1.0);
            (q - reference.0).abs().max((p - reference.1).abs())
        })
        .collect();
    let measured = slope(&hs, &errors);
    assert!(
        (measured - 4.0).abs() < 0.3,
        "slope {measured:.2} ({errors:?})"
    );
}

/// A unit mass in the plane under gravity on the hyperbola `q1 q2 = 1`, held either by the
/// holonomic constraint `g = q1 q2 − 1` or by its one-form `d(q1 q2) = q2 dq1 + q1 dq2`.
struct Hyperbola;

impl DiracSystem<2> for Hyperbola {
    const HOLONOMIC: usize = 1;

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        v.dot(v) * 0.5 - q[1]
    }

    fn holonomic<D: Scalar>(&self, q: &SVector<D, 2>, _b: usize) -> D {
        q[0] * q[1] - 1.0
    }
}

struct HyperbolaOneForm;

impl DiracSystem<2> for HyperbolaOneForm {
    const ONE_FORMS: usize = 1;

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        v.dot(v) * 0.5 - q[1]
    }

    fn one_form<D: Scalar>(&self, q: &SVector<D, 2>, _a: usize) -> SVector<D, 2> {
        SVector::from([q[1], q[0]])
    }
}

/// `q` at `t = 1` from `(1, 1)` with the tangent velocity `(1, −1)`.
fn hyperbola_run<S: DiracSystem<2>, C: ConfigurationSpace<2, Manifold = dirac::Vectors>>(
    system: S,
    space: C,
    h: f64,
) -> (SVector<f64, 2>, f64) {
    let mut stepper = Stepper::on_space(system, space, Quadrature::midpoint(), h).expect("valid");
    stepper
        .start_from_velocity(vector![1.0, 1.0], vector![1.0, -1.0])
        .expect("consistent start");
    let mut worst = 0.0_f64;
    for _ in 0..(1.0 / h).round() as usize {
        stepper.step().expect("step");
        worst = worst.max(stepper.constraint_violation());
    }
    (stepper.q(), worst)
}

/// Order 2 on `Positive` against a Euclidean reference at a step 16 times below the finest, with
/// the discrete constraint held to solver tolerance at every step.
fn constrained_order_in_the_chart<S: DiracSystem<2>>(system: impl Fn() -> S, what: &str) {
    let hs = [0.02, 0.01, 0.005, 0.0025];
    let reference = hyperbola_run(system(), Euclidean, 0.0025 / 16.0).0;
    let errors: Vec<f64> = hs
        .iter()
        .map(|&h| {
            let (q, worst) = hyperbola_run(system(), Positive, h);
            assert!(worst < 1e-12, "{what} violation {worst:e} at h = {h}");
            (q - reference).amax()
        })
        .collect();
    let measured = slope(&hs, &errors);
    assert!(
        (measured - 2.0).abs() < 0.3,
        "{what}: slope {measured:.2} ({errors:?})"
    );
}

#[test]
fn constraints_are_read_in_the_chart() {
    // The holonomic constraint is held on the nodes; the one-form d(q1 q2) keeps q1 q2 = 1 to
    // second order, its discrete constraint to solver tolerance.
    constrained_order_in_the_chart(|| Hyperbola, "holonomic");
    constrained_order_in_the_chart(|| HyperbolaOneForm, "one-form");
}

#[test]
fn a_start_outside_the_space_is_refused() {
    let mut stepper =
        Stepper::on_space(Wall { c: 0.0 }, Positive, Quadrature::midpoint(), 0.01).unwrap();
    for q0 in [-1.0, 0.0] {
        let error = stepper
            .start_from_velocity(vector![q0], vector![1.0])
            .expect_err("not in R₊");
        assert!(
            matches!(error, DiracError::InconsistentInitialState(_)),
            "{error}"
        );
        assert!(error.to_string().contains("Positive"), "{error}");
    }
    assert!(stepper.state().is_none());
}
