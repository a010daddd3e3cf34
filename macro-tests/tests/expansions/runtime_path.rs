//! The attribute used by a crate that depends on `dirac-runtime` and `dirac-macros` directly,
//! through `crate = dirac_runtime`.

use dirac_macros::dirac_system;
use dirac_runtime::nalgebra::SVector;
use dirac_runtime::{Quadrature, Stepper};

/// Unit oscillator, `x = cos t`.
#[dirac_system(
    crate = dirac_runtime,
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    quadrature = galerkin(2),
)]
struct Oscillator;

#[test]
fn a_model_built_on_the_runtime_alone_runs() {
    let mut stepper = Stepper::from_system(Oscillator, 0.1).unwrap();
    assert_eq!(stepper.quadrature(), &Quadrature::galerkin(2).unwrap());
    stepper
        .start_from_velocity(SVector::from([1.0]), SVector::from([0.0]))
        .unwrap();
    stepper.run_until(1.0).unwrap();
    assert!((stepper.q()[0] - 1.0_f64.cos()).abs() < 1e-6);
}
