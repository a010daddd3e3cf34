//! Lagrangians linear in the velocities, `L = ϑ(q)·v − H(q)`: the residual rows of their discrete
//! equations, which the step layer assembles.
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
//! form `ϑ'ᵀ − ϑ'` when that form is not constant: at degree 2 and 3 the error in `H` grows
//! linearly (Lotka–Volterra, h = 0.05: ×10 over T = 500).
//!
//! The second step, [`FirstOrderScheme::SymmetricProjection`](crate::FirstOrderScheme), is the
//! variational one with a symmetric projection onto `p = ϑ(q)` (Kraus's projected variational
//! integrators). The Galerkin step `p̄ + D₁L_d(q̄, ·) = 0`, `p̃ = D₂L_d` is taken from a state
//! moved off the primary constraint along its Hamiltonian direction, `(q̄, p̄) = (q_k + σ,
//! p_k + ∇ϑ(q_k)ᵀσ)`, and its end is moved back along the same direction at `q_{k+1}`, by
//! `R(∞) σ` (`R(∞) = (−1)^s` for the Gauss rule of degree `s`), with `σ` fixed by
//! `p_{k+1} = ϑ(q_{k+1})`:
//!
//! ```text
//! q_{k+1} = Q_s + R(∞) σ,    ϑ(q_{k+1}) = D₂L_d(q̄, Q_s) + R(∞) ∇ϑ(q_{k+1})ᵀσ.
//! ```
//!
//! The unknowns are the path's points and `σ` (the `N` multipliers scaled by `h/2`, which keeps
//! Newton's updates of alike size: with `λ` itself the step near the path's velocity is nearly
//! singular, `v + λ` being fixed to leading order, and Newton's contraction rose to 0.3). The
//! step is symmetric and of order `2s` in every gauge measured, and where the rule integrates
//! `ϑ·q̇` well (`ϑ` rational, or changed by the gradient of a polynomial, which the Gauss rule
//! integrates exactly along the polynomial path: the trajectories are then equal) the error in
//! `H` stays bounded with no drift over T = 500. It depends on the gauge: changed by the
//! gradient of `q2 sin q1` the error of `galerkin(2)` grows ×9 over the same run and the
//! midpoint rule's by ×22 until Newton stops contracting. Collocation is therefore the default.
//!
//! Two variational alternatives were measured and dropped (`tests/suite/first_order.rs` has the
//! figures of the kept ones):
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
//! A Lagrangian linear in some velocities and quadratic in others (`ϑ(q)·ẏ + T(q, ẋ) − H(q)`,
//! guiding-centre motion with a parallel velocity), without constraints, mixes the two kinds of
//! rows. The rows of the coordinates without kinetic energy (`∂²L/∂v∂v_d = 0`, so `∂L/∂v_d` is
//! a function of `q` alone) are collocated as above and their momenta kept on `ϑ_d(q)`; the
//! other rows stay those of the variational Galerkin step. With every row a Gauss method's, the
//! orders are `2s` (measured 2.00, 4.00, 5.89 on Lotka–Volterra coupled to an oscillator; the
//! plain variational step measured 2 for `galerkin(2)`, and the trapezoid did not converge).
//!
//! Gauss–Lobatto rules (the trapezoid among them) have one node more than the path has free
//! points, so collocating there is overdetermined, and Gauss rules with more nodes than the
//! path's degree would collocate at some of their nodes only (a θ-method of order 1 for
//! `galerkin(1, gauss_legendre(2))`): both are refused before the first step.

use nalgebra::{DMatrix, DVector, SVector};

use crate::discrete::discrete_lagrangian::DiscreteLagrangian;
use crate::model::derivatives::{Seed, degenerate, seeded};
use crate::model::system::DiracSystem;
use crate::quadrature::{Quadrature, Rule};
use crate::space::configuration_space::ConfigurationSpace;
use crate::space::manifold::Vectors;

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

/// Writes `ρ_r(Q(c_i), Q̇(c_i))` for the Gauss nodes `i = 1..s` and the coordinates `r` in
/// `rows` into row `r` of block `i` (all of them for a Lagrangian linear in every velocity; the
/// coordinates without kinetic energy of a mixed one, whose other rows are the variational
/// step's), and overwrites those rows of `jacobian` with their exact derivatives in `ξ_1..ξ_s`;
/// returns the size of the terms of `ρ`.
///
/// `∂ρ/∂q̇ = ∂²L/∂q∂v − (∂²L/∂q∂v)ᵀ`; `∂ρ_r/∂q_m = ∂²L/∂q_r∂q_m − Σ_j ∂³L/∂q_m∂q_j∂v_r q̇_j`,
/// whose last term is `(∇²ϑ_r q̇)_m` with `∇²ϑ_r = ∂²L/∂q²(q, e_r) − ∂²L/∂q²(q, 0)` (`L` is
/// linear in `v_r`, and `∂²L/∂v∂v_r = 0`).
pub(crate) fn collocation<
    S: DiracSystem<N>,
    C: ConfigurationSpace<N, Manifold = Vectors>,
    const N: usize,
>(
    discrete: &DiscreteLagrangian<S, N, C>,
    base: &SVector<f64, N>,
    increments: &[SVector<f64, N>],
    rows: &[usize],
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
        let flat = seeded(
            system,
            &q,
            &SVector::zeros(),
            Seed::POSITION,
            Seed::POSITION,
        )
        .mixed;
        let by_v = qv.mixed - qv.mixed.transpose();
        for &r in rows {
            residual[i * N + r] = qv.first[r] - transport[r];
            scale = scale.max(qv.first[r].abs()).max(transport[r].abs());
            let unit = SVector::<f64, N>::from_fn(|k, _| if k == r { 1.0 } else { 0.0 });
            let hessian = seeded(system, &q, &unit, Seed::POSITION, Seed::POSITION).mixed - flat;
            let by_q = qq.row(r) - (hessian * v).transpose();
            for k in 1..=s {
                let entries = by_q * quad.ell(i, k) + by_v.row(r) * (quad.ell_prime(i, k) / h);
                jacobian
                    .view_mut((i * N + r, (k - 1) * N), (1, N))
                    .copy_from(&entries);
            }
        }
    }
    scale
}

/// The sign `R(∞) = (−1)^s` of the Gauss rule of degree `s` with which the projection's second
/// half is applied (the rule's stability function at infinity, which keeps the projected step
/// symmetric).
fn projection_sign(quadrature: &Quadrature) -> f64 {
    if quadrature.degree().is_multiple_of(2) {
        1.0
    } else {
        -1.0
    }
}

/// The increment `q_{k+1} − q_k = ξ_s + (1 + R(∞)) σ` of the projected step whose end point,
/// read from `q̄ = q_k + σ`, is `ξ_s`.
pub(crate) fn projected_increment<const N: usize>(
    quadrature: &Quadrature,
    end: &SVector<f64, N>,
    shift: &SVector<f64, N>,
) -> SVector<f64, N> {
    end + shift * (1.0 + projection_sign(quadrature))
}

/// The rows of the variational step with a symmetric projection onto `p = ϑ(q)`
/// ([`FirstOrderScheme::SymmetricProjection`](crate::FirstOrderScheme)), from `(q_k, p_k)`
/// with `p_k = ϑ(q_k)`. The unknowns are the path's points `ξ_1..ξ_s`, read from
/// `q̄ = q_k + σ`, and the shift `σ = (h/2)λ` of the projection's multipliers `λ`:
///
/// ```text
/// p̄ + ∂L_d/∂Q_0 = 0,  ∂L_d/∂Q_j = 0 (j = 1..s−1),   p̄ = p_k + ∇ϑ(q_k)ᵀσ,
/// ϑ(q_{k+1}) = ∂L_d/∂Q_s + R(∞) ∇ϑ(q_{k+1})ᵀσ,       q_{k+1} = Q_s + R(∞) σ,
/// ```
///
/// with `Q_0 = q̄`, `Q_j = q̄ + ξ_j` and `(∇ϑᵀσ)_r = Σ_c σ_c ∂ϑ_c/∂q_r`: the state is moved off
/// the primary constraint `p − ϑ(q) = 0` and back onto it along the same Hamiltonian direction
/// `(σ, ∇ϑᵀσ)` of the constraint, in two halves. Writes the residual (rows: the `s` blocks of
/// the step, then the end point's) and its exact Jacobian into `jacobian` (zeroed by the
/// caller); returns the size of the terms summed.
///
/// `L` is linear in `v`, so `∂²L/∂v² = 0`, `∇ϑᵀ = ∂²L/∂q∂v` and
/// `Σ_c σ_c ∇²ϑ_c = ∂²L/∂q²(q, σ) − ∂²L/∂q²(q, 0)`.
pub(crate) fn symmetric_projection<
    S: DiracSystem<N>,
    C: ConfigurationSpace<N, Manifold = Vectors>,
    const N: usize,
>(
    discrete: &DiscreteLagrangian<S, N, C>,
    q: &SVector<f64, N>,
    p: &SVector<f64, N>,
    increments: &[SVector<f64, N>],
    shift: &SVector<f64, N>,
    residual: &mut DVector<f64>,
    jacobian: &mut DMatrix<f64>,
) -> f64 {
    let (quad, h, system) = (discrete.quadrature(), discrete.h(), discrete.system());
    let s = quad.degree();
    let sign = projection_sign(quad);
    let zero = SVector::<f64, N>::zeros();
    let column = s * N;
    // The first half of the projection.
    let start = seeded(system, q, &zero, Seed::POSITION, Seed::VELOCITY).mixed;
    let kick = start * shift;
    residual.as_mut_slice().fill(0.0);
    residual.rows_mut(0, N).copy_from(&(p + kick));
    let mut block = jacobian.fixed_view_mut::<N, N>(0, column);
    block += start;
    let mut magnitude = p.abs() + kick.abs();
    // The variational step from q̄: ∂L_d/∂Q_j, and the end point's momentum ∂L_d/∂Q_s.
    let base = q + shift;
    for (i, &b) in quad.weights().iter().enumerate() {
        let w = h * b;
        let (xi, v) = discrete.node(i, increments);
        let x = base + xi;
        let qv = seeded(system, &x, &v, Seed::POSITION, Seed::VELOCITY);
        let qq = seeded(system, &x, &v, Seed::POSITION, Seed::POSITION).mixed;
        let a = |j: usize| quad.ell(i, j);
        let d = |j: usize| quad.ell_prime(i, j) / h;
        for j in 0..=s {
            magnitude += (qv.first.abs() * a(j).abs() + qv.second.abs() * d(j).abs()) * w;
            // Row j holds +∂L_d/∂Q_j for j < s; the end point's row holds −∂L_d/∂Q_s.
            let (row, w) = if j < s { (j * N, w) } else { (s * N, -w) };
            let mut r = residual.rows_mut(row, N);
            r += (qv.first * a(j) + qv.second * d(j)) * w;
            for m in 1..=s {
                let mut block = jacobian.fixed_view_mut::<N, N>(row, (m - 1) * N);
                block += (qq * (a(j) * a(m))
                    + qv.mixed * (a(j) * d(m))
                    + qv.mixed.transpose() * (d(j) * a(m)))
                    * w;
            }
            // Every point moves with q̄ = q_k + σ.
            let mut block = jacobian.fixed_view_mut::<N, N>(row, column);
            block += (qq * a(j) + qv.mixed.transpose() * d(j)) * w;
        }
    }
    // The second half: ϑ(q_{k+1}) − ∂L_d/∂Q_s − R(∞) ∇ϑ(q_{k+1})ᵀσ.
    let next = base + increments[s - 1] + shift * sign;
    let at_end = seeded(system, &next, &zero, Seed::POSITION, Seed::VELOCITY);
    let (theta, turn) = (at_end.second, at_end.mixed);
    let curvature = seeded(system, &next, shift, Seed::POSITION, Seed::POSITION).mixed
        - seeded(system, &next, &zero, Seed::POSITION, Seed::POSITION).mixed;
    let kick = turn * shift * sign;
    let mut r = residual.rows_mut(s * N, N);
    r += theta - kick;
    magnitude += theta.abs() + kick.abs();
    // q_{k+1} moves with ξ_s and with (1 + R(∞))σ.
    let by_end = turn.transpose() - curvature * sign;
    let mut block = jacobian.fixed_view_mut::<N, N>(s * N, (s - 1) * N);
    block += by_end;
    let mut block = jacobian.fixed_view_mut::<N, N>(s * N, column);
    block += by_end * (1.0 + sign) - turn * sign;
    magnitude.amax()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::scalar::Scalar;

    /// Lotka–Volterra in a gauge with curvature in every entry of `∇ϑ`.
    struct Gauged;
    impl DiracSystem<2> for Gauged {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
            let theta0 = q[1].ln() / q[0] + q[1] * q[0].cos();
            let theta1 = q[0].sin();
            theta0 * v[0] + theta1 * v[1] - (q[0] + q[1] - q[0].ln() - q[1].ln() * 2.0)
        }
    }

    /// The assembled Jacobian of the projected step against central differences of its
    /// residual, for degrees 1 to 3 (odd and even `R(∞)`), away from the solution.
    #[test]
    fn the_projected_step_has_an_exact_jacobian() {
        for s in 1..=3 {
            let quadrature = Quadrature::galerkin(s).unwrap();
            let discrete = DiscreteLagrangian::new(Gauged, quadrature, 0.1);
            let q = SVector::<f64, 2>::new(2.0, 1.3);
            let p = SVector::<f64, 2>::new(0.3, -0.2);
            let n = 2 * (s + 1);
            let x = DVector::from_fn(n, |i, _| 0.05 * ((i as f64) * 1.7).sin() + 0.01);
            let residual_at = |x: &DVector<f64>| {
                let increments: Vec<SVector<f64, 2>> = (0..s)
                    .map(|j| x.fixed_rows::<2>(2 * j).into_owned())
                    .collect();
                let shift = x.fixed_rows::<2>(2 * s).into_owned();
                let mut r = DVector::zeros(n);
                let mut j = DMatrix::zeros(n, n);
                symmetric_projection(&discrete, &q, &p, &increments, &shift, &mut r, &mut j);
                (r, j)
            };
            let (_, jacobian) = residual_at(&x);
            let delta = 1e-6;
            for c in 0..n {
                let (mut up, mut down) = (x.clone(), x.clone());
                up[c] += delta;
                down[c] -= delta;
                let column = (residual_at(&up).0 - residual_at(&down).0) / (2.0 * delta);
                let error = (column - jacobian.column(c)).amax();
                assert!(error < 1e-7, "degree {s}, column {c}: {error:e}");
            }
        }
    }
}
