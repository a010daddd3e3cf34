//! Step-map derivatives on rotations and unit vectors, in the cotangent lift of the chart at
//! each end of the step: against central differences through the retraction (with forces
//! that read positions, velocities and inputs, at midpoint and Galerkin steps, with Cayley and
//! exp), symplectic for conservative models, and equal on `Rⁿ` to the vector step's.

use dirac::configuration_space::{ConfigurationSpace, Point, Positive, Tangent};
use dirac::nalgebra::DMatrix;
use dirac::prelude::*;
use dirac::product::Product;
use scenes::{double_pendulum, rigid_body, rigid_chain, satellite, spherical_pendulum};

/// A mass on a spring, a body and a pendulum, `(r, R, n) ∈ R × SO(3) × S²`, coupled, with a
/// damper on every coordinate and two inputs (a force on `r`, a torque on the body).
#[dirac_system(
    coordinates(r, R: SO3, n: S2),
    lagrangian = 0.5 * dot(r) * dot(r) + 0.5 * dot(omega(R), j * omega(R))
        + 0.5 * dot(dot(n), dot(n)) - g * n[2] - 0.5 * k * r * r
        - c * dot(R * [0.0, 0.0, 1.0], n) + r * n[0],
    forces((u - d * dot(r)) * dr, dot([w - d * omega(R)[0], -d * omega(R)[1], r * n[1]], dR),
        dot([-d * dot(n)[0], -d * dot(n)[1], -d * dot(n)[2] + u * r], dn)),
    inputs(u, w),
)]
#[derive(Debug, Clone, Copy)]
struct Damped {
    j: [[f64; 3]; 3],
    g: f64,
    k: f64,
    c: f64,
    d: f64,
}

const DAMPED: Damped = Damped {
    j: [[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 4.0]],
    g: 1.5,
    k: 2.0,
    c: 0.7,
    d: 0.3,
};

/// The largest entry of `a`, and of `a − b` relative to it.
fn relative_gap(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / a.amax().max(1e-300)
}

/// `(A, B)` of `steps` steps of `stepper` from `(q, p)` by central differences through the
/// retraction: each perturbation `(δ, dμ)` starts the step at `R_q(δ)` with the momentum whose
/// pull-back to the chart at `q` is `μ + dμ`, and the end is read in the chart at the
/// unperturbed end, position by `R⁻¹` and momentum by the pull-back.
fn central_differences<S, C, const N: usize>(
    stepper: &mut ManifoldStepper<S, N, C>,
    q: &Point<C, N, f64>,
    p: &Tangent<C, N, f64>,
    inputs: &[f64],
    step: f64,
    steps: u64,
) -> (DMatrix<f64>, DMatrix<f64>)
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    let space = stepper.space().clone();
    let zero = SVector::<f64, N>::zeros();
    let mu = space.pull_back(q, &zero, p);
    let mut run = |delta: &SVector<f64, N>, d_mu: &SVector<f64, N>, u: &[f64]| {
        let start = space.retract(q, delta);
        let momentum = space.push_covector(q, delta, &(mu + d_mu)).unwrap();
        stepper.set_inputs(u).unwrap();
        stepper.start_from_momentum(start, momentum).unwrap();
        stepper.run(steps).unwrap();
        (stepper.q(), stepper.p())
    };
    let (end, _) = run(&zero, &zero, inputs);
    let mut read = |delta: &SVector<f64, N>, d_mu: &SVector<f64, N>, u: &[f64]| {
        let (q1, p1) = run(delta, d_mu, u);
        let eps = space.local(&end, &q1).unwrap();
        let mu1 = space.pull_back(&end, &eps, &p1);
        eps.iter().chain(mu1.iter()).copied().collect::<Vec<f64>>()
    };
    let mut a = DMatrix::zeros(2 * N, 2 * N);
    for c in 0..2 * N {
        let mut column = |sign: f64| {
            let mut delta = zero;
            let mut d_mu = zero;
            if c < N {
                delta[c] = sign * step;
            } else {
                d_mu[c - N] = sign * step;
            }
            read(&delta, &d_mu, inputs)
        };
        let (plus, minus) = (column(1.0), column(-1.0));
        for r in 0..2 * N {
            a[(r, c)] = (plus[r] - minus[r]) / (2.0 * step);
        }
    }
    let mut b = DMatrix::zeros(2 * N, inputs.len());
    for c in 0..inputs.len() {
        let mut moved = |sign: f64| {
            let mut u = inputs.to_vec();
            u[c] += sign * step;
            read(&zero, &zero, &u)
        };
        let (plus, minus) = (moved(1.0), moved(-1.0));
        for r in 0..2 * N {
            b[(r, c)] = (plus[r] - minus[r]) / (2.0 * step);
        }
    }
    (a, b)
}

/// `A`, `B` of `stepper`'s step from `(q, v)` with `inputs` against central differences
/// (relative to their largest entry), and `A`'s symplecticity defect.
fn check<S, C, const N: usize>(
    mut stepper: ManifoldStepper<S, N, C>,
    q: Point<C, N, f64>,
    v: Tangent<C, N, f64>,
    inputs: &[f64],
) -> (f64, f64, f64)
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    stepper.set_inputs(inputs).unwrap();
    stepper.start_from_velocity(q, v).unwrap();
    let p = stepper.p();
    let derivatives = stepper.step_linearised().unwrap();
    let (a, b) = central_differences(&mut stepper, &q, &p, inputs, 1e-5, 1);
    let a_gap = relative_gap(&derivatives.matrix(), &a);
    let b_gap = if inputs.is_empty() {
        0.0
    } else {
        relative_gap(&derivatives.input_matrix(), &b)
    };
    (a_gap, b_gap, derivatives.symplecticity_defect())
}

/// A generic state of `R × SO(3) × S²`.
fn generic_state() -> (Configuration<f64, 1, 1, 1>, Rates<f64, 1, 1, 1>) {
    let n = Vector3::new(0.3, -0.4, 0.8).normalize();
    let n_dot = Vector3::new(0.5, 0.2, -0.1);
    let q = Configuration::new(
        vector![0.3],
        [Retraction::Exp.map(&Vector3::new(0.3, -0.2, 0.5))],
        [n],
    );
    let v = Rates::new(
        vector![0.2],
        [Vector3::new(0.4, -0.3, 0.6)],
        [n_dot - n * n.dot(&n_dot)],
    );
    (q, v)
}

/// `A` and `B` of a forced model on `R × SO(3) × S²` (damping that reads positions and
/// velocities, two inputs) match central differences through the retraction, at the midpoint
/// and at Galerkin(2) (with an internal point), with both retractions.
#[test]
fn derivatives_on_groups_match_central_differences() {
    let (q, v) = generic_state();
    for space in [Product::cayley(), Product::exp()] {
        for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
            let name = format!("{:?} {}", space.retraction(), quadrature.name());
            let stepper = Stepper::on_manifold(DAMPED, space, quadrature, 0.05).unwrap();
            let (a, b, _) = check(stepper, q, v, &[0.4, -0.2]);
            println!("{name}: A {a:.1e}, B {b:.1e}");
            assert!(a < 1e-7 && b < 1e-7, "{name}: A {a:.1e}, B {b:.1e}");
        }
    }
}

/// Conservative models on SO(3), S² and a product keep the canonical structure: their `A`
/// matches central differences and is symplectic to round-off; the satellite's torques (held
/// at zero, so that the step is conservative) give `B`.
#[test]
fn conservative_steps_on_groups_are_symplectic() {
    let at = Retraction::Exp.map(&Vector3::new(0.4, 0.9, -0.3));
    let spin = Rates::of_rotation(Vector3::new(0.7, -1.1, 0.4));
    for retraction in [Retraction::Cayley, Retraction::Exp] {
        for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
            let name = format!("{retraction:?} {}", quadrature.name());
            let space = Product::new(retraction);
            let top = Stepper::on_manifold(rigid_body::PENDULUM, space, quadrature.clone(), 0.05);
            let (a, _, defect) = check(top.unwrap(), Configuration::of_rotation(at), spin, &[]);
            println!("3D pendulum {name}: A {a:.1e}, defect {defect:.1e}");
            assert!(
                a < 1e-7 && defect < 1e-12,
                "3D pendulum {name}: {a:.1e} {defect:.1e}"
            );

            let n = Vector3::new(0.6, 0.0, -0.8);
            let pendulum = Stepper::on_manifold(
                spherical_pendulum::SCENE,
                Product::new(retraction),
                quadrature.clone(),
                0.05,
            );
            let (a, _, defect) = check(
                pendulum.unwrap(),
                Configuration::of_direction(n),
                Rates::of_direction(Vector3::new(0.0, 1.3, 0.0)),
                &[],
            );
            println!("spherical pendulum {name}: A {a:.1e}, defect {defect:.1e}");
            assert!(
                a < 1e-7 && defect < 1e-12,
                "spherical {name}: {a:.1e} {defect:.1e}"
            );

            let satellite =
                Stepper::on_manifold(satellite::SCENE, Product::new(retraction), quadrature, 0.05);
            let (a, b, defect) = check(
                satellite.unwrap(),
                Configuration::of_rotation(at),
                spin,
                &[0.0; 3],
            );
            println!("satellite {name}: A {a:.1e}, B {b:.1e}, defect {defect:.1e}");
            assert!(a < 1e-7 && b < 1e-7 && defect < 1e-12, "satellite {name}");
        }
    }
}

/// A double spherical pendulum, `(n₀, n₁) ∈ S² × S²`: two unit vectors, conservative (their
/// momenta then advance by the torque path).
#[dirac_system(
    coordinates(n[2]: S2),
    lagrangian = 0.5 * dot(dot(n[0]), dot(n[0]))
        + 0.25 * dot(dot(n[0]) + dot(n[1]), dot(n[0]) + dot(n[1]))
        - g * (1.5 * n[0][2] + 0.5 * n[1][2]),
)]
#[derive(Debug, Clone, Copy)]
struct DoubleSpherical {
    g: f64,
}

/// Two unit vectors (`DoubleSpherical`) and two rotations (the rigid chain): `A` against
/// central differences and symplectic, at the midpoint, trapezoid and Galerkin(3) rules.
#[test]
fn derivatives_with_several_rotations_and_unit_vectors() {
    let pendulum = DoubleSpherical { g: 2.0 };
    let q = Configuration::new(
        SVector::zeros(),
        [],
        [Vector3::new(0.6, 0.0, -0.8), Vector3::new(0.0, 0.8, -0.6)],
    );
    let v = Rates::new(
        SVector::zeros(),
        [],
        [Vector3::new(0.0, 0.7, 0.0), Vector3::new(0.5, 0.0, 0.0)],
    );
    let (chain_q, chain_v) = rigid_chain::start();
    for quadrature in [
        Quadrature::midpoint(),
        Quadrature::trapezoid(),
        Quadrature::galerkin(3).unwrap(),
    ] {
        let name = quadrature.name();
        let stepper = Stepper::on_manifold(pendulum, Product::exp(), quadrature.clone(), 0.02);
        let (a, _, defect) = check(stepper.unwrap(), q, v, &[]);
        println!("S² × S² {name}: A {a:.1e}, defect {defect:.1e}");
        assert!(
            a < 1e-7 && defect < 1e-12,
            "S² × S² {name}: {a:.1e} {defect:.1e}"
        );
        let chain = Stepper::on_manifold(rigid_chain::CHAIN, Product::cayley(), quadrature, 0.005);
        let (a, _, defect) = check(chain.unwrap(), chain_q, chain_v, &[]);
        println!("rigid chain {name}: A {a:.1e}, defect {defect:.1e}");
        assert!(
            a < 1e-7 && defect < 1e-12,
            "chain {name}: {a:.1e} {defect:.1e}"
        );
    }
}

/// The derivatives read the end in the chart the next step starts in: two steps' `A_2 A_1` and
/// `A_2 B_1 + B_2` are the two-step map's, by central differences.
#[test]
fn derivatives_of_consecutive_steps_compose() {
    let (q, v) = generic_state();
    let inputs = [0.4, -0.2];
    let mut stepper =
        Stepper::on_manifold(DAMPED, Product::cayley(), Quadrature::midpoint(), 0.05).unwrap();
    stepper.set_inputs(&inputs).unwrap();
    stepper.start_from_velocity(q, v).unwrap();
    let p = stepper.p();
    let first = stepper.step_linearised().unwrap();
    let second = stepper.step_linearised().unwrap();
    let a = second.matrix() * first.matrix();
    let b = second.matrix() * first.input_matrix() + second.input_matrix();
    let (a_fd, b_fd) = central_differences(&mut stepper, &q, &p, &inputs, 1e-5, 2);
    let (a_gap, b_gap) = (relative_gap(&a, &a_fd), relative_gap(&b, &b_fd));
    println!("two steps: A {a_gap:.1e}, B {b_gap:.1e}");
    assert!(a_gap < 1e-7 && b_gap < 1e-7, "A {a_gap:.1e}, B {b_gap:.1e}");
}

/// On `Rⁿ` the group step equations' derivatives are the vector step's.
#[test]
fn group_derivatives_on_vectors_are_the_vector_steps() {
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(3).unwrap()] {
        let mut fixed = Stepper::new(double_pendulum::SCENE, quadrature.clone(), 0.02).unwrap();
        let mut group =
            Stepper::on_manifold(double_pendulum::SCENE, Euclidean, quadrature, 0.02).unwrap();
        let (q, v) = (vector![0.4, -0.9], vector![1.1, 0.3]);
        fixed.start_from_velocity(q, v).unwrap();
        group.start_from_velocity(q, v).unwrap();
        let (a, b) = (
            fixed.step_linearised().unwrap(),
            group.step_linearised().unwrap(),
        );
        // The two steps reach their roots by different sums: they agree to Newton's tolerance,
        // and the derivatives (measured 1.6e-12 at Galerkin(3)) to a little more.
        let gap = relative_gap(&a.matrix(), &b.matrix());
        println!("{}: {gap:.1e}", fixed.quadrature().name());
        assert!(gap < 1e-10, "{gap:.1e}");
    }
}

/// A particle held in the positive half-line, `R_q(ξ) = q exp ξ`, with a damper and a force
/// input.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x) * dot(x) - 0.5 * (x - 1.0) * (x - 1.0) + ln(x),
    forces((u - 0.2 * dot(x)) * dx),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct Held;

/// On the positive half-line (`Positive`, through the group step equations) the derivatives
/// match central differences through its retraction.
#[test]
fn derivatives_on_the_positive_half_line_match_central_differences() {
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let name = quadrature.name();
        let stepper = Stepper::on_manifold(Held, Positive, quadrature, 0.1).unwrap();
        let (a, b, _) = check(stepper, vector![0.7], vector![0.4], &[0.3]);
        println!("Positive {name}: A {a:.1e}, B {b:.1e}");
        assert!(a < 1e-7 && b < 1e-7, "{name}: A {a:.1e}, B {b:.1e}");
    }
}

/// A ball with an uneven inertia rolling without slipping down a slope `s`, pushed along `x`:
/// the rolling one-forms carry impulses at every step.
#[dirac_system(
    coordinates(x, y, R: SO3),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) + 0.5 * dot(omega(R), j * omega(R))
        + m * s * x,
    constraints(dx - r * (R * dR)[1], dy + r * (R * dR)[0]),
    forces(u * dx),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct Rolling {
    m: f64,
    j: [[f64; 3]; 3],
    r: f64,
    s: f64,
}

/// Nonholonomic one-forms on a group (`Rolling`, `R² × SO(3)`, two one-forms) at each
/// constraint point: `A` and `B` against central differences (the perturbed starts solve for
/// the velocity the forms allow), with multipliers that do not vanish.
#[test]
fn derivatives_with_one_forms_on_groups_match_central_differences() {
    let ball = Rolling {
        m: 1.0,
        j: [[0.5, 0.05, 0.0], [0.05, 0.4, 0.1], [0.0, 0.1, 0.3]],
        r: 0.8,
        s: 1.2,
    };
    let r0 = Retraction::Exp.map(&Vector3::new(0.2, -0.3, 0.1));
    let omega = Vector3::new(0.3, 0.8, 0.5);
    let q = Configuration::new(vector![0.1, -0.2], [r0], []);
    let v = Rates::new(
        vector![ball.r * omega[1], -ball.r * omega[0]],
        [r0.transpose() * omega],
        [],
    );
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        let stepper = Stepper::on_manifold(ball, Product::cayley(), Quadrature::midpoint(), 0.05)
            .unwrap()
            .with_constraint_point(point);
        let (a, b, _) = check(stepper, q, v, &[0.3]);
        println!("rolling {point:?}: A {a:.1e}, B {b:.1e}");
        assert!(a < 1e-7 && b < 1e-7, "{point:?}: A {a:.1e}, B {b:.1e}");
    }
}

/// LQR on the derivatives on `R³ × SO(3)` stabilises a satellite with three reaction wheels:
/// at the target `A` is marginal on the attitude and the wheels' momenta (spectral radius 1)
/// and `A − BK` contracts; from rest 0.78 rad away the closed loop (the feedback computed inside
/// the run) brings the attitude within 1e-2 rad in 20 s, and the spatial angular momentum stays
/// zero to round-off (the motors' torques are internal).
#[test]
fn lqr_on_the_group_derivatives_stabilises_a_satellite_with_reaction_wheels() {
    use scenes::reaction_wheels::{self, REGULATED};
    let h = 0.05;
    let regulator = reaction_wheels::regulator(h, 0.01).unwrap();
    let regulated = |m: &DMatrix<f64>| {
        DMatrix::from_fn(REGULATED.len(), REGULATED.len(), |i, j| {
            m[(REGULATED[i], REGULATED[j])]
        })
    };
    let radius = |m: &DMatrix<f64>| {
        m.complex_eigenvalues()
            .iter()
            .map(|e| e.norm())
            .fold(0.0, f64::max)
    };
    let open = radius(&regulated(&regulator.a));
    let closed = radius(&regulated(&(&regulator.a - &regulator.b * &regulator.k)));
    // A's eigenvalue 1 is defective (the attitude drifts at a constant rate): round-off moves it
    // by about √ε.
    assert!(
        (open - 1.0).abs() < 1e-6 && closed < 0.995,
        "{open} {closed}"
    );
    let tilt = reaction_wheels::tilt();
    let samples = reaction_wheels::stabilised(&regulator.k, tilt, h, 20.0, 20).unwrap();
    let (first, last) = (samples[0], samples[samples.len() - 1]);
    let momentum = samples.iter().map(|s| s.momentum).fold(0.0, f64::max);
    println!(
        "angle {:.2e} → {:.2e} rad, |Ω| {:.1e}, momentum ≤ {momentum:.1e}",
        first.angle, last.angle, last.rate
    );
    assert!((first.angle - tilt.norm()).abs() < 1e-12);
    assert!(last.angle < 1e-2 && last.rate < 5e-3, "{last:?}");
    assert!(momentum < 1e-13, "{momentum:.1e}");
}
