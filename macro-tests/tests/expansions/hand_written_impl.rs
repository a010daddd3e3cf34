use dirac::prelude::*;

/// Without the macro: implement the trait by hand.
struct Free;

impl DiracSystem<2> for Free {
    fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        (v[0] * v[0] + v[1] * v[1]) * 0.5
    }
}

#[test]
fn compiles_and_runs() {
    let mut stepper = Stepper::new(Free, Quadrature::trapezoid(), 0.5).unwrap();
    stepper
        .start_from_velocity(vector![0.0, 0.0], vector![1.0, 2.0])
        .unwrap();
    stepper.run(4).unwrap();
    assert!((stepper.q() - vector![2.0, 4.0]).amax() < 1e-14);
}
