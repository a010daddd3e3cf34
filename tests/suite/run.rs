//! Runs over a time span: start time, `run_until`, saved times, dense output and its orders,
//! events against closed forms, observers, failures that keep what was made, trajectories with
//! velocities, metadata and columns, and serde.

use crate::support;

use std::f64::consts::PI;
use std::ops::ControlFlow;

use dirac::prelude::*;
use scenes::pendulum;
use support::assert_order;

/// `q̈ = −q + a cos(ω t)`: a forced oscillator whose solution depends on the absolute time.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces(a * cos(omega * t) * dx),
)]
#[derive(Debug, Clone, Copy)]
struct Forced {
    a: f64,
    omega: f64,
}

const FORCED: Forced = Forced { a: 0.5, omega: 2.0 };

/// The forced oscillator's solution with `x(0) = 1`, `ẋ(0) = 0`: position and velocity.
fn forced_exact(t: f64) -> (f64, f64) {
    let (a, w) = (FORCED.a, FORCED.omega);
    let c = a / (1.0 - w * w);
    let x = (1.0 - c) * t.cos() + c * (w * t).cos();
    let v = -(1.0 - c) * t.sin() - c * w * (w * t).sin();
    (x, v)
}

/// Unit oscillator, `q = cos t`.
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x)]
#[derive(Debug, Clone, Copy)]
struct Oscillator;

/// The pendulum's period at amplitude `q0` (unit frequency): `4 K(sin(q0/2))`, with the complete
/// elliptic integral by the arithmetic–geometric mean.
fn pendulum_period(q0: f64) -> f64 {
    let k = (q0 / 2.0).sin();
    let (mut a, mut b) = (1.0, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        (a, b) = ((a + b) / 2.0, (a * b).sqrt());
    }
    4.0 * PI / (2.0 * a)
}

#[test]
fn a_run_starts_at_its_start_time_and_ends_at_t_end() {
    let (t0, h) = (2.0, 0.01);
    let (x0, v0) = forced_exact(t0);
    let mut stepper = Stepper::new(FORCED, Quadrature::galerkin(2).unwrap(), h)
        .unwrap()
        .with_start_time(t0);
    stepper
        .start_from_velocity(vector![x0], vector![v0])
        .unwrap();
    let trajectory = stepper.run_until(5.0).unwrap();
    assert_eq!(trajectory.t()[0], t0);
    assert_eq!(stepper.steps(), 300);
    assert!((stepper.t() - 5.0).abs() < 1e-12);
    // The force is evaluated at the absolute time: started as if at 0, the answer is off by
    // O(1); at t0 it is off by the method's error.
    let (x, v) = forced_exact(5.0);
    let error = (stepper.q()[0] - x)
        .abs()
        .max((stepper.v().unwrap()[0] - v).abs());
    assert!(error < 1e-8, "error {error:e}");
    assert_eq!(trajectory.metadata().unwrap().t0, t0);
    // A span that ends before the current time is refused, and nothing moves.
    assert!(matches!(
        stepper.run_until(4.0),
        Err(interrupted) if matches!(interrupted.error, DiracError::InvalidRun(_))
    ));
    assert_eq!(stepper.steps(), 300);
    // t_end off the grid: the fewest steps that reach it.
    stepper.run_until(5.015).unwrap();
    assert_eq!(stepper.steps(), 302);
}

#[test]
fn saved_times_are_the_dense_output_and_equal_the_states_on_the_grid() {
    let h = 0.1;
    let mut stepper = Stepper::new(pendulum::SCENE, Quadrature::galerkin(2).unwrap(), h).unwrap();
    stepper
        .start_from_momentum(vector![1.0], vector![0.0])
        .unwrap();
    let mut other = stepper.clone();
    let every_step = stepper.run_until(2.0).unwrap();
    let times = [0.0, 0.05, 0.5, 0.73, 1.0, 2.0];
    let saved = other
        .solve(Run::until(2.0).saveat(times))
        .unwrap()
        .trajectory;
    assert_eq!(saved.t(), &times);
    for (k, &t) in times.iter().enumerate() {
        let on_grid = (t / h).round();
        if ((t / h) - on_grid).abs() < 1e-9 {
            let node = on_grid as usize;
            let d = (saved.q()[k] - every_step.q()[node]).amax()
                + (saved.v()[k] - every_step.v()[node]).amax()
                + (saved.p()[k] - every_step.p()[node]).amax()
                + (saved.energy()[k] - every_step.energy()[node]).abs();
            assert!(d < 1e-13, "t = {t}: dense output off the state by {d:e}");
        }
    }
    // Save times outside the span or out of order are refused before any step.
    let before = other.steps();
    for bad in [vec![1.0, 0.5], vec![2.5], vec![f64::NAN]] {
        let refused = other.solve(Run::until(2.2).saveat(bad)).unwrap_err();
        assert!(
            matches!(refused.error, DiracError::InvalidRun(_)),
            "{}",
            refused.error
        );
    }
    assert_eq!(other.steps(), before);
}

/// The largest error of the dense output of an oscillator at 7 points inside every step over
/// `[0, 2]`: positions, velocities, momenta.
fn dense_errors(quadrature: &Quadrature, h: f64) -> [f64; 3] {
    let mut stepper = Stepper::new(Oscillator, quadrature.clone(), h).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    let steps = (2.0 / h).round() as u64;
    let times: Vec<f64> = (0..steps)
        .flat_map(|k| (1..8).map(move |i| (k as f64 + i as f64 / 8.0) * h))
        .collect();
    let saved = stepper
        .solve(Run::steps(steps).saveat(times))
        .unwrap()
        .trajectory;
    let mut errors = [0.0_f64; 3];
    for k in 0..saved.len() {
        let t = saved.t()[k];
        errors[0] = errors[0].max((saved.q()[k][0] - t.cos()).abs());
        errors[1] = errors[1].max((saved.v()[k][0] + t.sin()).abs());
        errors[2] = errors[2].max((saved.p()[k][0] + t.sin()).abs());
    }
    errors
}

#[test]
fn dense_output_converges_at_its_measured_order() {
    let hs = [0.1, 0.05, 0.025, 0.0125];
    for (quadrature, orders) in [
        (Quadrature::midpoint(), [2.0, 2.0, 2.0]),
        (Quadrature::galerkin(2).unwrap(), [4.0, 3.0, 3.0]),
        (Quadrature::galerkin(3).unwrap(), [4.0, 3.0, 3.0]),
    ] {
        let errors: Vec<[f64; 3]> = hs.iter().map(|&h| dense_errors(&quadrature, h)).collect();
        for (i, what) in ["q", "v", "p"].iter().enumerate() {
            let e: Vec<f64> = errors.iter().map(|e| e[i]).collect();
            assert_order(
                &format!("{} dense {what}", quadrature.name()),
                &hs,
                &e,
                orders[i],
            );
        }
    }
}

/// The period of the pendulum from the first two upward crossings of the vertical, against
/// `4 K(sin(q0/2))`, converging at the order of the dense output.
#[test]
fn events_locate_the_pendulum_period() {
    let q0 = 1.0;
    let period = pendulum_period(q0);
    let hs = [0.2, 0.1, 0.05, 0.025];
    for (quadrature, order) in [
        (Quadrature::midpoint(), 2.0),
        (Quadrature::galerkin(2).unwrap(), 4.0),
    ] {
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let mut stepper = Stepper::new(pendulum::SCENE, quadrature.clone(), h).unwrap();
                stepper
                    .start_from_momentum(vector![q0], vector![0.0])
                    .unwrap();
                let vertical = Event::new(
                    "vertical",
                    |_t, q: &SVector<f64, 1>, _v: &SVector<f64, 1>| q[0],
                )
                .rising();
                let solution = stepper
                    .solve(Run::until(3.0 * period).event(vertical))
                    .unwrap();
                let crossings: Vec<&Crossing<1>> = solution.events.iter().collect();
                assert_eq!(crossings.len(), 3, "h = {h}");
                for crossing in &crossings {
                    assert_eq!(crossing.direction, Direction::Rising);
                    // At the crossing the event function vanishes to round-off.
                    assert!(crossing.sample.q[0].abs() < 1e-14);
                }
                (crossings[1].sample.t - crossings[0].sample.t - period).abs()
            })
            .collect();
        assert_order(
            &format!("{} period", quadrature.name()),
            &hs,
            &errors,
            order,
        );
    }
}

/// A terminal event ends the run in the step where it is located; the crossing is at the event's
/// own time and the stepper can go on from the end of that step.
#[test]
fn a_terminal_event_ends_the_run_and_the_stepper_goes_on() {
    let h = 0.1;
    let mut stepper = Stepper::new(Oscillator, Quadrature::galerkin(3).unwrap(), h).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    let half = Event::new(
        "x = 1/2",
        |_t, q: &SVector<f64, 1>, _v: &SVector<f64, 1>| q[0] - 0.5,
    )
    .terminal();
    let solution = stepper.solve(Run::until(10.0).event(half)).unwrap();
    assert_eq!(solution.status, Status::Event(0));
    let crossing = &solution.events[0];
    assert_eq!(crossing.direction, Direction::Falling);
    // cos t = 1/2 at t = π/3, to the dense output's accuracy at this step (2.6e-8 in q).
    assert!(
        (crossing.sample.t - PI / 3.0).abs() < 1e-7,
        "{}",
        crossing.sample.t
    );
    assert!((crossing.sample.v[0] + (PI / 3.0).sin()).abs() < 1e-6);
    assert!((crossing.sample.q[0] - 0.5).abs() < 1e-15);
    assert!(stepper.t() >= crossing.sample.t && stepper.t() < crossing.sample.t + h);
    assert_eq!(solution.trajectory.t().last(), Some(&stepper.t()));
    stepper.run_until(2.0).unwrap();
}

/// The observer sees every step and can stop the run; the trajectory ends at the stepper's state.
#[test]
fn an_observer_sees_every_step_and_can_stop_the_run() {
    let mut stepper = Stepper::new(pendulum::SCENE, Quadrature::midpoint(), 0.01).unwrap();
    stepper
        .start_from_momentum(vector![1.0], vector![0.0])
        .unwrap();
    let mut seen = Vec::new();
    let run = Run::until(10.0).every(7).observe(|progress| {
        seen.push((progress.steps, progress.state.t()));
        assert_eq!(progress.total, 1000);
        if progress.steps == 250 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    let solution = stepper.solve(run).unwrap();
    assert_eq!(solution.status, Status::Stopped);
    assert_eq!(seen.len(), 250);
    assert!(
        seen.iter()
            .enumerate()
            .all(|(k, &(steps, _))| steps == k as u64 + 1)
    );
    assert_eq!(stepper.steps(), 250);
    let trajectory = &solution.trajectory;
    // Every 7th step, then the last state (250 is not a multiple of 7).
    assert_eq!(trajectory.len(), 1 + 250 / 7 + 1);
    assert_eq!(trajectory.t().last(), Some(&stepper.t()));
    assert_eq!(trajectory.q().last(), Some(&stepper.q()));
    assert_eq!(*trajectory.v().last().unwrap(), stepper.v().unwrap());
}

/// `L = v²/2 − √(1 − q)`: the potential ends at `q = 1`, where a step fails.
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2) - sqrt(1.0 - x))]
#[derive(Debug, Clone, Copy)]
struct Edge;

/// A failing step keeps the samples and the events located before it.
#[test]
fn a_failed_run_keeps_its_samples_and_events() {
    let mut stepper = Stepper::new(Edge, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_velocity(vector![0.0], vector![1.0])
        .unwrap();
    let half = Event::new(
        "x = 1/2",
        |_t, q: &SVector<f64, 1>, _v: &SVector<f64, 1>| q[0] - 0.5,
    );
    let interrupted = stepper.solve(Run::until(100.0).event(half)).unwrap_err();
    assert_eq!(interrupted.trajectory.len() as u64, stepper.steps() + 1);
    assert_eq!(interrupted.events.len(), 1);
    assert!(interrupted.events[0].sample.t < stepper.t());
    assert!(stepper.q()[0] < 1.0);
}

/// Trajectories carry velocities (the stepper's exact ones), the run's metadata and columns by
/// name, and the CSV has one column per name.
#[test]
fn trajectories_have_velocities_metadata_and_named_columns() {
    let mut stepper = Stepper::new(scenes::knife_edge::SCENE, Quadrature::midpoint(), 0.05)
        .unwrap()
        .with_newton_options(NewtonOptions {
            residual_tolerance: 1e-13,
            ..NewtonOptions::default()
        })
        .unwrap();
    stepper
        .start_from_velocity(
            SVector::zeros(),
            vector![0.0, 0.0, scenes::knife_edge::OMEGA],
        )
        .unwrap();
    let trajectory = stepper.run_until(1.0).unwrap();
    assert_eq!(*trajectory.v().last().unwrap(), stepper.v().unwrap());
    let metadata = trajectory.metadata().unwrap();
    assert_eq!(metadata.model, "KnifeEdge");
    assert_eq!(metadata.quadrature, "midpoint");
    assert_eq!(
        (metadata.h, metadata.t0, metadata.residual_tolerance),
        (0.05, 0.0, 1e-13)
    );
    let names = trajectory.column_names();
    assert_eq!(names[0], "t");
    assert!(names.contains(&"constraint_violation".to_string()));
    for name in trajectory.names() {
        let v = trajectory.column(&format!("v_{name}")).unwrap();
        let i = trajectory.names().iter().position(|n| n == name).unwrap();
        assert!(v.iter().zip(trajectory.v()).all(|(a, b)| *a == b[i]));
    }
    assert_eq!(trajectory.column("energy").unwrap(), trajectory.energy());
    assert_eq!(trajectory.column("no such column"), None);
    assert_eq!(support::csv_header(&trajectory), names.join(","));
}

/// `serde` round trips, and a quadrature read back is checked like one built by hand.
#[test]
fn serde_round_trips() {
    let mut stepper =
        Stepper::new(scenes::circuit::LC, Quadrature::galerkin(2).unwrap(), 0.01).unwrap();
    stepper
        .start_from_velocity(scenes::circuit::q0(), SVector::zeros())
        .unwrap();
    let trajectory = stepper.run(20).unwrap();
    let json = serde_json::to_string(&trajectory).unwrap();
    let back: Trajectory<4> = serde_json::from_str(&json).unwrap();
    assert_eq!(back, trajectory);
    for quadrature in scenes::quadratures() {
        let json = serde_json::to_string(&quadrature).unwrap();
        assert_eq!(
            serde_json::from_str::<Quadrature>(&json).unwrap(),
            quadrature
        );
    }
    let invalid = r#"{"degree":3,"rule":{"GaussLegendre":2}}"#;
    let refused = serde_json::from_str::<Quadrature>(invalid).unwrap_err();
    assert!(
        refused
            .to_string()
            .contains("degree 3 needs at least 3 nodes"),
        "{refused}"
    );
    let options = NewtonOptions {
        max_iterations: 7,
        ..NewtonOptions::default()
    };
    let json = serde_json::to_string(&options).unwrap();
    assert_eq!(
        serde_json::from_str::<NewtonOptions>(&json).unwrap(),
        options
    );
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        let json = serde_json::to_string(&point).unwrap();
        assert_eq!(
            serde_json::from_str::<ConstraintPoint>(&json).unwrap(),
            point
        );
    }
}

/// A recorded sample's energy is the model's `⟨∂L/∂v, v⟩ − L` at the sample's position and
/// velocity, bit for bit, whether the velocity solve brought it (the chord step of closed-form
/// derivatives, unconstrained models) or the stepper evaluated it after (constrained ones).
#[test]
fn recorded_energies_are_the_energy_at_the_recorded_state() {
    use scenes::{double_pendulum, knife_edge};
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let mut stepper = double_pendulum::stepper(quadrature, 0.01).unwrap();
        let trajectory = stepper.run(300).unwrap();
        for k in 0..trajectory.len() {
            let (q, v) = (&trajectory.q()[k], &trajectory.v()[k]);
            let energy = dirac::legendre::energy(&double_pendulum::SCENE, q, v);
            assert_eq!(energy, trajectory.energy()[k], "sample {k}");
        }
    }
    let mut stepper = knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).unwrap();
    let trajectory = stepper.run(300).unwrap();
    for k in 0..trajectory.len() {
        let (q, v) = (&trajectory.q()[k], &trajectory.v()[k]);
        let energy = dirac::legendre::energy(&knife_edge::SCENE, q, v);
        assert_eq!(energy, trajectory.energy()[k], "sample {k}");
    }
}
