//! Linear models pay once: the attribute says which Lagrangians are quadratic in `(q, v)` and
//! which forces are affine with constant coefficients. A stepper then keeps one factorised
//! Jacobian for a run of linear step equations (the LC circuit, a driven RLC ladder, a driven
//! damped oscillator) and steps as Newton's method does, to round-off; a wrong claim costs
//! iterations, not accuracy. Where nothing changes the step from one step to the next (no
//! forces), a stepper `with_step_map` reads the step map off the step and steps by it, as
//! Newton's method to round-off, checking the claim it rests on at every reading.

use dirac::StepEquations;
use dirac::prelude::*;
use scenes::circuit::LcCircuit;
use scenes::{
    cartesian_pendulum, circuit, components, knife_edge, oscillator, pendulum, rlc_ladder,
};

/// What the attribute declared: whether `S` is quadratic.
fn quadratic<S: DiracSystem<N>, const N: usize>() -> bool {
    S::QUADRATIC
}

/// What the attribute declared: whether the forces of `S` are affine with constant coefficients.
fn forces_affine<S: DiracSystem<N>, const N: usize>() -> bool {
    S::FORCES_AFFINE
}

#[dirac_system(coordinates(x), lagrangian = 0.5 * m * dot(x).powi(2) - c * abs(x))]
struct Kinked {
    m: f64,
    c: f64,
}

#[dirac_system(coordinates(x, y), lagrangian = 0.5 * dot(x) * dot(y) + 2.0 * x * y - x + 3.0)]
struct Mixed;

/// A damped oscillator: quadratic, but forced.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces(-c * dot(x) * dx),
)]
struct Damped {
    c: f64,
}

/// A damped oscillator driven by an input and a sinusoid: affine forces.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces((u + sin(2.0 * t) - c * dot(x) - k * x) * dx),
    inputs(u),
)]
#[derive(Clone, Copy)]
struct Driven {
    c: f64,
    k: f64,
}

/// Two coordinates of one array, a damper between them and a source scaled by a parameter.
#[dirac_system(
    coordinates(x[2]),
    lagrangian = 0.5 * (dot(x[0]).powi(2) + dot(x[1]).powi(2)) - 0.5 * (x[0] - x[1]).powi(2),
    forces(-c * (dot(x[0]) - dot(x[1])) * (dx[0] - dx[1]) + g * u * dx[0]),
    inputs(u),
)]
struct Pair {
    c: f64,
    g: f64,
}

/// Forces whose derivatives move with the state, an input or the time.
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), forces(-c * dot(x).powi(3) * dx))]
struct Cubic {
    c: f64,
}
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), forces(u * dot(x) * dx), inputs(u))]
struct Gained;
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), forces(-t * x * dx))]
struct Ageing;
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), forces(-c * abs(dot(x)) * dx))]
#[derive(Clone, Copy)]
struct Friction {
    c: f64,
}
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), forces(-x * dot(x) * dx))]
struct VanDerPol;
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), forces(-sin(x) * dx))]
#[derive(Clone, Copy)]
struct Swinging;
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), forces(-x / t * dx))]
struct Relaxing;
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2), forces(-x.powi(2) * dx))]
struct Stiffening;

/// A model of subsystems with one component whose forces are not affine.
#[dirac_system(subsystems(r, f), junctions(series = r.dq - f.dx))]
struct Rubbing {
    r: components::Resistor,
    f: Friction,
}

#[test]
fn the_attribute_says_which_forces_are_affine() {
    assert!(forces_affine::<Damped, 1>());
    assert!(forces_affine::<Driven, 1>());
    assert!(forces_affine::<components::Resistor, 1>());
    assert!(forces_affine::<components::DcMotor, 2>());
    assert!(forces_affine::<Pair, 2>());
    assert!(!forces_affine::<Cubic, 1>());
    assert!(!forces_affine::<Gained, 1>());
    assert!(!forces_affine::<Ageing, 1>());
    assert!(!forces_affine::<VanDerPol, 1>());
    assert!(!forces_affine::<Swinging, 1>());
    assert!(!forces_affine::<Relaxing, 1>());
    assert!(!forces_affine::<Stiffening, 1>());
    // c |v| is linear on each side of 0, with a slope that jumps.
    assert!(!forces_affine::<Friction, 1>());
    assert!(!forces_affine::<Rubbing, 2>());
    // A model of subsystems sums its components' Lagrangians and forces.
    assert!(quadratic::<rlc_ladder::RlcLadder, 10>());
    assert!(forces_affine::<rlc_ladder::RlcLadder, 10>());
}

/// Whether a model is quadratic, and its forces affine, read from a value.
fn declared<S: DiracSystem<N>, const N: usize>(_: &S) -> (bool, bool) {
    (S::QUADRATIC, S::FORCES_AFFINE)
}

#[test]
fn interconnections_and_repeated_components_are_linear_where_every_component_is() {
    use dirac::interconnection::{Interconnection, Junction};
    let series = |a: &str, b: &str| [Junction::new("series").flow(a, 1.0).flow(b, -1.0)];
    let rl = Interconnection::new(
        ("l", components::Inductor { l: 1.0 }),
        ("r", components::Resistor { r: 0.5 }),
        series("l.q", "r.q"),
    )
    .unwrap();
    assert_eq!(declared::<_, 2>(&rl), (true, true));
    let rubbing = Interconnection::new(
        ("r", components::Resistor { r: 0.5 }),
        ("f", Friction { c: 0.1 }),
        series("r.q", "f.x"),
    )
    .unwrap();
    assert_eq!(declared::<_, 2>(&rubbing), (true, false));
    let swinging = Interconnection::new(
        ("l", components::Inductor { l: 1.0 }),
        (
            "arm",
            components::Arm {
                inertia: 1.0,
                mgd: 1.0,
            },
        ),
        series("l.q", "arm.phi"),
    )
    .unwrap();
    assert_eq!(declared::<_, 2>(&swinging), (false, true));
    let free = Junction::new("shaft")
        .flow("motor[0].theta", 1.0)
        .flow("motor[1].theta", -1.0);
    let motors = Repeated::<components::DcMotor, 2, 2, 4, 1>::new(
        "motor",
        [scenes::motor::MOTOR; 2],
        [free],
    )
    .unwrap();
    assert_eq!(declared::<_, 4>(&motors), (true, true));
    let swings = Repeated::<Swinging, 2, 1, 2, 0>::new("s", [Swinging, Swinging], []).unwrap();
    assert_eq!(declared::<_, 2>(&swings), (true, false));
}

#[test]
fn the_attribute_says_which_lagrangians_are_quadratic() {
    assert!(quadratic::<circuit::LcCircuit, 4>());
    assert!(quadratic::<oscillator::Oscillator, 1>());
    assert!(quadratic::<Mixed, 2>());
    assert!(!quadratic::<pendulum::Pendulum, 1>());
    // |x| has no second derivative to speak of, but it is not a polynomial.
    assert!(!quadratic::<Kinked, 1>());
}

/// Only linear step equations keep their Jacobian: a quadratic `L` with constant one-forms and
/// nothing else.
#[test]
fn only_linear_step_equations_say_their_jacobian_is_constant() {
    let lc = Stepper::new(circuit::LC, Quadrature::midpoint(), 0.01).unwrap();
    assert!(lc.equations().constant_jacobian());
    let damped = Stepper::new(Damped { c: 0.1 }, Quadrature::midpoint(), 0.01).unwrap();
    assert!(damped.equations().constant_jacobian());
    let cubic = Stepper::new(Cubic { c: 0.1 }, Quadrature::midpoint(), 0.01).unwrap();
    assert!(quadratic::<Cubic, 1>() && !cubic.equations().constant_jacobian());
    // A one-form of the position (the knife edge's heading), a holonomic constraint, and a
    // Lagrangian that is not quadratic.
    let knife = knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).unwrap();
    assert!(!knife.equations().constant_jacobian());
    let held = Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), 0.01).unwrap();
    assert!(!held.equations().constant_jacobian());
    let swing = Stepper::new(pendulum::SCENE, Quadrature::midpoint(), 0.01).unwrap();
    assert!(!swing.equations().constant_jacobian());
}

/// The LC circuit over 1 000 steps of `quadrature`: its positions, and the Jacobians evaluated
/// after the first step.
fn lc_run(quadrature: Quadrature, options: NewtonOptions) -> (SVector<f64, 4>, usize) {
    let mut stepper = Stepper::new(circuit::LC, quadrature, 0.01)
        .unwrap()
        .with_newton_options(options)
        .unwrap();
    stepper
        .start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    stepper.step().unwrap();
    let mut jacobians = 0;
    for _ in 1..1_000 {
        stepper.step().unwrap();
        jacobians += stepper.last_report().unwrap().jacobians;
    }
    (stepper.q(), jacobians)
}

/// Newton's method: a Jacobian at every evaluation.
fn newtons_method() -> NewtonOptions {
    NewtonOptions {
        jacobian_reuse: Some(0.0),
        ..Default::default()
    }
}

/// 1 000 steps with the kept Jacobian (`kept`: positions, Jacobians after the first step)
/// against Newton's method (`fresh`): none evaluated by the first, one a step by the second, and
/// the same positions to `tolerance`.
fn assert_kept_as_newton<const N: usize>(
    name: &str,
    (kept, kept_jacobians): (SVector<f64, N>, usize),
    (fresh, fresh_jacobians): (SVector<f64, N>, usize),
    tolerance: f64,
) {
    assert_eq!(kept_jacobians, 0, "{name}");
    assert!(fresh_jacobians >= 999, "{name}: {fresh_jacobians}");
    let gap = (kept - fresh).amax();
    assert!(gap <= tolerance, "{name}: the runs differ by {gap:e}");
}

#[test]
fn a_linear_model_keeps_one_jacobian_and_steps_as_newtons_method_does() {
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let name = quadrature.name();
        let kept = lc_run(quadrature.clone(), NewtonOptions::default());
        assert_kept_as_newton(&name, kept, lc_run(quadrature, newtons_method()), 1e-13);
        // And both are the circuit: q_c2(10) against its closed form.
        assert!((kept.0[2] - circuit::lc_q_c2(10.0)).abs() < 1e-3, "{name}");
    }
}

/// The positions after 1 000 steps of `stepper` from rest at `q0`, its input `input` set before
/// each step to a voltage that changes every step, and the Jacobians evaluated after the first.
fn driven_run<S: DiracSystem<N>, const N: usize>(
    mut stepper: Stepper<S, N>,
    q0: SVector<f64, N>,
    input: &str,
) -> (SVector<f64, N>, usize) {
    stepper.start_from_velocity(q0, SVector::zeros()).unwrap();
    let mut jacobians = 0;
    for k in 0..1_000 {
        stepper
            .set_input(input, 1.0 + (0.01 * k as f64).sin())
            .unwrap();
        stepper.step().unwrap();
        if k > 0 {
            jacobians += stepper.last_report().unwrap().jacobians;
        }
    }
    (stepper.q(), jacobians)
}

#[test]
fn driven_linear_models_keep_one_jacobian_and_step_as_newtons_method_does() {
    let ladder = rlc_ladder::ladder(0.5, 0.3, 0.2);
    let with = |options: NewtonOptions| {
        Stepper::new(ladder, Quadrature::midpoint(), 0.01)
            .unwrap()
            .with_newton_options(options)
            .unwrap()
    };
    let kept = driven_run(with(NewtonOptions::default()), SVector::zeros(), "v.u");
    let fresh = driven_run(with(newtons_method()), SVector::zeros(), "v.u");
    let scale = fresh.0.amax();
    assert_kept_as_newton("ladder", kept, fresh, 1e-13 * scale);
    let oscillator = Driven { c: 0.3, k: 0.5 };
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let with = |options: NewtonOptions| {
            Stepper::new(oscillator, quadrature.clone(), 0.01)
                .unwrap()
                .with_newton_options(options)
                .unwrap()
        };
        let q0 = SVector::from([1.0]);
        let kept = driven_run(with(NewtonOptions::default()), q0, "u");
        let fresh = driven_run(with(newtons_method()), q0, "u");
        assert_kept_as_newton(&quadrature.name(), kept, fresh, 1e-13);
    }
}

/// A pendulum that claims to be quadratic: its equations are not linear.
struct Claimed;

impl DiracSystem<1> for Claimed {
    const QUADRATIC: bool = true;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        v[0] * v[0] * 0.5 + q[0].cos()
    }
}

#[test]
fn a_wrong_claim_costs_iterations_not_accuracy() {
    struct Honest;
    impl DiracSystem<1> for Honest {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
            Claimed.lagrangian(q, v)
        }
    }
    let (q0, v0) = (SVector::from([2.0]), SVector::from([0.5]));
    let mut claimed = Stepper::new(Claimed, Quadrature::midpoint(), 0.1).unwrap();
    let mut honest = Stepper::new(Honest, Quadrature::midpoint(), 0.1).unwrap();
    claimed.start_from_velocity(q0, v0).unwrap();
    honest.start_from_velocity(q0, v0).unwrap();
    let (mut claimed_iterations, mut honest_iterations) = (0, 0);
    for _ in 0..500 {
        claimed.step().unwrap();
        honest.step().unwrap();
        claimed_iterations += claimed.last_report().unwrap().iterations;
        honest_iterations += honest.last_report().unwrap().iterations;
    }
    // The kept Jacobian is not the pendulum's: the iteration converges, linearly, in more
    // evaluations than Newton's method takes.
    assert!(
        claimed_iterations > honest_iterations,
        "{claimed_iterations} against {honest_iterations}"
    );
    let gap = (claimed.q() - honest.q()).amax();
    assert!(gap <= 1e-10, "the runs differ by {gap:e}");
}

/// The LC circuit from charge 1 on C2 over `steps` steps of `h`, by the step map or by Newton's
/// method: the end state, the multipliers of the last step, the energy balance's error, the
/// Newton iterations and how the steps were solved.
fn lc_long(
    quadrature: &Quadrature,
    h: f64,
    steps: usize,
    map: bool,
) -> (SVector<f64, 8>, Vec<f64>, f64, usize, Solver) {
    let mut stepper = Stepper::new(circuit::LC, quadrature.clone(), h).unwrap();
    if map {
        stepper = stepper.with_step_map().unwrap();
    }
    stepper
        .start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    let mut iterations = 0;
    for _ in 0..steps {
        stepper.step().unwrap();
        iterations += stepper.last_report().unwrap().iterations;
    }
    let (q, p) = (stepper.q(), stepper.p());
    let end = SVector::<f64, 8>::from_fn(|i, _| if i < 4 { q[i] } else { p[i - 4] });
    let balance = stepper.energy_balance_error().unwrap();
    (
        end,
        stepper.multipliers().to_vec(),
        balance,
        iterations,
        stepper.solver(),
    )
}

#[test]
fn linear_step_equations_are_stepped_by_a_map_read_off_the_step() {
    let (h, steps) = (0.05, 10_000);
    for quadrature in [
        Quadrature::midpoint(),
        Quadrature::galerkin(2).unwrap(),
        Quadrature::galerkin(3).unwrap(),
    ] {
        let name = quadrature.name();
        let (mapped, mu, balance, iterations, solver) = lc_long(&quadrature, h, steps, true);
        let (solved, mu_solved, balance_solved, iterations_solved, newton) =
            lc_long(&quadrature, h, steps, false);
        assert_eq!(solver, Solver::StepMap, "{name}");
        let Solver::Newton(why) = newton else {
            panic!("{name}: {newton:?}")
        };
        assert!(why.contains("with_step_map"), "{name}: {why}");
        // No Newton iteration by the map; Newton's method iterates every step.
        assert_eq!(iterations, 0, "{name}");
        assert!(iterations_solved >= steps, "{name}");
        // The same steps to round-off, 10⁴ steps on: states, multipliers, energy balance.
        let gap = (mapped - solved).amax();
        assert!(gap <= 1e-12, "{name}: the runs differ by {gap:e}");
        let mu_gap = mu
            .iter()
            .zip(&mu_solved)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        let mu_size = mu_solved.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        assert!(
            mu_gap <= 1e-12 * mu_size,
            "{name}: multipliers differ by {mu_gap:e} (of {mu_size:e})"
        );
        assert!(
            (balance - balance_solved).abs() <= 1e-12,
            "{name}: {balance:e} against {balance_solved:e}"
        );
    }
    // And the map is the circuit's: q_c2 at t = 500 against its closed form, at order 6.
    let (end, ..) = lc_long(&Quadrature::galerkin(3).unwrap(), h, steps, true);
    let error = (end[2] - circuit::lc_q_c2(h * steps as f64)).abs();
    assert!(error <= 1e-9, "galerkin(3) at t = 500: {error:e}");
}

/// The largest energy error over the first and the last tenth of `steps` steps of the LC
/// circuit (midpoint, h = 0.1) by the step map, sampled every 1 000 steps, and the solver.
fn lc_energy(steps: usize) -> (f64, f64, Solver) {
    let mut stepper = Stepper::new(circuit::LC, Quadrature::midpoint(), 0.1)
        .unwrap()
        .with_step_map()
        .unwrap();
    stepper
        .start_from_velocity(circuit::q0(), SVector::zeros())
        .unwrap();
    let e0 = stepper.energy().unwrap();
    let tenth = steps / 10;
    let (mut first, mut last) = (0.0_f64, 0.0_f64);
    for k in 0..steps {
        stepper.step().unwrap();
        if k % 1000 == 999 {
            let error = (stepper.energy().unwrap() - e0).abs();
            if k < tenth {
                first = first.max(error);
            } else if k >= steps - tenth {
                last = last.max(error);
            }
        }
    }
    (first, last, stepper.solver())
}

#[test]
fn a_step_map_read_again_keeps_the_energy_without_drift_over_a_million_steps() {
    let steps = 1_000_000;
    let (first, last, solver) = lc_energy(steps);
    assert_eq!(solver, Solver::StepMap);
    // The midpoint rule keeps the circuit's quadratic energy exactly: what is left is round-off.
    // One map read at the start and kept would apply its round-off at every step, a drift of
    // about ε a step (3.5e-11 here); read again every 1 024 steps from probes of other
    // scales, its round-off walks at random (measured 2.0e-12; Newton's method 1.5e-14).
    println!("energy error: {first:e} in the first tenth, {last:e} in the last");
    assert!(last <= 1e-11, "energy error {last:e} in the last tenth");
    assert!(first <= 1e-12, "energy error {first:e} in the first tenth");
}

/// A free particle that claims to be quadratic, with a quartic potential too weak to see at the
/// start: its step equations are not linear far from it.
struct Faint;

impl DiracSystem<1> for Faint {
    const QUADRATIC: bool = true;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        v[0] * v[0] * 0.5 - q[0].powi(4) * 1e-12
    }
}

#[test]
fn a_step_map_checks_the_claim_it_rests_on() {
    // A claim wrong at the start: the map cannot be read, and the first step says so.
    let mut claimed = Stepper::new(Claimed, Quadrature::midpoint(), 0.1)
        .unwrap()
        .with_step_map()
        .unwrap();
    claimed
        .start_from_velocity(SVector::from([2.0]), SVector::from([0.5]))
        .unwrap();
    let failed = claimed.step().unwrap_err();
    assert!(
        matches!(failed, DiracError::InconsistentDerivatives(ref why) if why.contains("not linear")),
        "{failed}"
    );
    assert_eq!(claimed.steps(), 0);
    // And so does every later step of the run.
    let again = claimed.step().unwrap_err();
    assert!(
        matches!(again, DiracError::InconsistentDerivatives(_)),
        "{again}"
    );
    assert_eq!(claimed.solver(), Solver::StepMap);
    // A claim wrong only far from the start: a later reading of the map stops the run there,
    // and the state is kept.
    let mut faint = Stepper::new(Faint, Quadrature::midpoint(), 0.1)
        .unwrap()
        .with_step_map()
        .unwrap();
    faint
        .start_from_velocity(SVector::from([0.0]), SVector::from([10.0]))
        .unwrap();
    let failed = loop {
        let before = (faint.steps(), faint.q(), faint.p());
        match faint.step() {
            Ok(()) => assert!(faint.steps() < 100_000, "never caught"),
            Err(error) => {
                assert_eq!(before, (faint.steps(), faint.q(), faint.p()));
                break error;
            }
        }
    };
    assert!(
        matches!(failed, DiracError::InconsistentDerivatives(ref why) if why.contains("QUADRATIC")),
        "{failed}"
    );
    // Caught at a reading, where the quartic force 4e-12 q³ bends the step by more than 1e-9.
    let q = faint.q()[0];
    assert!((10.0..1e4).contains(&q), "caught at q = {q}");
    // Models whose steps change from step to step, or whose equations are not linear, are
    // refused, saying why.
    let driven = Stepper::new(Driven { c: 0.3, k: 0.5 }, Quadrature::midpoint(), 0.1).unwrap();
    assert!(refusal(driven.with_step_map()).contains("forces"));
    let swing = Stepper::new(pendulum::SCENE, Quadrature::midpoint(), 0.1).unwrap();
    assert!(refusal(swing.with_step_map()).contains("not quadratic"));
    let knife = knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).unwrap();
    assert!(refusal(knife.with_step_map()).contains("one-form"));
}

/// Why a stepper was refused its step map.
fn refusal<S: DiracSystem<N>, const N: usize>(
    stepper: Result<Stepper<S, N>, DiracError>,
) -> String {
    match stepper {
        Err(DiracError::Unsupported(why)) => why,
        other => panic!("{:?}", other.map(|s| s.solver())),
    }
}

#[test]
fn a_step_maps_steps_serve_derivatives_dense_output_and_restarts_as_newtons_do() {
    // The midpoint rule: derivatives of constrained steps are of degree 1.
    let quadrature = Quadrature::midpoint();
    let start = |stepper: &mut Stepper<LcCircuit, 4>| {
        stepper
            .start_from_velocity(circuit::q0(), SVector::zeros())
            .unwrap()
    };
    let mut mapped = Stepper::new(circuit::LC, quadrature.clone(), 0.05)
        .unwrap()
        .with_step_map()
        .unwrap();
    let mut solved = Stepper::new(circuit::LC, quadrature, 0.05).unwrap();
    for restart in 0..2 {
        start(&mut mapped);
        start(&mut solved);
        // Past a reading (every 1 024 steps), then a step with its derivatives.
        for _ in 0..1_500 {
            mapped.step().unwrap();
            solved.step().unwrap();
        }
        let (a, b) = (
            mapped.step_linearised().unwrap(),
            solved.step_linearised().unwrap(),
        );
        let gap = (a.matrix() - b.matrix()).amax();
        assert!(gap <= 1e-12, "restart {restart}: A differs by {gap:e}");
        let t = mapped.t() - 0.02;
        let (inside, newton) = (
            mapped.interpolate(t).unwrap(),
            solved.interpolate(t).unwrap(),
        );
        let gap = (inside.q - newton.q)
            .amax()
            .max((inside.v - newton.v).amax());
        assert!(
            gap <= 1e-12,
            "restart {restart}: dense output differs by {gap:e}"
        );
        let violation = mapped.constraint_violation();
        assert!(
            violation <= 1e-13,
            "restart {restart}: violation {violation:e}"
        );
    }
}
