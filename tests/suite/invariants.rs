//! Long-run invariants: bounded energy error without drift and discrete Noether conservation of
//! angular momentum. Symplecticity of the step map is checked exactly, on the step's own
//! derivatives, in `tests/suite/step_derivatives.rs`.

use crate::support;

use dirac::prelude::*;
use scenes::{kepler, pendulum};
use support::energy_error_first_and_last_tenth;

/// 10⁶ midpoint steps of the pendulum (h = 0.1, T = 10⁵, ~16 000 periods). A symplectic method's
/// energy error oscillates: the largest error in the last tenth of the run is no larger than in
/// the first tenth (up to 10 %), where a drifting method would grow by a factor of ~10; and it
/// stays at its O(h²) size (measured 8.8e-5 at h = 0.1).
#[test]
fn energy_error_is_bounded_without_drift_over_a_million_steps() {
    let mut stepper = Stepper::new(pendulum::SCENE, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_momentum(vector![1.0], vector![0.0])
        .unwrap();
    let run = Run::steps(1_000_000).every(37);
    let trajectory = stepper.solve(run).unwrap().trajectory;
    let (first, last) = energy_error_first_and_last_tenth(trajectory.energy());
    assert!(
        last <= 1.1 * first,
        "drift: first tenth {first:e}, last tenth {last:e}"
    );
    assert!(first < 2e-4, "{first:e}");
    assert_eq!(stepper.steps(), 1_000_000);
}

/// Kepler, e = 0.5, 10⁵ steps of h = 0.01 (~160 orbits): the discrete Lagrangian is rotation
/// invariant, so x p_y − y p_x is conserved up to round-off, with every quadrature.
#[test]
fn kepler_angular_momentum_is_conserved_to_round_off() {
    for quadrature in scenes::quadratures() {
        let name = quadrature.name();
        let mut stepper = Stepper::new(kepler::SCENE, quadrature, 0.01).unwrap();
        stepper
            .start_from_momentum(kepler::q0(), kepler::p0())
            .unwrap();
        let l0 = kepler::angular_momentum(&stepper.q(), &stepper.p());
        let mut worst: f64 = 0.0;
        for _ in 0..100_000 {
            stepper.step().unwrap();
            worst =
                worst.max(((kepler::angular_momentum(&stepper.q(), &stepper.p()) - l0) / l0).abs());
        }
        assert!(worst <= 1e-12, "{name}: relative drift {worst:e}");
    }
}
