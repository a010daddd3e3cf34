use dirac::prelude::*;

/// A system generic in its length, with its Lagrangian as a generic function.
#[dirac_system(coordinates(x[L]), lagrangian = springs)]
struct Springs<const L: usize> {
    k: f64,
}

fn springs<D: Scalar, const L: usize>(s: &Springs<L>, x: &SVector<D, L>, v: &SVector<D, L>) -> D {
    (0..L)
        .map(|i| v[i] * v[i] * 0.5 - x[i] * x[i] * (0.5 * s.k))
        .sum()
}

#[test]
fn compiles_and_runs() {
    let mut stepper = Stepper::new(Springs::<3> { k: 1.0 }, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_momentum(vector![1.0, 0.0, -1.0], SVector::zeros())
        .unwrap();
    stepper.step().unwrap();
    assert_eq!(stepper.coordinate_names(), ["x[0]", "x[1]", "x[2]"]);
}
