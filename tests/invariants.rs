//! Long-run invariants: bounded energy error without drift, discrete Noether conservation of
//! angular momentum, and symplecticity of the step map.

#[path = "../examples/scenes/mod.rs"]
mod scenes;
mod support;

use dirac::nalgebra::{SMatrix, SVector};
use dirac::prelude::*;
use scenes::{double_pendulum, kepler, pendulum};
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
    let mut trajectory = Trajectory::new(stepper.coordinate_names()).unwrap();
    stepper.record(&mut trajectory, 1_000_000, 37).unwrap();
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

/// One step of the double pendulum as a map (q, p) ↦ (q', p').
fn step_map(quadrature: &Quadrature, h: f64, x: SVector<f64, 4>) -> SVector<f64, 4> {
    let mut stepper = Stepper::new(double_pendulum::SCENE, quadrature.clone(), h).unwrap();
    stepper
        .start_from_momentum(vector![x[0], x[1]], vector![x[2], x[3]])
        .unwrap();
    stepper.step().unwrap();
    let (q, p) = (stepper.q(), stepper.p());
    vector![q[0], q[1], p[0], p[1]]
}

/// ∂Φᵀ Ω ∂Φ = Ω with ∂Φ from fourth-order central differences (ε = 10⁻³: truncation ~ε⁴ = 10⁻¹²,
/// round-off ~10⁻¹⁶/ε = 10⁻¹³), at a point of the scene's trajectory with large velocities.
#[test]
fn step_map_is_symplectic() {
    let omega = SMatrix::<f64, 4, 4>::from_fn(|i, j| match (i, j) {
        (0, 2) | (1, 3) => 1.0,
        (2, 0) | (3, 1) => -1.0,
        _ => 0.0,
    });
    let mut start = double_pendulum::stepper(Quadrature::midpoint(), 0.01).unwrap();
    for _ in 0..150 {
        start.step().unwrap();
    }
    let x = vector![start.q()[0], start.q()[1], start.p()[0], start.p()[1]];
    for quadrature in scenes::quadratures() {
        let eps = 1e-3;
        let jacobian = SMatrix::<f64, 4, 4>::from_columns(&[0, 1, 2, 3].map(|c| {
            let e = SVector::<f64, 4>::ith(c, eps);
            let f = |k: f64| step_map(&quadrature, 0.05, x + e * k);
            (f(-2.0) - f(2.0) + (f(1.0) - f(-1.0)) * 8.0) / (12.0 * eps)
        }));
        let defect = (jacobian.transpose() * omega * jacobian - omega).amax();
        assert!(
            defect < 1e-9,
            "{}: ‖∂Φᵀ Ω ∂Φ − Ω‖ = {defect:e}",
            quadrature.name()
        );
        // The test can fail: the map is far from the identity here.
        assert!((jacobian - SMatrix::identity()).amax() > 1e-2);
    }
}
