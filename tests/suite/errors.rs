//! Bad input gives an error that says what is wrong, and a failed step changes nothing.

use dirac::prelude::*;
use scenes::pendulum::{self, Pendulum, SCENE};

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
    let mut stepper = Stepper::new(SCENE, Quadrature::galerkin(2).unwrap(), 0.5)
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
    let mut stepper = stepper
        .with_newton_options(NewtonOptions::default())
        .unwrap();
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
    // unique: the rule is refused before the first step, and the stepper is not started.
    let err = stepper
        .start_from_velocity(vector![0.0, 0.0], vector![0.0, 1.0])
        .unwrap_err();
    match &err {
        DiracError::SingularJacobian {
            unknowns, step: 0, ..
        } => assert_eq!(unknowns, "x (q_{k+1})"),
        other => panic!("expected SingularJacobian, got {other}"),
    }
    assert!(stepper.state().is_none());
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
    assert_eq!(lines[0], "t,theta,v_theta,p_theta,energy");
    assert_eq!(lines.len(), 5);
    let last: Vec<f64> = lines[4].split(',').map(|x| x.parse().unwrap()).collect();
    assert!((last[0] - 0.3).abs() < 1e-15);
    assert_eq!(last[1], trajectory.q()[3][0]);
    assert_eq!(last[2], trajectory.v()[3][0]);
    assert_eq!(last[3], trajectory.p()[3][0]);
    assert_eq!(last[4], trajectory.energy()[3]);
}

/// L = v²/2 − √(1 − q): defined for q ≤ 1 only; the force pushes q towards the edge.
#[dirac_system(coordinates(q), lagrangian = 0.5 * dot(q).powi(2) - sqrt(1.0 - q))]
struct Edge;

/// The macro declares a Lagrangian finite everywhere only where its expression has no domain:
/// the pendulum's, not `Edge`'s, whose step ends are checked.
#[test]
fn only_a_lagrangian_without_a_domain_skips_the_end_check() {
    const { assert!(<Pendulum as DiracSystem<1>>::LAGRANGIAN_ENTIRE) };
    const { assert!(!<Edge as DiracSystem<1>>::LAGRANGIAN_ENTIRE) };
}

#[test]
fn an_initial_state_outside_the_lagrangians_domain_is_refused() {
    let mut stepper = Stepper::new(Edge, Quadrature::midpoint(), 0.1).unwrap();
    let err = stepper
        .start_from_velocity(vector![2.0], vector![0.0])
        .unwrap_err();
    assert!(
        matches!(&err, DiracError::NonFinite { what, .. } if what.contains("Lagrangian at the initial state")),
        "{err}"
    );
    assert_eq!(stepper.energy(), Err(DiracError::NotStarted));
    // A velocity so large that the Lagrangian overflows.
    let err = Stepper::new(pendulum::SCENE, Quadrature::midpoint(), 0.1)
        .unwrap()
        .start_from_velocity(vector![0.0], vector![1e200])
        .unwrap_err();
    assert!(
        matches!(&err, DiracError::NonFinite { what, .. } if what.contains("initial state")),
        "{err}"
    );
}

/// The midpoint rule evaluates L at step midpoints only; a step whose end leaves the domain is
/// refused all the same, the state stays at the last good step, and `run` hands back every
/// sample it recorded, none of them NaN.
#[test]
fn a_step_leaving_the_domain_is_refused_and_run_keeps_its_trajectory() {
    for quadrature in scenes::quadratures() {
        let name = quadrature.name();
        let mut stepper = Stepper::new(Edge, quadrature, 0.1).unwrap();
        stepper
            .start_from_velocity(vector![0.0], vector![1.0])
            .unwrap();
        let interrupted = stepper.run(100).unwrap_err();
        let steps = stepper.steps() as usize;
        assert!(steps > 0 && steps < 100, "{name}: {steps} steps");
        assert_eq!(interrupted.trajectory.len(), steps + 1, "{name}");
        assert!(
            matches!(
                interrupted.error,
                DiracError::NonFinite { .. }
                    | DiracError::UntrustedStep { .. }
                    | DiracError::NoConvergence { .. }
            ),
            "{name}: {}",
            interrupted.error
        );
        assert!(stepper.q()[0] <= 1.0, "{name}");
        assert_eq!(stepper.q(), *interrupted.trajectory.q().last().unwrap());
        assert!(
            interrupted
                .trajectory
                .energy()
                .iter()
                .all(|e| e.is_finite()),
            "{name}"
        );
        // The energy of the last good state is finite, and `?` still yields a DiracError.
        assert!(stepper.energy().unwrap().is_finite());
        let as_error: DiracError = interrupted.into();
        assert!(!as_error.to_string().is_empty());
    }
}

#[test]
fn newton_options_out_of_range_are_refused() {
    let stepper = || Stepper::new(pendulum::SCENE, Quadrature::midpoint(), 0.1).unwrap();
    for options in [
        NewtonOptions {
            residual_tolerance: f64::NAN,
            ..Default::default()
        },
        NewtonOptions {
            step_tolerance: -1.0,
            ..Default::default()
        },
        NewtonOptions {
            max_iterations: 0,
            ..Default::default()
        },
        NewtonOptions {
            max_contraction: 0.0,
            ..Default::default()
        },
        NewtonOptions {
            singular_tolerance: 1.0,
            ..Default::default()
        },
    ] {
        let err = stepper().with_newton_options(options).unwrap_err();
        assert!(matches!(err, DiracError::InvalidOptions(_)), "{err}");
    }
    assert!(
        stepper()
            .with_newton_options(NewtonOptions::default())
            .is_ok()
    );
}

/// A relativistic particle, L = −m c² √(1 − v²/c²) − k q²/2: p = m v / √(1 − v²/c²), so
/// v = p / √(m² + p²/c²). From v = 0 a full Newton step for p ≥ 2mc lands at |v| ≥ 2c, outside
/// the Lagrangian's domain; the globalised inversion backtracks into it.
#[dirac_system(
    coordinates(x),
    lagrangian = -m * c * c * sqrt(1.0 - dot(x).powi(2) / (c * c)) - 0.5 * k * x.powi(2)
)]
#[derive(Clone)]
struct Relativistic {
    m: f64,
    c: f64,
    k: f64,
}

#[test]
fn momentum_starts_solve_strongly_nonlinear_legendre_transforms() {
    let particle = Relativistic {
        m: 1.0,
        c: 1.0,
        k: 1.0,
    };
    for p in [2.0, 3.0, 10.0, 100.0] {
        let mut stepper = Stepper::new(particle.clone(), Quadrature::midpoint(), 0.01).unwrap();
        stepper
            .start_from_momentum(vector![0.0], vector![p])
            .unwrap();
        let exact = p / (1.0 + p * p).sqrt();
        assert!((stepper.v().unwrap()[0] - exact).abs() < 1e-12, "p = {p}");
        stepper.step().unwrap();
        // From a guess near the answer as well.
        let mut near = Stepper::new(particle.clone(), Quadrature::midpoint(), 0.01).unwrap();
        near.start_from_momentum_near(vector![0.0], vector![p], vector![0.9])
            .unwrap();
        assert!((near.v().unwrap()[0] - exact).abs() < 1e-12, "p = {p}");
    }
}

#[test]
fn out_of_range_queries_are_errors_not_panics() {
    let midpoint = Quadrature::midpoint();
    assert_eq!(midpoint.basis(5, 5), None);
    assert_eq!(midpoint.basis_derivative(0, 2), None);
    assert_eq!(midpoint.basis(0, 1), Some(0.5));
    let ld = DiscreteLagrangian::new(pendulum::SCENE, Quadrature::galerkin(2).unwrap(), 0.1);
    assert!(matches!(
        ld.value(&[vector![0.0], vector![0.1]]),
        Err(DiracError::Dimension(_))
    ));
    assert!(
        ld.value(&[vector![0.0], vector![0.05], vector![0.1]])
            .is_ok()
    );
    assert!(matches!(
        Trajectory::<2>::new(vec!["x".into()]),
        Err(DiracError::Dimension(_))
    ));
    let mut trajectory =
        Trajectory::<1>::with_multipliers(vec!["x".into()], vec!["mu".into()]).unwrap();
    let zero = vector![0.0];
    let sample = dirac::Sample {
        t: 0.0,
        q: zero,
        v: zero,
        p: zero,
    };
    assert!(trajectory.push(&sample, 0.0).is_err()); // it records multipliers
    assert!(
        trajectory
            .push_constrained(&sample, 0.0, 0.0, &[1.0, 2.0])
            .is_err()
    );
    assert!(trajectory.is_empty());
    let mut newton = dirac::Newton::new(2, NewtonOptions::default()).unwrap();
    let mut x = dirac::nalgebra::DVector::zeros(3);
    assert_eq!(
        newton.solve(&mut x, |_, _, _| 1.0),
        Err(dirac::NewtonFailure::Dimension {
            expected: 2,
            got: 3
        })
    );
}

/// A refused step leaves everything as it was, down to the predictor and the compensated
/// sums' carries: after `UntrustedStep`, the stepper and a copy taken before the step continue
/// bit for bit alike (with the check off, so that the step can be taken).
#[test]
fn an_untrusted_step_leaves_the_whole_stepper_as_it_was() {
    use scenes::double_pendulum::{self, DoublePendulum};
    let model = DoublePendulum {
        m1: 0.0,
        ..double_pendulum::SCENE
    };
    let mut stepper = Stepper::new(model, Quadrature::midpoint(), 0.01).unwrap();
    stepper
        .start_from_velocity(double_pendulum::q0(), double_pendulum::v0())
        .unwrap();
    let before = loop {
        let before = stepper.clone();
        match stepper.step() {
            Ok(()) => continue,
            Err(err) => {
                assert!(matches!(err, DiracError::UntrustedStep { .. }), "{err}");
                break before;
            }
        }
    };
    let same = |s: &Stepper<DoublePendulum, 2>| {
        (
            s.t(),
            s.q(),
            s.p(),
            s.steps(),
            s.last_report(),
            s.multipliers().to_vec(),
        )
    };
    assert_eq!(same(&stepper), same(&before));
    let off = NewtonOptions {
        max_contraction: f64::INFINITY,
        ..Default::default()
    };
    let (mut a, mut b) = (
        stepper.with_newton_options(off).unwrap(),
        before.with_newton_options(off).unwrap(),
    );
    let (ra, rb) = (a.step(), b.step());
    assert_eq!(ra, rb);
    assert_eq!(same(&a), same(&b));
}

/// A hand-written model may name an invalid quadrature: `Stepper::from_system` refuses it with
/// the quadrature's error (the macro checks its own at compile time).
struct BadQuadrature;

impl DiracSystem<1> for BadQuadrature {
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        (v[0] * v[0] - q[0] * q[0]) * 0.5
    }

    fn quadrature(&self) -> Result<Quadrature, DiracError> {
        Quadrature::galerkin_with_rule(0, Rule::GaussLegendre(1))
    }
}

#[test]
fn an_invalid_quadrature_of_a_model_is_an_error() {
    assert!(matches!(
        Stepper::from_system(BadQuadrature, 0.1),
        Err(DiracError::InvalidQuadrature(_))
    ));
}

/// A free particle on the plane held to move radially, `A(q) = (q₂, −q₁)/|q|`: the one-form is
/// not finite at the origin.
struct Radial;

impl DiracSystem<2> for Radial {
    const ONE_FORMS: usize = 1;
    fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        (v[0] * v[0] + v[1] * v[1]) * 0.5
    }
    fn one_form<D: Scalar>(&self, q: &SVector<D, 2>, _a: usize) -> SVector<D, 2> {
        let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
        SVector::from([q[1] / r, -q[0] / r])
    }
}

/// A start where a constraint is not finite is refused there, naming it (the start check passed
/// it before, and the first step failed with a singular Jacobian that named no cause).
#[test]
fn a_constraint_that_is_not_finite_at_the_start_is_refused() {
    let mut stepper = Stepper::new(Radial, Quadrature::midpoint(), 0.1).unwrap();
    let err = stepper
        .start_from_velocity(SVector::zeros(), vector![1.0, 0.0])
        .unwrap_err();
    assert!(
        matches!(&err, DiracError::InconsistentInitialState(why) if why.contains("not finite")),
        "{err}"
    );
    assert_eq!(stepper.energy(), Err(DiracError::NotStarted));
    // Away from the origin the same model starts and keeps its constraint.
    stepper
        .start_from_velocity(vector![1.0, 0.0], vector![1.0, 0.0])
        .unwrap();
    stepper.run(10).unwrap();
    assert!(stepper.q()[1].abs() < 1e-12, "{}", stepper.q());
}
