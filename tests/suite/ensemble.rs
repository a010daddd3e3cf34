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
