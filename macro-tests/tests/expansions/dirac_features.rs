use dirac::prelude::*;

/// Every argument at once: a one-form on an array element, a holonomic constraint, a force with
/// time, an input and a parameter, and the (+) constraint point.
#[dirac_system(
    coordinates(x, y, theta[2]),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2) + dot(theta[0]).powi(2) + dot(theta[1]).powi(2))
        - 0.5 * k * x * x,
    constraints(cos(theta[0]) * dx + sin(theta[0]) * dtheta[1]),
    holonomic(y - 0.5 * theta[1]),
    forces(-c * dot(x) * dx + (u * cos(t)) * dtheta[0]),
    inputs(u),
    constraint_at = start,
)]
struct Everything {
    k: f64,
    c: f64,
}

#[test]
fn compiles_and_runs() {
    let system = Everything { k: 1.0, c: 0.1 };
    assert_eq!(system.constraint_point(), ConstraintPoint::Start);
    assert_eq!(system.input_name(0), "u");
    let q = vector![0.0, 0.0, 0.0, 0.0];
    let form: SVector<f64, 4> = system.one_form(&q, 0);
    assert_eq!(form, vector![1.0, 0.0, 0.0, 0.0]);
    let g: f64 = system.holonomic(&vector![0.0, 1.0, 0.0, 2.0], 0);
    assert_eq!(g, 0.0);
    let f: SVector<f64, 4> = system.force(&q, &vector![2.0, 0.0, 0.0, 0.0], 0.0, &[3.0]);
    assert_eq!(f, vector![-0.2, 0.0, 3.0, 0.0]);
    let mut stepper = Stepper::new(system, Quadrature::midpoint(), 0.01).unwrap();
    stepper.set_input("u", 1.0).unwrap();
    stepper
        .start_from_velocity(vector![1.0, 0.0, 0.0, 0.0], vector![0.0, 0.5, 0.3, 1.0])
        .unwrap();
    stepper.run(10).unwrap();
    assert!(stepper.constraint_violation() < 1e-12);
}
