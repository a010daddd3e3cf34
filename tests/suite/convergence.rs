//! Orders of accuracy, measured as least-squares slopes of log(error) against log(h) over four
//! step sizes halving each time, for every quadrature, on the pendulum (against its golden values)
//! and the double pendulum (against an order-8 reference).
//!
//! Tolerance on a slope: ±0.3. Over a factor 8 in h, a pre-asymptotic term of relative size
//! O(h) moves the fitted slope by well under that, while a wrong order moves it by ≥ 1.

use crate::support;

use dirac::prelude::*;
use scenes::{double_pendulum, pendulum};
use support::slope;

/// (quadrature, expected order, coarsest pendulum step count over T = 5).
fn cases() -> Vec<(Quadrature, f64, usize)> {
    vec![
        (Quadrature::midpoint(), 2.0, 50),
        (Quadrature::trapezoid(), 2.0, 50),
        (Quadrature::galerkin(2).unwrap(), 4.0, 10),
        (Quadrature::galerkin(3).unwrap(), 6.0, 10),
        (
            Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap(),
            4.0,
            10,
        ),
        (
            Quadrature::galerkin_with_rule(3, Rule::GaussLobatto(4)).unwrap(),
            6.0,
            10,
        ),
    ]
}

#[test]
fn pendulum_orders_match_theory() {
    for (quadrature, order, coarsest) in cases() {
        let hs: Vec<f64> = (0..4).map(|k| 5.0 / (coarsest << k) as f64).collect();
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| pendulum::error_at_5(quadrature.clone(), h).unwrap())
            .collect();
        let measured = slope(&hs, &errors);
        println!(
            "pendulum {:<32} order {measured:.2} errors {errors:?}",
            quadrature.name()
        );
        assert!(
            (measured - order).abs() < 0.3,
            "{}: slope {measured}",
            quadrature.name()
        );
    }
}

#[test]
fn double_pendulum_orders_match_theory() {
    let t = 1.0;
    let reference =
        double_pendulum::state_at(Quadrature::galerkin(4).unwrap(), 1.0 / 400.0, t).unwrap();
    for (quadrature, order, _) in cases() {
        let coarsest = match order as usize {
            2 => 100,
            4 => 20,
            _ => 20,
        };
        let hs: Vec<f64> = (0..4).map(|k| t / (coarsest << k) as f64).collect();
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                (double_pendulum::state_at(quadrature.clone(), h, t).unwrap() - reference).amax()
            })
            .collect();
        let measured = slope(&hs, &errors);
        println!(
            "double pendulum {:<32} order {measured:.2} errors {errors:?}",
            quadrature.name()
        );
        assert!(
            (measured - order).abs() < 0.3,
            "{}: slope {measured}",
            quadrature.name()
        );
    }
}

/// The predictor extrapolates the last four steps' solutions (a cubic), and Newton's method
/// evaluates the point after an update below the step tolerance without its Jacobian: on the
/// double pendulum at h = 0.01 a step takes 2.97 evaluations on average over 1 000 steps, 1.97
/// of them with the Jacobian (measured for the midpoint rule and `galerkin(2)`): two Newton
/// iterations and a check. With the line through two steps and a Jacobian at every evaluation
/// it took 3.22, all with the Jacobian, and from the last step alone 4.00. The answer does not change: the same tolerances end every solve.
#[test]
fn the_extrapolating_predictor_saves_a_newton_iteration() {
    let newton = NewtonOptions {
        jacobian_reuse: Some(0.0),
        ..Default::default()
    };
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let name = quadrature.name();
        let mut stepper = double_pendulum::stepper(quadrature, 0.01)
            .unwrap()
            .with_newton_options(newton)
            .unwrap();
        let (mut evaluations, mut jacobians) = (0, 0);
        for _ in 0..1000 {
            stepper.step().unwrap();
            let report = stepper.last_report().unwrap();
            evaluations += report.iterations;
            jacobians += report.jacobians;
        }
        let (mean, with_jacobian) = (evaluations as f64 / 1e3, jacobians as f64 / 1e3);
        println!("{name}: {mean} Newton evaluations per step, {with_jacobian} with the Jacobian");
        assert!(
            mean <= 3.0 && with_jacobian <= 2.0,
            "{name}: {mean}, {with_jacobian}"
        );
    }
}
