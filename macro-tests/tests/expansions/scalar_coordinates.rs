use dirac::prelude::*;

/// A particle on a spring with a cubic stiffening term, written like the math.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * m * dot(x).powi(2) - 0.5 * k * x * x - 0.25 * (eps * x.powi(4)),
    quadrature = galerkin(2, gauss_lobatto(3)),
)]
struct Duffing {
    m: f64,
    k: f64,
    eps: f64,
}

#[test]
fn compiles_and_runs() {
    let system = Duffing {
        m: 2.0,
        k: 1.0,
        eps: 0.1,
    };
    assert_eq!(
        system.quadrature().unwrap().name(),
        "galerkin(2, gauss_lobatto(3))"
    );
    assert_eq!(system.coordinate_name(0), "x");
    assert_eq!(system.parameters().len(), 3);
    // L at q = 1, v = 2: 4 − 0.5 − 0.025.
    let l: f64 = system.lagrangian(&vector![1.0], &vector![2.0]);
    assert!((l - 3.475).abs() < 1e-15);
    let mut stepper = Stepper::from_system(system, 0.1).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    assert_eq!(stepper.p(), vector![0.0]);
    stepper.run(10).unwrap();
}
