//! Known answers from DESIGN.md.

#[path = "../examples/scenes/mod.rs"]
mod scenes;

use dirac::prelude::*;
use scenes::{double_pendulum, hand_written::HandMidpoint, oscillator, pendulum};

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

/// The generated midpoint stepper and the hand-written one (analytic derivatives, same Newton)
/// follow the same discrete trajectory of the double pendulum.
#[test]
fn generated_stepper_matches_the_hand_written_one() {
    let h = 0.01;
    let mut generated = double_pendulum::stepper(Quadrature::midpoint(), h).unwrap();
    let mut hand = HandMidpoint::new(
        double_pendulum::SCENE,
        h,
        double_pendulum::q0(),
        double_pendulum::v0(),
    );
    assert!((generated.p() - hand.p).amax() < 1e-14);
    for _ in 0..200 {
        generated.step().unwrap();
        hand.step().unwrap();
    }
    assert!(
        (generated.q() - hand.q).amax() < 1e-10,
        "{}",
        (generated.q() - hand.q).amax()
    );
    assert!((generated.p() - hand.p).amax() < 1e-9);
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
