//! Lagrangians linear in the velocities, `L = ϑ(q)·q̇ − H(q)`: started from the position alone,
//! their orders in two gauges of `ϑ`, the Hamiltonian over long runs, against references
//! computed here by an independent method (classical Runge–Kutta on the vector field derived by
//! hand).

use crate::support;

use dirac::prelude::*;
use scenes::lotka_volterra::{self, LotkaVolterra};
use support::{assert_order, slope};

/// The same system in the gauge ϑ = (q2 + ln q2 / q1, q1) (ϑ changed by the gradient of q1 q2).
#[dirac_system(
    coordinates(q1, q2),
    lagrangian = (q2 + ln(q2) / q1) * dot(q1) + q1 * dot(q2)
        - (a1 * q1 + a2 * q2 + b1 * ln(q1) + b2 * ln(q2)),
)]
#[derive(Debug, Clone, Copy)]
struct LotkaVolterraGauge {
    a1: f64,
    a2: f64,
    b1: f64,
    b2: f64,
}

const LV: LotkaVolterra = lotka_volterra::SCENE;
const A1: f64 = LV.a1;
const A2: f64 = LV.a2;
const B1: f64 = LV.b1;
const B2: f64 = LV.b2;
const LV_GAUGE: LotkaVolterraGauge = LotkaVolterraGauge {
    a1: A1,
    a2: A2,
    b1: B1,
    b2: B2,
};

use lotka_volterra::{field, hamiltonian, q0, reference};

fn error_at<S: DiracSystem<2>>(
    system: S,
    quadrature: Quadrature,
    h: f64,
    t: f64,
    exact: &SVector<f64, 2>,
) -> f64 {
    error_under(
        system,
        FirstOrderScheme::Collocation,
        quadrature,
        h,
        t,
        exact,
    )
}

fn error_under<S: DiracSystem<2>>(
    system: S,
    scheme: FirstOrderScheme,
    quadrature: Quadrature,
    h: f64,
    t: f64,
    exact: &SVector<f64, 2>,
) -> f64 {
    let mut stepper = Stepper::new(system, quadrature, h)
        .unwrap()
        .with_first_order_scheme(scheme);
    stepper.start_from_position(q0()).unwrap();
    for _ in 0..(t / h).round() as usize {
        stepper.step().unwrap();
    }
    (stepper.q() - exact).amax()
}

/// The started state: momentum ϑ(q0), velocity the vector field at q0.
#[test]
fn a_first_order_lagrangian_starts_from_its_position() {
    let mut stepper = Stepper::new(LV, Quadrature::midpoint(), 0.01).unwrap();
    stepper.start_from_position(q0()).unwrap();
    assert!((stepper.v().unwrap() - field(&q0())).amax() < 1e-14);
    assert!((stepper.p() - vector![0.0, 0.0]).amax() < 1e-15); // ln 1 / 2 = 0
    let mut gauge = Stepper::new(LV_GAUGE, Quadrature::midpoint(), 0.01).unwrap();
    gauge.start_from_position(q0()).unwrap();
    assert!((gauge.p() - vector![1.0, 2.0]).amax() < 1e-15);
    // From (q0, ϑ(q0)) as well, and a momentum off ϑ(q0) is refused.
    let mut again = Stepper::new(LV_GAUGE, Quadrature::midpoint(), 0.01).unwrap();
    again.start_from_momentum(q0(), vector![1.0, 2.0]).unwrap();
    assert!((again.v().unwrap() - field(&q0())).amax() < 1e-14);
    let err = again
        .start_from_momentum(q0(), vector![1.0, 2.5])
        .unwrap_err();
    assert!(
        matches!(err, DiracError::InconsistentInitialState(_)),
        "{err}"
    );
    // A model with kinetic energy needs more than its position.
    let mut regular = Stepper::new(scenes_free(), Quadrature::midpoint(), 0.1).unwrap();
    assert!(matches!(
        regular.start_from_position(vector![0.0]),
        Err(DiracError::InconsistentInitialState(_))
    ));
}

#[dirac_system(coordinates(x), lagrangian = 0.5 * dot(x).powi(2))]
#[derive(Debug, Clone, Copy)]
struct Free;

fn scenes_free() -> Free {
    Free
}

/// Orders in both gauges against the Runge–Kutta reference at T = 2: midpoint 2, `galerkin(2)`
/// 4, `galerkin(3)` 6 (measured 2.00, 4.00, 6.05 in both, the errors equal to 1e-15: the step
/// depends on ϑ only through ϑ'ᵀ − ϑ').
#[test]
fn orders_do_not_depend_on_the_gauge() {
    let t = 2.0;
    let exact = reference(t);
    let cases: [(Quadrature, [f64; 4], f64); 3] = [
        (Quadrature::midpoint(), [0.1, 0.05, 0.025, 0.0125], 2.0),
        (
            Quadrature::galerkin(2).unwrap(),
            [0.2, 0.1, 0.05, 0.025],
            4.0,
        ),
        (
            Quadrature::galerkin(3).unwrap(),
            [0.2, 0.1, 0.05, 0.025],
            6.0,
        ),
    ];
    for (quadrature, hs, order) in cases {
        let first: Vec<f64> = hs
            .iter()
            .map(|&h| error_at(LV, quadrature.clone(), h, t, &exact))
            .collect();
        let second: Vec<f64> = hs
            .iter()
            .map(|&h| error_at(LV_GAUGE, quadrature.clone(), h, t, &exact))
            .collect();
        for (a, b) in first.iter().zip(&second) {
            assert!(
                (a - b).abs() <= 1e-13 + 1e-9 * a,
                "gauges differ: {a:e} vs {b:e}"
            );
        }
        let (m1, m2) = (slope(&hs, &first), slope(&hs, &second));
        println!(
            "{}: {m1:.2} {first:?} / {m2:.2} {second:?}",
            quadrature.name()
        );
        assert!(
            (m1 - order).abs() < 0.3 && (m2 - order).abs() < 0.3,
            "{}: orders {m1} (gauge 1, {first:?}) and {m2} (gauge 2, {second:?}), expected {order}",
            quadrature.name()
        );
    }
}

/// A third gauge, ϑ + ∇φ with φ = q2 sin q1, which no quadrature integrates exactly.
#[dirac_system(
    coordinates(q1, q2),
    lagrangian = (q2 * cos(q1) + ln(q2) / q1) * dot(q1) + sin(q1) * dot(q2)
        - (a1 * q1 + a2 * q2 + b1 * ln(q1) + b2 * ln(q2)),
)]
#[derive(Debug, Clone, Copy)]
struct LotkaVolterraSine {
    a1: f64,
    a2: f64,
    b1: f64,
    b2: f64,
}

const LV_SINE: LotkaVolterraSine = LotkaVolterraSine {
    a1: A1,
    a2: A2,
    b1: B1,
    b2: B2,
};

/// In a gauge no rule integrates exactly the orders hold too; the errors differ from the first
/// gauge's by less than the errors themselves.
#[test]
fn orders_hold_in_a_transcendental_gauge() {
    let t = 2.0;
    let exact = reference(t);
    for (quadrature, hs, order) in [
        (Quadrature::midpoint(), [0.1, 0.05, 0.025, 0.0125], 2.0),
        (
            Quadrature::galerkin(2).unwrap(),
            [0.2, 0.1, 0.05, 0.025],
            4.0,
        ),
        (
            Quadrature::galerkin(3).unwrap(),
            [0.2, 0.1, 0.05, 0.025],
            6.0,
        ),
    ] {
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| error_at(LV_SINE, quadrature.clone(), h, t, &exact))
            .collect();
        assert_order(&quadrature.name(), &hs, &errors, order);
    }
}

/// Gauss–Lobatto rules, the trapezoid among them, and Gauss rules with more nodes than the
/// path's degree are refused before the first step, saying why (the trapezoid's variational
/// step drifted from 0.15 to 0.49 in H over T = 500).
#[test]
fn lobatto_rules_are_refused() {
    for quadrature in [
        Quadrature::trapezoid(),
        Quadrature::galerkin_with_rule(2, Rule::GaussLobatto(3)).unwrap(),
    ] {
        let mut stepper = Stepper::new(LV, quadrature, 0.1).unwrap();
        let err = stepper.start_from_position(q0()).unwrap_err();
        assert!(matches!(err, DiracError::InvalidQuadrature(_)), "{err}");
        assert!(err.to_string().contains("use a Gauss rule"), "{err}");
        assert!(stepper.state().is_none());
    }
    // A Gauss rule with more nodes than the path's degree would collocate at some of them only
    // (order 1): refused.
    let overintegrated = Quadrature::galerkin_with_rule(1, Rule::GaussLegendre(2)).unwrap();
    let mut stepper = Stepper::new(LV, overintegrated, 0.1).unwrap();
    let err = stepper.start_from_position(q0()).unwrap_err();
    assert!(matches!(err, DiracError::InvalidQuadrature(_)), "{err}");
}

/// The Hamiltonian over 10⁴ steps at h = 0.05 (T = 500, about 80 periods) in the
/// transcendental gauge. The midpoint rule keeps it bounded (measured 1.11e-3 in the first tenth,
/// 1.18e-3 in the last). The Gauss collocation of degree 2 and 3 is not symplectic for this
/// form: its error grows linearly, from 1.4e-6 to 1.4e-5 and from 6.1e-10 to 6.1e-9, at the
/// method's order (a drift of O(t h^2s)).
#[test]
fn the_hamiltonian_over_a_long_run() {
    let h0 = hamiltonian(&q0());
    for (quadrature, bound, growth) in [
        (Quadrature::midpoint(), 2e-3, 1.2),
        (Quadrature::galerkin(2).unwrap(), 2e-5, 12.0),
        (Quadrature::galerkin(3).unwrap(), 1e-8, 12.0),
    ] {
        let mut stepper = Stepper::new(LV_SINE, quadrature.clone(), 0.05).unwrap();
        stepper.start_from_position(q0()).unwrap();
        let errors: Vec<f64> = (0..10_000)
            .map(|_| {
                stepper.step().unwrap();
                (hamiltonian(&stepper.q()) - h0).abs()
            })
            .collect();
        let first = errors[..1000].iter().cloned().fold(0.0, f64::max);
        let last = errors[9000..].iter().cloned().fold(0.0, f64::max);
        println!(
            "{}: first tenth {first:e}, last tenth {last:e}",
            quadrature.name()
        );
        assert!(last < bound, "{}: {last:e}", quadrature.name());
        assert!(
            last < growth * first,
            "{}: {first:e} → {last:e}",
            quadrature.name()
        );
    }
}

/// The Hamiltonian's largest error in the first and the last tenth of 10⁴ steps of h = 0.05
/// (T = 500, about 80 periods).
fn hamiltonian_first_and_last_tenth<S: DiracSystem<2>>(
    system: S,
    scheme: FirstOrderScheme,
    quadrature: Quadrature,
) -> (f64, f64) {
    let mut stepper = Stepper::new(system, quadrature, 0.05)
        .unwrap()
        .with_first_order_scheme(scheme);
    stepper.start_from_position(q0()).unwrap();
    let mut energy = vec![hamiltonian(&q0())];
    for _ in 0..10_000 {
        stepper.step().unwrap();
        energy.push(hamiltonian(&stepper.q()));
    }
    support::energy_error_first_and_last_tenth(&energy)
}

/// The variational step with the symmetric projection: orders 2, 4, 6 in the three gauges
/// (measured ~ in the first two, where the trajectories are equal: the gradient of q1 q2 is
/// integrated exactly by the rule along a polynomial path; and in the transcendental gauge).
#[test]
fn the_projected_step_has_full_order_in_every_gauge() {
    let t = 2.0;
    let exact = reference(t);
    let scheme = FirstOrderScheme::SymmetricProjection;
    for (quadrature, hs, order) in [
        (Quadrature::midpoint(), [0.1, 0.05, 0.025, 0.0125], 2.0),
        (
            Quadrature::galerkin(2).unwrap(),
            [0.2, 0.1, 0.05, 0.025],
            4.0,
        ),
        (
            Quadrature::galerkin(3).unwrap(),
            [0.2, 0.1, 0.05, 0.025],
            6.0,
        ),
    ] {
        let errors = |gauge: usize| -> Vec<f64> {
            hs.iter()
                .map(|&h| match gauge {
                    0 => error_under(LV, scheme, quadrature.clone(), h, t, &exact),
                    1 => error_under(LV_GAUGE, scheme, quadrature.clone(), h, t, &exact),
                    _ => error_under(LV_SINE, scheme, quadrature.clone(), h, t, &exact),
                })
                .collect()
        };
        let (first, second, sine) = (errors(0), errors(1), errors(2));
        for (a, b) in first.iter().zip(&second) {
            assert!(
                (a - b).abs() <= 1e-13 + 1e-9 * a,
                "gauges differ: {a:e} vs {b:e}"
            );
        }
        for (gauge, errors) in [("ϑ", &first), ("ϑ + ∇(q2 sin q1)", &sine)] {
            assert_order(
                &format!("{} in {gauge}", quadrature.name()),
                &hs,
                errors,
                order,
            );
        }
    }
}

/// The projected step keeps the Hamiltonian bounded with no drift over T = 500 in the gauges
/// ϑ = (ln q2 / q1, 0) and ϑ + ∇(q1 q2), where collocation's error grows linearly (the test
/// above). Measured, first tenth → last tenth: midpoint 2.558e-3 → 2.558e-3, `galerkin(2)`
/// 1.1248e-6 → 1.1248e-6, `galerkin(3)` 2.87e-10 → 2.83e-10 (collocation: 1.11e-3 → 1.18e-3,
/// 1.38e-6 → 1.36e-5, 6.1e-10 → 6.1e-9).
///
/// In the transcendental gauge the projected step is not as good, and the test prints it:
/// `galerkin(2)` 2.2e-5 → 2.0e-4, `galerkin(3)` 4.2e-8 → 3.7e-7, and the midpoint rule drifts
/// from 1.3e-2 to 0.28 until Newton stops contracting at step 3 093 (an error, not a wrong
/// step). The quadrature of `∇φ·q̇` is not exact for φ = q2 sin q1, and the projection depends
/// on the gauge; collocation does not (see `FirstOrderScheme`).
#[test]
fn the_projected_step_keeps_the_hamiltonian_without_drift() {
    let scheme = FirstOrderScheme::SymmetricProjection;
    for (quadrature, bound) in [
        (Quadrature::midpoint(), 3e-3),
        (Quadrature::galerkin(2).unwrap(), 2e-6),
        (Quadrature::galerkin(3).unwrap(), 5e-10),
    ] {
        let name = quadrature.name();
        for (gauge, (first, last)) in [
            (
                "ϑ",
                hamiltonian_first_and_last_tenth(LV, scheme, quadrature.clone()),
            ),
            (
                "ϑ + ∇(q1 q2)",
                hamiltonian_first_and_last_tenth(LV_GAUGE, scheme, quadrature.clone()),
            ),
        ] {
            println!("{name} in {gauge}: {first:e} → {last:e}");
            assert!(last < bound, "{name} in {gauge}: {last:e}");
            assert!(
                last < 1.05 * first,
                "{name} in {gauge}: {first:e} → {last:e}"
            );
        }
        if quadrature.degree() > 1 {
            let (first, last) = hamiltonian_first_and_last_tenth(LV_SINE, scheme, quadrature);
            println!("{name} in ϑ + ∇(q2 sin q1): {first:e} → {last:e} (drifts)");
        } else {
            let mut stepper = Stepper::new(LV_SINE, quadrature, 0.05)
                .unwrap()
                .with_first_order_scheme(scheme);
            stepper.start_from_position(q0()).unwrap();
            let (mut worst, h0) = (0.0_f64, hamiltonian(&q0()));
            let stopped = (0..10_000).find_map(|k| match stepper.step() {
                Ok(()) => {
                    worst = worst.max((hamiltonian(&stepper.q()) - h0).abs());
                    None
                }
                Err(err) => Some(format!("stopped at step {k}: {err}")),
            });
            println!("{name} in ϑ + ∇(q2 sin q1): H error up to {worst:e}; {stopped:?}");
        }
    }
}

/// A run restarts from its own position under either scheme (same h: exactly; h/2: below the h
/// run's error).
#[test]
fn a_first_order_run_restarts_from_its_position() {
    let (h, t) = (0.05, 4.0);
    for scheme in [
        FirstOrderScheme::Collocation,
        FirstOrderScheme::SymmetricProjection,
    ] {
        let stepper = |h: f64| {
            Stepper::new(LV_GAUGE, Quadrature::midpoint(), h)
                .unwrap()
                .with_first_order_scheme(scheme)
        };
        let mut reference = stepper(h);
        reference.start_from_position(q0()).unwrap();
        for _ in 0..40 {
            reference.step().unwrap();
        }
        let mut same = stepper(h);
        same.start_from_momentum(reference.q(), reference.p())
            .unwrap();
        let mut half = stepper(h / 2.0);
        half.start_from_position(reference.q()).unwrap();
        for _ in 40..(t / h).round() as usize {
            reference.step().unwrap();
            same.step().unwrap();
            half.step().unwrap();
            half.step().unwrap();
        }
        let exact = reference_at(t);
        assert!((same.q() - reference.q()).amax() < 1e-13, "{scheme:?}");
        let (error_h, error_half) = ((reference.q() - exact).amax(), (half.q() - exact).amax());
        assert!(
            error_half < error_h,
            "{scheme:?}: {error_half:e} vs {error_h:e}"
        );
    }
}

fn reference_at(t: f64) -> SVector<f64, 2> {
    reference(t)
}

/// Three point vortices, L = Σ Γ_i (x_i ẏ_i − y_i ẋ_i)/2 − H with
/// H = −(1/4π) Σ_{i<j} Γ_i Γ_j ln |r_i − r_j|² / 2 (the factor 1/2 from |r|² inside the log).
#[dirac_system(
    coordinates(x1, y1, x2, y2, x3, y3),
    lagrangian = 0.5 * (g1 * (x1 * dot(y1) - y1 * dot(x1))
        + g2 * (x2 * dot(y2) - y2 * dot(x2))
        + g3 * (x3 * dot(y3) - y3 * dot(x3)))
        + (g1 * g2 * ln((x1 - x2).powi(2) + (y1 - y2).powi(2))
            + g1 * g3 * ln((x1 - x3).powi(2) + (y1 - y3).powi(2))
            + g2 * g3 * ln((x2 - x3).powi(2) + (y2 - y3).powi(2)))
            / (8.0 * 3.141592653589793),
)]
#[derive(Debug, Clone, Copy)]
struct Vortices {
    g1: f64,
    g2: f64,
    g3: f64,
}

/// Three vortices: the Hamiltonian bounded without drift, the linear and angular impulses
/// (quadratic invariants) kept to round-off by the midpoint rule and `galerkin(2)`.
#[test]
fn point_vortices_keep_their_hamiltonian_and_impulses() {
    let vortices = Vortices {
        g1: 1.0,
        g2: 2.0,
        g3: -0.5,
    };
    let q0 = vector![1.0, 0.0, -0.5, 0.3, 0.2, -1.0];
    let impulses = |q: &SVector<f64, 6>| {
        let g = [vortices.g1, vortices.g2, vortices.g3];
        let (mut px, mut py, mut angular) = (0.0, 0.0, 0.0);
        for i in 0..3 {
            let (x, y) = (q[2 * i], q[2 * i + 1]);
            px += g[i] * x;
            py += g[i] * y;
            angular += g[i] * (x * x + y * y);
        }
        vector![px, py, angular]
    };
    let energy = |q: &SVector<f64, 6>| {
        let g = [vortices.g1, vortices.g2, vortices.g3];
        let mut e = 0.0;
        for i in 0..3 {
            for j in i + 1..3 {
                let r2 = (q[2 * i] - q[2 * j]).powi(2) + (q[2 * i + 1] - q[2 * j + 1]).powi(2);
                e -= g[i] * g[j] * r2.ln() / (8.0 * std::f64::consts::PI);
            }
        }
        e
    };
    for quadrature in [Quadrature::midpoint(), Quadrature::galerkin(2).unwrap()] {
        let mut stepper = Stepper::new(vortices, quadrature.clone(), 0.05).unwrap();
        stepper.start_from_position(q0).unwrap();
        let (i0, e0) = (impulses(&q0), energy(&q0));
        let (mut impulse, mut first, mut last) = (0.0_f64, 0.0_f64, 0.0_f64);
        for k in 0..4000 {
            stepper.step().unwrap();
            let q = stepper.q();
            impulse = impulse.max((impulses(&q) - i0).amax());
            let e = (energy(&q) - e0).abs();
            if k < 400 {
                first = first.max(e);
            } else if k >= 3600 {
                last = last.max(e);
            }
        }
        println!(
            "{}: impulses {impulse:e}, H {first:e} → {last:e}",
            quadrature.name()
        );
        assert!(impulse < 1e-12, "{}: {impulse:e}", quadrature.name());
        assert!(
            last < 1e-3 && last < 2.0 * first.max(1e-14),
            "{}",
            quadrature.name()
        );
    }
}

/// A charged particle without mass in a unit magnetic field and the potential V = (x² + y²)/2:
/// L = (x ẏ − y ẋ)/2 − V, whose drift ẋ = −∂V/∂y, ẏ = ∂V/∂x turns the particle around the origin
/// at unit angular speed: q(t) = (cos t, sin t) from (1, 0).
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * (x * dot(y) - y * dot(x)) - 0.5 * (x * x + y * y),
)]
#[derive(Debug, Clone, Copy)]
pub(crate) struct MagneticDrift;

/// The drift against its closed form at T = 10: orders 2, 4, 6, and the potential (the
/// Hamiltonian, quadratic here) kept to round-off by every Gauss rule.
#[test]
fn a_particle_drifting_in_a_magnetic_field() {
    let exact = vector![10.0_f64.cos(), 10.0_f64.sin()];
    for (quadrature, hs, order) in [
        (Quadrature::midpoint(), [0.2, 0.1, 0.05, 0.025], 2.0),
        (Quadrature::galerkin(2).unwrap(), [0.4, 0.2, 0.1, 0.05], 4.0),
        (Quadrature::galerkin(3).unwrap(), [0.4, 0.2, 0.1, 0.05], 6.0),
    ] {
        let mut errors = Vec::new();
        for &h in &hs {
            let mut stepper = Stepper::new(MagneticDrift, quadrature.clone(), h).unwrap();
            stepper.start_from_position(vector![1.0, 0.0]).unwrap();
            for _ in 0..(10.0 / h).round() as usize {
                stepper.step().unwrap();
                let q = stepper.q();
                assert!((q.norm_squared() - 1.0).abs() < 1e-13, "{q}");
            }
            errors.push((stepper.q() - exact).amax());
        }
        assert_order(&quadrature.name(), &hs, &errors, order);
    }
}

/// The drift by its step map (quadratic `L`, every row collocated, and under the symmetric
/// projection the multipliers of `p = ϑ(q)` among the unknowns): the steps of Newton's method to
/// round-off, past a reading of the map, with the primary constraint held.
#[test]
fn a_drift_by_its_step_map_steps_as_newtons_method_does() {
    for scheme in [
        FirstOrderScheme::default(),
        FirstOrderScheme::SymmetricProjection,
    ] {
        let stepper = || {
            Stepper::new(MagneticDrift, Quadrature::galerkin(2).unwrap(), 0.05)
                .unwrap()
                .with_first_order_scheme(scheme)
        };
        let mut mapped = stepper().with_step_map().unwrap();
        let mut solved = stepper();
        mapped.start_from_position(vector![1.0, 0.0]).unwrap();
        solved.start_from_position(vector![1.0, 0.0]).unwrap();
        for _ in 0..2_000 {
            mapped.step().unwrap();
            solved.step().unwrap();
        }
        let gap = (mapped.q() - solved.q())
            .amax()
            .max((mapped.p() - solved.p()).amax());
        assert!(gap <= 1e-12, "{scheme:?}: the runs differ by {gap:e}");
        // p = ϑ(q) = (−y, x)/2, and the orbit the unit circle.
        let (q, p) = (mapped.q(), mapped.p());
        let theta = vector![-q[1], q[0]] * 0.5;
        assert!(
            (p - theta).amax() <= 1e-14,
            "{scheme:?}: {p} against {theta}"
        );
        assert!((q.norm_squared() - 1.0).abs() <= 1e-12, "{scheme:?}: {q}");
    }
}

/// Lotka–Volterra coupled to an oscillator with kinetic energy: L = ϑ(q)·q̇ + ẋ²/2 − H with
/// H = H_LV(q) + x²/2 + ε x q1. The rows of q1, q2 (linear in their velocities) are
/// collocated, the row of x stays variational. Its equations: q̇1 = q1 q2 ∂H/∂q2,
/// q̇2 = −q1 q2 ∂H/∂q1, ẍ = −x − ε q1.
#[dirac_system(
    coordinates(q1, q2, x),
    lagrangian = ln(q2) / q1 * dot(q1) + 0.5 * dot(x).powi(2)
        - (a1 * q1 + a2 * q2 + b1 * ln(q1) + b2 * ln(q2) + 0.5 * x.powi(2) + eps * x * q1),
)]
#[derive(Debug, Clone, Copy)]
struct CoupledToAnOscillator {
    a1: f64,
    a2: f64,
    b1: f64,
    b2: f64,
    eps: f64,
}

const COUPLED: CoupledToAnOscillator = CoupledToAnOscillator {
    a1: A1,
    a2: A2,
    b1: B1,
    b2: B2,
    eps: 0.3,
};

/// The coupled model's vector field on (q1, q2, x, ẋ).
fn coupled_field(y: &SVector<f64, 4>) -> SVector<f64, 4> {
    let (q1, q2, x, v) = (y[0], y[1], y[2], y[3]);
    let dh_dq1 = A1 + B1 / q1 + COUPLED.eps * x;
    let dh_dq2 = A2 + B2 / q2;
    vector![
        q1 * q2 * dh_dq2,
        -q1 * q2 * dh_dq1,
        v,
        -x - COUPLED.eps * q1
    ]
}

const COUPLED_START: [f64; 4] = [2.0, 1.0, 0.5, 0.0];

/// Classical Runge–Kutta at h = 1e-4 on the vector field.
fn coupled_reference(t: f64) -> SVector<f64, 4> {
    let steps = (t / 1e-4).round() as usize;
    let h = t / steps as f64;
    let mut y = SVector::<f64, 4>::from(COUPLED_START);
    for _ in 0..steps {
        let k1 = coupled_field(&y);
        let k2 = coupled_field(&(y + k1 * (h / 2.0)));
        let k3 = coupled_field(&(y + k2 * (h / 2.0)));
        let k4 = coupled_field(&(y + k3 * h));
        y += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
    }
    y
}

fn coupled_stepper(
    quadrature: Quadrature,
    h: f64,
) -> Result<Stepper<CoupledToAnOscillator, 3>, DiracError> {
    let start = SVector::<f64, 4>::from(COUPLED_START);
    let field = coupled_field(&start);
    let mut stepper = Stepper::new(COUPLED, quadrature, h)?;
    stepper.start_from_velocity(
        vector![start[0], start[1], start[2]],
        vector![field[0], field[1], start[3]],
    )?;
    Ok(stepper)
}

/// A Lagrangian linear in some velocities and quadratic in others keeps the orders 2, 4, 6 (the
/// plain variational step measured 2 for `galerkin(2)`), refuses the trapezoid before the first
/// step, reports the velocity of its vector field, and restarts from its own state.
#[test]
fn a_lagrangian_linear_in_some_velocities() {
    let t = 2.0;
    let exact = coupled_reference(t);
    for (quadrature, hs, order) in [
        (Quadrature::midpoint(), [0.1, 0.05, 0.025, 0.0125], 2.0),
        (
            Quadrature::galerkin(2).unwrap(),
            [0.2, 0.1, 0.05, 0.025],
            4.0,
        ),
        (
            Quadrature::galerkin(3).unwrap(),
            [0.2, 0.1, 0.05, 0.025],
            6.0,
        ),
    ] {
        let errors: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let mut stepper = coupled_stepper(quadrature.clone(), h).unwrap();
                for _ in 0..(t / h).round() as usize {
                    stepper.step().unwrap();
                }
                let q = stepper.q();
                (q - vector![exact[0], exact[1], exact[2]]).amax()
            })
            .collect();
        assert_order(
            &format!("coupled, {}", quadrature.name()),
            &hs,
            &errors,
            order,
        );
    }
    let err = coupled_stepper(Quadrature::trapezoid(), 0.1).unwrap_err();
    assert!(matches!(err, DiracError::InvalidQuadrature(_)), "{err}");
    // The velocity: the vector field on q1, q2 at the current state.
    let mut stepper = coupled_stepper(Quadrature::galerkin(2).unwrap(), 0.05).unwrap();
    for _ in 0..20 {
        stepper.step().unwrap();
    }
    let (q, v) = (stepper.q(), stepper.v().unwrap());
    let field = coupled_field(&vector![q[0], q[1], q[2], v[2]]);
    assert!(
        (v[0] - field[0]).abs() < 1e-12 && (v[1] - field[1]).abs() < 1e-12,
        "{v:?} vs {field:?}"
    );
    // A restart from (q, p) continues the run.
    let mut again = Stepper::new(COUPLED, Quadrature::galerkin(2).unwrap(), 0.05).unwrap();
    again.start_from_momentum(q, stepper.p()).unwrap();
    for _ in 0..20 {
        stepper.step().unwrap();
        again.step().unwrap();
    }
    assert!((again.q() - stepper.q()).amax() < 1e-12);
}

/// The same coupled model with a constraint: its rows linear in the velocities would be stepped
/// variationally, which loses order when their momenta depend on q; refused before the first
/// step.
#[dirac_system(
    coordinates(q1, q2, x),
    lagrangian = ln(q2) / q1 * dot(q1) + 0.5 * dot(x).powi(2)
        - (q1 + q2 - ln(q1) - 2.0 * ln(q2) + 0.5 * x.powi(2)),
    constraints(dx - dq2),
)]
#[derive(Debug, Clone, Copy)]
struct ConstrainedFirstOrder;

#[test]
fn constraints_on_rows_linear_in_their_velocities_are_refused() {
    let mut stepper = Stepper::new(ConstrainedFirstOrder, Quadrature::midpoint(), 0.05).unwrap();
    let err = stepper
        .start_from_velocity(vector![2.0, 1.0, 0.0], vector![-2.0, -1.0, -1.0])
        .unwrap_err();
    assert!(matches!(err, DiracError::Unsupported(_)), "{err}");
    assert!(err.to_string().contains("depends on the position"), "{err}");
    assert!(stepper.state().is_none());
}

/// The coupled model with a massless coordinate z tied to x by a spring: a hidden constraint
/// among the degenerate rows, which then are not collocated; refused like the constrained one.
#[dirac_system(
    coordinates(q1, q2, x, z),
    lagrangian = ln(q2) / q1 * dot(q1) + 0.5 * dot(x).powi(2)
        - (q1 + q2 - ln(q1) - 2.0 * ln(q2) + 0.5 * x.powi(2) + 0.5 * (z - x).powi(2)),
)]
#[derive(Debug, Clone, Copy)]
struct WithAMasslessSpring;

#[test]
fn hidden_constraints_beside_rows_linear_in_their_velocities_are_refused() {
    let mut stepper =
        Stepper::new(WithAMasslessSpring, Quadrature::galerkin(2).unwrap(), 0.05).unwrap();
    let err = stepper
        .start_from_velocity(vector![2.0, 1.0, 0.5, 0.5], vector![-2.0, -1.0, 0.0, 0.0])
        .unwrap_err();
    assert!(matches!(err, DiracError::Unsupported(_)), "{err}");
    assert!(err.to_string().contains("depends on the position"), "{err}");
}

/// The scheme is taken up by the next start: changed on a running stepper, the run goes on as it
/// was (no resizing of its unknowns mid-run), and a restart from its own state uses the new one.
#[test]
fn the_scheme_is_taken_up_by_the_next_start() {
    let quadrature = Quadrature::galerkin(2).unwrap();
    let mut collocated = Stepper::new(LV, quadrature.clone(), 0.05).unwrap();
    collocated.start_from_position(q0()).unwrap();
    let mut changed = Stepper::new(LV, quadrature.clone(), 0.05).unwrap();
    changed.start_from_position(q0()).unwrap();
    changed.step().unwrap();
    collocated.step().unwrap();
    let mut changed = changed.with_first_order_scheme(FirstOrderScheme::SymmetricProjection);
    for _ in 0..10 {
        changed.step().unwrap();
        collocated.step().unwrap();
    }
    assert_eq!(changed.q(), collocated.q());
    let mut projected = Stepper::new(LV, quadrature, 0.05)
        .unwrap()
        .with_first_order_scheme(FirstOrderScheme::SymmetricProjection);
    projected.start_from_position(changed.q()).unwrap();
    changed.start_from_position(changed.q()).unwrap();
    for _ in 0..10 {
        changed.step().unwrap();
        projected.step().unwrap();
        collocated.step().unwrap();
    }
    assert_eq!(changed.q(), projected.q());
    // At the same time the two schemes differ by their errors (~1e-7 here).
    assert!((changed.q() - collocated.q()).amax() > 1e-9);
}
