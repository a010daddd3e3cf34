//! The speed/accuracy study: errors against closed forms computed independently, the reference it
//! converges by itself, the chooser picking the cheapest run that truly meets a target, and the
//! refusals.

use dirac::prelude::*;
use dirac::work_precision::Study;
use scenes::{double_pendulum, knife_edge, pendulum};

/// Unit oscillator, `x = cos t`, `p = −sin t`.
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x)]
#[derive(Debug, Clone, Copy)]
struct Oscillator;

fn oscillator_at(t: f64) -> Sample<1> {
    Sample {
        t,
        q: vector![t.cos()],
        v: vector![-t.sin()],
        p: vector![-t.sin()],
    }
}

const STEPS: [f64; 4] = [0.2, 0.1, 0.05, 0.025];

/// `|(q, p)(T) − exact|` by a stepper run here, not by the study, with the quadrature (by
/// Newton's method, by its step map or by fixed-point iteration) or the explicit composition
/// called `method`.
fn direct_error(method: &str, h: f64, horizon: f64) -> f64 {
    let exact = oscillator_at(horizon);
    let error =
        |q: SVector<f64, 1>, p: SVector<f64, 1>| (q - exact.q).amax().max((p - exact.p).amax());
    let (name, how) = match method.split_once(", ") {
        Some((name, how)) => (name, how),
        None => (method, "Newton"),
    };
    if let Some(quadrature) = scenes::quadratures().into_iter().find(|q| q.name() == name) {
        let mut stepper = Stepper::new(Oscillator, quadrature, h).unwrap();
        stepper = match how {
            "step map" => stepper.with_step_map().unwrap(),
            "fixed point" => stepper.with_fixed_point().unwrap(),
            _ => stepper,
        };
        stepper
            .start_from_velocity(vector![1.0], vector![0.0])
            .unwrap();
        stepper.run_until(horizon).unwrap();
        return error(stepper.q(), stepper.p());
    }
    let composition = [2, 4, 6, 8]
        .map(|order| Composition::of_order(order).unwrap())
        .into_iter()
        .find(|c| c.name() == method)
        .unwrap();
    let mut stepper = Stepper::explicit(Oscillator, composition, h).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    stepper.run_until(horizon).unwrap();
    error(stepper.q(), stepper.p())
}

#[test]
fn the_chooser_picks_the_cheapest_run_that_truly_meets_the_target() {
    let horizon = 10.0;
    let study = Study::new(Oscillator, horizon, |s| {
        s.start_from_velocity(vector![1.0], vector![0.0])
    })
    .steps(STEPS)
    .repetitions(2)
    .reference(oscillator_at(horizon))
    .run()
    .unwrap();
    assert!(study.failures.is_empty(), "{:?}", study.failures);
    // Three quadratures, by Newton's method and, the oscillator being quadratic, by their step
    // maps; and the oscillator being separable, by fixed-point iteration, and four explicit
    // compositions.
    assert_eq!(study.measurements.len(), 52);
    for m in &study.measurements {
        let direct = direct_error(&m.quadrature, m.h, horizon);
        assert!(
            (m.error - direct).abs() <= 1e-14 + 1e-9 * direct,
            "{m:?} against {direct:e}"
        );
        assert_eq!(m.steps, (horizon / m.h).round() as u64);
        assert!(m.seconds_per_unit_time > 0.0);
        // ω h ≤ 0.2: every iteration settles.
        assert_eq!(m.handed_over, 0, "{m:?}");
        let implicit = scenes::quadratures()
            .iter()
            .any(|q| q.name() == m.quadrature);
        let mapped = m.quadrature.ends_with(", step map");
        let iterated = m.quadrature.ends_with(", fixed point");
        if implicit || mapped || iterated {
            if mapped {
                assert_eq!(m.newton_iterations, 0.0, "{m:?}");
            } else {
                assert!(m.newton_iterations >= 1.0, "{m:?}");
            }
            // A quadratic energy: the Gauss rules keep it to round-off.
            assert!(m.energy_error < 1e-13, "{m:?}");
        } else {
            // An explicit step: no Newton iteration. Störmer–Verlet keeps p²/2 + (1 − h²/4) q²/2
            // exactly, so its energy error is (h²/8)(1 − q_k²), largest near q = 0 (where a step
            // comes within h/2 of it): h²/8 to a relative h²/4. The higher orders stay below it.
            assert_eq!(m.newton_iterations, 0.0, "{m:?}");
            let verlet = m.h * m.h / 8.0;
            if m.quadrature == "Störmer–Verlet" {
                assert!(
                    (m.energy_error - verlet).abs() <= 0.25 * m.h * m.h * verlet,
                    "{m:?}"
                );
            } else {
                assert!(m.energy_error < verlet, "{m:?}");
            }
        }
    }
    for target in [1e-3, 1e-6, 1e-9] {
        let choice = study.cheapest(target).unwrap();
        assert!(
            direct_error(&choice.quadrature, choice.h, horizon) <= target,
            "{choice:?}"
        );
        assert!(
            study
                .measurements
                .iter()
                .filter(|m| m.error <= target)
                .all(|m| m.seconds_per_unit_time >= choice.seconds_per_unit_time)
        );
        println!(
            "target {target:e}: {} at h = {} ({:e})",
            choice.quadrature, choice.h, choice.error
        );
    }
    // Unreachable targets (below the spacing of doubles near 1) are refused, naming the most
    // accurate run.
    let refused = study.cheapest(1e-17).unwrap_err();
    assert!(refused.to_string().contains("no run reaches"), "{refused}");
    let png = std::env::temp_dir().join("dirac_work_precision_test.png");
    study.save_png(&png, "oscillator to T = 10").unwrap();
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 10_000);
    let mut csv = Vec::new();
    study.write_csv(&mut csv).unwrap();
    let text = String::from_utf8(csv).unwrap();
    assert_eq!(text.lines().count(), 53);
    assert!(text.starts_with("quadrature,h,steps,error,energy_error,"));
}

/// `½ ẋ² − ½ x²` pushed by an input `u`.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces(u * dx),
    inputs(u)
)]
#[derive(Debug, Clone, Copy)]
struct Pushed;

/// A fixed-point run's steps that its iteration hands to Newton's method are counted: on the
/// double pendulum at h = 0.1 the iteration on the rows stops contracting in a few of the fast
/// swings of `galerkin(3)`'s 50 steps, and the study counts as many as the run itself does; at
/// h = 0.02 none. The steps handed over are still the rule's: the errors are Newton's. On the
/// oscillator at h = 2.5 the midpoint rule's iteration (contracting by `(ω h)²/4`) hands over
/// its first step, and that run is left out, without a failure, while h = 0.1 is measured.
#[test]
fn the_steps_a_fixed_point_run_hands_over_are_counted() {
    let (horizon, galerkin) = (5.0, Quadrature::galerkin(3).unwrap());
    let start =
        |s: &mut Stepper<_, 2>| s.start_from_velocity(double_pendulum::q0(), double_pendulum::v0());
    let mut reference = double_pendulum::stepper(Quadrature::galerkin(6).unwrap(), 0.01).unwrap();
    reference.run(500).unwrap();
    let study = Study::new(double_pendulum::SCENE, horizon, start)
        .quadratures([galerkin.clone()])
        .steps([0.1, 0.02])
        .repetitions(1)
        .reference(Sample {
            t: reference.t(),
            q: reference.q(),
            v: reference.v().unwrap(),
            p: reference.p(),
        })
        .run()
        .unwrap();
    let find = |name: &str, h: f64| {
        study
            .measurements
            .iter()
            .find(|m| m.quadrature == name && m.h == h)
            .unwrap_or_else(|| panic!("no {name} at h = {h}: {study:?}"))
    };
    for h in [0.1, 0.02] {
        let mut run = double_pendulum::stepper(galerkin.clone(), h)
            .unwrap()
            .with_fixed_point()
            .unwrap();
        run.run((horizon / h).round() as u64).unwrap();
        let expected = run.handed_over().0;
        assert_eq!(expected > 0, h > 0.05, "h = {h}: {expected}");
        let (newton, iterated) = (find("galerkin(3)", h), find("galerkin(3), fixed point", h));
        assert_eq!(iterated.handed_over, expected, "{iterated:?}");
        assert!(
            (iterated.error - newton.error).abs() <= 1e-12 * newton.error.max(1.0),
            "{iterated:?} against {newton:?}"
        );
    }
    let study = Study::new(Oscillator, 10.0, |s| {
        s.start_from_velocity(vector![1.0], vector![0.0])
    })
    .quadratures([Quadrature::midpoint()])
    .compositions([])
    .steps([0.1, 2.5])
    .repetitions(1)
    .reference(oscillator_at(10.0))
    .run()
    .unwrap();
    let iterated = |h: f64| {
        study
            .measurements
            .iter()
            .any(|m| m.quadrature == "midpoint, fixed point" && m.h == h)
    };
    assert!(iterated(0.1) && !iterated(2.5));
    assert!(study.failures.is_empty());
}

/// The explicit runs and those by fixed-point iteration hold the inputs the start function
/// sets, as the implicit runs do: Störmer–Verlet and the trapezoidal rule are one map, so
/// their errors agree.
#[test]
fn explicit_runs_hold_the_inputs_the_start_sets() {
    let horizon = 2.0;
    // x = u + (x₀ − u) cos t from rest.
    let (x0, u) = (1.0, 0.5);
    let x = u + (x0 - u) * horizon.cos();
    let v = -(x0 - u) * horizon.sin();
    let exact = Sample {
        t: horizon,
        q: vector![x],
        v: vector![v],
        p: vector![v],
    };
    let study = Study::new(Pushed, horizon, |s| {
        s.set_input("u", u)?;
        s.start_from_velocity(vector![x0], vector![0.0])
    })
    .quadratures([Quadrature::trapezoid()])
    .compositions([Composition::verlet()])
    .steps([0.1])
    .repetitions(1)
    .reference(exact)
    .run()
    .unwrap();
    let run = |name: &str| {
        study
            .measurements
            .iter()
            .find(|m| m.quadrature == name)
            .unwrap_or_else(|| panic!("no run {name}: {:?}", study.measurements))
    };
    let implicit = run("trapezoid");
    // The input held by the fixed-point iteration's runs too.
    for other in [run("Störmer–Verlet"), run("trapezoid, fixed point")] {
        assert!(
            (implicit.error - other.error).abs() < 1e-12,
            "{implicit:?} {other:?}"
        );
    }
    assert!(implicit.error < 1e-2);
}

/// Without a reference the study converges one, and it agrees with the pendulum's known q(5),
/// p(5) (14 digits) to its own error estimate.
#[test]
fn the_converged_reference_agrees_with_the_known_answer() {
    let study = Study::new(pendulum::SCENE, 5.0, |s| {
        s.start_from_momentum(vector![1.0], vector![0.0])
    })
    .steps([0.1, 0.05])
    .repetitions(1)
    .run()
    .unwrap();
    let reference = study.reference;
    let off = (reference.q[0] - pendulum::Q5)
        .abs()
        .max((reference.p[0] - pendulum::P5).abs());
    assert!(
        off < 1e-12,
        "reference off by {off:e} ({})",
        study.reference_method
    );
    assert!(study.reference_error < 1e-11, "{}", study.reference_error);
    assert!(study.reference_method.starts_with("galerkin(3)"));
    for m in &study.measurements {
        assert!(m.error > 0.0);
    }
    // The midpoint rule's energy error is bounded but not round-off: the energy chooser picks a
    // run that meets its target, the cheapest of those that do.
    let choice = study.cheapest_in_energy(1e-6).unwrap();
    assert!(choice.energy_error <= 1e-6);
    assert!(
        study
            .measurements
            .iter()
            .filter(|m| m.energy_error <= 1e-6)
            .all(|m| m.seconds_per_unit_time >= choice.seconds_per_unit_time)
    );
    // A target below what the reference resolves is refused.
    let refused = study.cheapest(study.reference_error).unwrap_err();
    assert!(
        refused
            .to_string()
            .contains("below what the reference resolves"),
        "{refused}"
    );
}

/// A quadrature the model refuses is reported with its reason; the rest of the grid is measured.
#[test]
fn refused_runs_are_reported_and_the_rest_measured() {
    let lobatto = Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap();
    let study = Study::new(knife_edge::SCENE, 1.0, |s| {
        s.start_from_velocity(SVector::zeros(), vector![0.0, 0.0, knife_edge::OMEGA])
    })
    .quadratures([Quadrature::midpoint(), lobatto])
    .steps([0.05])
    .repetitions(1)
    .reference(Sample {
        t: 1.0,
        q: knife_edge::exact(1.0),
        v: SVector::zeros(),
        p: SVector::zeros(),
    })
    .run()
    .unwrap();
    assert_eq!(study.measurements.len(), 1);
    assert_eq!(study.failures.len(), 1);
    assert!(study.failures[0].quadrature.contains("gauss_lobatto"));
    assert!(study.measurements[0].constraint_violation < 1e-12);
}

#[test]
fn an_invalid_study_is_refused() {
    let start = |s: &mut Stepper<Oscillator, 1>| s.start_from_velocity(vector![1.0], vector![0.0]);
    let invalid =
        |study: Study<'_, Oscillator, 1>| matches!(study.run(), Err(DiracError::InvalidRun(_)));
    assert!(invalid(Study::new(Oscillator, -1.0, start)));
    assert!(invalid(Study::new(Oscillator, 1.0, start).steps([])));
    assert!(invalid(
        Study::new(Oscillator, 1.0, start).steps([0.1, -0.1])
    ));
    assert!(invalid(
        Study::new(Oscillator, 1.0, start)
            .quadratures([])
            .compositions([])
    ));
    assert!(invalid(
        Study::new(Oscillator, 1.0, start).reference(oscillator_at(2.0))
    ));
    for bad in [-1e-9, f64::NAN] {
        assert!(invalid(
            Study::new(Oscillator, 1.0, start).reference_with_error(oscillator_at(1.0), bad)
        ));
    }
    // A reference that is not finite is refused (its NaN component would drop out of the
    // errors, and a run could seem to meet a target it does not).
    let mut nan = oscillator_at(1.0);
    nan.p[0] = f64::NAN;
    assert!(invalid(Study::new(Oscillator, 1.0, start).reference(nan)));
    // A fictive step that is not positive.
    assert!(invalid(
        Study::new(Oscillator, 1.0, start).time_transformed(1.0, [0.1, 0.0])
    ));
}

/// On Kepler's orbit of eccentricity 0.9 the study measures the time-transformed compositions
/// beside the fixed ones: each error is the one of a run made here against Kepler's equation,
/// the energy is kept to round-off, and a time-transformed run meets 1e-8 with fewer gradients
/// than any fixed-step run that meets it (counted, not timed).
#[test]
fn time_transformed_runs_are_measured_beside_the_fixed_ones() {
    use scenes::first_order::{FirstOrder, KeplerOde};
    use scenes::kepler;
    let orbit = KeplerOde {
        kepler: kepler::SCENE,
        e: 0.9,
    };
    let y = orbit.initial();
    let (q0, v0) = (vector![y[0], y[1]], vector![y[2], y[3]]);
    let horizon = 10.0;
    let end = orbit.exact(horizon).unwrap();
    let reference = Sample {
        t: horizon,
        q: vector![end[0], end[1]],
        v: vector![end[2], end[3]],
        p: vector![end[2], end[3]],
    };
    let study = Study::new(kepler::SCENE, horizon, |s| s.start_from_velocity(q0, v0))
        .quadratures([])
        .compositions([Composition::kahan_li_8()])
        .steps([0.01, 0.005, 0.0025])
        .time_transformed(0.0, [0.4, 0.2])
        .reference(reference)
        .repetitions(1)
        .run()
        .unwrap();
    assert!(study.failures.is_empty(), "{:?}", study.failures);
    let (adaptive, fixed): (Vec<_>, Vec<_>) = study
        .measurements
        .iter()
        .partition(|m| m.quadrature.ends_with("time-transformed"));
    assert_eq!((adaptive.len(), fixed.len()), (2, 3));
    for m in &adaptive {
        let mut comet =
            TimeTransformed::new(kepler::SCENE, Composition::kahan_li_8(), m.h).unwrap();
        comet.start_from_velocity(q0, v0).unwrap();
        comet.run_until(horizon).unwrap();
        let error = (comet.q() - reference.q)
            .amax()
            .max((comet.p() - reference.p).amax());
        assert_eq!((m.error, m.steps), (error, comet.steps()));
        assert!(m.energy_error < 1e-12, "{m:?}");
    }
    let target = 1e-8;
    assert!(fixed.iter().any(|m| m.error <= target));
    let cheapest_adaptive = adaptive
        .iter()
        .filter(|m| m.error <= target)
        .map(|m| m.steps)
        .min()
        .expect("a time-transformed run meets 1e-8");
    for m in fixed.iter().filter(|m| m.error <= target) {
        assert!(
            m.steps > 20 * cheapest_adaptive,
            "{m:?} {cheapest_adaptive}"
        );
    }
}
