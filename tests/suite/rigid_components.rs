//! Rigid bodies as components of a modular interconnection: a body on `SO(3)` alone by parts
//! steps as on its own; joined to a flywheel by a shaft along its third axis it steps the
//! equations of the one model on `R × SO(3)` (junction held at `Start`), converges at second
//! order to an independent reference (midpoint), moves as the free body where the shaft's force
//! vanishes, and keeps Tellegen's theorem; what it cannot do is refused.

use dirac::modular::Modular;
use dirac::nalgebra::DVector;
use dirac::prelude::*;
use scenes::components::{Capacitor, Flywheel, Inductor, Modulated};
use scenes::rigid_body::{self, ASYMMETRIC, SYMMETRIC};
use scenes::shafted_body::{self, BodyOnShaft, WHEEL, attitude, by_parts};

/// A rotation's nine entries, row by row (a component's positions).
fn flat(r: &Matrix3<f64>) -> Vec<f64> {
    r.transpose().iter().copied().collect()
}

#[test]
fn a_rigid_body_alone_by_parts_steps_as_on_its_own() {
    let (h, begin) = (0.01, rigid_body::free_start());
    for space in [Product::cayley(), Product::exp()] {
        let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
        parts.add_on_space("body", ASYMMETRIC, space).unwrap();
        assert_eq!(
            parts.coordinate_names(),
            ["body.R_x", "body.R_y", "body.R_z"]
        );
        assert_eq!(parts.position_names()[1], "body.R_12");
        parts
            .start_from_velocity(&flat(&begin.0), begin.1.as_slice())
            .unwrap();
        let mut alone =
            rigid_body::started(ASYMMETRIC, space, Quadrature::midpoint(), h, begin).unwrap();
        let mut worst: f64 = 0.0;
        for _ in 0..2000 {
            parts.step().unwrap();
            alone.step().unwrap();
            let (q, p) = (alone.q(), alone.p());
            worst = worst
                .max((attitude(&parts.q()) - q.rotation[0]).amax())
                .max((parts.p() - DVector::from_column_slice(p.rotation[0].as_slice())).amax());
        }
        let v = alone.v().unwrap().rotation[0];
        let apart = (parts.velocities().unwrap() - DVector::from_column_slice(v.as_slice())).amax();
        println!("{space:?}: the body by parts and alone apart by {worst:e}, velocities {apart:e}");
        assert!(worst < 1e-13 && apart < 1e-13, "{worst:e}, {apart:e}");
    }
}

#[test]
fn a_component_on_r_times_so3_with_its_own_one_form_steps_as_on_its_own() {
    // The shafted body written as one model, with its one-form, as the only component.
    let (h, (r0, w0)) = (0.01, rigid_body::free_start());
    let model = BodyOnShaft {
        body: ASYMMETRIC,
        wheel: WHEEL,
    };
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts
        .add_on_space("both", model, Product::cayley())
        .unwrap();
    assert_eq!(
        parts.coordinate_names(),
        ["both.theta", "both.R_x", "both.R_y", "both.R_z"]
    );
    let q: Vec<f64> = std::iter::once(0.0).chain(flat(&r0)).collect();
    parts
        .start_from_velocity(&q, &[w0[2], w0[0], w0[1], w0[2]])
        .unwrap();
    let mut alone = shafted_body::one_model(ASYMMETRIC, WHEEL, h, (r0, w0)).unwrap();
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        parts.step().unwrap();
        alone.step().unwrap();
        let (q, p) = (alone.q(), alone.p());
        let (mine, momenta) = (parts.q(), parts.p());
        let r = Matrix3::from_row_slice(&mine.as_slice()[1..10]);
        worst = worst
            .max((r - q.rotation[0]).amax())
            .max((mine[0] - q.vector[0]).abs())
            .max((momenta[0] - p.vector[0]).abs())
            .max((momenta.rows(1, 3) - p.rotation[0]).amax());
    }
    let (v, theirs) = (parts.velocities().unwrap(), alone.v().unwrap());
    let apart = (v[0] - theirs.vector[0])
        .abs()
        .max((v.rows(1, 3) - theirs.rotation[0]).amax());
    println!("R × SO(3) by parts and alone: apart by {worst:e}, velocities {apart:e}");
    assert!(worst < 1e-13 && apart < 1e-12, "{worst:e}, {apart:e}");
}

#[test]
fn the_body_and_flywheel_by_parts_step_to_the_one_models_positions() {
    // The one model holds the shaft at the step's start, the parts half at each end: the same
    // positions and velocities, its multiplier the average of two of theirs, its momenta theirs
    // less the half impulse the last step left at its end.
    let (h, begin) = (0.01, rigid_body::free_start());
    let mut parts = by_parts(ASYMMETRIC, WHEEL, Product::cayley(), h).unwrap();
    shafted_body::start(&mut parts, begin).unwrap();
    let mut one = shafted_body::one_model(ASYMMETRIC, WHEEL, h, begin).unwrap();
    let (mut worst, mut impulse, mut before): (f64, f64, f64) = (0.0, 0.0, 0.0);
    let mut evaluations = (0, 0);
    for _ in 0..2000 {
        parts.step().unwrap();
        one.step().unwrap();
        evaluations.0 += parts.report().unwrap().iterations;
        evaluations.1 += one.last_report().unwrap().iterations;
        let (q, p) = (one.q(), one.p());
        let (mine, momenta) = (parts.q(), parts.p());
        let mu = parts.multipliers().unwrap()[0];
        // The parts' coordinates are (Ω, θ), the one model's (θ, Ω).
        let half = 0.5 * mu;
        worst = worst
            .max((attitude(&mine) - q.rotation[0]).amax())
            .max((mine[9] - q.vector[0]).abs())
            .max((0.5 * (before + mu) - one.multipliers()[0]).abs())
            .max((momenta[0] - p.rotation[0][0]).abs())
            .max((momenta[1] - p.rotation[0][1]).abs())
            .max((momenta[2] - half - p.rotation[0][2]).abs())
            .max((momenta[3] + half - p.vector[0]).abs());
        impulse = impulse.max(mu.abs());
        before = mu;
    }
    let (v, theirs) = (parts.velocities().unwrap(), one.v().unwrap());
    let apart = (v.rows(0, 3) - theirs.rotation[0])
        .amax()
        .max((v[3] - theirs.vector[0]).abs());
    println!(
        "by parts and as one model: apart by {worst:e}, velocities {apart:e} (impulses up to \
         {impulse:e})"
    );
    assert!(
        worst < 1e-12 && apart < 1e-12,
        "apart by {worst:e}, {apart:e}"
    );
    assert!(impulse > 1e-4, "the shaft carries a force: {impulse:e}");
    // The parts' multipliers alternate about the one model's (a mode of the start); predicted
    // from the smooth node impulses, Newton's method takes as many evaluations as for the one
    // model.
    println!("Newton evaluations over 2 000 steps: by parts {evaluations:?} (parts, one model)");
    assert!(evaluations.0 <= evaluations.1, "{evaluations:?}");
}

/// The attitude error of the body and the flywheel by parts at `t_end` against Dop853 at
/// 1e-13, for each step in `steps`.
fn errors(steps: &[f64], t_end: f64) -> Vec<f64> {
    let begin = rigid_body::free_start();
    let (r, _) = shafted_body::reference(&ASYMMETRIC, WHEEL, begin, t_end, 1e-13).unwrap();
    steps
        .iter()
        .map(|&h| {
            let mut parts = by_parts(ASYMMETRIC, WHEEL, Product::cayley(), h).unwrap();
            shafted_body::start(&mut parts, begin).unwrap();
            parts.run((t_end / h).round() as u64).unwrap();
            (attitude(&parts.q()) - r).amax()
        })
        .collect()
}

#[test]
fn the_body_and_flywheel_by_parts_converge_at_second_order() {
    let steps = [0.02, 0.01, 0.005];
    let found = errors(&steps, 2.0);
    let slopes: Vec<f64> = found.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
    println!("errors {found:?}, slopes {slopes:?}");
    assert!(
        slopes.iter().all(|s| (1.9..2.1).contains(s)) && found[2] < 1e-4,
        "errors {found:?}, slopes {slopes:?}"
    );
}

#[test]
fn a_symmetric_body_on_the_shaft_moves_as_the_free_body() {
    // With I₁ = I₂ the shaft's force vanishes: the body's closed form, the wheel at Ω₃.
    let (r0, w0) = rigid_body::free_start();
    let t_end = 2.0;
    let exact = rigid_body::symmetric(&SYMMETRIC, &r0, &w0, t_end);
    let mut found = Vec::new();
    for h in [0.02, 0.01] {
        let mut parts = by_parts(SYMMETRIC, WHEEL, Product::cayley(), h).unwrap();
        shafted_body::start(&mut parts, (r0, w0)).unwrap();
        let mut force: f64 = 0.0;
        for _ in 0..(t_end / h).round() as u64 {
            parts.step().unwrap();
            force = force.max(parts.multipliers().unwrap()[0].abs());
        }
        let q = parts.q();
        let v = parts.velocities().unwrap();
        let error = (attitude(&q) - exact).amax();
        let wheel = (q[9] - w0[2] * t_end).abs();
        println!(
            "h = {h}: |R − R_exact| = {error:.3e}, wheel angle off by {wheel:.3e}, \
             Ω₃ − θ̇ = {:.1e}, shaft impulse up to {force:.1e}",
            v[2] - v[3]
        );
        found.push((error, wheel, force));
    }
    // The attitude, the wheel and the shaft's impulse (zero in the limit) all at second order.
    let order = |f: fn(&(f64, f64, f64)) -> f64| (f(&found[0]) / f(&found[1])).log2();
    let (attitude, wheel, force) = (order(|e| e.0), order(|e| e.1), order(|e| e.2));
    println!("orders: attitude {attitude:.3}, wheel {wheel:.3}, shaft impulse {force:.3}");
    assert!(
        (1.9..2.1).contains(&attitude) && (1.9..2.1).contains(&wheel) && found[1].0 < 1e-4,
        "{found:?}"
    );
    assert!((1.9..2.1).contains(&force), "{found:?}");
}

#[test]
fn the_shaft_keeps_tellegens_theorem_and_the_energy_stays_bounded() {
    let begin = rigid_body::free_start();
    let mut drifts = Vec::new();
    for h in [0.02, 0.01] {
        let mut parts = by_parts(ASYMMETRIC, WHEEL, Product::cayley(), h).unwrap();
        shafted_body::start(&mut parts, begin).unwrap();
        let e0: f64 = parts.energies().unwrap().iter().sum();
        let (mut tellegen, mut work, mut drift): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for _ in 0..(50.0 / h).round() as u64 {
            parts.step().unwrap();
            tellegen = tellegen.max(shafted_body::tellegen_in_ulps(&parts).unwrap());
            work = work.max(parts.ports().unwrap().scale);
            let e: f64 = parts.energies().unwrap().iter().sum();
            drift = drift.max((e - e0).abs() / e0);
        }
        println!(
            "h = {h}: Tellegen {tellegen:.2} ε|e|(|θ| + 1) (port work up to {work:.1e}); energy \
             within {drift:.2e} of its start to T = 50"
        );
        // The net work is the rounding of the wheel's stored angle that its step is read from.
        assert!(tellegen < 4.0 && work > 1e-6, "{tellegen}, {work:e}");
        drifts.push(drift);
    }
    // Bounded and of second order, not growing with the steps.
    let order = (drifts[0] / drifts[1]).log2();
    assert!((1.8..2.2).contains(&order), "{drifts:?}");
}

#[test]
fn what_a_rigid_component_cannot_do_is_refused() {
    let h = 0.01;
    // Unit vectors: their chart's frame turns with the point.
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    let sphere = parts.add_on_space(
        "pendulum",
        scenes::spherical_pendulum::SphericalPendulum {
            m: 1.0,
            l: 1.0,
            g: 9.81,
        },
        Product::<0, 0, 1>::cayley(),
    );
    assert!(
        matches!(&sphere, Err(DiracError::Unsupported(why)) if why.contains("unit vectors")),
        "{sphere:?}"
    );
    // Positions must be a rotation's nine numbers and a rotation.
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts
        .add_on_space("body", ASYMMETRIC, Product::cayley())
        .unwrap();
    parts.add("wheel", Flywheel { i: WHEEL }).unwrap();
    let short = parts.start_from_velocity(&[0.0; 4], &[0.0; 4]);
    assert!(matches!(short, Err(DiracError::Dimension(_))), "{short:?}");
    let mut skewed = flat(&Matrix3::identity());
    skewed[1] = 0.1;
    skewed.push(0.0);
    let off = parts.start_from_velocity(&skewed, &[0.0; 4]);
    assert!(
        matches!(&off, Err(DiracError::InconsistentInitialState(why)) if why.contains("rotation")),
        "{off:?}"
    );
    // A shaft the start's velocity does not satisfy.
    parts
        .join(
            Junction::new("shaft")
                .flow("body.R_z", 1.0)
                .flow("wheel.theta", -1.0),
        )
        .unwrap();
    let mut identity = flat(&Matrix3::identity());
    identity.push(0.0);
    let violated = parts.start_from_velocity(&identity, &[0.0, 0.0, 1.0, 0.5]);
    assert!(
        matches!(&violated, Err(DiracError::InconsistentInitialState(why)) if why.contains("shaft")),
        "{violated:?}"
    );
    // A space without rotations belongs to `add`.
    let flat_space = Modular::new(Quadrature::midpoint(), h)
        .unwrap()
        .add_on_space("wheel", Flywheel { i: WHEEL }, Euclidean);
    assert!(
        matches!(&flat_space, Err(DiracError::Unsupported(why)) if why.contains("add")),
        "{flat_space:?}"
    );
    // A coordinate without kinetic energy on a space of rotations.
    let mut parts = Modular::new(Quadrature::midpoint(), h).unwrap();
    parts
        .add_on_space("body", SpringOnBody, Product::cayley())
        .unwrap();
    let q: Vec<f64> = std::iter::once(0.0)
        .chain(flat(&Matrix3::identity()))
        .collect();
    let dead = parts.start_from_velocity(&q, &[0.0, 0.0, 0.0, 1.0]);
    assert!(
        matches!(&dead, Err(DiracError::Unsupported(why)) if why.contains("body") && why.contains("kinetic")),
        "{dead:?}"
    );
}

/// A body with a spring coordinate beside it (no kinetic energy): `L = ½|Ω|² − ½ x²`.
struct SpringOnBody;

impl DiracSystem<4, Product<1, 1, 0>> for SpringOnBody {
    fn lagrangian<D: Scalar>(&self, q: &Configuration<D, 1, 1, 0>, v: &Rates<D, 1, 1, 0>) -> D {
        v.rotation[0].dot(&v.rotation[0]) * 0.5 - q.vector[0] * q.vector[0] * 0.5
    }
}

#[test]
fn components_after_a_body_are_read_at_their_own_positions() {
    // Positions (a rotation's nine numbers) and coordinates (three) part after a body: the
    // hidden constraint of two capacitors in parallel, one modulated in time, is found and
    // refused from q = 0 only if its probe moves the capacitors' own positions.
    let mut parts = Modular::new(Quadrature::midpoint(), 0.01).unwrap();
    parts
        .add_on_space("body", ASYMMETRIC, Product::cayley())
        .unwrap();
    parts.add("l", Inductor { l: 1.0 }).unwrap();
    parts.add("a", Capacitor { c: 1.0 }).unwrap();
    parts.add("m", Modulated).unwrap();
    parts
        .join(
            Junction::new("kcl")
                .flow("l.q", 1.0)
                .flow("a.q", -1.0)
                .flow("m.q", -1.0),
        )
        .unwrap();
    let q: Vec<f64> = flat(&Matrix3::identity())
        .into_iter()
        .chain([0.0; 3])
        .collect();
    let error = parts.start_from_velocity(&q, &[0.1, 0.2, 0.3, 0.0, 0.0, 0.0]);
    assert!(
        matches!(&error, Err(DiracError::Unsupported(why)) if why.contains("m.q") && why.contains("depend on time")),
        "{error:?}"
    );
    // The body and the wheel included after a mass step as on their own.
    let (h, begin) = (0.01, rigid_body::free_start());
    let mut outer = Modular::new(Quadrature::midpoint(), h).unwrap();
    outer
        .add("mass", scenes::components::Mass { m: 1.0 })
        .unwrap();
    outer
        .include(
            "ship",
            by_parts(ASYMMETRIC, WHEEL, Product::cayley(), h).unwrap(),
        )
        .unwrap();
    assert_eq!(outer.positions(), 11);
    assert_eq!(outer.position_names()[1], "ship.body.R_11");
    assert_eq!(outer.position_names()[10], "ship.wheel.theta");
    let mut alone = by_parts(ASYMMETRIC, WHEEL, Product::cayley(), h).unwrap();
    shafted_body::start(&mut alone, begin).unwrap();
    let q: Vec<f64> = std::iter::once(0.5)
        .chain(alone.q().iter().copied())
        .collect();
    let v = [0.25, begin.1[0], begin.1[1], begin.1[2], begin.1[2]];
    outer.start_from_velocity(&q, &v).unwrap();
    for _ in 0..300 {
        outer.step().unwrap();
        alone.step().unwrap();
    }
    let (mine, theirs) = (outer.q(), alone.q());
    assert_eq!(mine.rows(1, 10), theirs.rows(0, 10));
    assert!(
        (mine[0] - (0.5 + 0.25 * 300.0 * h)).abs() < 1e-12,
        "{}",
        mine[0]
    );
    assert_eq!(outer.p().rows(1, 4), alone.p().rows(0, 4));
}
