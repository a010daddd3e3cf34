//! Linear models pay once: the attribute says which Lagrangians are quadratic in `(q, v)`, and a
//! stepper then keeps one factorised Jacobian for a run of linear step equations (the LC
//! circuit) and steps as Newton's method does, to round-off; a wrong claim costs iterations,
//! not accuracy.

use dirac::StepEquations;
use dirac::prelude::*;
use scenes::{cartesian_pendulum, circuit, knife_edge, oscillator, pendulum};

/// What the attribute declared: whether `S` is quadratic.
fn quadratic<S: DiracSystem<N>, const N: usize>() -> bool {
    S::QUADRATIC
}

#[dirac_system(coordinates(x), lagrangian = 0.5 * m * dot(x).powi(2) - c * abs(x))]
struct Kinked {
    m: f64,
    c: f64,
}

#[dirac_system(coordinates(x, y), lagrangian = 0.5 * dot(x) * dot(y) + 2.0 * x * y - x + 3.0)]
struct Mixed;

/// A damped oscillator: quadratic, but forced.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces(-c * dot(x) * dx),
)]
struct Damped {
    c: f64,
}

#[test]
fn the_attribute_says_which_lagrangians_are_quadratic() {
    assert!(quadratic::<circuit::LcCircuit, 4>());
    assert!(quadratic::<oscillator::Oscillator, 1>());
    assert!(quadratic::<Mixed, 2>());
    assert!(!quadratic::<pendulum::Pendulum, 1>());
    // |x| has no second derivative to speak of, but it is not a polynomial.
    assert!(!quadratic::<Kinked, 1>());
}

/// Only linear step equations keep their Jacobian: a quadratic `L` with constant one-forms and
/// nothing else.
#[test]
fn only_linear_step_equations_say_their_jacobian_is_constant() {
    let lc = Stepper::new(circuit::LC, Quadrature::midpoint(), 0.01).unwrap();
    assert!(lc.equations().constant_jacobian());
    let damped = Stepper::new(Damped { c: 0.1 }, Quadrature::midpoint(), 0.01).unwrap();
    assert!(quadratic::<Damped, 1>() && !damped.equations().constant_jacobian());
    // A one-form of the position (the knife edge's heading), a holonomic constraint, and a
    // Lagrangian that is not quadratic.
    let knife = knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).unwrap();
    assert!(!knife.equations().constant_jacobian());
    let held = Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), 0.01).unwrap();
    assert!(!held.equations().constant_jacobian());
    let swing = Stepper::new(pendulum::SCENE, Quadrature::midpoint(), 0.01).unwrap();
    assert!(!swing.equations().constant_jacobian());
}

/// The LC circuit over 1 000 steps of `quadrature`: its positions, and the Jacobians evaluated
/// after the first step.
fn lc_run(quadrature: Quadrature, options: NewtonOptions) -> (SVector<f64, 4>, usize) {
    let mut stepper = Stepper::new(circuit::LC, quadrature, 0.01)
        .unwrap()
        .with_newton_options(options)
        .unwrap();
    stepper
        .start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    stepper.step().unwrap();
    let mut jacobians = 0;
    for _ in 1..1_000 {
        stepper.step().unwrap();
        jacobians += stepper.last_report().unwrap().jacobians;
    }
    (stepper.q(), jacobians)
}

#[test]
fn a_linear_model_keeps_one_jacobian_and_steps_as_newtons_method_does() {
    let newton = NewtonOptions {
        jacobian_reuse: Some(0.0),
        ..Default::default()
    };
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let name = quadrature.name();
        let (kept, kept_jacobians) = lc_run(quadrature.clone(), NewtonOptions::default());
        let (fresh, fresh_jacobians) = lc_run(quadrature, newton);
        assert_eq!(kept_jacobians, 0, "{name}");
        assert!(fresh_jacobians >= 999, "{name}: {fresh_jacobians}");
        let gap = (kept - fresh).amax();
        assert!(gap <= 1e-13, "{name}: the runs differ by {gap:e}");
        // And both are the circuit: q_c2(10) against its closed form.
        assert!((kept[2] - circuit::lc_q_c2(10.0)).abs() < 1e-3, "{name}");
    }
}

/// A pendulum that claims to be quadratic: its equations are not linear.
struct Claimed;

impl DiracSystem<1> for Claimed {
    const QUADRATIC: bool = true;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        v[0] * v[0] * 0.5 + q[0].cos()
    }
}

#[test]
fn a_wrong_claim_costs_iterations_not_accuracy() {
    struct Honest;
    impl DiracSystem<1> for Honest {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
            Claimed.lagrangian(q, v)
        }
    }
    let (q0, v0) = (SVector::from([2.0]), SVector::from([0.5]));
    let mut claimed = Stepper::new(Claimed, Quadrature::midpoint(), 0.1).unwrap();
    let mut honest = Stepper::new(Honest, Quadrature::midpoint(), 0.1).unwrap();
    claimed.start_from_velocity(q0, v0).unwrap();
    honest.start_from_velocity(q0, v0).unwrap();
    let (mut claimed_iterations, mut honest_iterations) = (0, 0);
    for _ in 0..500 {
        claimed.step().unwrap();
        honest.step().unwrap();
        claimed_iterations += claimed.last_report().unwrap().iterations;
        honest_iterations += honest.last_report().unwrap().iterations;
    }
    // The kept Jacobian is not the pendulum's: the iteration converges, linearly, in more
    // evaluations than Newton's method takes.
    assert!(
        claimed_iterations > honest_iterations,
        "{claimed_iterations} against {honest_iterations}"
    );
    let gap = (claimed.q() - honest.q()).amax();
    assert!(gap <= 1e-10, "the runs differ by {gap:e}");
}
