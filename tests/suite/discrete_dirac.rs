//! Discrete Dirac mechanics: constraint one-forms, holonomic constraints, degenerate Lagrangians,
//! forces and inputs, on the scenes with known answers (`docs/scenes.md`).

use crate::support;

use dirac::prelude::*;
use scenes::{cartesian_pendulum, circuit, double_pendulum, knife_edge, pendulum, port};
use support::energy_error_first_and_last_tenth;
use support::slope;

const HS: [f64; 4] = [0.1, 0.05, 0.025, 0.0125];

/// LC circuit: second order against the golden q(10) (measured slope 2.01, errors 3.3e-3 to
/// 5.0e-5), Kirchhoff's current law to round-off at every step, energy conserved exactly (the
/// midpoint scheme is symmetric and the energy quadratic).
#[test]
fn lc_circuit_is_second_order_keeps_kcl_and_energy() {
    let exact = SVector::from(circuit::LC_Q10);
    let errors: Vec<f64> = HS
        .iter()
        .map(|&h| (circuit::lc_at_10(Quadrature::midpoint(), h).unwrap().0 - exact).amax())
        .collect();
    let order = slope(&HS, &errors);
    assert!(
        (order - 2.0).abs() < 0.2,
        "order {order}, errors {errors:?}"
    );

    let mut stepper = Stepper::new(circuit::LC, Quadrature::midpoint(), 0.01).unwrap();
    stepper
        .start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    let trajectory = stepper.run(1000).unwrap();
    assert!(trajectory.max_constraint_violation() <= 1e-13);
    // Energy 1/2 on C2 at the start.
    assert!((trajectory.energy()[0] - 0.5).abs() < 1e-15);
    assert!(
        trajectory.max_energy_error() < 1e-13,
        "{:e}",
        trajectory.max_energy_error()
    );
    // The closed form of q_c2 along the way, and the inductor current p_l / l at t = 10.
    for (t, q) in trajectory.t().iter().zip(trajectory.q()) {
        assert!((q[2] - circuit::lc_q_c2(*t)).abs() < 1e-4);
    }
    // The current is second order too: measured error 1.2e-4 at h = 0.01.
    let current = trajectory.p()[1000][0] / circuit::LC.l;
    assert!((current - circuit::LC_CURRENT10).abs() < 2e-4, "{current}");
    // The multipliers are the capacitor voltages' impulses, finite and reported per sample.
    assert_eq!(trajectory.multipliers_at(1000).map(<[f64]>::len), Some(2));
    assert_eq!(trajectory.multipliers().len(), trajectory.len());
}

/// RLC (R = 0.5): golden q(10) and current; the discrete energy balance
/// E_{k+1} − E_k = −h R (Δq_l/h)² to round-off at every step.
#[test]
fn rlc_circuit_golden_values_and_energy_balance() {
    let h = 0.01;
    let rlc = circuit::rlc(circuit::LC, circuit::R).unwrap();
    let mut stepper = Stepper::new(rlc, Quadrature::midpoint(), h).unwrap();
    stepper
        .start_from_velocity(circuit::rlc_q0(), SVector::zeros())
        .unwrap();
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let (e0, q0) = (stepper.energy().unwrap(), stepper.q());
        stepper.step().unwrap();
        let dissipated = h * circuit::R * ((stepper.q()[0] - q0[0]) / h).powi(2);
        worst = worst.max((stepper.energy().unwrap() - e0 + dissipated).abs());
    }
    assert!(worst < 1e-14, "energy balance off by {worst:e}");
    let error = (stepper.q().fixed_rows::<4>(0) - SVector::from(circuit::RLC_Q10)).amax();
    assert!(error < 1e-5, "{error:e}");
    // Measured error 1.0e-5 at h = 0.01 (second order).
    let current = stepper.p()[0] / circuit::LC.l;
    assert!((current - circuit::RLC_CURRENT10).abs() < 2e-5, "{current}");
}

/// Trapezoid on the LC circuit: ker M ∩ ker A ≠ 0 (charge moving from C1 to C3 costs nothing in
/// the trapezoid's step equations). The error names those capacitors; nothing is NaN.
#[test]
fn trapezoid_on_the_lc_circuit_is_refused_naming_the_capacitors() {
    let err = circuit::lc_at_10(Quadrature::trapezoid(), 0.01).unwrap_err();
    match &err {
        DiracError::SingularJacobian {
            unknowns, step: 0, ..
        } => {
            assert_eq!(unknowns, "q_c1 (q_{k+1}), q_c3 (q_{k+1})");
        }
        other => panic!("expected a singular Jacobian, got {other}"),
    }
}

/// Parallel capacitors must start at equal voltages (q_c1/c1 = q_c3/c3): a hidden constraint.
/// Currents must satisfy KCL.
#[test]
fn inconsistent_initial_data_is_refused() {
    let mut stepper = Stepper::new(circuit::LC, Quadrature::midpoint(), 0.01).unwrap();
    let err = stepper
        .start_from_velocity(vector![0.0, 0.3, 1.0, 0.0], SVector::zeros())
        .unwrap_err();
    assert!(
        matches!(err, DiracError::InconsistentInitialState(_)),
        "{err}"
    );
    assert!(err.to_string().contains("q_c1"), "{err}");
    let err = stepper
        .start_from_velocity(circuit::q0(), vector![1.0, 0.0, 0.0, 0.0])
        .unwrap_err();
    assert!(err.to_string().contains("one-form 0"), "{err}");
    assert_eq!(stepper.step(), Err(DiracError::NotStarted));
    // Equal voltages are accepted.
    stepper
        .start_from_velocity(vector![0.0, 0.3, 1.0, 0.3], SVector::zeros())
        .unwrap();

    let mut stepper =
        Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), 0.01).unwrap();
    let err = stepper
        .start_from_velocity(vector![1.0, 1.0], SVector::zeros())
        .unwrap_err();
    assert!(err.to_string().contains("holonomic constraint 0"), "{err}");
    let err = stepper
        .start_from_velocity(vector![0.0, -1.0], vector![0.0, 1.0])
        .unwrap_err();
    assert!(err.to_string().contains("not tangent"), "{err}");
}

/// Cartesian pendulum: |x² + y² − l²| ≤ 1e-12 over 10⁶ steps, energy error bounded without drift,
/// and the same motion as the angle pendulum (both second order: at h = 0.01 they agree to
/// O(h²) and each is within 1e-4 of the golden θ(5)).
#[test]
fn cartesian_pendulum_keeps_its_length_and_matches_the_angle_pendulum() {
    let mut stepper =
        Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), 0.05).unwrap();
    stepper
        .start_from_velocity(cartesian_pendulum::q0(1.0), SVector::zeros())
        .unwrap();
    let run = Run::steps(1_000_000).every(41);
    let trajectory = stepper.solve(run).unwrap().trajectory;
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        stepper.step().unwrap();
        worst = worst.max(stepper.constraint_violation());
    }
    assert!(trajectory.max_constraint_violation() <= 1e-12 && worst <= 1e-12);
    let (first, last) = energy_error_first_and_last_tenth(trajectory.energy());
    assert!(
        last <= 1.1 * first && first < 2e-3,
        "first tenth {first:e}, last tenth {last:e}"
    );

    let h = 0.01;
    let mut cartesian = Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), h).unwrap();
    cartesian
        .start_from_velocity(cartesian_pendulum::q0(1.0), SVector::zeros())
        .unwrap();
    let mut angle = Stepper::new(pendulum::SCENE, Quadrature::midpoint(), h).unwrap();
    angle
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    for _ in 0..500 {
        cartesian.step().unwrap();
        angle.step().unwrap();
    }
    let theta = cartesian_pendulum::angle(&cartesian.q());
    assert!(
        (theta - angle.q()[0]).abs() < 1e-4,
        "{theta} vs {}",
        angle.q()[0]
    );
    assert!((theta - pendulum::Q5).abs() < 1e-4);
}

/// Knife edge on an incline against its closed form at T = 2: the one-form at q_k or q_{k+1}
/// gives order 1, at the midpoint order 2 (measured 0.99, 2.00, 1.00). Start and End lose
/// energy (impulsive projections of the velocity); the midpoint keeps it bounded. The energy is
/// that of the velocity the knife edge allows (`A(q) v = 0`, see `Stepper::v`): over T = 10 its
/// largest error measured 4.8e-7, 3.0e-8, 1.9e-9 at h = 0.02, 0.01, 0.005 (fourth order, no
/// drift). The velocity `p/m`, which the constraint does not allow (`A·p` = 2.3e-4 at h = 0.01),
/// kept it to round-off.
#[test]
fn knife_edge_orders_and_energy_of_the_three_constraint_points() {
    let hs = [0.04, 0.02, 0.01, 0.005];
    for (point, order) in [
        (ConstraintPoint::Start, 1.0),
        (ConstraintPoint::Midpoint, 2.0),
        (ConstraintPoint::End, 1.0),
    ] {
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| knife_edge::error_at(point, h, 2.0).unwrap())
            .collect();
        let measured = slope(&hs, &errors);
        assert!(
            (measured - order).abs() < 0.2,
            "{point:?}: slope {measured}, errors {errors:?}"
        );
        let mut stepper = knife_edge::stepper(point, 0.01).unwrap();
        let e0 = stepper.energy().unwrap();
        for _ in 0..1000 {
            stepper.step().unwrap();
        }
        let change = stepper.energy().unwrap() - e0;
        match point {
            ConstraintPoint::Midpoint => {
                assert!(change.abs() < 5e-8, "{change:e}");
                let v = stepper.v().unwrap();
                let phi = stepper.q()[2];
                assert!((phi.sin() * v[0] - phi.cos() * v[1]).abs() < 1e-15);
                let exact = SVector::from(knife_edge::Q10);
                assert!((stepper.q() - exact).amax() < 2e-3);
            }
            _ => assert!(change < -0.1, "{point:?}: ΔE = {change}"),
        }
    }
}

/// Two oscillators joined through a massless port: order 2 against the golden x(20), the port
/// constraint y = x1 exact at every step.
#[test]
fn port_interconnection_is_second_order_and_exact_on_the_port() {
    let exact = vector![port::X20[0], port::X20[1]];
    let mut errors = Vec::new();
    for &h in &HS {
        let (x, violation) = port::at_20(h).unwrap();
        assert!(violation <= 1e-13, "{violation:e}");
        errors.push((x - exact).amax());
    }
    let order = slope(&HS, &errors);
    assert!(
        (order - 2.0).abs() < 0.2,
        "order {order}, errors {errors:?}"
    );
}

/// An RLC driven by u(t) = sin(2t), set as an input before every step: after the transient
/// (decay rate R/2L = 0.25, gone by t = 70) the current's amplitude is the phasor's U/|Z|,
/// Z = R + i(ωL − 1/(ωC)), 1/C = 1/c2 + 1/(c1 + c3). Tolerance 1e-3: the O(h²) error and the
/// sampling of the peak at h = 0.005 are both ~1e-5. The discrete energy balance with the
/// source's and the resistor's work, `E_{k+1} − E_k = (u − R Δq_l/h) Δq_l`, holds to round-off
/// at every step.
#[test]
fn driven_rlc_reaches_the_phasor_amplitude() {
    let (peak, phasor, balance) = circuit::driven_amplitude(0.005).unwrap();
    assert!(
        (peak / phasor - 1.0).abs() < 1e-3,
        "peak {peak}, phasor {phasor}"
    );
    assert!(balance < 1e-12, "energy balance error {balance:e}");
    let rlc = circuit::rlc(circuit::LC, circuit::R).unwrap();
    let mut stepper = Stepper::new(rlc, Quadrature::midpoint(), 0.01).unwrap();
    assert!(matches!(
        stepper.set_input("u", 1.0),
        Err(DiracError::UnknownInput(_))
    ));
    assert!(matches!(
        stepper.set_input("drive.source.u", f64::NAN),
        Err(DiracError::NonFinite { .. })
    ));
    assert!(stepper.set_inputs(&[1.0, 2.0]).is_err());
    stepper.set_inputs(&[0.5]).unwrap();
    assert_eq!(stepper.inputs(), &[0.5]);
    // A handle resolved once sets the same input; a bad value changes nothing.
    let u = stepper.input("drive.source.u").unwrap();
    assert_eq!(u.index(), 0);
    stepper.set_input_value(u, 0.25).unwrap();
    assert_eq!(stepper.inputs(), &[0.25]);
    assert!(stepper.set_input_value(u, f64::INFINITY).is_err());
    assert_eq!(stepper.inputs(), &[0.25]);
    assert!(matches!(
        stepper.input("v"),
        Err(DiracError::UnknownInput(_))
    ));
}

/// Constraint one-forms of a Galerkin step are held at the nodes of its Gauss rule: a Lobatto
/// rule (a node more than the path's free points) is refused for them rather than integrated
/// wrongly. Holonomic constraints are held at every point of the path: degree 2 is accepted
/// (order 4, `tests/suite/constrained.rs`), degree 3 refused (it measured order 4 too, not 6).
#[test]
fn constrained_systems_refuse_quadratures_they_cannot_hold() {
    let lobatto = Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap();
    let err = Stepper::new(circuit::LC, lobatto, 0.01).unwrap_err();
    assert!(matches!(err, DiracError::InvalidQuadrature(_)), "{err}");
    assert!(Stepper::new(circuit::LC, Quadrature::galerkin(2).unwrap(), 0.01).is_ok());
    let err = Stepper::new(
        cartesian_pendulum::SCENE,
        Quadrature::galerkin(3).unwrap(),
        0.01,
    )
    .unwrap_err();
    assert!(err.to_string().contains("order 4"), "{err}");
    assert!(
        Stepper::new(
            cartesian_pendulum::SCENE,
            Quadrature::galerkin(2).unwrap(),
            0.01
        )
        .is_ok()
    );
}

/// Unconstrained models carry no constraint or force machinery; constrained ones report their
/// multipliers and violations, also in CSV.
#[test]
fn only_what_a_model_names_is_there() {
    type Dp = double_pendulum::DoublePendulum;
    assert_eq!(
        (
            <Dp as DiracSystem<2>>::ONE_FORMS,
            <Dp as DiracSystem<2>>::HOLONOMIC
        ),
        (0, 0)
    );
    const { assert!(!<Dp as DiracSystem<2>>::FORCES) };
    let mut stepper = double_pendulum::stepper(Quadrature::midpoint(), 0.01).unwrap();
    stepper.step().unwrap();
    assert!(stepper.multipliers().is_empty());
    assert_eq!(<circuit::Rlc as DiracSystem<6>>::INPUTS, 1);

    let mut stepper = Stepper::new(circuit::LC, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    let trajectory = stepper.run(2).unwrap();
    let header = support::csv_header(&trajectory);
    assert_eq!(
        header,
        "t,q_l,q_c1,q_c2,q_c3,v_q_l,v_q_c1,v_q_c2,v_q_c3,p_q_l,p_q_c1,p_q_c2,p_q_c3,energy,\
         constraint_violation,mu_0,mu_1"
    );
}
