//! The discrete Lagrangian `L_d(Q_0, …, Q_s)` of a system under a quadrature, and its slot
//! derivatives and second derivatives by hyper-dual numbers.
//!
//! A step from `q_k` works in the chart centred at `q_k` (see
//! [`configuration_space`](crate::space::configuration_space)): the points are `Q_j = R_{q_k}(ξ_j)`
//! with `ξ_0 = 0`. With chart nodes `ξ(c_i) = Σ_j ℓ_j(c_i) ξ_j` and chart velocities
//! `ξ̇(c_i) = (1/h) Σ_j ℓ'_j(c_i) ξ_j`, `L_d = h Σ_i b_i ℓ(ξ(c_i), ξ̇(c_i))` where
//! `ℓ(ξ, ξ̇) = L(R_{q_k}(ξ), T_ξR_{q_k} ξ̇)`. Its derivative in the point `ξ_j` is
//! `h Σ_i b_i [ℓ_j(c_i) ∂_ξ ℓ + (ℓ'_j(c_i)/h) ∂_ξ̇ ℓ]`, and its second derivatives follow by the
//! chain rule from the Hessian of `ℓ` at the nodes. On `Rⁿ`, `ℓ = L` at `q_k + ξ`. Every
//! derivative comes from one evaluation of the user's Lagrangian over
//! [`num_dual::HyperDualSVec64`] (the `derivatives` module): seeding the two dual directions
//! along `(α_x, β_x)` and `(α_y, β_y)` in `(ξ, ξ̇)` yields both gradients along those directions
//! and the mixed second derivative in one pass.

use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector3};

use crate::base::error::DiracError;
use crate::base::float::rounded_sum;
use crate::discrete::group_slots;
use crate::discrete::state::State;
use crate::model::closed_form::{HessianZeros, LagrangianGradient, LagrangianHessian};
use crate::model::derivatives::{
    InChart, PhaseFunction, Seed, directional_gradient, gradient, gradients, hessian, lift,
    moving_row, seeded, third_derivative,
};
use crate::model::system::DiracSystem;
use crate::quadrature::{MAX_DEGREE, Quadrature, path_sums};
use crate::space::configuration_space::{
    ConfigurationSpace, Euclidean, Point, StepCovectors, Tangent,
};
use crate::space::manifold::Vectors;

/// The discrete Lagrangian of `system` under `quadrature` with step `h`, on the configuration
/// space `C` (`Rⁿ` unless given).
///
/// ```
/// use dirac_runtime::{DiracSystem, DiscreteLagrangian, Quadrature, Scalar};
/// use nalgebra::{SVector, vector};
/// struct Free;
/// impl DiracSystem<1> for Free {
///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 0.5
///     }
/// }
/// // A free particle: L_d = (q1 − q0)² / (2h) for every quadrature.
/// let ld = DiscreteLagrangian::new(Free, Quadrature::trapezoid(), 0.5);
/// assert!((ld.value(&[vector![1.0], vector![2.0]])? - 1.0).abs() < 1e-15);
/// assert!(ld.value(&[vector![1.0]]).is_err()); // a step has degree + 1 points
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct DiscreteLagrangian<S, const N: usize, C = Euclidean> {
    system: S,
    space: C,
    quadrature: Quadrature,
    h: f64,
    /// The quadrature's nodes with their weights, read once for every step.
    nodes: Vec<NodeWeights>,
}

/// Node `i` of a step of degree `s`: its weight `w = h b_i`, the path's basis
/// `a[j] = ℓ_j(c_i)` and its rates `d[j] = ℓ'_j(c_i)/h` (`j = 0..=s`; zero beyond), where with
/// internal points row 0's `a[0]` and `d[0]` are `1 − Σ_{j≥1} a[j]` and `−Σ_{j≥1} d[j]` (see
/// `DiscreteLagrangian::on_space`).
#[derive(Debug, Clone, Copy)]
struct NodeWeights {
    w: f64,
    a: [f64; MAX_DEGREE + 1],
    d: [f64; MAX_DEGREE + 1],
    /// No zero among `a[0], a[1], d[0], d[1]`: a degree-1 step's seeds take plain products.
    pair_without_zeros: bool,
    /// With internal points, what rounding left of row 0's weights `a[0] = 1 − Σ_{j≥1} a[j]`
    /// and `d[0] = −Σ_{j≥1} d[j]`; zero for a degree-1 step. The midpoint and trapezoidal
    /// rules' weights are exact; a degree-1 step on several Gauss nodes keeps the basis at
    /// point 0, a few ulps off (its round-off is not measured for drift).
    a0_rest: f64,
    d0_rest: f64,
}

impl NodeWeights {
    /// The weight, basis and rates of a degree-1 step's two points at this node.
    #[inline(always)]
    fn pair(&self) -> (f64, [f64; 2], [f64; 2]) {
        (self.w, [self.a[0], self.a[1]], [self.d[0], self.d[1]])
    }

    /// The path through `0, increments[0], …, increments[s−1]` at this node and its rate (the
    /// numbers of [`Quadrature::path_at`], read from the table).
    #[inline(always)]
    fn path<const N: usize>(
        &self,
        increments: &[SVector<f64, N>],
    ) -> (SVector<f64, N>, SVector<f64, N>) {
        // Points 1..=s: the sums stop with the increments.
        path_sums(
            increments,
            self.a[1..].iter().copied(),
            self.d[1..].iter().copied(),
        )
    }
}

/// The sums of the general assembly over a step's nodes: the rows `∂L_d/∂ξ_j` (`j < s`), the
/// slot covectors' terms, the size of the terms, and whether the gradient came in closed form.
struct NodeSums<const N: usize> {
    rows: [SVector<f64, N>; MAX_DEGREE],
    impulse: SVector<f64, N>,
    end: SVector<f64, N>,
    magnitude: SVector<f64, N>,
    closed_gradient: bool,
}

/// The sums of a degree-1 step assembled from the Lagrangian's closed forms (see
/// [`DiscreteLagrangian::pair_in_closed_form`]), node by node: rows `0..N` of the residual, the
/// slot covectors and the size of the terms (the Jacobian's block, where one is asked for, is
/// added with them).
struct PairSums<'a, const N: usize> {
    row: &'a mut SVector<f64, N>,
    impulse: &'a mut SVector<f64, N>,
    end: &'a mut SVector<f64, N>,
    magnitude: &'a mut SVector<f64, N>,
}

impl<const N: usize> PairSums<'_, N> {
    /// Adds the node of weight `w`, basis `a` and rates `d` from `L`'s closed-form gradient
    /// there (no Jacobian).
    #[inline(always)]
    fn add_gradient(
        &mut self,
        g: &LagrangianGradient<N>,
        (w, [a0, a1], [d0, d1]): (f64, [f64; 2], [f64; 2]),
    ) {
        for i in 0..N {
            let first = g.q[i] * a0 + g.v[i] * d0;
            self.row[i] += first * w;
            self.impulse[i] += g.q[i] * w;
            self.end[i] += (g.q[i] * a1 + g.v[i] * d1) * w;
            self.magnitude[i] += first.abs() * w;
        }
    }

    /// Adds the node from `L`'s closed-form Hessian there, each product by `times`, and its
    /// part of the block of `ξ` to `block` (by columns of `stride`): `Σ` of the Hessian's
    /// blocks' entries by the products of the seeds `(a_0, d_0)` and `(a_1, d_1)`, the entries
    /// `zeros` says vanish left out.
    #[inline(always)]
    fn add_hessian(
        &mut self,
        hessian: &LagrangianHessian<N>,
        zeros: HessianZeros<N>,
        (w, [a0, a1], [d0, d1]): (f64, [f64; 2], [f64; 2]),
        block: &mut [f64],
        stride: usize,
        times: impl Fn(f64, f64) -> f64,
    ) {
        let g = &hessian.gradient;
        let c = [a0 * a1, a0 * d1, d0 * a1, d0 * d1];
        for j in 0..N {
            for i in 0..N {
                if zeros != HessianZeros::NONE && zeros.vanishes(i, j) {
                    continue;
                }
                let terms = [
                    (zeros.qq[i][j], hessian.qq[(i, j)], c[0]),
                    (zeros.qv[i][j], hessian.qv[(i, j)], c[1]),
                    (zeros.qv[j][i], hessian.qv[(j, i)], c[2]),
                    (zeros.vv[i][j], hessian.vv[(i, j)], c[3]),
                ];
                let mut entry: Option<f64> = None;
                for (zero, x, c) in terms {
                    if !zero {
                        let term = times(x, c);
                        entry = Some(entry.map_or(term, |e| e + term));
                    }
                }
                block[j * stride + i] += entry.unwrap_or(0.0) * w;
            }
        }
        for i in 0..N {
            let first = times(g.q[i], a0) + times(g.v[i], d0);
            let second = times(g.q[i], a1) + times(g.v[i], d1);
            self.row[i] += first * w;
            self.impulse[i] += (first + second) * w;
            self.end[i] += second * w;
            self.magnitude[i] += first.abs() * w;
        }
    }
}

impl<S: DiracSystem<N>, const N: usize> DiscreteLagrangian<S, N> {
    /// `L_d` for step `h` on `Rⁿ`.
    pub fn new(system: S, quadrature: Quadrature, h: f64) -> Self {
        Self::on_space(system, Euclidean, quadrature, h)
    }
}

impl<S: DiracSystem<N, C::Manifold>, C: ConfigurationSpace<N>, const N: usize>
    DiscreteLagrangian<S, N, C>
{
    /// `L_d` for step `h`, with the step's points `R_{q_k}(ξ_j)` in `space`.
    pub fn on_space(system: S, space: C, quadrature: Quadrature, h: f64) -> Self {
        let s = quadrature.degree();
        let nodes = (0..quadrature.weights().len())
            .map(|i| {
                let mut node = NodeWeights {
                    w: h * quadrature.weights()[i],
                    a: [0.0; MAX_DEGREE + 1],
                    d: [0.0; MAX_DEGREE + 1],
                    pair_without_zeros: false,
                    a0_rest: 0.0,
                    d0_rest: 0.0,
                };
                for j in 0..=s {
                    node.a[j] = quadrature.ell(i, j);
                    node.d[j] = quadrature.ell_prime(i, j) / h;
                }
                if s > 1 {
                    // The path in the chart at `q_k` is `q_k + Σ_{j≥1} a_j ξ_j`: its derivative
                    // in `q_k` weighs the node by `1 − Σ_{j≥1} a_j` and `−Σ_{j≥1} d_j`, not by
                    // the basis at point 0 evaluated apart (a few ulps off them). Row 0 takes
                    // those weights, rounded, and what rounding left of them: the step is then
                    // the flow of the discrete Lagrangian it evaluates.
                    (node.a[0], node.a0_rest) = rounded_sum(1.0, node.a[1..=s].iter().map(|a| -a));
                    (node.d[0], node.d0_rest) = rounded_sum(0.0, node.d[1..=s].iter().map(|d| -d));
                }
                node.pair_without_zeros =
                    ![node.a[0], node.a[1], node.d[0], node.d[1]].contains(&0.0);
                node
            })
            .collect();
        Self {
            system,
            space,
            quadrature,
            h,
            nodes,
        }
    }

    /// Fails on a non-positive or non-finite step or a non-finite parameter.
    pub(crate) fn check(&self) -> Result<(), DiracError> {
        let h = self.h;
        if !(h > 0.0 && h.is_finite()) {
            return Err(DiracError::InvalidStep { h });
        }
        match self
            .system
            .parameters()
            .into_iter()
            .find(|(_, v)| !v.is_finite())
        {
            Some((name, value)) => Err(DiracError::NonFinite {
                what: format!("parameter {name}"),
                value,
            }),
            None => Ok(()),
        }
    }

    /// The state after a step from `state` to `R_{q_k}(ξ)`: the position advanced through the
    /// chart, the momentum from the step's `covectors` (to which the discrete Lagrangian's own are
    /// added here when the residual left them `pending`), the velocity not yet set. `step`
    /// counts the steps before, for the error where the chart's tangent map is singular.
    ///
    /// `conservative`: the step's action is the discrete Lagrangian alone (no forces,
    /// constraints or junction impulses). Each unit vector's angular momentum then advances by
    /// the step's torque ([`torque`](Self::torque),
    /// [`advance_momentum_turned`](ConfigurationSpace::advance_momentum_turned)), so that a
    /// rotation the Lagrangian is invariant under keeps its momentum map to round-off.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn advanced(
        &self,
        state: &State<N, C::Manifold>,
        xi: &SVector<f64, N>,
        increments: &[SVector<f64, N>],
        mut covectors: StepCovectors<N>,
        pending: bool,
        conservative: bool,
        step: u64,
    ) -> Result<State<N, C::Manifold>, DiracError> {
        let turned = conservative && self.space.unit_vectors() > 0;
        // Where every factor is a unit vector, the torques alone advance the momentum.
        if pending && !(turned && 2 * self.space.unit_vectors() == N) {
            covectors += self.slot_covectors(&state.q, increments);
        }
        let mut next = *state;
        self.space.advance(&mut next.q, &mut next.q_carry, xi);
        let advanced = if turned {
            self.space.advance_momentum_turned(
                &state.q,
                xi,
                &next.q,
                &mut next.p,
                &mut next.p_carry,
                &mut next.q_carry,
                &covectors,
                |b| self.torque(&state.q, increments, b),
            )
        } else {
            self.space
                .advance_momentum(&state.q, xi, &mut next.p, &mut next.p_carry, &covectors)
        };
        advanced.ok_or_else(|| {
            DiracError::OutsideChart(format!(
                "step {step} reaches a point where the retraction's tangent map is singular"
            ))
        })?;
        Ok(next)
    }

    /// The torque of the step with points `ξ_1..ξ_s` (chart at `base`) on unit vector `b`:
    /// `T = ∂/∂ω h Σ_i b_i L(X_i + ω × X_i, Ẋ_i + ω × Ẋ_i)` at `ω = 0`, which is
    /// `h Σ_i b_i (X_i × ∂L/∂X + Ẋ_i × ∂L/∂Ẋ)` on the nodes' points and velocities.
    pub(crate) fn torque(
        &self,
        base: &Point<C, N, f64>,
        increments: &[SVector<f64, N>],
        b: usize,
    ) -> Vector3<f64> {
        let omega = lift(&Vector3::zeros(), 1.0);
        let mut torque = Vector3::zeros();
        for (i, &weight) in self.quadrature.weights().iter().enumerate() {
            let (xi, xi_dot) = self.node(i, increments);
            let x = self.space.retract(base, &xi);
            let v = self.space.push_forward(base, &xi, &xi_dot);
            if let Some((x, v)) = self.space.turned(&x, &v, b, &omega) {
                torque += gradient(&self.system.lagrangian(&x, &v)) * (self.h * weight);
            }
        }
        torque
    }

    /// Refuses the end of step `step` where `L(q, v)` is not finite. The quadrature may never
    /// evaluate `L` at `q_{k+1}` (the midpoint rule does not): a step that leaves the
    /// Lagrangian's domain is refused here, not found later as NaN energies. A Lagrangian
    /// finite at every finite state ([`DiracSystem::LAGRANGIAN_ENTIRE`]) has no domain to
    /// leave, and the stepper has already refused a position or momentum that is not finite.
    pub(crate) fn check_end(
        &self,
        q: &Point<C, N, f64>,
        v: &Tangent<C, N, f64>,
        step: u64,
    ) -> Result<(), DiracError> {
        if S::LAGRANGIAN_ENTIRE {
            return Ok(());
        }
        let lagrangian = self.system.lagrangian(q, v);
        if lagrangian.is_finite() {
            return Ok(());
        }
        Err(DiracError::NonFinite {
            what: format!(
                "the Lagrangian at the end of step {step} (the step leaves its domain or \
                 overflows; try a smaller step)"
            ),
            value: lagrangian,
        })
    }

    /// The continuous system.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// The configuration space.
    pub fn space(&self) -> &C {
        &self.space
    }

    /// The quadrature.
    pub fn quadrature(&self) -> &Quadrature {
        &self.quadrature
    }

    /// The step size.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// The Lagrangian read in the chart centred at `base`.
    pub(crate) fn in_chart<'a>(&'a self, base: &'a Point<C, N, f64>) -> InChart<'a, S, C, N> {
        InChart {
            system: &self.system,
            space: &self.space,
            base,
        }
    }

    /// Chart position and velocity at node `i` of the path with points `ξ_j` (`j = 1..=s`,
    /// `ξ_0 = 0`). The velocity is summed from the chart increments, so it carries no
    /// cancellation of the large `q_k` terms.
    pub(crate) fn node(
        &self,
        i: usize,
        increments: &[SVector<f64, N>],
    ) -> (SVector<f64, N>, SVector<f64, N>) {
        self.nodes[i].path(increments)
    }

    /// How node `i`'s position and velocity move when the step's points `0..=s` move by
    /// `points[m]`: `(Σ_m ℓ_m(c_i) points[m], Σ_m ℓ'_m(c_i) points[m] / h)`.
    pub(crate) fn node_displacement(
        &self,
        i: usize,
        points: &[SVector<f64, N>],
    ) -> (SVector<f64, N>, SVector<f64, N>) {
        let mut dq = SVector::zeros();
        let mut dv = SVector::zeros();
        for (m, point) in points.iter().enumerate() {
            dq += point * self.quadrature.ell(i, m);
            dv += point * (self.quadrature.ell_prime(i, m) / self.h);
        }
        (dq, dv)
    }

    /// `L_d(Q_0, …, Q_s)`; `points` holds the `s + 1` points of the step (an error otherwise, or
    /// when a point lies outside the chart centred at `Q_0`).
    pub fn value(&self, points: &[Point<C, N, f64>]) -> Result<f64, DiracError> {
        if points.len() != self.quadrature.degree() + 1 {
            return Err(DiracError::Dimension(format!(
                "L_d under {} takes {} points, got {}",
                self.quadrature.name(),
                self.quadrature.degree() + 1,
                points.len()
            )));
        }
        let increments = points[1..]
            .iter()
            .map(|q| self.space.local(&points[0], q))
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| {
                DiracError::OutsideChart("a point of the step lies outside the chart at Q_0".into())
            })?;
        let chart = self.in_chart(&points[0]);
        Ok((0..self.quadrature.nodes().len())
            .map(|i| {
                let (xi, xi_dot) = self.node(i, &increments);
                self.h * self.quadrature.weights()[i] * chart.value(&xi, &xi_dot)
            })
            .sum())
    }

    /// The discrete Euler–Lagrange rows of one step.
    ///
    /// The points are `Q_0 = base` and `Q_j = R_base(ξ_j)`; the unknowns are `ξ_1, …, ξ_s`
    /// (`Q_s = q_{k+1}`), blocks of `N`. Writes the residual
    /// `[π_k + ∂L_d/∂ξ_0; ∂L_d/∂ξ_1; …; ∂L_d/∂ξ_{s−1}]` (`π_k` the momentum in the chart) into
    /// the first `N s` rows (the rows after them zeroed) and, when asked for, adds its Jacobian
    /// into `jacobian` (which the caller zeroes). Without a Jacobian only first derivatives of
    /// `L` are taken, and with one pair of slots and more than two coordinates only those the
    /// residual needs: the slot covectors are then left to
    /// [`slot_covectors`](Self::slot_covectors) (`None`). Returns the slot covectors and the
    /// size of the terms summed into the residual.
    pub(crate) fn euler_lagrange(
        &self,
        base: &Point<C, N, f64>,
        increments: &[SVector<f64, N>],
        momentum: &SVector<f64, N>,
        residual: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
    ) -> (Option<StepCovectors<N>>, f64) {
        if !C::AFFINE {
            return self.euler_lagrange_moving(base, increments, momentum, residual, jacobian);
        }
        let s = self.quadrature.degree();
        if s == 1
            && let Some((covectors, magnitude)) = self.pair_in_closed_form(
                base,
                &increments[0],
                momentum,
                residual.as_mut_slice(),
                jacobian.as_deref_mut().map(|j| j.as_mut_slice()),
                false,
            )
        {
            residual.as_mut_slice()[N..].fill(0.0);
            return (Some(covectors), magnitude);
        }
        // The rows ∂L_d/∂ξ_j (j < s), summed on the stack and written once.
        let mut rows = [SVector::<f64, N>::zeros(); MAX_DEGREE];
        rows[0] = *momentum;
        let mut sums = NodeSums {
            rows,
            impulse: SVector::zeros(),
            end: SVector::zeros(),
            magnitude: momentum.abs(),
            closed_gradient: false,
        };
        let chart = self.in_chart(base);
        // One loop for each case, as in `pair_in_closed_form`.
        match jacobian.as_deref_mut() {
            Some(jacobian) => {
                for node in &self.nodes {
                    self.add_node_terms(&chart, node, increments, &mut sums, Some(&mut *jacobian));
                }
            }
            None => {
                for node in &self.nodes {
                    self.add_node_terms(&chart, node, increments, &mut sums, None);
                }
            }
        }
        let NodeSums {
            rows,
            impulse,
            end,
            magnitude,
            closed_gradient,
        } = sums;
        for (j, row) in rows[..s].iter().enumerate() {
            residual.fixed_rows_mut::<N>(j * N).copy_from(row);
        }
        residual.as_mut_slice()[N * s..].fill(0.0);
        let complete = s > 1 || N <= 2 || jacobian.is_some() || closed_gradient;
        (
            complete.then_some(StepCovectors { impulse, end }),
            magnitude.amax(),
        )
    }

    /// Adds node `node`'s terms to the sums of the general assembly
    /// ([`euler_lagrange`](Self::euler_lagrange)), and its Jacobian blocks into `jacobian` where
    /// one is asked for. Called from one loop for each case: within one loop body the compiler
    /// hoists what the gradient and the Hessian in closed form share above the branch between
    /// them, which splits a `sin` from its `cos` (two calls where one `sincos` does).
    #[inline(always)]
    fn add_node_terms(
        &self,
        chart: &InChart<'_, S, C, N>,
        node: &NodeWeights,
        increments: &[SVector<f64, N>],
        sums: &mut NodeSums<N>,
        jacobian: Option<&mut DMatrix<f64>>,
    ) {
        let (h, s) = (self.h, self.quadrature.degree());
        let (w, a, d) = (node.w, &node.a[..=s], &node.d[..=s]);
        let (xi, xi_dot) = node.path(increments);
        // A gradient in closed form brings every slot at the cost of the residual's alone.
        let closed = match jacobian {
            None => chart.closed_gradient(&xi, &xi_dot),
            _ => None,
        };
        let (lq, lv) = match jacobian {
            None if let Some(g) = closed => {
                sums.closed_gradient = true;
                (g.q, g.v)
            }
            // Up to two coordinates the hyper-dual pass costs about one first-order pass,
            // and brings both slots: the covectors come with the residual.
            None if s == 1 && N > 2 => {
                // The residual's slot alone: one pass along the direction of ξ_0.
                let seed = Seed {
                    position: a[0],
                    velocity: d[0],
                };
                let first = directional_gradient(chart, &xi, &xi_dot, seed);
                sums.rows[0] += first * w;
                sums.magnitude += first.abs() * w;
                return;
            }
            None => gradients(chart, &xi, &xi_dot),
            jacobian if s == 1 => {
                // One pair of slots: seed the directions of ξ_0 and ξ_1 themselves.
                let l = seeded(
                    chart,
                    &xi,
                    &xi_dot,
                    Seed {
                        position: a[0],
                        velocity: d[0],
                    },
                    Seed {
                        position: a[1],
                        velocity: d[1],
                    },
                );
                if let Some(jacobian) = jacobian {
                    let mut block = jacobian.fixed_view_mut::<N, N>(0, 0);
                    block += l.mixed * w;
                }
                sums.rows[0] += l.first * w;
                sums.impulse += (l.first + l.second) * w;
                sums.end += l.second * w;
                sums.magnitude += l.first.abs() * w;
                return;
            }
            Some(jacobian) => {
                // Many pairs: the Hessian of ℓ at the node, then the chain rule (row block
                // j: the slot ξ_j, j < s; column block k: the unknown ξ_{k+1}).
                let l = hessian(chart, &xi, &xi_dot);
                for (j, (&aj, &dj)) in a[..s].iter().zip(&d[..s]).enumerate() {
                    for (k, (&ak, &dk)) in a[1..].iter().zip(&d[1..]).enumerate() {
                        let mut block = jacobian.fixed_view_mut::<N, N>(j * N, k * N);
                        block += (l.qq * (aj * ak)
                            + l.qv * (aj * dk)
                            + l.qv.transpose() * (dj * ak)
                            + l.vv * (dj * dk))
                            * w;
                    }
                }
                (l.gradient.q, l.gradient.v)
            }
        };
        sums.impulse += lq * w;
        sums.end += (lq * a[s] + lv * d[s]) * w;
        sums.magnitude += if s == 1 {
            // The terms summed into the residual, as the dual-number passes count them.
            (lq * a[0] + lv * d[0]).abs() * w
        } else {
            (lq.abs() + lv.abs() * s as f64 / h) * w
        };
        for (row, (&a, &d)) in sums.rows[..s].iter_mut().zip(a.iter().zip(d)) {
            *row += (lq * a + lv * d) * w;
        }
        if s > 1 {
            // Below an ulp of the row's terms: it moves the row's rounding on average only,
            // which is what keeps the energy's round-off from drifting (examples/brouwer.rs).
            sums.rows[0] += (lq * node.a0_rest + lv * node.d0_rest) * w;
        }
    }

    /// Whether the rule has a single node (the midpoint rule among the degree-1 rules).
    pub(crate) fn one_node(&self) -> bool {
        self.nodes.len() == 1
    }

    /// [`euler_lagrange`](Self::euler_lagrange) of a degree-1 step (one pair of slots, `ξ` the
    /// end point's increment) from the Lagrangian's closed-form derivatives: the same sums in
    /// the same order as the general path, without its loops over the step's points: the slot
    /// covectors and the size of the residual's terms. Writes rows `0..N` of `residual` alone
    /// (the rows after them are the caller's to write) and, where a Jacobian is asked for (by
    /// columns, `n × n` for `n = residual.len()`), adds the block of `ξ` over the entries of the
    /// Hessian that do not vanish. On slices: their own indices, without a check each. With
    /// `one_node` (the rule has one node) the node's code is seen whole. `None`, with nothing
    /// written, where the model has no closed forms.
    #[inline(always)]
    pub(crate) fn pair_in_closed_form(
        &self,
        base: &Point<C, N, f64>,
        xi: &SVector<f64, N>,
        momentum: &SVector<f64, N>,
        residual: &mut [f64],
        jacobian: Option<&mut [f64]>,
        one_node: bool,
    ) -> Option<(StepCovectors<N>, f64)> {
        debug_assert_eq!(
            self.quadrature.degree(),
            1,
            "a pair of slots is a degree-1 step"
        );
        // Cut to one node, the loop over the nodes has a known length, and the compiler sees
        // the node's code whole.
        debug_assert!(!one_node || self.nodes.len() == 1);
        let nodes = match one_node {
            true => self.nodes.get(..1)?,
            false => self.nodes.as_slice(),
        };
        let chart = self.in_chart(base);
        // On a translation chart the chart's Hessian is the model's, its zero entries too.
        let zeros = match C::TRANSLATION {
            true => S::LAGRANGIAN_HESSIAN_ZEROS,
            false => HessianZeros::NONE,
        };
        let n = residual.len();
        debug_assert!(jacobian.as_ref().is_none_or(|j| j.len() == n * n));
        let (mut row, mut magnitude, mut impulse, mut end) = (
            *momentum,
            momentum.abs(),
            SVector::zeros(),
            SVector::zeros(),
        );
        let mut sums = PairSums {
            row: &mut row,
            impulse: &mut impulse,
            end: &mut end,
            magnitude: &mut magnitude,
        };
        // One loop for each case: within one loop body the compiler hoists what the gradient and
        // the Hessian share (a `sin`) above the branch and leaves its partner (the `cos`) below,
        // where the two can no longer be one `sincos` call.
        if let Some(jacobian) = jacobian {
            // Nothing is written before every node has its closed forms: the block of a rule of
            // several nodes is summed aside (by columns of `N`) and added after them.
            let mut block = SMatrix::<f64, N, N>::zeros();
            let (target, stride) = match one_node {
                true => (&mut *jacobian, n),
                false => (block.as_mut_slice(), N),
            };
            for node in nodes {
                let (_, [_, a1], [_, d1]) = node.pair();
                let hessian = chart.closed_hessian(&(xi * a1), &(xi * d1))?;
                // As the general path's `seeded` along the directions of ξ_0 and ξ_1: where a
                // weight is zero its terms are left out, not multiplied by zero.
                if node.pair_without_zeros {
                    sums.add_hessian(&hessian, zeros, node.pair(), target, stride, |x, c| x * c);
                } else {
                    sums.add_hessian(&hessian, zeros, node.pair(), target, stride, |x, c| {
                        if c == 0.0 { 0.0 } else { x * c }
                    });
                }
            }
            if !one_node {
                for j in 0..N {
                    for i in 0..N {
                        jacobian[j * n + i] += block[(i, j)];
                    }
                }
            }
        } else {
            for node in nodes {
                let (_, [_, a1], [_, d1]) = node.pair();
                let gradient = chart.closed_gradient(&(xi * a1), &(xi * d1))?;
                sums.add_gradient(&gradient, node.pair());
            }
        }
        residual[..N].copy_from_slice(row.as_slice());
        Some((StepCovectors { impulse, end }, magnitude.amax()))
    }

    /// [`euler_lagrange`](Self::euler_lagrange) on a space whose charts have non-affine
    /// transitions: row 0 is `π_k + D1 L_d` through the moving chart (see
    /// [`MovingRow`](crate::model::derivatives::MovingRow)), the internal points' rows and the end
    /// covector are read in the chart at `base`. The end covector comes with the residual where a
    /// Jacobian is asked for, the step has internal points, or the space is one of vectors and
    /// rotations (its degree-1 step by the chain rule, [`group_slots`]); otherwise it is left to
    /// [`slot_covectors`](Self::slot_covectors) (`None`).
    fn euler_lagrange_moving(
        &self,
        base: &Point<C, N, f64>,
        increments: &[SVector<f64, N>],
        momentum: &SVector<f64, N>,
        residual: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
    ) -> (Option<StepCovectors<N>>, f64) {
        let (quad, h) = (&self.quadrature, self.h);
        let s = quad.degree();
        residual.as_mut_slice().fill(0.0);
        if s == 1
            && let Some(chart) = self.space.group_chart()
        {
            let slot = group_slots::first_slot(
                &self.system,
                &self.space,
                chart,
                base,
                quad,
                h,
                &increments[0],
                jacobian.is_some(),
            );
            residual
                .fixed_rows_mut::<N>(0)
                .copy_from(&(momentum + slot.row));
            if let (Some(jacobian), Some(block)) = (jacobian, slot.jacobian) {
                let mut target = jacobian.fixed_view_mut::<N, N>(0, 0);
                target += block;
            }
            let covectors = StepCovectors {
                impulse: SVector::zeros(),
                end: slot.end,
            };
            return (Some(covectors), (momentum.abs() + slot.magnitude).amax());
        }
        let moving = moving_row(
            &self.system,
            &self.space,
            base,
            quad,
            h,
            increments,
            jacobian.is_some(),
        );
        residual
            .fixed_rows_mut::<N>(0)
            .copy_from(&(momentum + moving.row));
        let mut magnitude = momentum.abs() + moving.magnitude;
        if let Some(jacobian) = jacobian.as_deref_mut() {
            for (m, block) in moving.blocks.iter().enumerate() {
                let mut target = jacobian.fixed_view_mut::<N, N>(0, m * N);
                target += block;
            }
        }
        if s == 1 {
            let end = moving.slots.first().map(|&end| StepCovectors {
                impulse: SVector::zeros(),
                end,
            });
            return (end, magnitude.amax());
        }
        let chart = self.in_chart(base);
        let mut end = SVector::zeros();
        for (i, &b) in quad.weights().iter().enumerate() {
            let w = h * b;
            let (xi, xi_dot) = self.node(i, increments);
            let a = |j: usize| quad.ell(i, j);
            let d = |j: usize| quad.ell_prime(i, j) / h;
            let (lq, lv) = match jacobian.as_deref_mut() {
                Some(jacobian) => {
                    let l = hessian(&chart, &xi, &xi_dot);
                    for j in 1..s {
                        for k in 1..=s {
                            let mut block = jacobian.fixed_view_mut::<N, N>(j * N, (k - 1) * N);
                            block += (l.qq * (a(j) * a(k))
                                + l.qv * (a(j) * d(k))
                                + l.qv.transpose() * (d(j) * a(k))
                                + l.vv * (d(j) * d(k)))
                                * w;
                        }
                    }
                    (l.gradient.q, l.gradient.v)
                }
                None => gradients(&chart, &xi, &xi_dot),
            };
            end += (lq * a(s) + lv * d(s)) * w;
            magnitude += (lq.abs() + lv.abs() * s as f64 / h) * w;
            for j in 1..s {
                let mut r = residual.fixed_rows_mut::<N>(j * N);
                r += (lq * a(j) + lv * d(j)) * w;
            }
        }
        let covectors = StepCovectors {
            impulse: SVector::zeros(),
            end,
        };
        (Some(covectors), magnitude.amax())
    }

    /// The slot covectors of the step with points `ξ_1..ξ_s` in the chart at `base`:
    /// `Σ_j ∂L_d/∂ξ_j` and `∂L_d/∂ξ_s` (first derivatives only).
    pub(crate) fn slot_covectors(
        &self,
        base: &Point<C, N, f64>,
        increments: &[SVector<f64, N>],
    ) -> StepCovectors<N> {
        let (quad, h, s) = (&self.quadrature, self.h, self.quadrature.degree());
        let chart = self.in_chart(base);
        let mut covectors = StepCovectors::zero();
        for (i, &b) in quad.weights().iter().enumerate() {
            let (xi, xi_dot) = self.node(i, increments);
            let (lq, lv) = gradients(&chart, &xi, &xi_dot);
            covectors.impulse += lq * (h * b);
            covectors.end += (lq * quad.ell(i, s) + lv * (quad.ell_prime(i, s) / h)) * (h * b);
        }
        covectors
    }
}

impl<S: DiracSystem<N>, C: ConfigurationSpace<N, Manifold = Vectors>, const N: usize>
    DiscreteLagrangian<S, N, C>
{
    /// `D³L_d` along three displacements of the step's points (`d[k][m]` moves point `m`,
    /// `m = 0..=s`), on a translation chart: `h Σ_i b_i D³L(q_i, v_i)` along the node
    /// displacements `(Σ_m ℓ_m(c_i) d_m, Σ_m ℓ'_m(c_i) d_m / h)`.
    pub(crate) fn slot_third(
        &self,
        base: &SVector<f64, N>,
        increments: &[SVector<f64, N>],
        d: [&[SVector<f64, N>]; 3],
    ) -> f64 {
        let (quad, h) = (&self.quadrature, self.h);
        let mut total = 0.0;
        for (i, &b) in quad.weights().iter().enumerate() {
            let (xi, xi_dot) = self.node(i, increments);
            let directions = d.map(|points| self.node_displacement(i, points));
            total += h * b * third_derivative(&self.system, &(base + xi), &xi_dot, directions);
        }
        total
    }

    /// Every second slot derivative `∂²L_d/∂ξ_j∂ξ_m` (`j, m = 0..=s`, `ξ_0 = 0`) at the step
    /// with points `ξ_1..ξ_s` from `base`.
    pub(crate) fn slot_hessian(
        &self,
        base: &SVector<f64, N>,
        increments: &[SVector<f64, N>],
    ) -> SlotBlocks<N> {
        let (quad, h) = (&self.quadrature, self.h);
        let mut blocks = SlotBlocks::zeros(quad.degree() + 1);
        let chart = self.in_chart(base);
        for (i, &b) in quad.weights().iter().enumerate() {
            let w = h * b;
            let (xi, xi_dot) = self.node(i, increments);
            let LagrangianHessian { qq, qv, vv, .. } = hessian(&chart, &xi, &xi_dot);
            let a = |j: usize| quad.ell(i, j);
            let d = |j: usize| quad.ell_prime(i, j) / h;
            blocks.add(|j, m| {
                (qq * (a(j) * a(m))
                    + qv * (a(j) * d(m))
                    + qv.transpose() * (d(j) * a(m))
                    + vv * (d(j) * d(m)))
                    * w
            });
        }
        blocks
    }
}

/// Blocks `G_jm` (`j, m = 0..=s`; rows: the components of point `j`) of the second derivatives
/// of a step's discrete Lagrangian, or of its forces, in the step's points: one buffer, row by
/// row.
pub(crate) struct SlotBlocks<const N: usize> {
    points: usize,
    blocks: Vec<SMatrix<f64, N, N>>,
}

impl<const N: usize> SlotBlocks<N> {
    /// Zero blocks for a step of `points` points.
    pub(crate) fn zeros(points: usize) -> Self {
        Self {
            points,
            blocks: vec![SMatrix::zeros(); points * points],
        }
    }

    /// Adds `term(j, m)` to every block `G_jm`.
    pub(crate) fn add(&mut self, mut term: impl FnMut(usize, usize) -> SMatrix<f64, N, N>) {
        for (k, block) in self.blocks.iter_mut().enumerate() {
            *block += term(k / self.points, k % self.points);
        }
    }

    /// Row `j`: the blocks `G_jm`, `m = 0..=s`.
    pub(crate) fn row(&self, j: usize) -> &[SMatrix<f64, N, N>] {
        &self.blocks[j * self.points..(j + 1) * self.points]
    }

    /// `Σ_m G_jm`: how row `j` moves when every point moves alike (as with `q_k`).
    pub(crate) fn row_sum(&self, j: usize) -> SMatrix<f64, N, N> {
        self.row(j).iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::scalar::Scalar;
    use crate::space::configuration_space::Positive;
    use crate::space::manifold::Manifold;
    use crate::space::product::{Configuration, Product, Rates};
    use nalgebra::vector;

    /// A pendulum-like coupled Lagrangian with nonzero q–v cross terms.
    struct Coupled;
    impl DiracSystem<2> for Coupled {
        fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
            v[0] * v[0] * 0.5 + v[1] * v[1] * (q[0].cos() + 2.0) * 0.5 + v[0] * v[1] * q[1] * 0.3
                - q[0].powi(2) * q[1].sin()
        }
    }

    /// `L_d` as a function of all `s + 1` chart points `ξ_0, …, ξ_s` in the chart fixed at `base`
    /// (`ξ_0` free too), summed from the quadrature's basis independently of `node`.
    fn in_fixed_chart<C: ConfigurationSpace<2, Manifold = Vectors>>(
        ld: &DiscreteLagrangian<Coupled, 2, C>,
        base: &SVector<f64, 2>,
        xis: &[SVector<f64, 2>],
    ) -> f64 {
        let (quad, h) = (ld.quadrature(), ld.h());
        let chart = ld.in_chart(base);
        (0..quad.nodes().len())
            .map(|i| {
                let xi: SVector<f64, 2> = (0..xis.len())
                    .map(|j| xis[j] * quad.basis(i, j).unwrap())
                    .sum();
                let xi_dot: SVector<f64, 2> = (0..xis.len())
                    .map(|j| xis[j] * (quad.basis_derivative(i, j).unwrap() / h))
                    .sum();
                h * quad.weights()[i] * chart.value(&xi, &xi_dot)
            })
            .sum()
    }

    /// Central difference of `f` in component `c` of chart point `j`.
    fn fd(
        f: &dyn Fn(&[SVector<f64, 2>]) -> f64,
        xis: &[SVector<f64, 2>],
        j: usize,
        c: usize,
    ) -> f64 {
        let eps = 1e-6;
        let mut plus = xis.to_vec();
        let mut minus = xis.to_vec();
        plus[j][c] += eps;
        minus[j][c] -= eps;
        (f(&plus) - f(&minus)) / (2.0 * eps)
    }

    /// The residual, slot covectors and Jacobian of `euler_lagrange` against central
    /// differences of `L_d` in the chart at `base`, and `value` against the chart sum.
    fn check<C: ConfigurationSpace<2, Manifold = Vectors>>(space: C, quadrature: Quadrature) {
        let s = quadrature.degree();
        let name = quadrature.name();
        let ld = DiscreteLagrangian::on_space(Coupled, space, quadrature, 0.1);
        let base = vector![0.3, 0.4];
        let xis: Vec<_> = (0..=s)
            .map(|j| vector![0.05 * j as f64, -0.1 + 0.03 * (j * j) as f64] * (j.min(1) as f64))
            .collect();
        let f = |xis: &[SVector<f64, 2>]| in_fixed_chart(&ld, &base, xis);
        let p = vector![0.7, -0.4];
        let mut r = DVector::zeros(2 * s);
        let mut jac = DMatrix::zeros(2 * s, 2 * s);
        let (covectors, _) = ld.euler_lagrange(&base, &xis[1..], &p, &mut r, Some(&mut jac));
        let covectors = covectors.expect("complete with a Jacobian");
        // Without a Jacobian (first derivatives only) the same rows, and the same covectors
        // (from `slot_covectors` where the residual did not need them).
        let mut alone = DVector::zeros(2 * s);
        let (gradient_only, _) = ld.euler_lagrange(&base, &xis[1..], &p, &mut alone, None);
        assert!((&alone - &r).amax() < 1e-14, "{name}: {alone} vs {r}");
        // Two coordinates: the one-slot residual comes with its covectors.
        assert!(gradient_only.is_some(), "{name}");
        let separate = ld.slot_covectors(&base, &xis[1..]);
        for found in [gradient_only, Some(separate)].into_iter().flatten() {
            assert!((found.impulse - covectors.impulse).amax() < 1e-14, "{name}");
            assert!((found.end - covectors.end).amax() < 1e-14, "{name}");
        }
        for c in 0..2 {
            assert!((r[c] - p[c] - fd(&f, &xis, 0, c)).abs() < 1e-8, "{name}");
            for j in 1..s {
                assert!((r[j * 2 + c] - fd(&f, &xis, j, c)).abs() < 1e-8, "{name}");
            }
            let total: f64 = (0..=s).map(|j| fd(&f, &xis, j, c)).sum();
            assert!((covectors.impulse[c] - total).abs() < 1e-8, "{name}");
            assert!(
                (covectors.end[c] - fd(&f, &xis, s, c)).abs() < 1e-8,
                "{name}"
            );
        }
        // The public value at the points R_base(ξ_j) is the chart sum.
        let points: Vec<_> = xis.iter().map(|xi| ld.space().retract(&base, xi)).collect();
        assert!(
            (ld.value(&points).unwrap() - f(&xis)).abs() < 1e-14,
            "{name}"
        );
        // Jacobian columns against differences of the residual.
        let eps = 1e-6;
        for k in 1..=s {
            for c in 0..2 {
                let mut plus = xis.clone();
                let mut minus = xis.clone();
                plus[k][c] += eps;
                minus[k][c] -= eps;
                let (mut rp, mut rm) = (DVector::zeros(2 * s), DVector::zeros(2 * s));
                let mut scratch = DMatrix::zeros(2 * s, 2 * s);
                ld.euler_lagrange(&base, &plus[1..], &p, &mut rp, Some(&mut scratch));
                ld.euler_lagrange(&base, &minus[1..], &p, &mut rm, Some(&mut scratch));
                let column = (rp - rm) / (2.0 * eps);
                let exact = jac.column((k - 1) * 2 + c);
                assert!((column - exact).amax() < 1e-6, "{name}: column {k},{c}");
            }
        }
    }

    #[test]
    fn slot_derivatives_match_finite_differences() {
        for quadrature in [
            Quadrature::midpoint(),
            Quadrature::trapezoid(),
            Quadrature::galerkin(2).unwrap(),
            Quadrature::galerkin(3).unwrap(),
        ] {
            check(Euclidean, quadrature.clone());
            check(Positive, quadrature);
        }
    }

    /// A model on `R × SO(3) × S²` whose terms couple all three factors, in position and in
    /// velocity.
    struct Mixed;
    impl DiracSystem<6, Product<1, 1, 1>> for Mixed {
        fn lagrangian<D: Scalar>(&self, q: &Configuration<D, 1, 1, 1>, v: &Rates<D, 1, 1, 1>) -> D {
            let (x, r, n) = (q.vector[0], q.rotation[0], q.direction[0]);
            let (u, w, m) = (v.vector[0], v.rotation[0], v.direction[0]);
            let kinetic = u * u * 0.5
                + (w[0] * w[0] + w[1] * w[1] * 2.0 + w[2] * w[2] * 3.0) * 0.5
                + (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]) * 0.5;
            let axis = r[(0, 2)] * n[0] + r[(1, 2)] * n[1] + r[(2, 2)] * n[2];
            kinetic + w[0] * u * 0.3 + m[2] * w[1] * 0.2 + axis * (x + 1.5)
                - r[(2, 2)]
                - x * x * 0.4
        }
    }

    /// On a space whose charts move with the base, `euler_lagrange` against differences of the
    /// public `value` on the manifold's points: row 0 minus `π` is the derivative of
    /// `L_d(R_{q_0}(η), Q_1, …, Q_s)` in `η`; the internal rows and the end covector are the
    /// derivatives in `ξ_j` of `L_d(q_0, …, R_{q_0}(ξ_j), …)`; the Jacobian's columns are
    /// differences of the residual.
    fn check_moving(space: Product<1, 1, 1>, quadrature: Quadrature) {
        let s = quadrature.degree();
        let name = format!("{} {:?}", quadrature.name(), space.retraction());
        let ld = DiscreteLagrangian::on_space(Mixed, space, quadrature, 0.1);
        let base = space.retract(
            &<Product<1, 1, 1> as Manifold<6>>::origin(),
            &SVector::<f64, 6>::from_column_slice(&[0.2, 0.3, -0.5, 0.8, 0.4, -0.6]),
        );
        let increments: Vec<SVector<f64, 6>> = (1..=s)
            .map(|j| {
                let t = j as f64 / s as f64;
                SVector::from_column_slice(&[0.07, 0.05, -0.03, 0.09, 0.04, 0.06]) * t
                    + SVector::from_column_slice(&[0.0, 0.02, 0.01, 0.0, -0.03, 0.01]) * (t * t)
            })
            .collect();
        let points = |base: &Configuration<f64, 1, 1, 1>, xis: &[SVector<f64, 6>]| {
            std::iter::once(*base)
                .chain(xis.iter().map(|xi| space.retract(base, xi)))
                .collect::<Vec<_>>()
        };
        let p = SVector::<f64, 6>::from_column_slice(&[0.7, -0.4, 0.2, 0.1, -0.3, 0.5]);
        let mut r = DVector::zeros(6 * s);
        let mut jac = DMatrix::zeros(6 * s, 6 * s);
        let (covectors, _) = ld.euler_lagrange(&base, &increments, &p, &mut r, Some(&mut jac));
        let end = covectors
            .expect("with a Jacobian the end covector comes along")
            .end;
        let mut alone = DVector::zeros(6 * s);
        ld.euler_lagrange(&base, &increments, &p, &mut alone, None);
        assert!((&alone - &r).amax() < 1e-14, "{name}: {alone} vs {r}");
        assert!(
            (ld.slot_covectors(&base, &increments).end - end).amax() < 1e-13,
            "{name}"
        );
        let eps = 1e-6;
        let unit = |c: usize| SVector::<f64, 6>::from_fn(|i, _| if i == c { eps } else { 0.0 });
        let ends = points(&base, &increments);
        for c in 0..6 {
            // Row 0: the first point moves on the manifold, the others stay where they are.
            let moved = |sign: f64| {
                let mut pts = ends.clone();
                pts[0] = space.retract(&base, &(unit(c) * sign));
                ld.value(&pts).unwrap()
            };
            let d0 = (moved(1.0) - moved(-1.0)) / (2.0 * eps);
            assert!(
                (r[c] - p[c] - d0).abs() < 1e-8,
                "{name}: row 0 [{c}] {} vs {d0}",
                r[c] - p[c]
            );
            // Point j in the chart at q_0.
            let slot = |j: usize| {
                let shifted = |sign: f64| {
                    let mut xis = increments.clone();
                    xis[j - 1] += unit(c) * sign;
                    ld.value(&points(&base, &xis)).unwrap()
                };
                (shifted(1.0) - shifted(-1.0)) / (2.0 * eps)
            };
            for j in 1..s {
                assert!(
                    (r[j * 6 + c] - slot(j)).abs() < 1e-8,
                    "{name}: row {j} [{c}]"
                );
            }
            assert!((end[c] - slot(s)).abs() < 1e-8, "{name}: end [{c}]");
        }
        for k in 0..s {
            for c in 0..6 {
                let residual = |sign: f64| {
                    let mut xis = increments.clone();
                    xis[k] += unit(c) * sign;
                    let mut out = DVector::zeros(6 * s);
                    let mut scratch = DMatrix::zeros(6 * s, 6 * s);
                    ld.euler_lagrange(&base, &xis, &p, &mut out, Some(&mut scratch));
                    out
                };
                let column = (residual(1.0) - residual(-1.0)) / (2.0 * eps);
                let exact = jac.column(k * 6 + c);
                assert!(
                    (&column - exact).amax() < 1e-6,
                    "{name}: column {k},{c}: {column} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn moving_chart_slot_derivatives_match_finite_differences() {
        for quadrature in [
            Quadrature::midpoint(),
            Quadrature::trapezoid(),
            Quadrature::galerkin(2).unwrap(),
        ] {
            check_moving(Product::cayley(), quadrature.clone());
            check_moving(Product::exp(), quadrature);
        }
    }

    /// On vectors the moving chart is the fixed one: the moving-chart rows, Jacobian and end
    /// covector equal the fixed chart's.
    #[test]
    fn the_moving_chart_reduces_to_the_fixed_one_on_vectors() {
        for quadrature in [
            Quadrature::midpoint(),
            Quadrature::trapezoid(),
            Quadrature::galerkin(2).unwrap(),
            Quadrature::galerkin(3).unwrap(),
        ] {
            let s = quadrature.degree();
            let name = quadrature.name();
            let ld = DiscreteLagrangian::on_space(Coupled, Euclidean, quadrature, 0.1);
            let base = vector![0.3, 0.4];
            let xis: Vec<_> = (1..=s)
                .map(|j| vector![0.05 * j as f64, -0.1 + 0.03 * (j * j) as f64])
                .collect();
            let p = vector![0.7, -0.4];
            let (mut r, mut rm) = (DVector::zeros(2 * s), DVector::zeros(2 * s));
            let (mut jac, mut jm) = (DMatrix::zeros(2 * s, 2 * s), DMatrix::zeros(2 * s, 2 * s));
            let (fixed, _) = ld.euler_lagrange(&base, &xis, &p, &mut r, Some(&mut jac));
            let (moving, _) = ld.euler_lagrange_moving(&base, &xis, &p, &mut rm, Some(&mut jm));
            assert!((&r - &rm).amax() < 1e-13, "{name}: {r} vs {rm}");
            assert!((&jac - &jm).amax() < 1e-12, "{name}: {jac} vs {jm}");
            assert!(
                (fixed.unwrap().end - moving.unwrap().end).amax() < 1e-13,
                "{name}"
            );
        }
    }
}
