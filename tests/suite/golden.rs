//! Known answers from `docs/scenes.md`.

use dirac::prelude::*;
use scenes::hand_written::{Galerkin2, HandEquations, HandStepper, KnifeEdgeMidpoint, Midpoint};
use scenes::{double_pendulum, knife_edge, oscillator, pendulum};

/// Harmonic oscillator m = 1, k = 0.5, q0 = 0.5, h = 0.1, T = 1: the error bounds of the design
/// (midpoint < 4e-4, trapezoid < 2e-4) and the higher orders far below (measured 8.0e-9 and
/// 2.9e-13; bounds a decade above).
#[test]
fn oscillator_error_bounds() {
    let bounds = [
        (Quadrature::midpoint(), 4e-4),
        (Quadrature::trapezoid(), 2e-4),
        (Quadrature::galerkin(2).unwrap(), 1e-7),
        (Quadrature::galerkin(3).unwrap(), 1e-11),
    ];
    for (quadrature, bound) in bounds {
        let error = oscillator::max_error(quadrature.clone(), 0.1).unwrap();
        assert!(
            error < bound,
            "{}: {error:e} ≥ {bound:e}",
            quadrature.name()
        );
    }
}

/// The midpoint rule preserves quadratic invariants: the oscillator's energy to round-off.
#[test]
fn midpoint_keeps_the_oscillator_energy_exactly() {
    let mut stepper = Stepper::new(oscillator::SCENE, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_momentum(vector![0.5], vector![0.0])
        .unwrap();
    let trajectory = stepper.run(1000).unwrap();
    assert!(
        trajectory.max_energy_error() < 1e-15,
        "{}",
        trajectory.max_energy_error()
    );
    // and the exact energy k q0²/2.
    assert!((trajectory.energy()[0] - 0.0625).abs() < 1e-16);
}

/// Pendulum at T = 5: q(5) = −0.02395128485293, p(5) = 0.95855190346756. Order 6 with h = 0.05
/// reaches the golden digits (measured 5e-13); the midpoint rule is within its O(h²) error.
#[test]
fn pendulum_golden_values() {
    let error = pendulum::error_at_5(Quadrature::galerkin(3).unwrap(), 0.05).unwrap();
    assert!(error < 2e-12, "{error:e}");
    let error = pendulum::error_at_5(Quadrature::midpoint(), 0.05).unwrap();
    assert!(error < 1e-3 && error > 1e-5, "{error:e}");
}

/// Steps `generated` and `hand` 200 times side by side: their positions and momenta agree to
/// `tolerance` after every step (the same discrete trajectory, from the same start).
fn same_trajectory<S: DiracSystem<N>, E: HandEquations<N>, const N: usize>(
    mut generated: Stepper<S, N>,
    mut hand: HandStepper<E, N>,
    tolerance: f64,
) {
    assert!((generated.p() - hand.p).amax() < 1e-14);
    let (start, mut moved) = (hand.q, 0.0_f64);
    for step in 1..=200 {
        generated.step().unwrap();
        hand.step().unwrap();
        let (dq, dp) = (
            (generated.q() - hand.q).amax(),
            (generated.p() - hand.p).amax(),
        );
        assert!(
            dq < tolerance && dp < tolerance,
            "step {step}: {dq:e}, {dp:e}"
        );
        moved = moved.max((hand.q - start).amax());
    }
    // The trajectories went somewhere: the agreement is not that of two resting states.
    assert!(moved > 0.1, "{moved}");
}

/// The generated steppers and the hand-written ones of the benches (analytic derivatives, same
/// Newton, same predictor) follow the same discrete trajectories: the double pendulum under the
/// midpoint rule and `galerkin(2)`, the knife edge under the midpoint rule.
#[test]
fn generated_steppers_match_the_hand_written_ones() {
    let h = 0.01;
    let (q0, v0) = (double_pendulum::q0(), double_pendulum::v0());
    let scene = double_pendulum::SCENE;
    same_trajectory(
        double_pendulum::stepper(Quadrature::midpoint(), h).unwrap(),
        HandStepper::new(Midpoint(scene), h, q0, v0),
        1e-12,
    );
    same_trajectory(
        double_pendulum::stepper(Quadrature::galerkin(2).unwrap(), h).unwrap(),
        HandStepper::new(Galerkin2(scene), h, q0, v0),
        1e-12,
    );
    same_trajectory(
        knife_edge::stepper(ConstraintPoint::Midpoint, h).unwrap(),
        HandStepper::new(
            KnifeEdgeMidpoint(knife_edge::SCENE),
            h,
            SVector::zeros(),
            vector![0.0, 0.0, knife_edge::OMEGA],
        ),
        1e-12,
    );
}

/// Several quadratures of one model in one program, and the system's own default.
#[test]
fn quadratures_are_values_of_one_stepper_type() {
    let steppers: Vec<Stepper<pendulum::Pendulum, 1>> = scenes::quadratures()
        .into_iter()
        .map(|q| Stepper::new(pendulum::SCENE, q, 0.1).unwrap())
        .collect();
    assert_eq!(steppers.len(), 4);
    assert_eq!(
        Stepper::from_system(oscillator::SCENE, 0.1)
            .unwrap()
            .quadrature()
            .name(),
        "midpoint"
    );
}
