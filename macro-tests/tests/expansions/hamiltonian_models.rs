//! Models given by a Hamiltonian: momenta p(x), arrays, forces with inputs, one-forms, a
//! function path, and the steps they run.
use dirac::prelude::*;

#[dirac_system(
    coordinates(x[2], phi),
    hamiltonian = 0.5 * (p(x[0]).powi(2) + p(x[1]).powi(2)) / m + 0.5 * p(phi).powi(2),
    constraints(sin(phi) * dx[0] - cos(phi) * dx[1]),
    forces((u - c * p(phi)) * dphi),
    inputs(u),
    quadrature = galerkin(2),
)]
struct Skate {
    m: f64,
    c: f64,
}

fn energy<D: Scalar>(_model: &Free, q: &SVector<D, 1>, p: &SVector<D, 1>) -> D {
    p[0] * p[0] * 0.5 + q[0] * 0.0
}

#[dirac_system(coordinates(x), hamiltonian = energy)]
struct Free;

#[test]
fn compiles_and_runs() -> Result<(), DiracError> {
    let mut skate = Stepper::hamiltonian_from_system(Skate { m: 1.0, c: 0.1 }, 0.01)?;
    skate.set_input("u", 1.0)?;
    skate.start_from_momentum(vector![0.0, 0.0, 0.0], vector![0.0, 0.0, 1.0])?;
    skate.run(10)?;
    assert_eq!(skate.quadrature().name(), "galerkin(2)");
    let mut free = Stepper::hamiltonian(Free, Quadrature::midpoint(), 0.5)?;
    free.start_from_momentum(vector![0.0], vector![2.0])?;
    free.step()?;
    assert_eq!(free.q()[0], 1.0);
    Ok(())
}
