//! A Hamiltonian model with a holonomic constraint: the Cartesian pendulum, stepped on its
//! circle.
use dirac::prelude::*;

#[dirac_system(
    coordinates(x, y),
    hamiltonian = 0.5 * (p(x).powi(2) + p(y).powi(2)) + g * y,
    holonomic(x * x + y * y - 1.0),
)]
struct Pendulum {
    g: f64,
}

#[test]
fn compiles_and_runs() -> Result<(), DiracError> {
    let mut stepper = Stepper::hamiltonian(Pendulum { g: 9.81 }, Quadrature::midpoint(), 0.01)?;
    stepper.start_from_momentum(vector![1.0, 0.0], vector![0.0, 0.5])?;
    stepper.run(100)?;
    let (x, y) = (stepper.q()[0], stepper.q()[1]);
    assert!((x * x + y * y - 1.0).abs() < 1e-12);
    Ok(())
}
