//! Energy bookkeeping: each step's work of the forces and inputs in the discrete form the scheme
//! uses, so that `E_{k+1} − E_k = W_k` holds to round-off where the unforced scheme keeps the
//! energy exactly (the midpoint rule and Gauss–Galerkin steps on quadratic energies), with the
//! defect falling at the scheme's order elsewhere; component by component for circuits.

use dirac::prelude::*;
use scenes::components::{Capacitor, Inductor, Resistor, Source};
use scenes::rlc_ladder::{self, Section};
use scenes::satellite;

/// `m ẍ = −k x − c ẋ + u`: a damped oscillator driven by the input `u`.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * m * dot(x).powi(2) - 0.5 * k * x * x,
    forces((u - c * dot(x)) * dx),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct Driven {
    m: f64,
    k: f64,
    c: f64,
}

const DRIVEN: Driven = Driven {
    m: 1.5,
    k: 2.0,
    c: 0.3,
};

/// A pendulum with a damper and a time-dependent torque: `θ̈ = −sin θ − c θ̇ + cos(t)`.
#[dirac_system(
    coordinates(theta),
    lagrangian = 0.5 * dot(theta).powi(2) + cos(theta),
    forces((cos(t) - c * dot(theta)) * dtheta),
)]
#[derive(Debug, Clone, Copy)]
struct ForcedPendulum {
    c: f64,
}

/// A series loop of an inductor, a resistor, a capacitor and a voltage source, each a component.
#[dirac_system(
    subsystems(l, r, c, v),
    junctions(l.dq - r.dq, r.dq - c.dq, c.dq - v.dq),
)]
#[derive(Debug, Clone, Copy)]
struct SeriesRlc {
    l: Inductor,
    r: Resistor,
    c: Capacitor,
    v: Source,
}

const RLC: SeriesRlc = SeriesRlc {
    l: Inductor { l: 0.5 },
    r: Resistor { r: 0.4 },
    c: Capacitor { c: 2.0 },
    v: Source,
};

/// The drive of the tests, held over each step from the state the step starts from.
fn drive(t: f64) -> f64 {
    (1.3 * t).cos()
}

/// The driven oscillator from `x = 1` at rest, driven by `drive`, every step recorded.
fn driven_run(quadrature: Quadrature, h: f64, t_end: f64) -> Trajectory<1> {
    let mut stepper = Stepper::new(DRIVEN, quadrature, h).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    let run =
        Run::until(t_end).control(|now: &Feedback<1>, u: &mut [f64]| u[0] = drive(now.sample.t));
    stepper.solve(run).unwrap().trajectory
}

#[test]
fn the_midpoint_rule_books_the_work_of_a_damped_driven_oscillator_to_round_off() {
    let h = 0.05;
    let trajectory = driven_run(Quadrature::midpoint(), h, 20.0);
    let balance = trajectory.energy_balance().unwrap();
    // The input and the damper both did work of order 1: a balance that ignored either fails.
    assert!(balance.work.abs() > 0.1, "{balance}");
    assert!(
        balance.max_defect < 1e-14 * balance.scale.max(1.0) * 10.0,
        "{balance}"
    );
    // The work by hand: W_k = (u_k − c Δx/h) Δx, the midpoint rule's force `F(x̄, Δx/h)`.
    let (q, t) = (trajectory.q(), trajectory.t());
    let work = trajectory.work().unwrap();
    let mut by_hand = 0.0;
    for k in 0..trajectory.len() - 1 {
        let dx = q[k + 1][0] - q[k][0];
        by_hand += (drive(t[k]) - DRIVEN.c * dx / h) * dx;
        assert!(
            (work[k + 1] - by_hand).abs() < 1e-13,
            "step {k}: {} against {by_hand}",
            work[k + 1]
        );
    }
    assert_eq!(work[0], 0.0);
}

#[test]
fn gauss_galerkin_steps_book_the_work_to_round_off() {
    // Gauss–Legendre with s nodes integrates the energy's rate along the degree-s path exactly
    // on a quadratic energy: E_{k+1} − E_k = h Σ_i b_i F_i · q̇_i.
    for s in [2, 3, 4] {
        let trajectory = driven_run(Quadrature::galerkin(s).unwrap(), 0.1, 20.0);
        let balance = trajectory.energy_balance().unwrap();
        assert!(balance.work.abs() > 0.1, "galerkin({s}): {balance}");
        assert!(balance.max_defect < 1e-13, "galerkin({s}): {balance}");
    }
}

#[test]
fn the_hamiltonian_route_books_the_work_as_the_lagrangian_route_does() {
    // The same damped, driven oscillator written as a Hamiltonian (m = 1, k = 1).
    let system = scenes::hamiltonian::Damped { c: 0.3 };
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let mut stepper = Stepper::hamiltonian(system, quadrature.clone(), 0.05).unwrap();
        stepper
            .start_from_momentum(vector![1.0], vector![0.0])
            .unwrap();
        let run =
            Run::until(10.0).control(|now: &Feedback<1>, u: &mut [f64]| u[0] = drive(now.sample.t));
        let trajectory = stepper.solve(run).unwrap().trajectory;
        let balance = trajectory.energy_balance().unwrap();
        // Driven near resonance, the input feeds the oscillator more than the damper takes.
        assert!(balance.work > 0.1, "{}: {balance}", quadrature.name());
        assert!(
            balance.max_defect < 1e-13,
            "{}: {balance}",
            quadrature.name()
        );
        assert!(stepper.energy_balance_error().unwrap().abs() < 1e-13);
    }
}

/// The largest energy balance defect of the forced pendulum to T = 4 with step `h`.
fn pendulum_defect(quadrature: Quadrature, h: f64) -> f64 {
    let mut stepper = Stepper::new(ForcedPendulum { c: 0.2 }, quadrature, h).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    let trajectory = stepper.solve(Run::until(4.0)).unwrap().trajectory;
    trajectory.max_energy_balance_error().unwrap()
}

#[test]
fn on_a_nonlinear_model_the_defect_falls_at_the_schemes_order() {
    // The pendulum's energy is not quadratic: the balance's defect is the scheme's energy
    // error, of order 2 for the midpoint rule and 4 for galerkin(2).
    for (quadrature, order, h) in [
        (Quadrature::midpoint(), 2.0, 0.04),
        (Quadrature::galerkin(2).unwrap(), 4.0, 0.2),
    ] {
        let coarse = pendulum_defect(quadrature.clone(), h);
        let fine = pendulum_defect(quadrature.clone(), h / 2.0);
        let slope = (coarse / fine).log2();
        assert!(coarse > 1e-9, "{}: {coarse:e}", quadrature.name());
        assert!(
            (slope - order).abs() < 0.3,
            "{}: defect {coarse:e} → {fine:e}, slope {slope}",
            quadrature.name()
        );
    }
}

#[test]
fn a_series_rlc_books_each_components_energy() {
    let h = 0.01;
    let mut stepper = Stepper::new(RLC, Quadrature::midpoint(), h).unwrap();
    // Charge 1 on the capacitor (each element carries the loop's charge).
    stepper
        .start_from_velocity(vector![1.0, 1.0, 1.0, 1.0], SVector::zeros())
        .unwrap();
    let run =
        Run::until(10.0).control(|now: &Feedback<4>, u: &mut [f64]| u[0] = drive(now.sample.t));
    let trajectory = stepper.solve(run).unwrap().trajectory;
    let ledger = stepper.ledger().unwrap();
    println!("{ledger}");
    let names: Vec<&str> = ledger.components.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["l", "r", "c", "v"]);
    let [l, r, c, v] = &ledger.components[..] else {
        unreachable!()
    };
    // Every component balances to round-off, and the ports pass energy on without keeping any.
    for component in &ledger.components {
        assert!(component.defect().abs() < 1e-13, "{ledger}");
    }
    assert!(ledger.net_port_work().abs() < 1e-13, "{ledger}");
    // The elements without energy pass on what their forces take or give.
    assert_eq!(
        (r.initial, r.energy, v.initial, v.energy),
        (0.0, 0.0, 0.0, 0.0)
    );
    assert_eq!((l.forces, c.forces), (0.0, 0.0));
    // The resistor dissipates r (Δq/h)² h a step and the source supplies u_k Δq, by hand.
    let (q, t) = (trajectory.q(), trajectory.t());
    let (mut dissipated, mut supplied) = (0.0, 0.0);
    for k in 0..trajectory.len() - 1 {
        let dq = q[k + 1][1] - q[k][1];
        dissipated += RLC.r.r * dq * dq / h;
        supplied += drive(t[k]) * dq;
    }
    assert!(dissipated > 0.1 && supplied.abs() > 0.01);
    assert!(
        (r.forces + dissipated).abs() < 1e-12,
        "{} against {dissipated}",
        r.forces
    );
    assert!(
        (v.forces - supplied).abs() < 1e-12,
        "{} against {supplied}",
        v.forces
    );
    // The whole model's balance is the sum of the components'.
    let balance = trajectory.energy_balance().unwrap();
    assert!((balance.work - (r.forces + v.forces)).abs() < 1e-13);
    assert!(balance.max_defect < 1e-13, "{balance}");
}

#[test]
fn the_trapezoid_reports_its_defect_and_galerkin_junctions_are_refused() {
    // Störmer–Verlet does not keep a quadratic energy exactly: the defect is its energy error,
    // reported, not hidden, falling as h², and Tellegen's theorem still holds.
    let defect = |h: f64| {
        let mut stepper = Stepper::new(RLC, Quadrature::trapezoid(), h).unwrap();
        stepper
            .start_from_velocity(vector![1.0, 1.0, 1.0, 1.0], SVector::zeros())
            .unwrap();
        stepper.run((10.0 / h).round() as u64).unwrap();
        let ledger = stepper.ledger().unwrap();
        assert!(ledger.net_port_work().abs() < 1e-14, "{ledger}");
        ledger.max_defect()
    };
    let (coarse, fine) = (defect(0.05), defect(0.025));
    let slope = (coarse / fine).log2();
    assert!(coarse > 1e-10, "{coarse:e}");
    assert!(
        (slope - 2.0).abs() < 0.3,
        "{coarse:e} → {fine:e}, slope {slope}"
    );

    let mut stepper = Stepper::new(RLC, Quadrature::galerkin(2).unwrap(), 0.05).unwrap();
    stepper
        .start_from_velocity(vector![1.0, 1.0, 1.0, 1.0], SVector::zeros())
        .unwrap();
    stepper.run(10).unwrap();
    assert!(matches!(stepper.ledger(), Err(DiracError::Unsupported(_))));
    // The whole model's balance does not need the ports.
    assert!(stepper.energy_balance_error().unwrap().abs() < 1e-13);
}

/// `satellite` tumbling at `Ω = (0.3, 1, −0.5)` from the identity, with `retraction` and step
/// `h`, detumbled by `τ = −k Ω` held over each step to `t_end`: its energy balance.
fn detumbling(
    satellite: satellite::Satellite,
    retraction: Product<0, 1, 0>,
    h: f64,
    k: f64,
    t_end: f64,
) -> dirac::EnergyBalance {
    let mut stepper =
        Stepper::on_manifold(satellite, retraction, Quadrature::midpoint(), h).unwrap();
    stepper
        .start_from_velocity(
            Configuration::of_rotation(Matrix3::identity()),
            Rates::of_rotation(Vector3::new(0.3, 1.0, -0.5)),
        )
        .unwrap();
    let run = Run::until(t_end).control(|now: &Feedback<3, Product<0, 1, 0>>, u: &mut [f64]| {
        let omega = now.sample.v.rotation[0];
        for (u, w) in u.iter_mut().zip(omega.iter()) {
            *u = -k * w;
        }
    });
    let trajectory = stepper.solve(run).unwrap().trajectory;
    trajectory.energy_balance().unwrap()
}

#[test]
fn a_satellites_detumbling_is_booked_on_so3() {
    // Body torques τ = −k Ω held over each step: the work takes the kinetic energy away. The
    // group step keeps this energy only to its order, so the defect falls as h².
    let defect = |h: f64| {
        let balance = detumbling(satellite::SCENE, Product::cayley(), h, 0.5, 5.0);
        assert!(balance.work < -0.5 * balance.initial, "{balance}");
        balance.max_defect
    };
    let (coarse, fine) = (defect(0.1), defect(0.05));
    let slope = (coarse / fine).log2();
    assert!(
        (slope - 2.0).abs() < 0.3,
        "{coarse:e} → {fine:e}, slope {slope}"
    );

    // A spherical body rotates about a fixed axis under τ = −k Ω. With the exponential map the
    // angle is linear in the chart and the step is the midpoint rule in that angle, so the
    // balance holds to round-off: the work on the group is booked exactly. (With the Cayley map
    // the chart bends the angle, `f⁻ ≠ f⁺`, and the defect is O(h²), as on the asymmetric body.)
    let sphere = satellite::Satellite { j: [3.0; 3] };
    let balance = detumbling(sphere, Product::exp(), 0.02, 0.2, 20.0);
    assert!(balance.work < -1.5, "{balance}");
    assert!(balance.max_defect < 1e-13, "{balance}");

    // Without torques no work is done at all.
    let free = detumbling(satellite::SCENE, Product::cayley(), 0.1, 0.0, 5.0);
    assert_eq!(free.work, 0.0);
}

#[test]
fn the_work_column_is_recorded_at_steps_only() {
    let mut stepper = Stepper::new(DRIVEN, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    stepper.set_input("u", 0.5).unwrap();
    let trajectory = stepper.solve(Run::steps(10)).unwrap().trajectory;
    assert!(trajectory.column_names().contains(&"work".to_string()));
    assert_eq!(
        trajectory.column("work").unwrap(),
        trajectory.work().unwrap()
    );
    // Samples interpolated between steps have no work of their own: no column, and the balance
    // is refused rather than made up.
    let mut stepper = Stepper::new(DRIVEN, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    let trajectory = stepper
        .solve(Run::until(1.0).saveat([0.25, 0.55]))
        .unwrap()
        .trajectory;
    assert!(trajectory.work().is_none());
    assert!(!trajectory.column_names().contains(&"work".to_string()));
    assert!(matches!(
        trajectory.energy_balance(),
        Err(DiracError::Unsupported(_))
    ));
    // A run's work continues the stepper's from its start: the balance of a second run is
    // measured from its own first sample.
    let mut stepper = Stepper::new(DRIVEN, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    stepper.set_input("u", 0.5).unwrap();
    stepper.run(10).unwrap();
    let before = stepper.work().unwrap();
    let second = stepper.run(10).unwrap();
    assert_eq!(second.work().unwrap()[0], before);
    assert!(second.max_energy_balance_error().unwrap() < 1e-14);
}

#[test]
fn a_first_order_model_books_no_work_and_its_balance_is_its_energy_error() {
    // A Lagrangian linear in the velocities takes no forces (refused when a run begins): its
    // steps do no work, and its balance's defect is the drift of its energy H.
    let mut stepper =
        Stepper::new(scenes::lotka_volterra::SCENE, Quadrature::midpoint(), 0.01).unwrap();
    assert!(matches!(stepper.work(), Err(DiracError::NotStarted)));
    stepper
        .start_from_position(scenes::lotka_volterra::q0())
        .unwrap();
    let trajectory = stepper.run(1000).unwrap();
    assert_eq!(stepper.work().unwrap(), 0.0);
    let balance = trajectory.energy_balance().unwrap();
    assert_eq!(balance.max_defect, trajectory.max_energy_error());
    assert!(balance.max_defect > 0.0);
}

/// An inductor with its series resistance and a voltage source in series: each component of
/// the modular step must determine its own step, which a source alone (no energy) does not.
#[dirac_system(
    coordinates(q),
    lagrangian = 0.5 * l * dot(q).powi(2),
    forces((u - r * dot(q)) * dq),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct DrivenCoil {
    l: f64,
    r: f64,
}

/// The driven coil charging a capacitor.
#[dirac_system(subsystems(coil, c), junctions(kcl = coil.dq - c.dq))]
#[derive(Debug, Clone, Copy)]
struct CoilLoop {
    coil: DrivenCoil,
    c: Capacitor,
}

#[test]
fn the_modular_step_books_each_components_energy_as_the_monolithic_one() {
    let (h, coil, c) = (0.01, DrivenCoil { l: 0.5, r: 0.4 }, Capacitor { c: 2.0 });
    let mut modular = Modular::new(Quadrature::midpoint(), h).unwrap();
    modular.add("coil", coil).unwrap();
    modular.add("c", c).unwrap();
    modular
        .join(Junction::new("kcl").flow("coil.q", 1.0).flow("c.q", -1.0))
        .unwrap();
    modular
        .start_from_velocity(&[1.0, 1.0], &[0.0, 0.0])
        .unwrap();
    let mut monolithic = Stepper::new(CoilLoop { coil, c }, Quadrature::midpoint(), h).unwrap();
    monolithic
        .start_from_velocity(vector![1.0, 1.0], SVector::zeros())
        .unwrap();
    for k in 0..1000 {
        let u = drive(k as f64 * h);
        modular.set_input("coil.u", u).unwrap();
        monolithic.set_input("coil.u", u).unwrap();
        modular.step().unwrap();
        monolithic.step().unwrap();
    }
    let (parts, whole) = (modular.ledger().unwrap(), monolithic.ledger().unwrap());
    println!("{parts}");
    for (a, b) in parts.components.iter().zip(&whole.components) {
        assert_eq!(a.name, b.name);
        for (x, y) in [
            (a.energy, b.energy),
            (a.forces, b.forces),
            (a.ports, b.ports),
        ] {
            assert!((x - y).abs() < 1e-11, "{parts}\n{whole}");
        }
        assert!(a.defect().abs() < 1e-13, "{parts}");
    }
    assert!(parts.net_port_work().abs() < 1e-13, "{parts}");
    // The capacitor's energy went through its port: its own forces did nothing.
    assert_eq!(parts.components[1].forces, 0.0);
    assert!(parts.components[1].ports.abs() > 0.1, "{parts}");
}

/// The ladder of `scenes::rlc_ladder` with its sections named one by one and its junctions
/// written out: the array `s: [Section; 3]` and the junction loop must mean exactly this.
#[dirac_system(
    subsystems(v, s0, s1, s2),
    junctions(
        source = v.dq - s0.l.dq,
        node_0 = s0.l.dq - s0.c.dq - s1.l.dq,
        node_1 = s1.l.dq - s1.c.dq - s2.l.dq,
        last = s2.l.dq - s2.c.dq,
    ),
)]
#[derive(Debug, Clone, Copy)]
struct NamedLadder {
    v: Source,
    s0: Section,
    s1: Section,
    s2: Section,
}

#[test]
fn an_array_of_subsystems_is_its_elements_named_one_by_one() {
    let array = rlc_ladder::ladder(1.0, 0.5, 2.0);
    let section = array.s[0];
    let named = NamedLadder {
        v: Source,
        s0: section,
        s1: section,
        s2: section,
    };
    let mut a = Stepper::new(array, Quadrature::midpoint(), 0.01).unwrap();
    let mut b = Stepper::new(named, Quadrature::midpoint(), 0.01).unwrap();
    assert_eq!(a.coordinate_names()[6], "s[1].c.q");
    assert_eq!(b.coordinate_names()[6], "s1.c.q");
    a.start_from_velocity(SVector::zeros(), SVector::zeros())
        .unwrap();
    b.start_from_velocity(SVector::zeros(), SVector::zeros())
        .unwrap();
    a.set_input("v.u", 1.0).unwrap();
    b.set_input("v.u", 1.0).unwrap();
    a.run(500).unwrap();
    b.run(500).unwrap();
    assert_eq!(a.q(), b.q());
    assert_eq!(a.multipliers(), b.multipliers());
    let names: Vec<String> = a
        .ledger()
        .unwrap()
        .components
        .into_iter()
        .map(|c| c.name)
        .collect();
    assert_eq!(names, ["v", "s[0]", "s[1]", "s[2]"]);
}

#[test]
fn an_rlc_ladder_charged_through_its_resistors_dissipates_what_it_stores() {
    // Charging capacitors from a constant voltage V through resistors dissipates ½ V² Σc, the
    // energy they store, whatever the resistors and inductors.
    for (l, r, c) in [(1.0, 1.0, 1.0), (0.5, 2.0, 0.3)] {
        let voltage = 2.0;
        let (solution, ledger) =
            rlc_ladder::charged(rlc_ladder::ladder(l, r, c), voltage, 0.01, 200.0, 1000).unwrap();
        let last = solution.trajectory.q().last().unwrap();
        for k in [3, 6, 9] {
            assert!((last[k] - c * voltage).abs() < 1e-6, "{last:?}");
        }
        let dissipated: f64 = -ledger.components[1..].iter().map(|s| s.forces).sum::<f64>();
        let half = 0.5 * voltage * voltage * 3.0 * c;
        assert!(
            (dissipated - half).abs() < 1e-6 * half,
            "{dissipated} against {half}\n{ledger}"
        );
        assert!(
            (ledger.components[0].forces - 2.0 * half).abs() < 1e-6 * half,
            "{ledger}"
        );
        assert!(ledger.max_defect() < 1e-12, "{ledger}");
        assert!(solution.trajectory.max_energy_balance_error().unwrap() < 1e-12);
    }
}
