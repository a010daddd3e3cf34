//! The peers of the speed/accuracy study against dirac and against closed forms: the hand-derived
//! first-order forms of the seven scenes and dirac's discrete Lagrangian are independent
//! derivations of the same dynamics, so agreement at tight tolerance checks both.

use dirac::prelude::*;
use scenes::first_order::FirstOrder;
use scenes::peers::{self, Peer};
use scenes::study::{self, Scene, Visitor};
use scenes::{circuit, kepler, knife_edge, pendulum};

const HORIZON: f64 = 2.0;

/// dirac's `galerkin(3)` at half the scene's smallest step against Dop853 at 1e-13, and every
/// peer that takes the scene against the same reference.
struct AgreeWithDirac;

impl Visitor for AgreeWithDirac {
    fn visit<S, F, G, const Y: usize, const Z: usize, const N: usize>(
        &mut self,
        scene: Scene<S, F, G, Y, Z, N>,
    ) -> Result<(), String>
    where
        S: DiracSystem<N> + Clone,
        F: FirstOrder<Y, N>,
        G: FirstOrder<Z, N>,
    {
        let (reference, estimate) = peers::reference(&scene.ode, HORIZON)?;
        assert!(
            estimate < 1e-10,
            "{}: reference estimate {estimate:e}",
            scene.name
        );
        let h = scene.steps.iter().cloned().fold(f64::INFINITY, f64::min) / 2.0;
        let start = scene.ode.sample(0.0, &scene.ode.initial());
        let mut stepper = Stepper::new(scene.system, Quadrature::galerkin(3).unwrap(), h)
            .map_err(|e| e.to_string())?;
        stepper
            .start_from_velocity(start.q, start.v)
            .map_err(|e| e.to_string())?;
        // The form's energy is the model's.
        let (form, model) = (
            scene.ode.energy(&scene.ode.initial()),
            stepper.energy().map_err(|e| e.to_string())?,
        );
        assert!(
            (form - model).abs() <= 1e-12 * model.abs().max(1.0),
            "{}: energy {form} in the form, {model} in the model",
            scene.name
        );
        stepper.run_until(HORIZON).map_err(|e| e.to_string())?;
        let end = stepper.interpolate(HORIZON).map_err(|e| e.to_string())?;
        let gap = peers::distance(&end, &reference);
        println!(
            "{}: dirac galerkin(3) h = {h} vs Dop853: {gap:.1e}",
            scene.name
        );
        assert!(
            gap < 1e-8,
            "{}: dirac and Dop853 differ by {gap:e}",
            scene.name
        );
        for peer in [Peer::Dop853, Peer::Dopri5] {
            let run = peers::measure(peer, &scene.ode, HORIZON, 1e-10, &reference, 1)?;
            println!(
                "  {} at 1e-10: error {:.1e}, |ΔE| {:.1e}",
                peer.name(),
                run.error,
                run.energy_error
            );
            assert!(
                run.error < 1e-7,
                "{} {}: {:e}",
                scene.name,
                peer.name(),
                run.error
            );
            let tight = peers::measure(peer, &scene.ode, HORIZON, 1e-12, &reference, 1)?;
            assert!(
                tight.energy_error < 1e-8,
                "{} {} at 1e-12: energy error {:e}",
                scene.name,
                peer.name(),
                tight.energy_error
            );
        }
        // BDF where this build has it (`--features scenes/bdf`); its refusal otherwise is
        // checked by `the_first_order_forms_meet_the_closed_forms`.
        if let Some(dae) = scene.dae.as_ref().filter(|_| Peer::Bdf.is_built()) {
            let run = peers::measure(Peer::Bdf, dae, HORIZON, 1e-10, &reference, 1)?;
            println!(
                "  BDF at 1e-10: error {:.1e}, violation {:.1e}",
                run.error, run.violation
            );
            assert!(run.error < 1e-6, "{} BDF: {:e}", scene.name, run.error);
            assert!(
                run.violation < 1e-6,
                "{} BDF violation: {:e}",
                scene.name,
                run.violation
            );
        }
        Ok(())
    }
}

#[test]
fn every_scene_agrees_with_dirac_and_the_peers_with_each_other() {
    study::visit_all(&mut AgreeWithDirac).unwrap();
}

/// The index-1 DAE forms that BDF integrates, checked without BDF (so in every build) along the
/// ODE forms' closed-form solutions: their algebraic rows vanish there, their differential rows
/// are the ODE's right-hand sides, their states are the same samples of the model, and they
/// start where the ODE forms start.
#[test]
fn the_dae_forms_are_the_ode_forms_on_their_constraints() {
    use scenes::first_order::{KnifeEdgeDae, KnifeEdgeOde, LcDae, LcOde};
    /// `to_dae` maps an ODE state to the DAE's (and an ODE rate to the DAE's differential rates).
    fn compare<F, G, const Y: usize, const Z: usize, const N: usize>(
        ode: &F,
        dae: &G,
        to_dae: impl Fn(&[f64; Y]) -> [f64; Z],
        name: &str,
    ) where
        F: FirstOrder<Y, N>,
        G: FirstOrder<Z, N>,
    {
        assert_eq!(
            dae.initial(),
            to_dae(&ode.initial()),
            "{name}: initial states"
        );
        for t in [0.0, 0.7, 3.1, 10.0] {
            let y = ode.exact(t).expect("a closed form");
            let z = to_dae(&y);
            let (expected, rate) = (to_dae(&ode.rhs(&y)), dae.rhs(&z));
            for row in 0..Z {
                let want = if row < G::DIFFERENTIAL {
                    expected[row]
                } else {
                    0.0
                };
                assert!(
                    (rate[row] - want).abs() < 1e-12,
                    "{name} at t = {t}, row {row}: {} against {want}",
                    rate[row]
                );
            }
            let gap = peers::distance(&dae.sample(t, &z), &ode.sample(t, &y));
            assert!(gap < 1e-15, "{name} at t = {t}: samples {gap:e} apart");
        }
    }
    // (q_l, q_c1, q_c2, q_c3, i) in the ODE; (q_l, q_c2, i | q_c1, q_c3) in the DAE.
    let lc = LcOde {
        circuit: circuit::LC,
        q0: circuit::q0().into(),
    };
    let to_dae = |y: &[f64; 5]| [y[0], y[2], y[4], y[1], y[3]];
    compare(&lc, &LcDae(lc), to_dae, "LC circuit");
    // (x, y, φ, ẋ, ẏ, φ̇) in the ODE; the DAE appends λ/m, the value its algebraic row holds.
    let knife = KnifeEdgeOde {
        knife: knife_edge::SCENE,
        omega: knife_edge::OMEGA,
    };
    let dae = KnifeEdgeDae(knife);
    let to_dae = |y: &[f64; 6]| {
        let mut z = [y[0], y[1], y[2], y[3], y[4], y[5], 0.0];
        z[6] = -dae.rhs(&z)[6];
        z
    };
    compare(&knife, &dae, to_dae, "knife edge");
}

/// The forms against the scenes' closed forms, with no dirac involved.
#[test]
fn the_first_order_forms_meet_the_closed_forms() {
    use scenes::first_order::{KeplerOde, KnifeEdgeOde, LcDae, LcOde, PendulumOde};
    let pendulum = PendulumOde {
        pendulum: pendulum::SCENE,
        theta0: 1.0,
    };
    let end = peers::solution(&pendulum, 5.0, 1e-13).unwrap();
    assert!((end.q[0] - pendulum::Q5).abs() < 1e-11 && (end.p[0] - pendulum::P5).abs() < 1e-11);

    let lc = LcOde {
        circuit: circuit::LC,
        q0: circuit::q0().into(),
    };
    let end = peers::solution(&lc, 10.0, 1e-13).unwrap();
    assert!(
        (end.q[2] - circuit::lc_q_c2(10.0)).abs() < 1e-11,
        "{}",
        end.q[2]
    );
    let dae = LcDae(lc);
    let reference = peers::solution(&lc, 10.0, 1e-13).unwrap();
    // BDF on the DAE where this build has it; otherwise refused by name, never left out silently.
    match peers::measure(Peer::Bdf, &dae, 10.0, 1e-10, &reference, 1) {
        Ok(run) => {
            assert!(Peer::Bdf.is_built());
            assert!(run.error < 1e-6, "BDF on the LC DAE: {:e}", run.error);
        }
        Err(why) => {
            assert!(!Peer::Bdf.is_built(), "{why}");
            assert!(why.contains("`bdf` feature"), "{why}");
        }
    }

    let knife = KnifeEdgeOde {
        knife: knife_edge::SCENE,
        omega: knife_edge::OMEGA,
    };
    let end = peers::solution(&knife, 10.0, 1e-13).unwrap();
    assert!(
        (end.q - knife_edge::exact(10.0)).amax() < 1e-10,
        "{}",
        end.q
    );

    // The closed forms the study measures against, against Dop853 at 1e-13.
    fn agree<F: FirstOrder<Y, N>, const Y: usize, const N: usize>(ode: &F, name: &str) {
        for t in [0.0, 3.7, 10.0] {
            let exact = ode.sample(t, &ode.exact(t).unwrap());
            let gap = if t == 0.0 {
                peers::distance(&exact, &ode.sample(0.0, &ode.initial()))
            } else {
                peers::distance(&exact, &peers::solution(ode, t, 1e-13).unwrap())
            };
            assert!(gap < 1e-10, "{name} at t = {t}: {gap:e}");
        }
    }
    // The violation vanishes on the closed forms and sees a state off the constraint.
    for t in [1.0, 10.0] {
        let on = knife.exact(t).unwrap();
        assert!(knife.violation(&on) < 1e-12);
        let mut off = on;
        off[4] += 1e-3;
        assert!(knife.violation(&off) > 1e-4);
        let on = lc.exact(t).unwrap();
        assert!(lc.violation(&on) < 1e-12);
        let mut off = on;
        off[1] += 1e-3;
        assert!(lc.violation(&off) > 1e-4);
    }
    agree(&knife, "knife edge");
    agree(&lc, "LC circuit");
    agree(
        &KeplerOde {
            kepler: kepler::SCENE,
            e: 0.5,
        },
        "Kepler e = 0.5",
    );
    agree(
        &KeplerOde {
            kepler: kepler::SCENE,
            e: 0.9,
        },
        "Kepler e = 0.9",
    );
}

#[test]
fn explicit_peers_refuse_algebraic_rows() {
    use scenes::first_order::{LcDae, LcOde};
    let dae = LcDae(LcOde {
        circuit: circuit::LC,
        q0: circuit::q0().into(),
    });
    let reference = peers::solution(&dae.0, 1.0, 1e-13).unwrap();
    let refused = peers::measure(Peer::Dop853, &dae, 1.0, 1e-8, &reference, 1).unwrap_err();
    assert!(refused.contains("algebraic"), "{refused}");
}
