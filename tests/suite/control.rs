//! Controllers inside runs: the inputs set before each step from the state it starts from, held
//! over the step, with events, save times, recording and partial results as without them.

use dirac::prelude::*;
use scenes::knife_edge;

/// `ẍ = −x + u`: an oscillator pushed by the input `u`.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces(u * dx),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct Pushed;

/// The feedback of the tests: a spring and a damper, `u = −x − ẋ`.
fn feedback(x: f64, v: f64) -> f64 {
    -x - v
}

fn started(quadrature: Quadrature, h: f64) -> Stepper<Pushed, 1> {
    let mut stepper = Stepper::new(Pushed, quadrature, h).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    stepper
}

#[test]
fn a_controlled_run_is_the_loop_written_by_hand() {
    // Saving every 10th step, the run solves the velocity the controller reads at the other
    // steps too: the step's mean velocity would be O(h) off.
    for (quadrature, every) in [
        (Quadrature::midpoint(), 1),
        (Quadrature::galerkin(2).unwrap(), 1),
        (Quadrature::midpoint(), 10),
    ] {
        let h = 0.05;
        let mut by_hand = started(quadrature.clone(), h);
        let u = by_hand.input("u").unwrap();
        let mut expected = vec![(by_hand.t(), by_hand.q()[0], by_hand.p()[0])];
        for _ in 0..200 {
            let (x, v) = (by_hand.q()[0], by_hand.v().unwrap()[0]);
            by_hand.set_input_value(u, feedback(x, v)).unwrap();
            by_hand.step().unwrap();
            expected.push((by_hand.t(), by_hand.q()[0], by_hand.p()[0]));
        }
        let mut stepper = started(quadrature.clone(), h);
        let mut seen = Vec::new();
        let run = Run::<1>::steps(200).every(every).control(|now, inputs| {
            seen.push(now.steps);
            inputs[u.index()] = feedback(now.sample.q[0], now.sample.v[0]);
        });
        let solution = stepper.solve(run).unwrap();
        assert_eq!(
            seen,
            (0..200).collect::<Vec<u64>>(),
            "called before each step"
        );
        let trajectory = &solution.trajectory;
        assert_eq!(trajectory.len(), 200 / every + 1);
        for (saved, &(t, x, p)) in expected.iter().step_by(every).enumerate() {
            // The two loops solve the velocity from different guesses, so the inputs agree to
            // Newton's tolerance, not bit for bit.
            let label = format!("{quadrature:?}, every {every}, sample {saved}");
            assert_eq!(trajectory.t()[saved], t, "{label}");
            assert!((trajectory.q()[saved][0] - x).abs() < 1e-12, "{label}: x");
            assert!((trajectory.p()[saved][0] - p).abs() < 1e-12, "{label}: p");
        }
        // The closed loop ẍ + ẋ + 2x = 0 decays as e^{−t/2}, from an amplitude below 2.
        let end = stepper.q()[0].abs();
        assert!(
            end < 2.0 * (-0.5 * 10.0_f64).exp(),
            "{quadrature:?}: |x(10)| = {end}"
        );
        assert!(
            (stepper.inputs()[0] - by_hand.inputs()[0]).abs() < 1e-12,
            "the last input stays set"
        );
    }
}

#[test]
fn a_controller_that_keeps_the_inputs_changes_nothing() {
    let zero = || {
        Event::new("x = 0", |_t, q: &SVector<f64, 1>, _v: &SVector<f64, 1>| {
            q[0]
        })
    };
    let times: Vec<f64> = (0..=40).map(|i| 0.25 * f64::from(i)).collect();
    let make = || {
        let mut stepper = started(Quadrature::galerkin(2).unwrap(), 0.1);
        stepper.set_input("u", 0.25).unwrap();
        stepper
    };
    let plain = make()
        .solve(Run::until(10.0).saveat(times.clone()).event(zero()))
        .unwrap();
    let mut calls = 0;
    let controlled = make()
        .solve(
            Run::until(10.0)
                .saveat(times)
                .event(zero())
                .control(|_, inputs| {
                    calls += 1;
                    assert_eq!(inputs, &[0.25]);
                }),
        )
        .unwrap();
    assert_eq!(calls, 100);
    assert_eq!(controlled, plain, "samples, events and status bit for bit");
    assert_eq!(plain.events.len(), 3);
}

#[test]
fn a_non_finite_input_ends_the_run_before_that_step() {
    let mut stepper = started(Quadrature::midpoint(), 0.1);
    let run = Run::<1>::steps(10).control(|now, inputs| {
        inputs[0] = if now.steps < 5 { 0.5 } else { f64::NAN };
    });
    let interrupted = stepper.solve(run).unwrap_err();
    assert!(
        matches!(interrupted.error, DiracError::NonFinite { .. }),
        "{}",
        interrupted.error
    );
    assert_eq!(stepper.steps(), 5, "the failing step is not taken");
    assert_eq!(
        interrupted.trajectory.len(),
        6,
        "the start and five steps are kept"
    );
    assert_eq!(
        stepper.inputs(),
        &[0.5],
        "the inputs stay at their last good values"
    );
    assert_eq!(interrupted.trajectory.q()[5], stepper.q());
}

#[test]
fn the_controller_sees_the_last_steps_multipliers() {
    let start = |stepper: &mut Stepper<knife_edge::KnifeEdge, 3>| {
        stepper
            .start_from_velocity(vector![0.0, 0.0, 0.0], vector![1.0, 0.0, 1.0])
            .unwrap();
    };
    let mut by_hand = Stepper::from_system(knife_edge::SCENE, 0.1).unwrap();
    start(&mut by_hand);
    let mut expected = Vec::new();
    for _ in 0..20 {
        expected.push(by_hand.multipliers().to_vec());
        by_hand.step().unwrap();
    }
    let mut stepper = Stepper::from_system(knife_edge::SCENE, 0.1).unwrap();
    start(&mut stepper);
    let mut seen = Vec::new();
    stepper
        .solve(Run::<3>::steps(20).control(|now, inputs| {
            assert!(inputs.is_empty());
            seen.push(now.multipliers.to_vec());
        }))
        .unwrap();
    assert_eq!(seen, expected);
    assert!(seen[1][0] != 0.0, "the blade pushes sideways as it turns");
}

#[test]
fn a_furuta_pendulum_is_balanced_with_its_torque_saturated() {
    use scenes::furuta;
    let h = 0.005;
    let scenes::lqr::Lqr { a, b, k } = furuta::linearisation_and_gain(h, 10.0).unwrap();
    let radius = |m: &dirac::nalgebra::DMatrix<f64>| {
        m.complex_eigenvalues()
            .iter()
            .map(|e| e.norm())
            .fold(0.0, f64::max)
    };
    assert!(radius(&a) > 1.0, "upright is unstable: {}", radius(&a));
    let closed = &a - &b * &k;
    assert!(
        radius(&closed) < 1.0,
        "the gain stabilises it: {}",
        radius(&closed)
    );
    let (samples, solution) = furuta::closed_loop(h, 0.2, furuta::TAU_MAX, 2000, 200).unwrap();
    assert_eq!((samples.len(), solution.trajectory.len()), (2000, 11));
    let limit = furuta::TAU_MAX;
    assert!(samples.iter().all(|s| s.tau.abs() <= limit));
    let saturated = samples.iter().filter(|s| s.tau.abs() == limit).count();
    assert!(saturated > 0, "the torque limit is reached");
    let last = samples.last().unwrap();
    assert!(
        last.theta.abs() < 1e-3 && last.tau.abs() < 1e-2,
        "θ = {}, τ = {}",
        last.theta,
        last.tau
    );
    // The limit is applied: with 0.2 N m the motor cannot catch the same tilt, and it falls.
    let (weak, _) = furuta::closed_loop(h, 0.2, 0.2, 2000, 200).unwrap();
    assert!(weak.last().unwrap().theta.abs() > 1.0);
}

/// Two pushed masses glued by a junction, the first pushed by the feedback `u = −x − ẋ` read
/// from the state before each step: by `Modular::run_controlled`, by hand, and monolithically.
#[test]
fn the_modular_step_runs_a_controller_as_a_stepper_does() {
    let h = 0.05;
    let glue = || Junction::new("glue").flow("a.x", 1.0).flow("b.x", -1.0);
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts.add("a", Pushed).unwrap();
    parts.add("b", Pushed).unwrap();
    parts.join(glue()).unwrap();
    parts.start_from_velocity(&[1.0, 1.0], &[0.0, 0.0]).unwrap();
    assert_eq!(parts.input_names(), ["a.u", "b.u"]);
    parts
        .run_controlled(200, |now, u| {
            assert_eq!(now.multipliers.len(), 1);
            u[0] = feedback(now.q[0], now.v[0]);
        })
        .unwrap();
    // The same loop by hand: set the input from the state, then step.
    let mut by_hand = Modular::new(Quadrature::midpoint(), h).unwrap();
    by_hand.add("a", Pushed).unwrap();
    by_hand.add("b", Pushed).unwrap();
    by_hand.join(glue()).unwrap();
    by_hand
        .start_from_velocity(&[1.0, 1.0], &[0.0, 0.0])
        .unwrap();
    for _ in 0..200 {
        let (q, v) = (by_hand.q(), by_hand.velocities().unwrap());
        by_hand.set_input("a.u", feedback(q[0], v[0])).unwrap();
        by_hand.step().unwrap();
    }
    assert_eq!(parts.q(), by_hand.q());
    // And the monolithic model under Run::control, to round-off.
    let glued = Interconnection::new(("a", Pushed), ("b", Pushed), [glue()]).unwrap();
    let mut whole = Stepper::new(glued, Quadrature::midpoint(), h).unwrap();
    whole
        .start_from_velocity(vector![1.0, 1.0], vector![0.0, 0.0])
        .unwrap();
    let run = Run::<2>::steps(200).control(|now, u| {
        u[0] = feedback(now.sample.q[0], now.sample.v[0]);
    });
    whole.solve(run).unwrap();
    assert!((parts.q()[0] - whole.q()[0]).abs() < 1e-12);
    // The feedback damped the glued pair (u = −x − ẋ on mass 2, spring 2: it decays).
    assert!(parts.q()[0].abs() < 0.1, "{}", parts.q()[0]);
    // A value that is not finite is refused before its step.
    let steps = parts.steps();
    assert!(matches!(
        parts.run_controlled(5, |_, u| u[1] = f64::NAN),
        Err(DiracError::NonFinite { .. })
    ));
    assert_eq!(parts.steps(), steps);
}
