//! Lagrangians linear in the velocities, `L = ϑ(q)·v − H(q)`: their step equations.
//!
//! Such a Lagrangian has no kinetic energy in any coordinate (`∂²L/∂v² = 0`). Its
//! Euler–Lagrange equations are of first order, `ρ(q, q̇) = ∂L/∂q − (∂²L/∂q∂v)ᵀ q̇ =
//! (ϑ'ᵀ − ϑ') q̇ − ∇H = 0` (`ϑ'_{ij} = ∂ϑ_i/∂q_j`; `ϑ'ᵀ − ϑ'` is the symplectic form, the same in
//! every gauge `ϑ + ∇φ`), its momentum is `p = ϑ(q)` (the primary constraint), and `q` alone is
//! the state.
//!
//! The discrete Euler–Lagrange equations `p_k + D₁L_d = 0`, `p_{k+1} = D₂L_d` make a two-step
//! method of them with a parasitic second root: `p_{k+1}` leaves `ϑ(q_{k+1})` by an amount that
//! depends on the gauge of `ϑ`, the trapezoid rule can follow the parasitic mode, and Galerkin
//! rules lose order. The step keeps `p = ϑ(q)` at every node instead, and fixes the degree-s
//! path through `q_k` by collocating the first-order equations at the nodes of the Gauss rule:
//!
//! ```text
//! ρ(Q(c_i), Q̇(c_i)) = 0,   i = 1..s,        p_{k+1} = ϑ(q_{k+1}).
//! ```
//!
//! This is the Galerkin method of the action's weak form `∫ ρ·φ dt = 0` with test functions `φ`
//! of degree `s − 1`, the Gauss rule making it pointwise. It is a symmetric one-step map of `q`
//! of order `2s`, and it does not depend on the gauge: `ρ` depends on `ϑ` only through
//! `ϑ'ᵀ − ϑ'`. It is not the discrete variational principle, and it is not symplectic for the
//! form `ϑ'ᵀ − ϑ'` when that form is not constant.
//!
//! Two variational alternatives were measured and dropped (`tests/first_order.rs` has the
//! figures of the kept one):
//!
//! - Keeping the internal points' stationarity and replacing the two end-point rows by their
//!   sum with both momenta on the primary constraint, `ϑ(q_{k+1}) − ϑ(q_k) = D₁L_d + D₂L_d`.
//!   With one free point (midpoint, trapezoid) it is of order 2 in every gauge. It drifts on
//!   Lotka–Volterra, though: at h = 0.05 the midpoint's error in `H` grew from 1.3e-2 to 0.17
//!   over T = 500 and its Newton iteration stopped contracting after 3 857 steps, and the
//!   trapezoid's grew from 0.15 to 0.49. With two free points its Jacobian is singular to
//!   leading order in `h`: the quadratic bubble that tests the internal point vanishes against
//!   it at the two Gauss nodes.
//! - The plain two-step method, with the parasitic root described above.
//!
//! Gauss–Lobatto rules (the trapezoid among them) have one node more than the path has free
//! points, so collocating there is overdetermined, and Gauss rules with more nodes than the
//! path's degree would collocate at some of their nodes only (a θ-method of order 1 for
//! `galerkin(1, gauss_legendre(2))`): both are refused before the first step.

use nalgebra::{DMatrix, DVector, SVector};

use crate::configuration_space::ConfigurationSpace;
use crate::derivatives::{Seed, degenerate, seeded};
use crate::discrete_lagrangian::DiscreteLagrangian;
use crate::quadrature::{Quadrature, Rule};
use crate::system::DiracSystem;

/// Whether the Lagrangian is linear in every velocity at `(q, v)` (`∂²L/∂v² = 0`), with no
/// constraints.
pub(crate) fn is_first_order<S: DiracSystem<N>, const N: usize>(
    system: &S,
    q: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> bool {
    N > 0 && S::ONE_FORMS + S::HOLONOMIC == 0 && degenerate(system, q, v).len() == N
}

/// Why `quadrature` cannot step a Lagrangian linear in the velocities, if it cannot.
pub(crate) fn refusal(quadrature: &Quadrature) -> Option<String> {
    match quadrature.rule() {
        Rule::GaussLobatto(_) => Some(format!(
            "{} has {} nodes for {} free points of the step's path: collocating a Lagrangian \
             linear in the velocities there is overdetermined, and the variational step with \
             its end-point rows drifts (see the first_order module); use a Gauss rule \
             (midpoint, galerkin(s): order 2s)",
            quadrature.name(),
            quadrature.nodes().len(),
            quadrature.degree()
        )),
        Rule::GaussLegendre(nodes) if nodes != quadrature.degree() => Some(format!(
            "{} has {nodes} nodes for {} free points of the step's path: a Lagrangian linear \
             in the velocities is collocated at the nodes of a Gauss rule with as many nodes as \
             the path's degree (galerkin(s) with gauss_legendre(s), order 2s)",
            quadrature.name(),
            quadrature.degree()
        )),
        _ => None,
    }
}

/// Writes `ρ(Q(c_i), Q̇(c_i))` for the Gauss nodes `i = 1..s` into the row
/// blocks and its exact Jacobian in `ξ_1..ξ_s` into `jacobian` (zeroed by the caller); returns
/// the size of the terms of `ρ`.
///
/// `∂ρ/∂q̇ = ∂²L/∂q∂v − (∂²L/∂q∂v)ᵀ`; `∂ρ_i/∂q_m = ∂²L/∂q_i∂q_m − Σ_j ∂³L/∂q_m∂q_j∂v_i q̇_j`,
/// whose last term is `(∇²ϑ_i q̇)_m` with `∇²ϑ_i = ∂²L/∂q²(q, e_i) − ∂²L/∂q²(q, 0)` (`L` is
/// linear in `v`).
pub(crate) fn collocation<S: DiracSystem<N>, C: ConfigurationSpace<N>, const N: usize>(
    discrete: &DiscreteLagrangian<S, N, C>,
    base: &SVector<f64, N>,
    increments: &[SVector<f64, N>],
    residual: &mut DVector<f64>,
    jacobian: &mut DMatrix<f64>,
) -> f64 {
    let (quad, h, system) = (discrete.quadrature(), discrete.h(), discrete.system());
    let s = quad.degree();
    let mut scale = 0.0_f64;
    for i in 0..s {
        let (xi, v) = discrete.node(i, increments);
        let q = base + xi;
        let qv = seeded(system, &q, &v, Seed::POSITION, Seed::VELOCITY);
        let qq = seeded(system, &q, &v, Seed::POSITION, Seed::POSITION).mixed;
        let transport = qv.mixed.transpose() * v;
        residual
            .rows_mut(i * N, N)
            .copy_from(&(qv.first - transport));
        scale = scale.max(qv.first.amax()).max(transport.amax());
        let flat = seeded(
            system,
            &q,
            &SVector::zeros(),
            Seed::POSITION,
            Seed::POSITION,
        )
        .mixed;
        let mut by_q = qq;
        for r in 0..N {
            let unit = SVector::<f64, N>::from_fn(|k, _| if k == r { 1.0 } else { 0.0 });
            let hessian = seeded(system, &q, &unit, Seed::POSITION, Seed::POSITION).mixed - flat;
            let row = hessian * v;
            for m in 0..N {
                by_q[(r, m)] -= row[m];
            }
        }
        let by_v = qv.mixed - qv.mixed.transpose();
        for k in 1..=s {
            let block = by_q * quad.ell(i, k) + by_v * (quad.ell_prime(i, k) / h);
            jacobian
                .fixed_view_mut::<N, N>(i * N, (k - 1) * N)
                .copy_from(&block);
        }
    }
    scale
}
