//! The explicit variational step of a separable Lagrangian (Störmer–Verlet and its compositions):
//! which models the attribute declares separable, the step against the implicit trapezoidal step
//! it equals, each composition's order measured against Kepler's closed-form orbit, the
//! invariants it keeps, dense output, and the refusals.

use crate::support::assert_order;

use dirac::prelude::*;
use scenes::{cart_pole, double_pendulum, kepler, knife_edge, oscillator, pendulum};

/// What the attribute declared: whether `S` is separable.
fn separable<S: DiracSystem<N>, const N: usize>() -> bool {
    S::SEPARABLE
}

/// What the attribute declared: whether the forces of `S` do not read the velocity.
fn forces_free_of_velocity<S: DiracSystem<N>, const N: usize>() -> bool {
    S::FORCES_FREE_OF_VELOCITY
}

/// Kepler's orbit for μ = 1, e = 0.5 from perihelion (the scene's start): `x = cos E − e`,
/// `y = √(1 − e²) sin E` with `E − e sin E = t` (a = 1, period 2π).
fn kepler_exact(t: f64) -> SVector<f64, 2> {
    let e = 0.5;
    let mut anomaly = t;
    for _ in 0..50 {
        anomaly -= (anomaly - e * anomaly.sin() - t) / (1.0 - e * anomaly.cos());
    }
    vector![anomaly.cos() - e, (1.0 - e * e).sqrt() * anomaly.sin()]
}

/// The position error at `t = 3` (inside the first orbit, past perihelion's fast arc) of `n`
/// steps of `composition`.
fn kepler_error(composition: &Composition, n: usize) -> f64 {
    let t = 3.0;
    let mut stepper = Stepper::explicit(kepler::SCENE, composition.clone(), t / n as f64).unwrap();
    stepper
        .start_from_momentum(kepler::q0(), kepler::p0())
        .unwrap();
    stepper.run(n as u64).unwrap();
    (stepper.q() - kepler_exact(t)).norm()
}

#[test]
fn the_attribute_declares_the_separable_lagrangians() {
    // ½ m l² θ̇² + m g l cos θ, ½ |v|² + μ/|q|, ½ m ẋ² − ½ k x²: constant mass matrices.
    assert!(separable::<pendulum::Pendulum, 1>());
    assert!(separable::<kepler::Kepler, 2>());
    assert!(separable::<oscillator::Oscillator, 1>());
    // The knife edge's Lagrangian is separable too (its constraint is refused elsewhere).
    assert!(separable::<knife_edge::KnifeEdge, 3>());
    // cos(θ₁ − θ₂) θ̇₁ θ̇₂ and the cart-pole's cos θ ẋ θ̇: mass matrices that move.
    assert!(!separable::<double_pendulum::DoublePendulum, 2>());
    assert!(!separable::<cart_pole::CartPole, 2>());
}

/// `½ m (ẋ² + ẏ²) + B (x ẏ − y ẋ)/2 − k (x² + y²)/2`: a charge in a uniform magnetic field.
/// Quadratic in the velocity with a constant mass, but its `∂²L/∂q∂v` does not vanish.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) + 0.5 * b * (x * dot(y) - y * dot(x))
        - 0.5 * k * (x * x + y * y),
)]
#[derive(Debug, Clone, Copy)]
pub(crate) struct Charge {
    pub(crate) m: f64,
    pub(crate) b: f64,
    pub(crate) k: f64,
}

/// `½ ẋ² + c |ẋ| − ½ x²`.
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2) + c * dot(x).abs() - 0.5 * x * x)]
#[derive(Debug, Clone, Copy)]
struct Kinked {
    c: f64,
}

/// `½ (ẋ + c)² − cos x`: a constant `b = c` in the momentum, `p = ẋ + c`.
#[dirac_system(coordinates(x), lagrangian = 0.5 * (dot(x) + c).powi(2) + cos(x))]
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shifted {
    pub(crate) c: f64,
}

#[test]
fn a_velocity_coupled_to_the_position_is_not_separable_a_constant_offset_is() {
    assert!(!separable::<Charge, 2>());
    // c |ẋ|: its second derivatives vanish away from ẋ = 0, but its momentum offset jumps there.
    assert!(!separable::<Kinked, 1>());
    let charge = Charge {
        m: 1.0,
        b: 0.5,
        k: 1.0,
    };
    assert!(matches!(
        Stepper::explicit(charge, Composition::verlet(), 0.1),
        Err(DiracError::Unsupported(_))
    ));
    // The offset is read at the start: the step equals the implicit trapezoidal one.
    assert!(separable::<Shifted, 1>());
    let shifted = Shifted { c: 0.7 };
    let h = 0.05;
    let mut explicit = Stepper::explicit(shifted, Composition::verlet(), h).unwrap();
    let mut implicit = Stepper::new(shifted, Quadrature::trapezoid(), h).unwrap();
    for stepper_start in [
        explicit.start_from_velocity(vector![1.0], vector![0.3]),
        implicit.start_from_velocity(vector![1.0], vector![0.3]),
    ] {
        stepper_start.unwrap();
    }
    explicit.run(400).unwrap();
    implicit.run(400).unwrap();
    assert!((explicit.q()[0] - implicit.q()[0]).abs() < 1e-12);
    assert!((explicit.p()[0] - implicit.p()[0]).abs() < 1e-12);
    assert!((explicit.v().unwrap()[0] - implicit.v().unwrap()[0]).abs() < 1e-12);
}

#[test]
fn verlet_is_the_implicit_trapezoidal_step() {
    // The trapezoidal discrete Lagrangian of a separable L has the Störmer–Verlet map as its
    // discrete flow; Newton solves it to its tolerance, the explicit step takes it directly.
    let h = 0.01;
    let mut explicit = Stepper::explicit(kepler::SCENE, Composition::verlet(), h).unwrap();
    let mut implicit = Stepper::new(kepler::SCENE, Quadrature::trapezoid(), h).unwrap();
    explicit
        .start_from_momentum(kepler::q0(), kepler::p0())
        .unwrap();
    implicit
        .start_from_momentum(kepler::q0(), kepler::p0())
        .unwrap();
    let mut largest: f64 = 0.0;
    for _ in 0..1000 {
        explicit.step().unwrap();
        implicit.step().unwrap();
        largest = largest
            .max((explicit.q() - implicit.q()).amax())
            .max((explicit.p() - implicit.p()).amax());
    }
    println!("explicit against implicit trapezoid, 1000 Kepler steps: {largest:.1e}");
    assert!(largest < 1e-12, "{largest:e}");
    assert_eq!(explicit.composition().name(), "Störmer–Verlet");
}

#[test]
fn each_composition_has_its_order_on_kepler() {
    // Step counts over t = 3 (from perihelion past the fast arc), growing geometrically inside
    // the range where each method's error is above round-off (1e-12 and up) and its leading
    // term dominates.
    let cases = [
        (Composition::verlet(), [200, 400, 800, 1600]),
        (Composition::triple_jump(), [100, 200, 400, 800]),
        (Composition::suzuki(), [60, 120, 240, 480]),
        (Composition::kahan_li_6(), [40, 80, 160, 320]),
        (Composition::mclachlan_8(), [20, 30, 45, 68]),
        (Composition::kahan_li_8(), [20, 30, 45, 68]),
        (Composition::sofroniou_spaletta_10(), [10, 14, 20, 28]),
    ];
    for (composition, ns) in cases {
        let hs: Vec<f64> = ns.iter().map(|&n| 3.0 / n as f64).collect();
        let errors: Vec<f64> = ns.iter().map(|&n| kepler_error(&composition, n)).collect();
        assert_order(composition.name(), &hs, &errors, composition.order() as f64);
    }
    // Sofroniou–Spaletta 10 at 64 steps is at round-off.
    let floor = kepler_error(&Composition::sofroniou_spaletta_10(), 64);
    println!("Sofroniou–Spaletta 10, 64 steps: {floor:.1e}");
    assert!(floor < 1e-14, "{floor:e}");
}

/// Every composition over 10⁶ steps of Kepler (e = 0.5), at a step where its own energy error
/// lies far above round-off (64 steps an orbit, about 15 600 orbits; 48 for Sofroniou–Spaletta 10,
/// whose error at 64 is round-off's): the energy error stays within the band of the run's first
/// tenth (a drift, of the method or of round-off, would widen it about tenfold by the end), and
/// angular momentum moves by round-off alone. Measured: every band widens by at most 1.06× over
/// the last 9·10⁵ steps. Larger steps leave the range where a composition's modified energy is
/// kept: Sofroniou–Spaletta 10 at 40 steps an orbit widens its band 5.7×, at 32 2 000×.
#[test]
fn every_composition_keeps_the_energy_bounded_over_a_million_steps() {
    use rayon::prelude::*;
    let runs = [
        (Composition::verlet(), 64.0),
        (Composition::triple_jump(), 64.0),
        (Composition::suzuki(), 64.0),
        (Composition::kahan_li_6(), 64.0),
        (Composition::mclachlan_8(), 64.0),
        (Composition::kahan_li_8(), 64.0),
        (Composition::sofroniou_spaletta_10(), 48.0),
    ];
    let l0 = kepler::angular_momentum(&kepler::q0(), &kepler::p0());
    let bands: Vec<(f64, f64, f64)> = runs
        .par_iter()
        .map(|(composition, per_orbit)| {
            let h = std::f64::consts::TAU / per_orbit;
            let mut stepper = Stepper::explicit(kepler::SCENE, composition.clone(), h).unwrap();
            stepper
                .start_from_momentum(kepler::q0(), kepler::p0())
                .unwrap();
            let e0 = stepper.energy().unwrap();
            let (mut first, mut band, mut turned): (f64, f64, f64) = (0.0, 0.0, 0.0);
            for block in 0..10_000 {
                stepper.run(100).unwrap();
                band = band.max((stepper.energy().unwrap() - e0).abs());
                if block < 1_000 {
                    first = band;
                }
                let l = kepler::angular_momentum(&stepper.q(), &stepper.p());
                turned = turned.max((l - l0).abs());
            }
            println!(
                "{}: |ΔE| ≤ {first:.2e} over 10⁵ steps, ≤ {band:.2e} over 10⁶; |ΔL| ≤ {turned:.1e}",
                composition.name()
            );
            (first, band, turned)
        })
        .collect();
    for ((composition, _), &(first, band, turned)) in runs.iter().zip(&bands) {
        let name = composition.name();
        // At round-off the band would test round-off's random walk, which widens about √10 ≈ 3×
        // from 10⁵ to 10⁶ steps.
        assert!(
            first > 1e-12,
            "{name}: its own error {first:e} is not above round-off"
        );
        assert!(
            band < 1.5 * first,
            "{name}: {band:e} over 10⁶ steps against {first:e}"
        );
        assert!(
            turned < 1e-12,
            "{name}: angular momentum moved by {turned:e}"
        );
    }
}

#[test]
fn dense_output_is_the_cubic_hermite_interpolant_of_order_four() {
    // With an order-8 step the interpolant's own error dominates: order 4 in the positions.
    let errors: Vec<f64> = [0.2, 0.1, 0.05, 0.025]
        .iter()
        .map(|&h| {
            let mut stepper =
                Stepper::explicit(oscillator::SCENE, Composition::kahan_li_8(), h).unwrap();
            stepper
                .start_from_velocity(vector![oscillator::Q0], vector![0.0])
                .unwrap();
            stepper.run((1.0 / h).round() as u64).unwrap();
            stepper.step().unwrap();
            let t = stepper.t() - 0.5 * h;
            (stepper.interpolate(t).unwrap().q[0] - oscillator::exact(t)).abs()
        })
        .collect();
    assert_order("dense output", &[0.2, 0.1, 0.05, 0.025], &errors, 4.0);
}

#[test]
fn runs_events_and_saved_times_drive_the_explicit_step() {
    // A pendulum released from 1 rad crosses θ = 0 first at a quarter period.
    let mut stepper = Stepper::explicit(pendulum::SCENE, Composition::kahan_li_6(), 0.01).unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    let crossing = Event::new(
        "theta = 0",
        |_t, q: &SVector<f64, 1>, _v: &SVector<f64, 1>| q[0],
    );
    let solution = stepper
        .solve(
            Run::until(3.0)
                .saveat([1.0, 2.0])
                .event(crossing.terminal()),
        )
        .unwrap();
    let at = solution.events[0].sample.t;
    // Saved at t = 1 (the state 100 steps reach, to the interpolant's round-off), then stopped
    // by the event before t = 2.
    let saved = solution
        .trajectory
        .t()
        .iter()
        .position(|&t| t == 1.0)
        .unwrap();
    let mut direct = Stepper::explicit(pendulum::SCENE, Composition::kahan_li_6(), 0.01).unwrap();
    direct
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    direct.run(100).unwrap();
    let off = (solution.trajectory.q()[saved][0] - direct.q()[0]).abs();
    assert!(off < 1e-12, "{off:e}");
    assert!(!solution.trajectory.t().contains(&2.0));
    // The quarter period of the pendulum at amplitude 1: K(sin ½)/√(g/l).
    let k = {
        // Complete elliptic integral of the first kind by the arithmetic–geometric mean.
        let (mut a, mut b) = (1.0f64, (1.0 - 0.5f64.sin().powi(2)).sqrt());
        for _ in 0..20 {
            (a, b) = (0.5 * (a + b), (a * b).sqrt());
        }
        std::f64::consts::FRAC_PI_2 / a
    };
    let omega = (pendulum::SCENE.g / pendulum::SCENE.l).sqrt();
    println!("first crossing at {at}, exact {}", k / omega);
    assert!((at - k / omega).abs() < 1e-6, "{at} against {}", k / omega);
}

#[test]
fn models_the_explicit_step_does_not_cover_are_refused() {
    let unsupported = |r: Result<(), DiracError>| matches!(r, Err(DiracError::Unsupported(_)));
    // A mass matrix that moves.
    assert!(unsupported(
        Stepper::explicit(double_pendulum::SCENE, Composition::verlet(), 0.01).map(|_| ())
    ));
    // A constraint.
    assert!(unsupported(
        Stepper::explicit(knife_edge::SCENE, Composition::verlet(), 0.01).map(|_| ())
    ));
    // A force that reads the velocity (a damper).
    assert!(!forces_free_of_velocity::<Damped, 1>());
    assert!(unsupported(
        Stepper::explicit(Damped, Composition::verlet(), 0.01).map(|_| ())
    ));
    // A coordinate without kinetic energy: refused at the start, named, nothing started.
    let mut stepper = Stepper::explicit(Massless, Composition::verlet(), 0.01).unwrap();
    match stepper.start_from_velocity(vector![1.0, 0.0], vector![0.0, 0.0]) {
        Err(DiracError::Unsupported(message)) => {
            assert!(message.contains("(y carries"), "{message}")
        }
        other => panic!("expected Unsupported, got {other:?}"),
    }
    assert!(stepper.state().is_none());
    // A bad step size or order.
    assert!(matches!(
        Stepper::explicit(pendulum::SCENE, Composition::verlet(), -0.1),
        Err(DiracError::InvalidStep { .. })
    ));
    assert!(matches!(
        Composition::of_order(12),
        Err(DiracError::InvalidQuadrature(_))
    ));
}

/// `½ ẋ² − x² − y²`: `y` has no kinetic energy (its mass matrix row vanishes).
#[dirac_system(coordinates(x, y), lagrangian = 0.5 * dot(x).powi(2) - x * x - y * y)]
#[derive(Debug, Clone, Copy)]
struct Massless;

/// A damped oscillator: its force reads the velocity.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces(-0.1 * dot(x) * dx),
)]
#[derive(Debug, Clone, Copy)]
pub(crate) struct Damped;

/// A Duffing oscillator driven by `u cos t`, its cubic spring written as a force: forces of the
/// position, the time and an input.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)) - 0.5 * (x * x + y * y),
    forces((u * cos(t) - k * x.powi(3)) * dx - k * x * y * dy),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
pub(crate) struct Duffing {
    pub(crate) k: f64,
}

#[test]
fn forces_of_position_time_and_inputs_keep_the_step_explicit() {
    assert!(forces_free_of_velocity::<Duffing, 2>());
    let duffing = Duffing { k: 0.3 };
    let h = 0.02;
    let mut explicit = Stepper::explicit(duffing, Composition::verlet(), h).unwrap();
    let mut implicit = Stepper::new(duffing, Quadrature::trapezoid(), h).unwrap();
    for stepper_start in [
        explicit.start_from_velocity(vector![1.0, 0.5], vector![0.0, 0.2]),
        implicit.start_from_velocity(vector![1.0, 0.5], vector![0.0, 0.2]),
    ] {
        stepper_start.unwrap();
    }
    let mut largest: f64 = 0.0;
    for k in 0..500 {
        // The input changes between steps and is held over each.
        let u = 0.5 + 0.3 * (k as f64 * 0.01).sin();
        explicit.set_input("u", u).unwrap();
        implicit.set_input("u", u).unwrap();
        explicit.step().unwrap();
        implicit.step().unwrap();
        largest = largest
            .max((explicit.q() - implicit.q()).amax())
            .max((explicit.p() - implicit.p()).amax());
    }
    // The same map as the trapezoidal rule's, and the same work booked for its forces.
    println!("driven Duffing, explicit against implicit trapezoid: {largest:.1e}");
    assert!(largest < 1e-12, "{largest:e}");
    let (a, b) = (explicit.work().unwrap(), implicit.work().unwrap());
    println!("work: explicit {a}, implicit {b}");
    assert!((a - b).abs() < 1e-12 * (1.0 + b.abs()), "{a} against {b}");
    assert!(a.abs() > 1e-3);
}

/// `½ ẋ² − ½ x²` driven by `u cos 2t`: `x = (x₀ + u/3) cos t + v₀ sin t − (u/3) cos 2t`.
#[dirac_system(
    coordinates(x),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * x * x,
    forces(u * cos(2.0 * t) * dx),
    inputs(u),
)]
#[derive(Debug, Clone, Copy)]
struct Driven;

#[test]
fn compositions_keep_their_order_under_a_time_dependent_force() {
    // The force is read at each stage's own time: a force frozen over the step would fall to
    // order 1 or 2 here.
    let (x0, v0, u, t) = (1.0, 0.3, 0.8, 3.0);
    let exact = (x0 + u / 3.0) * t.cos() + v0 * t.sin() - u / 3.0 * (2.0 * t).cos();
    for (composition, ns) in [
        (Composition::suzuki(), [30, 60, 120, 240]),
        (Composition::kahan_li_8(), [15, 20, 30, 45]),
    ] {
        let errors: Vec<f64> = ns
            .iter()
            .map(|&n| {
                let mut stepper =
                    Stepper::explicit(Driven, composition.clone(), t / n as f64).unwrap();
                stepper.set_input("u", u).unwrap();
                stepper
                    .start_from_velocity(vector![x0], vector![v0])
                    .unwrap();
                stepper.run(n).unwrap();
                (stepper.q()[0] - exact).abs()
            })
            .collect();
        let hs: Vec<f64> = ns.iter().map(|&n| t / n as f64).collect();
        assert_order(composition.name(), &hs, &errors, composition.order() as f64);
    }
}

/// A hand-written damper that claims its force does not read the velocity.
#[derive(Clone)]
pub(crate) struct FalseForce;

impl DiracSystem<1> for FalseForce {
    const SEPARABLE: bool = true;
    const FORCES: bool = true;
    const FORCES_FREE_OF_VELOCITY: bool = true;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        (v[0] * v[0] - q[0] * q[0]) * 0.5
    }
    fn force<D: Scalar>(
        &self,
        _q: &SVector<D, 1>,
        v: &SVector<D, 1>,
        _t: f64,
        _u: &[D],
    ) -> SVector<D, 1> {
        SVector::from([-v[0] * 0.1])
    }
}

#[test]
fn a_false_claim_about_the_forces_is_caught_even_at_rest() {
    let mut stepper = Stepper::explicit(FalseForce, Composition::verlet(), 0.01).unwrap();
    let refused = stepper.start_from_velocity(vector![1.0], vector![0.0]);
    assert!(
        matches!(refused, Err(DiracError::InconsistentDerivatives(_))),
        "{refused:?}"
    );
}

#[test]
fn the_energy_balance_of_a_driven_explicit_step_closes_to_its_order() {
    // E_{k+1} − E_k − W_k is the unforced step's own energy error, O(h²) for Störmer–Verlet and
    // O(h⁸) for Kahan–Li 8: the balance closes at the step's order.
    let defect = |composition: Composition, h: f64| {
        let mut stepper = Stepper::explicit(Duffing { k: 0.3 }, composition, h).unwrap();
        stepper
            .start_from_velocity(vector![1.0, 0.5], vector![0.0, 0.2])
            .unwrap();
        stepper.set_input("u", 0.5).unwrap();
        stepper.run_until(2.0).unwrap();
        stepper.energy_balance_error().unwrap().abs()
    };
    let hs = [0.1, 0.05, 0.025, 0.0125];
    let errors: Vec<f64> = hs
        .iter()
        .map(|&h| defect(Composition::verlet(), h))
        .collect();
    assert_order("Störmer–Verlet energy balance", &hs, &errors, 2.0);
    let hs = [0.4, 0.3, 0.2, 0.15];
    let errors: Vec<f64> = hs
        .iter()
        .map(|&h| defect(Composition::kahan_li_8(), h))
        .collect();
    assert_order("Kahan–Li 8 energy balance", &hs, &errors, 8.0);
}

/// A hand-written model that claims to be separable and is not: `½ (1 + x²) ẋ²`.
struct FalseClaim;

impl DiracSystem<1> for FalseClaim {
    const SEPARABLE: bool = true;
    fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
        (q[0] * q[0] + 1.0) * v[0] * v[0] * 0.5
    }
}

#[test]
fn a_false_claim_of_separability_is_caught_at_the_start() {
    let mut stepper = Stepper::explicit(FalseClaim, Composition::verlet(), 0.01).unwrap();
    let refused = stepper.start_from_velocity(vector![0.5], vector![1.0]);
    assert!(
        matches!(refused, Err(DiracError::InconsistentDerivatives(_))),
        "{refused:?}"
    );
    assert!(stepper.state().is_none());
}

/// `½ ẋ² + eˣ`: pushed to overflow in one step from x = 700.
#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2) + exp(x))]
#[derive(Debug, Clone, Copy)]
struct Runaway;

#[test]
fn a_step_that_overflows_is_refused_and_changes_nothing() {
    let mut stepper = Stepper::explicit(Runaway, Composition::verlet(), 1.0).unwrap();
    stepper
        .start_from_velocity(vector![700.0], vector![0.0])
        .unwrap();
    let before = *stepper.state().unwrap();
    let refused = stepper.step();
    assert!(
        matches!(refused, Err(DiracError::NonFinite { .. })),
        "{refused:?}"
    );
    assert_eq!(*stepper.state().unwrap(), before);
    assert_eq!(stepper.steps(), 0);
}

/// A step depends on its state alone: step after step, a run carried on (which takes its first
/// gradient over from the step before) and a stepper started again from the same state (which
/// takes it afresh) give the same bits.
#[test]
fn an_explicit_step_depends_on_its_state_alone() {
    let composition = Composition::kahan_li_8();
    let mut carried = Stepper::explicit(kepler::SCENE, composition.clone(), 0.01).unwrap();
    let mut fresh = Stepper::explicit(kepler::SCENE, composition, 0.01).unwrap();
    carried
        .start_from_momentum(kepler::q0(), kepler::p0())
        .unwrap();
    for k in 0..1_000 {
        let state = *carried.state().unwrap();
        carried.step().unwrap();
        fresh.start_from_state(state).unwrap();
        fresh.step().unwrap();
        assert_eq!(carried.q(), fresh.q(), "step {k}");
        assert_eq!(carried.p(), fresh.p(), "step {k}");
    }
}
