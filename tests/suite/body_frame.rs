//! Closed forms on rotations: the body-frame derivatives `#[dirac_system]` derives for models on
//! `Rᴷ × SO(3)ᴬ` against central differences of the Lagrangian along `R exp(ŵ)` (no dual
//! numbers involved), a wrong hand-written one refused at the start, and steps taken with them
//! equal to steps taken with dual numbers.

use dirac::prelude::*;
use dirac::{LagrangianGradient, LagrangianHessian};
use scenes::rigid_body::{self, HeavyTopByHand};

/// Vectors and two rotations coupled in position and velocity, with potentials that are not
/// linear in the attitudes, a parameter matrix and velocity-dependent inertia.
#[dirac_system(
    coordinates(x[2], R: SO3, S: SO3),
    lagrangian = 0.5 * dot(omega(R), j * omega(R))
        + 0.5 * dot(omega(S), omega(S)) * (1.0 + 0.1 * x[0] * x[0])
        + dot(omega(R), transpose(S) * R * [0.1, 0.2, 0.3]) * dot(x[1])
        + 0.5 * (dot(x[0]).powi(2) + dot(x[1]).powi(2))
        - m * dot([0.0, 0.0, 1.0], R * rho) * cos(x[1])
        - dot(R * [1.0, 0.0, 0.0], S * [0.0, 1.0, 0.0]).powi(2)
        + trace(transpose(R) * S) * x[0],
)]
#[derive(Debug, Clone, Copy)]
struct Coupled {
    j: [[f64; 3]; 3],
    m: f64,
    rho: [f64; 3],
}

const COUPLED: Coupled = Coupled {
    j: [[1.0, 0.1, 0.0], [0.1, 2.0, 0.2], [0.0, 0.2, 3.0]],
    m: 1.3,
    rho: [0.1, -0.2, 0.4],
};

/// A state of `Coupled`: both bodies turned and turning, the vectors moving.
fn coupled_start() -> (Configuration<f64, 2, 2, 0>, Rates<f64, 2, 2, 0>) {
    let q = Configuration::<f64, 2, 2, 0> {
        vector: SVector::from([0.4, -0.7]),
        rotation: [
            Retraction::Exp.map(&Vector3::new(0.7, 0.2, -0.4)),
            Retraction::Exp.map(&Vector3::new(-0.3, 1.1, 0.5)),
        ],
        direction: [],
    };
    let v = Rates::<f64, 2, 2, 0> {
        vector: SVector::from([0.3, -1.2]),
        rotation: [Vector3::new(1.5, -0.6, 2.0), Vector3::new(-0.4, 0.9, 0.2)],
        direction: [],
    };
    (q, v)
}

/// `L(R_a exp(ŵ_a), x + w_x; rates)` for a chart vector `w` (vectors first, then each
/// rotation's three), by the exponential map in `f64`.
fn along<S: DiracSystem<N, Product<K, A, 0>>, const N: usize, const K: usize, const A: usize>(
    system: &S,
    q: &Configuration<f64, K, A, 0>,
    v: &Rates<f64, K, A, 0>,
    w: &SVector<f64, N>,
) -> f64 {
    let mut moved = *q;
    for k in 0..K {
        moved.vector[k] += w[k];
    }
    for a in 0..A {
        let turn = Vector3::new(w[K + 3 * a], w[K + 3 * a + 1], w[K + 3 * a + 2]);
        moved.rotation[a] = q.rotation[a] * Retraction::Exp.map(&turn);
    }
    system.lagrangian(&moved, v)
}

/// The rates moved by `u` (a chart vector: velocities, then angular velocities).
fn rates_moved<const N: usize, const K: usize, const A: usize>(
    v: &Rates<f64, K, A, 0>,
    u: &SVector<f64, N>,
) -> Rates<f64, K, A, 0> {
    let mut moved = *v;
    for k in 0..K {
        moved.vector[k] += u[k];
    }
    for a in 0..A {
        for c in 0..3 {
            moved.rotation[a][c] += u[K + 3 * a + c];
        }
    }
    moved
}

/// The body-frame closed forms of `system` at `(q, v)` against central differences of `L`
/// along `R exp(ŵ)` and the rates, to `1e-6` of each block's size.
fn agrees<S: DiracSystem<N, Product<K, A, 0>>, const N: usize, const K: usize, const A: usize>(
    system: &S,
    q: &Configuration<f64, K, A, 0>,
    v: &Rates<f64, K, A, 0>,
) {
    let h = system
        .lagrangian_hessian(q, v)
        .expect("closed forms on rotations");
    let g = system
        .lagrangian_gradient(q, v)
        .expect("closed forms on rotations");
    assert_eq!(g, h.gradient);
    let eps = 1e-4;
    let e = |i: usize| SVector::<f64, N>::from_fn(|r, _| if r == i { eps } else { 0.0 });
    let zero = SVector::<f64, N>::zeros();
    // f(w, u): L along the body frame and the rates.
    let f = |w: &SVector<f64, N>, u: &SVector<f64, N>| along(system, q, &rates_moved(v, u), w);
    assert!((h.gradient.value - f(&zero, &zero)).abs() < 1e-14 * h.gradient.value.abs().max(1.0));
    let mut gq = SVector::<f64, N>::zeros();
    let mut gv = SVector::<f64, N>::zeros();
    let mut qq = SMatrix::<f64, N, N>::zeros();
    let (mut qv, mut vv) = (qq, qq);
    for i in 0..N {
        gq[i] = (f(&e(i), &zero) - f(&-e(i), &zero)) / (2.0 * eps);
        gv[i] = (f(&zero, &e(i)) - f(&zero, &-e(i))) / (2.0 * eps);
        for j in 0..N {
            // ∂²f along (wa, ua) and (wb, ub), by four points.
            let four = |wa: SVector<f64, N>,
                        ua: SVector<f64, N>,
                        wb: SVector<f64, N>,
                        ub: SVector<f64, N>| {
                (f(&(wa + wb), &(ua + ub)) - f(&(wa - wb), &(ua - ub)) - f(&(wb - wa), &(ub - ua))
                    + f(&(-wa - wb), &(-ua - ub)))
                    / (4.0 * eps * eps)
            };
            qq[(i, j)] = four(e(i), zero, e(j), zero);
            qv[(i, j)] = four(e(i), zero, zero, e(j));
            vv[(i, j)] = four(zero, e(i), zero, e(j));
        }
    }
    // Differences of step ε err by about ε² of the third derivatives and by round-off over ε²:
    // judged against the largest entry of the first or the second derivatives.
    let largest = |blocks: &[&[f64]]| {
        blocks
            .iter()
            .flat_map(|b| b.iter())
            .fold(0.0_f64, |m, x| m.max(x.abs()))
    };
    let first = largest(&[gq.as_slice(), gv.as_slice()]);
    let second = largest(&[qq.as_slice(), qv.as_slice(), vv.as_slice()]);
    let close = |what: &str, closed: &[f64], differenced: &[f64]| {
        let size = if what.contains('²') { second } else { first };
        for (k, (a, b)) in closed.iter().zip(differenced).enumerate() {
            assert!(
                (a - b).abs() < 1e-6 * size,
                "{what} entry {k}: {a} against {b}"
            );
        }
    };
    close("∂L/∂w", h.gradient.q.as_slice(), gq.as_slice());
    close("∂L/∂Ω", h.gradient.v.as_slice(), gv.as_slice());
    close("∂²L/∂w²", h.qq.as_slice(), qq.as_slice());
    close("∂²L/∂w∂Ω", h.qv.as_slice(), qv.as_slice());
    close("∂²L/∂Ω²", h.vv.as_slice(), vv.as_slice());
    assert_eq!(
        h.qq,
        h.qq.transpose(),
        "the body-frame ∂²L/∂w² is symmetric"
    );
}

#[test]
fn body_frame_closed_forms_are_the_derivatives_along_the_exponential() {
    let (q, v) = coupled_start();
    agrees(&COUPLED, &q, &v);
    let (r0, omega0) = rigid_body::pendulum_start();
    for top in [rigid_body::PENDULUM, rigid_body::TOP] {
        agrees(
            &top,
            &Configuration::of_rotation(r0),
            &Rates::of_rotation(omega0),
        );
    }
    let (r0, omega0) = rigid_body::free_start();
    agrees(
        &rigid_body::ASYMMETRIC,
        &Configuration::of_rotation(r0),
        &Rates::of_rotation(omega0),
    );
}

/// The heavy top written by hand without closed forms, with a sign slip in its body-frame
/// gradient.
#[derive(Debug, Clone, Copy)]
struct Slipped(HeavyTopByHand);

impl DiracSystem<3, Product<0, 1, 0>> for Slipped {
    fn lagrangian<D: Scalar>(&self, q: &Configuration<D, 0, 1, 0>, v: &Rates<D, 0, 1, 0>) -> D {
        self.0.lagrangian(q, v)
    }

    fn lagrangian_gradient(
        &self,
        q: &Configuration<f64, 0, 1, 0>,
        v: &Rates<f64, 0, 1, 0>,
    ) -> Option<LagrangianGradient<3>> {
        let mut g = self.0.0.lagrangian_gradient(q, v)?;
        g.q = -g.q;
        Some(g)
    }
}

/// The heavy top with a wrong body-frame Hessian (one entry of `∂²L/∂w²` off by 0.01).
#[derive(Debug, Clone, Copy)]
struct WrongHessian(HeavyTopByHand);

impl DiracSystem<3, Product<0, 1, 0>> for WrongHessian {
    fn lagrangian<D: Scalar>(&self, q: &Configuration<D, 0, 1, 0>, v: &Rates<D, 0, 1, 0>) -> D {
        self.0.lagrangian(q, v)
    }

    fn lagrangian_hessian(
        &self,
        q: &Configuration<f64, 0, 1, 0>,
        v: &Rates<f64, 0, 1, 0>,
    ) -> Option<LagrangianHessian<3>> {
        let mut h = self.0.0.lagrangian_hessian(q, v)?;
        h.qq[(0, 1)] += 0.01;
        h.qq[(1, 0)] += 0.01;
        Some(h)
    }
}

/// Whether a start of `model` (the 3D pendulum's) is refused for its closed forms.
fn refused_at_the_start<S: DiracSystem<3, Product<0, 1, 0>> + std::fmt::Debug>(model: S) {
    let refused = rigid_body::started(
        model,
        Product::cayley(),
        Quadrature::midpoint(),
        0.01,
        rigid_body::pendulum_start(),
    );
    assert!(
        matches!(refused, Err(DiracError::InconsistentDerivatives(_))),
        "{refused:?}"
    );
}

/// A gradient with a sign slip and a Hessian with one entry off are refused at the start.
#[test]
fn wrong_body_frame_closed_forms_are_refused_at_the_start() {
    refused_at_the_start(Slipped(HeavyTopByHand(rigid_body::PENDULUM)));
    refused_at_the_start(WrongHessian(HeavyTopByHand(rigid_body::PENDULUM)));
}

/// Steps with the generated closed forms against steps with dual numbers (the same model
/// written by hand): the same trajectory to round-off over 500 steps, for both retractions and
/// the midpoint and trapezoid. (The two round differently, and the 3D pendulum doubles a
/// difference about every 200 steps: 3e-15 after 200, 1e-12 after 1 600.)
#[test]
fn closed_forms_on_rotations_step_as_dual_numbers_do() {
    for space in [Product::cayley(), Product::exp()] {
        for quadrature in [Quadrature::midpoint(), Quadrature::trapezoid()] {
            let name = format!("{} {:?}", quadrature.name(), space.retraction());
            let start = rigid_body::pendulum_start();
            let mut closed =
                rigid_body::started(rigid_body::PENDULUM, space, quadrature.clone(), 0.01, start)
                    .unwrap();
            let mut duals = rigid_body::started(
                HeavyTopByHand(rigid_body::PENDULUM),
                space,
                quadrature,
                0.01,
                start,
            )
            .unwrap();
            let mut worst = 0.0_f64;
            for _ in 0..500 {
                closed.step().unwrap();
                duals.step().unwrap();
                let dq = (closed.q().rotation[0] - duals.q().rotation[0]).amax();
                let dp = (closed.p().rotation[0] - duals.p().rotation[0]).amax();
                worst = worst.max(dq).max(dp / closed.p().rotation[0].amax());
            }
            println!("{name}: closed forms and dual numbers {worst:.1e} apart after 500 steps");
            assert!(worst < 1e-13, "{name}: {worst:e}");
        }
    }
}

/// `Coupled` without its closed forms: the Lagrangian alone, differentiated by dual numbers.
#[derive(Debug, Clone, Copy)]
struct CoupledByDuals(Coupled);

impl DiracSystem<8, Product<2, 2, 0>> for CoupledByDuals {
    fn lagrangian<D: Scalar>(&self, q: &Configuration<D, 2, 2, 0>, v: &Rates<D, 2, 2, 0>) -> D {
        self.0.lagrangian(q, v)
    }
}

/// Vectors and two coupled rotations: steps with the generated closed forms against steps with
/// dual numbers, to round-off over 200 steps (both retractions, midpoint and trapezoid).
#[test]
fn closed_forms_on_vectors_and_rotations_step_as_dual_numbers_do() {
    let (q, v) = coupled_start();
    for space in [Product::cayley(), Product::exp()] {
        for quadrature in [Quadrature::midpoint(), Quadrature::trapezoid()] {
            let name = format!("{} {:?}", quadrature.name(), space.retraction());
            let mut closed =
                Stepper::on_manifold(COUPLED, space, quadrature.clone(), 0.01).unwrap();
            let mut duals =
                Stepper::on_manifold(CoupledByDuals(COUPLED), space, quadrature, 0.01).unwrap();
            closed.start_from_velocity(q, v).unwrap();
            duals.start_from_velocity(q, v).unwrap();
            let mut worst = 0.0_f64;
            for _ in 0..200 {
                closed.step().unwrap();
                duals.step().unwrap();
                let (a, b) = (closed.q(), duals.q());
                let positions = (a.vector - b.vector).amax().max(
                    (0..2)
                        .map(|k| (a.rotation[k] - b.rotation[k]).amax())
                        .fold(0.0, f64::max),
                );
                let (p, r) = (closed.p(), duals.p());
                let momenta = (p.vector - r.vector).amax().max(
                    (0..2)
                        .map(|k| (p.rotation[k] - r.rotation[k]).amax())
                        .fold(0.0, f64::max),
                );
                worst = worst.max(positions).max(momenta);
            }
            println!("{name}: closed forms and dual numbers {worst:.1e} apart after 200 steps");
            assert!(worst < 1e-13, "{name}: {worst:e}");
        }
    }
}
