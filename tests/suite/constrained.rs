//! Constrained and degenerate models that stay exact: hidden constraints held at every node,
//! velocities the constraints allow, restarts from a running stepper's own state, and RATTLE
//! against SHAKE.

use crate::support;

use dirac::prelude::*;
use dirac::step_equations::State;
use scenes::circuit::{self, LcCircuit};
use scenes::{cartesian_pendulum, knife_edge, port, rolling_disk};
use support::{assert_order, slope};

/// L in series with C2 and (C1 ∥ C3) with unequal capacitances.
const UNEQUAL: LcCircuit = LcCircuit {
    l: 1.0,
    c1: 1.0,
    c2: 1.0,
    c3: 2.0,
};

/// Equal voltages on C1 and C3 (0.2 = 0.4 / 2) and a current 0.5 split 1 : 2 between them.
fn unequal_start() -> (SVector<f64, 4>, SVector<f64, 4>) {
    (
        vector![0.0, 0.2, 1.0, 0.4],
        vector![0.5, 0.5 / 3.0, 0.5, 1.0 / 3.0],
    )
}

/// The closed form: with x = q_c2 and S = q_c1 + q_c3 = x + K (KCL), the parallel pair holds
/// q_c1 = c1 S / C, q_c3 = c3 S / C (C = c1 + c3) and `l ẍ = −x/c2 − (x + K)/C`.
fn unequal_exact(t: f64) -> SVector<f64, 4> {
    let LcCircuit { l, c1, c2, c3 } = UNEQUAL;
    let (q0, v0) = unequal_start();
    let big_c = c1 + c3;
    let k = q0[1] + q0[3] - q0[2];
    let rest = -k * c2 / (c2 + big_c);
    let omega = ((1.0 / c2 + 1.0 / big_c) / l).sqrt();
    let x = rest + (q0[2] - rest) * (omega * t).cos() + v0[2] / omega * (omega * t).sin();
    let s = x + k;
    vector![q0[0] + x - q0[2], c1 * s / big_c, x, c3 * s / big_c]
}

/// The hidden constraint of the parallel pair, q_c1/c1 − q_c3/c3.
fn parallel(q: &SVector<f64, 4>) -> f64 {
    q[1] / UNEQUAL.c1 - q[3] / UNEQUAL.c3
}

/// Unequal parallel capacitors with a current: the hidden constraint q_c1/c1 = q_c3/c3 is held
/// at every node to round-off over 10⁶ steps (it used to alternate in sign from step to step and
/// grow to 2.7e-9 over 10⁵ steps), Kirchhoff's law too, and the energy is conserved to
/// round-off.
#[test]
fn hidden_constraint_is_held_at_every_node_over_a_million_steps() {
    let (q0, v0) = unequal_start();
    let mut stepper = Stepper::new(UNEQUAL, Quadrature::midpoint(), 0.01).unwrap();
    stepper.start_from_velocity(q0, v0).unwrap();
    let e0 = stepper.energy().unwrap();
    let (mut worst, mut kcl): (f64, f64) = (0.0, 0.0);
    for _ in 0..1_000_000 {
        stepper.step().unwrap();
        worst = worst.max(parallel(&stepper.q()).abs());
        kcl = kcl.max(stepper.constraint_violation());
    }
    assert!(worst <= 1e-13, "hidden constraint at the nodes {worst:e}");
    assert!(kcl <= 1e-13, "{kcl:e}");
    let drift = (stepper.energy().unwrap() - e0).abs();
    assert!(drift < 1e-12, "energy drift {drift:e}");
}

/// Second order against the closed form, and the velocity reported at each node satisfies
/// Kirchhoff's law and the hidden constraint's velocity form (it used to violate KCL by 3e-3).
#[test]
fn unequal_capacitors_are_second_order_with_admissible_velocities() {
    let hs = [0.1, 0.05, 0.025, 0.0125];
    let (q0, v0) = unequal_start();
    let errors: Vec<f64> = hs
        .iter()
        .map(|&h| {
            let mut stepper = Stepper::new(UNEQUAL, Quadrature::midpoint(), h).unwrap();
            stepper.start_from_velocity(q0, v0).unwrap();
            for _ in 0..(5.0 / h).round() as usize {
                stepper.step().unwrap();
                let v = stepper.v().unwrap();
                assert!((v[2] - v[0]).abs() < 1e-14, "KCL 1: {v}");
                assert!((v[2] - v[1] - v[3]).abs() < 1e-14, "KCL 2: {v}");
                assert!((v[1] / UNEQUAL.c1 - v[3] / UNEQUAL.c3).abs() < 1e-14, "{v}");
            }
            (stepper.q() - unequal_exact(5.0)).amax()
        })
        .collect();
    let order = slope(&hs, &errors);
    assert!((order - 2.0).abs() < 0.1, "order {order}, {errors:?}");
}

/// Stops `reference` after `steps`, starts a new stepper from its `(q, p)` at its time with step
/// `h`, and returns the new stepper.
fn restarted<S: DiracSystem<N> + Clone, const N: usize>(
    reference: &Stepper<S, N>,
    quadrature: Quadrature,
    h: f64,
) -> Stepper<S, N> {
    let mut restart = Stepper::new(reference.system().clone(), quadrature, h)
        .unwrap()
        .with_constraint_point(reference.constraint_point());
    let (q, p) = (reference.q(), reference.p());
    let v = reference.v().unwrap();
    restart
        .start_from_state(State::new(reference.t(), q, p, v))
        .unwrap_or_else(|e| panic!("restart from the stepper's own state refused: {e}"));
    restart
}

/// A restart from a running stepper's `(q, p)` continues the run exactly with the same step;
/// with h/2 its error ends below the uninterrupted run's (a spurious jump at the restart would
/// not); starting from `(q, v())` is accepted and stays within the h run's error.
fn check_restart<S: DiracSystem<N> + Clone, const N: usize>(
    name: &str,
    make: impl Fn(f64) -> Stepper<S, N>,
    h: f64,
    exact: impl Fn(f64) -> SVector<f64, N>,
    stop: usize,
    more: usize,
) {
    let mut reference = make(h);
    let quadrature = reference.quadrature().clone();
    for _ in 0..stop {
        reference.step().unwrap();
    }
    let error_at_stop = (reference.q() - exact(reference.t())).amax();
    let mut same = restarted(&reference, quadrature.clone(), h);
    let mut half = restarted(&reference, quadrature.clone(), h / 2.0);
    let mut from_velocity = Stepper::new(reference.system().clone(), quadrature, h)
        .unwrap()
        .with_constraint_point(reference.constraint_point());
    from_velocity
        .start_from_velocity(reference.q(), reference.v().unwrap())
        .unwrap_or_else(|e| panic!("{name}: restart from (q, v()) refused: {e}"));
    let mut fine = make(h / 2.0);
    for _ in 0..2 * stop {
        fine.step().unwrap();
    }
    for _ in 0..more {
        reference.step().unwrap();
        same.step().unwrap();
        from_velocity.step().unwrap();
        for _ in 0..2 {
            half.step().unwrap();
            fine.step().unwrap();
        }
    }
    let t = reference.t();
    assert!((same.t() - t).abs() < 1e-12 && (half.t() - t).abs() < 1e-12);
    let continued = (same.q() - reference.q()).amax();
    assert!(
        continued < 1e-12,
        "{name}: same-h restart off by {continued:e}"
    );
    let error_h = (reference.q() - exact(t)).amax();
    let error_half = (half.q() - exact(t)).amax();
    let error_fine = (fine.q() - exact(t)).amax();
    let error_velocity = (from_velocity.q() - exact(t)).amax();
    // The restarted run inherits the h run's error in (q, p) at the stop (the discrete
    // momentum is O(h²) off the exact one, and a position error can be near a zero there), and
    // then makes the errors of h/2: between the runs at h/2 and h, and less than the h run.
    assert!(
        error_half < error_h && error_half > 0.5 * error_fine,
        "{name}: h/2 restart error {error_half:e}; at the stop {error_at_stop:e}, h/2 run \
         {error_fine:e}, h run {error_h:e}"
    );
    assert!(
        error_velocity <= 1.2 * error_h,
        "{name}: restart from (q, v()) error {error_velocity:e} vs {error_h:e}"
    );
}

#[test]
fn every_constrained_scene_restarts_from_its_own_state() {
    let (q0, v0) = unequal_start();
    let lc = |h| {
        let mut stepper = Stepper::new(UNEQUAL, Quadrature::midpoint(), h).unwrap();
        stepper.start_from_velocity(q0, v0).unwrap();
        stepper
    };
    check_restart("unequal LC", lc, 0.02, unequal_exact, 100, 150);

    let seed = |h| {
        let mut stepper = Stepper::new(circuit::LC, Quadrature::midpoint(), h).unwrap();
        stepper
            .start_from_velocity(circuit::q0(), SVector::zeros())
            .unwrap();
        stepper
    };
    let exact_seed = |t: f64| {
        let x = circuit::lc_q_c2(t);
        let s = x - 1.0; // q_c1 + q_c3 = q_c2 − 1, split equally.
        vector![x - 1.0, s / 2.0, x, s / 2.0]
    };
    check_restart("seed LC", seed, 0.02, exact_seed, 100, 150);

    let knife = |h| knife_edge::stepper(ConstraintPoint::Midpoint, h).unwrap();
    check_restart("knife edge", knife, 0.02, knife_edge::exact, 50, 100);

    let pendulum = |h| {
        let mut stepper =
            Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), h).unwrap();
        stepper
            .start_from_velocity(cartesian_pendulum::q0(1.0), SVector::zeros())
            .unwrap();
        stepper
    };
    let exact_pendulum = |t: f64| cartesian_pendulum::q0(angle_pendulum_at(t));
    check_restart(
        "Cartesian pendulum",
        pendulum,
        0.02,
        exact_pendulum,
        50,
        100,
    );

    let ports = |h| {
        let mut stepper = Stepper::new(port::SCENE, Quadrature::midpoint(), h).unwrap();
        stepper
            .start_from_velocity(port::q0(), SVector::zeros())
            .unwrap();
        stepper
    };
    check_restart("massless port", ports, 0.02, port_at, 100, 150);

    let rc = |h| {
        let mut stepper = Stepper::new(ParallelRc, Quadrature::midpoint(), h).unwrap();
        stepper
            .start_from_velocity(vector![0.0, 1.0, 0.0], vector![0.0, -2.0, 2.0])
            .unwrap();
        stepper
    };
    check_restart(
        "resistor beside a capacitor",
        rc,
        0.02,
        parallel_rc_at,
        50,
        100,
    );

    let disk = |h| rolling_disk::stepper(Quadrature::midpoint(), h).unwrap();
    check_restart("rolling disk", disk, 0.05, rolling_disk::exact, 50, 100);
    // A constrained Galerkin step (one-forms at the Gauss nodes) restarts the same way.
    let disk_galerkin = |h| rolling_disk::stepper(Quadrature::galerkin(2).unwrap(), h).unwrap();
    check_restart(
        "rolling disk, galerkin(2)",
        disk_galerkin,
        0.1,
        rolling_disk::exact,
        20,
        40,
    );
}

/// The pendulum angle at `t` from rest at 1 rad, by `galerkin(3)` at h = 1e-3 (error < 1e-12).
fn angle_pendulum_at(t: f64) -> f64 {
    let mut stepper = Stepper::new(
        scenes::pendulum::SCENE,
        Quadrature::galerkin(3).unwrap(),
        1e-3,
    )
    .unwrap();
    stepper
        .start_from_velocity(vector![1.0], vector![0.0])
        .unwrap();
    for _ in 0..(t / 1e-3).round() as usize {
        stepper.step().unwrap();
    }
    stepper.q()[0]
}

/// The massless port's closed form: normal modes of `x1` (with y = x1) and `x2`.
fn port_at(t: f64) -> SVector<f64, 3> {
    // M = I, K = [[k1 + k2, −k2], [−k2, k2]] with unit parameters: ω² = (3 ∓ √5)/2.
    let s5 = 5.0_f64.sqrt();
    let (w1, w2) = (((3.0 - s5) / 2.0).sqrt(), ((3.0 + s5) / 2.0).sqrt());
    // Eigenvectors (1, a) with a = 2 − ω²; start x = (1, 0) at rest.
    let (a1, a2) = (2.0 - w1 * w1, 2.0 - w2 * w2);
    // (1, 0) = c1 (1, a1) + c2 (1, a2).
    let c1 = -a2 / (a1 - a2);
    let c2 = a1 / (a1 - a2);
    let x1 = c1 * (w1 * t).cos() + c2 * (w2 * t).cos();
    let x2 = c1 * a1 * (w1 * t).cos() + c2 * a2 * (w2 * t).cos();
    vector![x1, x2, x1]
}

/// The port's closed form agrees with the scene's golden value.
#[test]
fn port_closed_form_matches_the_golden_value() {
    let q = port_at(20.0);
    assert!((q[0] - port::X20[0]).abs() < 1e-6 && (q[1] - port::X20[1]).abs() < 1e-6);
}

/// RATTLE and SHAKE on the Cartesian pendulum: the same positions; RATTLE's momentum is tangent
/// (`dg·M⁻¹p = 0` to round-off), SHAKE's has a normal component of the method's order; the
/// velocity both report is tangent, so the energy both report is the same.
#[test]
fn rattle_against_shake_on_the_cartesian_pendulum() {
    let h = 0.05;
    let start = |scheme| {
        let mut stepper = Stepper::new(cartesian_pendulum::SCENE, Quadrature::midpoint(), h)
            .unwrap()
            .with_holonomic_scheme(scheme);
        stepper
            .start_from_velocity(cartesian_pendulum::q0(1.0), SVector::zeros())
            .unwrap();
        stepper
    };
    let (mut shake, mut rattle) = (
        start(HolonomicScheme::Shake),
        start(HolonomicScheme::Rattle),
    );
    let e0 = shake.energy().unwrap();
    let (mut normal_shake, mut normal_rattle, mut energy_shake, mut energy_rattle, mut gap) =
        (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    // dg·v for the momentum read as m v (the unit mass).
    let normal = |s: &Stepper<_, 2>| {
        let (q, p) = (s.q(), s.p());
        (q[0] * p[0] + q[1] * p[1]).abs()
    };
    for _ in 0..4000 {
        shake.step().unwrap();
        rattle.step().unwrap();
        gap = gap.max((shake.q() - rattle.q()).amax());
        normal_shake = normal_shake.max(normal(&shake));
        normal_rattle = normal_rattle.max(normal(&rattle));
        let q = rattle.q();
        assert!((q.norm_squared() - 1.0).abs() < 1e-12);
        let v = rattle.v().unwrap();
        assert!(q.dot(&v).abs() < 1e-14);
        energy_shake = energy_shake.max((shake.energy().unwrap() - e0).abs());
        energy_rattle = energy_rattle.max((rattle.energy().unwrap() - e0).abs());
    }
    assert!(gap < 1e-12, "positions differ by {gap:e}");
    assert!(normal_rattle < 1e-14, "{normal_rattle:e}");
    assert!(normal_shake > 1e-4, "{normal_shake:e}");
    // Measured: both 6.2e-4 over T = 200, bounded.
    assert!((energy_shake - energy_rattle).abs() < 1e-12);
    assert!(energy_rattle < 1e-3, "{energy_rattle:e}");
    // Derivatives are available for SHAKE only.
    assert!(matches!(
        rattle.step_linearised(),
        Err(DiracError::Unsupported(_))
    ));
    assert!(shake.step_linearised().is_ok());
}

/// A force on a capacitor that depends on time makes the hidden constraint time dependent:
/// refused at the start, since its velocity form would miss ∂c/∂t.
#[dirac_system(
    coordinates(q_l, q_c1, q_c3),
    lagrangian = 0.5 * dot(q_l).powi(2) - q_c1.powi(2) / 2.0 - q_c3.powi(2) / 2.0,
    constraints(-dq_l + dq_c1 + dq_c3),
    forces(sin(t) * dq_c1),
)]
#[derive(Debug, Clone, Copy)]
struct DrivenPair;

#[test]
fn a_time_dependent_hidden_constraint_is_refused() {
    let mut stepper = Stepper::new(DrivenPair, Quadrature::midpoint(), 0.01).unwrap();
    let err = stepper
        .start_from_velocity(SVector::zeros(), SVector::zeros())
        .unwrap_err();
    assert!(matches!(err, DiracError::Unsupported(_)), "{err}");
    assert!(err.to_string().contains("q_c1, q_c3"), "{err}");
    assert!(stepper.state().is_none());
}

/// The start checks are relative: the same consistent circuit in microcoulombs starts, and an
/// inconsistency of 1e-6 relative to its charges is refused (an absolute tolerance of 1e-9
/// accepted it).
#[test]
fn start_checks_are_relative_to_the_state() {
    let scale = 1e-6;
    let (q0, v0) = unequal_start();
    let mut stepper = Stepper::new(UNEQUAL, Quadrature::midpoint(), 0.01).unwrap();
    stepper.start_from_velocity(q0 * scale, v0 * scale).unwrap();
    let mut off = q0 * scale;
    off[1] += 1e-6 * scale;
    let err = stepper.start_from_velocity(off, v0 * scale).unwrap_err();
    assert!(
        matches!(err, DiracError::InconsistentInitialState(_)),
        "{err}"
    );
}

/// A force on a capacitor that is periodic in t (50 Hz, zero at whole offsets of t) and one
/// proportional to a charge that starts at 0 are time dependent too: refused.
#[dirac_system(
    coordinates(q_l, q_c1, q_c3),
    lagrangian = 0.5 * dot(q_l).powi(2) - q_c1.powi(2) / 2.0 - q_c3.powi(2) / 2.0,
    constraints(-dq_l + dq_c1 + dq_c3),
    forces(cos(314.1592653589793 * t) * dq_c1 + t * q_c3 * dq_c3),
)]
#[derive(Debug, Clone, Copy)]
struct HiddenlyDriven;

#[test]
fn time_dependence_is_found_where_it_vanishes_at_the_start() {
    let mut stepper = Stepper::new(HiddenlyDriven, Quadrature::midpoint(), 0.01).unwrap();
    let err = stepper
        .start_from_velocity(vector![0.0, 1.0, 0.0], SVector::zeros())
        .unwrap_err();
    assert!(matches!(err, DiracError::Unsupported(_)), "{err}");
}

/// An inductor feeding a resistor in parallel with a capacitor: the resistor's charge has no
/// kinetic energy, and its row with the capacitor's is a first-order equation (R q̇_r = q_c/C),
/// not a hidden constraint. The run, the energy and the velocity work (the velocity solve with
/// constraint multipliers would be singular there).
#[dirac_system(
    coordinates(q_l, q_c, q_r),
    lagrangian = 0.5 * dot(q_l).powi(2) - q_c.powi(2) / 2.0,
    constraints(-dq_l + dq_c + dq_r),
    forces(-0.5 * dot(q_r) * dq_r),
)]
#[derive(Debug, Clone, Copy)]
struct ParallelRc;

/// The closed form from q_c = 1 with no current: with x = q_c and i = q̇_l, ẋ = i − 2x and
/// i̇ = −x (double eigenvalue −1), so x = (1 − t) e^{−t}, i = −t e^{−t}, q_l = (1 + t) e^{−t} − 1
/// and q_r = ∫ 2x = 2 t e^{−t}.
fn parallel_rc_at(t: f64) -> SVector<f64, 3> {
    let decay = (-t).exp();
    vector![(1.0 + t) * decay - 1.0, (1.0 - t) * decay, 2.0 * t * decay]
}

#[test]
fn a_resistor_parallel_to_a_capacitor_runs() {
    let mut stepper = Stepper::new(ParallelRc, Quadrature::midpoint(), 0.01).unwrap();
    // q_c = 1, no current: the resistor carries q̇_r = q_c / (R C) = 2, the inductor −(−2)... the
    // balance fixes v_r = 2 and KCL v_l = v_c + v_r with v_l = 0: v_c = −2.
    stepper
        .start_from_velocity(vector![0.0, 1.0, 0.0], vector![0.0, -2.0, 2.0])
        .unwrap();
    let trajectory = stepper.run(200).unwrap();
    assert!(trajectory.energy().iter().all(|e| e.is_finite()));
    assert!(trajectory.max_constraint_violation() < 1e-13);
    // Energy only leaves through the resistor.
    let energy = trajectory.energy();
    assert!(
        energy.windows(2).all(|w| w[1] <= w[0] + 1e-12),
        "{energy:?}"
    );
    // The velocity keeps Kirchhoff's current law and the resistor's law R q̇_r = q_c / C at the
    // node, and is the closed form's to the method's order.
    let v = stepper.v().unwrap();
    let q = stepper.q();
    assert!((-v[0] + v[1] + v[2]).abs() < 1e-14, "KCL: {v:?}");
    assert!(
        (0.5 * v[2] - q[1]).abs() < 1e-14,
        "resistor: {v:?} at {q:?}"
    );
    let t = stepper.t();
    let exact = vector![
        -t * (-t).exp(),
        (t - 2.0) * (-t).exp(),
        2.0 * (1.0 - t) * (-t).exp()
    ];
    assert!((v - exact).amax() < 1e-3, "{v:?} vs {exact:?}");
}

/// The trapezoid (its error on this circuit grew as e^(2t) from a parasitic mode of the
/// resistor's and capacitor's charges) and a Gauss rule with more nodes than the path's degree
/// (order 1) are refused before the first step; midpoint and Gauss Galerkin keep their orders
/// against the closed form (measured 2.00, 4.00, 6.0).
#[test]
fn a_resistor_parallel_to_a_capacitor_keeps_its_orders() {
    let start = |quadrature: Quadrature, h: f64| {
        let mut stepper = Stepper::new(ParallelRc, quadrature, h)?;
        stepper.start_from_velocity(vector![0.0, 1.0, 0.0], vector![0.0, -2.0, 2.0])?;
        Ok::<_, DiracError>(stepper)
    };
    for quadrature in [
        Quadrature::trapezoid(),
        Quadrature::galerkin_with_rule(1, Rule::GaussLegendre(2)).unwrap(),
    ] {
        let err = start(quadrature, 0.05).unwrap_err();
        assert!(matches!(err, DiracError::InvalidQuadrature(_)), "{err}");
        assert!(err.to_string().contains("first-order equations"), "{err}");
    }
    let t = 2.0;
    for (quadrature, hs, order) in [
        (Quadrature::midpoint(), [0.1, 0.05, 0.025], 2.0),
        (Quadrature::galerkin(2).unwrap(), [0.2, 0.1, 0.05], 4.0),
        (Quadrature::galerkin(3).unwrap(), [0.4, 0.2, 0.1], 6.0),
    ] {
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let mut stepper = start(quadrature.clone(), h).unwrap();
                for _ in 0..(t / h).round() as usize {
                    stepper.step().unwrap();
                }
                (stepper.q() - parallel_rc_at(t)).amax()
            })
            .collect();
        assert_order(&quadrature.name(), &hs, &errors, order);
    }
}

/// A Maxwell element without constraints: a mass on a spring whose other end y has no mass and
/// is held by a damper, L = ẋ²/2 − k (x − y)²/2 with F_y = −c ẏ. The row of y is a first-order
/// equation with a constant momentum (0); the variational step keeps the orders, and the
/// trapezoid is refused.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * dot(x).powi(2) - 0.5 * k * (x - y).powi(2),
    forces(-c * dot(y) * dy),
)]
#[derive(Debug, Clone, Copy)]
struct Maxwell {
    k: f64,
    c: f64,
}

const MAXWELL: Maxwell = Maxwell { k: 4.0, c: 2.0 };

/// (x, ẋ, y) by classical Runge–Kutta at h = 1e-4: ẍ = −k (x − y), ẏ = k (x − y) / c.
fn maxwell_at(t: f64) -> SVector<f64, 3> {
    let field = |s: &SVector<f64, 3>| {
        let stretch = MAXWELL.k * (s[0] - s[2]);
        vector![s[1], -stretch, stretch / MAXWELL.c]
    };
    let steps = (t / 1e-4).round() as usize;
    let h = t / steps as f64;
    let mut s = vector![1.0, 0.0, 0.0];
    for _ in 0..steps {
        let k1 = field(&s);
        let k2 = field(&(s + k1 * (h / 2.0)));
        let k3 = field(&(s + k2 * (h / 2.0)));
        let k4 = field(&(s + k3 * h));
        s += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
    }
    s
}

#[test]
fn a_maxwell_element_keeps_its_orders() {
    // y's velocity at the start: k (x − y) / c = 2.
    let start = |quadrature: Quadrature, h: f64| {
        let mut stepper = Stepper::new(MAXWELL, quadrature, h)?;
        stepper.start_from_velocity(vector![1.0, 0.0], vector![0.0, 2.0])?;
        Ok::<_, DiracError>(stepper)
    };
    let err = start(Quadrature::trapezoid(), 0.05).unwrap_err();
    assert!(matches!(err, DiracError::InvalidQuadrature(_)), "{err}");
    let t = 2.0;
    let exact = maxwell_at(t);
    for (quadrature, hs, order) in [
        (Quadrature::midpoint(), [0.1, 0.05, 0.025], 2.0),
        (Quadrature::galerkin(2).unwrap(), [0.2, 0.1, 0.05], 4.0),
    ] {
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let mut stepper = start(quadrature.clone(), h).unwrap();
                for _ in 0..(t / h).round() as usize {
                    stepper.step().unwrap();
                }
                (stepper.q() - vector![exact[0], exact[2]]).amax()
            })
            .collect();
        assert_order(
            &format!("Maxwell, {}", quadrature.name()),
            &hs,
            &errors,
            order,
        );
    }
}

/// The holonomic check is relative to the terms of g: g = x y − 1 at (1e-5, 6e5) is 5, far from
/// 0 relative to its terms (12), though small next to |dg| |q| (3.6e11).
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (dot(x).powi(2) + dot(y).powi(2)),
    holonomic(x * y - 1.0),
)]
#[derive(Debug, Clone, Copy)]
struct Hyperbola;

#[test]
fn the_holonomic_start_check_is_relative_to_its_terms() {
    let mut stepper = Stepper::new(Hyperbola, Quadrature::midpoint(), 0.01).unwrap();
    let err = stepper
        .start_from_velocity(vector![1e-5, 6e5], SVector::zeros())
        .unwrap_err();
    assert!(
        matches!(err, DiracError::InconsistentInitialState(_)),
        "{err}"
    );
    stepper
        .start_from_velocity(vector![1e-5, 1e5], SVector::zeros())
        .unwrap();
}

/// The Cartesian pendulum with `galerkin(2)`: the constraint held at the internal point and the
/// end point, order 4 against the angle pendulum with both Gauss and Lobatto rules (measured
/// 4.00; errors 6.5e-6 to 1.6e-9 for h = 0.2 to 0.025 at T = 2), g to round-off, and the
/// multipliers named per point.
#[test]
fn holonomic_galerkin_of_degree_two_is_fourth_order() {
    let t = 2.0;
    let exact = cartesian_pendulum::q0(angle_pendulum_at(t));
    let hs = [0.2, 0.1, 0.05, 0.025];
    for quadrature in [
        Quadrature::galerkin(2).unwrap(),
        Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap(),
    ] {
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let mut stepper =
                    Stepper::new(cartesian_pendulum::SCENE, quadrature.clone(), h).unwrap();
                stepper
                    .start_from_velocity(cartesian_pendulum::q0(1.0), SVector::zeros())
                    .unwrap();
                for _ in 0..(t / h).round() as usize {
                    stepper.step().unwrap();
                    assert!(stepper.constraint_violation() < 1e-14);
                }
                (stepper.q() - exact).amax()
            })
            .collect();
        let order = slope(&hs, &errors);
        assert!(
            (order - 4.0).abs() < 0.2,
            "{}: {order}, {errors:?}",
            quadrature.name()
        );
    }
    // Hanging at rest: the internal point carries 4/6 of the weight over a step and the end
    // point's SHAKE impulse, once the momentum's normal part has settled, 2/6: the multipliers
    // come out in the order of their names.
    let mut hanging = Stepper::new(
        cartesian_pendulum::SCENE,
        Quadrature::galerkin(2).unwrap(),
        0.1,
    )
    .unwrap();
    assert_eq!(
        hanging.trajectory().multiplier_names(),
        ["lambda_0_internal_1", "lambda_0"]
    );
    hanging
        .start_from_velocity(vector![0.0, -1.0], SVector::zeros())
        .unwrap();
    for _ in 0..3 {
        hanging.step().unwrap();
    }
    let lambda = hanging.multipliers();
    assert!(
        (lambda[0] - 2.0 * lambda[1]).abs() < 1e-12 * lambda[0].abs(),
        "{lambda:?}"
    );
    assert!(lambda[0].abs() > 1e-3);
    // RATTLE with galerkin(2): the stored momentum is tangent (unit mass: q·p = 0).
    let mut rattle = Stepper::new(
        cartesian_pendulum::SCENE,
        Quadrature::galerkin(2).unwrap(),
        0.1,
    )
    .unwrap()
    .with_holonomic_scheme(HolonomicScheme::Rattle);
    rattle
        .start_from_velocity(cartesian_pendulum::q0(1.0), SVector::zeros())
        .unwrap();
    for _ in 0..100 {
        rattle.step().unwrap();
        assert!(rattle.q().dot(&rattle.p()).abs() < 1e-13);
    }
}

/// Constraint one-forms held at the Gauss nodes of a Galerkin step (the constraint force enters
/// the rows as a force does): orders 2, 4, 6 for midpoint, `galerkin(2)`, `galerkin(3)` on the
/// knife edge (measured 2.00, 4.00, 6.00), the rolling disk and the LC circuit (2.01, 3.99,
/// 6.07), the one-forms held at every node to round-off.
#[test]
fn one_forms_at_the_nodes_of_galerkin_steps_keep_the_orders() {
    let cases = [
        (Quadrature::midpoint(), 2.0, [0.04, 0.02, 0.01, 0.005]),
        (
            Quadrature::galerkin(2).unwrap(),
            4.0,
            [0.2, 0.1, 0.05, 0.025],
        ),
        (Quadrature::galerkin(3).unwrap(), 6.0, [0.4, 0.2, 0.1, 0.05]),
    ];
    for (quadrature, order, hs) in cases {
        let name = quadrature.name();
        let knife: Vec<f64> = hs
            .iter()
            .map(|&h| {
                // Newton's method (no Jacobian kept across steps), to see its convergence.
                let newton = NewtonOptions {
                    jacobian_reuse: Some(0.0),
                    ..Default::default()
                };
                let mut stepper = Stepper::new(knife_edge::SCENE, quadrature.clone(), h)
                    .unwrap()
                    .with_newton_options(newton)
                    .unwrap();
                stepper
                    .start_from_velocity(SVector::zeros(), vector![0.0, 0.0, knife_edge::OMEGA])
                    .unwrap();
                for _ in 0..(2.0 / h).round() as usize {
                    stepper.step().unwrap();
                    assert!(stepper.constraint_violation() < 1e-14, "{name}");
                    // Quadratic convergence (an exact Jacobian): 3 evaluations, the minimum.
                    assert!(stepper.last_report().unwrap().iterations <= 4, "{name}");
                }
                (stepper.q() - knife_edge::exact(2.0)).amax()
            })
            .collect();
        let disk: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let mut stepper = rolling_disk::stepper(quadrature.clone(), h).unwrap();
                for _ in 0..(2.0 / h).round() as usize {
                    stepper.step().unwrap();
                    assert!(stepper.constraint_violation() < 1e-14, "{name}");
                }
                (stepper.q() - rolling_disk::exact(2.0)).amax()
            })
            .collect();
        let lc: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let h = h * 2.5;
                let (q, _) = circuit::lc_at_10(quadrature.clone(), h).unwrap();
                (q - SVector::from(circuit::LC_Q10)).amax()
            })
            .collect();
        let lc_hs = hs.map(|h| h * 2.5);
        for (scene, errors, steps) in [
            ("knife edge", &knife, &hs),
            ("rolling disk", &disk, &hs),
            ("LC circuit", &lc, &lc_hs),
        ] {
            let measured = slope(steps, errors);
            assert!(
                (measured - order).abs() < 0.2,
                "{scene}, {name}: order {measured}, {errors:?}"
            );
        }
    }
    // Lobatto rules have a node more than the path has free points: refused for one-forms.
    let lobatto = Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap();
    let err = Stepper::new(knife_edge::SCENE, lobatto, 0.1).unwrap_err();
    assert!(matches!(err, DiracError::InvalidQuadrature(_)), "{err}");
    // A Galerkin step has no constraint point: asking for one is refused at the start.
    let mut end = Stepper::new(knife_edge::SCENE, Quadrature::galerkin(2).unwrap(), 0.1)
        .unwrap()
        .with_constraint_point(ConstraintPoint::End);
    let err = end
        .start_from_velocity(SVector::zeros(), vector![0.0, 0.0, 1.0])
        .unwrap_err();
    assert!(matches!(err, DiracError::InvalidQuadrature(_)), "{err}");
}

/// The knife edge's energy over T = 200 (h = 0.05) with the one-forms at the Gauss nodes:
/// bounded with no drift (measured over T = 1000: 1.9e-5, 3.7e-6 and 1.3e-13 for midpoint,
/// `galerkin(2)`, `galerkin(3)`, the same in the first and the last tenth).
#[test]
fn knife_edge_energy_with_galerkin_steps_does_not_drift() {
    for (quadrature, bound) in [
        (Quadrature::galerkin(2).unwrap(), 1e-5),
        (Quadrature::galerkin(3).unwrap(), 1e-12),
    ] {
        let mut stepper = Stepper::new(knife_edge::SCENE, quadrature.clone(), 0.05).unwrap();
        stepper
            .start_from_velocity(SVector::zeros(), vector![0.0, 0.0, knife_edge::OMEGA])
            .unwrap();
        let e0 = stepper.energy().unwrap();
        let errors: Vec<f64> = (0..4000)
            .map(|_| {
                stepper.step().unwrap();
                (stepper.energy().unwrap() - e0).abs()
            })
            .collect();
        let first = errors[..400].iter().cloned().fold(0.0, f64::max);
        let last = errors[3600..].iter().cloned().fold(0.0, f64::max);
        let name = quadrature.name();
        assert!(
            last < bound && last < 1.5 * first,
            "{name}: {first:e} → {last:e}"
        );
    }
}

/// The reported violation of a degree-1 step is `|A(q_c)(q_{k+1} − q_k)|` with the one-form
/// evaluated at the stored points (`q_c = q_k + θ(q_{k+1} − q_k)`), as a user reading the
/// trajectory would compute it, bit for bit, at every constraint point.
#[test]
fn the_reported_violation_is_the_one_form_at_the_stored_points() {
    for point in [
        ConstraintPoint::Start,
        ConstraintPoint::Midpoint,
        ConstraintPoint::End,
    ] {
        let mut stepper = knife_edge::stepper(point, 0.05).unwrap();
        for _ in 0..100 {
            let q0 = stepper.q();
            stepper.step().unwrap();
            let xi = stepper.q() - q0;
            let form = knife_edge::SCENE.one_form(&(q0 + xi * point.theta()), 0);
            assert_eq!(
                stepper.constraint_violation(),
                form.dot(&xi).abs(),
                "{point:?}"
            );
        }
    }
}

/// The violation is measured when asked, from the last accepted step: a step that fails (and
/// changes nothing) leaves it as it was, a new constraint point does not re-measure the step
/// already taken, and a run records at each sample what `constraint_violation` reports after
/// that sample's step. `galerkin(2)` reads its internal point from the step's solution, which a
/// failed step's iterations overwrite.
#[test]
fn the_violation_measured_on_request_is_the_last_accepted_steps() {
    let (h, omega) = (0.05, knife_edge::OMEGA);
    let galerkin = Quadrature::galerkin(2).unwrap();
    let mut stepper = Stepper::new(knife_edge::SCENE, galerkin.clone(), h).unwrap();
    stepper
        .start_from_velocity(SVector::zeros(), vector![0.0, 0.0, omega])
        .unwrap();
    stepper.run(20).unwrap();
    let before = (stepper.q(), stepper.constraint_violation());
    // One Newton iteration cannot solve a step from a far predictor: it fails and keeps the state.
    let options = NewtonOptions {
        max_iterations: 1,
        ..NewtonOptions::default()
    };
    let mut failing = stepper.with_newton_options(options).unwrap();
    assert!(failing.step().is_err());
    assert_eq!((failing.q(), failing.constraint_violation()), before);

    // Step by step and by a run: the same violation at every sample.
    let mut by_steps = Stepper::new(knife_edge::SCENE, galerkin.clone(), h).unwrap();
    let mut by_run = Stepper::new(knife_edge::SCENE, galerkin, h).unwrap();
    for stepper in [&mut by_steps, &mut by_run] {
        stepper
            .start_from_velocity(SVector::zeros(), vector![0.0, 0.0, omega])
            .unwrap();
    }
    let recorded = by_run.run(30).unwrap();
    assert_eq!(recorded.constraint_violation()[0], 0.0);
    for k in 1..=30 {
        by_steps.step().unwrap();
        assert_eq!(
            by_steps.constraint_violation(),
            recorded.constraint_violation()[k]
        );
    }

    // A midpoint step measured at its midpoint keeps that measure under a new constraint point;
    // measured at the end point it would differ.
    let mut stepper = knife_edge::stepper(ConstraintPoint::Midpoint, h).unwrap();
    let q0 = stepper.q();
    stepper.step().unwrap();
    let at_midpoint = stepper.constraint_violation();
    let xi = stepper.q() - q0;
    let at_end = knife_edge::SCENE.one_form(&stepper.q(), 0).dot(&xi).abs();
    assert!(
        at_end > 1e-6 && at_midpoint < 1e-14,
        "{at_end:e}, {at_midpoint:e}"
    );
    let stepper = stepper.with_constraint_point(ConstraintPoint::End);
    assert_eq!(stepper.constraint_violation(), at_midpoint);
}
