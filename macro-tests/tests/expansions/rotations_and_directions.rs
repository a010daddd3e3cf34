//! A model with real coordinates, an array of rotations and a unit vector, with one-forms, a
//! force with an input and a matrix parameter, compiles and steps.
use dirac::prelude::*;

#[dirac_system(
    coordinates(x, links[2]: SO3, n: S2),
    lagrangian = 0.5 * m * dot(x).powi(2) + d2 * dot(x)
        + 0.5 * dot(omega(links[0]), j * omega(links[0]))
        + 0.5 * dot(omega(links[1]), omega(links[1]))
        + 0.5 * dot(dot(n), dot(n))
        - g * (links[0] * rho)[2] - g * n[2] - 0.5 * k * x * x + dot(d, omega(links[1])),
    constraints(dx - dot(rho, dlinks[1])),
    forces(u * dn[0] - c * dot(x) * dx),
    inputs(u),
)]
struct Mixed {
    m: f64,
    k: f64,
    c: f64,
    g: f64,
    j: [[f64; 3]; 3],
    rho: [f64; 3],
    // Parameters whose names start with `d` are not differentials.
    d: [f64; 3],
    d2: f64,
}

#[test]
fn compiles_and_runs() {
    let model = Mixed {
        m: 1.0,
        k: 2.0,
        c: 0.1,
        g: 9.81,
        j: [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]],
        rho: [0.0, 0.0, 0.5],
        d: [0.1, 0.0, 0.0],
        d2: 0.3,
    };
    assert_eq!(model.coordinate_name(1), "links[0]");
    assert_eq!(model.coordinate_name(3), "n");
    let mut stepper =
        Stepper::on_manifold(model, Product::cayley(), Quadrature::midpoint(), 0.01).unwrap();
    let start = Configuration::new(
        vector![0.0],
        [Matrix3::identity(); 2],
        [Vector3::new(0.0, 0.6, -0.8)],
    );
    let rates = Rates::new(
        vector![0.5],
        [Vector3::new(0.0, 0.0, 1.0), Vector3::new(1.0, 0.0, 1.0)],
        [Vector3::new(1.0, 0.0, 0.0)],
    );
    stepper.start_from_velocity(start, rates).unwrap();
    stepper.set_input("u", 0.2).unwrap();
    stepper.run(10).unwrap();
    assert!(stepper.constraint_violation() < 1e-12);
}
