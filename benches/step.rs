//! One step of the generated stepper against the hand-written limit, and how the cost grows.
//!
//! `cargo bench --bench step`. Compare figures within one run only: the ratio generated / hand is
//! what `docs/performance.md` reports (`scripts/performance.sh` writes it from this bench).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group};
use dirac::prelude::*;
use dirac::{StepEquations, Vectors};
use scenes::hand_written::{Galerkin2, HandStepper, KnifeEdgeMidpoint, Midpoint};
use scenes::{chain, double_pendulum, knife_edge};

/// One step of the generated steppers against the hand-written ones (analytic derivatives, the
/// same Newton, the same predictor; `tests/suite/golden.rs` checks they follow the same trajectories),
/// h = 0.01: the double pendulum under the midpoint rule and `galerkin(2)`, the knife edge under
/// the midpoint rule with its one-form at the midpoint.
fn generated_vs_hand(c: &mut Criterion) {
    let mut group = c.benchmark_group("generated_vs_hand_written");
    let h = 0.01;
    let (q0, v0, scene) = (
        double_pendulum::q0(),
        double_pendulum::v0(),
        double_pendulum::SCENE,
    );
    let mut generated = double_pendulum::stepper(Quadrature::midpoint(), h).expect("valid scene");
    group.bench_function("double_pendulum_midpoint/generated", |b| {
        b.iter(|| black_box(generated.step()).expect("step"))
    });
    let mut hand = HandStepper::new(Midpoint(scene), h, q0, v0);
    group.bench_function("double_pendulum_midpoint/hand_written", |b| {
        b.iter(|| black_box(hand.step()).expect("step"))
    });
    let galerkin = Quadrature::galerkin(2).expect("valid rule");
    let mut generated = double_pendulum::stepper(galerkin, h).expect("valid scene");
    group.bench_function("double_pendulum_galerkin2/generated", |b| {
        b.iter(|| black_box(generated.step()).expect("step"))
    });
    let mut hand = HandStepper::new(Galerkin2(scene), h, q0, v0);
    group.bench_function("double_pendulum_galerkin2/hand_written", |b| {
        b.iter(|| black_box(hand.step()).expect("step"))
    });
    let mut generated = knife_edge::stepper(ConstraintPoint::Midpoint, h).expect("valid scene");
    group.bench_function("knife_edge_midpoint/generated", |b| {
        b.iter(|| black_box(generated.step()).expect("step"))
    });
    let v0 = SVector::from([0.0, 0.0, knife_edge::OMEGA]);
    let mut hand = HandStepper::new(
        KnifeEdgeMidpoint(knife_edge::SCENE),
        h,
        SVector::zeros(),
        v0,
    );
    group.bench_function("knife_edge_midpoint/hand_written", |b| {
        b.iter(|| black_box(hand.step()).expect("step"))
    });
    group.finish();
}

/// Double pendulum, h = 0.01, one step with each tour quadrature.
fn quadratures(c: &mut Criterion) {
    let mut group = c.benchmark_group("double_pendulum_step_by_quadrature");
    for quadrature in scenes::quadratures() {
        let name = quadrature.name();
        let mut stepper = double_pendulum::stepper(quadrature, 0.01).expect("valid scene");
        group.bench_function(name, |b| {
            b.iter(|| black_box(stepper.step()).expect("step"))
        });
    }
    group.finish();
}

/// Gauss steps of models that are not separable, solved by Newton's method (`implicit`) and by
/// fixed-point iteration on their rows (`fixed_point`, `Stepper::with_fixed_point`): the double
/// pendulum (h = 0.02) at degrees 2, 4 and 6 and the 8-link chain (h = 0.01) at degree 3, each
/// timed over the first 500 steps from its start (as `chain_step`), per step.
fn fixed_point_rows(c: &mut Criterion) {
    let mut group = c.benchmark_group("fixed_point_step");
    group.sample_size(20);
    fn solved<S: DiracSystem<N>, const N: usize>(
        stepper: Stepper<S, N>,
        iterated: bool,
    ) -> Stepper<S, N> {
        match iterated {
            true => stepper
                .with_fixed_point()
                .expect("an unconstrained model on Rⁿ"),
            false => stepper,
        }
    }
    for s in [2, 4, 6] {
        for (how, iterated) in [("implicit", false), ("fixed_point", true)] {
            let quadrature = Quadrature::galerkin(s).expect("valid rule");
            let started = solved(
                double_pendulum::stepper(quadrature, 0.02).expect("valid scene"),
                iterated,
            );
            group.bench_function(format!("double_pendulum_galerkin{s}/{how}"), |b| {
                over_stretches(b, 8, || started.clone(), |stepper| stepper.step());
            });
        }
    }
    for (how, iterated) in [("implicit", false), ("fixed_point", true)] {
        let quadrature = Quadrature::galerkin(3).expect("valid rule");
        let mut stepper = Stepper::new(chain::SCENE8, quadrature, 0.01).expect("valid scene");
        stepper
            .start_from_velocity(chain::initial(), SVector::zeros())
            .expect("finite start");
        let started = solved(stepper, iterated);
        group.bench_function(format!("chain8_galerkin3/{how}"), |b| {
            over_stretches(b, 8, || started.clone(), |stepper| stepper.step());
        });
    }
    group.finish();
}

/// One chain size in trep's scene: unit links and masses, g = 9.81, midpoint, h = 0.01, straight
/// and horizontal at rest. Like trep's script, a measurement steps from the start for
/// `max(200, 4000 / n)` steps (starting over from a copy of the started stepper), so that every
/// sample averages the same stretch of the fall; the time reported is per step.
fn chain_step<const L: usize>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
) {
    let system = chain::Chain::<L> {
        m: 1.0,
        l: 1.0,
        g: 9.81,
    };
    let mut started = Stepper::new(system, Quadrature::midpoint(), 0.01).expect("valid scene");
    started
        .start_from_velocity(
            SVector::from_element(std::f64::consts::FRAC_PI_2),
            SVector::zeros(),
        )
        .expect("finite start");
    group.bench_with_input(BenchmarkId::from_parameter(L), &L, |b, _| {
        over_stretches(b, L, || started.clone(), |stepper| stepper.step());
    });
}

/// Times steps over trep's stretch of the fall of an `n`-link chain, `max(200, 4000 / n)` steps
/// from the start (`start`, untimed, gives a started model to `step`): the time per step.
fn over_stretches<M>(
    bencher: &mut criterion::Bencher<'_>,
    n: usize,
    mut start: impl FnMut() -> M,
    mut step: impl FnMut(&mut M) -> Result<(), DiracError>,
) {
    let stretch = 200.max(4000 / n) as u64;
    bencher.iter_custom(|iterations| {
        let runs = iterations.div_ceil(stretch);
        let mut total = Duration::ZERO;
        for _ in 0..runs {
            let mut model = start();
            let clock = Instant::now();
            for _ in 0..stretch {
                black_box(step(&mut model)).expect("step");
            }
            total += clock.elapsed();
        }
        total.mul_f64(iterations as f64 / (runs * stretch) as f64)
    });
}

/// trep's n-link chain in maximal coordinates (`scenes::mechanism::point_chain`: point masses
/// on rods held by joints, the modular step), n = 10, 20, 40, 100, 1 000, timed as
/// `chain_step`.
fn mechanism(c: &mut Criterion) {
    use scenes::mechanism;
    let mut group = c.benchmark_group("mechanism_chain");
    group.sample_size(20);
    for n in [10, 20, 40, 100, 1000] {
        let theta = vec![std::f64::consts::FRAC_PI_2; n];
        let (q0, v0) = mechanism::point_chain_state(&theta, &vec![0.0; n], 1.0);
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            let start = || {
                let mut chain = mechanism::point_chain(n, 1.0, 1.0, 9.81, 0.01).expect("scene");
                chain
                    .start_from_velocity(&q0, &v0)
                    .expect("consistent start");
                chain
            };
            over_stretches(b, n, start, Modular::step);
        });
    }
    group.finish();
}

/// The n-link chain in trep's scene for n = 2, 4, 5, 8, 10, 16, 20, 32, 40, 64: trep's sizes
/// (trep 1.0.2, `MidpointVI`, timed beside it on the same machine) and the
/// powers of two the growth exponent is fitted over.
fn chain_growth(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain_trep_scene");
    group.sample_size(10);
    chain_step::<2>(&mut group);
    chain_step::<4>(&mut group);
    chain_step::<5>(&mut group);
    chain_step::<8>(&mut group);
    chain_step::<10>(&mut group);
    chain_step::<16>(&mut group);
    chain_step::<20>(&mut group);
    chain_step::<32>(&mut group);
    chain_step::<40>(&mut group);
    chain_step::<64>(&mut group);
    group.finish();
}

/// Constrained steps (midpoint, h = 0.01) beside the unconstrained double pendulum: the LC circuit
/// (4 coordinates, 2 constant one-forms, KKT 6×6, its hidden constraint projected at each step's
/// end; linear, so Newton's method keeps one factorised Jacobian for the run; again by its step
/// map, `with_step_map`, and by Newton's method with a Jacobian at each step), the
/// knife edge (3 coordinates, one configuration-dependent one-form, KKT 4×4), and the
/// Cartesian pendulum under SHAKE and RATTLE.
fn constrained(c: &mut Criterion) {
    let mut group = c.benchmark_group("constrained_midpoint_step");
    let mut unconstrained =
        double_pendulum::stepper(Quadrature::midpoint(), 0.01).expect("valid scene");
    group.bench_function("double_pendulum", |b| {
        b.iter(|| black_box(unconstrained.step()).expect("step"))
    });
    let mut lc =
        Stepper::new(scenes::circuit::LC, Quadrature::midpoint(), 0.01).expect("valid scene");
    lc.start_from_velocity(scenes::circuit::q0(), SVector::zeros())
        .expect("consistent start");
    group.bench_function("lc_circuit", |b| {
        b.iter(|| black_box(lc.step()).expect("step"))
    });
    // The same steps by the circuit's step map (read off the step every 1 024 steps), and by
    // Newton's method with a Jacobian evaluated and factorised at each step, against Newton's
    // method with the one Jacobian the linear circuit keeps by default.
    let mut lc_map = Stepper::new(scenes::circuit::LC, Quadrature::midpoint(), 0.01)
        .expect("valid scene")
        .with_step_map()
        .expect("a linear circuit");
    lc_map
        .start_from_velocity(scenes::circuit::q0(), SVector::zeros())
        .expect("consistent start");
    group.bench_function("lc_circuit_step_map", |b| {
        b.iter(|| black_box(lc_map.step()).expect("step"))
    });
    let newton = NewtonOptions {
        jacobian_reuse: Some(0.0),
        ..Default::default()
    };
    let mut lc_newton = Stepper::new(scenes::circuit::LC, Quadrature::midpoint(), 0.01)
        .expect("valid scene")
        .with_newton_options(newton)
        .expect("valid options");
    lc_newton
        .start_from_velocity(scenes::circuit::q0(), SVector::zeros())
        .expect("consistent start");
    group.bench_function("lc_circuit_jacobian_each_step", |b| {
        b.iter(|| black_box(lc_newton.step()).expect("step"))
    });
    // A driven RLC ladder of components (10 coordinates, resistors' forces affine): the kept
    // Jacobian against one at each step.
    for (name, options) in [
        ("rlc_ladder", NewtonOptions::default()),
        ("rlc_ladder_jacobian_each_step", newton),
    ] {
        let ladder = scenes::rlc_ladder::ladder(0.5, 0.3, 0.2);
        let mut stepper = Stepper::new(ladder, Quadrature::midpoint(), 0.01)
            .expect("valid scene")
            .with_newton_options(options)
            .expect("valid options");
        stepper
            .start_from_velocity(SVector::zeros(), SVector::zeros())
            .expect("consistent start");
        stepper.set_input("v.u", 1.0).expect("the source's input");
        group.bench_function(name, |b| {
            b.iter(|| black_box(stepper.step()).expect("step"))
        });
    }
    let mut knife =
        scenes::knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).expect("valid scene");
    group.bench_function("knife_edge", |b| {
        b.iter(|| black_box(knife.step()).expect("step"))
    });
    for scheme in [HolonomicScheme::Shake, HolonomicScheme::Rattle] {
        let mut pendulum = Stepper::new(
            scenes::cartesian_pendulum::SCENE,
            Quadrature::midpoint(),
            0.01,
        )
        .expect("valid scene")
        .with_holonomic_scheme(scheme);
        pendulum
            .start_from_velocity(scenes::cartesian_pendulum::q0(1.0), SVector::zeros())
            .expect("consistent start");
        let name = format!("cartesian_pendulum_{scheme:?}").to_lowercase();
        group.bench_function(name, |b| {
            b.iter(|| black_box(pendulum.step()).expect("step"))
        });
    }
    group.finish();
}

/// Steps of the newer model classes (h = 0.05): a Lagrangian linear in the velocities
/// (collocated at the Gauss nodes, p = ϑ(q)), and the knife edge with its one-form held at the
/// Gauss nodes of a Galerkin step.
fn newer_classes(c: &mut Criterion) {
    let mut group = c.benchmark_group("model_class_step");
    for quadrature in [
        Quadrature::midpoint(),
        Quadrature::galerkin(2).expect("rule"),
    ] {
        let name = quadrature.name();
        let mut lv =
            Stepper::new(scenes::lotka_volterra::SCENE, quadrature.clone(), 0.05).expect("valid");
        lv.start_from_position(vector![2.0, 1.0]).expect("start");
        group.bench_function(format!("lotka_volterra/{name}"), |b| {
            b.iter(|| black_box(lv.step()).expect("step"))
        });
        let mut projected = Stepper::new(scenes::lotka_volterra::SCENE, quadrature.clone(), 0.05)
            .expect("valid")
            .with_first_order_scheme(FirstOrderScheme::SymmetricProjection);
        projected
            .start_from_position(vector![2.0, 1.0])
            .expect("start");
        group.bench_function(format!("lotka_volterra_projected/{name}"), |b| {
            b.iter(|| black_box(projected.step()).expect("step"))
        });
        let mut knife =
            Stepper::new(scenes::knife_edge::SCENE, quadrature.clone(), 0.05).expect("valid");
        knife
            .start_from_velocity(SVector::zeros(), vector![0.0, 0.0, 1.0])
            .expect("start");
        group.bench_function(format!("knife_edge/{name}"), |b| {
            b.iter(|| black_box(knife.step()).expect("step"))
        });
    }
    group.finish();
}

/// trep's double pendulum (m = l = 1, g = 9.81, both links horizontal at rest, midpoint,
/// h = 0.01): a step, a step with the first derivatives of the step map (`A` by the implicit
/// function theorem), and with the first and second, beside
/// trep's (1.0.2, `MidpointVI`) same three figures on the same model, timed on the same machine.
fn step_derivatives(c: &mut Criterion) {
    let mut group = c.benchmark_group("double_pendulum_trep_scene");
    let model = double_pendulum::DoublePendulum {
        m1: 1.0,
        m2: 1.0,
        l1: 1.0,
        l2: 1.0,
        g: 9.81,
    };
    let half_pi = std::f64::consts::FRAC_PI_2;
    let start = |stepper: &mut Stepper<double_pendulum::DoublePendulum, 2>| {
        stepper
            .start_from_velocity(vector![half_pi, half_pi], SVector::zeros())
            .expect("finite start");
    };
    // Started over every 10⁵ steps (1 000 s): the chaotic pendulum's angles grow without bound
    // over the millions of steps a measurement takes, and at thousands of radians their
    // rounding can keep a step's residual above Newton's tolerance (the step is refused).
    let again = |stepper: &mut Stepper<double_pendulum::DoublePendulum, 2>| {
        if stepper.steps() >= 100_000 {
            start(stepper);
        }
    };
    let mut plain = Stepper::new(model, Quadrature::midpoint(), 0.01).expect("valid scene");
    start(&mut plain);
    group.bench_function("step", |b| {
        b.iter(|| {
            again(&mut plain);
            black_box(plain.step()).expect("step")
        })
    });
    let mut linearised = Stepper::new(model, Quadrature::midpoint(), 0.01).expect("valid scene");
    start(&mut linearised);
    group.bench_function("step_and_first_derivatives", |b| {
        b.iter(|| {
            again(&mut linearised);
            black_box(linearised.step_linearised()).expect("step")
        })
    });
    let mut second = Stepper::new(model, Quadrature::midpoint(), 0.01).expect("valid scene");
    start(&mut second);
    group.bench_function("step_and_second_derivatives", |b| {
        b.iter(|| {
            again(&mut second);
            black_box(second.step_second_order()).expect("step")
        })
    });
    group.finish();
}

/// Recording a run against bare steps: 100 midpoint steps of the double pendulum (h = 0.01) by
/// `step()` in a loop, and by `run(100)`, which also solves every sample's velocity for its
/// energy and stores the sample.
fn recording(c: &mut Criterion) {
    let mut group = c.benchmark_group("double_pendulum_100_steps");
    let mut bare = double_pendulum::stepper(Quadrature::midpoint(), 0.01).expect("valid scene");
    group.bench_function("step_loop", |b| {
        b.iter(|| {
            for _ in 0..100 {
                black_box(bare.step()).expect("step");
            }
        })
    });
    let mut recorded = double_pendulum::stepper(Quadrature::midpoint(), 0.01).expect("valid scene");
    group.bench_function("run", |b| {
        b.iter(|| black_box(recorded.run(100)).expect("run"))
    });
    group.finish();
}

/// The 3D pendulum (an asymmetric body hanging off its centre of mass), h = 0.01, one step:
/// the generated Lie group variational integrator (midpoint and trapezoid in the Cayley chart)
/// against Lee, Leok and McClamroch's written by hand (Newton on the Cayley parameter, analytic
/// derivatives, the same Newton solver). The schemes differ in their discrete Lagrangian but are
/// both of order 2, with errors within 1 % of each other on this scene (tests/suite/lie_group.rs).
fn lie_group(c: &mut Criterion) {
    use scenes::{hand_written_lgvi::HandLgvi, rigid_body};
    let mut group = c.benchmark_group("pendulum_3d_step");
    let h = 0.01;
    let (r0, omega0) = rigid_body::pendulum_start();
    for quadrature in [Quadrature::midpoint(), Quadrature::trapezoid()] {
        let name = format!("generated_{}", quadrature.name());
        let started = rigid_body::started(
            rigid_body::PENDULUM,
            Product::cayley(),
            quadrature,
            h,
            (r0, omega0),
        )
        .expect("valid scene");
        restarting(&mut group, &name, started);
    }
    // The same midpoint step with its derivatives A in the tangent chart (`step_linearised`).
    let started = rigid_body::started(
        rigid_body::PENDULUM,
        Product::cayley(),
        Quadrature::midpoint(),
        h,
        (r0, omega0),
    )
    .expect("valid scene");
    let mut linearised = started.clone();
    group.bench_function("generated_midpoint_with_derivatives", |b| {
        b.iter(|| {
            if linearised.steps() >= 100_000 {
                linearised = started.clone();
            }
            black_box(linearised.step_linearised()).expect("step")
        })
    });
    let mut hand = HandLgvi::new(&rigid_body::PENDULUM, h, r0, omega0);
    let mut steps = 0;
    group.bench_function("hand_written_lgvi", |b| {
        b.iter(|| {
            if steps >= 100_000 {
                hand = HandLgvi::new(&rigid_body::PENDULUM, h, r0, omega0);
                steps = 0;
            }
            steps += 1;
            black_box(hand.step()).expect("step")
        })
    });
    group.finish();
}

/// The spherical pendulum (h = 0.01, midpoint): the generated step on `S²` with either
/// retraction against the same pendulum in Cartesian coordinates held on the sphere by a
/// holonomic constraint.
fn sphere(c: &mut Criterion) {
    use scenes::spherical_pendulum;
    let mut group = c.benchmark_group("spherical_pendulum_step");
    let h = 0.01;
    for (name, space) in [("s2_cayley", Product::cayley()), ("s2_exp", Product::exp())] {
        let started =
            spherical_pendulum::on_sphere(space, Quadrature::midpoint(), h).expect("valid scene");
        restarting(&mut group, name, started);
    }
    let started = spherical_pendulum::cartesian(Quadrature::midpoint(), h).expect("valid scene");
    restarting(&mut group, "cartesian_holonomic", started);
    group.finish();
}

/// `step()` of a copy of `started`, started over every 10⁵ steps (a measurement of millions
/// of steps would otherwise carry the scene far from where it is measured).
fn restarting<E: StepEquations<N> + Clone, const N: usize>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    started: Stepper<E::System, N, E>,
) where
    E::System: Clone,
{
    let mut stepper = started.clone();
    group.bench_function(name, |b| {
        b.iter(|| {
            if stepper.steps() >= 100_000 {
                stepper = started.clone();
            }
            black_box(stepper.step()).expect("step")
        })
    });
}

/// One step of the same model on the Lagrangian and the discrete Hamiltonian route: Kepler
/// (h = 0.01) and the knife edge (h = 0.01, one one-form), midpoint and `galerkin(2)`.
fn routes(c: &mut Criterion) {
    let mut group = c.benchmark_group("route_step");
    let knife = scenes::hamiltonian::KnifeEdge {
        m: 1.0,
        j: 1.0,
        g: 9.81,
        alpha: std::f64::consts::FRAC_PI_6,
    };
    let (q0, p0) = (scenes::kepler::q0(), scenes::kepler::p0());
    let knife_p0 = vector![0.0, 0.0, 1.0];
    for quadrature in [
        Quadrature::midpoint(),
        Quadrature::galerkin(2).expect("valid"),
    ] {
        let name = quadrature.name();
        let mut lagrangian =
            Stepper::new(scenes::kepler::SCENE, quadrature.clone(), 0.01).expect("valid scene");
        lagrangian.start_from_momentum(q0, p0).expect("start");
        group.bench_function(format!("kepler/lagrangian/{name}"), |b| {
            b.iter(|| black_box(lagrangian.step()).expect("step"))
        });
        let model = scenes::hamiltonian::Kepler { mu: 1.0 };
        let mut hamiltonian =
            Stepper::hamiltonian(model, quadrature.clone(), 0.01).expect("valid scene");
        hamiltonian.start_from_momentum(q0, p0).expect("start");
        group.bench_function(format!("kepler/hamiltonian/{name}"), |b| {
            b.iter(|| black_box(hamiltonian.step()).expect("step"))
        });
        let mut lagrangian =
            Stepper::new(scenes::knife_edge::SCENE, quadrature.clone(), 0.01).expect("valid scene");
        lagrangian
            .start_from_momentum(SVector::zeros(), knife_p0)
            .expect("start");
        group.bench_function(format!("knife_edge/lagrangian/{name}"), |b| {
            b.iter(|| black_box(lagrangian.step()).expect("step"))
        });
        let mut hamiltonian =
            Stepper::hamiltonian(knife, quadrature.clone(), 0.01).expect("valid scene");
        hamiltonian
            .start_from_momentum(SVector::zeros(), knife_p0)
            .expect("start");
        group.bench_function(format!("knife_edge/hamiltonian/{name}"), |b| {
            b.iter(|| black_box(hamiltonian.step()).expect("step"))
        });
    }
    group.finish();
}

/// Interconnected models against the same model written as one struct (midpoint, h = 0.01;
/// both solved monolithically): the seed's LC circuit from its two subcircuits in plain Rust
/// and with the attribute, and the LC ladder of K cells in a ring (`Repeated`, N = 2K
/// coordinates and K junctions) for the growth with K.
fn interconnection(c: &mut Criterion) {
    let mut group = c.benchmark_group("interconnection_step");
    let q0 = vector![0.0, 1.0, 0.0, 0.0];
    let mut whole =
        Stepper::new(scenes::circuit::LC, Quadrature::midpoint(), 0.01).expect("valid scene");
    whole
        .start_from_velocity(scenes::circuit::q0(), SVector::zeros())
        .expect("consistent start");
    group.bench_function("lc_monolithic", |b| {
        b.iter(|| black_box(whole.step()).expect("step"))
    });
    let parts = scenes::circuit::lc_from_subcircuits(&scenes::circuit::LC).expect("valid");
    let mut plain = Stepper::new(parts, Quadrature::midpoint(), 0.01).expect("valid scene");
    plain
        .start_from_velocity(q0, SVector::zeros())
        .expect("consistent start");
    group.bench_function("lc_two_subcircuits", |b| {
        b.iter(|| black_box(plain.step()).expect("step"))
    });
    let parts = scenes::circuit::LcByAttribute::of(&scenes::circuit::LC);
    let mut attribute = Stepper::new(parts, Quadrature::midpoint(), 0.01).expect("valid scene");
    attribute
        .start_from_velocity(q0, SVector::zeros())
        .expect("consistent start");
    group.bench_function("lc_two_subcircuits_attribute", |b| {
        b.iter(|| black_box(attribute.step()).expect("step"))
    });
    fn ladder<const K: usize, const N: usize>(
        group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    ) {
        let ring = scenes::ladder::ring::<K, N>(1.0, 1.0).expect("valid ladder");
        let mut stepper = Stepper::new(ring, Quadrature::midpoint(), 0.01).expect("valid scene");
        // A standing wave: charge on the capacitors only where KCL allows it (q_c = q_l − q_l').
        let q0 = SVector::from_fn(|i, _| {
            let j = i / 2;
            let x = |j: usize| 0.1 * (2.0 * std::f64::consts::PI * j as f64 / K as f64).cos();
            if i % 2 == 0 {
                x(j)
            } else {
                x(j) - x((j + 1) % K)
            }
        });
        stepper
            .start_from_velocity(q0, SVector::zeros())
            .expect("consistent start");
        group.bench_with_input(BenchmarkId::new("ladder_cells", K), &K, |b, _| {
            b.iter(|| black_box(stepper.step()).expect("step"))
        });
    }
    ladder::<4, 8>(&mut group);
    ladder::<8, 16>(&mut group);
    ladder::<16, 32>(&mut group);
    ladder::<32, 64>(&mut group);
    group.finish();
}

/// Three angles coupled by cosines, with a position-dependent inertia, written by hand without
/// closed forms: a component whose step takes hyper-dual Hessians.
struct Angles;

impl DiracSystem<3> for Angles {
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
        let kinetic = (0..3).fold(D::from(0.0), |sum, i| {
            sum + v[i] * v[i] * (q[i].cos() * 0.1 + 1.0) * 0.5
        });
        kinetic + (q[0] - q[1]).cos() + (q[1] - q[2]).cos() + q[0].cos()
    }
}

/// The modular step against the monolithic one on the same interconnections (h = 0.01,
/// midpoint), and how it grows along an open chain of `K` tethered masses, one component after
/// another and in parallel.
fn modular(c: &mut Criterion) {
    use scenes::components::{Capacitor, Inductor};
    use scenes::ladder;
    let mut group = c.benchmark_group("modular_step");
    let h = 0.01;
    let series = || Junction::new("series").flow("l.q", 1.0).flow("c.q", -1.0);
    let whole = Interconnection::new(
        ("l", Inductor { l: 1.0 }),
        ("c", Capacitor { c: 1.0 }),
        [series()],
    )
    .expect("valid loop");
    let mut monolithic = Stepper::new(whole, Quadrature::midpoint(), h).expect("valid scene");
    monolithic
        .start_from_velocity(vector![1.0, 1.0], SVector::zeros())
        .expect("consistent start");
    group.bench_function("lc_loop/monolithic", |b| {
        b.iter(|| black_box(monolithic.step()).expect("step"))
    });
    let mut parts = Modular::new(Quadrature::midpoint(), h).expect("valid rule");
    parts.add("l", Inductor { l: 1.0 }).expect("a name");
    parts.add("c", Capacitor { c: 1.0 }).expect("a name");
    parts.join(series()).expect("valid junction");
    parts
        .start_from_velocity(&[1.0, 1.0], &[0.0, 0.0])
        .expect("consistent start");
    group.bench_function("lc_loop/modular", |b| {
        b.iter(|| black_box(parts.step()).expect("step"))
    });
    // The seed's LC circuit from its two subcircuits (unequal capacitors): monolithically, and
    // by parts with its hidden constraint across the components held at every step's end.
    let seed = scenes::circuit::UNEQUAL;
    let (q0, v0) = scenes::circuit::UNEQUAL_START;
    let mut whole = Stepper::new(
        scenes::circuit::lc_from_subcircuits(&seed).expect("valid circuit"),
        Quadrature::midpoint(),
        h,
    )
    .expect("valid scene");
    whole
        .start_from_velocity(SVector::from(q0), SVector::from(v0))
        .expect("consistent start");
    group.bench_function("seed_lc/monolithic", |b| {
        b.iter(|| black_box(whole.step()).expect("step"))
    });
    let mut parts = scenes::circuit::lc_by_parts(&seed, h).expect("valid circuit");
    parts
        .start_from_velocity(&q0, &v0)
        .expect("consistent start");
    group.bench_function("seed_lc/modular", |b| {
        b.iter(|| black_box(parts.step()).expect("step"))
    });
    // A rigid body turning a flywheel through a shaft: one model on R × SO(3), and by parts
    // (the body on SO(3), the wheel on R).
    use scenes::shafted_body::{self, WHEEL};
    let begin = scenes::rigid_body::free_start();
    let body = scenes::rigid_body::ASYMMETRIC;
    let mut one = shafted_body::one_model(body, WHEEL, h, begin).expect("valid scene");
    group.bench_function("shafted_body/one_model", |b| {
        b.iter(|| black_box(one.step()).expect("step"))
    });
    let mut parts = shafted_body::by_parts(body, WHEEL, Product::cayley(), h).expect("valid scene");
    shafted_body::start(&mut parts, begin).expect("consistent start");
    group.bench_function("shafted_body/modular", |b| {
        b.iter(|| black_box(parts.step()).expect("step"))
    });
    let (q0, v0) = ladder::chain_wave(3, 0.5);
    let mut ring = Stepper::new(
        ladder::chain(1.0, 1.0).expect("valid ring"),
        Quadrature::midpoint(),
        h,
    )
    .expect("valid scene");
    ring.start_from_velocity(q0, v0).expect("consistent start");
    group.bench_function("ring16/monolithic", |b| {
        b.iter(|| black_box(ring.step()).expect("step"))
    });
    let mut parts = ladder::modular_chain(1.0, 1.0, ladder::CELLS, true, h).expect("valid ring");
    parts
        .start_from_velocity(q0.as_slice(), v0.as_slice())
        .expect("consistent start");
    group.bench_function("ring16/modular", |b| {
        b.iter(|| black_box(parts.step()).expect("step"))
    });
    group.sample_size(20);
    // Heavier components: three coupled angles each, differentiated by dual numbers (no closed
    // forms), 1 000 of them in a chain, the last angle's rate of one the first's of the next.
    let mut heavy = Modular::new(Quadrature::midpoint(), h).expect("valid rule");
    let cells = 1000;
    for j in 0..cells {
        heavy.add(&format!("cell[{j}]"), Angles).expect("a name");
    }
    for j in 0..cells - 1 {
        let joint = Junction::new(format!("joint{j}"))
            .flow(format!("cell[{j}].q2"), 1.0)
            .flow(format!("cell[{}].q0", j + 1), -1.0);
        heavy.join(joint).expect("valid junction");
    }
    let q0: Vec<f64> = (0..3 * cells)
        .map(|i| 0.1 * (i as f64 * 0.37).sin())
        .collect();
    for parallel in [false, true] {
        let mut chain = std::mem::replace(
            &mut heavy,
            Modular::new(Quadrature::midpoint(), h).expect("valid rule"),
        )
        .with_parallel(parallel);
        chain
            .start_from_velocity(&q0, &vec![0.0; 3 * cells])
            .expect("consistent start");
        let name = if parallel {
            "angles/parallel"
        } else {
            "angles/sequential"
        };
        group.bench_with_input(BenchmarkId::new(name, cells), &cells, |b, _| {
            b.iter(|| black_box(chain.step()).expect("step"))
        });
        heavy = chain;
    }
    for cells in [10, 100, 1000, 10000] {
        // A wave along the open chain: masses at 0.1 sin(πj/K), each spring's end at the next.
        let x = |j: usize| 0.1 * (std::f64::consts::PI * j as f64 / cells as f64).sin();
        let q0: Vec<f64> = (0..cells).flat_map(|j| [x(j), x(j + 1)]).collect();
        for parallel in [false, true] {
            let mut chain = ladder::modular_chain(1.0, 1.0, cells, false, h)
                .expect("valid chain")
                .with_parallel(parallel);
            chain
                .start_from_velocity(&q0, &vec![0.0; 2 * cells])
                .expect("consistent start");
            let name = if parallel {
                "chain/parallel"
            } else {
                "chain/sequential"
            };
            group.bench_with_input(BenchmarkId::new(name, cells), &cells, |b, _| {
                b.iter(|| black_box(chain.step()).expect("step"))
            });
        }
    }
    group.finish();
}

/// One step of models driven by forces and inputs, each step's work booked for the energy
/// balance (`Stepper::work`): the cart-pole pushed by a constant force (midpoint), the RLC
/// circuit with its source on (midpoint) and the satellite under a constant body torque on SO(3)
/// (midpoint, Cayley). Each is started over every 10⁴ steps.
fn forced(c: &mut Criterion) {
    let mut group = c.benchmark_group("forced_step");
    let h = 0.01;
    let mut cart_pole = Stepper::from_system(scenes::cart_pole::SCENE, h).expect("valid scene");
    let start_cart = |stepper: &mut Stepper<scenes::cart_pole::CartPole, 2>| {
        stepper
            .start_from_velocity(vector![0.0, 0.2], vector![0.0, 0.0])
            .expect("finite start");
        stepper.set_input("u", 0.5).expect("input u");
    };
    start_cart(&mut cart_pole);
    group.bench_function("cart_pole_midpoint", |b| {
        b.iter(|| {
            if cart_pole.steps() >= 10_000 {
                start_cart(&mut cart_pole);
            }
            black_box(cart_pole.step()).expect("step")
        })
    });
    let rlc = scenes::circuit::rlc(scenes::circuit::LC, 0.5).expect("valid scene");
    let mut circuit = Stepper::new(rlc, Quadrature::midpoint(), h).expect("valid scene");
    let start_circuit = |stepper: &mut Stepper<scenes::circuit::Rlc, 6>| {
        stepper
            .start_from_velocity(scenes::circuit::rlc_q0(), SVector::zeros())
            .expect("finite start");
        stepper.set_inputs(&[1.0]).expect("the source");
    };
    start_circuit(&mut circuit);
    group.bench_function("rlc_midpoint", |b| {
        b.iter(|| {
            if circuit.steps() >= 10_000 {
                start_circuit(&mut circuit);
            }
            black_box(circuit.step()).expect("step")
        })
    });
    let mut satellite = Stepper::on_manifold(
        scenes::satellite::SCENE,
        Product::cayley(),
        Quadrature::midpoint(),
        h,
    )
    .expect("valid scene");
    let start_satellite =
        |stepper: &mut ManifoldStepper<scenes::satellite::Satellite, 3, Product<0, 1, 0>>| {
            stepper
                .start_from_velocity(
                    Configuration::of_rotation(Matrix3::identity()),
                    Rates::of_rotation(Vector3::new(0.3, 1.0, -0.5)),
                )
                .expect("finite start");
            stepper.set_inputs(&[0.01, -0.02, 0.03]).expect("torques");
        };
    start_satellite(&mut satellite);
    group.bench_function("satellite_midpoint", |b| {
        b.iter(|| {
            if satellite.steps() >= 10_000 {
                start_satellite(&mut satellite);
            }
            black_box(satellite.step()).expect("step")
        })
    });
    group.finish();
}

/// One Kepler step (e = 0.5, h = 0.01), restarted every 10 000 steps.
fn kepler_step<E: StepEquations<2, System = scenes::kepler::Kepler, Manifold = Vectors>>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    mut stepper: Stepper<scenes::kepler::Kepler, 2, E>,
) {
    let start = |stepper: &mut Stepper<scenes::kepler::Kepler, 2, E>| {
        stepper
            .start_from_momentum(scenes::kepler::q0(), scenes::kepler::p0())
            .expect("finite start")
    };
    start(&mut stepper);
    group.bench_function(name, |b| {
        b.iter(|| {
            if stepper.steps() >= 10_000 {
                start(&mut stepper);
            }
            black_box(stepper.step()).expect("step")
        })
    });
}

/// The explicit variational step of a separable Lagrangian against the implicit step of the
/// same order on Kepler's problem: Störmer–Verlet against the trapezoidal rule (the same map,
/// `tests/suite/explicit.rs`), Kahan–Li 8 against `galerkin(4)` (order 8), Sofroniou–Spaletta 10
/// against `galerkin(5)` (order 10).
fn explicit(c: &mut Criterion) {
    let mut group = c.benchmark_group("explicit_step");
    let (scene, h) = (scenes::kepler::SCENE, 0.01);
    let cases = [
        ("order_2", Composition::verlet(), Quadrature::trapezoid()),
        (
            "order_8",
            Composition::kahan_li_8(),
            Quadrature::galerkin(4).expect("degree 4"),
        ),
        (
            "order_10",
            Composition::sofroniou_spaletta_10(),
            Quadrature::galerkin(5).expect("degree 5"),
        ),
    ];
    for (order, composition, quadrature) in cases {
        // The same composition written by hand for this model: a plain loop over
        // `p += γh/2 g(q)`, `q += γh p`, `p += γh/2 g(q)` with adjacent kicks merged and the
        // gradient carried to the next step, no compensated sums, no checks.
        let mut hand = HandComposition::start(composition.coefficients(), h);
        let explicit = Stepper::explicit(scene, composition, h).expect("separable scene");
        kepler_step(&mut group, &format!("kepler_{order}/explicit"), explicit);
        let implicit = Stepper::new(scene, quadrature.clone(), h).expect("valid scene");
        kepler_step(&mut group, &format!("kepler_{order}/implicit"), implicit);
        // The implicit step solved by fixed-point iteration, without a Jacobian.
        let iterated = Stepper::new(scene, quadrature, h)
            .and_then(Stepper::with_fixed_point)
            .expect("separable scene");
        kepler_step(&mut group, &format!("kepler_{order}/fixed_point"), iterated);
        group.bench_function(format!("kepler_{order}/hand_written"), |b| {
            b.iter(|| {
                if hand.steps >= 10_000 {
                    hand = HandComposition::start(&hand.gammas, h);
                }
                hand.step();
                black_box(&hand.q);
            })
        });
    }
    group.finish();
}

/// A composition of Störmer–Verlet steps on Kepler's problem (μ = 1), by hand.
struct HandComposition {
    /// The composition's coefficients `γ_i`.
    gammas: Vec<f64>,
    h: f64,
    q: [f64; 2],
    p: [f64; 2],
    g: [f64; 2],
    steps: u64,
}

impl HandComposition {
    fn gradient(q: [f64; 2]) -> [f64; 2] {
        let r2 = q[0] * q[0] + q[1] * q[1];
        let k = -1.0 / (r2 * r2.sqrt());
        [k * q[0], k * q[1]]
    }

    fn start(gammas: &[f64], h: f64) -> Self {
        let (q, p) = (scenes::kepler::q0(), scenes::kepler::p0());
        let q = [q[0], q[1]];
        Self {
            gammas: gammas.to_vec(),
            h,
            q,
            p: [p[0], p[1]],
            g: Self::gradient(q),
            steps: 0,
        }
    }

    fn step(&mut self) {
        let h = self.h;
        let mut kick = 0.5 * self.gammas[0] * h;
        for (i, &gamma) in self.gammas.iter().enumerate() {
            for k in 0..2 {
                self.p[k] += kick * self.g[k];
                self.q[k] += gamma * h * self.p[k];
            }
            self.g = Self::gradient(self.q);
            kick = 0.5 * gamma * h + self.gammas.get(i + 1).map_or(0.0, |&g| 0.5 * g * h);
        }
        for k in 0..2 {
            self.p[k] += kick * self.g[k];
        }
        self.steps += 1;
    }
}

/// One time-transformed step (`dt/ds = |q|`, the logarithmic Hamiltonian) on Kepler's orbit of
/// eccentricity 0.9, 32 fictive steps a revolution: `TimeTransformed` against the same
/// drift–kick–drift composition written by hand (no compensated sums, no checks).
fn time_transformed(c: &mut Criterion) {
    let mut group = c.benchmark_group("time_transformed_step");
    let (e, ds) = (0.9, std::f64::consts::TAU / 32.0);
    let q0 = vector![1.0 - e, 0.0];
    let v0 = vector![0.0, ((1.0 + e) / (1.0 - e)).sqrt()];
    for (order, composition) in [
        ("order_2", Composition::verlet()),
        ("order_8", Composition::kahan_li_8()),
    ] {
        let mut hand = HandLogH::start(composition.coefficients(), ds, q0, v0);
        let mut stepper =
            TimeTransformed::new(scenes::kepler::SCENE, composition, ds).expect("separable scene");
        stepper.start_from_velocity(q0, v0).expect("finite start");
        group.bench_function(format!("kepler_e0.9_{order}/time_transformed"), |b| {
            b.iter(|| {
                if stepper.steps() >= 10_000 {
                    stepper.start_from_velocity(q0, v0).expect("finite start");
                }
                black_box(stepper.step()).expect("step")
            })
        });
        group.bench_function(format!("kepler_e0.9_{order}/hand_written"), |b| {
            b.iter(|| {
                if hand.steps >= 10_000 {
                    hand = HandLogH::start(&hand.gammas, ds, q0, v0);
                }
                hand.step();
                black_box(&hand.q);
            })
        });
    }
    group.finish();
}

/// The logarithmic-Hamiltonian composition on Kepler's problem (μ = 1), by hand: per stage
/// `q += (γ δs/2) p/W, t += (γ δs/2)/W` with `W = |p|²/2 − E`, `p += γ δs ∇(1/|q|)·|q|`, and the
/// same drift again (adjacent drifts merged).
struct HandLogH {
    gammas: Vec<f64>,
    ds: f64,
    energy: f64,
    t: f64,
    q: [f64; 2],
    p: [f64; 2],
    steps: u64,
}

impl HandLogH {
    fn start(gammas: &[f64], ds: f64, q: SVector<f64, 2>, v: SVector<f64, 2>) -> Self {
        let energy = 0.5 * v.norm_squared() - 1.0 / q.norm();
        Self {
            gammas: gammas.to_vec(),
            ds,
            energy,
            t: 0.0,
            q: [q[0], q[1]],
            p: [v[0], v[1]],
            steps: 0,
        }
    }

    fn drift(&mut self, by: f64) {
        let w = 0.5 * (self.p[0] * self.p[0] + self.p[1] * self.p[1]) - self.energy;
        let rate = by / w;
        self.t += rate;
        self.q[0] += rate * self.p[0];
        self.q[1] += rate * self.p[1];
    }

    fn step(&mut self) {
        let ds = self.ds;
        let mut drift = 0.5 * self.gammas[0] * ds;
        for i in 0..self.gammas.len() {
            let gamma = self.gammas[i];
            self.drift(drift);
            // p += γ δs F/U with F = −q/|q|³, U = 1/|q|: F/U = −q/|q|².
            let k = -gamma * ds / (self.q[0] * self.q[0] + self.q[1] * self.q[1]);
            self.p[0] += k * self.q[0];
            self.p[1] += k * self.q[1];
            drift = 0.5 * gamma * ds + self.gammas.get(i + 1).map_or(0.0, |&g| 0.5 * g * ds);
        }
        self.drift(drift);
        self.steps += 1;
    }
}

/// One step of the sine-Gordon field (Störmer–Verlet, Δx = 0.05, Δt = 0.02, periodic, started
/// from `u = sin x`) by number of cells: `Field` one cell after another and in parallel, and
/// cells of degree 3 with as many nodes, against a hand-written leapfrog of the same scheme
/// (`scenes::field::leapfrog_sine_gordon`).
fn field(c: &mut Criterion) {
    use dirac::{Boundary, Field};
    use scenes::field::{SineGordon, leapfrog_sine_gordon, sine_gordon_force};
    let mut group = c.benchmark_group("field_step");
    group.sample_size(20);
    let (dx, dt) = (0.05, 0.02);
    for cells in [1_000, 10_000, 100_000, 1_000_000] {
        let length = cells as f64 * dx;
        let u0: Vec<f64> = (0..cells).map(|j| (j as f64 * dx).sin()).collect();
        for parallel in [false, true] {
            let mut field = Field::new(SineGordon, (0.0, length), cells, Boundary::Periodic, dt)
                .expect("valid field")
                .with_parallel(parallel);
            let u: Vec<SVector<f64, 1>> = u0.iter().map(|&u| SVector::from([u])).collect();
            field
                .start(&u, &vec![SVector::zeros(); cells])
                .expect("finite start");
            let name = if parallel { "parallel" } else { "sequential" };
            group.bench_with_input(BenchmarkId::new(name, cells), &cells, |b, _| {
                b.iter(|| black_box(field.step()).expect("step"))
            });
        }
        if (10_000..=100_000).contains(&cells) {
            // Cells of degree 3 with as many nodes (a third as many cells, three times as wide).
            let mut field =
                Field::new(SineGordon, (0.0, length), cells / 3, Boundary::Periodic, dt)
                    .and_then(|field| field.with_degree(3))
                    .expect("valid field");
            let u: Vec<SVector<f64, 1>> = (field.positions().iter())
                .map(|&x| SVector::from([x.sin()]))
                .collect();
            field
                .start(&u, &vec![SVector::zeros(); u.len()])
                .expect("finite start");
            group.bench_with_input(BenchmarkId::new("degree_3", cells), &cells, |b, _| {
                b.iter(|| black_box(field.step()).expect("step"))
            });
        }
        let (mut u, mut p, mut force) = (u0.clone(), vec![0.0; cells], vec![0.0; cells]);
        sine_gordon_force(&u, &mut force, dx);
        group.bench_with_input(BenchmarkId::new("hand_written", cells), &cells, |b, _| {
            b.iter(|| {
                leapfrog_sine_gordon(&mut u, &mut p, &mut force, dx, dt);
                black_box(&u);
            })
        });
    }
    group.finish();
}

/// One step of the membrane (Störmer–Verlet, square cells Δx = 0.01, Δt = 0.005, periodic,
/// started from a standing wave) by number of nodes, 10⁴ to 10⁶: `PlaneField` row by row on one
/// thread and, from 10⁵ nodes (several bands of rows), in parallel, and cells of degree 3 (10⁴
/// and 10⁵ nodes, at a fifth of the step, below their stability limit), against a hand-written
/// five-point leapfrog of the same scheme (`scenes::membrane::leapfrog_membrane`).
fn plane_field(c: &mut Criterion) {
    use dirac::{Boundary, PlaneField};
    use scenes::membrane::{DRUM, laplacian, leapfrog_membrane};
    let mut group = c.benchmark_group("plane_field_step");
    group.sample_size(10);
    let (dx, dt) = (0.01, 0.005);
    for side in [100, 316, 1000] {
        let nodes = side * side;
        let length = side as f64 * dx;
        let u0: Vec<f64> = (0..nodes)
            .map(|k| ((k % side) as f64 * dx).sin() * ((k / side) as f64 * dx).cos())
            .collect();
        // A field of 10⁴ nodes is one band: its parallel step is the sequential one.
        for parallel in [false, true]
            .into_iter()
            .take(if nodes < 50_000 { 1 } else { 2 })
        {
            let periodic = [Boundary::Periodic; 2];
            let sides = [(0.0, length); 2];
            let mut drum = PlaneField::new(DRUM, sides, [side, side], periodic, dt)
                .expect("valid field")
                .with_parallel(parallel);
            let u: Vec<SVector<f64, 1>> = u0.iter().map(|&u| SVector::from([u])).collect();
            drum.start(&u, &vec![SVector::zeros(); nodes])
                .expect("finite start");
            let name = if parallel { "parallel" } else { "sequential" };
            group.bench_with_input(BenchmarkId::new(name, nodes), &nodes, |b, _| {
                b.iter(|| black_box(drum.step()).expect("step"))
            });
        }
        if side <= 316 {
            // Cells of degree 3 with about as many nodes (3 × 3 points a cell), the step below
            // their stability limit.
            let periodic = [Boundary::Periodic; 2];
            let cells = side / 3;
            let mut drum =
                PlaneField::new(DRUM, [(0.0, length); 2], [cells, cells], periodic, 0.2 * dt)
                    .and_then(|drum| drum.with_degree(3))
                    .expect("valid field");
            let u: Vec<SVector<f64, 1>> = (drum.points().into_iter())
                .map(|[x, y]| SVector::from([x.sin() * y.cos()]))
                .collect();
            drum.start(&u, &vec![SVector::zeros(); u.len()])
                .expect("finite start");
            // Named by the box cells' node count beside it (it holds 2 % fewer: 99², 315²).
            group.bench_with_input(BenchmarkId::new("degree_3", nodes), &u.len(), |b, _| {
                b.iter(|| black_box(drum.step()).expect("step"))
            });
        }
        let (mut u, mut p, mut force) = (u0.clone(), vec![0.0; nodes], vec![0.0; nodes]);
        laplacian(&u, &mut force, side, [dx, dx]);
        group.bench_with_input(BenchmarkId::new("hand_written", nodes), &nodes, |b, _| {
            b.iter(|| {
                leapfrog_membrane([&mut u, &mut p, &mut force], side, [dx, dx], dt);
                black_box(&u);
            })
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    explicit,
    fixed_point_rows,
    time_transformed,
    forced,
    modular,
    field,
    plane_field,
    interconnection,
    routes,
    lie_group,
    sphere,
    recording,
    generated_vs_hand,
    quadratures,
    chain_growth,
    mechanism,
    constrained,
    step_derivatives,
    newer_classes
);

/// The benchmarks on a thread with a large stack: the hyper-dual numbers of the 64-link chain
/// carry a 64 × 64 block each, megabytes per vector of them.
fn main() {
    std::thread::Builder::new()
        .stack_size(1 << 30)
        .spawn(|| {
            benches();
            Criterion::default().configure_from_args().final_summary();
        })
        .expect("a thread for the benchmarks")
        .join()
        .expect("the benchmarks ran");
}
