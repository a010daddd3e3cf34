//! The time-transformed explicit step (`dt/ds = 1/(c − V(q))`, the logarithmic Hamiltonian):
//! Kepler's orbits followed exactly at high eccentricity, the orders in the fictive step against
//! closed forms, the offset on a potential of either sign, bounded energy, landing on a time, and
//! the refusals.

use crate::support::{assert_order, energy_error_first_and_last_tenth};

use dirac::prelude::*;
use scenes::first_order::{FirstOrder, KeplerOde};
use scenes::{double_pendulum, kepler, oscillator, pendulum};

use std::f64::consts::PI;

/// The Kepler orbit of eccentricity `e` and semi-major axis 1 from its pericentre.
fn orbit(e: f64) -> KeplerOde {
    KeplerOde {
        kepler: kepler::SCENE,
        e,
    }
}

/// A time-transformed Kepler step on the orbit of eccentricity `e`, `n` fictive steps a
/// revolution (the fictive period of `dt/ds = |q|` is 2π).
fn comet(e: f64, composition: Composition, n: usize) -> TimeTransformed<kepler::Kepler, 2> {
    let y = orbit(e).initial();
    let mut comet = TimeTransformed::new(kepler::SCENE, composition, 2.0 * PI / n as f64).unwrap();
    comet
        .start_from_velocity(vector![y[0], y[1]], vector![y[2], y[3]])
        .unwrap();
    comet
}

/// The Runge–Lenz vector `p × L − q/|q|` of a unit mass in the plane (μ = 1).
fn runge_lenz(q: &SVector<f64, 2>, p: &SVector<f64, 2>) -> SVector<f64, 2> {
    let l = kepler::angular_momentum(q, p);
    vector![p[1] * l, -p[0] * l] - q / q.norm()
}

/// |(q, p)(t_end) − Kepler's closed form| after a run that lands on `t_end`.
fn error_at(e: f64, composition: Composition, n: usize, t_end: f64) -> f64 {
    let mut comet = comet(e, composition, n);
    comet.run_until(t_end).unwrap();
    let exact = orbit(e).exact(t_end).unwrap();
    (comet.q() - vector![exact[0], exact[1]])
        .amax()
        .max((comet.p() - vector![exact[2], exact[3]]).amax())
}

/// With `V = −1/|q|` and no offset the step follows Kepler's orbit exactly, whatever the step:
/// over 100 revolutions at e = 0.9 and e = 0.99, 8 to 100 fictive steps a revolution, the
/// energy, the angular momentum and the Runge–Lenz vector stay at their start to round-off at
/// every step, the energy relative to the potential at the pericentre (which it sums). The
/// orbit's points are exact; the time along it is not (`orders_in_the_fictive_step`).
#[test]
fn keplers_orbit_is_followed_exactly_at_high_eccentricity() {
    for e in [0.9, 0.99] {
        for (composition, n) in [
            (Composition::verlet(), 8),
            (Composition::verlet(), 20),
            (Composition::verlet(), 100),
            (Composition::kahan_li_8(), 20),
        ] {
            let name = composition.name();
            let mut comet = comet(e, composition, n);
            let (q0, p0) = (comet.q(), comet.p());
            let (l0, a0) = (kepler::angular_momentum(&q0, &p0), runge_lenz(&q0, &p0));
            let trajectory = comet.trajectory_until(200.0 * PI).unwrap();
            let energy = trajectory.max_energy_error();
            let (mut momentum, mut lenz) = (0.0_f64, 0.0_f64);
            for (q, p) in trajectory.q().iter().zip(trajectory.p()) {
                momentum = momentum.max((kepler::angular_momentum(q, p) - l0).abs());
                lenz = lenz.max((runge_lenz(q, p) - a0).amax());
            }
            println!(
                "e = {e}, {name}, {n} a revolution, {} steps: |ΔE| {energy:.1e}, |ΔL| \
                 {momentum:.1e}, |ΔA| {lenz:.1e}",
                comet.steps()
            );
            // Round-off: E = T + V sums terms of size |V| = 1/(1 − e) at the pericentre.
            let scale = 1.0 / (1.0 - e);
            assert!(energy < 1e-13 * scale, "{e} {name} {n}: {energy}");
            assert!(momentum < 1e-12, "{e} {name} {n}: {momentum}");
            assert!(lenz < 1e-10, "{e} {name} {n}: {lenz}");
        }
    }
}

/// The error at t = 10 (landing on it) against Kepler's equation at e = 0.9: order 2, 4, 6 and
/// 8 in the fictive step for Störmer–Verlet, Suzuki, Kahan–Li 6 and Kahan–Li 8.
#[test]
fn orders_in_the_fictive_step_against_keplers_equation() {
    for (composition, steps, order) in [
        (Composition::verlet(), [50, 100, 200, 400], 2.0),
        (Composition::suzuki(), [25, 50, 100, 200], 4.0),
        (Composition::kahan_li_6(), [12, 16, 24, 32], 6.0),
        (Composition::kahan_li_8(), [8, 10, 12, 16], 8.0),
    ] {
        let name = composition.name();
        let errors: Vec<f64> = steps
            .iter()
            .map(|&n| error_at(0.9, composition.clone(), n, 10.0))
            .collect();
        let ds: Vec<f64> = steps.iter().map(|&n| 2.0 * PI / n as f64).collect();
        assert_order(&format!("e = 0.9, {name}"), &ds, &errors, order);
    }
}

/// A pendulum (`V = −cos θ`, positive above the horizontal) with the offset c = 2, so that
/// `dt/ds = 1/(2 + cos θ)`: orders 2 and 4 against the pendulum's q(5), p(5), the same limit for
/// another offset, and an energy error that does not drift over 10⁵ steps.
#[test]
fn an_offset_takes_potentials_of_either_sign() {
    let error = |composition: &Composition, ds: f64, offset: f64| {
        let mut stepper = TimeTransformed::new(pendulum::SCENE, composition.clone(), ds)
            .unwrap()
            .with_offset(offset)
            .unwrap();
        stepper
            .start_from_momentum(vector![1.0], vector![0.0])
            .unwrap();
        stepper.run_until(5.0).unwrap();
        (stepper.q()[0] - pendulum::Q5)
            .abs()
            .max((stepper.p()[0] - pendulum::P5).abs())
    };
    let ds = [0.4, 0.2, 0.1, 0.05];
    for (composition, order) in [(Composition::verlet(), 2.0), (Composition::suzuki(), 4.0)] {
        let errors: Vec<f64> = ds.iter().map(|&ds| error(&composition, ds, 2.0)).collect();
        assert_order(
            &format!("pendulum, c = 2, {}", composition.name()),
            &ds,
            &errors,
            order,
        );
    }
    // A larger offset, smaller steps of s: the same motion (the closed form to 1e-9).
    assert!(error(&Composition::kahan_li_8(), 0.5, 10.0) < 1e-9);
    let mut stepper = TimeTransformed::new(pendulum::SCENE, Composition::verlet(), 0.2)
        .unwrap()
        .with_offset(2.0)
        .unwrap();
    stepper
        .start_from_momentum(vector![2.0], vector![0.0])
        .unwrap();
    let mut energies = vec![stepper.energy().unwrap()];
    for _ in 0..100_000 {
        stepper.step().unwrap();
        energies.push(stepper.energy().unwrap());
    }
    let (first, last) = energy_error_first_and_last_tenth(&energies);
    println!(
        "pendulum from θ = 2, 10⁵ steps: |ΔE| {first:.2e} in the first tenth, {last:.2e} in the last"
    );
    assert!(first > 1e-4 && last < 1.1 * first, "{first} {last}");
}

/// Kepler's problem with a mass `m = 2`, a force constant `k = 2` and a constant gauge term
/// `bᵀv` (a total derivative): the same motion as the unit problem, its momentum `p = m v + b`.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) + bx * dot(x) + by * dot(y)
        + k / sqrt(x * x + y * y),
)]
#[derive(Debug, Clone, Copy)]
struct HeavyKepler {
    m: f64,
    k: f64,
    bx: f64,
    by: f64,
}

/// A mass matrix other than the identity and a momentum offset `b`: with `dt/ds = 1/(c − V)`
/// twice the unit problem's, a fictive step twice as long gives the same positions, to
/// round-off, at every step and at the end a run lands on; a start time shifts the run alone.
#[test]
fn a_mass_and_a_gauge_term_give_the_same_motion() {
    let heavy = HeavyKepler {
        m: 2.0,
        k: 2.0,
        bx: 0.3,
        by: -0.2,
    };
    let y = orbit(0.9).initial();
    let (q0, v0) = (vector![y[0], y[1]], vector![y[2], y[3]]);
    let ds = 2.0 * PI / 32.0;
    let mut unit = TimeTransformed::new(kepler::SCENE, Composition::suzuki(), ds).unwrap();
    unit.start_from_velocity(q0, v0).unwrap();
    let mut scaled = TimeTransformed::new(heavy, Composition::suzuki(), 2.0 * ds)
        .unwrap()
        .with_start_time(100.0);
    scaled.start_from_velocity(q0, v0).unwrap();
    assert!((scaled.p() - (v0 * 2.0 + vector![0.3, -0.2])).amax() < 1e-15);
    assert!((scaled.energy().unwrap() - 2.0 * unit.energy().unwrap()).abs() < 1e-13);
    for _ in 0..100 {
        unit.step().unwrap();
        scaled.step().unwrap();
        assert!(
            (scaled.q() - unit.q()).amax() < 1e-12,
            "{} {}",
            scaled.q(),
            unit.q()
        );
        assert!((scaled.v() - unit.v()).amax() < 1e-11);
    }
    assert!((scaled.t() - 100.0 - unit.t()).abs() < 1e-11);
    unit.run_until(20.0).unwrap();
    scaled.run_until(120.0).unwrap();
    assert!(
        (scaled.q() - unit.q()).amax() < 1e-11,
        "{} {}",
        scaled.q(),
        unit.q()
    );
    let exact = orbit(0.9).exact(20.0).unwrap();
    assert!((unit.q() - vector![exact[0], exact[1]]).amax() < 1e-4);
}

/// Landing: the run's time is the end asked for, the trajectory's times increase, the steps are
/// short at the pericentre and long at the apocentre (by the ratio of the distances), and a run
/// that is already at its end takes no step.
#[test]
fn a_run_lands_on_its_end_and_adapts_its_steps() {
    let mut comet = comet(0.9, Composition::verlet(), 200);
    let trajectory = comet.trajectory_until(PI).unwrap();
    let t = trajectory.t();
    assert_eq!(*t.last().unwrap(), PI);
    assert!(t.windows(2).all(|w| w[1] > w[0]));
    let dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    // dt ≈ δs |q|: |q| is 0.1 at the pericentre, 1.9 at the apocentre (t = π).
    let ratio = dt[dt.len() - 2] / dt[0];
    assert!((ratio / 19.0 - 1.0).abs() < 0.05, "{ratio}");
    let steps = comet.steps();
    comet.run_until(PI).unwrap();
    assert_eq!(comet.steps(), steps);
    // Nor does a recorded one: the trajectory is the start alone.
    assert_eq!(comet.trajectory_until(PI).unwrap().t(), &[PI]);
    // The rate of time at the apocentre: 1/(T + c − E) = |q| there.
    assert!((comet.time_rate().unwrap() - 1.9).abs() < 1e-3);
}

/// Saving at given times does not change the run: it ends where `run_until` ends, bit for
/// bit, after as many steps; each saved state is on Kepler's orbit at its time, to the run's
/// accuracy; and bad save times are refused, changing nothing.
#[test]
fn saved_times_do_not_change_the_run() {
    let times: Vec<f64> = (1..=40).map(|i| 0.25 * i as f64).collect();
    let mut saved = comet(0.9, Composition::kahan_li_8(), 32);
    let trajectory = saved.trajectory_at(&times).unwrap();
    let mut plain = comet(0.9, Composition::kahan_li_8(), 32);
    plain.run_until(10.0).unwrap();
    assert_eq!(saved.sample(), plain.sample());
    assert_eq!(saved.steps(), plain.steps());
    assert_eq!(trajectory.t(), &times[..]);
    let mut worst = 0.0_f64;
    for (t, q) in trajectory.t().iter().zip(trajectory.q()) {
        let exact = orbit(0.9).exact(*t).unwrap();
        worst = worst.max((q - vector![exact[0], exact[1]]).amax());
    }
    println!("40 saved states, Kahan–Li 8 at 32 steps a revolution: {worst:.1e} from the orbit");
    assert!(worst < 1e-10, "{worst}");
    assert!(trajectory.max_energy_error() < 1e-13);
    let before = saved.sample();
    for bad in [vec![11.0, 10.5], vec![11.0, f64::NAN], vec![9.0, 12.0]] {
        assert!(matches!(
            saved.trajectory_at(&bad),
            Err(DiracError::InvalidRun(_))
        ));
    }
    assert_eq!(saved.sample(), before);
    assert!(saved.trajectory_at(&[]).unwrap().is_empty());
    // A time equal to now is saved without a step.
    assert_eq!(saved.trajectory_at(&[10.0]).unwrap().t(), &[10.0]);
    assert_eq!(saved.sample(), before);
}

/// Refusals, each leaving the state as it was.
#[test]
fn refusals() {
    let unsupported = |result: Result<TimeTransformed<_, 2>, DiracError>, what: &str| match result {
        Err(DiracError::Unsupported(message)) => {
            assert!(message.contains(what), "{message}");
        }
        other => panic!("{other:?}"),
    };
    unsupported(
        TimeTransformed::new(double_pendulum::SCENE, Composition::verlet(), 0.1),
        "not known to be separable",
    );
    for ds in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            TimeTransformed::new(kepler::SCENE, Composition::verlet(), ds),
            Err(DiracError::InvalidStep { .. })
        ));
    }
    let comet = TimeTransformed::new(kepler::SCENE, Composition::verlet(), 0.1).unwrap();
    assert!(matches!(
        comet.clone().with_offset(f64::NAN),
        Err(DiracError::NonFinite { .. })
    ));
    let mut idle = comet.clone();
    assert!(matches!(idle.step(), Err(DiracError::NotStarted)));
    assert!(matches!(idle.energy(), Err(DiracError::NotStarted)));
    assert!(matches!(idle.run_until(1.0), Err(DiracError::NotStarted)));
    // An oscillator's potential ½ k x² is not negative: c = 0 is refused at the start, c = 1
    // taken; the same start with the offset raised above V is accepted.
    let mut oscillator =
        TimeTransformed::new(oscillator::SCENE, Composition::verlet(), 0.1).unwrap();
    let refused = oscillator.start_from_velocity(vector![0.5], vector![0.0]);
    assert!(
        matches!(&refused, Err(DiracError::Unsupported(m)) if m.contains("with_offset")),
        "{refused:?}"
    );
    assert!(oscillator.sample().is_none());
    let mut oscillator = oscillator.with_offset(1.0).unwrap();
    oscillator
        .start_from_velocity(vector![0.5], vector![0.0])
        .unwrap();
    oscillator.run_until(2.0).unwrap();
    assert!((oscillator.q()[0] - oscillator::exact(2.0)).abs() < 1e-3);
    // Lowering the offset below the potential during a run is refused.
    assert!(oscillator.clone().with_offset(0.0).is_err());
    // A start that is not finite, an end before now or not finite.
    let mut comet = comet.clone();
    assert!(matches!(
        comet.start_from_velocity(vector![f64::NAN, 1.0], vector![0.0, 1.0]),
        Err(DiracError::NonFinite { .. })
    ));
    comet
        .start_from_velocity(vector![1.0, 0.0], vector![0.0, 1.0])
        .unwrap();
    comet.run_until(1.0).unwrap();
    let before = comet.sample().unwrap();
    for end in [0.5, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            comet.run_until(end),
            Err(DiracError::InvalidRun(_))
        ));
    }
    assert_eq!(comet.sample(), Some(before));
    // A step that carries the oscillator (c = 0.6, E = 0.5: c − V ≥ 0.1 on the motion) past
    // where c − V > 0 fails and changes nothing.
    let mut oscillator = TimeTransformed::new(oscillator::SCENE, Composition::verlet(), 2.0)
        .unwrap()
        .with_offset(0.6)
        .unwrap();
    oscillator
        .start_from_velocity(vector![0.0], vector![1.0])
        .unwrap();
    let before = oscillator.sample().unwrap();
    let failed = oscillator.step();
    assert!(
        matches!(&failed, Err(DiracError::OutsideDomain { step: 0, why }) if why.contains("c − V(q)")),
        "{failed:?}"
    );
    assert_eq!(oscillator.sample(), Some(before));
    assert_eq!(oscillator.steps(), 0);
}
