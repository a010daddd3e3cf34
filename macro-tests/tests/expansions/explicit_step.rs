use dirac::prelude::*;

/// A pendulum naming its explicit step by name, a driven oscillator by order (forces of time
/// and an input keep the step explicit).
#[dirac_system(
    coordinates(theta),
    lagrangian = 0.5 * dot(theta).powi(2) + cos(theta),
    quadrature = explicit(kahan_li_8),
)]
#[derive(Debug)]
struct Pendulum;

#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * m * dot(x).powi(2) - 0.5 * x * x,
    forces((u * cos(t)) * dx),
    inputs(u),
    quadrature = explicit(4),
)]
struct Driven {
    m: f64,
}

#[test]
fn the_named_explicit_step_is_taken_and_from_system_points_to_it() {
    let mut stepper = Stepper::explicit_from_system(Pendulum, 0.1).unwrap();
    assert_eq!(stepper.composition().name(), "Kahan–Li 8 (17 stages)");
    stepper
        .start_from_momentum(vector![1.0], vector![0.0])
        .unwrap();
    stepper.run(50).unwrap();
    // q(5), p(5) of q̈ = −sin q from q = 1 (docs/scenes.md).
    assert!((stepper.q()[0] + 0.02395128485293).abs() < 1e-9);
    assert!((stepper.p()[0] - 0.95855190346756).abs() < 1e-9);
    let refused = Stepper::from_system(Pendulum, 0.1).unwrap_err();
    assert!(
        refused
            .to_string()
            .contains("Stepper::explicit_from_system"),
        "{refused}"
    );
    let mut driven = Stepper::explicit_from_system(Driven { m: 1.0 }, 0.1).unwrap();
    assert_eq!(driven.composition().name(), "Suzuki");
    driven.set_input("u", 1.0).unwrap();
    driven
        .start_from_velocity(vector![0.0], vector![0.0])
        .unwrap();
    driven.run(10).unwrap();
    // ẍ = −x + cos t from rest: x = t sin(t)/2, to Suzuki's accuracy at h = 0.1.
    assert!(
        (driven.q()[0] - 0.5 * 1f64.sin()).abs() < 1e-5,
        "{}",
        driven.q()[0]
    );
}

/// A model generic over a constant: its explicit step is generic too.
#[dirac_system(
    coordinates(x[2]),
    lagrangian = 0.5 * (dot(x[0]).powi(2) + dot(x[1]).powi(2)) - 0.5 * w[K - 1] * x[0] * x[0],
    quadrature = explicit(verlet),
)]
struct Weighted<const K: usize> {
    w: [f64; K],
}

#[test]
fn a_generic_model_names_its_explicit_step() {
    let stepper = Stepper::explicit_from_system(Weighted::<3> { w: [0.0, 0.0, 1.0] }, 0.1).unwrap();
    assert_eq!(stepper.composition().order(), 2);
}
