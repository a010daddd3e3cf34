//! Models on rotations and unit vectors (`R: SO3`, `n: S2`): the Lie group variational
//! integrators' invariants (orthogonality, discrete Noether, bounded energy), their orders against
//! closed forms and against an independent Dop853 reference, one-forms at the three constraint
//! points, torque inputs, hand-written models, and the errors a bad start gets.

use dirac::prelude::*;
use dirac::product::Product;
use scenes::{rigid_body, rolling_ball, satellite, spherical_pendulum};
use support::assert_order;

use crate::support;

/// Asserts the order of `(h, error)` pairs (see `support::assert_order`).
fn order_of(what: &str, errors: &[(f64, f64)], expected: f64) {
    let (hs, errors): (Vec<f64>, Vec<f64>) = errors.iter().copied().unzip();
    assert_order(what, &hs, &errors, expected);
}

/// The largest `|RᵀR − I|` entry.
fn orthogonality(r: &Matrix3<f64>) -> f64 {
    (r.transpose() * r - Matrix3::identity()).amax()
}

/// A free asymmetric body over 10⁶ steps of h = 0.01 (Cayley, midpoint): `RᵀR = I` to round-off
/// at every step, the spatial angular momentum `R Π` to round-off (discrete Noether: the
/// discrete Lagrangian is invariant under `R ↦ Q R`), and the energy error bounded, as large in
/// the last tenth of the run as in the first.
#[test]
fn a_free_body_keeps_its_attitude_orthogonal_and_its_momentum_over_a_million_steps() {
    let mut stepper = rigid_body::started(
        rigid_body::ASYMMETRIC,
        Product::cayley(),
        Quadrature::midpoint(),
        0.01,
        rigid_body::free_start(),
    )
    .unwrap();
    let pi0 = stepper.q().spatial(&stepper.p(), 0);
    let e0 = stepper.energy().unwrap();
    let steps = 1_000_000;
    let (mut worst_orthogonality, mut worst_momentum) = (0.0_f64, 0.0_f64);
    let (mut early, mut late) = (0.0_f64, 0.0_f64);
    for k in 1..=steps {
        stepper.step().unwrap();
        let q = stepper.q();
        worst_orthogonality = worst_orthogonality.max(orthogonality(&q.rotation[0]));
        worst_momentum = worst_momentum.max((q.spatial(&stepper.p(), 0) - pi0).amax());
        if k % 100 == 0 && (k <= steps / 10 || k > steps - steps / 10) {
            let error = (stepper.energy().unwrap() - e0).abs();
            if k <= steps / 10 {
                early = early.max(error);
            } else {
                late = late.max(error);
            }
        }
    }
    println!(
        "free body, 10⁶ steps: |RᵀR − I| ≤ {worst_orthogonality:.1e}, |ΔRΠ| ≤ {worst_momentum:.1e} \
         (|RΠ| = {:.3}), energy error {early:.5e} in the first tenth, {late:.5e} in the last",
        pi0.norm()
    );
    assert!(
        worst_orthogonality <= 1e-13,
        "|RᵀR − I| = {worst_orthogonality:e}"
    );
    assert!(
        worst_momentum <= 1e-12 * pi0.norm(),
        "|ΔRΠ| = {worst_momentum:e}"
    );
    // Bounded, not drifting: the error of the last 10⁵ steps is that of the first.
    assert!(
        early > 1e-7 && late < 2.0 * early,
        "early {early:e}, late {late:e}"
    );
}

/// The heavy top's vertical angular momentum `e₃ · R Π` is conserved to round-off (the potential
/// is symmetric about the vertical), with both retractions and with `galerkin(2)`; its energy
/// error stays bounded.
#[test]
fn the_heavy_top_keeps_its_vertical_momentum() {
    for (space, quadrature) in [
        (Product::cayley(), Quadrature::midpoint()),
        (Product::exp(), Quadrature::midpoint()),
        (Product::cayley(), Quadrature::galerkin(2).unwrap()),
    ] {
        let name = format!("{:?} {}", space.retraction(), quadrature.name());
        let mut stepper = rigid_body::started(
            rigid_body::TOP,
            space,
            quadrature,
            0.01,
            rigid_body::top_start(),
        )
        .unwrap();
        let lz0 = rigid_body::vertical_momentum(&stepper.q(), &stepper.p());
        let trajectory = stepper.run(20_000).unwrap();
        let drift = trajectory
            .q()
            .iter()
            .zip(trajectory.p())
            .map(|(q, p)| (rigid_body::vertical_momentum(q, p) - lz0).abs())
            .fold(0.0, f64::max);
        assert!(drift <= 1e-12 * lz0.abs(), "{name}: |ΔL_z| = {drift:e}");
        assert!(trajectory.max_energy_error() < 1e-3, "{name}");
        // The top precesses: it turns about the vertical by much more than its nutation.
        let axis = trajectory.q().last().unwrap().rotation[0] * Vector3::z();
        assert!(axis[2] > 0.85 && axis.xy().norm() > 0.3, "{name}: {axis}");
    }
}

/// A symmetric free body against its closed form: orders 2, 2, 4 and 6 for the midpoint rule,
/// the trapezoid, `galerkin(2)` and `galerkin(3)` in the chart, with the Cayley and the
/// exponential retraction.
#[test]
fn the_symmetric_body_converges_at_the_quadratures_orders() {
    let (r0, omega0) = rigid_body::free_start();
    let t_end = 2.0;
    let exact = rigid_body::symmetric(&rigid_body::SYMMETRIC, &r0, &omega0, t_end);
    for space in [Product::cayley(), Product::exp()] {
        for (quadrature, order, steps) in [
            (Quadrature::midpoint(), 2.0, [20, 40, 80, 160]),
            (Quadrature::trapezoid(), 2.0, [20, 40, 80, 160]),
            (Quadrature::galerkin(2).unwrap(), 4.0, [10, 20, 40, 80]),
            (Quadrature::galerkin(3).unwrap(), 6.0, [5, 10, 15, 20]),
        ] {
            let name = format!("{:?} {}", space.retraction(), quadrature.name());
            let errors: Vec<(f64, f64)> = steps
                .iter()
                .map(|&n| {
                    let h = t_end / n as f64;
                    let mut stepper = rigid_body::started(
                        rigid_body::SYMMETRIC,
                        space,
                        quadrature.clone(),
                        h,
                        (r0, omega0),
                    )
                    .unwrap();
                    stepper.run(n).unwrap();
                    (h, (stepper.q().rotation[0] - exact).amax())
                })
                .collect();
            order_of(&name, &errors, order);
        }
    }
}

/// The 3D pendulum (an asymmetric body hanging off its centre of mass) against Dop853 on the
/// quaternion ODE at tolerance 1e-13: order 2 with both retractions, 4 with `galerkin(2)`.
#[test]
fn the_3d_pendulum_converges_against_a_quaternion_reference() {
    let t_end = 1.0;
    let (r0, omega0) = rigid_body::pendulum_start();
    let (r_ref, pi_ref) =
        rigid_body::reference(&rigid_body::PENDULUM, &r0, &omega0, t_end, 1e-13).unwrap();
    for (space, quadrature, order, steps) in [
        (
            Product::cayley(),
            Quadrature::midpoint(),
            2.0,
            [20, 40, 80, 160],
        ),
        (
            Product::exp(),
            Quadrature::midpoint(),
            2.0,
            [20, 40, 80, 160],
        ),
        (
            Product::cayley(),
            Quadrature::galerkin(2).unwrap(),
            4.0,
            [10, 20, 40, 80],
        ),
    ] {
        let name = format!("{:?} {}", space.retraction(), quadrature.name());
        let errors: Vec<(f64, f64)> = steps
            .iter()
            .map(|&n| {
                let h = t_end / n as f64;
                let mut stepper = rigid_body::started(
                    rigid_body::PENDULUM,
                    space,
                    quadrature.clone(),
                    h,
                    (r0, omega0),
                )
                .unwrap();
                stepper.run(n).unwrap();
                let q_error = (stepper.q().rotation[0] - r_ref).amax();
                let p_error = (stepper.p().rotation[0] - pi_ref).amax();
                (h, q_error.max(p_error))
            })
            .collect();
        order_of(&name, &errors, order);
    }
}

/// The macro's top and the top written against the traits by hand step alike.
#[test]
fn a_hand_written_top_steps_like_the_generated_one() {
    let run = |by_hand: bool| {
        let (space, quadrature, h) = (Product::cayley(), Quadrature::midpoint(), 0.01);
        let start = rigid_body::top_start();
        let (q, p) = if by_hand {
            let top = rigid_body::HeavyTopByHand(rigid_body::TOP);
            let mut stepper = rigid_body::started(top, space, quadrature, h, start).unwrap();
            stepper.run(500).unwrap();
            (stepper.q(), stepper.p())
        } else {
            let mut stepper =
                rigid_body::started(rigid_body::TOP, space, quadrature, h, start).unwrap();
            stepper.run(500).unwrap();
            (stepper.q(), stepper.p())
        };
        (q.rotation[0], p.rotation[0])
    };
    let (generated, by_hand) = (run(false), run(true));
    assert!((generated.0 - by_hand.0).amax() < 1e-13);
    assert!((generated.1 - by_hand.1).amax() < 1e-12);
}

/// The pendulum on `S²` against the Cartesian pendulum held on the sphere by SHAKE and against
/// Dop853 on the constrained ODE: order 2 for both (both retractions on the sphere), the two
/// discretisations approaching each other at order 2, and the vertical angular momentum
/// conserved by both.
#[test]
fn the_spherical_pendulum_matches_the_cartesian_one() {
    let t_end = 2.0;
    let (x_ref, v_ref) = spherical_pendulum::reference(t_end, 1e-13).unwrap();
    let l = spherical_pendulum::SCENE.l;
    for space in [Product::cayley(), Product::exp()] {
        let errors: Vec<(f64, f64)> = [40, 80, 160, 320]
            .iter()
            .map(|&n| {
                let h = t_end / n as f64;
                let mut stepper =
                    spherical_pendulum::on_sphere(space, Quadrature::midpoint(), h).unwrap();
                stepper.run(n).unwrap();
                let x = stepper.q().direction[0] * l;
                let v = stepper.v().unwrap().direction[0] * l;
                (h, (x - x_ref).amax().max((v - v_ref).amax()))
            })
            .collect();
        order_of(&format!("{:?}", space.retraction()), &errors, 2.0);
    }
    let (cartesian_errors, gaps): (Vec<_>, Vec<_>) = [40, 80, 160, 320]
        .iter()
        .map(|&n| {
            let h = t_end / n as f64;
            let mut cartesian = spherical_pendulum::cartesian(Quadrature::midpoint(), h).unwrap();
            let mut sphere =
                spherical_pendulum::on_sphere(Product::exp(), Quadrature::midpoint(), h).unwrap();
            cartesian.run(n).unwrap();
            sphere.run(n).unwrap();
            let (x, v) = (cartesian.q(), cartesian.v().unwrap());
            let gap = (sphere.q().direction[0] * l - x).amax();
            // The same measure as on the sphere: position and velocity.
            let error = (x - x_ref).amax().max((v - v_ref).amax());
            ((h, error), (h, gap))
        })
        .unzip();
    order_of("Cartesian SHAKE", &cartesian_errors, 2.0);
    order_of("sphere − Cartesian", &gaps, 2.0);
    // The vertical angular momentum, equal at the start, is kept by both.
    let h = 0.005;
    let n = (t_end / h).round() as u64;
    let mut sphere =
        spherical_pendulum::on_sphere(Product::exp(), Quadrature::midpoint(), h).unwrap();
    let mut cartesian = spherical_pendulum::cartesian(Quadrature::midpoint(), h).unwrap();
    let lz_sphere = |s: &ManifoldStepper<_, 2, Product<0, 0, 1>>| {
        spherical_pendulum::vertical_momentum(&(s.q().direction[0] * l), &(s.p().direction[0] / l))
    };
    let lz_cartesian = |s: &Stepper<_, 3>| spherical_pendulum::vertical_momentum(&s.q(), &s.p());
    let (l_sphere, l_cartesian) = (lz_sphere(&sphere), lz_cartesian(&cartesian));
    assert!(
        (l_sphere - l_cartesian).abs() < 1e-14,
        "{l_sphere} {l_cartesian}"
    );
    sphere.run(n).unwrap();
    cartesian.run(n).unwrap();
    assert!((lz_sphere(&sphere) - l_sphere).abs() < 1e-12);
    assert!((lz_cartesian(&cartesian) - l_cartesian).abs() < 1e-12);
}

/// The largest `|e₃ · (q × p) − L₀|` of the spherical pendulum over `steps` steps of `h = 0.01`
/// from its start.
fn vertical_momentum_drift(space: Product<0, 0, 1>, quadrature: Quadrature, steps: u64) -> f64 {
    let mut stepper = spherical_pendulum::on_sphere(space, quadrature, 0.01).unwrap();
    let lz = |s: &ManifoldStepper<_, 2, Product<0, 0, 1>>| {
        spherical_pendulum::vertical_momentum(&s.q().direction[0], &s.p().direction[0])
    };
    let lz0 = lz(&stepper);
    let mut drift = 0.0_f64;
    for _ in 0..steps {
        stepper.step().unwrap();
        drift = drift.max((lz(&stepper) - lz0).abs());
    }
    drift
}

/// Rotations about the vertical are a symmetry of the spherical pendulum's discrete
/// Lagrangian, so its vertical angular momentum (0.85 here) is kept to round-off, without a
/// trend, with both retractions and at order 4: each unit vector's angular momentum advances by
/// the step's torque, whose vertical component vanishes. (With the momentum pushed through the
/// chart it drifted by 3.5e-17 a step with Cayley, 1.0e-12 after these 3·10⁴ steps.)
#[test]
fn the_spherical_pendulum_keeps_its_vertical_momentum_to_round_off() {
    for (space, quadrature, steps) in [
        (Product::cayley(), Quadrature::midpoint(), 30_000),
        (Product::exp(), Quadrature::midpoint(), 30_000),
        (Product::cayley(), Quadrature::galerkin(2).unwrap(), 3_000),
    ] {
        let name = format!("{:?} {}", space.retraction(), quadrature.name());
        let drift = vertical_momentum_drift(space, quadrature, steps);
        println!("{name}: |ΔL_z| ≤ {drift:.1e} over {steps} steps");
        assert!(drift <= 1e-13, "{name}: {drift:e}");
    }
}

/// The same over 10⁶ steps (`cargo test --test suite -- --ignored million`, a minute).
#[test]
#[ignore = "10⁶ steps, a minute"]
fn the_spherical_pendulum_keeps_its_vertical_momentum_over_a_million_steps() {
    for space in [Product::cayley(), Product::exp()] {
        let drift = vertical_momentum_drift(space, Quadrature::midpoint(), 1_000_000);
        println!(
            "{:?}: |ΔL_z| ≤ {drift:.1e} over 10⁶ steps",
            space.retraction()
        );
        assert!(drift <= 1e-13, "{:?}: {drift:e}", space.retraction());
    }
}

/// A pendulum on a spring, `(r, n) ∈ R × S²`: its length `r` stretches, its direction `n`
/// swings. Conservative, it advances `n`'s angular momentum by the step's torque.
#[dirac_system(
    coordinates(r, n: S2),
    lagrangian = 0.5 * m * (dot(r) * dot(r) + r * r * dot(dot(n), dot(n)))
        - 0.5 * k * (r - l) * (r - l) - m * g * r * n[2],
)]
#[derive(Debug, Clone, Copy)]
struct SpringPendulum {
    m: f64,
    k: f64,
    l: f64,
    g: f64,
}

/// The same pendulum with a force on its length, whose momentum is pushed through the chart.
#[dirac_system(
    coordinates(r, n: S2),
    lagrangian = 0.5 * m * (dot(r) * dot(r) + r * r * dot(dot(n), dot(n)))
        - 0.5 * k * (r - l) * (r - l) - m * g * r * n[2],
    forces(u * dr),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct DrivenSpringPendulum {
    m: f64,
    k: f64,
    l: f64,
    g: f64,
}

/// A body coupled to a pendulum, `(R, n) ∈ SO(3) × S²`: the pendulum is drawn towards the
/// body's third axis.
#[dirac_system(
    coordinates(R: SO3, n: S2),
    lagrangian = 0.5 * dot(omega(R), j * omega(R)) + 0.5 * dot(dot(n), dot(n)) - g * n[2]
        - c * dot(R * [0.0, 0.0, 1.0], n),
)]
#[derive(Debug, Clone, Copy)]
struct BodyAndPendulum {
    j: [[f64; 3]; 3],
    g: f64,
    c: f64,
}

/// The same with a torque on the body, whose momenta are pushed through the chart.
#[dirac_system(
    coordinates(R: SO3, n: S2),
    lagrangian = 0.5 * dot(omega(R), j * omega(R)) + 0.5 * dot(dot(n), dot(n)) - g * n[2]
        - c * dot(R * [0.0, 0.0, 1.0], n),
    forces(dot([u, 0.0, 0.0], dR)),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct DrivenBodyAndPendulum {
    j: [[f64; 3]; 3],
    g: f64,
    c: f64,
}

/// The largest difference between two states on `Rᴷ × SO(3)ᴬ × (S²)ᴮ`, in position and momentum.
fn state_gap<const K: usize, const A: usize, const B: usize>(
    (qa, pa): &(Configuration<f64, K, A, B>, Rates<f64, K, A, B>),
    (qb, pb): &(Configuration<f64, K, A, B>, Rates<f64, K, A, B>),
) -> f64 {
    let mut gap = (qa.vector - qb.vector)
        .amax()
        .max((pa.vector - pb.vector).amax());
    for a in 0..A {
        gap = gap
            .max((qa.rotation[a] - qb.rotation[a]).amax())
            .max((pa.rotation[a] - pb.rotation[a]).amax());
    }
    for b in 0..B {
        gap = gap
            .max((qa.direction[b] - qb.direction[b]).amax())
            .max((pa.direction[b] - pb.direction[b]).amax());
    }
    gap
}

/// Steps two runs `steps` times (each closure steps its run and returns its state) and returns
/// the largest gap between them and how far the first run's states move from its start.
fn twin_runs<const K: usize, const A: usize, const B: usize>(
    steps: usize,
    mut free: impl FnMut() -> (Configuration<f64, K, A, B>, Rates<f64, K, A, B>),
    mut driven: impl FnMut() -> (Configuration<f64, K, A, B>, Rates<f64, K, A, B>),
    start: &(Configuration<f64, K, A, B>, Rates<f64, K, A, B>),
) -> (f64, f64) {
    let (mut largest, mut travel) = (0.0_f64, 0.0_f64);
    for _ in 0..steps {
        let (a, b) = (free(), driven());
        largest = largest.max(state_gap(&a, &b));
        travel = travel.max(state_gap(&a, start));
    }
    (largest, travel)
}

/// The momentum advanced by torques is the one pushed through the chart (the same model with
/// a zero force takes that path): on `R × S²` with the midpoint rule, the trapezoid and
/// `galerkin(2)` (internal points), and on `SO(3) × S²`, the two runs agree to the solver's
/// round-off while the states travel far; the vertical momentum of `R × S²` is kept.
#[test]
fn torques_advance_the_momentum_the_chart_pushes() {
    let (m, k, l, g) = (1.0, 40.0, 1.0, 9.81);
    let n0 = Vector3::new(0.6_f64.sin(), 0.0, -0.6_f64.cos());
    let start = (
        Configuration::new(vector![1.1], [], [n0]),
        Rates::new(vector![0.3], [], [Vector3::new(0.0, 1.5, 0.0)]),
    );
    let lz = |q: &Configuration<f64, 1, 0, 1>, p: &Rates<f64, 1, 0, 1>| {
        q.direction[0].cross(&p.direction[0])[2]
    };
    for quadrature in [
        Quadrature::midpoint(),
        Quadrature::trapezoid(),
        Quadrature::galerkin(2).unwrap(),
    ] {
        let name = quadrature.name();
        let space = Product::<1, 0, 1>::cayley();
        let mut free = Stepper::on_manifold(
            SpringPendulum { m, k, l, g },
            space,
            quadrature.clone(),
            0.01,
        )
        .unwrap();
        let mut driven =
            Stepper::on_manifold(DrivenSpringPendulum { m, k, l, g }, space, quadrature, 0.01)
                .unwrap();
        free.start_from_velocity(start.0, start.1).unwrap();
        driven.start_from_velocity(start.0, start.1).unwrap();
        let p0 = free.p();
        let lz0 = lz(&start.0, &p0);
        let mut drift = 0.0_f64;
        let (gap, travel) = twin_runs(
            1_000,
            || {
                free.step().unwrap();
                drift = drift.max((lz(&free.q(), &free.p()) - lz0).abs());
                (free.q(), free.p())
            },
            || {
                driven.step().unwrap();
                (driven.q(), driven.p())
            },
            &(start.0, p0),
        );
        println!(
            "R × S², {name}: runs {gap:.1e} apart, {travel:.2} from the start; |ΔL_z| ≤ {drift:.1e}"
        );
        assert!(gap < 1e-11 && travel > 0.5, "{name}: {gap:e}, {travel}");
        assert!(drift <= 1e-13, "{name}: |ΔL_z| = {drift:e}");
    }
    let j = [[2.0, 0.1, 0.0], [0.1, 1.5, 0.2], [0.0, 0.2, 1.0]];
    let (g, c) = (9.81, 3.0);
    let space = Product::<0, 1, 1>::cayley();
    let start = (
        Configuration::new(SVector::zeros(), [Matrix3::identity()], [n0]),
        Rates::new(
            SVector::zeros(),
            [Vector3::new(0.4, -0.2, 1.1)],
            [Vector3::new(0.0, 1.5, 0.0)],
        ),
    );
    let mut free = Stepper::on_manifold(
        BodyAndPendulum { j, g, c },
        space,
        Quadrature::midpoint(),
        0.01,
    )
    .unwrap();
    let mut driven = Stepper::on_manifold(
        DrivenBodyAndPendulum { j, g, c },
        space,
        Quadrature::midpoint(),
        0.01,
    )
    .unwrap();
    free.start_from_velocity(start.0, start.1).unwrap();
    driven.start_from_velocity(start.0, start.1).unwrap();
    let p0 = free.p();
    let (gap, travel) = twin_runs(
        1_000,
        || {
            free.step().unwrap();
            (free.q(), free.p())
        },
        || {
            driven.step().unwrap();
            (driven.q(), driven.p())
        },
        &(start.0, p0),
    );
    println!("SO(3) × S²: runs {gap:.1e} apart, {travel:.2} from the start");
    assert!(gap < 1e-11 && travel > 0.5, "{gap:e}, {travel}");
}

/// A pendulum looping over the top crosses the equator, where the frame of the sphere's chart
/// changes branch (the chart at each step is its own; nothing carries chart coordinates across
/// steps unchecked): order 2 against Dop853 with both retractions.
#[test]
fn a_looping_spherical_pendulum_crosses_the_equator_at_order_two() {
    let theta: f64 = 1.2;
    let n0 = Vector3::new(theta.sin(), 0.0, -theta.cos());
    let up = Vector3::new(7.0 * theta.cos(), 1.0, 7.0 * theta.sin());
    let start = (n0, up - n0 * n0.dot(&up));
    let t_end = 4.0;
    let (x_ref, _) = spherical_pendulum::reference_from(start, t_end, 1e-13).unwrap();
    for space in [Product::cayley(), Product::exp()] {
        let errors: Vec<(f64, f64)> = [200, 400, 800, 1600]
            .iter()
            .map(|&n| {
                let h = t_end / n as f64;
                let mut stepper = Stepper::on_manifold(
                    spherical_pendulum::SCENE,
                    space,
                    Quadrature::midpoint(),
                    h,
                )
                .unwrap();
                stepper
                    .start_from_velocity(
                        Configuration::of_direction(start.0),
                        Rates::of_direction(start.1),
                    )
                    .unwrap();
                let trajectory = stepper.run(n).unwrap();
                let crossings = trajectory
                    .q()
                    .windows(2)
                    .filter(|w| w[0].direction[0][2].signum() != w[1].direction[0][2].signum())
                    .count();
                println!("looping, {n} steps: {crossings} equator crossings");
                assert!(crossings >= 6, "{n}: {crossings} crossings");
                (
                    h,
                    (stepper.q().direction[0] * spherical_pendulum::SCENE.l - x_ref).amax(),
                )
            })
            .collect();
        order_of(&format!("looping, {:?}", space.retraction()), &errors, 2.0);
        // At coarse steps too (0.3 to 0.6 rad per step), where a first guess extrapolated across
        // the change of branch made Newton's updates stop contracting: the run goes through, its
        // events find every crossing, and it is the run turned by 90° about the vertical,
        // turned back (the steps do not depend on the frames of the charts, which differ
        // between the two).
        let quarter = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        for h in [0.04, 0.08] {
            let n = (t_end / h).round() as u64;
            let ends: Vec<Vector3<f64>> = [Matrix3::identity(), quarter]
                .iter()
                .map(|turn| {
                    let mut stepper = Stepper::on_manifold(
                        spherical_pendulum::SCENE,
                        space,
                        Quadrature::midpoint(),
                        h,
                    )
                    .unwrap();
                    stepper
                        .start_from_velocity(
                            Configuration::of_direction(turn * start.0),
                            Rates::of_direction(turn * start.1),
                        )
                        .unwrap();
                    // The crossings located as events: the dense output of a step whose end
                    // changed branch is read in its own chart.
                    let equator = Event::new(
                        "equator",
                        |_t, q: &Configuration<f64, 0, 0, 1>, _v: &Rates<f64, 0, 0, 1>| {
                            q.direction[0][2]
                        },
                    );
                    let solution = stepper.solve(Run::steps(n).event(equator)).unwrap();
                    let stored = solution
                        .trajectory
                        .q()
                        .windows(2)
                        .filter(|w| w[0].direction[0][2].signum() != w[1].direction[0][2].signum())
                        .count();
                    assert_eq!(solution.events.len(), stored);
                    assert!(stored >= 6, "{stored}");
                    for crossing in &solution.events {
                        assert!(crossing.sample.q.direction[0][2].abs() < 1e-14);
                    }
                    turn.transpose() * stepper.q().direction[0]
                })
                .collect();
            let gap = (ends[0] - ends[1]).amax();
            assert!(gap < 1e-9, "{:?}, h = {h}: {gap:e}", space.retraction());
        }
    }
}

/// The rolling ball against its closed form with the one-forms at the start, the midpoint and
/// the end of each step: order 2 at the midpoint, the one-forms held to round-off at every
/// point, and every point converging; a Galerkin step with one-forms is refused.
#[test]
fn the_rolling_ball_follows_its_closed_form_at_every_constraint_point() {
    let t_end = 2.0;
    let (x_exact, r_exact) = rolling_ball::exact(t_end);
    for (point, order) in [
        (ConstraintPoint::Start, None),
        (ConstraintPoint::Midpoint, Some(2.0)),
        (ConstraintPoint::End, None),
    ] {
        let errors: Vec<(f64, f64)> = [20, 40, 80, 160]
            .iter()
            .map(|&n| {
                let h = t_end / n as f64;
                let mut stepper = rolling_ball::started(Quadrature::midpoint(), h, point).unwrap();
                let trajectory = stepper.run(n).unwrap();
                assert!(
                    trajectory.max_constraint_violation() < 1e-14,
                    "{point:?}: {}",
                    trajectory.max_constraint_violation()
                );
                let q = stepper.q();
                let error = (q.vector - x_exact)
                    .amax()
                    .max((q.rotation[0] - r_exact).amax());
                (h, error)
            })
            .collect();
        if let Some(order) = order {
            order_of(&format!("{point:?}"), &errors, order);
        }
        // Every point converges.
        assert!(errors[3].1 < errors[0].1 / 3.0, "{point:?}: {errors:?}");
    }
    // One-forms are held at one point of a degree-1 step: a Galerkin step is refused up front.
    let error = rolling_ball::started(
        Quadrature::galerkin(2).unwrap(),
        0.01,
        ConstraintPoint::Midpoint,
    )
    .unwrap_err();
    assert!(
        matches!(&error, DiracError::InvalidQuadrature(m) if m.contains("one-forms")),
        "{error}"
    );
}

/// A constant torque about a principal axis from rest turns the satellite about that axis by
/// `τ t²/(2I)`: the inputs reach the steps as body torques, at order 2.
#[test]
fn torque_inputs_turn_the_satellite() {
    let (t_end, tau) = (2.0, 0.3);
    for axis in 0..3 {
        let errors: Vec<(f64, f64)> = [10, 20, 40, 80]
            .iter()
            .map(|&n| {
                let h = t_end / n as f64;
                let mut stepper = Stepper::on_manifold(
                    satellite::SCENE,
                    Product::cayley(),
                    Quadrature::midpoint(),
                    h,
                )
                .unwrap();
                stepper
                    .start_from_velocity(
                        Configuration::of_rotation(Matrix3::identity()),
                        Rates::of_rotation(Vector3::zeros()),
                    )
                    .unwrap();
                stepper
                    .set_input(["tau_x", "tau_y", "tau_z"][axis], tau)
                    .unwrap();
                stepper.run(n).unwrap();
                let exact = satellite::spun_up(axis, tau, t_end);
                (h, (stepper.q().rotation[0] - exact).amax())
            })
            .collect();
        order_of(&format!("axis {axis}"), &errors, 2.0);
    }
    // A PD slew reaches its target attitude.
    let target = Retraction::Exp.map(&Vector3::new(0.5, -0.8, 1.2));
    let (_, errors) = satellite::slew(&target, 0.01, 12.0).unwrap();
    assert!(
        errors[0] > 1.0 && *errors.last().unwrap() < 1e-3,
        "{:?}",
        errors.last()
    );
}

/// A start off the manifold is refused, naming the variable: a matrix that is not a rotation,
/// a vector that is not of unit length, a velocity or a momentum that leaves the sphere; the
/// stepper keeps no state.
#[test]
fn a_start_off_the_manifold_is_refused_naming_the_variable() {
    let mut top = Stepper::on_manifold(
        rigid_body::TOP,
        Product::cayley(),
        Quadrature::midpoint(),
        0.01,
    )
    .unwrap();
    let skewed = Matrix3::new(1.0, 0.01, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    let error = top
        .start_from_velocity(
            Configuration::of_rotation(skewed),
            Rates::of_rotation(Vector3::z()),
        )
        .unwrap_err();
    assert!(
        matches!(&error, DiracError::InconsistentInitialState(m) if m.contains("of R") && m.contains("not a rotation")),
        "{error}"
    );
    let reflection = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
    let error = top
        .start_from_velocity(
            Configuration::of_rotation(reflection),
            Rates::of_rotation(Vector3::z()),
        )
        .unwrap_err();
    assert!(error.to_string().contains("reflection"), "{error}");
    assert!(top.state().is_none());
    let mut pendulum =
        spherical_pendulum::on_sphere(Product::cayley(), Quadrature::midpoint(), 0.01).unwrap();
    let before = *pendulum.state().unwrap();
    let error = pendulum
        .start_from_velocity(
            Configuration::of_direction(Vector3::new(0.0, 0.0, -1.1)),
            Rates::of_direction(Vector3::x()),
        )
        .unwrap_err();
    assert!(
        matches!(&error, DiracError::InconsistentInitialState(m) if m.contains("of n") && m.contains("unit vector")),
        "{error}"
    );
    // A velocity, or a momentum (a covector on the tangent plane), with a normal part.
    let (down, off) = (-Vector3::z(), Vector3::new(1.0, 0.0, 0.5));
    for (what, error) in [
        (
            "velocity",
            pendulum
                .start_from_velocity(Configuration::of_direction(down), Rates::of_direction(off)),
        ),
        (
            "momentum",
            pendulum
                .start_from_momentum(Configuration::of_direction(down), Rates::of_direction(off)),
        ),
    ] {
        let error = error.unwrap_err().to_string();
        assert!(
            error.contains(&format!("{what} of n leaves the sphere")),
            "{error}"
        );
    }
    // A refused start leaves the running state as it was.
    assert_eq!(*pendulum.state().unwrap(), before);
}

/// Turns of up to π per step. Spin about the symmetry axis of a symmetric body and a free unit
/// vector on a great circle are one-parameter subgroups, which the midpoint step in the
/// exponential chart follows exactly; an asymmetric body tumbling by 2.8 rad per step keeps its
/// spatial momentum. Steps past π, where the exponential chart ends (their equations would
/// belong to another branch of it), and one of 3 rad with the Cayley chart (whose step cannot
/// turn that far here) are errors that leave the state as it was.
#[test]
fn large_turns_per_step_are_exact_below_pi_and_refused_past_it() {
    use std::f64::consts::PI;
    let h = 0.1;
    let spun = |space: Product<0, 1, 0>, body, spin: Vector3<f64>| {
        rigid_body::started(
            body,
            space,
            Quadrature::midpoint(),
            h,
            (Matrix3::identity(), spin),
        )
        .unwrap()
    };
    for turn in [0.5, 3.0] {
        let spin = Vector3::new(0.0, 0.0, turn / h);
        let mut stepper = spun(Product::exp(), rigid_body::SYMMETRIC, spin);
        let p0 = stepper.p().rotation[0];
        stepper.run(3).unwrap();
        let r = stepper.q().rotation[0];
        let expected = Retraction::Exp.map(&(spin * (3.0 * h)));
        assert!(
            (r - expected).amax() < 1e-12,
            "{turn} rad per step: {r} vs {expected}"
        );
        assert!(
            (stepper.p().rotation[0] - p0).amax() < 1e-12 * p0.norm(),
            "{turn}"
        );
    }
    let tumbling = Vector3::new(3.0, -2.0, 28.0);
    let mut stepper = spun(Product::exp(), rigid_body::ASYMMETRIC, tumbling);
    let pi0 = stepper.q().spatial(&stepper.p(), 0);
    stepper.run(5).unwrap();
    let drift = (stepper.q().spatial(&stepper.p(), 0) - pi0).amax();
    assert!(drift < 1e-12 * pi0.norm(), "|ΔRΠ| = {drift:e}");
    // Past π about the symmetry axis the step's root lies outside the chart: refused as such.
    // Tumbling past π, or turning 3 rad with Cayley, Newton finds no root it can trust.
    let refusals = [
        (
            Product::exp(),
            rigid_body::SYMMETRIC,
            Vector3::new(0.0, 0.0, 35.0),
            true,
        ),
        (
            Product::exp(),
            rigid_body::ASYMMETRIC,
            Vector3::new(3.0, -2.0, 38.0),
            false,
        ),
        (
            Product::cayley(),
            rigid_body::SYMMETRIC,
            Vector3::new(0.0, 0.0, 30.0),
            false,
        ),
    ];
    for (space, body, spin, outside) in refusals {
        let mut stepper = spun(space, body, spin);
        let before = *stepper.state().unwrap();
        let error = stepper.step().unwrap_err();
        println!("{:?}, {:?}: {error}", space.retraction(), spin.as_slice());
        assert!(
            !outside || matches!(error, DiracError::OutsideChart(_)),
            "{error}"
        );
        assert_eq!(*stepper.state().unwrap(), before);
    }
    // A free unit vector follows a great circle, which the exponential chart's midpoint step
    // follows exactly up to π per step; past it the step is refused.
    let free = spherical_pendulum::SphericalPendulum {
        g: 0.0,
        ..spherical_pendulum::SCENE
    };
    let (n0, e) = (Vector3::z(), Vector3::x());
    for turn in [2.5, 3.0, 3.5] {
        let mut stepper =
            Stepper::on_manifold(free, Product::exp(), Quadrature::midpoint(), h).unwrap();
        stepper
            .start_from_velocity(
                Configuration::of_direction(n0),
                Rates::of_direction(e * (turn / h)),
            )
            .unwrap();
        let before = *stepper.state().unwrap();
        match stepper.step() {
            Ok(_) => {
                assert!(turn < PI, "{turn}");
                let n = stepper.q().direction[0];
                let expected = n0 * turn.cos() + e * turn.sin();
                assert!((n - expected).amax() < 1e-12, "{turn}: {n} vs {expected}");
            }
            Err(error) => {
                println!("S², {turn} rad per step: {error}");
                assert!(turn > PI, "{turn}: {error}");
                assert!(matches!(error, DiracError::OutsideChart(_)), "{error}");
                assert_eq!(*stepper.state().unwrap(), before);
            }
        }
    }
}

/// Events see the points on the group: a symmetric body spinning about its axis at ω turns its
/// first body axis through the `yz`-plane at `t = (k + ½)π/ω`. The run locates each crossing
/// with the event's function at zero to round-off on an attitude that is a rotation; in the
/// exponential chart (whose steps follow this spin exactly) at the dense output's accuracy, with
/// Cayley at order 2.
#[test]
fn events_locate_crossings_of_the_attitude() {
    use std::f64::consts::PI;
    let omega = 2.0;
    let crossings = |space: Product<0, 1, 0>, h: f64| {
        let mut stepper = rigid_body::started(
            rigid_body::SYMMETRIC,
            space,
            Quadrature::midpoint(),
            h,
            (Matrix3::identity(), Vector3::new(0.0, 0.0, omega)),
        )
        .unwrap();
        let axis = Event::new(
            "first axis in the yz-plane",
            |_t, q: &Configuration<f64, 0, 1, 0>, _v: &Rates<f64, 0, 1, 0>| q.rotation[0][(0, 0)],
        );
        let solution = stepper.solve(Run::until(4.0).event(axis)).unwrap();
        assert_eq!(
            solution.events.len(),
            3,
            "{:?}, h = {h}",
            space.retraction()
        );
        let mut worst = 0.0_f64;
        for (k, crossing) in solution.events.iter().enumerate() {
            let r = crossing.sample.q.rotation[0];
            assert!(r[(0, 0)].abs() < 1e-14, "{}", r[(0, 0)]);
            assert!(orthogonality(&r) < 1e-14);
            let expected = (k as f64 + 0.5) * PI / omega;
            worst = worst.max((crossing.sample.t - expected).abs());
        }
        (h, worst)
    };
    let (_, exact) = crossings(Product::exp(), 0.01);
    println!("exp, h = 0.01: crossing times within {exact:.1e}");
    assert!(exact < 1e-12, "{exact:e}");
    let errors: Vec<(f64, f64)> = [0.04, 0.02, 0.01, 0.005]
        .iter()
        .map(|&h| crossings(Product::cayley(), h))
        .collect();
    order_of("Cayley crossing times", &errors, 2.0);
}

/// A step that cannot converge (a step far too large for the spin) is an error that leaves the
/// state as it was.
#[test]
fn a_failed_step_on_the_group_changes_nothing() {
    let (r0, _) = rigid_body::top_start();
    let mut stepper = rigid_body::started(
        rigid_body::TOP,
        Product::cayley(),
        Quadrature::midpoint(),
        0.5,
        (r0, Vector3::new(3.0, -2.0, 400.0)),
    )
    .unwrap();
    let before = *stepper.state().unwrap();
    let error = stepper.step().unwrap_err();
    assert!(
        matches!(
            error,
            DiracError::NoConvergence { .. }
                | DiracError::UntrustedStep { .. }
                | DiracError::SingularJacobian { .. }
                | DiracError::NonFinite { .. }
        ),
        "{error}"
    );
    assert_eq!(*stepper.state().unwrap(), before);
    assert_eq!(stepper.steps(), 0);
}

/// The group step equations on `Rⁿ` (`Stepper::on_manifold` with `Euclidean`) step like the
/// vector ones: the double pendulum steps alike through both. (The moving chart's own rows are
/// compared with the fixed chart's in the unit tests of `discrete_lagrangian`.)
#[test]
fn the_group_step_equations_reduce_to_the_vector_ones_on_vectors() {
    use scenes::double_pendulum;
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let (q0, v0) = (vector![0.7, -0.3], vector![0.2, 0.5]);
        let mut fixed = Stepper::new(double_pendulum::SCENE, quadrature.clone(), 0.01).unwrap();
        let mut moving =
            Stepper::on_manifold(double_pendulum::SCENE, Euclidean, quadrature, 0.01).unwrap();
        fixed.start_from_velocity(q0, v0).unwrap();
        moving.start_from_velocity(q0, v0).unwrap();
        fixed.run(300).unwrap();
        moving.run(300).unwrap();
        assert!((fixed.q() - moving.q()).amax() < 1e-12);
        assert!((fixed.p() - moving.p()).amax() < 1e-12);
    }
}

/// Runs on the group record attitudes, velocities and momenta with the product's column names,
/// and the dense output passes through the step's ends on the manifold.
#[test]
fn runs_record_attitudes_and_interpolate_on_the_group() {
    let mut stepper = rigid_body::started(
        rigid_body::TOP,
        Product::cayley(),
        Quadrature::galerkin(2).unwrap(),
        0.02,
        rigid_body::top_start(),
    )
    .unwrap();
    let solution = stepper
        .solve(Run::until(0.2).saveat([0.0, 0.05, 0.1]))
        .unwrap();
    let names = solution.trajectory.column_names();
    assert_eq!(&names[..4], ["t", "R_11", "R_12", "R_13"]);
    assert!(names.contains(&"v_R_z".to_string()) && names.contains(&"p_R_x".to_string()));
    let mut csv = Vec::new();
    solution.trajectory.write_csv(&mut csv).unwrap();
    assert_eq!(String::from_utf8(csv).unwrap().lines().count(), 4);
    for q in solution.trajectory.q() {
        assert!(orthogonality(&q.rotation[0]) < 1e-13);
    }
    // The dense output at the end of the last step is its end state.
    let end = stepper.interpolate(stepper.t()).unwrap();
    assert!((end.q.rotation[0] - stepper.q().rotation[0]).amax() < 1e-13);
    let inside = stepper.interpolate(stepper.t() - 0.01).unwrap();
    assert!(orthogonality(&inside.q.rotation[0]) < 1e-13);
}

/// The hand-written Lie group variational integrator of the bench (Lee, Leok and McClamroch's,
/// Newton on the Cayley parameter) converges at order 2 to the same reference as the generated
/// steppers: the bench compares two correct second-order schemes.
#[test]
fn the_hand_written_lgvi_of_the_bench_converges_at_order_two() {
    use scenes::hand_written_lgvi::HandLgvi;
    let t_end = 1.0;
    let (r0, omega0) = rigid_body::pendulum_start();
    let (r_ref, pi_ref) =
        rigid_body::reference(&rigid_body::PENDULUM, &r0, &omega0, t_end, 1e-13).unwrap();
    let errors: Vec<(f64, f64)> = [20, 40, 80, 160]
        .iter()
        .map(|&n| {
            let h = t_end / n as f64;
            let mut hand = HandLgvi::new(&rigid_body::PENDULUM, h, r0, omega0);
            for _ in 0..n {
                hand.step().unwrap();
            }
            (h, (hand.r - r_ref).amax().max((hand.pi - pi_ref).amax()))
        })
        .collect();
    order_of("hand-written LGVI", &errors, 2.0);
}

/// A chain of two rigid bodies (`links[2]: SO3`, a 3D double pendulum of bodies). Its Lagrangian
/// written as an expression (with `Ṙ d`) and as a function of the typed points (with `R (Ω × d)`)
/// step alike; the total vertical angular momentum is conserved to round-off and the energy error
/// stays bounded over 2·10⁴ steps; with the joint at the pivot (`d = 0`) the bodies decouple into
/// two heavy tops that step like the single-body model.
#[test]
fn a_chain_of_rigid_bodies_keeps_its_momentum_and_decouples_into_tops() {
    use scenes::rigid_chain::{self, CHAIN, RigidChain, RigidChainByFunction};
    let (h, (q0, v0)) = (0.01, rigid_chain::start());
    let started = |stepper: &mut ManifoldStepper<_, 6, Product<0, 2, 0>>| {
        stepper.start_from_velocity(q0, v0).unwrap();
    };
    let space = Product::cayley();
    let mut expression = Stepper::on_manifold(CHAIN, space, Quadrature::midpoint(), h).unwrap();
    started(&mut expression);
    let mut function = Stepper::on_manifold(
        RigidChainByFunction::from(CHAIN),
        space,
        Quadrature::midpoint(),
        h,
    )
    .unwrap();
    function.start_from_velocity(q0, v0).unwrap();
    let trajectory = expression.run(200).unwrap();
    function.run(200).unwrap();
    for a in 0..2 {
        let gap = (expression.q().rotation[a] - function.q().rotation[a]).amax()
            + (expression.p().rotation[a] - function.p().rotation[a]).amax();
        println!("chain body {a}: expression and function differ by {gap:.1e} after 200 steps");
        assert!(
            gap < 1e-10,
            "body {a}: expression and function differ by {gap:e}"
        );
    }
    // The chain moves: both bodies turn by more than a radian in 2 s.
    let turned = |a: usize| {
        Retraction::Exp
            .inverse(&(q0.rotation[a].transpose() * expression.q().rotation[a]))
            .map_or(f64::INFINITY, |xi| xi.norm())
    };
    assert!(
        turned(0) > 1.0 && turned(1) > 1.0,
        "{} {}",
        turned(0),
        turned(1)
    );
    let lz0 = rigid_chain::vertical_momentum(&trajectory.q()[0], &trajectory.p()[0]);
    let scale = (trajectory.q()[0].spatial(&trajectory.p()[0], 0)).norm();
    let trajectory = expression.run(20_000).unwrap();
    let drift = trajectory
        .q()
        .iter()
        .zip(trajectory.p())
        .map(|(q, p)| (rigid_chain::vertical_momentum(q, p) - lz0).abs())
        .fold(0.0, f64::max);
    let e0 = trajectory.energy()[0];
    println!(
        "chain, 2·10⁴ steps: |ΔL_z| ≤ {drift:.1e} of |RΠ| = {scale:.3}, energy error {:.1e} of {e0:.3}",
        trajectory.max_energy_error()
    );
    assert!(drift <= 1e-12 * scale, "|ΔL_z| = {drift:e} of {scale:e}");
    assert!(
        trajectory.max_energy_error() < 1e-2 * e0.abs(),
        "energy error {:e} of {e0:e}",
        trajectory.max_energy_error()
    );

    // With d = 0 the second body is a top about the pivot: J = J₂ + m₂ (|ρ₂|² I − ρ₂ ρ₂ᵀ).
    let decoupled = RigidChain {
        d: [0.0; 3],
        ..CHAIN
    };
    let mut chain = Stepper::on_manifold(decoupled, space, Quadrature::midpoint(), h).unwrap();
    started(&mut chain);
    let rho2 = Vector3::from(CHAIN.rho2);
    let shifted = Matrix3::from(CHAIN.j2).transpose()
        + (Matrix3::identity() * rho2.norm_squared() - rho2 * rho2.transpose()) * CHAIN.m2;
    let tops = [
        rigid_body::HeavyTop {
            j: CHAIN.j1,
            m: CHAIN.m1,
            g: CHAIN.g,
            rho: CHAIN.rho1,
        },
        rigid_body::HeavyTop {
            j: shifted.transpose().into(),
            m: CHAIN.m2,
            g: CHAIN.g,
            rho: CHAIN.rho2,
        },
    ];
    chain.run(1000).unwrap();
    for (a, top) in tops.into_iter().enumerate() {
        let mut single = rigid_body::started(
            top,
            Product::cayley(),
            Quadrature::midpoint(),
            h,
            (q0.rotation[a], v0.rotation[a]),
        )
        .unwrap();
        single.run(1000).unwrap();
        let gap = (chain.q().rotation[a] - single.q().rotation[0]).amax()
            + (chain.p().rotation[a] - single.p().rotation[0]).amax();
        println!("decoupled chain body {a}: differs from its single top by {gap:.1e}");
        assert!(
            gap < 1e-10,
            "body {a}: chain and single top differ by {gap:e}"
        );
    }
}

/// The attitude views: the quaternion of a rotation by `θ` about `a` is `[cos(θ/2), sin(θ/2) a]`
/// and rebuilds `R = (w² − |v|²) I + 2 v vᵀ + 2 w v̂`; the Euler angles of
/// `R_z(yaw) R_y(pitch) R_x(roll)`, built here from the three elementary matrices, are
/// `[roll, pitch, yaw]`.
#[test]
fn attitudes_read_as_quaternions_and_euler_angles() {
    let elementary = |axis: usize, angle: f64| {
        let (c, s) = (angle.cos(), angle.sin());
        match axis {
            0 => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
            1 => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
            _ => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
        }
    };
    for (roll, pitch, yaw) in [(0.1, -0.2, 0.3), (-2.5, 1.2, 3.0), (0.0, -1.5, -0.7)] {
        let r = elementary(2, yaw) * elementary(1, pitch) * elementary(0, roll);
        let q = Configuration::of_rotation(r);
        let [a, b, c] = q.euler_angles(0).unwrap();
        assert!((a - roll).abs() < 1e-14 && (b - pitch).abs() < 1e-14 && (c - yaw).abs() < 1e-14);
        let [w, x, y, z] = q.quaternion(0).unwrap();
        let v = Vector3::new(x, y, z);
        let rebuilt = Matrix3::identity() * (w * w - v.norm_squared())
            + v * v.transpose() * 2.0
            + dirac::rotation::hat(&v) * (2.0 * w);
        assert!((rebuilt - r).amax() < 1e-14 && w >= 0.0);
        assert!((w * w + v.norm_squared() - 1.0).abs() < 1e-15);
    }
    for (theta, axis) in [
        (0.3, Vector3::new(1.0, 2.0, -2.0) / 3.0),
        (3.0, Vector3::z()),
    ] {
        let r = Retraction::Exp.map(&(axis * theta));
        let [w, x, y, z] = dirac::rotation::quaternion(&r);
        let expected = [(theta / 2.0).cos(), 0.0, 0.0, 0.0];
        assert!((w - expected[0]).abs() < 1e-15);
        assert!((Vector3::new(x, y, z) - axis * (theta / 2.0).sin()).amax() < 1e-15);
    }
    assert_eq!(
        Configuration::of_rotation(Matrix3::identity()).quaternion(1),
        None
    );
}
