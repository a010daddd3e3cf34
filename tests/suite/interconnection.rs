//! Interconnection: models built from separately written components through junctions equal
//! the same models written as one struct, and the ports keep Tellegen's theorem and each
//! component's energy balance step by step.

use crate::support;

use support::slope;

use dirac::interconnection::{Interconnection, Junction};
use dirac::prelude::*;
use scenes::components::{Capacitor, DcMotor, Inductor, MassSpring, Resistor, Source};
use scenes::{circuit, ladder, motor, port, ports};
use std::f64::consts::PI;
use support::monolithic_rlc::MonolithicRlc;

/// Unequal parameters, so that no symmetry hides a misplaced coordinate.
const UNEQUAL: circuit::LcCircuit = circuit::LcCircuit {
    l: 1.3,
    c1: 0.7,
    c2: 1.1,
    c3: 2.0,
};

/// The LC circuit from its two subcircuits (inductor + C2 in series, C1 and C3) joined by KCL
/// equals the monolithic circuit over 1 000 steps, with the midpoint rule and `galerkin(2)`:
/// positions, momenta, and the KCL multiplier (the junction's effort), to 1e-12.
#[test]
fn lc_from_two_subcircuits_equals_the_monolithic_circuit() {
    // Monolithic (q_l, q_c1, q_c2, q_c3) against interconnected (q_l, q_c2, q_c1, q_c3).
    let order = [0, 2, 1, 3];
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let h = 0.01;
        let q0 = vector![0.0, 0.14, 1.0, 0.4];
        let mut monolithic = Stepper::new(UNEQUAL, quadrature.clone(), h).unwrap();
        monolithic
            .start_from_velocity(q0, SVector::zeros())
            .unwrap();
        let parts = circuit::lc_from_subcircuits(&UNEQUAL).unwrap();
        let mut joined = Stepper::new(parts, quadrature.clone(), h).unwrap();
        joined
            .start_from_velocity(SVector::from_fn(|i, _| q0[order[i]]), SVector::zeros())
            .unwrap();
        let mut worst: f64 = 0.0;
        for _ in 0..1000 {
            monolithic.step().unwrap();
            joined.step().unwrap();
            for (i, &j) in order.iter().enumerate() {
                worst = worst
                    .max((joined.q()[i] - monolithic.q()[j]).abs())
                    .max((joined.p()[i] - monolithic.p()[j]).abs());
            }
            if quadrature.name() == "midpoint" {
                // KCL is the monolithic circuit's second one-form, with the same signs.
                let kcl = joined.multipliers()[1];
                worst = worst.max((kcl - monolithic.multipliers()[1]).abs());
            }
        }
        assert!(worst < 1e-12, "{}: apart by {worst:e}", quadrature.name());
        // The circuit is really moving: q_c2 left its start by far more than the tolerance.
        assert!((joined.q()[1] - 1.0).abs() > 0.1);
    }
}

/// The RLC built as LC + resistor + source equals the RLC written as one struct (driven, with
/// `u` set through the hierarchical input name `drive.source.u`). The resistor's and the
/// source's charges carry no kinetic energy and their forces read their velocities, so the
/// interconnected circuit's step map has no derivatives yet: they are refused, not guessed.
#[test]
fn rlc_as_lc_plus_resistor_plus_source_equals_the_monolithic_rlc() {
    let h = 0.01;
    let reference = MonolithicRlc {
        l: UNEQUAL.l,
        c1: UNEQUAL.c1,
        c2: UNEQUAL.c2,
        c3: UNEQUAL.c3,
        r: 0.3,
    };
    let mut monolithic = Stepper::new(reference, Quadrature::midpoint(), h).unwrap();
    monolithic
        .start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    let rlc = circuit::rlc(UNEQUAL, 0.3).unwrap();
    assert_eq!(
        Stepper::new(rlc.clone(), Quadrature::midpoint(), h)
            .unwrap()
            .coordinate_names(),
        [
            "lc.q_l",
            "lc.q_c1",
            "lc.q_c2",
            "lc.q_c3",
            "drive.r.q",
            "drive.source.q"
        ]
    );
    let mut joined = Stepper::new(rlc, Quadrature::midpoint(), h).unwrap();
    joined
        .start_from_velocity(circuit::rlc_q0(), SVector::zeros())
        .unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..2000 {
        let u = (1.7 * (k as f64 + 0.5) * h).sin();
        monolithic.set_input("u", u).unwrap();
        joined.set_input("drive.source.u", u).unwrap();
        monolithic.step().unwrap();
        joined.step().unwrap();
        for i in 0..4 {
            worst = worst
                .max((joined.q()[i] - monolithic.q()[i]).abs())
                .max((joined.p()[i] - monolithic.p()[i]).abs());
        }
        // The resistor and the source carry the inductor's charge.
        worst = worst
            .max((joined.q()[4] - joined.q()[0]).abs())
            .max((joined.q()[5] - joined.q()[0]).abs());
    }
    assert!(worst < 1e-12, "apart by {worst:e}");
    assert!(monolithic.step_linearised().is_ok());
    assert!(matches!(
        joined.step_linearised(),
        Err(DiracError::Unsupported(_))
    ));
}

/// The port scene rebuilt from two mass–spring components equals today's monolithic scene.
#[test]
fn port_scene_from_two_components_equals_the_monolithic_scene() {
    let scene = port::Port {
        m1: 1.0,
        m2: 2.5,
        k1: 1.5,
        k2: 0.8,
    };
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let h = 0.02;
        let mut monolithic = Stepper::new(scene, quadrature.clone(), h).unwrap();
        monolithic
            .start_from_velocity(port::q0(), SVector::zeros())
            .unwrap();
        let parts = port::from_components(&scene).unwrap();
        let mut joined = Stepper::new(parts, quadrature.clone(), h).unwrap();
        joined
            .start_from_velocity(port::q0(), SVector::zeros())
            .unwrap();
        let mut worst: f64 = 0.0;
        for _ in 0..1000 {
            monolithic.step().unwrap();
            joined.step().unwrap();
            worst = worst
                .max((joined.q() - monolithic.q()).amax())
                .max((joined.p() - monolithic.p()).amax());
        }
        assert!(worst < 1e-12, "{}: apart by {worst:e}", quadrature.name());
    }
}

/// Tellegen's theorem and each component's discrete energy balance, at every step: on the LC
/// circuit from its subcircuits and on the port scene from its components (midpoint rule,
/// quadratic Lagrangians), `W_A + W_B = 0` to round-off of the work's terms and
/// `E_A(k+1) − E_A(k) = W_A`, `E_B(k+1) − E_B(k) = W_B` to round-off of the energies in play
/// (measured 3e-16 and 8e-16; asserted 1e-14).
#[test]
fn ports_keep_tellegen_and_each_components_energy_balance() {
    let check = |what: &str, found: ports::Balance| {
        assert!(
            found.tellegen < 1e-14,
            "{what}: W_A + W_B = {:e} of the terms",
            found.tellegen
        );
        assert!(
            found.energy < 1e-14,
            "{what}: energy balance off by {:e}",
            found.energy
        );
        // Energy really crosses the ports (the check is not vacuous).
        assert!(found.largest_work > 1e-4, "{what}: {found:?}");
    };
    let lc = circuit::lc_from_subcircuits(&UNEQUAL).unwrap();
    check(
        "LC from subcircuits",
        ports::balance(
            &lc,
            (vector![0.0, 1.0, 0.14, 0.4], SVector::zeros()),
            0.01,
            2000,
        )
        .unwrap(),
    );
    let port = port::from_components(&port::SCENE).unwrap();
    check(
        "port from components",
        ports::balance(&port, (port::q0(), SVector::zeros()), 0.01, 2000).unwrap(),
    );
}

/// The junctions' multipliers are the ports' efforts; they are read once per step only: a
/// Galerkin step's multipliers (one per node) are refused with an error.
#[test]
fn port_readings_need_one_multiplier_per_junction_and_step() {
    let system = port::from_components(&port::SCENE).unwrap();
    let mut stepper = Stepper::new(system.clone(), Quadrature::galerkin(2).unwrap(), 0.1).unwrap();
    stepper
        .start_from_velocity(port::q0(), SVector::zeros())
        .unwrap();
    let q = stepper.q();
    stepper.step().unwrap();
    let error = system
        .ports(&q, &stepper.q(), stepper.multipliers(), 0.1)
        .unwrap_err();
    assert!(matches!(error, DiracError::Unsupported(_)), "{error}");
    assert_eq!(system.junctions().names(), &["port".to_string()]);
    // Each component's part of a state: left.x, then right.x and right.end.
    assert_eq!(
        system.split(&vector![1.0, 2.0, 3.0]),
        (vector![1.0], vector![2.0, 3.0])
    );
    // The port junction's row: +1 on right.end, −1 on left.x.
    assert_eq!(system.junctions().row(0), &vector![-1.0, 0.0, 1.0]);
}

fn invalid<T: std::fmt::Debug>(result: Result<T, DiracError>) -> String {
    match result {
        Err(DiracError::InvalidInterconnection(why)) => why,
        other => panic!("expected InvalidInterconnection, got {other:?}"),
    }
}

/// Bad interconnections are refused before any step, naming what is wrong.
#[test]
fn bad_interconnections_are_refused_naming_the_junctions() {
    let (l, c) = (Inductor { l: 1.0 }, Capacitor { c: 1.0 });
    let join = |junctions: [Junction; 2]| {
        Interconnection::<_, _, 1, 1, 2, 2>::new(("l", l), ("c", c), junctions)
    };
    let series = || Junction::new("series").flow("l.q", 1.0).flow("c.q", -1.0);
    // Unknown instance, unknown coordinate (listing the instance's coordinates).
    let why = invalid(join([series(), Junction::new("x").flow("r.q", 1.0)]));
    assert!(
        why.contains("\"r.q\"") && why.contains("instances are l, c"),
        "{why}"
    );
    let why = invalid(join([series(), Junction::new("x").flow("c.charge", 1.0)]));
    assert!(
        why.contains("\"c.charge\"") && why.contains("c has c.q"),
        "{why}"
    );
    // Dependent junctions: the second is twice the first.
    let twice = Junction::new("twice").flow("l.q", 2.0).flow("c.q", -2.0);
    let why = invalid(join([series(), twice]));
    assert!(
        why.contains("\"twice\" is a combination of series"),
        "{why}"
    );
    // Repeated names, empty junctions, zero or non-finite coefficients, repeated coordinates.
    let why = invalid(join([series(), series()]));
    assert!(why.contains("two junctions are named \"series\""), "{why}");
    let why = invalid(join([series(), Junction::new("empty")]));
    assert!(why.contains("\"empty\" has no terms"), "{why}");
    let why = invalid(join([series(), Junction::new("z").flow("l.q", 0.0)]));
    assert!(why.contains("finite and nonzero"), "{why}");
    let why = invalid(join([series(), Junction::new("n").flow("l.q", f64::NAN)]));
    assert!(why.contains("finite and nonzero"), "{why}");
    let why = invalid(join([
        series(),
        Junction::new("d").flow("l.q", 1.0).flow("l.q", 1.0),
    ]));
    assert!(why.contains("names l.q twice"), "{why}");
    // Instance names.
    let why = invalid(Interconnection::<_, _, 1, 1, 2, 0>::new(
        ("x", l),
        ("x", c),
        [],
    ));
    assert!(why.contains("two instances are named \"x\""), "{why}");
    let why = invalid(Interconnection::<_, _, 1, 1, 2, 0>::new(
        ("a.b", l),
        ("c", c),
        [],
    ));
    assert!(why.contains("without '.'"), "{why}");
    // Three junctions on three coordinates where one is the sum of the other two.
    let lc = circuit::lc_from_subcircuits(&UNEQUAL).unwrap();
    let sum = Interconnection::<_, _, 4, 1, 5, 3>::new(
        ("lc", lc),
        ("extra", Capacitor { c: 1.0 }),
        [
            Junction::new("a")
                .flow("lc.loop.l.q", 1.0)
                .flow("extra.q", -1.0),
            Junction::new("b")
                .flow("lc.pair.c1.q", 1.0)
                .flow("extra.q", 1.0),
            Junction::new("a+b")
                .flow("lc.loop.l.q", 1.0)
                .flow("lc.pair.c1.q", 1.0),
        ],
    );
    let why = invalid(sum);
    assert!(why.contains("\"a+b\" is a combination of a, b"), "{why}");
}

/// Components that name different quadratures leave the choice to the user: `from_system`
/// refuses, naming both.
#[test]
fn components_naming_different_quadratures_are_refused_by_from_system() {
    #[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), quadrature = galerkin(2))]
    #[derive(Debug, Clone, Copy)]
    struct Free;
    let system = Interconnection::<_, _, 1, 1, 2, 0>::new(
        ("free", Free),
        ("spring", MassSpring { m: 1.0, k: 1.0 }),
        [],
    )
    .unwrap();
    let error = Stepper::from_system(system, 0.1).unwrap_err();
    assert!(
        matches!(&error, DiracError::InvalidQuadrature(why) if why.contains("free names galerkin(2)") && why.contains("spring names midpoint")),
        "{error}"
    );
    // Closed-form derivatives of the components pass through the interconnection.
    let joined = port::from_components(&port::SCENE).unwrap();
    let (q, v) = (vector![0.3, -0.2, 0.5], vector![0.1, 0.7, -0.4]);
    let gradient = joined.lagrangian_gradient(&q, &v).expect("closed forms");
    assert!((gradient.value - joined.lagrangian(&q, &v)).abs() < 1e-15);
    // ∂L/∂end = k2 (x2 − end) from the tethered mass; ∂L/∂x1 = −k1 x1 from the oscillator.
    assert!((gradient.q[2] - port::SCENE.k2 * (-0.2 - 0.5)).abs() < 1e-15);
    assert!((gradient.q[0] + port::SCENE.k1 * 0.3).abs() < 1e-15);
}

/// The RLC of three subsystems in one level, written with the attribute.
#[dirac_system(subsystems(lc, r, source), junctions(lc.dq_l - r.dq, r.dq - source.dq))]
#[derive(Debug, Clone, Copy)]
struct RlcFromParts {
    lc: circuit::LcCircuit,
    r: Resistor,
    source: Source,
}

/// The attribute's `subsystems(...)` gives the same model as `Interconnection` in plain Rust:
/// the same steps to the last bit over 1 000 steps (the LC circuit in two levels, the RLC of
/// three subsystems driven through `source.u`), with the components' closed-form derivatives.
#[test]
fn the_attributes_subsystems_equal_the_plain_rust_interconnection() {
    let c = UNEQUAL;
    let parts = circuit::LcByAttribute::of(&c);
    let (q0, v0) = (vector![0.0, 1.0, 0.14, 0.4], SVector::zeros());
    let mut attribute = Stepper::new(parts, Quadrature::galerkin(2).unwrap(), 0.01).unwrap();
    assert_eq!(
        attribute.coordinate_names(),
        ["loop_.l.q", "loop_.c2.q", "pair.c1.q", "pair.c3.q"]
    );
    attribute.start_from_velocity(q0, v0).unwrap();
    let plain = circuit::lc_from_subcircuits(&c).unwrap();
    let mut rust = Stepper::new(plain.clone(), Quadrature::galerkin(2).unwrap(), 0.01).unwrap();
    rust.start_from_velocity(q0, v0).unwrap();
    for _ in 0..1000 {
        attribute.step().unwrap();
        rust.step().unwrap();
        assert_eq!((attribute.q(), attribute.p()), (rust.q(), rust.p()));
    }
    // The attribute's model reads its ports like the plain-Rust one (midpoint).
    assert_eq!(parts.junctions().names(), &["kcl".to_string()]);
    assert_eq!(parts.junctions().row(0), plain.junctions().row(0));
    let found = ports::balance(&parts, (q0, v0), 0.01, 500).unwrap();
    let reference = ports::balance(&plain, (q0, v0), 0.01, 500).unwrap();
    assert_eq!(
        (found.tellegen, found.energy, found.largest_work),
        (reference.tellegen, reference.energy, reference.largest_work)
    );
    let (q, v) = (vector![0.1, 0.9, 0.2, 0.3], vector![0.4, 0.4, 0.1, 0.3]);
    assert_eq!(
        parts.lagrangian_hessian(&q, &v),
        plain.lagrangian_hessian(&q, &v)
    );
    assert!(parts.lagrangian_hessian(&q, &v).is_some());

    let rlc = RlcFromParts {
        lc: c,
        r: Resistor { r: 0.3 },
        source: Source,
    };
    assert_eq!(rlc.input_name(0), "source.u");
    let mut attribute = Stepper::new(rlc, Quadrature::midpoint(), 0.01).unwrap();
    let mut rust =
        Stepper::new(circuit::rlc(c, 0.3).unwrap(), Quadrature::midpoint(), 0.01).unwrap();
    attribute
        .start_from_velocity(circuit::rlc_q0(), SVector::zeros())
        .unwrap();
    rust.start_from_velocity(circuit::rlc_q0(), SVector::zeros())
        .unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..1000 {
        let u = (1.7 * k as f64 * 0.01).sin();
        attribute.set_input("source.u", u).unwrap();
        rust.set_input("drive.source.u", u).unwrap();
        attribute.step().unwrap();
        rust.step().unwrap();
        // One level against two: the junction rows differ, the solutions agree to round-off.
        worst = worst.max((attribute.q() - rust.q()).amax());
    }
    assert!(worst < 1e-13, "apart by {worst:e}");
    assert!((attribute.q()[0] - circuit::rlc_q0()[0]).abs() > 0.1);
}

/// The LC ladder and the chain of masses, 16 cells in a ring built from components, carry a
/// travelling wave of wave number `κ = 2π m / 16` with the phase advance per step of the
/// discrete dispersion relation `θ = 2 atan(h Ω / 2)`, `Ω = 2 ω₀ |sin(κ/2)|` (derived in
/// `scenes/src/ladder.rs`), to 1e-12 relative, for three modes and three steps; the wave's
/// amplitude stays to 1e-13.
#[test]
fn ladder_and_chain_follow_the_discrete_dispersion_relation() {
    let (m, k) = (1.5, 0.6);
    for mode in [1, 3, 5] {
        let kappa = 2.0 * PI * mode as f64 / ladder::CELLS as f64;
        for h in [0.2, 0.1, 0.05] {
            // The ladder with l c = 1, the chain with k / m = 0.4.
            let omega = ladder::lattice_frequency(1.0, kappa);
            let wave = ladder::ladder_wave(mode, omega);
            let system = ladder::ladder(1.0, 1.0).unwrap();
            let (theta, drift) = ladder::measured_phase_step(system, mode, wave, h, 200).unwrap();
            let expected = ladder::discrete_phase_step(h, omega);
            assert!(
                (theta / expected - 1.0).abs() < 1e-12,
                "ladder m = {mode}, h = {h}: {theta} against {expected}"
            );
            assert!(drift < 1e-13, "ladder amplitude drift {drift:e}");

            let omega = ladder::lattice_frequency((k / m).sqrt(), kappa);
            let wave = ladder::chain_wave(mode, omega);
            let system = ladder::chain(m, k).unwrap();
            let (theta, drift) = ladder::measured_phase_step(system, mode, wave, h, 200).unwrap();
            let expected = ladder::discrete_phase_step(h, omega);
            assert!(
                (theta / expected - 1.0).abs() < 1e-12,
                "chain m = {mode}, h = {h}: {theta} against {expected}"
            );
            assert!(drift < 1e-13, "chain amplitude drift {drift:e}");
        }
    }
}

/// A travelling wave's phase speed on the ladder, measured from the stepped wave, approaches
/// the lattice's `Ω/κ` at second order (the measured slope), with the leading error
/// `−(hΩ)²/12` of the discrete dispersion relation.
#[test]
fn the_ladders_phase_speed_converges_at_second_order() {
    let mode = 3;
    let kappa = 2.0 * PI * mode as f64 / ladder::CELLS as f64;
    let omega = ladder::lattice_frequency(1.0, kappa);
    let hs = [0.4, 0.2, 0.1, 0.05];
    let errors: Vec<f64> = hs
        .iter()
        .map(|&h| {
            let system = ladder::ladder(1.0, 1.0).unwrap();
            let wave = ladder::ladder_wave(mode, omega);
            let (theta, _) = ladder::measured_phase_step(system, mode, wave, h, 100).unwrap();
            let speed = theta / (h * kappa);
            let relative = speed / (omega / kappa) - 1.0;
            // The leading term of the discrete relation, to its next order (h Ω)⁴.
            let leading = -(h * omega).powi(2) / 12.0;
            assert!(
                (relative - leading).abs() < (h * omega).powi(4) / 50.0,
                "h = {h}: {relative} against {leading}"
            );
            relative.abs()
        })
        .collect();
    let order = slope(&hs, &errors);
    eprintln!("phase speed: order {order:.4}, relative errors {errors:?}");
    assert!(
        (order - 2.0).abs() < 0.02,
        "order {order}, errors {errors:?}"
    );
}

/// The ladder's 16 cells keep Tellegen's theorem and each cell's energy balance at every step
/// of a travelling wave.
#[test]
fn the_ladders_cells_balance_their_energy_through_the_ports() {
    let mode = 2;
    let kappa = 2.0 * PI * mode as f64 / ladder::CELLS as f64;
    let wave = ladder::ladder_wave(mode, ladder::lattice_frequency(1.0, kappa));
    let system = ladder::ladder(1.0, 1.0).unwrap();
    let found = ports::balance(&system, wave, 0.05, 400).unwrap();
    assert!(found.tellegen < 1e-14, "{found:?}");
    assert!(found.energy < 1e-14, "{found:?}");
    assert!(found.largest_work > 1e-5, "{found:?}");
}

/// A DC motor (its electrical and mechanical sides coupled by a gyrator) driving a pendulum arm
/// through the shaft junction, under a voltage input: against Dop853 on the same model written
/// as one ODE at T = 5, order 2 (measured 2.00); at every step the motor's energy changes by
/// exactly the electrical work in, less the resistor's, plus its shaft work (to 1e-13 of the
/// terms), Tellegen holds to 1e-14, and the whole model's balance defect (the arm's, its
/// potential not being quadratic) summed over the run falls at order 2; the arm comes to rest
/// at `asin(k u / (r m g d))` (the midpoint rule's equilibria are exact).
#[test]
fn a_dc_motor_drives_a_pendulum_arm_with_its_energy_balanced() {
    let y0 = ode_solvers::SVector::<f64, 4>::zeros();
    let reference = scenes::peers::dop853_end(motor::MotorArmOde, y0, 5.0, 1e-13).unwrap();
    let hs = [0.02, 0.01, 0.005, 0.0025];
    let (mut errors, mut defects) = (Vec::new(), Vec::new());
    for &h in &hs {
        let q = motor::at(h, 5.0).unwrap();
        errors.push((q[0] - reference[0]).abs().max((q[1] - reference[2]).abs()));
        // The arm turns with the rotor.
        assert!((q[2] - q[1]).abs() < 1e-13);
        let (exact, tellegen, defect) = motor::balance(h, (5.0 / h) as usize).unwrap();
        assert!(
            exact < 1e-13,
            "h = {h}: the motor's balance is off by {exact:e}"
        );
        assert!(tellegen < 1e-14, "h = {h}: Tellegen off by {tellegen:e}");
        defects.push(defect);
    }
    let order = slope(&hs, &errors);
    assert!(
        (order - 2.0).abs() < 0.05,
        "order {order}, errors {errors:?}"
    );
    let order = slope(&hs, &defects);
    assert!(
        (order - 2.0).abs() < 0.05,
        "defect order {order}, {defects:?}"
    );
    let rest = motor::at(0.01, 40.0).unwrap();
    assert!((rest[1] - motor::rest_angle()).abs() < 1e-12, "{rest:?}");
    assert!(motor::rest_angle() > 0.5);
}

/// Copies with one-forms and inputs of their own: two loops (each with its series junction)
/// as `Repeated` equal the same two as an `Interconnection`, bit for bit, and two driven
/// motors name their inputs `motor[i].u` and answer to them.
#[test]
fn repeated_copies_keep_their_own_one_forms_and_inputs() {
    let cell = circuit::Loop {
        l: Inductor { l: 1.3 },
        c2: Capacitor { c: 0.7 },
    };
    let link = |a: &str, b: &str| [Junction::new("link").flow(a, 1.0).flow(b, -1.0)];
    let repeated =
        Repeated::<_, 2, 2, 4, 1>::new("loop", [cell; 2], link("loop[0].c2.q", "loop[1].l.q"))
            .unwrap();
    let pair =
        Interconnection::<_, _, 2, 2, 4, 1>::new(("a", cell), ("b", cell), link("a.c2.q", "b.l.q"))
            .unwrap();
    assert_eq!(
        <Repeated<circuit::Loop, 2, 2, 4, 1> as DiracSystem<4>>::ONE_FORMS,
        3
    );
    let q0 = vector![0.0, 1.0, 0.0, 0.5];
    let mut a = Stepper::new(repeated, Quadrature::midpoint(), 0.01).unwrap();
    let mut b = Stepper::new(pair, Quadrature::midpoint(), 0.01).unwrap();
    a.start_from_velocity(q0, SVector::zeros()).unwrap();
    b.start_from_velocity(q0, SVector::zeros()).unwrap();
    for _ in 0..500 {
        a.step().unwrap();
        b.step().unwrap();
        assert_eq!((a.q(), a.multipliers()), (b.q(), b.multipliers()));
    }
    assert!((a.q()[1] - 1.0).abs() > 0.1);

    let motor = motor::MOTOR;
    let free = |i: usize| {
        Junction::new(format!("shaft{i}"))
            .flow(format!("motor[{i}].theta"), 1.0)
            .flow(format!("motor[{}].theta", i + 1), -1.0)
    };
    let motors = Repeated::<DcMotor, 2, 2, 4, 1>::new("motor", [motor; 2], [free(0)]).unwrap();
    assert_eq!(
        (0..2).map(|i| motors.input_name(i)).collect::<Vec<_>>(),
        ["motor[0].u", "motor[1].u"]
    );
    let mut stepper = Stepper::new(motors, Quadrature::midpoint(), 0.01).unwrap();
    stepper
        .start_from_velocity(SVector::zeros(), SVector::zeros())
        .unwrap();
    stepper.set_input("motor[1].u", 2.0).unwrap();
    stepper.run(100).unwrap();
    // Only the second motor is driven; the shared shaft turns both rotors alike, and the
    // first motor's back-EMF drives a current through its own (unpowered) armature.
    assert!((stepper.q()[1] - stepper.q()[3]).abs() < 1e-14);
    assert!(stepper.q()[3] > 0.0 && stepper.q()[2] > 0.0 && stepper.q()[0] < 0.0);
}

/// Edge cases are errors, not panics: two coordinates of one name, port readings with a step
/// that is not positive or with the wrong multipliers; a coefficient of 1e200 builds (its
/// independence is judged on the scaled row) and its step is refused as singular.
#[test]
fn edge_cases_are_errors_not_panics() {
    /// Two coordinates, both named `x`.
    #[derive(Debug, Clone, Copy)]
    struct Twins;
    impl DiracSystem<2> for Twins {
        fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
            (v[0] * v[0] + v[1] * v[1]) * 0.5
        }
        fn coordinate_name(&self, _i: usize) -> String {
            "x".into()
        }
    }
    let junction = [Junction::new("j").flow("a.x", 1.0).flow("b.q", -1.0)];
    let why = invalid(Interconnection::<_, _, 2, 1, 3, 1>::new(
        ("a", Twins),
        ("b", Inductor { l: 1.0 }),
        junction,
    ));
    assert!(why.contains("both named \"a.x\""), "{why}");

    let huge = [Junction::new("j").flow("l.q", 1e200).flow("c.q", -1e200)];
    let system = Interconnection::<_, _, 1, 1, 2, 1>::new(
        ("l", Inductor { l: 1.0 }),
        ("c", Capacitor { c: 1.0 }),
        huge,
    )
    .unwrap();
    assert_eq!(system.junctions().row(0), &vector![1e200, -1e200]);
    // Its step is refused as singular (the row is 1e200 times the others): an error.
    let mut stepper = Stepper::new(system, Quadrature::midpoint(), 0.1).unwrap();
    let refused = stepper
        .start_from_velocity(vector![1.0, 1.0], SVector::zeros())
        .and_then(|()| stepper.step());
    assert!(
        matches!(refused, Err(DiracError::SingularJacobian { .. })),
        "{refused:?}"
    );
    let system = circuit::lc_from_subcircuits(&UNEQUAL).unwrap();
    let mut stepper = Stepper::new(system.clone(), Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_velocity(vector![0.0, 1.0, 0.14, 0.4], SVector::zeros())
        .unwrap();
    let q = stepper.q();
    stepper.step().unwrap();
    for h in [0.0, -0.1, f64::NAN] {
        assert!(matches!(
            system.ports(&q, &stepper.q(), stepper.multipliers(), h),
            Err(DiracError::InvalidStep { .. })
        ));
    }
    assert!(system.ports(&q, &stepper.q(), &[], 0.1).is_err());
}

/// A model that answers `one_form_is_constant` as told, delegating the rest to `inner`.
#[derive(Debug, Clone, Copy)]
struct Claims<S> {
    inner: S,
    constant: bool,
}

impl<S: DiracSystem<N>, const N: usize> DiracSystem<N> for Claims<S> {
    const ONE_FORMS: usize = S::ONE_FORMS;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, N>, v: &SVector<D, N>) -> D {
        self.inner.lagrangian(q, v)
    }
    fn one_form<D: Scalar>(&self, q: &SVector<D, N>, a: usize) -> SVector<D, N> {
        self.inner.one_form(q, a)
    }
    fn one_form_is_constant(&self, _a: usize) -> bool {
        self.constant
    }
}

/// Constant one-forms (Kirchhoff's laws, junctions) are read without dual numbers: the steps
/// are bit for bit those that differentiate them (the LC circuit, 1 000 steps), the attribute
/// says which of a model's one-forms are constant, and a one-form wrongly said constant is
/// refused at the start, naming it.
#[test]
fn constant_one_forms_are_read_without_differentiating_them() {
    assert!(circuit::LC.one_form_is_constant(0) && circuit::LC.one_form_is_constant(1));
    assert!(!scenes::knife_edge::SCENE.one_form_is_constant(0));
    let lc = circuit::lc_from_subcircuits(&UNEQUAL).unwrap();
    assert!((0..2).all(|a| lc.one_form_is_constant(a)));
    let step = |constant: bool| {
        let system = Claims {
            inner: UNEQUAL,
            constant,
        };
        let mut stepper = Stepper::new(system, Quadrature::midpoint(), 0.01).unwrap();
        stepper
            .start_from_velocity(vector![0.0, 0.14, 1.0, 0.4], SVector::zeros())
            .unwrap();
        stepper.run(1000).unwrap();
        (stepper.q(), stepper.p())
    };
    assert_eq!(step(true), step(false));

    let knife = Claims {
        inner: scenes::knife_edge::SCENE,
        constant: true,
    };
    let mut stepper = Stepper::new(knife, Quadrature::midpoint(), 0.01).unwrap();
    let refused = stepper.start_from_velocity(
        vector![0.0, 0.0, 0.3],
        vector![0.3f64.cos(), 0.3f64.sin(), 1.0],
    );
    assert!(
        matches!(&refused, Err(DiracError::InconsistentDerivatives(why)) if why.contains("one-form 0 is said to be constant")),
        "{refused:?}"
    );
}

/// Constraints that depend on each other across components (a junction restating a
/// component's own one-form) or within one model are refused at the start, naming them.
#[test]
fn dependent_constraints_are_refused_at_the_start_naming_them() {
    let cell = circuit::Loop {
        l: Inductor { l: 1.0 },
        c2: Capacitor { c: 1.0 },
    };
    let again = [Junction::new("again")
        .flow("a.l.q", 2.0)
        .flow("a.c2.q", -2.0)];
    let system =
        Interconnection::<_, _, 2, 1, 3, 1>::new(("a", cell), ("b", Capacitor { c: 1.0 }), again)
            .unwrap();
    let mut stepper = Stepper::new(system, Quadrature::midpoint(), 0.01).unwrap();
    let refused = stepper.start_from_velocity(vector![0.0, 1.0, 0.0], SVector::zeros());
    let message = format!("{refused:?}");
    assert!(
        message.contains("junction again is a combination of junction series of a"),
        "{message}"
    );
    assert_eq!(stepper.steps(), 0);

    #[dirac_system(
        coordinates(x, y),
        lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)),
        constraints(dx - dy, 2.0 * dy - 2.0 * dx),
    )]
    struct Twice;
    let mut stepper = Stepper::new(Twice, Quadrature::midpoint(), 0.01).unwrap();
    let refused = stepper.start_from_velocity(vector![0.0, 0.0], vector![1.0, 1.0]);
    assert!(
        matches!(&refused, Err(DiracError::InconsistentInitialState(why))
            if why.contains("one-form `2.0 * dy - 2.0 * dx` is a combination of one-form `dx - dy`")),
        "{refused:?}"
    );
}
