//! The modular step: components assembled and factorised on their own, coupled through the
//! junctions' Schur complement, step exactly the monolithic interconnection's equations; the
//! ports keep Tellegen's theorem; what the modular step cannot do it refuses.

use dirac::interconnection::{Interconnection, Junction};
use dirac::nalgebra::DVector;
use dirac::prelude::*;
use scenes::components::{
    Capacitor, Damper, Inductor, Mass, MassSpring, Modulated, Resistor, Source, Spring,
};
use scenes::{circuit, ladder, motor};

/// Steps `parts` and `whole` side by side `steps` times, running `check` on the parts after each
/// step: the largest difference of their positions, momenta and junction multipliers (the
/// parts' junction `j` against the monolithic model's multiplier `theirs[j]`: its components'
/// own one-forms come first, its holonomic constraints last).
fn lockstep<S: DiracSystem<N>, const N: usize>(
    parts: &mut Modular,
    whole: &mut Stepper<S, N>,
    steps: usize,
    theirs: &[usize],
    check: impl Fn(&Modular),
) -> f64 {
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        parts.step().unwrap();
        whole.step().unwrap();
        check(parts);
        let mine = parts.multipliers().unwrap();
        assert_eq!(mine.len(), theirs.len());
        let multipliers = mine
            .iter()
            .zip(theirs.iter().map(|&j| whole.multipliers()[j]));
        worst = multipliers.fold(worst, |w, (a, b)| w.max((a - b).abs()));
        worst = worst
            .max((parts.q() - DVector::from_column_slice(whole.q().as_slice())).amax())
            .max((parts.p() - DVector::from_column_slice(whole.p().as_slice())).amax());
    }
    worst
}

/// The LC loop of [`lc_loop`] as one interconnection, stepped monolithically.
fn lc_monolithic(h: f64) -> Stepper<Interconnection<Inductor, Capacitor, 1, 1, 2, 1>, 2> {
    let whole = Interconnection::new(
        ("l", Inductor { l: 1.3 }),
        ("c", Capacitor { c: 0.7 }),
        [Junction::new("series").flow("l.q", 1.0).flow("c.q", -1.0)],
    )
    .unwrap();
    Stepper::new(whole, Quadrature::midpoint(), h).unwrap()
}

fn lc_loop(h: f64) -> Modular {
    let mut lc = Modular::new(Quadrature::midpoint(), h).unwrap();
    lc.add("l", Inductor { l: 1.3 }).unwrap();
    lc.add("c", Capacitor { c: 0.7 }).unwrap();
    lc.join(Junction::new("series").flow("l.q", 1.0).flow("c.q", -1.0))
        .unwrap();
    lc
}

/// The LC loop from an inductor and a capacitor (the capacitor without kinetic energy, its
/// velocity fixed by the junction) stepped by parts equals the same interconnection stepped
/// monolithically over 1 000 steps: charges, momenta and the junction's multiplier to 1e-12;
/// the port work of the two parts cancels (Tellegen) to round-off at every step, and the
/// junction's effort is the capacitor's voltage at the step's midpoint.
#[test]
fn the_lc_loop_by_parts_equals_the_monolithic_loop() {
    let h = 0.05;
    let (mut parts, mut monolithic) = (lc_loop(h), lc_monolithic(h));
    let (q0, v0) = ([0.3, 0.3], [1.0, 1.0]);
    parts.start_from_velocity(&q0, &v0).unwrap();
    monolithic
        .start_from_velocity(SVector::from(q0), SVector::from(v0))
        .unwrap();
    assert_eq!(parts.coordinate_names(), monolithic.coordinate_names());
    let (mut worst, mut tellegen): (f64, f64) = (0.0, 0.0);
    let mut effort: f64 = 0.0;
    for _ in 0..1000 {
        let before = parts.q()[1];
        parts.step().unwrap();
        monolithic.step().unwrap();
        worst = worst
            .max((parts.q() - DVector::from_column_slice(monolithic.q().as_slice())).amax())
            .max((parts.p() - DVector::from_column_slice(monolithic.p().as_slice())).amax())
            .max((parts.multipliers().unwrap()[0] - monolithic.multipliers()[0]).abs());
        let ports = parts.ports().unwrap();
        tellegen = tellegen.max(ports.net_work().abs() / ports.scale);
        // The capacitor's row, `−h q̄/(2C) + ½ ι = 0` with `ι = −μ` (its junction coefficient
        // is −1): the junction's effort `μ/h` is minus its voltage at the step's midpoint.
        let voltage = 0.5 * (before + parts.q()[1]) / 0.7;
        effort = effort.max((ports.efforts[0] + voltage).abs() / voltage.abs().max(1.0));
    }
    println!("LC loop: apart by {worst:e}, Tellegen {tellegen:e}, effort {effort:e}");
    assert!(effort < 1e-12, "the effort is not the voltage: {effort:e}");
    assert!(worst < 1e-12, "apart by {worst:e}");
    assert!(
        tellegen < 1e-14,
        "Tellegen off by {tellegen:e} of the terms"
    );
    assert!((parts.t() - 50.0).abs() < 1e-12 && parts.steps() == 1000);
    // It oscillated (ω² = 1 / (1.3 · 0.7)): not a trivial agreement.
    assert!(parts.q().amax() > 0.5);
}

/// The ring of 16 masses on springs (each a mass tethered to a massless end, the ends joined to
/// the next mass) stepped by parts equals the `Repeated` ring stepped monolithically, a
/// travelling wave over 400 steps, to 1e-12; and the wave turns by the discrete dispersion
/// relation's phase step.
#[test]
fn the_ring_by_parts_equals_the_monolithic_ring() {
    let (m, k, h, mode) = (1.5, 0.6, 0.1, 3);
    let kappa = 2.0 * std::f64::consts::PI * mode as f64 / ladder::CELLS as f64;
    let omega = ladder::lattice_frequency((k / m).sqrt(), kappa);
    let (q0, v0) = ladder::chain_wave(mode, omega);
    let mut monolithic =
        Stepper::new(ladder::chain(m, k).unwrap(), Quadrature::midpoint(), h).unwrap();
    monolithic.start_from_velocity(q0, v0).unwrap();
    let mut parts = ladder::modular_chain(m, k, ladder::CELLS, true, h).unwrap();
    parts
        .start_from_velocity(q0.as_slice(), v0.as_slice())
        .unwrap();
    assert_eq!(parts.coordinate_names(), monolithic.coordinate_names());
    let all: Vec<usize> = (0..ladder::CELLS).collect();
    let worst = lockstep(&mut parts, &mut monolithic, 400, &all, |parts| {
        assert!(parts.constraint_violation().unwrap() < 1e-14)
    });
    println!("ring: apart by {worst:e}");
    assert!(worst < 1e-12, "apart by {worst:e}");
    let q = SVector::<f64, { 2 * ladder::CELLS }>::from_column_slice(parts.q().as_slice());
    let (phase, _) = ladder::phase(mode, &q);
    let (start, _) = ladder::phase(mode, &q0);
    let turned = 400.0 * ladder::discrete_phase_step(h, omega);
    let expected = (start + turned).rem_euclid(2.0 * std::f64::consts::PI);
    let found = phase.rem_euclid(2.0 * std::f64::consts::PI);
    assert!(
        (found - expected).abs() < 1e-9,
        "{found} against {expected}"
    );
}

/// Each component's velocity and energy read from a modular run: the velocities equal the
/// monolithic stepper's `v()` to 1e-12 (the capacitor's, which only the junction fixes,
/// included), and each component's energy changes over a step by exactly its port work
/// (midpoint rule, quadratic Lagrangians): on the LC loop and on every cell of the ring of 16
/// masses, to 1e-14 of the energies and work in play, at every step.
#[test]
fn each_components_energy_changes_by_its_port_work() {
    let h = 0.05;
    let (mut parts, mut monolithic) = (lc_loop(h), lc_monolithic(h));
    parts.start_from_velocity(&[0.3, 0.3], &[1.0, 1.0]).unwrap();
    monolithic
        .start_from_velocity(SVector::from([0.3, 0.3]), SVector::from([1.0, 1.0]))
        .unwrap();
    let balance = |parts: &mut Modular, steps: usize| {
        let (mut worst, mut largest_work): (f64, f64) = (0.0, 0.0);
        let mut before = parts.energies().unwrap();
        for _ in 0..steps {
            parts.step().unwrap();
            let now = parts.energies().unwrap();
            let ports = parts.ports().unwrap();
            let scale = before
                .iter()
                .chain(&now)
                .fold(ports.scale, |m, e| m.max(e.abs()));
            for c in 0..now.len() {
                worst = worst.max((now[c] - before[c] - ports.work[c]).abs() / scale);
                largest_work = largest_work.max(ports.work[c].abs());
            }
            before = now;
        }
        (worst, largest_work)
    };
    let mut apart: f64 = 0.0;
    for _ in 0..200 {
        parts.step().unwrap();
        monolithic.step().unwrap();
        let v = parts.velocities().unwrap();
        apart =
            apart.max((v - DVector::from_column_slice(monolithic.v().unwrap().as_slice())).amax());
    }
    println!("LC loop velocities apart by {apart:e}");
    assert!(apart < 1e-12, "velocities apart by {apart:e}");
    let (worst, work) = balance(&mut parts, 500);
    println!("LC loop: energy balance {worst:e}, largest work {work:e}");
    assert!(
        worst < 1e-14 && work > 1e-3,
        "balance off by {worst:e} (work {work:e})"
    );

    let (m, k, mode) = (1.5, 0.6, 3);
    let kappa = 2.0 * std::f64::consts::PI * mode as f64 / ladder::CELLS as f64;
    let (q0, v0) = ladder::chain_wave(mode, ladder::lattice_frequency((k / m).sqrt(), kappa));
    let mut ring = ladder::modular_chain(m, k, ladder::CELLS, true, 0.1).unwrap();
    ring.start_from_velocity(q0.as_slice(), v0.as_slice())
        .unwrap();
    let (worst, work) = balance(&mut ring, 300);
    println!("ring: energy balance {worst:e}, largest work {work:e}");
    assert!(
        worst < 1e-14 && work > 1e-4,
        "balance off by {worst:e} (work {work:e})"
    );
}

/// A hierarchy: two LC loops, each a `Modular` of its own, included into a third and joined
/// by the capacitors' currents, equal the same four components added flat (bit for bit) and the
/// monolithic interconnection of two interconnections (to 1e-12 over 500 steps).
#[test]
fn included_interconnections_equal_the_flat_and_the_monolithic_ones() {
    let h = 0.05;
    let (l, c) = ([1.3, 0.8], [0.7, 1.9]);
    let series = |name: &str| Junction::new(name).flow("l.q", 1.0).flow("c.q", -1.0);
    let lc = |k: usize| {
        let mut lc = Modular::new(Quadrature::midpoint(), h).unwrap();
        lc.add("l", Inductor { l: l[k] }).unwrap();
        lc.add("c", Capacitor { c: c[k] }).unwrap();
        lc.join(series("series")).unwrap();
        lc
    };
    let shared = || {
        Junction::new("shared")
            .flow("left.c.q", 1.0)
            .flow("right.c.q", -1.0)
    };
    let mut nested = Modular::new(Quadrature::midpoint(), h).unwrap();
    nested.include("left", lc(0)).unwrap();
    nested.include("right", lc(1)).unwrap();
    nested.join(shared()).unwrap();
    let error = refused(nested.include("left", lc(0)));
    assert!(
        matches!(&error, DiracError::InvalidInterconnection(why) if why.contains("two instances"))
    );
    let mut flat = Modular::new(Quadrature::midpoint(), h).unwrap();
    // A name with '.' is refused (only an included interconnection's parts carry one); the flat
    // model names its parts apart.
    let error = refused(flat.add("left.l", Inductor { l: l[0] }));
    assert!(
        matches!(&error, DiracError::InvalidInterconnection(why) if why.contains("without '.'"))
    );
    let names = ["left_l", "left_c", "right_l", "right_c"];
    flat.add(names[0], Inductor { l: l[0] }).unwrap();
    flat.add(names[1], Capacitor { c: c[0] }).unwrap();
    flat.add(names[2], Inductor { l: l[1] }).unwrap();
    flat.add(names[3], Capacitor { c: c[1] }).unwrap();
    for (a, b) in [
        (names[0], names[1]),
        (names[2], names[3]),
        (names[1], names[3]),
    ] {
        let junction = Junction::new(format!("{a}-{b}"));
        flat.join(
            junction
                .flow(format!("{a}.q"), 1.0)
                .flow(format!("{b}.q"), -1.0),
        )
        .unwrap();
    }
    let pair = |k: usize| {
        Interconnection::new(
            ("l", Inductor { l: l[k] }),
            ("c", Capacitor { c: c[k] }),
            [series("series")],
        )
        .unwrap()
    };
    let whole: Interconnection<_, _, 2, 2, 4, 1> =
        Interconnection::new(("left", pair(0)), ("right", pair(1)), [shared()]).unwrap();
    let mut monolithic = Stepper::new(whole, Quadrature::midpoint(), h).unwrap();
    assert_eq!(nested.coordinate_names(), monolithic.coordinate_names());
    assert_eq!(
        nested.junction_names(),
        ["left.series", "right.series", "shared"]
    );
    let q0 = [0.2, 0.2, -0.1, -0.1];
    for modular in [&mut nested, &mut flat] {
        modular.start_from_velocity(&q0, &[0.5; 4]).unwrap();
    }
    monolithic
        .start_from_velocity(SVector::from(q0), SVector::from([0.5; 4]))
        .unwrap();
    let mut worst: f64 = 0.0;
    for _ in 0..500 {
        nested.step().unwrap();
        flat.step().unwrap();
        monolithic.step().unwrap();
        assert_eq!(nested.q(), flat.q());
        worst =
            worst.max((nested.q() - DVector::from_column_slice(monolithic.q().as_slice())).amax());
    }
    println!("nested: apart from the monolithic model by {worst:e}");
    assert!(worst < 1e-12, "apart by {worst:e}");
    assert!(nested.q().amax() > 0.3);
}

/// A knife edge in the plane with its one-form held at the step's end (`σ = 1`).
struct KnifeEdge;
impl DiracSystem<3> for KnifeEdge {
    const ONE_FORMS: usize = 1;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * 0.5 - q[1] * 0.3
    }
    fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, _a: usize) -> SVector<D, 3> {
        SVector::from([q[2].sin(), -q[2].cos(), D::from(0.0)])
    }
    fn constraint_point(&self) -> ConstraintPoint {
        ConstraintPoint::End
    }
    fn coordinate_name(&self, i: usize) -> String {
        ["x", "y", "theta"][i].into()
    }
}

/// A component with its own one-forms held at the step's end, joined to one without: every
/// junction's impulse takes the constrained component's share (`σ = 1` here, not the other
/// component's ½), as in the monolithic interconnection, which the steps equal to 1e-12 over
/// 400 steps; its own multiplier sits beside the junction's in the velocity solve.
#[test]
fn the_junctions_take_the_constrained_components_constraint_point() {
    let h = 0.02;
    let tie = || {
        Junction::new("tie")
            .flow("knife.x", 1.0)
            .flow("mass.x", -1.0)
    };
    let whole = Interconnection::new(
        ("knife", KnifeEdge),
        ("mass", MassSpring { m: 2.0, k: 0.5 }),
        [tie()],
    )
    .unwrap();
    let mut monolithic = Stepper::new(whole, Quadrature::midpoint(), h).unwrap();
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts.add("knife", KnifeEdge).unwrap();
    parts.add("mass", MassSpring { m: 2.0, k: 0.5 }).unwrap();
    parts.join(tie()).unwrap();
    // Heading 0.3, moving along it; the mass moves with the blade's x.
    let (theta, speed) = (0.3_f64, 1.0);
    let q0 = [0.0, 0.0, theta, 0.0];
    let v0 = [
        speed * theta.cos(),
        speed * theta.sin(),
        0.7,
        speed * theta.cos(),
    ];
    parts.start_from_velocity(&q0, &v0).unwrap();
    monolithic
        .start_from_velocity(SVector::from(q0), SVector::from(v0))
        .unwrap();
    let worst = lockstep(&mut parts, &mut monolithic, 400, &[1], |_| ());
    let v = parts.velocities().unwrap();
    let apart = (v - DVector::from_column_slice(monolithic.v().unwrap().as_slice())).amax();
    println!("knife edge and mass: apart by {worst:e}, velocities {apart:e}");
    assert!(
        worst < 1e-12 && apart < 1e-12,
        "apart by {worst:e}, velocities {apart:e}"
    );
    assert!(
        parts.multipliers().unwrap()[0].abs() > 1e-6,
        "the junction carried no impulse"
    );
}

/// A bob on a unit circle (a holonomic constraint, its multiplier inside the component's own
/// block) whose horizontal velocity a junction ties to a mass on a spring: by parts it equals
/// the monolithic interconnection to 1e-12 over 300 steps, velocities included (the velocity
/// solve holds the bob's constraint beside the junction).
struct Bob;
impl DiracSystem<2> for Bob {
    const HOLONOMIC: usize = 1;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
        (v[0] * v[0] + v[1] * v[1]) * 0.5 - q[1] * 9.81
    }
    fn holonomic<D: Scalar>(&self, q: &SVector<D, 2>, _b: usize) -> D {
        q[0] * q[0] + q[1] * q[1] - 1.0
    }
    fn coordinate_name(&self, i: usize) -> String {
        ["x", "y"][i].into()
    }
}

#[test]
fn a_component_with_its_own_holonomic_constraint_joins_by_parts() {
    let h = 0.01;
    let tie = || Junction::new("tie").flow("bob.x", 1.0).flow("cart.x", -1.0);
    let cart = MassSpring { m: 3.0, k: 2.0 };
    let whole = Interconnection::new(("bob", Bob), ("cart", cart), [tie()]).unwrap();
    let mut monolithic = Stepper::new(whole, Quadrature::midpoint(), h).unwrap();
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts.add("bob", Bob).unwrap();
    parts.add("cart", cart).unwrap();
    parts.join(tie()).unwrap();
    let (theta, omega) = (0.4_f64, 0.5);
    let q0 = [theta.sin(), -theta.cos(), theta.sin()];
    let v0 = [
        omega * theta.cos(),
        omega * theta.sin(),
        omega * theta.cos(),
    ];
    parts.start_from_velocity(&q0, &v0).unwrap();
    monolithic
        .start_from_velocity(SVector::from(q0), SVector::from(v0))
        .unwrap();
    // The monolithic model's multipliers: the junction (a one-form), then the bob's λ.
    let worst = lockstep(&mut parts, &mut monolithic, 300, &[0], |parts| {
        assert!(parts.constraint_violation().unwrap() < 1e-12)
    });
    let v = parts.velocities().unwrap();
    let apart = (v - DVector::from_column_slice(monolithic.v().unwrap().as_slice())).amax();
    println!("bob and cart: apart by {worst:e}, velocities {apart:e}");
    assert!(
        worst < 1e-12 && apart < 1e-12,
        "apart by {worst:e}, velocities {apart:e}"
    );
    let q = parts.q();
    assert!((q[0] * q[0] + q[1] * q[1] - 1.0).abs() < 1e-12);
    assert!((q[0] - q0[0]).abs() > 0.05, "it did not move");
}

/// A monolithic `Interconnection` with an input as one component: its input `drive.source.u`
/// is set by name (the component's own input name carries a dot), and the series RLC it closes
/// with an inductor and a capacitor, driven, equals the monolithic model to 1e-12.
#[test]
fn an_interconnection_with_an_input_is_a_component() {
    let h = 0.01;
    let drive = || {
        Interconnection::new(
            ("r", Resistor { r: 0.3 }),
            ("source", Source),
            [Junction::new("through")
                .flow("r.q", 1.0)
                .flow("source.q", -1.0)],
        )
        .unwrap()
    };
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts.add("l", Inductor { l: 1.0 }).unwrap();
    parts.add("c", Capacitor { c: 0.5 }).unwrap();
    parts.add("drive", drive()).unwrap();
    parts
        .join(Junction::new("lc").flow("l.q", 1.0).flow("c.q", -1.0))
        .unwrap();
    parts
        .join(Junction::new("cr").flow("c.q", 1.0).flow("drive.r.q", -1.0))
        .unwrap();
    let lc: Interconnection<_, _, 1, 1, 2, 1> = Interconnection::new(
        ("l", Inductor { l: 1.0 }),
        ("c", Capacitor { c: 0.5 }),
        [Junction::new("lc").flow("l.q", 1.0).flow("c.q", -1.0)],
    )
    .unwrap();
    let whole: Interconnection<_, _, 2, 2, 4, 1> = Interconnection::new(
        ("lc", lc),
        ("drive", drive()),
        [Junction::new("cr")
            .flow("lc.c.q", 1.0)
            .flow("drive.r.q", -1.0)],
    )
    .unwrap();
    let mut monolithic = Stepper::new(whole, Quadrature::midpoint(), h).unwrap();
    parts.start_from_velocity(&[0.0; 4], &[0.0; 4]).unwrap();
    monolithic
        .start_from_velocity(SVector::zeros(), SVector::zeros())
        .unwrap();
    parts.set_input("drive.source.u", 2.0).unwrap();
    monolithic.set_input("drive.source.u", 2.0).unwrap();
    let error = refused(parts.set_input("drive.u", 1.0));
    assert!(
        matches!(&error, DiracError::UnknownInput(why) if why.contains("drive.source.u")),
        "{error}"
    );
    // The monolithic model's multipliers: its inner junctions (lc, through), then cr.
    let worst = lockstep(&mut parts, &mut monolithic, 500, &[0, 2], |_| ());
    println!("driven RLC with an interconnection component: apart by {worst:e}");
    assert!(worst < 1e-12, "apart by {worst:e}");
    assert!(
        parts.q()[1] > 0.1,
        "the source did not charge the capacitor"
    );
}

/// A Lagrangian linear in a degenerate coordinate's velocity with a momentum that turns with
/// the position (`q₀ q̇₁`) is refused even where that momentum is zero at the start.
#[test]
fn a_turning_first_order_momentum_is_refused() {
    struct Turning;
    impl DiracSystem<2> for Turning {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
            v[0] * v[0] * 0.5 + q[0] * v[1] - q[1] * q[1] * 0.5
        }
    }
    let mut parts = Modular::new(Quadrature::midpoint(), 0.1).unwrap();
    parts.add("t", Turning).unwrap();
    let error = refused(parts.start_from_velocity(&[0.0, 0.2], &[1.0, 0.0]));
    assert!(
        matches!(&error, DiracError::Unsupported(why) if why.contains("t.q1") && why.contains("depends on the position")),
        "{error}"
    );
}

/// A ring of 5 000 cells: its closing junction joins the first and the last cell, so the
/// Schur complement's band would be as wide as the ring; the start refuses it, saying why.
#[test]
fn a_band_too_wide_for_memory_is_refused() {
    let cells = 5000;
    let mut ring = ladder::modular_chain(1.0, 1.0, cells, true, 0.1).unwrap();
    let error = refused(ring.start_from_velocity(&vec![0.0; 2 * cells], &vec![0.0; 2 * cells]));
    assert!(
        matches!(&error, DiracError::Unsupported(why) if why.contains("Schur") && why.contains("closing junction")),
        "{error}"
    );
    assert!(matches!(ring.step(), Err(DiracError::NotStarted)));
}

/// Junctions joined in any order give the same steps: the multipliers are numbered along the
/// components inside (a chain of 30 tethered masses joined backwards, bit for bit).
#[test]
fn the_order_of_joining_does_not_change_the_steps() {
    let cells = 30;
    let x = |j: usize| 0.05 * (j as f64 * 0.7).sin();
    let q0: Vec<f64> = (0..cells).flat_map(|j| [x(j), x(j + 1)]).collect();
    let forward = ladder::modular_chain(1.0, 1.0, cells, false, 0.05).unwrap();
    let mut backward = Modular::new(Quadrature::midpoint(), 0.05).unwrap();
    for j in 0..cells {
        backward
            .add(
                &format!("cell[{j}]"),
                scenes::components::Tethered { m: 1.0, k: 1.0 },
            )
            .unwrap();
    }
    for j in (0..cells).rev() {
        let end = Junction::new(format!("joint{j}")).flow(format!("cell[{j}].end"), 1.0);
        backward
            .join(if j + 1 < cells {
                end.flow(format!("cell[{}].x", j + 1), -1.0)
            } else {
                Junction::new("wall").flow(format!("cell[{j}].end"), 1.0)
            })
            .unwrap();
    }
    let mut runs = [forward, backward];
    for chain in &mut runs {
        chain
            .start_from_velocity(&q0, &vec![0.0; 2 * cells])
            .unwrap();
        chain.run(100).unwrap();
    }
    assert_eq!(runs[0].q(), runs[1].q());
    let mut reversed = runs[1].multipliers().unwrap().to_vec();
    reversed.reverse();
    assert_eq!(runs[0].multipliers().unwrap(), &reversed[..]);
}

/// The open chain of `cells` tethered masses at `x_j = 0.01 sin(κ j)` (each spring's end at the
/// next mass), at rest, after `steps` steps in parallel (first) and one component after
/// another (second).
fn both_ways(cells: usize, kappa: f64, steps: u64) -> [Modular; 2] {
    let x = |j: usize| 0.01 * (kappa * j as f64).sin();
    let q0: Vec<f64> = (0..cells).flat_map(|j| [x(j), x(j + 1)]).collect();
    let v0 = vec![0.0; 2 * cells];
    [true, false].map(|parallel| {
        let mut chain = ladder::modular_chain(1.0, 1.0, cells, false, 0.05)
            .unwrap()
            .with_parallel(parallel);
        chain.start_from_velocity(&q0, &v0).unwrap();
        chain.run(steps).unwrap();
        chain
    })
}

/// Stepped in parallel (rayon) or one component after another, the open chain of 2 500 cells
/// (long enough to be split into tasks) steps bit for bit alike (each component's equations are
/// its own; the Schur complement is summed in one order).
#[test]
fn parallel_and_sequential_steps_agree_bit_for_bit() {
    let mut runs = both_ways(2_500, 1.0, 20);
    assert_eq!(runs[0].q(), runs[1].q());
    assert_eq!(runs[0].p(), runs[1].p());
    assert!(runs[0].q().amax() > 0.0);
    runs[0].step().unwrap();
    assert_ne!(runs[0].q(), runs[1].q());
}

/// A chain long enough (6 000 cells, 18 000 unknowns) that Newton's passes over its vectors
/// are split across threads too: still the same steps bit for bit, and moved.
#[test]
fn a_long_chain_steps_alike_in_parallel_and_one_component_after_another() {
    let runs = both_ways(6_000, 0.3, 5);
    assert_eq!(runs[0].q(), runs[1].q());
    assert_eq!(runs[0].p(), runs[1].p());
    assert_eq!(
        runs[0].multipliers().unwrap(),
        runs[1].multipliers().unwrap()
    );
    assert!(runs[0].p().amax() > 0.0);
}

/// The series RLC from three components, two of them (the resistor and the capacitor) without
/// kinetic energy: the junctions fix their velocities. It equals the monolithic
/// interconnection (the inductor and the resistor, then the capacitor) over 500 steps, and its
/// charge decays as the closed form `e^{−rt/2l} cos(ω_d t)` to the midpoint rule's error.
#[test]
fn the_rlc_by_parts_equals_the_monolithic_rlc() {
    let (l, r, c, h) = (1.0, 0.2, 1.0, 0.01);
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts.add("l", Inductor { l }).unwrap();
    parts.add("r", Resistor { r }).unwrap();
    parts.add("c", Capacitor { c }).unwrap();
    parts
        .join(Junction::new("lr").flow("l.q", 1.0).flow("r.q", -1.0))
        .unwrap();
    parts
        .join(Junction::new("rc").flow("r.q", 1.0).flow("c.q", -1.0))
        .unwrap();
    let lr: Interconnection<_, _, 1, 1, 2, 1> = Interconnection::new(
        ("l", Inductor { l }),
        ("r", Resistor { r }),
        [Junction::new("lr").flow("l.q", 1.0).flow("r.q", -1.0)],
    )
    .unwrap();
    let whole = Interconnection::new(
        ("lr", lr),
        ("c", Capacitor { c }),
        [Junction::new("rc").flow("lr.r.q", 1.0).flow("c.q", -1.0)],
    )
    .unwrap();
    let mut monolithic = Stepper::new(whole, Quadrature::midpoint(), h).unwrap();
    let q0 = [1.0, 1.0, 1.0];
    parts.start_from_velocity(&q0, &[0.0; 3]).unwrap();
    monolithic
        .start_from_velocity(SVector::from(q0), SVector::zeros())
        .unwrap();
    let worst = lockstep(&mut parts, &mut monolithic, 500, &[0, 1], |_| ());
    println!("RLC: apart by {worst:e}");
    assert!(worst < 1e-12, "apart by {worst:e}");
    let t = parts.t();
    let (decay, omega) = (
        r / (2.0 * l),
        (1.0 / (l * c) - (r / (2.0 * l)).powi(2)).sqrt(),
    );
    let exact = (-decay * t).exp() * ((omega * t).cos() + decay / omega * (omega * t).sin());
    assert!(
        (parts.q()[2] - exact).abs() < 1e-4,
        "{} against {exact}",
        parts.q()[2]
    );
}

/// The seed's LC circuit by parts, unequal capacitors: the loop (inductor ⊕ C2) and the pair
/// (C1 ⊕ C3), each a `Modular`, included and joined by KCL. C1 ∥ C3 is a hidden constraint across
/// the components, `q_c1/c1 = q_c3/c3`: held to round-off at every step's end (measured 0; here
/// the step keeps this linear constraint even without the projection, which the nonlinear pair
/// below needs), and the steps equal the monolithic circuit from the same subcircuits over
/// 2 000 steps to 1e-12 (charges, momenta, both multipliers). The
/// velocities equal the monolithic `v()` and satisfy KCL and the constraint's velocity form; the
/// energy is conserved to round-off; Tellegen's theorem holds to round-off of the charges.
#[test]
fn the_seed_lc_circuit_by_parts_holds_its_hidden_constraint_and_equals_the_whole() {
    let (c, h) = (circuit::UNEQUAL, 0.01);
    let (q0, v0) = circuit::UNEQUAL_START;
    let mut parts = circuit::lc_by_parts(&c, h).unwrap();
    assert_eq!(
        parts.coordinate_names(),
        ["loop.l.q", "loop.c2.q", "pair.c1.q", "pair.c3.q"]
    );
    parts.start_from_velocity(&q0, &v0).unwrap();
    let mut whole = Stepper::new(
        circuit::lc_from_subcircuits(&c).unwrap(),
        Quadrature::midpoint(),
        h,
    )
    .unwrap();
    whole
        .start_from_velocity(SVector::from(q0), SVector::from(v0))
        .unwrap();
    let e0: f64 = parts.energies().unwrap().iter().sum();
    let hidden = std::cell::Cell::new(0.0_f64);
    let tellegen = std::cell::Cell::new(0.0_f64);
    let worst = lockstep(&mut parts, &mut whole, 2_000, &[0, 1], |parts| {
        let q = parts.q();
        hidden.set(hidden.get().max((q[2] / c.c1 - q[3] / c.c3).abs()));
        // The net port work in units of the round-off of the stored charges' differences.
        let ports = parts.ports().unwrap();
        let effort = ports.efforts.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
        let round_off = f64::EPSILON * effort * q.amax();
        tellegen.set(tellegen.get().max(ports.net_work().abs() / round_off));
    });
    println!(
        "seed LC circuit: apart by {worst:e}, hidden constraint {:e}, Tellegen {} ε|e||q|",
        hidden.get(),
        tellegen.get()
    );
    assert!(worst < 1e-12, "apart by {worst:e}");
    // Tellegen to round-off of the charges: the port work is read on the stored positions'
    // differences q_{k+1} − q_k, each rounded to ε|q| (1.1 ε |e| |q| at worst; relative to the
    // work's terms, which vanish where the current turns, that is up to 2.4e-12).
    assert!(tellegen.get() < 4.0, "Tellegen {} ε|e||q|", tellegen.get());
    assert!(
        hidden.get() <= 1e-14,
        "hidden constraint {:e}",
        hidden.get()
    );
    let v = parts.velocities().unwrap();
    let theirs = whole.v().unwrap();
    let gap = (0..4).fold(0.0_f64, |m, i| m.max((v[i] - theirs[i]).abs()));
    assert!(gap < 1e-13, "velocities {v} against {theirs}");
    assert!(
        (v[0] - v[1]).abs() < 1e-14 && (v[1] - v[2] - v[3]).abs() < 1e-14,
        "{v}"
    );
    assert!((v[2] / c.c1 - v[3] / c.c3).abs() < 1e-14, "{v}");
    let drift = (parts.energies().unwrap().iter().sum::<f64>() - e0).abs();
    assert!(drift < 1e-13, "energy drift {drift:e}");
}

/// The seed's circuit from two attribute models as two components: the loop (its own one-form)
/// and the pair (C1 and C3, two coordinates without kinetic energy in one component, stepped
/// without its own hidden-constraint analysis): the constraint inside the pair is held by the
/// interconnection, and the steps equal the same circuit written with the attribute in two
/// levels (one model) to 1e-12 over 1 000 steps.
#[test]
fn a_hidden_constraint_inside_one_component_is_held_by_the_interconnection() {
    let (c, h) = (circuit::UNEQUAL, 0.01);
    let (q0, v0) = circuit::UNEQUAL_START;
    let whole_model = circuit::LcByAttribute::of(&c);
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts.add("loop_", whole_model.loop_).unwrap();
    parts.add("pair", whole_model.pair).unwrap();
    parts
        .join(
            Junction::new("kcl")
                .flow("loop_.c2.q", 1.0)
                .flow("pair.c1.q", -1.0)
                .flow("pair.c3.q", -1.0),
        )
        .unwrap();
    parts.start_from_velocity(&q0, &v0).unwrap();
    let mut whole = Stepper::new(whole_model, Quadrature::midpoint(), h).unwrap();
    whole
        .start_from_velocity(SVector::from(q0), SVector::from(v0))
        .unwrap();
    let hidden = std::cell::Cell::new(0.0_f64);
    let worst = lockstep(&mut parts, &mut whole, 1_000, &[1], |parts| {
        let q = parts.q();
        hidden.set(hidden.get().max((q[2] / c.c1 - q[3] / c.c3).abs()));
    });
    println!(
        "pair as one component: apart by {worst:e}, hidden constraint {:e}",
        hidden.get()
    );
    assert!(worst < 1e-12, "apart by {worst:e}");
    assert!(hidden.get() < 1e-14, "hidden constraint {:e}", hidden.get());
}

/// A capacitor whose voltage grows faster than its charge: `V(q) = q/c + β q³`.
struct StiffeningCapacitor {
    c: f64,
    beta: f64,
}

impl DiracSystem<1> for StiffeningCapacitor {
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, _v: &SVector<D, 1>) -> D {
        -(q[0] * q[0] / (2.0 * self.c) + q[0].powi(4) * (self.beta / 4.0))
    }
    fn coordinate_name(&self, _i: usize) -> String {
        "q".into()
    }
}

/// The seed's circuit with C3 nonlinear, by parts: the hidden constraint across the components,
/// `q_c1/c1 = q_c3/c3 + β q_c3³`, is not linear, so the midpoint rule's nodes leave the step's
/// end off it by the method's order; the step's projection holds it there to round-off (2e-15;
/// without it the end points miss by 7e-6 and part from the monolithic circuit by 4e-6), and the
/// steps equal the monolithic circuit, which projects onto the same constraint, to 1e-12 over
/// 2 000 steps (4e-15).
#[test]
fn a_nonlinear_hidden_constraint_across_components_is_held_at_every_step() {
    let (c, beta, h) = (circuit::UNEQUAL, 0.5, 0.01);
    let c3 = || StiffeningCapacitor { c: c.c3, beta };
    let voltage = |q: f64| q / c.c3 + beta * q.powi(3);
    let slope = |q: f64| 1.0 / c.c3 + 3.0 * beta * q * q;
    // Equal voltages, and a current 0.5 split so that they stay equal.
    let q3 = 0.4;
    let v3 = 0.5 / (1.0 + c.c1 * slope(q3));
    let q0 = [0.0, 1.0, c.c1 * voltage(q3), q3];
    let v0 = [0.5, 0.5, 0.5 - v3, v3];
    let mut parts = circuit::lc_by_parts_with(&c, c3(), h).unwrap();
    parts.start_from_velocity(&q0, &v0).unwrap();
    let whole = circuit::lc_from_subcircuits_with(&c, c3()).unwrap();
    let mut whole = Stepper::new(whole, Quadrature::midpoint(), h).unwrap();
    whole
        .start_from_velocity(SVector::from(q0), SVector::from(v0))
        .unwrap();
    let hidden = std::cell::Cell::new(0.0_f64);
    let worst = lockstep(&mut parts, &mut whole, 2_000, &[0, 1], |parts| {
        let q = parts.q();
        hidden.set(hidden.get().max((q[2] / c.c1 - voltage(q[3])).abs()));
    });
    println!(
        "nonlinear pair: apart by {worst:e}, hidden constraint {:e}",
        hidden.get()
    );
    assert!(worst < 1e-12, "apart by {worst:e}");
    assert!(hidden.get() < 1e-14, "hidden constraint {:e}", hidden.get());
}

/// The loop and three capacitors in parallel (C3 stiffening, `V = q/2 + q³/2`; C4 = 0.5),
/// written as one model: the reference of the test below.
#[dirac_system(
    coordinates(q_l, q_c2, q_c1, q_c3, q_c4),
    lagrangian = 0.5 * dot(q_l).powi(2) - 0.5 * q_c2.powi(2) - 0.5 * q_c1.powi(2)
        - (0.25 * q_c3.powi(2) + beta / 4.0 * q_c3.powi(4)) - q_c4.powi(2),
    constraints(dq_l - dq_c2, dq_c2 - dq_c1 - dq_c3 - dq_c4),
)]
struct ThreeInParallel {
    beta: f64,
}

/// Two hidden constraints across components, one nonlinear, and a component of two coordinates
/// whose degenerate one is its second: the loop (inductor and C2 in series, its own one-form)
/// feeding C1 ∥ C3 ∥ C4, each a component. Held at every step's end to round-off (`V1 = V3`,
/// `V1 = V4`), and the steps, the KCL multiplier and the velocities equal the model written as
/// one struct to 1e-12 over 1 000 steps.
#[test]
fn two_hidden_constraints_across_components_of_several_coordinates() {
    let (beta, h) = (0.5, 0.01);
    let voltage3 = |q: f64| q / 2.0 + beta * q.powi(3);
    let q3 = 0.4;
    let rate = 0.5 / (1.0 + 1.0 / (0.5 + 3.0 * beta * q3 * q3) + 0.5);
    let q0 = [0.0, 1.0, voltage3(q3), q3, voltage3(q3) / 2.0];
    let v0 = [
        0.5,
        0.5,
        rate,
        rate / (0.5 + 3.0 * beta * q3 * q3),
        rate / 2.0,
    ];
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    let loop_ = circuit::Loop {
        l: Inductor { l: 1.0 },
        c2: Capacitor { c: 1.0 },
    };
    parts.add("loop", loop_).unwrap();
    parts.add("c1", Capacitor { c: 1.0 }).unwrap();
    parts
        .add("c3", StiffeningCapacitor { c: 2.0, beta })
        .unwrap();
    parts.add("c4", Capacitor { c: 0.5 }).unwrap();
    parts
        .join(
            Junction::new("kcl")
                .flow("loop.c2.q", 1.0)
                .flow("c1.q", -1.0)
                .flow("c3.q", -1.0)
                .flow("c4.q", -1.0),
        )
        .unwrap();
    parts.start_from_velocity(&q0, &v0).unwrap();
    let mut whole = Stepper::new(ThreeInParallel { beta }, Quadrature::midpoint(), h).unwrap();
    whole
        .start_from_velocity(SVector::from(q0), SVector::from(v0))
        .unwrap();
    let hidden = std::cell::Cell::new(0.0_f64);
    let worst = lockstep(&mut parts, &mut whole, 1_000, &[1], |parts| {
        let q = parts.q();
        let off = (q[2] - voltage3(q[3])).abs().max((q[2] - 2.0 * q[4]).abs());
        hidden.set(hidden.get().max(off));
    });
    println!(
        "three in parallel: apart by {worst:e}, hidden constraints {:e}",
        hidden.get()
    );
    assert!(worst < 1e-12, "apart by {worst:e}");
    assert!(
        hidden.get() < 1e-14,
        "hidden constraints {:e}",
        hidden.get()
    );
    let v = parts.velocities().unwrap();
    let theirs = whole.v().unwrap();
    let gap = (0..5).fold(0.0_f64, |m, i| m.max((v[i] - theirs[i]).abs()));
    assert!(gap < 1e-12, "velocities {v} against {theirs}");
}

/// A mass, a spring and a damper, each a component, the spring and the damper both between the
/// ground and the mass (`ds = dx`, `dd = dx`): by parts, the damped oscillator
/// `m ẍ + c ẋ + k x = 0`, against its closed form at T = 5 at second order (h = 0.02, 0.01).
#[test]
fn a_mass_spring_and_damper_from_three_components_oscillate_as_one() {
    let (m, k, c) = (2.0, 3.0, 0.4);
    let omega = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    let damped = omega * (1.0 - zeta * zeta).sqrt();
    let exact = |t: f64| {
        (-zeta * omega * t).exp()
            * ((damped * t).cos() + zeta * omega / damped * (damped * t).sin())
    };
    let error = |h: f64| {
        let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
        parts.add("mass", Mass { m }).unwrap();
        parts.add("spring", Spring { k }).unwrap();
        parts.add("damper", Damper { c }).unwrap();
        parts
            .join(
                Junction::new("spring")
                    .flow("spring.x", 1.0)
                    .flow("mass.x", -1.0),
            )
            .unwrap();
        parts
            .join(
                Junction::new("damper")
                    .flow("damper.x", 1.0)
                    .flow("mass.x", -1.0),
            )
            .unwrap();
        parts
            .start_from_velocity(&[1.0, 1.0, 1.0], &[0.0; 3])
            .unwrap();
        parts.run((5.0 / h).round() as u64).unwrap();
        let q = parts.q();
        assert!(
            (q[0] - q[1]).abs() < 1e-12,
            "the spring's elongation is the mass's: {q}"
        );
        (q[0] - exact(parts.t())).abs()
    };
    let (coarse, fine) = (error(0.02), error(0.01));
    let order = (coarse / fine).log2();
    println!("mass, spring, damper: errors {coarse:e}, {fine:e}, order {order}");
    assert!(fine < 1e-4, "{fine:e}");
    assert!((order - 2.0).abs() < 0.05, "order {order}");
}

/// The DC motor driving a pendulum arm through the shaft junction, with a voltage input set by
/// name, stepped by parts equals the monolithic interconnection over 1 000 steps (a nonlinear
/// component with forces and an input) to 1e-12, and its arm turns towards the rest angle.
#[test]
fn the_driven_motor_and_arm_by_parts_equal_the_monolithic_model() {
    let h = 0.01;
    let mut monolithic =
        Stepper::new(motor::motor_arm().unwrap(), Quadrature::midpoint(), h).unwrap();
    monolithic
        .start_from_velocity(SVector::zeros(), SVector::zeros())
        .unwrap();
    monolithic.set_input("motor.u", motor::U).unwrap();
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts.add("motor", motor::MOTOR).unwrap();
    parts.add("arm", motor::ARM).unwrap();
    parts
        .join(
            Junction::new("shaft")
                .flow("motor.theta", 1.0)
                .flow("arm.phi", -1.0),
        )
        .unwrap();
    parts.start_from_velocity(&[0.0; 3], &[0.0; 3]).unwrap();
    let error = refused(parts.set_input("motor.volts", 1.0));
    assert!(
        matches!(&error, DiracError::UnknownInput(why) if why.contains("the inputs are motor.u")),
        "{error}"
    );
    assert!(matches!(
        refused(parts.set_input("motor.u", f64::NAN)),
        DiracError::NonFinite { .. }
    ));
    parts.set_input("motor.u", motor::U).unwrap();
    let worst = lockstep(&mut parts, &mut monolithic, 1000, &[0], |_| ());
    println!("motor and arm: apart by {worst:e}");
    assert!(worst < 1e-12, "apart by {worst:e}");
    assert!(
        parts.q()[2] > 0.1 * motor::rest_angle(),
        "the arm did not turn"
    );
}

/// A coordinate without energy or force: only junctions fix it.
struct Wire;
impl DiracSystem<1> for Wire {
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, _v: &SVector<D, 1>) -> D {
        q[0] * 0.0
    }
}

fn refused<T: std::fmt::Debug>(result: Result<T, DiracError>) -> DiracError {
    result.expect_err("refused")
}

/// What the modular step cannot do it refuses with an error that says why, and a failed step
/// or start changes nothing.
#[test]
fn what_the_modular_step_cannot_do_is_refused() {
    // A Galerkin rule.
    let error = refused(Modular::new(Quadrature::galerkin(2).unwrap(), 0.1));
    assert!(matches!(&error, DiracError::Unsupported(why) if why.contains("degree 1")));
    // Names.
    let mut lc = lc_loop(0.1);
    let error = refused(lc.add("l", Inductor { l: 1.0 }));
    assert!(
        matches!(&error, DiracError::InvalidInterconnection(why) if why.contains("two instances"))
    );
    let error = refused(lc.join(Junction::new("bad").flow("c.charge", 1.0)));
    assert!(
        matches!(&error, DiracError::InvalidInterconnection(why) if why.contains("\"c.charge\"") && why.contains("c has c.q")),
        "{error}"
    );
    let error = refused(lc.join(Junction::new("series").flow("c.q", 1.0)));
    assert!(
        matches!(&error, DiracError::InvalidInterconnection(why) if why.contains("two junctions"))
    );
    // A start that violates the junction.
    let error = refused(lc.start_from_velocity(&[0.0, 0.0], &[1.0, 0.5]));
    assert!(
        matches!(&error, DiracError::InconsistentInitialState(why) if why.contains("junction series")),
        "{error}"
    );
    assert!(matches!(lc.step(), Err(DiracError::NotStarted)));
    // Junctions that depend on each other: the first step's Schur complement is singular.
    let mut twice = lc_loop(0.1);
    twice
        .join(Junction::new("again").flow("l.q", 2.0).flow("c.q", -2.0))
        .unwrap();
    let error = refused(twice.start_from_velocity(&[0.0, 0.0], &[1.0, 1.0]));
    assert!(
        matches!(&error, DiracError::SingularJacobian { unknowns, .. } if unknowns.contains("junction again") && unknowns.contains("junction series")),
        "{error}"
    );
    assert!(matches!(twice.step(), Err(DiracError::NotStarted)));
    // Two capacitors in parallel: a hidden constraint across the components (equal voltages)
    // that no junction's impulse enters; the initial state must satisfy it and its velocity form.
    let parallel = |other: &str| {
        let mut parallel = Modular::new(Quadrature::midpoint(), 0.1).unwrap();
        parallel.add("a", Capacitor { c: 1.0 }).unwrap();
        match other {
            "capacitor" => parallel.add("b", Capacitor { c: 2.0 }).unwrap(),
            _ => parallel.add("b", Resistor { r: 2.0 }).unwrap(),
        }
        parallel.add("l", Inductor { l: 1.0 }).unwrap();
        parallel
            .join(
                Junction::new("kcl")
                    .flow("l.q", 1.0)
                    .flow("a.q", -1.0)
                    .flow("b.q", -1.0),
            )
            .unwrap();
        parallel
    };
    let error =
        refused(parallel("capacitor").start_from_velocity(&[1.0, 2.0, 3.0], &[0.5, 0.5, 1.0]));
    assert!(
        matches!(&error, DiracError::InconsistentInitialState(why) if why.contains("a.q, b.q") && why.contains("velocity form")),
        "{error}"
    );
    let error =
        refused(parallel("capacitor").start_from_velocity(&[1.0, 1.0, 3.0], &[0.5, 1.0, 1.5]));
    assert!(
        matches!(&error, DiracError::InconsistentInitialState(why) if why.contains("a.q, b.q") && why.contains("initial positions")),
        "{error}"
    );
    parallel("capacitor")
        .start_from_velocity(&[1.0, 2.0, 3.0], &[0.5, 1.0, 1.5])
        .unwrap();
    // A capacitor whose voltage is modulated in time, `q/c − cos(t) q`: the hidden constraint
    // depends on t, refused even from q = 0 where the modulation vanishes.
    let mut modulated = parallel("capacitor");
    modulated.add("m", Modulated).unwrap();
    modulated
        .join(Junction::new("beside").flow("m.q", 1.0).flow("a.q", -1.0))
        .unwrap();
    let error = refused(modulated.start_from_velocity(&[0.0; 4], &[0.0; 4]));
    assert!(
        matches!(&error, DiracError::Unsupported(why) if why.contains("m.q") && why.contains("depend on time")),
        "{error}"
    );
    // More hidden constraints than the dense projection takes: 258 capacitors in parallel.
    let mut many = Modular::new(Quadrature::midpoint(), 0.1).unwrap();
    many.add("l", Inductor { l: 1.0 }).unwrap();
    let mut kcl = Junction::new("kcl").flow("l.q", 1.0);
    for i in 0..258 {
        many.add(&format!("c{i}"), Capacitor { c: 1.0 }).unwrap();
        kcl = kcl.flow(format!("c{i}.q"), -1.0);
    }
    many.join(kcl).unwrap();
    let error = refused(many.start_from_velocity(&[0.0; 259], &[0.0; 259]));
    assert!(
        matches!(&error, DiracError::Unsupported(why) if why.contains("257 hidden constraints")),
        "{error}"
    );
    // A resistor beside a capacitor: their rows combine into a first-order equation across the
    // components, which the modular step does not solve.
    let error =
        refused(parallel("resistor").start_from_velocity(&[1.0, 2.0, 3.0], &[0.5, 1.0, 1.5]));
    assert!(
        matches!(&error, DiracError::Unsupported(why) if why.contains("a.q, b.q") && why.contains("contain velocities")),
        "{error}"
    );
    // A component whose own step equations are singular (a wire: no energy, no force), though
    // the junctions fix its current: the Schur complement needs each block regular.
    let mut wired = lc_loop(0.1);
    wired.add("wire", Wire).unwrap();
    wired
        .join(
            Junction::new("through")
                .flow("wire.q0", 1.0)
                .flow("l.q", -1.0),
        )
        .unwrap();
    let error = refused(wired.start_from_velocity(&[0.0, 0.0, 0.0], &[1.0, 1.0, 1.0]));
    assert!(
        matches!(&error, DiracError::Unsupported(why) if why.contains("wire: q0") && why.contains("monolithically")),
        "{error}"
    );
    // A step that fails leaves the state as it was.
    let mut chain = ladder::modular_chain(1.0, 1.0, 4, false, 0.1)
        .unwrap()
        .with_newton_options(NewtonOptions {
            max_iterations: 1,
            ..Default::default()
        })
        .unwrap();
    let q0 = [0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]; // the first spring stretched
    chain.start_from_velocity(&q0, &[0.0; 8]).unwrap();
    let error = refused(chain.step());
    assert!(matches!(error, DiracError::NoConvergence { .. }), "{error}");
    assert_eq!(chain.q().as_slice(), &q0);
    assert_eq!(chain.steps(), 0);
    assert!(matches!(
        refused(chain.start_from_velocity(&q0, &[0.0; 3])),
        DiracError::Dimension(_)
    ));
    // A component's own violation names it.
    let mut springs = Modular::new(Quadrature::midpoint(), 0.1).unwrap();
    springs.add("a", MassSpring { m: 1.0, k: 1.0 }).unwrap();
    let error = refused(springs.start_from_velocity(&[f64::NAN], &[0.0]));
    assert!(
        matches!(&error, DiracError::NonFinite { what, .. } if what.contains("component a")),
        "{error}"
    );
}
