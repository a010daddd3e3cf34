//! The discrete Hamiltonian route (`H_d⁺`, Galerkin): measured orders 2, 4, 6 against closed
//! forms and Dop853, a non-separable Hamiltonian (bounded energy, order, the same steps as its
//! Lagrangian), Kepler's angular momentum to round-off, the knife edge written with `H` against
//! its closed form and the Lagrangian scene, forces and inputs, a Hamiltonian with no Lagrangian,
//! and the errors.

use crate::support;

use dirac::prelude::*;
use dirac::{Hamilton, HamiltonianSystem, StepEquations};
use ode_solvers::System;
use scenes::hamiltonian::{
    Coupled, CoupledLagrangian, Damped, Kepler, KnifeEdge, Lifted, PENDULUM, lifted_exact,
};
use support::assert_order;

/// The quadratures of orders 2, 4 and 6 with their orders.
fn orders() -> Vec<(Quadrature, f64)> {
    vec![
        (Quadrature::midpoint(), 2.0),
        (Quadrature::trapezoid(), 2.0),
        (Quadrature::galerkin(2).unwrap(), 4.0),
        (Quadrature::galerkin(3).unwrap(), 6.0),
    ]
}

/// Four steps that divide `t`, halving, where a rule of `order` is in its asymptotic range and
/// above the references' floor (about 1e-13): 8 to 64 steps for order 6, 16 to 128 for order
/// 4, 32 to 256 for order 2.
fn steps_for(order: f64, t: f64) -> Vec<f64> {
    let first = if order >= 6.0 {
        8.0
    } else if order >= 4.0 {
        16.0
    } else {
        32.0
    };
    (0..4).map(|k| t / (first * 2f64.powi(k))).collect()
}

/// The order `quadrature` reaches on `system` from `(q0, p0)` to `t`, measured by `error` of
/// the end state over the steps of [`steps_for`], asserted to be `order`.
fn assert_route_order<S: HamiltonianSystem<1> + Clone>(
    what: &str,
    system: S,
    (quadrature, order): (Quadrature, f64),
    t: f64,
    error: impl Fn(f64, f64) -> f64,
) {
    let hs = steps_for(order, t);
    let errors: Vec<f64> = hs
        .iter()
        .map(|&h| {
            let steps = (t / h).round() as usize;
            let (q, p) = end(
                system.clone(),
                &quadrature,
                h,
                steps,
                vector![1.0],
                vector![0.0],
            );
            error(q[0], p[0])
        })
        .collect();
    assert_order(
        &format!("{what}, {}", quadrature.name()),
        &hs,
        &errors,
        order,
    );
}

/// The end of a run of `steps` steps of `h` from `(q0, p0)` on the Hamiltonian route.
fn end<S: HamiltonianSystem<N>, const N: usize>(
    system: S,
    quadrature: &Quadrature,
    h: f64,
    steps: usize,
    q0: SVector<f64, N>,
    p0: SVector<f64, N>,
) -> (SVector<f64, N>, SVector<f64, N>) {
    let mut stepper = Stepper::hamiltonian(system, quadrature.clone(), h).unwrap();
    stepper.start_from_momentum(q0, p0).unwrap();
    for _ in 0..steps {
        stepper.step().unwrap();
    }
    let state = stepper.state().unwrap();
    (*state.q(), *state.p())
}

/// `H = (p² + q²)/2` written by hand.
#[derive(Clone)]
struct Oscillator;

impl HamiltonianSystem<1> for Oscillator {
    fn hamiltonian<D: Scalar>(&self, q: &SVector<D, 1>, p: &SVector<D, 1>) -> D {
        (p[0] * p[0] + q[0] * q[0]) * 0.5
    }
}

#[test]
fn the_oscillator_converges_at_orders_2_4_and_6() {
    let t: f64 = 2.0;
    for rule in orders() {
        assert_route_order("oscillator", Oscillator, rule, t, |q, p| {
            (q - t.cos()).abs().max((p + t.sin()).abs())
        });
    }
}

/// The pendulum's ODE `θ̇ = p/(m l²)`, `ṗ = −m g l sin θ`, for Dop853.
struct PendulumOde;

type Y2 = ode_solvers::SVector<f64, 2>;

impl System<f64, Y2> for PendulumOde {
    fn system(&self, _t: f64, y: &Y2, dy: &mut Y2) {
        let (m, l, g) = (PENDULUM.m, PENDULUM.l, PENDULUM.g);
        dy[0] = y[1] / (m * l * l);
        dy[1] = -m * g * l * y[0].sin();
    }
}

#[test]
fn the_pendulum_converges_at_orders_2_4_and_6_against_dop853() {
    let t: f64 = 2.0;
    let reference = scenes::peers::dop853_end(PendulumOde, Y2::new(1.0, 0.0), t, 1e-14).unwrap();
    for rule in orders() {
        assert_route_order("pendulum", PENDULUM, rule, t, |q, p| {
            (q - reference[0]).abs().max((p - reference[1]).abs())
        });
    }
}

/// The non-separable `Coupled`'s ODE: `q̇ = (q² + 1) p`, `ṗ = −q (p² + 1)`.
struct CoupledOde;

impl System<f64, Y2> for CoupledOde {
    fn system(&self, _t: f64, y: &Y2, dy: &mut Y2) {
        dy[0] = (y[0] * y[0] + 1.0) * y[1];
        dy[1] = -y[0] * (y[1] * y[1] + 1.0);
    }
}

#[test]
fn a_non_separable_hamiltonian_converges_at_its_orders_against_dop853() {
    let t: f64 = 3.0;
    let reference = scenes::peers::dop853_end(CoupledOde, Y2::new(1.0, 0.0), t, 1e-14).unwrap();
    for rule in orders() {
        assert_route_order("H = (q²+1)(p²+1)/2", Coupled, rule, t, |q, p| {
            (q - reference[0]).abs().max((p - reference[1]).abs())
        });
    }
}

#[test]
fn a_non_separable_hamiltonian_keeps_its_energy_bounded_without_drift() {
    let mut stepper = Stepper::hamiltonian(Coupled, Quadrature::midpoint(), 0.05).unwrap();
    stepper
        .start_from_momentum(vector![0.5], vector![0.0])
        .unwrap();
    let trajectory = stepper.run(100_000).unwrap();
    let (first, last) = support::energy_error_first_and_last_tenth(trajectory.energy());
    println!("energy error: first tenth {first:.3e}, last tenth {last:.3e}");
    // Midpoint at h = 0.05: an O(h²) oscillation, the same in the first and the last tenth.
    assert!(first > 1e-6 && first < 1e-2, "{first}");
    assert!(last < 1.1 * first, "drift: {first} then {last}");
}

/// Where `∂²H/∂p²` is invertible both routes extremise the same action: the Hamiltonian route's
/// steps are the Lagrangian route's with the same quadrature, to solver tolerance.
#[test]
fn the_two_routes_take_the_same_steps_where_the_legendre_transform_is_invertible() {
    let quadratures = [
        Quadrature::midpoint(),
        Quadrature::trapezoid(),
        Quadrature::galerkin(2).unwrap(),
        Quadrature::galerkin(3).unwrap(),
        Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap(),
    ];
    for quadrature in quadratures {
        let mut hamiltonian = Stepper::hamiltonian(Coupled, quadrature.clone(), 0.05).unwrap();
        hamiltonian
            .start_from_momentum(vector![0.5], vector![0.3])
            .unwrap();
        let mut lagrangian = Stepper::new(CoupledLagrangian, quadrature.clone(), 0.05).unwrap();
        lagrangian
            .start_from_momentum(vector![0.5], vector![0.3])
            .unwrap();
        let (a, b) = (
            hamiltonian.run(2000).unwrap(),
            lagrangian.run(2000).unwrap(),
        );
        let difference = a
            .q()
            .iter()
            .zip(b.q())
            .chain(a.p().iter().zip(b.p()))
            .map(|(x, y)| (x - y).amax())
            .fold(0.0, f64::max);
        println!("{}: max difference {difference:.2e}", quadrature.name());
        assert!(difference < 1e-11, "{}: {difference}", quadrature.name());
    }
}

#[test]
fn keplers_angular_momentum_is_conserved_to_round_off() {
    let (q0, p0) = (vector![0.5, 0.0], vector![0.0, 3f64.sqrt()]);
    let l = |q: &SVector<f64, 2>, p: &SVector<f64, 2>| q[0] * p[1] - q[1] * p[0];
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let mut stepper =
            Stepper::hamiltonian(Kepler { mu: 1.0 }, quadrature.clone(), 0.01).unwrap();
        stepper.start_from_momentum(q0, p0).unwrap();
        let trajectory = stepper.run(20_000).unwrap();
        let drift = trajectory
            .q()
            .iter()
            .zip(trajectory.p())
            .map(|(q, p)| (l(q, p) - l(&q0, &p0)).abs())
            .fold(0.0, f64::max);
        println!(
            "{}: angular momentum drift {drift:.2e}, energy error {:.2e}",
            quadrature.name(),
            trajectory.max_energy_error()
        );
        assert!(drift < 1e-11, "{}: {drift}", quadrature.name());
        // The energy is not conserved to round-off: the test would not be one of round-off.
        assert!(trajectory.max_energy_error() > 1e3 * drift);
    }
}

const KNIFE: KnifeEdge = KnifeEdge {
    m: 1.0,
    j: 1.0,
    g: 9.81,
    alpha: std::f64::consts::FRAC_PI_6,
};

#[test]
fn the_knife_edge_written_with_h_follows_its_closed_form_at_order_2() {
    let t: f64 = 2.0;
    let hs = [0.02, 0.01, 0.005];
    let errors: Vec<f64> = hs
        .iter()
        .map(|&h| {
            let mut stepper = Stepper::hamiltonian(KNIFE, Quadrature::midpoint(), h).unwrap();
            let omega = scenes::knife_edge::OMEGA;
            stepper
                .start_from_momentum(SVector::zeros(), vector![0.0, 0.0, omega])
                .unwrap();
            for _ in 0..(t / h).round() as usize {
                stepper.step().unwrap();
                assert!(stepper.constraint_violation() < 1e-12);
            }
            (stepper.q() - scenes::knife_edge::exact(t)).amax()
        })
        .collect();
    assert_order("knife edge (H)", &hs, &errors, 2.0);
}

#[test]
fn the_knife_edge_takes_the_lagrangian_scenes_steps_at_each_constraint_point_and_order() {
    let cases = [
        (Quadrature::midpoint(), ConstraintPoint::Midpoint),
        (Quadrature::midpoint(), ConstraintPoint::Start),
        (Quadrature::trapezoid(), ConstraintPoint::End),
        (Quadrature::galerkin(2).unwrap(), ConstraintPoint::Midpoint),
    ];
    for (quadrature, point) in cases {
        let h = 0.01;
        let mut lagrangian = Stepper::new(scenes::knife_edge::SCENE, quadrature.clone(), h)
            .unwrap()
            .with_constraint_point(point);
        lagrangian
            .start_from_momentum(SVector::zeros(), vector![0.0, 0.0, 1.0])
            .unwrap();
        let system = KnifeEdgeAt {
            model: KNIFE,
            point,
        };
        let mut hamiltonian = Stepper::hamiltonian(system, quadrature.clone(), h).unwrap();
        hamiltonian
            .start_from_momentum(SVector::zeros(), vector![0.0, 0.0, 1.0])
            .unwrap();
        let (a, b) = (hamiltonian.run(500).unwrap(), lagrangian.run(500).unwrap());
        let difference = a
            .q()
            .iter()
            .zip(b.q())
            .chain(a.p().iter().zip(b.p()))
            .map(|(x, y)| (x - y).amax())
            .fold(0.0, f64::max);
        println!("{} at {point:?}: {difference:.2e}", quadrature.name());
        assert!(
            difference < 1e-10,
            "{} {point:?}: {difference}",
            quadrature.name()
        );
    }
}

/// The knife edge with its constraint point chosen.
struct KnifeEdgeAt {
    model: KnifeEdge,
    point: ConstraintPoint,
}

impl HamiltonianSystem<3> for KnifeEdgeAt {
    const ONE_FORMS: usize = 1;
    fn hamiltonian<D: Scalar>(&self, q: &SVector<D, 3>, p: &SVector<D, 3>) -> D {
        self.model.hamiltonian(q, p)
    }
    fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, a: usize) -> SVector<D, 3> {
        self.model.one_form(q, a)
    }
    fn constraint_point(&self) -> ConstraintPoint {
        self.point
    }
}

/// `H = (p² + q²)/2` with the force `(u − c v) dq` on the Lagrangian route.
#[dirac_system(
    coordinates(q),
    lagrangian = 0.5 * (dot(q) * dot(q) - q * q),
    forces((u - c * dot(q)) * dq),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct DampedLagrangian {
    c: f64,
}

#[test]
fn forces_and_inputs_act_as_on_the_lagrangian_route() {
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let (worst, _) = largest_gap(
            (Damped { c: 0.3 }, DampedLagrangian { c: 0.3 }),
            &quadrature,
            0.05,
            (vector![1.0], vector![0.0]),
            400,
            |k| Some((0.1 * k as f64).sin()),
        );
        println!("{}: {worst:.2e}", quadrature.name());
        assert!(worst < 1e-12, "{}: {worst}", quadrature.name());
    }
    // Without the input the damping takes energy out: E(20) = E(0) e^{−c t} to O(c²).
    let mut a =
        Stepper::hamiltonian(Damped { c: 0.3 }, Quadrature::galerkin(2).unwrap(), 0.05).unwrap();
    a.start_from_momentum(vector![1.0], vector![0.0]).unwrap();
    let trajectory = a.run(400).unwrap();
    let energy = trajectory.energy();
    assert!(energy[400] < 0.01 * energy[0], "{}", energy[400]);
}

/// A pendulum pushed by a force that depends on the position, the momentum, the time and an
/// input: `(u q/2 + sin 3t − 0.3 q³ − c p q²) dq` (bounded: the cubic restores, `c` damps).
#[dirac_system(
    coordinates(q),
    hamiltonian = 0.5 * p(q) * p(q) - cos(q),
    forces((0.5 * u * q + sin(3.0 * t) - 0.3 * q * q * q - c * p(q) * q * q) * dq),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct Pushed {
    c: f64,
}

/// [`Pushed`] on the Lagrangian route (`p = v`).
#[dirac_system(
    coordinates(q),
    lagrangian = 0.5 * dot(q) * dot(q) + cos(q),
    forces((0.5 * u * q + sin(3.0 * t) - 0.3 * q * q * q - c * dot(q) * q * q) * dq),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct PushedLagrangian {
    c: f64,
}

/// Every rule of the tour, and a Lobatto one.
fn rules() -> Vec<Quadrature> {
    let mut rules: Vec<Quadrature> = orders().into_iter().map(|(q, _)| q).collect();
    rules.push(Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap());
    rules
}

/// The largest difference in `(q, p)` between a stepper of the Hamiltonian route and one of the
/// Lagrangian route over `steps` steps from `(q0, p0)`, with input `u` set to `input(k)` on both
/// before step `k` where `input` gives one; and the largest `|q|, |p|` met (the difference is
/// absolute).
fn largest_gap<A: HamiltonianSystem<N>, B: DiracSystem<N>, const N: usize>(
    a: (A, B),
    quadrature: &Quadrature,
    h: f64,
    (q0, p0): (SVector<f64, N>, SVector<f64, N>),
    steps: usize,
    input: impl Fn(usize) -> Option<f64>,
) -> (f64, f64) {
    let (a, b) = a;
    let mut a = Stepper::hamiltonian(a, quadrature.clone(), h).unwrap();
    let mut b = Stepper::new(b, quadrature.clone(), h).unwrap();
    a.start_from_momentum(q0, p0).unwrap();
    b.start_from_momentum(q0, p0).unwrap();
    let (mut worst, mut size) = (0.0_f64, 0.0_f64);
    for k in 0..steps {
        if let Some(u) = input(k) {
            a.set_input("u", u).unwrap();
            b.set_input("u", u).unwrap();
        }
        a.step().unwrap();
        b.step().unwrap();
        worst = worst
            .max((a.q() - b.q()).amax())
            .max((a.p() - b.p()).amax());
        size = size.max(a.q().amax()).max(a.p().amax());
    }
    (worst, size)
}

#[test]
fn forces_of_the_position_momentum_time_and_input_act_as_on_the_lagrangian_route() {
    // The Lagrangian route reads forces at the nodes' times t_k + c_i h (tests/suite/step_derivatives.rs
    // pins that); a force read at another time, or at another point, would part the routes.
    for quadrature in rules() {
        let (worst, size) = largest_gap(
            (Pushed { c: 0.2 }, PushedLagrangian { c: 0.2 }),
            &quadrature,
            0.05,
            (vector![0.4], vector![0.1]),
            200,
            |k| Some((0.07 * k as f64).cos()),
        );
        println!(
            "pushed, {}: routes differ by {worst:.1e}",
            quadrature.name()
        );
        assert!(size < 3.0, "the pushed pendulum stays bounded: {size}");
        assert!(worst < 1e-12, "{}: {worst}", quadrature.name());
    }
}

/// The Cartesian pendulum written with `H`: a point mass on a rod, `g = x² + y² − l²`.
#[dirac_system(
    coordinates(x, y),
    hamiltonian = 0.5 * (p(x).powi(2) + p(y).powi(2)) / m + m * g * y,
    holonomic(x * x + y * y - l * l),
)]
#[derive(Debug, Clone, Copy)]
struct CartesianPendulumH {
    m: f64,
    l: f64,
    g: f64,
}

const ROD: CartesianPendulumH = CartesianPendulumH {
    m: 1.0,
    l: 1.0,
    g: 1.0,
};

#[test]
fn a_holonomic_constraint_is_held_and_the_lagrangian_routes_steps_are_taken() {
    use scenes::cartesian_pendulum::{SCENE, angle, q0};
    let rules = [
        Quadrature::midpoint(),
        Quadrature::trapezoid(),
        Quadrature::galerkin(2).unwrap(),
        Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap(),
    ];
    for quadrature in rules {
        let start = (q0(1.0), SVector::zeros());
        let (worst, _) = largest_gap((ROD, SCENE), &quadrature, 0.05, start, 400, |_| None);
        let mut a = Stepper::hamiltonian(ROD, quadrature.clone(), 0.05).unwrap();
        a.start_from_momentum(start.0, start.1).unwrap();
        let trajectory = a.run(400).unwrap();
        assert!(trajectory.max_constraint_violation() <= 1e-12);
        let violation = trajectory
            .q()
            .iter()
            .map(|q| (q[0] * q[0] + q[1] * q[1] - 1.0).abs())
            .fold(0.0, f64::max);
        println!(
            "Cartesian pendulum (H), {}: routes differ by {worst:.1e}, |g| ≤ {violation:.1e}",
            quadrature.name()
        );
        assert!(violation < 1e-13, "{}: {violation}", quadrature.name());
        assert!(worst < 1e-11, "{}: {worst}", quadrature.name());
    }
    // The order against the pendulum's q(5) (`docs/scenes.md`): 2 and 4.
    for (quadrature, order) in [
        (Quadrature::midpoint(), 2.0),
        (Quadrature::galerkin(2).unwrap(), 4.0),
    ] {
        let t = 5.0;
        let hs = steps_for(order, t);
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let mut a = Stepper::hamiltonian(ROD, quadrature.clone(), h).unwrap();
                a.start_from_momentum(q0(1.0), SVector::zeros()).unwrap();
                for _ in 0..(t / h).round() as usize {
                    a.step().unwrap();
                }
                (angle(&a.q()) - scenes::pendulum::Q5).abs()
            })
            .collect();
        assert_order(
            &format!("Cartesian pendulum (H), {}", quadrature.name()),
            &hs,
            &errors,
            order,
        );
    }
    // Degree 3 holds the constraint at order 4 only: refused, as on the Lagrangian route.
    assert!(matches!(
        Stepper::hamiltonian(ROD, Quadrature::galerkin(3).unwrap(), 0.05),
        Err(DiracError::InvalidQuadrature(_))
    ));
    // A start off the rod is refused, and a running stepper keeps its state.
    let mut stepper = Stepper::hamiltonian(ROD, Quadrature::midpoint(), 0.05).unwrap();
    stepper
        .start_from_momentum(q0(1.0), SVector::zeros())
        .unwrap();
    stepper.run(3).unwrap();
    let before = *stepper.state().unwrap();
    let error = stepper
        .start_from_momentum(vector![1.1, 0.0], SVector::zeros())
        .unwrap_err();
    assert!(
        matches!(error, DiracError::InconsistentInitialState(_)),
        "{error}"
    );
    assert_eq!(stepper.state().unwrap().q(), before.q());
    assert_eq!(stepper.state().unwrap().p(), before.p());
}

#[test]
fn a_constrained_hamiltonian_state_reads_its_velocity_and_energy_tangent_to_the_constraint() {
    use scenes::cartesian_pendulum::{SCENE, q0};
    // SHAKE leaves p_{k+1} an O(h) part normal to the rod; the velocity and the energy are
    // read at the momentum's tangent part, as the Lagrangian route reads them.
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let mut a = Stepper::hamiltonian(ROD, quadrature.clone(), 0.05).unwrap();
        let mut b = Stepper::new(SCENE, quadrature.clone(), 0.05).unwrap();
        a.start_from_momentum(q0(1.0), SVector::zeros()).unwrap();
        b.start_from_momentum(q0(1.0), SVector::zeros()).unwrap();
        let (ta, tb) = (a.run(400).unwrap(), b.run(400).unwrap());
        let normal = ta
            .q()
            .iter()
            .zip(ta.p())
            .map(|(q, p)| q.dot(p).abs())
            .fold(0.0, f64::max);
        let gap = |x: &[f64], y: &[f64]| {
            x.iter()
                .zip(y)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        };
        let energy = gap(ta.energy(), tb.energy());
        let velocity = ta
            .v()
            .iter()
            .zip(tb.v())
            .map(|(x, y)| (x - y).amax())
            .fold(0.0, f64::max);
        println!(
            "{}: normal momentum up to {normal:.1e}; energies differ by {energy:.1e}, velocities \
             by {velocity:.1e}; energy error {:.1e}",
            quadrature.name(),
            ta.max_energy_error()
        );
        assert!(normal > 1e-3, "SHAKE's momentum has a normal part");
        assert!(energy < 1e-12 && velocity < 1e-12, "{energy}, {velocity}");
        // A restart from the stepper's own state continues the run.
        let mut restart = Stepper::hamiltonian(ROD, quadrature.clone(), 0.05).unwrap();
        restart.start_from_state(*a.state().unwrap()).unwrap();
        a.run(50).unwrap();
        restart.run(50).unwrap();
        assert!((a.q() - restart.q()).amax() < 1e-12);
    }
    // The knife edge: the one-forms' share of the impulse on p_{k+1} is read off the same way.
    let (mut a, mut b) = (
        Stepper::hamiltonian(KNIFE, Quadrature::midpoint(), 0.01).unwrap(),
        scenes::knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).unwrap(),
    );
    let omega = scenes::knife_edge::OMEGA;
    a.start_from_momentum(SVector::zeros(), vector![0.0, 0.0, omega])
        .unwrap();
    let (ta, tb) = (a.run(300).unwrap(), b.run(300).unwrap());
    let energy = ta
        .energy()
        .iter()
        .zip(tb.energy())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    println!("knife edge: energies differ by {energy:.1e}");
    assert!(energy < 1e-11, "{energy}");
    let mut restart = Stepper::hamiltonian(KNIFE, Quadrature::midpoint(), 0.01).unwrap();
    restart.start_from_state(*a.state().unwrap()).unwrap();
    // Across the blade (p_y at φ = 0): the start from it is the start from rest, on both routes.
    let mut across = Stepper::hamiltonian(KNIFE, Quadrature::midpoint(), 0.01).unwrap();
    across
        .start_from_momentum(SVector::zeros(), vector![0.0, 1.0, 0.0])
        .unwrap();
    let mut lagrangian = scenes::knife_edge::stepper(ConstraintPoint::Midpoint, 0.01).unwrap();
    lagrangian
        .start_from_momentum(SVector::zeros(), vector![0.0, 1.0, 0.0])
        .unwrap();
    across.run(10).unwrap();
    lagrangian.run(10).unwrap();
    assert!((across.q() - lagrangian.q()).amax() < 1e-14);
    // A momentum across the rod moves nothing: the start from it is the start from rest.
    let start = |p: SVector<f64, 2>| {
        let mut a = Stepper::hamiltonian(ROD, Quadrature::midpoint(), 0.05).unwrap();
        a.start_from_momentum(vector![1.0, 0.0], p).unwrap();
        a.run(20).unwrap()
    };
    let (across, rest) = (start(vector![0.3, 0.0]), start(SVector::zeros()));
    assert!((across.q()[20] - rest.q()[20]).amax() < 1e-14);
    assert!((across.energy()[0] - rest.energy()[0]).abs() < 1e-14);
}

#[test]
fn derivatives_through_a_holonomic_constraint_match_central_differences() {
    // From a state on the rod; the map sends every state onto g = 0, so dg(q_{k+1}) ∂q_{k+1} = 0.
    let (q, p) = (vector![0.6, -0.8], vector![0.4, 0.3]);
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let name = format!("Cartesian pendulum (H), {}", quadrature.name());
        let a =
            against_central_differences(&name, |u| hamilton(ROD, &quadrature, 0.1, u), q, p, None);
        let (next, _, _) = raw_step(&mut hamilton(ROD, &quadrature, 0.1, 0.0), q, p);
        let dg = vector![2.0 * next[0], 2.0 * next[1]].transpose();
        let along = dg * a.matrix().view((0, 0), (2, 4));
        println!("{name}: |dg ∂q_(k+1)| = {:.1e}", along.amax());
        assert!(along.amax() < 1e-12, "{name}");
    }
}

#[test]
fn the_angle_of_a_pendulum_does_not_depend_on_its_mass_from_1e_minus_12_to_1e13() {
    // H = p²/(2 m l²) − m g l cos θ: θ(t) does not depend on m, p scales with it. The velocity
    // rows (entries ~1/h, ∂²H/∂p² = 1/m) and the momentum rows (~h m g) of one Jacobian are in
    // different units; a pivot test against the largest entry refused m ≥ 1e10. (At 1e14
    // galerkin(2) is still refused: its momentum rows mix `b ℓ' ∼ 1` with `h m g`.)
    let run = |m: f64, quadrature: &Quadrature| {
        let model = scenes::hamiltonian::Pendulum { m, ..PENDULUM };
        end(model, quadrature, 0.05, 100, vector![1.0], vector![0.3 * m])
    };
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let (q1, p1) = run(1.0, &quadrature);
        for m in [1e-12, 1e-6, 1e6, 1e10, 1e12, 1e13] {
            let (q, p) = run(m, &quadrature);
            let (dq, dp) = ((q[0] - q1[0]).abs(), (p[0] / m - p1[0]).abs());
            println!(
                "m = {m:e}, {}: |Δθ| = {dq:.1e}, |Δp/m| = {dp:.1e}",
                quadrature.name()
            );
            assert!(dq < 1e-11 && dp < 1e-11, "m = {m:e}: {dq:e}, {dp:e}");
        }
    }
}

#[test]
fn a_hamiltonian_without_a_lagrangian_is_stepped_at_the_gauss_order() {
    // H = p (1 − q²): ∂²H/∂p² = 0, so no Lagrangian route; the steps are Gauss collocation of
    // q̇ = 1 − q² with its adjoint, of order 2s in q and p.
    let t: f64 = 1.0;
    for (quadrature, order) in orders()
        .into_iter()
        .filter(|(q, _)| q.rule() == Rule::GaussLegendre(q.degree()))
    {
        let hs = [0.1, 0.05, 0.025];
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let steps = (t / h).round() as usize;
                let (q, p) = end(Lifted, &quadrature, h, steps, vector![0.0], vector![1.0]);
                let (q_exact, p_exact) = lifted_exact(t, 1.0);
                (q[0] - q_exact).abs().max((p[0] - p_exact).abs())
            })
            .collect();
        assert_order(
            &format!("H = p(1 − q²), {}", quadrature.name()),
            &hs,
            &errors,
            order,
        );
    }
    // With more nodes than the path's degree the velocity conditions q̇(c_i) = f(Q(c_i)) alone
    // over-determine the path (no momentum enters them): the trapezoid and Lobatto rules are
    // refused.
    for quadrature in [
        Quadrature::trapezoid(),
        Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap(),
    ] {
        let mut stepper = Stepper::hamiltonian(Lifted, quadrature, 0.1).unwrap();
        let error = stepper
            .start_from_momentum(vector![0.0], vector![1.0])
            .unwrap_err();
        assert!(matches!(error, DiracError::InvalidQuadrature(_)), "{error}");
        assert!(stepper.state().is_none());
    }
    // A start from a velocity needs the Legendre map inverted, which this H does not allow.
    let mut stepper = Stepper::hamiltonian(Lifted, Quadrature::midpoint(), 0.1).unwrap();
    let error = stepper
        .start_from_velocity(vector![0.0], vector![1.0])
        .unwrap_err();
    assert!(matches!(error, DiracError::Unsupported(_)), "{error}");
    assert!(stepper.state().is_none());
}

#[test]
fn a_start_from_a_velocity_inverts_the_legendre_map() {
    // v = (q² + 1) p: at q = 0.5, v = 0.5 gives p = 0.4.
    let mut stepper = Stepper::hamiltonian(Coupled, Quadrature::midpoint(), 0.1).unwrap();
    stepper
        .start_from_velocity(vector![0.5], vector![0.5])
        .unwrap();
    assert!((stepper.state().unwrap().p()[0] - 0.4).abs() < 1e-15);
}

#[test]
fn invalid_models_and_states_are_refused_with_the_reason() {
    let lobatto = Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap();
    assert!(matches!(
        Stepper::hamiltonian(KNIFE, lobatto, 0.01),
        Err(DiracError::InvalidQuadrature(_))
    ));
    assert!(matches!(
        Stepper::hamiltonian(Oscillator, Quadrature::midpoint(), 0.0),
        Err(DiracError::InvalidStep { .. })
    ));
    let nan = KnifeEdge {
        m: f64::NAN,
        ..KNIFE
    };
    assert!(matches!(
        Stepper::hamiltonian(nan, Quadrature::midpoint(), 0.01),
        Err(DiracError::NonFinite { .. })
    ));
    let mut stepper = Stepper::hamiltonian(KNIFE, Quadrature::midpoint(), 0.01).unwrap();
    let error = stepper
        .start_from_momentum(vector![f64::NAN, 0.0, 0.0], SVector::zeros())
        .unwrap_err();
    assert!(matches!(error, DiracError::NonFinite { .. }), "{error}");
    // Kepler at the origin: H is not finite there.
    let mut kepler =
        Stepper::hamiltonian(Kepler { mu: 1.0 }, Quadrature::midpoint(), 0.01).unwrap();
    assert!(
        kepler
            .start_from_momentum(SVector::zeros(), vector![0.0, 1.0])
            .is_err()
    );
}

#[test]
fn a_step_that_newton_cannot_take_fails_and_changes_nothing() {
    // Straight at the attracting centre with a step too long to resolve the passage.
    let mut stepper =
        Stepper::hamiltonian(Kepler { mu: 1.0 }, Quadrature::midpoint(), 0.5).unwrap();
    stepper
        .start_from_momentum(vector![2.0, 0.0], vector![-1.0, 0.0])
        .unwrap();
    let mut failed = false;
    for _ in 0..10 {
        let before = *stepper.state().unwrap();
        if let Err(error) = stepper.step() {
            println!("step {}: {error}", stepper.steps());
            assert_eq!(*stepper.state().unwrap(), before);
            failed = true;
            break;
        }
    }
    assert!(
        failed,
        "a head-on fall through r = 0 was stepped without an error"
    );
}

#[test]
fn the_trajectory_names_the_hamiltonian_routes_columns() {
    let mut stepper = Stepper::hamiltonian(KNIFE, Quadrature::galerkin(2).unwrap(), 0.01).unwrap();
    stepper
        .start_from_momentum(SVector::zeros(), vector![0.0, 0.0, 1.0])
        .unwrap();
    let trajectory = stepper.run(3).unwrap();
    let header = support::csv_header(&trajectory);
    assert!(
        header.starts_with("t,x,y,phi,v_x,v_y,v_phi,p_x,p_y,p_phi,energy"),
        "{header}"
    );
    assert!(
        header.contains("mu_0_node_1") && header.contains("mu_0_node_2"),
        "{header}"
    );
    assert_eq!(
        <Hamilton<KnifeEdge, 3> as StepEquations<3>>::NAME,
        "the discrete Hamilton's equations"
    );
}

/// One step of `equations` from `(q, p)` without start checks (so that perturbations off the
/// constraint manifold are allowed): the new state and the exact derivatives at the solution.
fn raw_step<E: StepEquations<N, Manifold = dirac::Vectors>, const N: usize>(
    equations: &mut E,
    q: SVector<f64, N>,
    p: SVector<f64, N>,
) -> (SVector<f64, N>, SVector<f64, N>, dirac::StepDerivatives<N>) {
    use dirac::nalgebra::DVector;
    use dirac::{Newton, State};
    let v = p; // a guess: it seeds the predictor only
    let state = State::new(0.3, q, p, v);
    let mut x = DVector::zeros(equations.unknowns());
    equations.predict(&state, None, &mut x);
    let options = NewtonOptions {
        max_contraction: f64::INFINITY,
        ..Default::default()
    };
    let mut newton = Newton::new(equations.unknowns(), options).unwrap();
    newton
        .solve(&mut x, |x, r, j| equations.assemble(&state, x, r, j))
        .expect("step");
    let next = equations.advance(&state, &x, 0).unwrap();
    newton
        .factorise_at(&x, |x, r, j| equations.assemble(&state, x, r, j))
        .expect("a regular root");
    let derivatives = equations.linearise(&state, &x, &newton).unwrap();
    (*next.q(), *next.p(), derivatives)
}

/// The exact `A` (and `B` for one input) of the step of `make(u)` from `(q, p)` against central
/// differences (δ = 1e-5); returns `A` and `B`.
fn against_central_differences<S: HamiltonianSystem<N>, const N: usize>(
    name: &str,
    make: impl Fn(f64) -> Hamilton<S, N>,
    q: SVector<f64, N>,
    p: SVector<f64, N>,
    u: Option<f64>,
) -> dirac::StepDerivatives<N> {
    let u0 = u.unwrap_or(0.0);
    let (_, _, exact) = raw_step(&mut make(u0), q, p);
    let (a, delta) = (exact.matrix(), 1e-5);
    let mut worst = 0.0_f64;
    for c in 0..2 * N {
        let nudge = |sign: f64| {
            let (mut q, mut p) = (q, p);
            match c < N {
                true => q[c] += sign * delta,
                false => p[c - N] += sign * delta,
            }
            raw_step(&mut make(u0), q, p)
        };
        let ((q1p, p1p, _), (q1m, p1m, _)) = (nudge(1.0), nudge(-1.0));
        for r in 0..N {
            worst = worst.max((a[(r, c)] - (q1p[r] - q1m[r]) / (2.0 * delta)).abs());
            worst = worst.max((a[(N + r, c)] - (p1p[r] - p1m[r]) / (2.0 * delta)).abs());
        }
    }
    println!("{name}: |A − central differences| = {worst:.1e}");
    assert!(worst < 1e-8, "{name}: A differs by {worst:e}");
    assert!(
        (a.clone() - DMatrix::identity(2 * N, 2 * N)).amax() > 1e-3,
        "{name}"
    );
    if let Some(u) = u {
        let ((q1p, p1p, _), (q1m, p1m, _)) = (
            raw_step(&mut make(u + delta), q, p),
            raw_step(&mut make(u - delta), q, p),
        );
        let b = exact.input_matrix();
        let mut worst = 0.0_f64;
        for r in 0..N {
            let dq = (q1p[r] - q1m[r]) / (2.0 * delta);
            let dp = (p1p[r] - p1m[r]) / (2.0 * delta);
            worst = worst.max((b[(r, 0)] - dq).abs().max((b[(N + r, 0)] - dp).abs()));
        }
        println!("{name}: |B − central differences| = {worst:.1e}");
        assert!(worst < 1e-8, "{name}: B differs by {worst:e}");
        assert!(b.amax() > 1e-3, "{name}: the input moves the state");
    }
    exact
}

use dirac::nalgebra::DMatrix;

/// The equations of `system` with `quadrature` and `h`, the first input at `u`.
fn hamilton<S: HamiltonianSystem<N>, const N: usize>(
    system: S,
    quadrature: &Quadrature,
    h: f64,
    u: f64,
) -> Hamilton<S, N> {
    let mut equations = Hamilton::new(system, quadrature.clone(), h).unwrap();
    if let Some(first) = equations.inputs_mut().first_mut() {
        *first = u;
    }
    equations
}

#[test]
fn step_derivatives_match_central_differences_and_are_symplectic() {
    let g2 = Quadrature::galerkin(2).unwrap();
    let g3 = Quadrature::galerkin(3).unwrap();
    let conservative = [
        (
            "coupled, galerkin(2)",
            against_central_differences(
                "coupled, galerkin(2)",
                |u| hamilton(Coupled, &g2, 0.1, u),
                vector![0.5],
                vector![0.3],
                None,
            ),
        ),
        (
            "pendulum, galerkin(3)",
            against_central_differences(
                "pendulum, galerkin(3)",
                |u| hamilton(PENDULUM, &g3, 0.1, u),
                vector![1.0],
                vector![0.5],
                None,
            ),
        ),
        (
            "H = p(1 − q²), galerkin(2)",
            against_central_differences(
                "H = p(1 − q²), galerkin(2)",
                |u| hamilton(Lifted, &g2, 0.1, u),
                vector![0.2],
                vector![1.3],
                None,
            ),
        ),
    ];
    for (name, a) in &conservative {
        let det = a.matrix().determinant();
        println!(
            "{name}: AᵀJA − J = {:.1e}, det A − 1 = {:.1e}",
            a.symplecticity_defect(),
            det - 1.0
        );
        assert!(a.symplecticity_defect() < 1e-12, "{name}");
        assert!((det - 1.0).abs() < 1e-12, "{name}");
    }
    let kepler = against_central_differences(
        "kepler, midpoint",
        |u| hamilton(Kepler { mu: 1.0 }, &Quadrature::midpoint(), 0.05, u),
        vector![0.5, 0.1],
        vector![0.2, 1.7],
        None,
    );
    println!("kepler: AᵀJA − J = {:.1e}", kepler.symplecticity_defect());
    assert!(kepler.symplecticity_defect() < 1e-12);
    // Damping is not symplectic, and the input moves the state: B against differences too.
    let damped = against_central_differences(
        "damped, galerkin(2)",
        |u| hamilton(Damped { c: 0.3 }, &g2, 0.1, u),
        vector![0.7],
        vector![-0.2],
        Some(0.4),
    );
    assert!(damped.symplecticity_defect() > 1e-3);
}

#[test]
fn derivatives_with_forces_of_the_position_momentum_time_and_input_on_every_rule() {
    // `raw_step` starts at t = 0.3: a force read at the wrong time moves `A` and `B`.
    for quadrature in rules() {
        let name = format!("pushed, {}", quadrature.name());
        against_central_differences(
            &name,
            |u| hamilton(Pushed { c: 0.2 }, &quadrature, 0.1, u),
            vector![0.6],
            vector![-0.4],
            Some(0.7),
        );
    }
}

#[test]
fn constrained_step_derivatives_match_central_differences() {
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let mut stepper = Stepper::hamiltonian(KNIFE, quadrature.clone(), 0.01).unwrap();
        stepper
            .start_from_momentum(SVector::zeros(), vector![0.0, 0.0, 1.0])
            .unwrap();
        stepper.run(40).unwrap();
        let state = *stepper.state().unwrap();
        let name = format!("knife edge, {}", quadrature.name());
        against_central_differences(
            &name,
            |u| hamilton(KNIFE, &quadrature, 0.01, u),
            *state.q(),
            *state.p(),
            None,
        );
        // The stepper's own linearised step is the step it would take.
        let mut twin = stepper.clone();
        let a = stepper.step_linearised().unwrap();
        twin.step().unwrap();
        assert_eq!(stepper.q(), twin.q());
        assert!(a.matrix().amax().is_finite());
    }
}
