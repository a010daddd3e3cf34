//! Ensembles across threads: a stepper is `Clone + Send`, and members run in parallel give the
//! numbers each member gives alone, bit for bit, whatever the thread count.

use dirac::prelude::*;
use scenes::double_pendulum::SCENE;
use scenes::ensemble;

#[test]
fn steppers_cross_threads() {
    fn send_and_clone<T: Send + Clone>() {}
    send_and_clone::<Stepper<scenes::double_pendulum::DoublePendulum, 2>>();
}

#[test]
fn parallel_members_equal_the_members_run_alone() {
    let (h, horizon) = (0.01, 40.0);
    let members = ensemble::grid(3);
    let quadrature = Quadrature::midpoint();
    let template = Stepper::new(SCENE, quadrature.clone(), h).unwrap();
    let alone: Vec<f64> = members
        .iter()
        .map(|&angles| ensemble::divergence_time(&template, angles, horizon).unwrap())
        .collect();
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let together = pool
            .install(|| ensemble::divergence_times(quadrature.clone(), h, &members, horizon))
            .unwrap();
        assert_eq!(together, alone, "{threads} threads");
    }
    // Some members are chaotic: their perturbation grows past 1e-3 within T = 40.
    assert!(alone.iter().any(|&t| t < horizon), "{alone:?}");
}

/// An ensemble of controlled runs: the Furuta pendulum balanced from a spread of tilts, each
/// member's feedback inside its own run on its own thread, gives each member's numbers alone and
/// its own energy balance.
#[test]
fn controlled_members_in_parallel_equal_the_members_run_alone() {
    use rayon::prelude::*;
    let h = 0.005;
    let tilts = [0.05, 0.1, 0.15, 0.2];
    let member = |tilt: f64| {
        let (_, solution) =
            scenes::furuta::closed_loop(h, tilt, scenes::furuta::TAU_MAX, 400, 100).unwrap();
        let balance = solution.trajectory.energy_balance().unwrap();
        (solution.trajectory.q().last().copied().unwrap(), balance)
    };
    let alone: Vec<_> = tilts.iter().map(|&tilt| member(tilt)).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let together: Vec<_> = pool.install(|| tilts.par_iter().map(|&tilt| member(tilt)).collect());
    assert_eq!(together, alone);
    // The motor did work on every member, and each books it.
    for (_, balance) in &alone {
        assert!(balance.work.abs() > 1e-4, "{balance}");
        assert!(balance.max_defect < 1e-3 * balance.work.abs(), "{balance}");
    }
}
