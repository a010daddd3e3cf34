//! Joints: mechanisms in maximal coordinates, stepped by the modular step.
//!
//! A joint is held as SHAKE holds a model's own holonomic constraint, so a mechanism of joined
//! components steps exactly the equations of one model with its joints as holonomic
//! constraints: checked to round-off on the pendulum, trep's two-link chain and a four-bar
//! linkage. trep's n-link chain in maximal coordinates converges at second order to the chain
//! in reduced coordinates; a chain of rigid bodies in space keeps its vertical angular momentum
//! to round-off (the discrete Noether theorem); the loops close at every step.

use dirac::nalgebra::Rotation3;
use dirac::prelude::*;
use scenes::cartesian_pendulum::CartesianPendulum;
use scenes::chain::Chain;
use scenes::mechanism::{self, FourBarMonolithic, PlanarMass, PointChain2};

/// A ball joint between the point `a` of body `i` (`None`: the origin) and `b` of body `j`.
type Ball = (Option<usize>, [f64; 3], usize, [f64; 3]);

/// The largest distance between the points `a` of body `i` and `b` of body `j` (`None`: the
/// origin) over `pairs`, read off the positions `q` (each body's centre, then its attitude row
/// by row).
fn ball_gaps(q: &[f64], pairs: &[Ball]) -> f64 {
    let point = |body: usize, a: [f64; 3]| {
        let q = &q[12 * body..12 * body + 12];
        let r = Matrix3::from_row_slice(&q[3..12]);
        Vector3::new(q[0], q[1], q[2]) + r * Vector3::from(a)
    };
    let gaps = pairs.iter().map(|&(i, a, j, b)| {
        let first = i.map_or(Vector3::zeros(), |i| point(i, a));
        (first - point(j, b)).amax()
    });
    gaps.fold(0.0, f64::max)
}

/// A mechanism and the one model with its joints as holonomic constraints, both started from
/// the positions and velocities `(q0, v0)` and stepped by the midpoint rule with step `h`.
fn started<S: DiracSystem<N>, const N: usize>(
    mut joined: Modular,
    model: S,
    h: f64,
    (q0, v0): (Vec<f64>, Vec<f64>),
) -> (Modular, Stepper<S, N>) {
    let mut one = Stepper::new(model, Quadrature::midpoint(), h).unwrap();
    joined.start_from_velocity(&q0, &v0).unwrap();
    let (q0, v0) = (
        SVector::from_column_slice(&q0),
        SVector::from_column_slice(&v0),
    );
    one.start_from_velocity(q0, v0).unwrap();
    (joined, one)
}

/// trep's start of an `n`-link chain of unit rods: straight and level, at rest.
fn straight(n: usize) -> (Vec<f64>, Vec<f64>) {
    let theta = vec![std::f64::consts::FRAC_PI_2; n];
    mechanism::point_chain_state(&theta, &vec![0.0; n], 1.0)
}

/// The largest entry of `a − b`.
fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_rod_joint_steps_the_equations_of_the_holonomic_pendulum() {
    let (g, h) = (1.0, 0.05);
    let mut joined = Modular::new(Quadrature::midpoint(), h).unwrap();
    joined.add("bob", PlanarMass { m: 1.0, g }).unwrap();
    let rod = Joint::rod(
        "rod",
        Anchor::fixed([0.0, 0.0]),
        Anchor::point("bob", ["x", "y"]),
        1.0,
    );
    joined.connect(rod).unwrap();
    let pendulum = CartesianPendulum { m: 1.0, l: 1.0, g };
    let (s, c) = 1.2_f64.sin_cos();
    let (mut joined, mut one) = started(joined, pendulum, h, (vec![s, -c], vec![0.0, 0.0]));
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        joined.step().unwrap();
        one.step().unwrap();
        worst = worst.max(distance(joined.q().as_slice(), one.q().as_slice()));
        let q = joined.q();
        assert!((q[0].hypot(q[1]) - 1.0).abs() < 1e-13);
        assert!(joined.constraint_violation().unwrap() < 1e-13);
    }
    assert!(worst < 1e-13, "joined and one model differ by {worst:.2e}");
    let v = joined.velocities().unwrap();
    let w = one.v().unwrap();
    assert!(distance(v.as_slice(), w.as_slice()) < 1e-11);
}

#[test]
fn trep_s_two_link_chain_joined_steps_as_one_model_with_holonomic_rods() {
    let (m, l, g, h) = (1.0, 1.0, 9.81, 0.01);
    let chain = mechanism::point_chain(2, m, l, g, h).unwrap();
    let (mut joined, mut one) = started(chain, PointChain2 { m, l, g }, h, straight(2));
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        joined.step().unwrap();
        one.step().unwrap();
        worst = worst.max(distance(joined.q().as_slice(), one.q().as_slice()));
        assert!(joined.constraint_violation().unwrap() < 1e-12);
    }
    assert!(worst < 1e-12, "joined and one model differ by {worst:.2e}");
}

#[test]
fn the_four_bar_closes_its_loop_at_every_step_as_one_model_does() {
    let [a, b, c, d] = mechanism::FOUR_BAR;
    let (g, h) = (9.81, 0.002);
    let model = FourBarMonolithic { a, b, c, d, g };
    let start = mechanism::four_bar_state(1.0, 2.0);
    let (mut joined, mut one) = started(mechanism::four_bar(g, h).unwrap(), model, h, start);
    let energy = |joined: &Modular| {
        let (q, v) = (joined.q(), joined.velocities().unwrap());
        mechanism::four_bar_energy(q.as_slice(), v.as_slice(), g)
    };
    let e0 = energy(&joined);
    let (mut worst, mut drift): (f64, f64) = (0.0, 0.0);
    for k in 0..2000 {
        joined.step().unwrap();
        one.step().unwrap();
        worst = worst.max(distance(joined.q().as_slice(), one.q().as_slice()));
        assert!(joined.constraint_violation().unwrap() < 1e-12, "step {k}");
        if k % 100 == 99 {
            drift = drift.max((energy(&joined) - e0).abs() / e0.abs());
        }
    }
    // The crank has turned past a full revolution.
    assert!(
        joined.q()[2] > 1.0 + std::f64::consts::TAU,
        "crank at {}",
        joined.q()[2]
    );
    assert!(worst < 1e-11, "joined and one model differ by {worst:.2e}");
    assert!(
        drift < 1e-4,
        "the energy's relative error reached {drift:.2e}"
    );
}

/// The n-link chain of trep's scene, straight and level at rest, over `t` at step `h` in
/// maximal coordinates: its absolute angles at the end.
fn maximal_chain_angles<const L: usize>(h: f64, t: f64) -> Vec<f64> {
    let mut chain = mechanism::point_chain(L, 1.0, 1.0, 9.81, h).unwrap();
    let (q0, v0) = straight(L);
    chain.start_from_velocity(&q0, &v0).unwrap();
    let steps = (t / h).round() as u64;
    for _ in 0..steps {
        chain.step().unwrap();
        let q = chain.q();
        let angles = mechanism::point_chain_angles(q.as_slice());
        let (back, _) = mechanism::point_chain_state(&angles, &[0.0; L], 1.0);
        // Every rod keeps its length: the positions are those of their own angles.
        assert!(distance(&back, q.as_slice()) < 1e-12);
    }
    mechanism::point_chain_angles(chain.q().as_slice())
}

#[test]
fn trep_s_chain_in_maximal_coordinates_converges_to_the_reduced_chain_at_second_order() {
    const L: usize = 4;
    let t = 1.0;
    let system = Chain::<L> {
        m: 1.0,
        l: 1.0,
        g: 9.81,
    };
    let mut reference = Stepper::new(system, Quadrature::galerkin(3).unwrap(), 0.001).unwrap();
    let theta = SVector::<f64, L>::repeat(std::f64::consts::FRAC_PI_2);
    reference
        .start_from_velocity(theta, SVector::zeros())
        .unwrap();
    reference.run(1000).unwrap();
    let exact = reference.q();
    let errors: Vec<f64> = [0.01, 0.005, 0.0025]
        .iter()
        .map(|&h| distance(&maximal_chain_angles::<L>(h, t), exact.as_slice()))
        .collect();
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!((order - 2.0).abs() < 0.15, "order {order:.3} ({errors:?})");
    }
    // The reduced chain's midpoint rule has an error of the same size: both are second order.
    let mut reduced = Stepper::new(system, Quadrature::midpoint(), 0.01).unwrap();
    reduced
        .start_from_velocity(theta, SVector::zeros())
        .unwrap();
    reduced.run(100).unwrap();
    let theirs = distance(reduced.q().as_slice(), exact.as_slice());
    assert!(
        errors[0] < 10.0 * theirs && theirs < 10.0 * errors[0],
        "{errors:?} vs {theirs}"
    );
}

#[test]
fn a_chain_of_bodies_keeps_its_vertical_angular_momentum_to_round_off() {
    let (n, l, g, h) = (3, 1.0, 9.81, 0.01);
    let mut chain = mechanism::body_chain(n, 1.0, l, g, h).unwrap();
    let tilt = |a: f64, b: f64| {
        Rotation3::from_axis_angle(&Vector3::x_axis(), a)
            * Rotation3::from_axis_angle(&Vector3::y_axis(), b)
    };
    let attitudes: Vec<Matrix3<f64>> = (0..n)
        .map(|k| tilt(0.4 + 0.2 * k as f64, -0.3 * k as f64).into_inner())
        .collect();
    let omegas: Vec<Vector3<f64>> = (0..n)
        .map(|k| Vector3::new(0.5, -0.2 * k as f64, 1.0 + k as f64))
        .collect();
    let (q0, v0) = mechanism::body_chain_state(&attitudes, &omegas, l);
    chain.start_from_velocity(&q0, &v0).unwrap();
    let momentum = |chain: &Modular| {
        mechanism::body_chain_momentum(chain.q().as_slice(), chain.p().as_slice())
    };
    let j0 = momentum(&chain);
    let energy = |chain: &Modular| chain.energies().unwrap().iter().sum::<f64>();
    let e0 = energy(&chain);
    let (mut worst, mut drift): (f64, f64) = (0.0, 0.0);
    let (top, bottom) = ([0.0, 0.0, l / 2.0], [0.0, 0.0, -l / 2.0]);
    let balls: Vec<_> = (0..n).map(|k| (k.checked_sub(1), bottom, k, top)).collect();
    for k in 0..1000 {
        chain.step().unwrap();
        assert!(chain.constraint_violation().unwrap() < 1e-12, "step {k}");
        // The accepted positions themselves hold the joints.
        assert!(ball_gaps(chain.q().as_slice(), &balls) < 1e-12, "step {k}");
        worst = worst.max((momentum(&chain)[2] - j0[2]).abs());
        if k % 100 == 99 {
            drift = drift.max((energy(&chain) - e0).abs());
        }
    }
    assert!(
        j0[2].abs() > 0.1,
        "a chain turning about the vertical: {j0}"
    );
    assert!(
        worst < 1e-13,
        "the vertical angular momentum moved by {worst:.2e}"
    );
    // The horizontal components are not conserved (gravity's torque).
    assert!((momentum(&chain)[0] - j0[0]).abs() > 1e-3);
    assert!(
        drift < 0.05 * e0.abs().max(1.0),
        "energy error {drift:.2e} of {e0}"
    );
}

/// A chain of rods hinged about parallel axes, in space and in the plane, at step `h` over
/// 1 s: the largest distance between their centres (`y`, `z` of space against the plane's).
fn hinged_against_pinned(h: f64) -> f64 {
    let (n, l, g) = (3, 1.0, 9.81);
    let alpha = [0.9, 0.4, -0.2];
    let rates = [0.0, 1.0, -0.5];
    let mut hinged = mechanism::hinge_chain(n, 1.0, l, g, h).unwrap();
    let attitudes: Vec<Matrix3<f64>> = alpha
        .iter()
        .map(|&a| Rotation3::from_axis_angle(&Vector3::x_axis(), a).into_inner())
        .collect();
    let omegas: Vec<Vector3<f64>> = rates.iter().map(|&w| Vector3::new(w, 0.0, 0.0)).collect();
    let (q0, v0) = mechanism::body_chain_state(&attitudes, &omegas, l);
    hinged.start_from_velocity(&q0, &v0).unwrap();
    let mut pinned = mechanism::bar_chain(n, 1.0, l, g, h).unwrap();
    let (q0, v0) = mechanism::bar_chain_state(&alpha, &rates, l);
    pinned.start_from_velocity(&q0, &v0).unwrap();
    let steps = (1.0 / h).round() as u64;
    for k in 0..steps {
        hinged.step().unwrap();
        pinned.step().unwrap();
        assert!(hinged.constraint_violation().unwrap() < 1e-12, "step {k}");
        assert!(pinned.constraint_violation().unwrap() < 1e-12, "step {k}");
    }
    let (q, p) = (hinged.q(), pinned.q());
    let mut worst: f64 = 0.0;
    for b in 0..n {
        let (body, bar) = (
            &q.as_slice()[12 * b..12 * b + 12],
            &p.as_slice()[3 * b..3 * b + 3],
        );
        // The motion stays in the plane: x = 0, and the hinge axis R e_x = e_x.
        assert!(body[0].abs() < 1e-12, "x = {}", body[0]);
        assert!((body[3] - 1.0).abs() < 1e-12 && body[6].abs() < 1e-12 && body[9].abs() < 1e-12);
        worst = worst
            .max((body[1] - bar[0]).abs())
            .max((body[2] - bar[1]).abs());
    }
    worst
}

#[test]
fn hinged_rods_in_space_move_as_pinned_bars_in_the_plane() {
    // Two second-order discretisations of one motion (the Cayley chart in space, the angle in
    // the plane): their distance falls as h².
    let (coarse, fine) = (hinged_against_pinned(0.004), hinged_against_pinned(0.002));
    let order = (coarse / fine).log2();
    assert!(
        coarse < 2e-5 && (order - 2.0).abs() < 0.2,
        "{coarse:.2e}, {fine:.2e}: {order:.2}"
    );
}

#[test]
fn a_free_humanoid_tree_keeps_its_momenta_and_joints() {
    // Nine bodies, eight ball joints, no gravity: linear and angular momentum are conserved.
    let limbs = mechanism::HUMANOID;
    let mut tree = mechanism::tree(&limbs, 0.0, 0.005).unwrap();
    let (q0, v0) = mechanism::humanoid_start();
    tree.start_from_velocity(&q0, &v0).unwrap();
    let momenta =
        |tree: &Modular| mechanism::bodies_momenta(tree.q().as_slice(), tree.p().as_slice());
    let (linear0, angular0) = momenta(&tree);
    let (mut linear, mut angular): (f64, f64) = (0.0, 0.0);
    let balls: Vec<_> = limbs
        .iter()
        .enumerate()
        .filter_map(|(k, limb)| Some((Some(limb.parent?), limb.at_parent, k, limb.at_self)))
        .collect();
    for k in 0..2000 {
        tree.step().unwrap();
        assert!(tree.constraint_violation().unwrap() < 1e-12, "step {k}");
        assert!(ball_gaps(tree.q().as_slice(), &balls) < 1e-12, "step {k}");
        let (l, a) = momenta(&tree);
        linear = linear.max((l - linear0).amax());
        angular = angular.max((a - angular0).amax());
    }
    assert!(
        linear0.norm() > 1.0 && angular0.norm() > 1.0,
        "{linear0}, {angular0}"
    );
    assert!(
        linear < 1e-12 && angular < 1e-12,
        "momenta moved by {linear:.2e}, {angular:.2e}"
    );
}

#[test]
fn an_included_chain_s_joints_step_as_its_own() {
    // Two links included as `upper`, a third joined to them: trep's three-link chain.
    let (m, l, g, h) = (1.0, 1.0, 9.81, 0.01);
    let mut whole = Modular::new(Quadrature::midpoint(), h).unwrap();
    whole
        .include("upper", mechanism::point_chain(2, m, l, g, h).unwrap())
        .unwrap();
    whole.add("last", PlanarMass { m, g }).unwrap();
    let rod = Joint::rod(
        "rod",
        Anchor::point("upper.link1", ["x", "y"]),
        Anchor::point("last", ["x", "y"]),
        l,
    );
    whole.connect(rod).unwrap();
    let names = whole.junction_names();
    assert_eq!(names, ["upper.rod0[0]", "upper.rod1[0]", "rod[0]"]);
    let mut three = mechanism::point_chain(3, m, l, g, h).unwrap();
    let (q0, v0) = mechanism::point_chain_state(&[1.2, 0.7, 0.3], &[0.0, 0.5, -1.0], l);
    whole.start_from_velocity(&q0, &v0).unwrap();
    three.start_from_velocity(&q0, &v0).unwrap();
    for _ in 0..500 {
        whole.step().unwrap();
        three.step().unwrap();
    }
    assert!(distance(whole.q().as_slice(), three.q().as_slice()) < 1e-13);
    // Names the included joints already hold.
    let mut other = Modular::new(Quadrature::midpoint(), h).unwrap();
    other.add("m", PlanarMass { m, g }).unwrap();
    other
        .join(Junction::new("upper.rod0").flow("m.x", 1.0))
        .unwrap();
    let clash = other.include("upper", mechanism::point_chain(2, m, l, g, h).unwrap());
    assert!(clash.unwrap_err().to_string().contains("upper.rod0"));
}

#[test]
fn the_slider_crank_steps_as_one_model_with_its_rail_and_pins() {
    let [a, b] = mechanism::SLIDER_CRANK;
    let (g, h) = (9.81, 0.002);
    let model = mechanism::SliderCrankMonolithic { a, b, g };
    let start = mechanism::slider_crank_state(0.8, 3.0);
    let mechanism = mechanism::slider_crank(g, h).unwrap();
    let (mut joined, mut one) = started(mechanism, model, h, start);
    let mut worst: f64 = 0.0;
    for k in 0..2000 {
        joined.step().unwrap();
        one.step().unwrap();
        worst = worst.max(distance(joined.q().as_slice(), one.q().as_slice()));
        let q = joined.q();
        // The slider on its rail, unturned.
        assert!(q[7].abs() < 1e-12 && q[8].abs() < 1e-12, "step {k}");
    }
    // The crank has turned a full revolution: the slider went to and fro.
    assert!(
        joined.q()[2] > 0.8 + std::f64::consts::TAU,
        "crank at {}",
        joined.q()[2]
    );
    assert!(worst < 1e-12, "joined and one model differ by {worst:.2e}");
}

/// A body at rest on a rail through the origin along `axis` in space, its frame held parallel
/// to space's, under gravity along `−z`: its positions and attitude over `steps` steps of `h`
/// against the closed form `x = x₀ − ½ g (a·e_z) t² a`, `R = R₀`.
#[test]
fn a_body_on_a_rail_slides_as_the_closed_form() {
    let (g, h) = (9.81, 0.01);
    let axis = [1.0, 2.0, 2.0];
    let a = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    let mut slider = Modular::new(Quadrature::midpoint(), h).unwrap();
    let body = mechanism::rod_body(2.0, 1.0, g);
    slider
        .add_on_space("block", body, Product::cayley())
        .unwrap();
    let rail = Joint::prismatic(
        "rail",
        Anchor::fixed([0.0, 0.0, 0.0]),
        Anchor::body("block", ["x", "y", "z"], "R", [0.0; 3]),
        axis,
    );
    slider.connect(rail).unwrap();
    let x0 = a * 0.5;
    let identity = Matrix3::<f64>::identity();
    let q0: Vec<f64> = x0.iter().chain(identity.iter()).copied().collect();
    let v0 = [a[0] * 0.3, a[1] * 0.3, a[2] * 0.3, 0.0, 0.0, 0.0];
    slider.start_from_velocity(&q0, &v0).unwrap();
    let mut worst: f64 = 0.0;
    for k in 1..=1000 {
        slider.step().unwrap();
        let t = k as f64 * h;
        let exact = x0 + a * (0.3 * t - 0.5 * g * a[2] * t * t);
        let q = slider.q();
        let x = Vector3::new(q[0], q[1], q[2]);
        worst = worst.max((x - exact).amax() / (1.0 + exact.amax()));
        assert!((Matrix3::from_row_slice(&q.as_slice()[3..12]) - identity).amax() < 1e-14);
    }
    assert!(
        worst < 1e-12,
        "the slide is {worst:.2e} off its closed form"
    );
}

#[test]
fn welded_and_universally_joined_bodies_keep_their_joints_and_momenta() {
    // Three bodies free in space: the second welded to the first, the third on a universal
    // joint to the second; no gravity, so both momenta are conserved.
    let (l, h) = (1.0, 0.005);
    let mut bodies = Modular::new(Quadrature::midpoint(), h).unwrap();
    for k in 0..3 {
        let rod = mechanism::rod_body(1.0 + k as f64, l, 0.0);
        bodies
            .add_on_space(&mechanism::link(k), rod, Product::cayley())
            .unwrap();
    }
    let (top, bottom) = ([0.0, 0.0, l / 2.0], [0.0, 0.0, -l / 2.0]);
    let end = |k: usize, offset| Anchor::body(&mechanism::link(k), ["x", "y", "z"], "R", offset);
    bodies
        .connect(Joint::fixed("weld", end(0, bottom), end(1, top)))
        .unwrap();
    let cardan = Joint::universal(
        "cardan",
        end(1, bottom),
        end(2, top),
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    );
    bodies.connect(cardan).unwrap();
    // The first two straight and turning together, the third turning about its own axes.
    let turn = Rotation3::new(Vector3::new(0.3, -0.4, 0.2)).into_inner();
    let third = turn * Rotation3::new(Vector3::new(0.5, 0.0, 0.0)).into_inner();
    let omegas = [
        Vector3::new(0.4, -0.7, 0.9),
        Vector3::new(0.4, -0.7, 0.9),
        Vector3::new(0.0, 0.0, 0.0),
    ];
    // The third turned about the cross's first axis; its rate the second's and a spin about
    // that axis (one of the universal joint's two freedoms), read in its axes.
    let spin = third.transpose() * (turn * omegas[1]) + Vector3::new(1.5, 0.0, 0.0);
    let omegas = [omegas[0], omegas[1], spin];
    let (q0, v0) = mechanism::body_chain_state(&[turn, turn, third], &omegas, l);
    bodies.start_from_velocity(&q0, &v0).unwrap();
    let momenta = |b: &Modular| mechanism::bodies_momenta(b.q().as_slice(), b.p().as_slice());
    let (linear0, angular0) = momenta(&bodies);
    let (mut linear, mut angular): (f64, f64) = (0.0, 0.0);
    for k in 0..2000 {
        bodies.step().unwrap();
        let q = bodies.q();
        let r = |k: usize| Matrix3::from_row_slice(&q.as_slice()[12 * k + 3..12 * k + 12]);
        // The weld: parallel frames; the universal joint: its axes perpendicular.
        assert!((r(0) - r(1)).amax() < 1e-12, "step {k}");
        let (u, w) = (r(1) * Vector3::x(), r(2) * Vector3::y());
        assert!(u.dot(&w).abs() < 1e-12, "step {k}");
        let balls = [(Some(0), bottom, 1, top), (Some(1), bottom, 2, top)];
        assert!(ball_gaps(q.as_slice(), &balls) < 1e-12, "step {k}");
        let (l, a) = momenta(&bodies);
        linear = linear.max((l - linear0).amax());
        angular = angular.max((a - angular0).amax());
    }
    assert!(
        linear < 1e-12 && angular < 1e-12,
        "momenta moved by {linear:.2e}, {angular:.2e}"
    );
}

#[test]
fn a_chain_stepped_with_kept_jacobians_reaches_newton_s_roots() {
    // A Jacobian kept from an earlier step is evaluated anew where the positions' updates stop
    // contracting (not refused: the iteration, not the step, was slow).
    let n = 10;
    let (q0, v0) = straight(n);
    let mut ends = Vec::new();
    for reuse in [None, Some(0.25)] {
        let options = NewtonOptions {
            jacobian_reuse: reuse,
            ..Default::default()
        };
        let chain = mechanism::point_chain(n, 1.0, 1.0, 9.81, 0.01).unwrap();
        let mut chain = chain.with_newton_options(options).unwrap();
        chain.start_from_velocity(&q0, &v0).unwrap();
        chain.run(400).unwrap();
        ends.push(chain.q());
    }
    assert!(distance(ends[0].as_slice(), ends[1].as_slice()) < 1e-12);
}

#[test]
fn a_long_chain_steps_across_threads_as_on_one() {
    // Enough links for the components' passes to be split across rayon's threads.
    let n = 2500;
    let (q0, v0) = straight(n);
    let mut states = Vec::new();
    for parallel in [false, true] {
        let chain = mechanism::point_chain(n, 1.0, 1.0, 9.81, 0.01).unwrap();
        let mut chain = chain.with_parallel(parallel);
        chain.start_from_velocity(&q0, &v0).unwrap();
        chain.run(5).unwrap();
        assert!(chain.constraint_violation().unwrap() < 1e-12);
        states.push((chain.q(), chain.multipliers().unwrap().to_vec()));
    }
    assert_eq!(states[0], states[1]);
}

#[test]
fn a_joint_on_a_coordinate_without_kinetic_energy_is_refused_at_the_start() {
    /// A massless point in a potential well: its step is fixed by the joint alone.
    #[dirac_system(coordinates(x, y), lagrangian = -(x * x + 2.0 * y * y))]
    struct Massless;
    let mut model = Modular::new(Quadrature::midpoint(), 0.01).unwrap();
    model.add("p", Massless).unwrap();
    let rod = Joint::rod(
        "rod",
        Anchor::fixed([0.0, 0.0]),
        Anchor::point("p", ["x", "y"]),
        1.0,
    );
    model.connect(rod).unwrap();
    let error = model
        .start_from_velocity(&[1.0, 0.0], &[0.0, 0.0])
        .unwrap_err();
    assert!(matches!(error, DiracError::Unsupported(_)), "{error}");
    assert!(error.to_string().contains("joint rod on p"), "{error}");
}

#[test]
fn joints_that_cannot_be_made_are_refused_with_the_reason() {
    let mut chain = mechanism::point_chain(2, 1.0, 1.0, 9.81, 0.01).unwrap();
    let bob = |name: &str| Anchor::point(name, ["x", "y"]);
    let error = |result: Result<(), DiracError>| result.unwrap_err().to_string();
    let unknown = error(chain.connect(Joint::rod("r", bob("nobody"), bob("link0"), 1.0)));
    assert!(unknown.contains("no instance \"nobody\"") && unknown.contains("link0, link1"));
    let position = error(chain.connect(Joint::rod(
        "r",
        Anchor::point("link0", ["x", "z"]),
        bob("link1"),
        1.0,
    )));
    assert!(position.contains("no position \"z\"") && position.contains("x, y"));
    let itself = error(chain.connect(Joint::rod("r", bob("link0"), bob("link0"), 1.0)));
    assert!(itself.contains("with itself"));
    let taken = error(chain.connect(Joint::rod("rod1", bob("link0"), bob("link1"), 1.0)));
    assert!(taken.contains("named \"rod1\""));
    // A junction named as a joint's row.
    let row = chain.join(Junction::new("rod1[0]").flow("link0.x", 1.0));
    assert!(error(row).contains("rod1[0]"));
    // Positions off the rods, and velocities along them.
    let half_pi = std::f64::consts::FRAC_PI_2;
    let (mut q, v) = mechanism::point_chain_state(&[half_pi, 0.0], &[1.0, 0.0], 1.0);
    let saved = chain.q();
    q[3] += 1e-3;
    let off = chain.start_from_velocity(&q, &v).unwrap_err();
    assert!(
        matches!(off, DiracError::InconsistentInitialState(_)),
        "{off}"
    );
    assert!(off.to_string().contains("rod1[0]"), "{off}");
    assert_eq!(chain.q(), saved);
    let (q, mut v) = mechanism::point_chain_state(&[half_pi, 0.0], &[1.0, 0.0], 1.0);
    v[0] += 0.5;
    let along = chain.start_from_velocity(&q, &v).unwrap_err();
    assert!(along.to_string().contains("rod0[0]"), "{along}");
    // A rod restating another's constraint: the step does not determine the impulses.
    let (q, v) = mechanism::point_chain_state(&[half_pi, 0.0], &[1.0, 0.0], 1.0);
    chain
        .connect(Joint::rod("again", bob("link0"), bob("link1"), 1.0))
        .unwrap();
    let twice = chain.start_from_velocity(&q, &v).unwrap_err();
    assert!(
        matches!(&twice, DiracError::SingularJacobian { unknowns, .. }
            if unknowns.contains("joint again[0]") && unknowns.contains("joint rod1[0]")),
        "{twice}"
    );
    // The port work through joints is not reported.
    let mut chain = mechanism::point_chain(2, 1.0, 1.0, 9.81, 0.01).unwrap();
    chain.start_from_velocity(&q, &v).unwrap();
    chain.step().unwrap();
    assert!(matches!(chain.ports(), Err(DiracError::Unsupported(_))));
}
