//! Exact derivatives of the step map, `A = ∂(q_{k+1}, p_{k+1})/∂(q_k, p_k)`, against central
//! differences (δ = 1e-5, as trep checks its derivatives) of the step itself, and the structure
//! they must have: `AᵀJA = J` for conservative models, `det A = 1` for one degree of freedom.

use crate::support;

use dirac::euler_lagrange::EulerLagrange;
use dirac::nalgebra::{DMatrix, DVector};
use dirac::newton::Newton;
use dirac::prelude::*;
use dirac::{State, StepDerivatives, StepEquations};
use scenes::{double_pendulum, knife_edge};

/// One step from `(q, p)` as a map, and its matrix of central differences with step `delta`.
/// The time the derivative checks start at: forces that depend on time must be read at the step's
/// own times, not from t = 0.
const T0: f64 = 1.3;

/// Starts `stepper` at `(T0, q, p)`.
fn start_at<S: DiracSystem<N>, const N: usize>(
    stepper: &mut Stepper<S, N>,
    q: SVector<f64, N>,
    p: SVector<f64, N>,
) {
    stepper.start_from_momentum(q, p).expect("a valid state");
    let v = stepper.v().expect("velocity");
    stepper
        .start_from_state(State::new(T0, q, p, v))
        .expect("a valid state");
}

/// `(q, p)` moved by `±delta` along phase-space coordinate `c` (`q` first, then `p`).
fn nudged<const N: usize>(
    q: SVector<f64, N>,
    p: SVector<f64, N>,
    c: usize,
    delta: f64,
) -> [(SVector<f64, N>, SVector<f64, N>); 2] {
    let (mut qp, mut pp, mut qm, mut pm) = (q, p, q, p);
    if c < N {
        qp[c] += delta;
        qm[c] -= delta;
    } else {
        pp[c - N] += delta;
        pm[c - N] -= delta;
    }
    [(qp, pp), (qm, pm)]
}

fn central_differences<S: DiracSystem<N>, const N: usize>(
    make: &dyn Fn() -> Stepper<S, N>,
    q: SVector<f64, N>,
    p: SVector<f64, N>,
    delta: f64,
) -> DMatrix<f64> {
    let step = |q: SVector<f64, N>, p: SVector<f64, N>| -> Vec<f64> {
        let mut stepper = make();
        start_at(&mut stepper, q, p);
        stepper.step().expect("step");
        stepper
            .q()
            .iter()
            .chain(stepper.p().iter())
            .copied()
            .collect()
    };
    let mut a = DMatrix::zeros(2 * N, 2 * N);
    for c in 0..2 * N {
        let [(qp, pp), (qm, pm)] = nudged(q, p, c, delta);
        let (plus, minus) = (step(qp, pp), step(qm, pm));
        for r in 0..2 * N {
            a[(r, c)] = (plus[r] - minus[r]) / (2.0 * delta);
        }
    }
    a
}

/// The exact derivatives at `(q, p)` and their largest difference from central differences.
fn compare<S: DiracSystem<N>, const N: usize>(
    make: &dyn Fn() -> Stepper<S, N>,
    q: SVector<f64, N>,
    p: SVector<f64, N>,
) -> (StepDerivatives<N>, f64) {
    let mut stepper = make();
    start_at(&mut stepper, q, p);
    let exact = stepper.step_linearised().expect("derivatives");
    let differences = central_differences(make, q, p, 1e-5);
    let difference = (exact.matrix() - differences).amax();
    (exact, difference)
}

/// A state of the double pendulum with large velocities (150 steps from the scene's start).
fn double_pendulum_state() -> (SVector<f64, 2>, SVector<f64, 2>) {
    let mut stepper = double_pendulum::stepper(Quadrature::midpoint(), 0.01).unwrap();
    stepper.run(150).unwrap();
    (stepper.q(), stepper.p())
}

#[test]
fn double_pendulum_derivatives_match_central_differences_and_are_symplectic() {
    let (q, p) = double_pendulum_state();
    for quadrature in scenes::quadratures() {
        let make = || Stepper::new(double_pendulum::SCENE, quadrature.clone(), 0.05).unwrap();
        let (exact, difference) = compare(&make, q, p);
        let name = quadrature.name();
        // Central differences at δ = 1e-5 are good to ~δ² |A'''| + ε/δ ≈ 1e-9 here.
        assert!(difference < 1e-7, "{name}: {difference:e}");
        // The map is far from the identity, so both checks can fail.
        assert!(
            (exact.matrix() - DMatrix::identity(4, 4)).amax() > 1e-2,
            "{name}"
        );
        let defect = exact.symplecticity_defect();
        assert!(defect < 1e-12, "{name}: ‖AᵀJA − J‖ = {defect:e}");
    }
}

/// A pendulum with position-dependent viscous damping, a torque `u · (1 + q²/4)(1 + cos(t)/2)`
/// (an input that enters through the state and the time) and a parametric drive `0.3 q sin 2t`
/// (its derivatives depend on time).
struct DampedPendulum {
    c: f64,
}

impl DiracSystem<1> for DampedPendulum {
    const FORCES: bool = true;
    const INPUTS: usize = 1;

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        v[0] * v[0] * 0.5 + q[0].cos()
    }

    fn force<D: Scalar>(
        &self,
        q: &SVector<D, 1>,
        v: &SVector<D, 1>,
        t: f64,
        u: &[D],
    ) -> SVector<D, 1> {
        // Depends on q too, so that ∂F/∂q enters.
        SVector::from([v[0] * (-self.c) * (q[0].cos() * 0.5 + 1.0)
            + u[0] * (q[0] * q[0] * 0.25 + 1.0) * (t.cos() * 0.5 + 1.0)
            + q[0] * (t * 2.0).sin() * 0.3])
    }
}

#[test]
fn forced_derivatives_match_central_differences() {
    for quadrature in scenes::quadratures() {
        let make = || {
            let mut stepper =
                Stepper::new(DampedPendulum { c: 0.7 }, quadrature.clone(), 0.1).unwrap();
            stepper.set_input("u0", 0.3).unwrap();
            stepper
        };
        let (exact, difference) = compare(&make, vector![0.8], vector![-1.2]);
        let name = quadrature.name();
        assert!(difference < 1e-7, "{name}: {difference:e}");
        // B = ∂(q_{k+1}, p_{k+1})/∂u against central differences in the input.
        let step_with = |u: f64| {
            let mut stepper = make();
            stepper.set_input("u0", u).unwrap();
            start_at(&mut stepper, vector![0.8], vector![-1.2]);
            stepper.step().unwrap();
            vector![stepper.q()[0], stepper.p()[0]]
        };
        let delta = 1e-5;
        let b = (step_with(0.3 + delta) - step_with(0.3 - delta)) / (2.0 * delta);
        let exact_b = exact.input_matrix();
        assert_eq!(exact_b.shape(), (2, 1));
        assert!(
            (exact_b[(0, 0)] - b[0]).abs() < 1e-8,
            "{name}: {exact_b} vs {b}"
        );
        assert!(
            (exact_b[(1, 0)] - b[1]).abs() < 1e-8,
            "{name}: {exact_b} vs {b}"
        );
        assert!(b[1].abs() > 1e-2, "the input moves the state");
        // Damping contracts phase-space area: det A < 1, by more than the differences' error.
        let det = exact.matrix().determinant();
        assert!(det < 1.0 - 1e-3, "{name}: det A = {det}");
    }
}

#[test]
fn one_degree_of_freedom_preserves_area() {
    for quadrature in scenes::quadratures() {
        let make = || Stepper::new(DampedPendulum { c: 0.0 }, quadrature.clone(), 0.2).unwrap();
        let (exact, difference) = compare(&make, vector![2.5], vector![0.4]);
        let det = exact.matrix().determinant();
        assert!(difference < 1e-7, "{}: {difference:e}", quadrature.name());
        assert!(
            (det - 1.0).abs() < 1e-14,
            "{}: det A = {det}",
            quadrature.name()
        );
    }
}

#[test]
fn a_linearised_step_is_the_same_step() {
    let mut plain = double_pendulum::stepper(Quadrature::galerkin(2).unwrap(), 0.01).unwrap();
    let mut linearised = plain.clone();
    for _ in 0..100 {
        plain.step().unwrap();
        linearised.step_linearised().unwrap();
    }
    assert_eq!((plain.q(), plain.p()), (linearised.q(), linearised.p()));
}

/// One step of `equations` from any `(q, p)`, through the public step-equations API (no start
/// checks, so perturbations off the constraint manifold are allowed): the new state, and the
/// exact derivatives at the solution.
fn raw_step<S: DiracSystem<N>, const N: usize>(
    equations: &mut EulerLagrange<S, N, Euclidean>,
    t0: f64,
    q: SVector<f64, N>,
    p: SVector<f64, N>,
    v: SVector<f64, N>,
) -> (SVector<f64, N>, SVector<f64, N>, StepDerivatives<N>) {
    let state = State::new(t0, q, p, v);
    let mut x = DVector::zeros(equations.unknowns());
    equations.predict(&state, None, &mut x);
    let options = NewtonOptions {
        max_contraction: f64::INFINITY,
        ..Default::default()
    };
    let mut newton = Newton::new(equations.unknowns(), options).unwrap();
    newton
        .solve(&mut x, |x, r, j| equations.assemble(&state, x, r, j))
        .expect("step");
    let next = equations.advance(&state, &x, 0).unwrap();
    // The derivatives need the Jacobian at the root, which the solve may not have evaluated.
    newton
        .factorise_at(&x, |x, r, j| equations.assemble(&state, x, r, j))
        .expect("a regular root");
    let derivatives = equations.linearise(&state, &x, &newton).unwrap();
    (*next.q(), *next.p(), derivatives)
}

/// The exact A (and B, for one input `u`) of a constrained model at a state of its own run,
/// against central differences of raw steps.
fn constrained_case<S: DiracSystem<N> + Clone, const N: usize>(
    name: &str,
    system: S,
    mut stepper: Stepper<S, N>,
    u: Option<f64>,
) {
    stepper.run(40).unwrap();
    let state = *stepper.state().unwrap();
    let (q, p, v) = (*state.q(), *state.p(), *state.velocity_hint());
    let point = stepper.constraint_point();
    let quadrature = stepper.quadrature().clone();
    let make = |u: f64| {
        let discrete = DiscreteLagrangian::new(system.clone(), quadrature.clone(), stepper.h());
        let mut equations = EulerLagrange::new(discrete).unwrap();
        equations.set_constraint_point(point);
        if S::INPUTS > 0 {
            equations.set_inputs(&[u]).unwrap();
        }
        // As a run does: the hidden constraints found at the start are projected at each end.
        equations.begin(&State::new(T0, q, p, v));
        equations
    };
    let u0 = u.unwrap_or(0.0);
    let (_, _, exact) = raw_step(&mut make(u0), T0, q, p, v);
    let delta = 1e-5;
    let mut worst = 0.0_f64;
    let a = exact.matrix();
    for c in 0..2 * N {
        let [(qp, pp), (qm, pm)] = nudged(q, p, c, delta);
        let (q1p, p1p, _) = raw_step(&mut make(u0), T0, qp, pp, v);
        let (q1m, p1m, _) = raw_step(&mut make(u0), T0, qm, pm, v);
        for r in 0..N {
            worst = worst.max((a[(r, c)] - (q1p[r] - q1m[r]) / (2.0 * delta)).abs());
            worst = worst.max((a[(N + r, c)] - (p1p[r] - p1m[r]) / (2.0 * delta)).abs());
        }
    }
    assert!(
        worst < 1e-7,
        "{name} ({point:?}): A differs from central differences by {worst:e}"
    );
    assert!(
        (a.clone() - DMatrix::identity(2 * N, 2 * N)).amax() > 1e-3,
        "{name}"
    );
    if let Some(u) = u {
        let (q1p, p1p, _) = raw_step(&mut make(u + delta), T0, q, p, v);
        let (q1m, p1m, _) = raw_step(&mut make(u - delta), T0, q, p, v);
        let b = exact.input_matrix();
        for r in 0..N {
            let dq = (q1p[r] - q1m[r]) / (2.0 * delta);
            let dp = (p1p[r] - p1m[r]) / (2.0 * delta);
            assert!((b[(r, 0)] - dq).abs() < 1e-7, "{name}: B row {r}");
            assert!((b[(N + r, 0)] - dp).abs() < 1e-7, "{name}: B row {}", N + r);
        }
        assert!(b.amax() > 1e-3, "{name}: the input moves the state");
    }
}

#[test]
fn constrained_derivatives_match_central_differences() {
    use scenes::{cartesian_pendulum, circuit};
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        // Each stepper evaluates the one-form at its own point; the raw steps use the same.
        let stepper = knife_edge::stepper(point, 0.01).unwrap();
        if point == stepper.constraint_point() {
            constrained_case("knife edge", knife_edge::SCENE, stepper, None);
        }
    }
    let mut pendulum =
        Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), 0.05).unwrap();
    pendulum
        .start_from_velocity(cartesian_pendulum::q0(1.0), SVector::zeros())
        .unwrap();
    constrained_case(
        "Cartesian pendulum",
        cartesian_pendulum::SCENE,
        pendulum,
        None,
    );
    let mut lc = Stepper::new(circuit::LC, Quadrature::midpoint(), 0.05).unwrap();
    lc.start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    constrained_case("LC circuit", circuit::LC, lc, None);
    // Unequal parallel capacitors with a current: the step's end is projected onto
    // q_c1/c1 = q_c3/c3, and A includes the projection.
    let unequal = circuit::LcCircuit {
        c3: 2.0,
        ..circuit::LC
    };
    let mut lc = Stepper::new(unequal, Quadrature::midpoint(), 0.05).unwrap();
    lc.start_from_velocity(
        vector![0.0, 0.2, 1.0, 0.4],
        vector![0.5, 0.5 / 3.0, 0.5, 1.0 / 3.0],
    )
    .unwrap();
    constrained_case("unequal LC circuit", unequal, lc, None);
    let system = support::monolithic_rlc::MonolithicRlc {
        l: 1.0,
        c1: 1.0,
        c2: 1.0,
        c3: 1.0,
        r: 0.5,
    };
    let mut rlc = Stepper::new(system, Quadrature::midpoint(), 0.05).unwrap();
    rlc.start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    rlc.set_input("u", 0.4).unwrap();
    constrained_case("RLC circuit", system, rlc, Some(0.4));
}

#[test]
fn holonomic_steps_keep_the_constraint_to_first_order() {
    // g(q_{k+1}) = 0 whatever (q_k, p_k): dg(q_{k+1}) ∂q_{k+1}/∂(q_k, p_k) = 0.
    use scenes::cartesian_pendulum;
    let mut stepper =
        Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), 0.05).unwrap();
    stepper
        .start_from_velocity(cartesian_pendulum::q0(1.0), SVector::zeros())
        .unwrap();
    stepper.run(10).unwrap();
    let a = stepper.step_linearised().unwrap();
    let q = stepper.q();
    let dg = vector![2.0 * q[0], 2.0 * q[1]];
    let along = dg.transpose() * a.q_q;
    let across = dg.transpose() * a.q_p;
    assert!(
        along.amax() < 1e-12 && across.amax() < 1e-12,
        "{along} {across}"
    );
}

#[test]
fn models_not_covered_yet_are_refused_and_keep_their_state() {
    let mut positive = Stepper::on_space(
        DampedPendulum { c: 0.0 },
        Positive,
        Quadrature::midpoint(),
        0.1,
    )
    .unwrap();
    positive
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    let error = positive.step_linearised().expect_err("not Rⁿ");
    assert!(matches!(error, DiracError::Unsupported(_)), "{error}");
    assert_eq!(positive.steps(), 0);
}

#[test]
fn the_cart_pole_linearisation_is_the_cayley_transform_and_lqr_balances_it() {
    use scenes::cart_pole::{self, SCENE};
    let h = 0.01;
    let cart_pole::Lqr { a, b, k } = cart_pole::linearisation_and_gain(h, 0.1).unwrap();
    // At rest upright the midpoint step of the linearised Lagrangian (mass matrix M, stiffness
    // m g l on θ, force u on x) is the implicit midpoint rule of ż = F z + G u:
    // A = (I − hF/2)⁻¹ (I + hF/2), B = (I − hF/2)⁻¹ h G.
    let mass = DMatrix::from_row_slice(
        2,
        2,
        &[
            SCENE.cart + SCENE.bob,
            SCENE.bob * SCENE.l,
            SCENE.bob * SCENE.l,
            SCENE.bob * SCENE.l * SCENE.l,
        ],
    );
    let mut f = DMatrix::zeros(4, 4);
    f.view_mut((0, 2), (2, 2))
        .copy_from(&mass.try_inverse().unwrap());
    f[(3, 1)] = SCENE.bob * SCENE.g * SCENE.l;
    let identity = DMatrix::<f64>::identity(4, 4);
    let implicit = (&identity - &f * (h / 2.0)).try_inverse().unwrap();
    let cayley = &implicit * (&identity + &f * (h / 2.0));
    let mut g = DMatrix::zeros(4, 1);
    g[(2, 0)] = h;
    assert!((&a - &cayley).amax() < 1e-13, "A {a} vs {cayley}");
    assert!((&b - &implicit * g).amax() < 1e-13, "B {b}");
    // Upright is unstable open loop and stable with the gain.
    let radius = |m: &DMatrix<f64>| {
        m.complex_eigenvalues()
            .iter()
            .map(|e| e.norm())
            .fold(0.0, f64::max)
    };
    assert!(radius(&a) > 1.05, "open loop {}", radius(&a));
    assert!(
        radius(&(&a - &b * &k)) < 0.999,
        "closed loop {}",
        radius(&(&a - &b * &k))
    );
    // The nonlinear closed loop from a 0.3 rad tilt settles.
    let samples = cart_pole::closed_loop(h, 0.3, 1000).unwrap();
    let last = samples.last().unwrap();
    let (x, theta) = (last.x, last.theta);
    assert!(theta.abs() < 1e-3 && x.abs() < 1e-2, "x = {x}, θ = {theta}");
    let peak = samples.iter().map(|s| s.theta.abs()).fold(0.0, f64::max);
    assert!(
        (peak - 0.3).abs() < 1e-12,
        "the tilt only decreases from its start: {peak}"
    );
}

/// The exact second derivatives at `(q, p)` from `T0` against central differences (step `delta`)
/// of the exact first derivatives: the largest difference and the largest second derivative.
fn second_order_check<S: DiracSystem<N>, const N: usize>(
    make: &dyn Fn() -> Stepper<S, N>,
    q: SVector<f64, N>,
    p: SVector<f64, N>,
    delta: f64,
) -> (f64, f64) {
    use dirac::StepHessians;
    let first_at = |q: SVector<f64, N>, p: SVector<f64, N>| {
        let mut stepper = make();
        start_at(&mut stepper, q, p);
        stepper.step_linearised().unwrap().matrix()
    };
    let mut stepper = make();
    start_at(&mut stepper, q, p);
    let (first, StepHessians { q: hq, p: hp }) = stepper.step_second_order().unwrap();
    assert_eq!(first.matrix(), first_at(q, p), "the same A");
    let (mut worst, mut largest) = (0.0_f64, 0.0_f64);
    for b in 0..2 * N {
        let [(qp, pp), (qm, pm)] = nudged(q, p, b, delta);
        let column = (first_at(qp, pp) - first_at(qm, pm)) / (2.0 * delta);
        for a in 0..2 * N {
            for i in 0..N {
                // Row i of A is ∂q_{k+1,i}/∂z, row N + i is ∂p_{k+1,i}/∂z.
                worst = worst.max((hq[i][(a, b)] - column[(i, a)]).abs());
                worst = worst.max((hp[i][(a, b)] - column[(N + i, a)]).abs());
                largest = largest.max(hq[i][(a, b)].abs()).max(hp[i][(a, b)].abs());
            }
        }
    }
    (worst, largest)
}

#[test]
fn second_derivatives_match_central_differences_of_the_first() {
    let (q, p) = double_pendulum_state();
    for quadrature in scenes::quadratures() {
        let name = quadrature.name();
        let make = || Stepper::new(double_pendulum::SCENE, quadrature.clone(), 0.05).unwrap();
        // At δ = 1e-5 the round-off of A (~1e-12) over 2δ reaches 1.3e-7 for galerkin(3); at
        // δ = 4e-5 the truncation error (∝ δ²) is 3–5e-8 for every rule, against second
        // derivatives of size 5.
        let (worst, largest) = second_order_check(&make, q, p, 4e-5);
        assert!(
            worst < 1e-7,
            "{name}: second derivatives differ by {worst:e}"
        );
        assert!(largest > 1e-2, "{name}: the step map is not linear here");
        // Forces that depend on the state, the time and an input add their own D²f.
        let forced = || {
            let mut stepper =
                Stepper::new(DampedPendulum { c: 0.7 }, quadrature.clone(), 0.1).unwrap();
            stepper.set_input("u0", 0.3).unwrap();
            stepper
        };
        let (worst, largest) = second_order_check(&forced, vector![0.8], vector![-1.2], 4e-5);
        assert!(
            worst < 1e-7,
            "{name}, forced: second derivatives differ by {worst:e}"
        );
        assert!(
            largest > 1e-2,
            "{name}, forced: the step map is not linear here"
        );
    }
}

#[test]
fn second_derivatives_are_refused_for_constrained_models() {
    let mut knife = knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).unwrap();
    let error = knife.step_second_order().expect_err("constrained");
    assert!(matches!(error, DiracError::Unsupported(_)), "{error}");
    assert_eq!(knife.steps(), 0);
}

/// A unit mass on the unit circle (`FORMS = 0`: the holonomic constraint `x² + y² = 1`;
/// `FORMS = 1`: its one-form `x dx + y dy`), under gravity, with damping that depends on the
/// position, a time-dependent push and an input torque.
#[derive(Debug, Clone, Copy)]
struct Bead<const FORMS: usize>;

impl<const FORMS: usize> DiracSystem<2> for Bead<FORMS> {
    const ONE_FORMS: usize = FORMS;
    const HOLONOMIC: usize = 1 - FORMS;
    const FORCES: bool = true;
    const INPUTS: usize = 1;

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        v.dot(v) * 0.5 - q[1] * 9.81
    }

    fn one_form<D: Scalar>(&self, q: &SVector<D, 2>, _a: usize) -> SVector<D, 2> {
        *q
    }

    fn holonomic<D: Scalar>(&self, q: &SVector<D, 2>, _b: usize) -> D {
        (q.dot(q) - 1.0) * 0.5
    }

    fn force<D: Scalar>(
        &self,
        q: &SVector<D, 2>,
        v: &SVector<D, 2>,
        t: f64,
        u: &[D],
    ) -> SVector<D, 2> {
        let damping = (q[0] * q[0] + 1.0) * -0.3;
        let torque = u[0] * (t.sin() * 0.5 + 1.0);
        SVector::from([
            v[0] * damping - q[1] * torque + q[0] * (t * 3.0).cos() * 0.2,
            v[1] * damping + q[0] * torque,
        ])
    }
}

/// Starts a bead at 0.7 rad with speed 3 along the circle, input 0.4.
fn start_bead<const FORMS: usize>(stepper: &mut Stepper<Bead<FORMS>, 2>) {
    let angle: f64 = 0.7;
    let q = vector![angle.sin(), -angle.cos()];
    let v = vector![angle.cos(), angle.sin()] * 3.0;
    stepper.start_from_velocity(q, v).unwrap();
    stepper.set_input("u0", 0.4).unwrap();
}

#[test]
fn constrained_and_forced_derivatives_match_at_every_point_and_rule() {
    for quadrature in [Quadrature::midpoint(), Quadrature::trapezoid()] {
        let mut holonomic = Stepper::new(Bead::<0>, quadrature.clone(), 0.02).unwrap();
        start_bead(&mut holonomic);
        constrained_case("holonomic bead", Bead::<0>, holonomic, Some(0.4));
        for point in [
            ConstraintPoint::Start,
            ConstraintPoint::Midpoint,
            ConstraintPoint::End,
        ] {
            let mut one_form = Stepper::new(Bead::<1>, quadrature.clone(), 0.02)
                .unwrap()
                .with_constraint_point(point);
            start_bead(&mut one_form);
            constrained_case("one-form bead", Bead::<1>, one_form, Some(0.4));
        }
    }
}

/// Two unit springs, one mass 1 and one mass `m`.
struct Masses {
    m: f64,
}

impl DiracSystem<2> for Masses {
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        (v[0] * v[0] + v[1] * v[1] * self.m - q.dot(q)) * 0.5
    }
}

#[test]
fn the_pivot_ratio_reports_an_ill_conditioned_step() {
    let ratio = |m: f64| {
        let mut stepper = Stepper::new(Masses { m }, Quadrature::midpoint(), 0.01).unwrap();
        stepper
            .start_from_velocity(vector![1.0, 1.0], vector![0.0, 0.0])
            .unwrap();
        stepper.step_linearised().unwrap().pivot_ratio
    };
    // The midpoint step's Jacobian is −diag(m_i/h + h/4): equal masses give ratio 1, a tiny
    // mass the ratio (1/h + h/4)/(m/h + h/4) = 4e4.
    assert!((ratio(1.0) - 1.0).abs() < 1e-12, "{}", ratio(1.0));
    let h = 0.01_f64;
    let expected = (1.0 / h + h / 4.0) / (1e-9 / h + h / 4.0);
    let stiff = ratio(1e-9);
    assert!(
        (stiff / expected - 1.0).abs() < 1e-9,
        "{stiff} vs {expected}"
    );
}

/// One step of the cart-pole (mass matrix depending on θ, an input force) from `(q, v)` with the
/// push `u`: the end's position and velocity.
fn cart_pole_step(q: SVector<f64, 2>, v: SVector<f64, 2>, u: f64, h: f64) -> [f64; 4] {
    let mut stepper = Stepper::new(
        scenes::cart_pole::SCENE,
        Quadrature::galerkin(2).unwrap(),
        h,
    )
    .expect("valid scene");
    stepper.start_from_velocity(q, v).expect("a valid state");
    stepper.set_input("u", u).expect("input u");
    stepper.step().expect("a step");
    let (q, v) = (stepper.q(), stepper.v().expect("velocity"));
    [q[0], q[1], v[0], v[1]]
}

/// The derivatives in `(q, v)` are those of the step map read in positions and velocities:
/// against central differences of the step started from nudged `(q, v)` and `u`, on a model
/// whose Legendre map depends on the position.
#[test]
fn derivatives_in_velocities_match_central_differences() {
    let (q, v, u, h) = (vector![0.1, 0.4], vector![-0.3, 0.7], 0.25, 0.05);
    let mut stepper = Stepper::new(
        scenes::cart_pole::SCENE,
        Quadrature::galerkin(2).unwrap(),
        h,
    )
    .unwrap();
    stepper.start_from_velocity(q, v).unwrap();
    stepper.set_input("u", u).unwrap();
    let found = stepper.step_linearised_in_velocities().unwrap();
    let (a, b) = (found.matrix(), found.input_matrix());
    let delta = 1e-5;
    let mut worst: f64 = 0.0;
    for column in 0..5 {
        let nudge = |sign: f64| {
            let mut z = [q[0], q[1], v[0], v[1], u];
            z[column] += sign * delta;
            cart_pole_step(vector![z[0], z[1]], vector![z[2], z[3]], z[4], h)
        };
        let (plus, minus) = (nudge(1.0), nudge(-1.0));
        for row in 0..4 {
            let difference = (plus[row] - minus[row]) / (2.0 * delta);
            let exact = if column < 4 {
                a[(row, column)]
            } else {
                b[(row, 0)]
            };
            worst = worst.max((difference - exact).abs() / exact.abs().max(1.0));
        }
    }
    assert!(
        worst < 1e-8,
        "(q, v) derivatives off central differences by {worst:e}"
    );
    // The same step as without derivatives.
    let end = cart_pole_step(q, v, u, h);
    assert_eq!([stepper.q()[0], stepper.q()[1]], [end[0], end[1]]);
}

/// An oscillator beside a coordinate without kinetic energy: `L = ½ẋ² − ½x² − ½y²`, whose
/// `∂²L/∂v²` is singular (and `y = 0` a hidden constraint).
struct HalfDegenerate;

impl DiracSystem<2> for HalfDegenerate {
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        (v[0] * v[0] - q[0] * q[0] - q[1] * q[1]) * 0.5
    }
}

/// A degenerate Lagrangian has no derivatives in `(q, v)`, nor has a constrained model (its
/// velocity comes with multipliers; the LC circuit is both): refused, the state as it was.
#[test]
fn derivatives_in_velocities_are_refused_where_the_legendre_map_is_singular() {
    let mut degenerate = Stepper::new(HalfDegenerate, Quadrature::midpoint(), 0.01).unwrap();
    degenerate
        .start_from_velocity(vector![1.0, 0.0], vector![0.0, 0.0])
        .unwrap();
    let before = (degenerate.q(), degenerate.p(), degenerate.steps());
    assert!(matches!(
        degenerate.step_linearised_in_velocities(),
        Err(DiracError::Unsupported(_))
    ));
    assert_eq!((degenerate.q(), degenerate.p(), degenerate.steps()), before);
    assert!(degenerate.step_linearised().is_ok());

    let mut stepper = Stepper::new(scenes::circuit::LC, Quadrature::midpoint(), 0.01).unwrap();
    stepper
        .start_from_velocity(scenes::circuit::q0(), SVector::zeros())
        .unwrap();
    let before = (stepper.q(), stepper.p(), stepper.steps());
    assert!(matches!(
        stepper.step_linearised_in_velocities(),
        Err(DiracError::Unsupported(_))
    ));
    assert_eq!((stepper.q(), stepper.p(), stepper.steps()), before);
    assert!(stepper.step_linearised().is_ok());
}
