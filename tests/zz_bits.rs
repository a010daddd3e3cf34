#[path = "../examples/scenes/mod.rs"]
mod scenes;
use dirac::prelude::*;
use scenes::*;

fn show<S: DiracSystem<N>, const N: usize>(name: &str, stepper: &mut Stepper<S, N>, steps: usize) {
    for _ in 0..steps {
        stepper.step().unwrap();
    }
    println!(
        "BITS {name} q={:?} p={:?} mult={:?} viol={:?} e={:?}",
        stepper.q().as_slice(),
        stepper.p().as_slice(),
        stepper.multipliers(),
        stepper.constraint_violation(),
        stepper.energy().unwrap()
    );
}

#[test]
fn bits() {
    for quadrature in scenes::quadratures() {
        let mut s = double_pendulum::stepper(quadrature.clone(), 0.01).unwrap();
        show(&quadrature.name(), &mut s, 2000);
    }
    let mut lc = Stepper::new(circuit::LC, Quadrature::midpoint(), 0.01).unwrap();
    lc.start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    show("lc", &mut lc, 2000);
    let mut rlc = Stepper::new(circuit::RLC, Quadrature::midpoint(), 0.01).unwrap();
    rlc.start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    show("rlc", &mut rlc, 2000);
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        let mut k = knife_edge::stepper(point, 0.01).unwrap();
        show("knife", &mut k, 2000);
    }
    for quadrature in [Quadrature::midpoint(), Quadrature::trapezoid()] {
        let mut c = Stepper::new(cartesian_pendulum::SCENE, quadrature, 0.01).unwrap();
        c.start_from_velocity(cartesian_pendulum::q0(0.5), SVector::zeros())
            .unwrap();
        show("cart", &mut c, 2000);
    }
}
