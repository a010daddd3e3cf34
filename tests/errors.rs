//! Bad input gives an error that says what is wrong, and a failed step changes nothing.

#[path = "../examples/scenes/mod.rs"]
mod scenes;

use dirac::prelude::*;
use scenes::pendulum::{Pendulum, SCENE};

#[test]
fn non_positive_or_non_finite_steps_are_rejected() {
    for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        let err = Stepper::new(SCENE, Quadrature::midpoint(), h).unwrap_err();
        assert!(matches!(err, DiracError::InvalidStep { .. }), "{err}");
    }
}

#[test]
fn non_finite_parameters_and_initial_values_are_named() {
    let err = Stepper::new(
        Pendulum {
            g: f64::NAN,
            ..SCENE
        },
        Quadrature::midpoint(),
        0.1,
    )
    .unwrap_err();
    assert!(err.to_string().contains("parameter g"), "{err}");
    let mut stepper = Stepper::new(SCENE, Quadrature::midpoint(), 0.1).unwrap();
    let err = stepper
        .start_from_velocity(vector![1.0], vector![f64::INFINITY])
        .unwrap_err();
    assert!(
        err.to_string().contains("initial velocity of theta"),
        "{err}"
    );
    assert_eq!(stepper.step(), Err(DiracError::NotStarted));
}

#[test]
fn a_step_that_does_not_converge_leaves_the_state_unchanged() {
    let options = NewtonOptions {
        max_iterations: 2,
        ..Default::default()
    };
    let mut stepper = Stepper::new(SCENE, Quadrature::gauss(2).unwrap(), 0.5)
        .unwrap()
        .with_newton_options(options)
        .unwrap();
    stepper
        .start_from_momentum(vector![1.0], vector![0.0])
        .unwrap();
    let before = (stepper.t(), stepper.q(), stepper.p(), stepper.steps());
    let err = stepper.step().unwrap_err();
    match &err {
        DiracError::NoConvergence {
            step,
            iterations,
            residual,
            ..
        } => {
            assert_eq!((*step, *iterations), (0, 2));
            assert!(*residual > 0.0);
        }
        other => panic!("expected NoConvergence, got {other}"),
    }
    assert_eq!(
        before,
        (stepper.t(), stepper.q(), stepper.p(), stepper.steps())
    );
    // With the default cap the same step succeeds.
    let mut stepper = stepper.with_newton_options(NewtonOptions::default()).unwrap();
    stepper.step().unwrap();
    assert_eq!(stepper.steps(), 1);
}

/// L = ẏ²/2 − x²/2 has no kinetic term in x: its Euler–Lagrange equation is the algebraic
/// x = 0 (a hidden constraint), and the trapezoid rule's step equations do not involve x_{k+1}
/// at all, so its Jacobian is singular.
#[dirac_system(coordinates(x, y), lagrangian = 0.5 * dot(y).powi(2) - 0.5 * x.powi(2))]
struct Degenerate;

#[test]
fn a_singular_jacobian_names_the_undetermined_coordinate() {
    let mut stepper = Stepper::new(Degenerate, Quadrature::trapezoid(), 0.1).unwrap();
    // x0 = 0.5 violates the hidden constraint x = 0.
    let err = stepper
        .start_from_velocity(vector![0.5, 0.0], vector![0.0, 1.0])
        .unwrap_err();
    assert!(
        matches!(&err, DiracError::InconsistentInitialState(m) if m.contains("(x)")),
        "{err}"
    );
    // x0 = 0: the predictor already solves the trapezoid's equations, but the solution is not
    // unique and is refused all the same.
    stepper
        .start_from_velocity(vector![0.0, 0.0], vector![0.0, 1.0])
        .unwrap();
    let err = stepper.step().unwrap_err();
    match &err {
        DiracError::SingularJacobian {
            unknowns, step: 0, ..
        } => assert_eq!(unknowns, "x (q_{k+1})"),
        other => panic!("expected SingularJacobian, got {other}"),
    }
    assert_eq!(stepper.q(), vector![0.0, 0.0]);
    // The energy skips the undetermined velocity: ẏ²/2 + x²/2.
    assert_eq!(stepper.energy(), Ok(0.5));
    // The midpoint rule couples x_k and x_{k+1}: the same model is well posed there.
    let mut stepper = Stepper::new(Degenerate, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_velocity(vector![0.0, 0.0], vector![0.0, 1.0])
        .unwrap();
    stepper.run(10).unwrap();
    assert!(stepper.q()[0].abs() < 1e-15 && (stepper.q()[1] - 1.0).abs() < 1e-14);
}

#[test]
fn trajectories_write_csv_with_named_columns() {
    let mut stepper = Stepper::new(SCENE, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_momentum(vector![1.0], vector![0.0])
        .unwrap();
    let trajectory = stepper.run(3).unwrap();
    let mut csv = Vec::new();
    trajectory.write_csv(&mut csv).unwrap();
    let text = String::from_utf8(csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "t,theta,p_theta,energy");
    assert_eq!(lines.len(), 5);
    let last: Vec<f64> = lines[4].split(',').map(|x| x.parse().unwrap()).collect();
    assert!((last[0] - 0.3).abs() < 1e-15);
    assert_eq!(last[1], trajectory.q()[3][0]);
    assert_eq!(last[2], trajectory.p()[3][0]);
}
