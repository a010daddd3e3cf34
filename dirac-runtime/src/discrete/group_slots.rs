//! The slot derivatives of a degree-1 step on `Rᴷ × SO(3)ᴬ` by the chain rule through the
//! retraction: the Lagrangian differentiated once, at each node, in the body frame, and the
//! chart's maps in closed form, in place of dual numbers carried through the moving chart.
//!
//! On such a space the chart at `q` is `R_q(ξ) = q τ(ξ)` on each rotation (`q + ξ` on the
//! vectors). A step with one point `ξ` (midpoint, trapezoid, any degree-1 quadrature with nodes
//! `c_i` and weights `b_i`) puts node `i` at `X_i = q τ(c_i ξ)`, turning at
//! `Ω_i = dτ_{c_i ξ} ξ/h = ψ(c_i ξ) ξ/h` (`ψ = 4/(4 + |x|²)` for Cayley, `1` for exp), so
//!
//! ```text
//! L_d(q, ξ) = h Σ_i b_i L(X_i, Ω_i),
//! ∂L_d/∂ξ   = h Σ_i b_i (P_iᵀ g_i + V_iᵀ γ_i),           P_i = c_i dτ_{c_i ξ},  V_i = ∂Ω_i/∂ξ,
//! D1 L_d    = h Σ_i b_i τ(c_i ξ) g_i − (dτ^R_ξ)⁻ᵀ ∂L_d/∂ξ,   dτ^R_ξ = dτ_{−ξ},
//! ```
//!
//! with `g_i = d/dε L(X_i exp(ε ŵ))` the body-frame gradient and `γ_i = ∂L/∂Ω` at node `i`.
//! `D1 L_d` is the derivative in the first point through the moving chart (the step's end held
//! on the manifold): the first sum moves the nodes with the chart's centre, the second moves
//! the end's chart coordinates, `∂ξ/∂η = −(dτ^R_ξ)⁻¹`. On the vectors `τ(c ξ) = 1`,
//! `P_i = c_i`, `V_i = 1/h` and `dτ^R = 1`.
//!
//! The Jacobian `∂(D1 L_d)/∂ξ` is the same expression over first-order dual numbers in `ξ`:
//! the chart's maps differentiate themselves, and the gradients carry
//! `∂g_i/∂ξ = (H_ww + ½ ĝ_i) P_i + H_wΩ V_i`, `∂γ_i/∂ξ = H_Ωw P_i + H_ΩΩ V_i`, where `H` is
//! `L`'s second derivative along `X_i exp(ŵ)` and `Ω` (symmetric) and `½ ĝ_i` the bracket
//! that left-trivialised gradients pick up when the point moves
//! (`exp(ŵ) exp(εê_k) = exp(ŵ + εe_k + ½ ε w × e_k + …)`).

use nalgebra::{Const, Matrix3, SMatrix, SVector, U1, Vector3};
use num_dual::Derivative;

use crate::base::error::DiracError;
use crate::base::scalar::Scalar;
use crate::model::closed_form::{self, LagrangianGradient, LagrangianHessian};
use crate::model::derivatives::{Dual, PhaseFunction, gradients, hessian, lift};
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;
use crate::space::configuration_space::{ConfigurationSpace, GroupChart, Point, Tangent};
use crate::space::rotation::{self, Retraction};

/// `D1 L_d`, `∂L_d/∂ξ` and, where asked for, `∂(D1 L_d)/∂ξ` of one degree-1 step.
pub(crate) struct FirstSlot<const N: usize> {
    /// `D1 L_d` read in the chart at the step's start.
    pub row: SVector<f64, N>,
    /// `Σ_i |term of node i in row|`: the size of what `row` sums.
    pub magnitude: SVector<f64, N>,
    /// `∂L_d/∂ξ` in the chart at the step's start: the step's end covector.
    pub end: SVector<f64, N>,
    /// `∂(D1 L_d)/∂ξ`.
    pub jacobian: Option<SMatrix<f64, N, N>>,
}

/// The Lagrangian at `at` read along `at · τ(w)` in the body frame and at the velocity `Ω`
/// itself: `ℓ(w, Ω) = L(R_at(w), Ω)`. Its derivatives at `w = 0` are the body-frame gradient
/// and `L`'s second derivative along `at · exp(ŵ)` (both retractions are `exp` to second order).
struct AlongBody<'a, S, C: ConfigurationSpace<N>, const N: usize> {
    system: &'a S,
    space: &'a C,
    at: Point<C, N, f64>,
}

impl<S, C: ConfigurationSpace<N>, const N: usize> AlongBody<'_, S, C, N> {
    /// The rates `omega` as the model's, where `w = 0` (the closed forms are read there alone).
    fn rates_at_centre(
        &self,
        w: &SVector<f64, N>,
        omega: &SVector<f64, N>,
    ) -> Option<Tangent<C, N, f64>> {
        w.iter()
            .all(|x| *x == 0.0)
            .then(|| self.space.push_forward(&self.at, w, omega))
    }
}

impl<S: DiracSystem<N, C::Manifold>, C: ConfigurationSpace<N>, const N: usize> PhaseFunction<N>
    for AlongBody<'_, S, C, N>
{
    #[inline]
    fn value<D: Scalar>(&self, w: &SVector<D, N>, omega: &SVector<D, N>) -> D {
        let q = self.space.retract(&self.at, w);
        // At ξ = 0 the push-forward is the identity: the rates are `omega` itself.
        let zero = SVector::from_element(D::from(0.0));
        let v = self.space.push_forward(&self.at, &zero, omega);
        self.system.lagrangian(&q, &v)
    }

    /// The model's body-frame closed forms ([`body_frame`](crate::model::body_frame)), read at
    /// `w = 0` only.
    #[inline]
    fn closed_gradient(
        &self,
        w: &SVector<f64, N>,
        omega: &SVector<f64, N>,
    ) -> Option<LagrangianGradient<N>> {
        self.system
            .lagrangian_gradient(&self.at, &self.rates_at_centre(w, omega)?)
    }

    #[inline]
    fn closed_hessian(
        &self,
        w: &SVector<f64, N>,
        omega: &SVector<f64, N>,
    ) -> Option<LagrangianHessian<N>> {
        self.system
            .lagrangian_hessian(&self.at, &self.rates_at_centre(w, omega)?)
    }
}

/// The model's body-frame closed forms against dual numbers at `(q, v)` (see
/// [`closed_form::check`](crate::model::closed_form::check)).
pub(crate) fn check_closed_forms<S, C, const N: usize>(
    system: &S,
    space: &C,
    q: &Point<C, N, f64>,
    v: &Tangent<C, N, f64>,
) -> Result<(), DiracError>
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    let zero = SVector::zeros();
    let Some(omega) = space.chart_velocity(q, v) else {
        return Ok(());
    };
    let along = AlongBody {
        system,
        space,
        at: *q,
    };
    let at = format!("q = {q:?}, v = {v:?}");
    closed_form::check_function(&along, &zero, &omega, &at)
}

/// The chart's maps at node `c ξ` of a rotation's chart coordinates `ξ`, over any scalar:
/// `τ(c ξ)`, `P = c dτ_{c ξ}` and `Vᵀ γ` for `V = ∂Ω/∂ξ`, `Ω = d ψ(c ξ) ξ` (`d = 1/h`, or the
/// node's `ℓ'`).
struct NodeMaps<D> {
    tau: Matrix3<D>,
    p: Matrix3<D>,
    psi: D,
    /// `κ` in `∇ψ(x) = κ x`.
    kappa: D,
}

impl<D: Scalar> NodeMaps<D> {
    fn new(retraction: Retraction, c: f64, xi: &Vector3<D>) -> Self {
        let x = xi * D::from(c);
        let (psi, kappa) = retraction.rate_factor(&x);
        Self {
            tau: retraction.map(&x),
            p: retraction.differential(&x) * D::from(c),
            psi,
            kappa,
        }
    }

    /// `Ω = d ψ ξ`.
    fn omega(&self, d: f64, xi: &Vector3<D>) -> Vector3<D> {
        xi * (self.psi * d)
    }

    /// `Vᵀ γ = d (ψ γ + c² κ (ξ·γ) ξ)`: `V = d (ψ I + c² κ ξ ξᵀ)` is symmetric.
    fn v_transpose(&self, c: f64, d: f64, xi: &Vector3<D>, gamma: &Vector3<D>) -> Vector3<D> {
        (gamma * self.psi + xi * (self.kappa * (c * c) * xi.dot(gamma))) * D::from(d)
    }
}

fn rows3<D: Scalar, const N: usize>(x: &SVector<D, N>, at: usize) -> Vector3<D> {
    Vector3::new(x[at], x[at + 1], x[at + 2])
}

/// One node's terms of `D1 L_d` before the end's chart moves (`h b τ(c ξ) g`) and of
/// `∂L_d/∂ξ` (`h b (Pᵀ g + Vᵀ γ)`), over any scalar.
#[allow(clippy::too_many_arguments)]
fn node_terms<D: Scalar, const N: usize>(
    chart: GroupChart,
    c: f64,
    d: f64,
    weight: f64,
    xi: &SVector<D, N>,
    g: &SVector<D, N>,
    gamma: &SVector<D, N>,
) -> (SVector<D, N>, SVector<D, N>) {
    let mut moved = SVector::from_element(D::from(0.0));
    let mut end = moved;
    for k in 0..chart.reals {
        moved[k] = g[k] * weight;
        end[k] = (g[k] * c + gamma[k] * d) * weight;
    }
    for a in 0..chart.rotations {
        let at = chart.reals + 3 * a;
        let x = rows3(xi, at);
        let maps = NodeMaps::new(chart.retraction, c, &x);
        let (g, gamma) = (rows3(g, at), rows3(gamma, at));
        let m = rotation::apply(&maps.tau, &g) * D::from(weight);
        let e = (rotation::apply(&maps.p.transpose(), &g) + maps.v_transpose(c, d, &x, &gamma))
            * D::from(weight);
        for r in 0..3 {
            moved[at + r] = m[r];
            end[at + r] = e[r];
        }
    }
    (moved, end)
}

/// `(dτ^R_ξ)⁻ᵀ y = τ(ξ) dτ_ξ⁻ᵀ y` block by block (`y` on the vectors), with its derivative
/// in `ξ` where `xi` carries one: the value as the step's end momentum reads it
/// ([`Retraction::body_momentum`]), the derivative by the closed form `dτ_ξ⁻¹` over dual numbers.
fn end_chart_moved<D: Scalar, const N: usize>(
    chart: GroupChart,
    xi: &SVector<D, N>,
    y: &SVector<D, N>,
) -> SVector<D, N> {
    let mut out = *y;
    for a in 0..chart.rotations {
        let at = chart.reals + 3 * a;
        let (x, y) = (rows3(xi, at), rows3(y, at));
        let tau = chart.retraction.map(&x);
        let inverse = chart.retraction.differential_inverse(&x);
        let mut z = rotation::apply(&tau, &rotation::apply(&inverse.transpose(), &y));
        let re = |v: &Vector3<D>| v.map(|c| c.re());
        if let Some(body) = chart.retraction.body_momentum(&re(&x), &re(&y)) {
            let value = tau.map(|c| c.re()) * body;
            for r in 0..3 {
                z[r] = z[r] - z[r].re() + value[r];
            }
        }
        for r in 0..3 {
            out[at + r] = z[r];
        }
    }
    out
}

/// `P` and `V` of node `c` as `N × N` block-diagonal matrices (`f64`).
fn node_jacobians<const N: usize>(
    chart: GroupChart,
    c: f64,
    d: f64,
    xi: &SVector<f64, N>,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
    let mut p = SMatrix::<f64, N, N>::zeros();
    let mut v = SMatrix::<f64, N, N>::zeros();
    for k in 0..chart.reals {
        p[(k, k)] = c;
        v[(k, k)] = d;
    }
    for a in 0..chart.rotations {
        let at = chart.reals + 3 * a;
        let x = rows3(xi, at);
        let maps = NodeMaps::new(chart.retraction, c, &x);
        p.fixed_view_mut::<3, 3>(at, at).copy_from(&maps.p);
        let block = (Matrix3::identity() * maps.psi + x * x.transpose() * (maps.kappa * c * c)) * d;
        v.fixed_view_mut::<3, 3>(at, at).copy_from(&block);
    }
    (p, v)
}

/// `½ ĝ` on each rotation's block, zero on the vectors.
fn bracket<const N: usize>(chart: GroupChart, g: &SVector<f64, N>) -> SMatrix<f64, N, N> {
    let mut out = SMatrix::<f64, N, N>::zeros();
    for a in 0..chart.rotations {
        let at = chart.reals + 3 * a;
        out.fixed_view_mut::<3, 3>(at, at)
            .copy_from(&(rotation::hat(&rows3(g, at)) * 0.5));
    }
    out
}

/// [`FirstSlot`] of the step from `base` to `R_base(ξ)` under the degree-1 `quadrature` (see
/// the [module](self)).
#[allow(clippy::too_many_arguments)]
pub(crate) fn first_slot<S, C, const N: usize>(
    system: &S,
    space: &C,
    chart: GroupChart,
    base: &Point<C, N, f64>,
    quadrature: &Quadrature,
    h: f64,
    xi: &SVector<f64, N>,
    with_jacobian: bool,
) -> FirstSlot<N>
where
    S: DiracSystem<N, C::Manifold>,
    C: ConfigurationSpace<N>,
{
    debug_assert_eq!(quadrature.degree(), 1);
    let mut moved = SVector::<f64, N>::zeros();
    let mut end = SVector::<f64, N>::zeros();
    let mut magnitude = SVector::<f64, N>::zeros();
    let mut jacobian = with_jacobian.then(SMatrix::<f64, N, N>::zeros);
    let seeded = lift(xi, 1.0);
    for (i, &b) in quadrature.weights().iter().enumerate() {
        let (c, d) = (quadrature.ell(i, 1), quadrature.ell_prime(i, 1) / h);
        let weight = h * b;
        let at = space.retract(base, &(xi * c));
        let mut omega = SVector::<f64, N>::zeros();
        for k in 0..chart.reals {
            omega[k] = xi[k] * d;
        }
        for a in 0..chart.rotations {
            let at = chart.reals + 3 * a;
            let x = rows3(xi, at);
            let w = NodeMaps::new(chart.retraction, c, &x).omega(d, &x);
            omega.fixed_rows_mut::<3>(at).copy_from(&w);
        }
        let body = AlongBody { system, space, at };
        let zero = SVector::zeros();
        match jacobian.as_mut() {
            None => {
                let (g, gamma) = gradients(&body, &zero, &omega);
                let (m, e) = node_terms(chart, c, d, weight, xi, &g, &gamma);
                let term = m - end_chart_moved(chart, xi, &e);
                moved += m;
                end += e;
                magnitude += term.abs();
            }
            Some(jacobian) => {
                let l = hessian(&body, &zero, &omega);
                let (g, gamma) = (l.gradient.q, l.gradient.v);
                let (p, v) = node_jacobians(chart, c, d, xi);
                let dg = (l.qq + bracket(chart, &g)) * p + l.qv * v;
                let dgamma = l.qv.transpose() * p + l.vv * v;
                let dual = |x: &SVector<f64, N>, dx: &SMatrix<f64, N, N>| {
                    SVector::<Dual<N>, N>::from_fn(|r, _| {
                        Dual::<N>::new(x[r], Derivative::some(dx.row(r).transpose()))
                    })
                };
                let (m, e) = node_terms(
                    chart,
                    c,
                    d,
                    weight,
                    &seeded,
                    &dual(&g, &dg),
                    &dual(&gamma, &dgamma),
                );
                let term = m - end_chart_moved(chart, &seeded, &e);
                for r in 0..N {
                    let row = term[r].eps.unwrap_generic(Const::<N>, U1);
                    let mut target = jacobian.row_mut(r);
                    target += row.transpose();
                }
                let (m, e, term) = (m.map(|x| x.re), e.map(|x| x.re), term.map(|x| x.re));
                moved += m;
                end += e;
                magnitude += term.abs();
            }
        }
    }
    FirstSlot {
        row: moved - end_chart_moved(chart, xi, &end),
        magnitude,
        end,
        jacobian,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::derivatives::moving_row;
    use crate::quadrature::Rule;
    use crate::space::manifold::Manifold;
    use crate::space::product::{Configuration, Product, Rates};

    /// Two bodies and a slider whose terms couple them in position and velocity, with a
    /// potential that is not linear in the attitudes.
    struct Coupled;
    impl DiracSystem<7, Product<1, 2, 0>> for Coupled {
        fn lagrangian<D: Scalar>(&self, q: &Configuration<D, 1, 2, 0>, v: &Rates<D, 1, 2, 0>) -> D {
            let (x, r, s) = (q.vector[0], q.rotation[0], q.rotation[1]);
            let (u, w, z) = (v.vector[0], v.rotation[0], v.rotation[1]);
            let kinetic = u * u * 0.5
                + (w[0] * w[0] + w[1] * w[1] * 2.0 + w[2] * w[2] * 3.0) * 0.5
                + (z[0] * z[0] * 1.5 + z[1] * z[1] + z[2] * z[2] * 0.7) * 0.5;
            let axes = r[(0, 2)] * s[(0, 1)] + r[(1, 2)] * s[(1, 1)] + r[(2, 2)] * s[(2, 1)];
            kinetic + w[0] * u * 0.3 + z[2] * w[1] * 0.2 + axes * axes * (x + 1.5)
                - r[(2, 2)] * r[(0, 1)]
                - x * x * 0.4
        }
    }

    /// The chain rule against dual numbers through the moving chart (`moving_row`, itself
    /// checked against differences of `L_d`): the same row, end covector and Jacobian to
    /// round-off, for both retractions and degree-1 quadratures, at a step turning by up to
    /// 0.6 rad.
    #[test]
    fn the_chain_rule_meets_the_moving_chart() {
        let gauss = Quadrature::galerkin_with_rule(1, Rule::GaussLegendre(3)).expect("valid");
        for quadrature in [Quadrature::midpoint(), Quadrature::trapezoid(), gauss] {
            for space in [Product::<1, 2, 0>::cayley(), Product::exp()] {
                let name = format!("{} {:?}", quadrature.name(), space.retraction());
                let chart = ConfigurationSpace::<7>::group_chart(&space).expect("no unit vectors");
                let base = space.retract(
                    &<Product<1, 2, 0> as Manifold<7>>::origin(),
                    &SVector::<f64, 7>::from_column_slice(&[0.2, 0.3, -0.5, 0.8, -0.7, 0.1, 0.4]),
                );
                let h = 0.1;
                for scale in [0.01, 1.0, 4.0] {
                    let xi = SVector::<f64, 7>::from_column_slice(&[
                        0.07, 0.05, -0.03, 0.09, 0.04, 0.06, -0.12,
                    ]) * scale;
                    let fast =
                        first_slot(&Coupled, &space, chart, &base, &quadrature, h, &xi, true);
                    let dual = moving_row(&Coupled, &space, &base, &quadrature, h, &[xi], true);
                    let size = dual.magnitude.amax();
                    assert!(
                        (fast.row - dual.row).amax() < 1e-14 * size,
                        "{name} {scale}: {} vs {}",
                        fast.row,
                        dual.row
                    );
                    assert!(
                        (fast.end - dual.slots[0]).amax() < 1e-14 * size,
                        "{name} {scale}"
                    );
                    let jacobian = fast.jacobian.expect("asked for");
                    let blocks = dual.blocks[0];
                    assert!(
                        (jacobian - blocks).amax() < 1e-13 * blocks.amax(),
                        "{name} {scale}: {jacobian} vs {blocks}"
                    );
                    let alone =
                        first_slot(&Coupled, &space, chart, &base, &quadrature, h, &xi, false);
                    assert!(
                        (alone.row - fast.row).amax() < 1e-15 * size,
                        "{name} {scale}"
                    );
                    assert!(
                        (alone.end - fast.end).amax() < 1e-15 * size,
                        "{name} {scale}"
                    );
                }
            }
        }
    }
}
