//! The discrete Hamiltonian route: the discrete Hamilton's equations of a Galerkin discrete
//! Hamiltonian, with constraint one-forms, holonomic constraints and forces.
//!
//! The type II generating function `H_d⁺(q_k, p_{k+1}) = ext [p_{k+1} q_{k+1} − 𝕃]` of the
//! phase-space action over one step, with the path `Q(τ) = Σ_j ℓ_j(τ) Q_j` of degree `s`
//! through `Q_0 = q_k, Q_1, …, Q_s = q_{k+1}` (equispaced) and a momentum `P_i` of its own at
//! each node `c_i` of the quadrature `(c_i, b_i)`,
//!
//! ```text
//! 𝕃(Q_0..Q_s, P_1..P_m) = h Σ_i b_i [ P_i · Q̇(c_i) − H(Q(c_i), P_i) ],   Q̇(c_i) = Σ_j ℓ'_j(c_i) Q_j / h,
//! ```
//!
//! gives `p_k = D₁H_d⁺`, `q_{k+1} = D₂H_d⁺` as the stationarity conditions of `𝕃`:
//!
//! ```text
//! p_k + ∂𝕃/∂Q_0 + f_0 + w_0 Aᵀμ = 0,        ∂𝕃/∂Q_j + f_j + w_j Aᵀμ = 0   (j = 1..s−1),
//! Q̇(c_i) − ∂H/∂p(Q(c_i), P_i) = 0  (i = 1..m),                A(Q_c) Q̇_c = 0,
//! ∂𝕃/∂Q_j = Σ_i b_i [ ℓ'_j(c_i) P_i − h ℓ_j(c_i) ∂H/∂q(Q(c_i), P_i) ],
//! ```
//!
//! solved for `x = [Q_1 − q_k, …, Q_s − q_k, P_1, …, P_m, μ]`, then
//! `p_{k+1} = p_k + h Σ_i b_i (F_i − ∂H/∂q_i) + Aᵀμ` (the sum of the rows, which equals
//! `∂𝕃/∂Q_s + f_s + w_s Aᵀμ` at the solution without its cancellation) and `q_{k+1} = Q_s`.
//! Forces enter as in the discrete Lagrange–d'Alembert principle, `f_j = h Σ_i b_i ℓ_j(c_i)
//! F(Q(c_i), P_i, t_k + c_i h, u)`. The one-forms are held where the Lagrangian route holds
//! them (a degree-1 step at its constraint point `Q_c = q_k + θ(q_{k+1} − q_k)` with
//! `Q̇_c = (q_{k+1} − q_k)/h` and the impulse shared `w = (σ, 1 − σ)`, see
//! [`ConstraintPoint`]; a Galerkin step at its Gauss nodes, with the force `A(Q(c_i))ᵀμ_i`
//! weighted as a force, `w_j = h b_i ℓ_j(c_i)`): the issue's implicit discrete Hamiltonian
//! system `p_k − D₁H_d⁺ ∈ Δ°`, `(q_k, q_{k+1}) ∈ Δ_d`. Holonomic constraints `g_b(q) = 0` are
//! held at the path's points `Q_1..Q_s` (degree 2 at most, as on the Lagrangian route): the
//! rows `g_b(Q_j) = 0`, with the impulse `dg_b(Q_j)ᵀλ_j` in the row of an internal point and
//! `dg_b(q_k)ᵀλ_s` in the row of `q_k` (SHAKE: `q_{k+1}` on the constraint, `p_{k+1}` not
//! projected onto its tangent space).
//!
//! **When the two routes agree.** Where `∂²H/∂p²` is invertible, the stationarity in `P_i`
//! is the Legendre transform at the node, and `P_i Q̇_i − H(Q_i, P_i) = L(Q_i, Q̇_i)`: `𝕃`
//! extremised over the momenta is the Galerkin discrete Lagrangian of the same path and
//! quadrature, so both routes take the same steps (`tests/suite/hamiltonian.rs` checks it to
//! round-off on a non-separable `H`). They differ where there is no Lagrangian: a Hamiltonian
//! whose `∂²H/∂p²` is singular (`H = p f(q)`, whose steps are the Gauss collocation of
//! `q̇ = f(q)` with its adjoint) has no Lagrangian route at all.
//!
//! ```
//! use dirac_runtime::{HamiltonianSystem, Quadrature, Scalar, Stepper};
//! use nalgebra::{SVector, vector};
//!
//! /// H = (p² + q²)/2.
//! struct Oscillator;
//! impl HamiltonianSystem<1> for Oscillator {
//!     fn hamiltonian<D: Scalar>(&self, q: &SVector<D, 1>, p: &SVector<D, 1>) -> D {
//!         (p[0] * p[0] + q[0] * q[0]) * 0.5
//!     }
//! }
//!
//! let mut stepper = Stepper::hamiltonian(Oscillator, Quadrature::galerkin(3)?, 0.1)?;
//! stepper.start_from_momentum(vector![1.0], vector![0.0])?;
//! let trajectory = stepper.run(10)?;
//! assert!((trajectory.q()[10][0] - 1.0_f64.cos()).abs() < 1e-8);
//! # Ok::<(), dirac_runtime::DiracError>(())
//! ```

use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use num_dual::Dual64;

use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::base::float::{exceeds, rounded_sum};
use crate::model::derivatives::{self, Dual, Hamiltonian};
use crate::model::hamiltonian_system::HamiltonianSystem;
use crate::quadrature::{Quadrature, Rule};
use crate::solve::lu;
use crate::solve::newton::{Newton, NewtonFailure};
use crate::space::configuration_space::compensated_add;
use crate::space::manifold::Vectors;
use crate::step::step_derivatives::StepDerivatives;
use crate::step::step_equations::{State, StepEquations, StepWork};

/// The path's basis at quadrature node `c_i`: `position_j = ℓ_j(c_i)` and `rate_j = ℓ'_j(c_i)`
/// (`j = 0..=s`). The path is `q_k + Σ_{j≥1} position_j ξ_j`, so its derivative in `q_k` weighs
/// the node by `1 − Σ_{j≥1} position_j` and `−Σ_{j≥1} rate_j`, not by the basis at point 0
/// evaluated apart (a few ulps off them, which lets the energy's round-off drift). With internal
/// points, point 0's entries are those sums rounded and the `rest`s what rounding left of them;
/// a degree-1 step keeps its two entries (the rests are zero).
#[derive(Debug, Clone, PartialEq)]
struct Basis {
    position: Vec<f64>,
    rate: Vec<f64>,
    position_rest: f64,
    rate_rest: f64,
}

impl Basis {
    /// The basis at node `i` of `quadrature`.
    fn at(quadrature: &Quadrature, i: usize) -> Self {
        let s = quadrature.degree();
        let mut basis = Self {
            position: (0..=s).map(|j| quadrature.ell(i, j)).collect(),
            rate: (0..=s).map(|j| quadrature.ell_prime(i, j)).collect(),
            position_rest: 0.0,
            rate_rest: 0.0,
        };
        if s > 1 {
            let (position, rate) = (&basis.position[1..], &basis.rate[1..]);
            (basis.position[0], basis.position_rest) =
                rounded_sum(1.0, position.iter().map(|a| -a));
            (basis.rate[0], basis.rate_rest) = rounded_sum(0.0, rate.iter().map(|d| -d));
        }
        basis
    }
}

/// Where a step holds the constraint one-forms: the point `Q_c = Σ_j position_j Q_j`, the
/// velocity `Q̇_c = Σ_j rate_j Q_j / h` and the weights `w_j` of the constraint's force on the
/// rows of `Q_0 … Q_s`, with what rounding left of `w_0` (see [`Basis`]).
#[derive(Debug, Clone, PartialEq)]
struct Site {
    position: Vec<f64>,
    rate: Vec<f64>,
    weight: Vec<f64>,
    weight_rest: f64,
}

/// The discrete Hamilton's equations of the Galerkin discrete Hamiltonian `H_d⁺` of a
/// [`HamiltonianSystem`] on `Rᴺ` (see the [module](self)), as [`StepEquations`] a
/// [`Stepper`](crate::Stepper) drives.
///
/// ```
/// use dirac_runtime::{HamiltonianSystem, Quadrature, Scalar, Stepper, hamilton::Hamilton};
/// use nalgebra::{SVector, vector};
/// struct Free;
/// impl HamiltonianSystem<1> for Free {
///     fn hamiltonian<D: Scalar>(&self, _q: &SVector<D, 1>, p: &SVector<D, 1>) -> D {
///         p[0] * p[0] * 0.5
///     }
/// }
/// let equations = Hamilton::new(Free, Quadrature::midpoint(), 0.5)?;
/// let mut stepper = Stepper::with_equations(equations)?;
/// stepper.start_from_momentum(vector![0.0], vector![2.0])?;
/// stepper.step()?;
/// assert_eq!(stepper.q()[0], 1.0);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Hamilton<S, const N: usize> {
    system: S,
    quadrature: Quadrature,
    h: f64,
    /// The path's basis at each node.
    bases: Vec<Basis>,
    sites: Vec<Site>,
    inputs: Vec<f64>,
    /// `p_{k+1} − p_k` at the point assembled last.
    impulse: SVector<f64, N>,
}

impl<S: HamiltonianSystem<N>, const N: usize> Hamilton<S, N> {
    /// The equations of `system` with `quadrature` and step `h`, every input at 0. Fails on a
    /// non-positive or non-finite step, a non-finite parameter, or constraint one-forms with a
    /// Galerkin quadrature other than a Gauss rule with as many nodes as its degree, or with a
    /// constraint point other than the midpoint on such a quadrature (the one-forms are then
    /// held at its nodes).
    pub fn new(system: S, quadrature: Quadrature, h: f64) -> Result<Self, DiracError> {
        if !(h > 0.0 && h.is_finite()) {
            return Err(DiracError::InvalidStep { h });
        }
        if let Some((name, value)) = system
            .parameters()
            .into_iter()
            .find(|(_, v)| !v.is_finite())
        {
            return Err(DiracError::NonFinite {
                what: format!("parameter {name}"),
                value,
            });
        }
        let bases: Vec<Basis> = (0..quadrature.nodes().len())
            .map(|i| Basis::at(&quadrature, i))
            .collect();
        let sites = Self::sites(&system, &quadrature, &bases, h)?;
        crate::discrete::constraint::check_holonomic_degree(S::HOLONOMIC, &quadrature)?;
        Ok(Self {
            system,
            quadrature,
            h,
            bases,
            sites,
            inputs: vec![0.0; S::INPUTS],
            impulse: SVector::zeros(),
        })
    }

    /// Where the one-forms are held (none without one-forms).
    fn sites(
        system: &S,
        quadrature: &Quadrature,
        bases: &[Basis],
        h: f64,
    ) -> Result<Vec<Site>, DiracError> {
        let s = quadrature.degree();
        let point = system.constraint_point();
        if S::ONE_FORMS == 0 {
            return Ok(Vec::new());
        }
        if s == 1 {
            let (theta, sigma) = (point.theta(), point.share());
            return Ok(vec![Site {
                position: vec![1.0 - theta, theta],
                rate: vec![-1.0, 1.0],
                weight: vec![sigma, 1.0 - sigma],
                weight_rest: 0.0,
            }]);
        }
        if quadrature.rule() != Rule::GaussLegendre(s) || point != ConstraintPoint::Midpoint {
            return Err(DiracError::InvalidQuadrature(format!(
                "{}: constraint one-forms of a Galerkin step are held at the nodes of a Gauss \
                 rule with as many nodes as the path's degree (galerkin(s) with \
                 gauss_legendre(s)), which has no constraint point (leave it at the midpoint)",
                quadrature.name()
            )));
        }
        Ok(bases
            .iter()
            .zip(quadrature.weights())
            .map(|(basis, &b)| Site {
                position: basis.position.clone(),
                rate: basis.rate.clone(),
                weight: basis.position.iter().map(|&a| h * b * a).collect(),
                weight_rest: h * b * basis.position_rest,
            })
            .collect())
    }

    /// The model.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// The quadrature of the phase-space action.
    pub fn quadrature(&self) -> &Quadrature {
        &self.quadrature
    }

    fn degree(&self) -> usize {
        self.quadrature.degree()
    }

    fn nodes(&self) -> usize {
        self.quadrature.nodes().len()
    }

    /// First column of `Q_j − q_k` (`j = 1..=s`).
    fn point(&self, j: usize) -> usize {
        (j - 1) * N
    }

    /// First column of the momentum `P_i` at node `i` (`0..m`).
    fn node_momentum(&self, i: usize) -> usize {
        (self.degree() + i) * N
    }

    /// Column of the multiplier of one-form `a` at site `k`.
    fn multiplier(&self, k: usize, a: usize) -> usize {
        (self.degree() + self.nodes()) * N + k * S::ONE_FORMS + a
    }

    /// Column of the multiplier `λ` of holonomic constraint `b` held at point `j` (`1..=s`):
    /// the internal points' first, the end point's last (as on the Lagrangian route).
    fn holonomic_multiplier(&self, j: usize, b: usize) -> usize {
        self.first_multiplier() + self.sites.len() * S::ONE_FORMS + (j - 1) * S::HOLONOMIC + b
    }

    /// `Σ_{j≥1} weights_j ξ_j` over the step's increments in `x`.
    fn combination(&self, x: &DVector<f64>, weights: &[f64]) -> SVector<f64, N> {
        (1..=self.degree()).fold(SVector::zeros(), |sum, j| {
            sum + x.fixed_rows::<N>(self.point(j)) * weights[j]
        })
    }

    /// Node `i` of the step from `state` solved by `x`: the path's basis there, its position
    /// `Q(c_i)` and rate `Q̇(c_i)`, and the node's momentum `P_i`.
    fn node(
        &self,
        state: &State<N>,
        x: &DVector<f64>,
        i: usize,
    ) -> (&Basis, SVector<f64, N>, SVector<f64, N>, SVector<f64, N>) {
        let basis = &self.bases[i];
        let q = state.q + self.combination(x, &basis.position);
        let v = self.combination(x, &basis.rate) / self.h;
        let p = x.fixed_rows::<N>(self.node_momentum(i)).into_owned();
        (basis, q, v, p)
    }

    /// The force at node values `(q, p)` at time `t`, with its Jacobians in `q` and `p` when
    /// `derivatives` (zeros otherwise).
    fn force(
        &self,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        t: f64,
        derivatives: bool,
    ) -> (SVector<f64, N>, SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
        if !S::FORCES {
            return (SVector::zeros(), SMatrix::zeros(), SMatrix::zeros());
        }
        if !derivatives {
            return (
                self.system.force(q, p, t, &self.inputs),
                SMatrix::zeros(),
                SMatrix::zeros(),
            );
        }
        let inputs: Vec<Dual<N>> = self.inputs.iter().map(|&u| Dual::from(u)).collect();
        let constant = |x: &SVector<f64, N>| x.map(Dual::<N>::from);
        let (f, fq) = derivatives::jacobian(q, |q| self.system.force(q, &constant(p), t, &inputs));
        let (_, fp) = derivatives::jacobian(p, |p| self.system.force(&constant(q), p, t, &inputs));
        (f, fq, fp)
    }

    /// The step's rows at `x` into `rows`, their Jacobian added into `jacobian` when one is
    /// given, the scale of their terms and the impulse `p_{k+1} − p_k`. The rows are those of
    /// `Q_0 … Q_{s−1}` (`p_k` in the first), the velocity rows of the nodes and the one-forms'
    /// rows; `extended` appends the rows `T_s` of `Q_s` (so that `p_{k+1} = T_s` at the
    /// solution) and one column per coordinate of `q_k` (which moves every point of the path
    /// with weight 1 and no velocity).
    fn rows(
        &self,
        state: &State<N>,
        x: &DVector<f64>,
        rows: &mut DVector<f64>,
        mut jacobian: Option<&mut DMatrix<f64>>,
        extended: bool,
    ) -> (f64, SVector<f64, N>) {
        let (s, h, n) = (self.degree(), self.h, self.unknowns());
        // Row of point j (j = s only when extended) and column of point l (l = 0: q_k).
        let row_of = |j: usize| if j < s { j * N } else { n };
        let column_of = |l: usize| if l == 0 { n } else { self.point(l) };
        let last = if extended { s } else { s - 1 };
        let first = if extended { 0 } else { 1 };
        // q_k enters every point of the path with weight 1 and no velocity.
        let moved = |weights: &[f64], l: usize| if l == 0 { 1.0 } else { weights[l] };
        let rate = |weights: &[f64], l: usize| if l == 0 { 0.0 } else { weights[l] };
        let hamiltonian = Hamiltonian(&self.system);
        rows.fill(0.0);
        let mut row = rows.fixed_rows_mut::<N>(0);
        row += state.p;
        let mut impulse = SVector::<f64, N>::zeros();
        let mut scale = state.p.amax();
        let identity = SMatrix::<f64, N, N>::identity();
        for i in 0..self.nodes() {
            let (c, b) = (self.quadrature.nodes()[i], self.quadrature.weights()[i]);
            let (basis, q, v, p) = self.node(state, x, i);
            let (position, velocity) = (&basis.position, &basis.rate);
            let column = self.node_momentum(i);
            let t = state.t + c * h;
            let second = jacobian
                .is_some()
                .then(|| derivatives::hessian(&hamiltonian, &q, &p));
            let (h_q, h_p) = match &second {
                Some(second) => (second.gradient.q, second.gradient.v),
                None => derivatives::gradients(&hamiltonian, &q, &p),
            };
            let (f, f_q, f_p) = self.force(&q, &p, t, jacobian.is_some());
            let generalised = f - h_q;
            // The node's terms weighed first and spread over the rows by the basis after: the
            // rows are then `ℓ_j(c_i)` and `ℓ'_j(c_i)` times one vector each (row 0 with its
            // rest), the derivatives of one discrete action (a constant product `h b_i ℓ_j(c_i)`
            // rounds differently in each row, a bias of an ulp a step that lets the energy drift).
            let (momentum, impulse_i) = (p * b, generalised * (h * b));
            for j in 0..=last {
                let mut target = rows.fixed_rows_mut::<N>(row_of(j));
                target += momentum * velocity[j] + impulse_i * position[j];
            }
            if s > 1 {
                // Below an ulp of the row's terms: it moves the row's rounding on average only.
                let mut target = rows.fixed_rows_mut::<N>(0);
                target += momentum * basis.rate_rest + impulse_i * basis.position_rest;
            }
            impulse += impulse_i;
            rows.fixed_rows_mut::<N>(column).copy_from(&(v - h_p));
            scale = scale
                .max(p.amax())
                .max(h * h_q.amax())
                .max(h * f.amax())
                .max(v.amax())
                .max(h_p.amax());
            let (Some(jacobian), Some(second)) = (jacobian.as_deref_mut(), &second) else {
                continue;
            };
            let force_q = f_q - second.qq;
            let force_p = f_p - second.qv;
            for j in 0..=last {
                for l in first..=s {
                    let weight = h * b * position[j] * moved(position, l);
                    let mut block = jacobian.fixed_view_mut::<N, N>(row_of(j), column_of(l));
                    block += force_q * weight;
                }
                let mut block = jacobian.fixed_view_mut::<N, N>(row_of(j), column);
                block += identity * (b * velocity[j]) + force_p * (h * b * position[j]);
            }
            for l in first..=s {
                let mut block = jacobian.fixed_view_mut::<N, N>(column, column_of(l));
                block +=
                    identity * (rate(velocity, l) / h) - second.qv.transpose() * moved(position, l);
            }
            let mut block = jacobian.fixed_view_mut::<N, N>(column, column);
            block -= second.vv;
        }
        for (k, site) in self.sites.iter().enumerate() {
            let q = state.q + self.combination(x, &site.position);
            let v = self.combination(x, &site.rate) / h;
            let total: f64 = site.weight.iter().sum();
            for a in 0..S::ONE_FORMS {
                let column = self.multiplier(k, a);
                let mu = x[column];
                let (form, differential) = match jacobian.is_some() {
                    true => derivatives::jacobian(&q, |q| self.system.one_form(q, a)),
                    false => (self.system.one_form(&q, a), SMatrix::zeros()),
                };
                for j in 0..=last {
                    let mut target = rows.fixed_rows_mut::<N>(row_of(j));
                    target += form * (site.weight[j] * mu);
                }
                if s > 1 {
                    let mut target = rows.fixed_rows_mut::<N>(0);
                    target += form * (site.weight_rest * mu);
                }
                impulse += form * (total * mu);
                rows[column] = form.dot(&v);
                scale = scale.max(total.abs() * (form * mu).amax());
                let Some(jacobian) = jacobian.as_deref_mut() else {
                    continue;
                };
                // d(A(q)·v)/dq = Σ_r v_r ∂A_r/∂q.
                let along = differential.transpose() * v;
                for l in first..=s {
                    let weight = moved(&site.position, l);
                    for j in 0..=last {
                        let mut block = jacobian.fixed_view_mut::<N, N>(row_of(j), column_of(l));
                        block += differential * (site.weight[j] * weight * mu);
                    }
                    let mut target = jacobian.fixed_view_mut::<1, N>(column, column_of(l));
                    target += (form * (rate(&site.rate, l) / h) + along * weight).transpose();
                }
                for j in 0..=last {
                    let mut entries = jacobian.fixed_view_mut::<N, 1>(row_of(j), column);
                    entries += form * site.weight[j];
                }
            }
        }
        // Holonomic constraints g_b(Q_j) = 0 at the path's points j = 1..=s: the impulse
        // dg_b(Q_j)ᵀλ acts on the row of Q_j at an internal point and, for the end point, on the
        // row of q_k at q_k (SHAKE), as on the Lagrangian route.
        for j in 1..=s {
            let point = state.q + x.fixed_rows::<N>(self.point(j));
            let row = if j < s { j * N } else { 0 };
            for b in 0..S::HOLONOMIC {
                let column = self.holonomic_multiplier(j, b);
                let lambda = x[column];
                let g = |q: &SVector<f64, N>| {
                    derivatives::scalar_hessian(q, |q| self.system.holonomic(q, b))
                };
                let (value, form, at_point) = g(&point);
                // An internal point's impulse acts where g is held; the end point's at q_k.
                let (direction, curvature) = match j < s {
                    true => (form, at_point),
                    false => {
                        let (_, direction, curvature) = g(&state.q);
                        (direction, curvature)
                    }
                };
                let mut target = rows.fixed_rows_mut::<N>(row);
                target += direction * lambda;
                impulse += direction * lambda;
                rows[column] = value;
                scale = scale
                    .max((direction * lambda).amax())
                    .max(form.abs().dot(&point.abs()));
                let Some(jacobian) = jacobian.as_deref_mut() else {
                    continue;
                };
                let mut entries = jacobian.fixed_view_mut::<N, 1>(row, column);
                entries += direction;
                // g_b(Q_j) moves with Q_j and, in the extended rows, with q_k.
                let mut entries = jacobian.fixed_view_mut::<1, N>(column, self.point(j));
                entries += form.transpose();
                if extended {
                    let mut entries = jacobian.fixed_view_mut::<1, N>(column, n);
                    entries += form.transpose();
                }
                // The impulse turns with the point it acts at: Q_j (internal), or q_k.
                if j < s {
                    let mut block = jacobian.fixed_view_mut::<N, N>(row, self.point(j));
                    block += curvature * lambda;
                }
                if extended {
                    let mut block = jacobian.fixed_view_mut::<N, N>(row, n);
                    block += curvature * lambda;
                }
            }
        }
        (scale.max(f64::MIN_POSITIVE), impulse)
    }

    /// `∂T_j/∂u` for the rows `j = 0..=s` of the step solved by `x` (the inputs enter through
    /// the forces), `(n + N) × inputs` in the rows' order of [`rows`](Self::rows) extended.
    fn input_rows(&self, state: &State<N>, x: &DVector<f64>) -> DMatrix<f64> {
        let (s, h, n) = (self.degree(), self.h, self.unknowns());
        let inputs = self.inputs.len();
        let mut rows = DMatrix::zeros(n + N, inputs);
        if !S::FORCES {
            return rows;
        }
        for i in 0..self.nodes() {
            let (c, b) = (self.quadrature.nodes()[i], self.quadrature.weights()[i]);
            let position = &self.bases[i].position;
            let q = (state.q + self.combination(x, position)).map(Dual64::from);
            let p = x.fixed_rows::<N>(self.node_momentum(i)).map(Dual64::from);
            for m in 0..inputs {
                let seeded: Vec<Dual64> = (0..inputs)
                    .map(|k| Dual64::new(self.inputs[k], if k == m { 1.0 } else { 0.0 }))
                    .collect();
                let f = self.system.force(&q, &p, state.t + c * h, &seeded);
                for (j, &weight) in position.iter().enumerate() {
                    let row = if j < s { j * N } else { n };
                    for r in 0..N {
                        rows[(row + r, m)] += f[r].eps * (h * b * weight);
                    }
                }
            }
        }
        rows
    }

    /// `∂H/∂p` at `(q, p̃)`, with `p̃` the [`allowed_momentum`](Self::allowed_momentum).
    fn velocity_at(&self, q: &SVector<f64, N>, p: &SVector<f64, N>) -> SVector<f64, N> {
        derivatives::directional_gradient(
            &Hamiltonian(&self.system),
            q,
            &self.allowed_momentum(q, p),
            derivatives::Seed::VELOCITY,
        )
    }

    /// `p̃ = p + C(q)ᵀν` with `C(q) ∂H/∂p(q, p̃) = 0`, `C` the rows `dg_b(q)` and `A_a(q)`: the
    /// momentum whose velocity the constraints allow (`p` itself without constraints). The
    /// step holds `g` as SHAKE does and puts part of the one-forms' impulse on `p_{k+1}`, so
    /// `p_{k+1}` keeps a part of order `h` that the next step's multipliers absorb: the state's
    /// velocity and energy are read at `p̃`, as the Lagrangian route reads them at the velocity
    /// its constrained Legendre transform gives. By Newton's method on `ν` (one step where `H`
    /// is quadratic in `p`); `p` where that does not converge.
    fn allowed_momentum(&self, q: &SVector<f64, N>, p: &SVector<f64, N>) -> SVector<f64, N> {
        if S::HOLONOMIC + S::ONE_FORMS == 0 {
            return *p;
        }
        let forms: Vec<SVector<f64, N>> = (0..S::HOLONOMIC)
            .map(|b| derivatives::scalar_hessian(q, |q| self.system.holonomic(q, b)).1)
            .chain((0..S::ONE_FORMS).map(|a| self.system.one_form(q, a)))
            .collect();
        if forms.iter().any(|f| !f.iter().all(|x| x.is_finite())) {
            // A constraint form that is not finite here allows no momentum: NaN, which the
            // velocity's finite checks refuse.
            return SVector::from_element(f64::NAN);
        }
        let hamiltonian = Hamiltonian(&self.system);
        let mut allowed = *p;
        for _ in 0..20 {
            let second = derivatives::hessian(&hamiltonian, q, &allowed);
            let count = forms.len();
            let rates = DVector::from_fn(count, |b, _| forms[b].dot(&second.gradient.v));
            let scale = forms
                .iter()
                .map(|f| f.abs().dot(&second.gradient.v.abs()))
                .fold(f64::MIN_POSITIVE, f64::max);
            if rates.amax() <= 4.0 * f64::EPSILON * scale {
                return allowed;
            }
            let matrix =
                DMatrix::from_fn(count, count, |b, c| forms[b].dot(&(second.vv * forms[c])));
            let Some(nu) = matrix.lu().solve(&rates) else {
                return *p;
            };
            let correction: SVector<f64, N> =
                forms.iter().zip(nu.iter()).map(|(f, nu)| f * *nu).sum();
            allowed -= correction;
            if correction.amax() <= 4.0 * f64::EPSILON * allowed.amax() {
                return allowed;
            }
        }
        if allowed.iter().all(|v| v.is_finite()) {
            allowed
        } else {
            *p
        }
    }
}

/// Whether `matrix` is singular (a pivot below 1e-13 of its largest entry, or all zero).
fn singular<const N: usize>(matrix: &SMatrix<f64, N, N>) -> bool {
    let mut lu = DMatrix::from_fn(N, N, |r, c| matrix[(r, c)]);
    let mut pivots = vec![0; N];
    matrix.amax() == 0.0 || lu::factorise(&mut lu, &mut pivots, &mut [0.0; N], 1e-13).is_err()
}

/// Fails naming `what` where a component of `x` is not finite.
fn finite<const N: usize>(what: &str, x: &SVector<f64, N>) -> Result<(), DiracError> {
    match x.iter().find(|x| !x.is_finite()) {
        Some(&value) => Err(DiracError::NonFinite {
            what: what.into(),
            value,
        }),
        None => Ok(()),
    }
}

impl<S: HamiltonianSystem<N>, const N: usize> StepEquations<N> for Hamilton<S, N> {
    type System = S;
    type Manifold = Vectors;
    const NAME: &'static str = "the discrete Hamilton's equations";
    const VELOCITY: &'static str = "the velocity v = ∂H/∂p";
    const FORCED: bool = S::FORCES;

    fn system(&self) -> &S {
        &self.system
    }

    fn h(&self) -> f64 {
        self.h
    }

    fn method(&self) -> String {
        format!("discrete Hamiltonian, {}", self.quadrature.name())
    }

    fn unknowns(&self) -> usize {
        (self.degree() + self.nodes()) * N + self.multipliers()
    }

    fn multipliers(&self) -> usize {
        self.sites.len() * S::ONE_FORMS + self.degree() * S::HOLONOMIC
    }

    fn multiplier_names(&self) -> Vec<String> {
        let nodes = self.sites.len() > 1 || self.degree() > 1;
        (0..self.sites.len())
            .flat_map(|k| {
                (0..S::ONE_FORMS).map(move |a| match nodes {
                    false => format!("mu_{a}"),
                    true => format!("mu_{a}_node_{}", k + 1),
                })
            })
            .chain(
                (1..self.degree()).flat_map(|j| {
                    (0..S::HOLONOMIC).map(move |b| format!("lambda_{b}_internal_{j}"))
                }),
            )
            .chain((0..S::HOLONOMIC).map(|b| format!("lambda_{b}")))
            .collect()
    }

    fn coordinate_name(&self, i: usize) -> String {
        self.system.coordinate_name(i)
    }

    /// The position, the momentum and `H` finite, the position on the holonomic constraints,
    /// and the velocity `∂H/∂p` tangent to them and allowed by the one-forms, to the relative
    /// `tolerance`.
    fn check_start(&self, state: &State<N>, tolerance: f64) -> Result<(), DiracError> {
        finite("initial position", &state.q)?;
        finite("initial momentum", &state.p)?;
        let energy = self.system.hamiltonian(&state.q, &state.p);
        if !energy.is_finite() {
            return Err(DiracError::NonFinite {
                what: "the Hamiltonian at the initial state (is (q0, p0) in its domain?)".into(),
                value: energy,
            });
        }
        let second = derivatives::hessian(&Hamiltonian(&self.system), &state.q, &state.p);
        let v = second.gradient.v;
        finite("initial velocity ∂H/∂p", &v)?;
        if self.nodes() > self.degree() && singular(&second.vv) {
            return Err(DiracError::InvalidQuadrature(format!(
                "{}: ∂²H/∂p² is singular at the initial state, so the velocity conditions \
                 Q̇(c_i) = ∂H/∂p at its {} nodes fix a path of degree {} on their own: use a \
                 Gauss rule with as many nodes as the degree (galerkin(s))",
                self.quadrature.name(),
                self.nodes(),
                self.degree()
            )));
        }
        // The velocity of the momentum whose velocity the constraints allow (the rest is the
        // next step's multipliers' to absorb, see `allowed_momentum`).
        let v = self.velocity_at(&state.q, &state.p);
        for b in 0..S::HOLONOMIC {
            let (g, form, _) =
                derivatives::scalar_hessian(&state.q, |q| self.system.holonomic(q, b));
            if exceeds(
                g.abs(),
                tolerance * form.abs().dot(&state.q.abs()).max(f64::MIN_POSITIVE),
            ) {
                return Err(DiracError::InconsistentInitialState(format!(
                    "the initial position violates holonomic constraint {b}: g = {g:.3e}"
                )));
            }
            let rate = form.dot(&v);
            if exceeds(
                rate.abs(),
                tolerance * form.abs().dot(&v.abs()).max(f64::MIN_POSITIVE),
            ) {
                return Err(DiracError::InconsistentInitialState(format!(
                    "holonomic constraint {b} at the initial state: no momentum p + dg(q)ᵀν \
                     gives a velocity ∂H/∂p tangent to it (dg(q) ∂H/∂p = {rate:.3e})"
                )));
            }
        }
        for a in 0..S::ONE_FORMS {
            let form = self.system.one_form(&state.q, a);
            let scale = form.abs().dot(&v.abs()).max(form.amax() * v.amax());
            let value = form.dot(&v);
            if exceeds(value.abs(), tolerance * scale.max(f64::MIN_POSITIVE)) && value != 0.0 {
                return Err(DiracError::InconsistentInitialState(format!(
                    "one-form {a} at the initial state: no momentum p + C(q)ᵀν gives a velocity \
                     ∂H/∂p the one-forms allow (A(q) ∂H/∂p = {value:e})"
                )));
            }
        }
        Ok(())
    }

    fn predict(&mut self, state: &State<N>, previous: Option<&DVector<f64>>, x: &mut DVector<f64>) {
        if let Some(previous) = previous.filter(|p| p.len() == x.len()) {
            x.copy_from(previous);
            return;
        }
        x.fill(0.0);
        let s = self.degree();
        for j in 1..=s {
            let c = j as f64 / s as f64;
            x.fixed_rows_mut::<N>(self.point(j))
                .copy_from(&(state.velocity * (c * self.h)));
        }
        for i in 0..self.nodes() {
            x.fixed_rows_mut::<N>(self.node_momentum(i))
                .copy_from(&state.p);
        }
    }

    fn assemble(
        &mut self,
        state: &State<N>,
        x: &DVector<f64>,
        residual: &mut DVector<f64>,
        jacobian: Option<&mut DMatrix<f64>>,
    ) -> f64 {
        let (scale, impulse) = self.rows(state, x, residual, jacobian, false);
        self.impulse = impulse;
        scale
    }

    /// A Jacobian takes three hyper-dual passes of `H` per node (about `(N + 1)²` numbers per
    /// operation) where the residual takes two first-order passes (`N + 1` each). One-forms held
    /// at the Gauss nodes slow a kept Jacobian's convergence more than it saves (measured on the
    /// knife edge with `galerkin(2)`: 6.7 µs a step against 5.5 µs with Newton's method), so
    /// there it counts as a residual.
    fn jacobian_cost(&self) -> f64 {
        match self.sites.len() {
            0 | 1 => 1.5 * (N + 1) as f64,
            _ => 1.0,
        }
    }

    /// `q_{k+1} = q_k + (Q_s − q_k)` and `p_{k+1} = p_k + impulse` (compensated sums), the
    /// velocity `∂H/∂p` there.
    fn advance(
        &self,
        state: &State<N>,
        x: &DVector<f64>,
        step: u64,
    ) -> Result<State<N>, DiracError> {
        let mut next = *state;
        let xi = x.fixed_rows::<N>(self.point(self.degree())).into_owned();
        compensated_add(&mut next.q, &mut next.q_carry, &xi);
        compensated_add(&mut next.p, &mut next.p_carry, &self.impulse);
        finite("new position", &next.q)?;
        finite("new momentum", &next.p)?;
        let energy = self.system.hamiltonian(&next.q, &next.p);
        if !energy.is_finite() {
            return Err(DiracError::NonFinite {
                what: format!(
                    "the Hamiltonian at the end of step {step} (the step leaves its domain or \
                     overflows; try a smaller step)"
                ),
                value: energy,
            });
        }
        next.velocity = self.velocity_at(&next.q, &next.p);
        // ∂H/∂p can leave its domain where H does not (|p| at p = 0).
        finite("new velocity ∂H/∂p", &next.velocity)?;
        Ok(next)
    }

    /// The worst `|A_a(Q_c) Q̇_c h|` over the sites of the step solved by `x` (a displacement,
    /// as the Lagrangian route reports it) and `|g_b(Q_j)|` over the path's points.
    fn violation(&self, state: &State<N>, _to: &State<N>, x: &DVector<f64>) -> f64 {
        let mut worst: f64 = 0.0;
        for site in &self.sites {
            let q = state.q + self.combination(x, &site.position);
            let displacement = self.combination(x, &site.rate);
            for a in 0..S::ONE_FORMS {
                worst = worst.max(self.system.one_form(&q, a).dot(&displacement).abs());
            }
        }
        for j in 1..=self.degree() {
            let point = state.q + x.fixed_rows::<N>(self.point(j));
            for b in 0..S::HOLONOMIC {
                worst = worst.max(self.system.holonomic(&point, b).abs());
            }
        }
        worst
    }

    /// By the implicit function theorem on the rows `R(x; q_k, p_k, u) = 0` with Newton's
    /// factorised `J = ∂R/∂x`: `∂x/∂z = −J⁻¹ ∂R/∂z` for `z = (q_k, p_k, u)`, where `q_k` moves
    /// every point of the path with weight 1, `p_k` enters the first row, and the inputs enter
    /// through the forces. Then `q_{k+1} = q_k + (Q_s − q_k)` and `p_{k+1} = T_s`, the row of
    /// `Q_s`, are differentiated along.
    fn linearise(
        &self,
        state: &State<N>,
        x: &DVector<f64>,
        newton: &Newton,
    ) -> Result<StepDerivatives<N>, DiracError> {
        let (n, inputs) = (self.unknowns(), self.inputs.len());
        let mut rows = DVector::zeros(n + N);
        let mut jacobian = DMatrix::zeros(n + N, n + N);
        self.rows(state, x, &mut rows, Some(&mut jacobian), true);
        // ∂R/∂z with the end rows T_s below: columns q_k, p_k, u.
        let mut dr = DMatrix::zeros(n + N, 2 * N + inputs);
        dr.columns_mut(0, N).copy_from(&jacobian.columns(n, N));
        for i in 0..N {
            dr[(i, N + i)] = 1.0;
        }
        dr.columns_mut(2 * N, inputs)
            .copy_from(&self.input_rows(state, x));
        let mut dx = dr.rows(0, n).clone_owned();
        newton
            .implicit_derivatives(x, &mut dx)
            .ok_or_else(crate::step::euler_lagrange::stale_factorisation)?;
        let mut dq = dx.rows(self.point(self.degree()), N).clone_owned();
        for i in 0..N {
            dq[(i, i)] += 1.0;
        }
        let dp = dr.rows(n, N) + jacobian.view((n, 0), (N, n)) * &dx;
        if !dq.iter().chain(dp.iter()).all(|v| v.is_finite()) {
            return Err(DiracError::NonFinite {
                what: "a derivative of the step map".into(),
                value: f64::NAN,
            });
        }
        let block =
            |m: &DMatrix<f64>, c: usize| SMatrix::<f64, N, N>::from_fn(|i, j| m[(i, c + j)]);
        Ok(StepDerivatives {
            q_q: block(&dq, 0),
            q_p: block(&dq, N),
            p_q: block(&dp, 0),
            p_p: block(&dp, N),
            q_u: dq.columns(2 * N, inputs).clone_owned(),
            p_u: dp.columns(2 * N, inputs).clone_owned(),
            pivot_ratio: newton.pivot_ratio(),
        })
    }

    fn first_multiplier(&self) -> usize {
        (self.degree() + self.nodes()) * N
    }

    fn unknown_name(&self, column: usize) -> String {
        let (s, m) = (self.degree(), self.nodes());
        let name = |i: usize| self.coordinate_name(i % N);
        match column / N {
            block if block < s && block + 1 == s => format!("{} (q_{{k+1}})", name(column)),
            block if block < s => format!("{} (internal point {})", name(column), block + 1),
            block if block < s + m => format!(
                "the momentum of {} at quadrature node {}",
                name(column),
                block - s + 1
            ),
            _ if column >= self.holonomic_multiplier(1, 0) => {
                let c = column - self.holonomic_multiplier(1, 0);
                let (j, b) = (c / S::HOLONOMIC.max(1) + 1, c % S::HOLONOMIC.max(1));
                match j == s {
                    true => format!("the multiplier of holonomic constraint {b}"),
                    false => {
                        format!("the multiplier of holonomic constraint {b} at internal point {j}")
                    }
                }
            }
            _ => {
                let c = column - self.first_multiplier();
                let (k, a) = (c / S::ONE_FORMS.max(1), c % S::ONE_FORMS.max(1));
                match self.sites.len() {
                    1 if s == 1 => format!("the multiplier of one-form {a}"),
                    _ => format!(
                        "the multiplier of one-form {a} at quadrature node {}",
                        k + 1
                    ),
                }
            }
        }
    }

    /// `∂H/∂p(q, p)`: explicit, no solve (with constraints, at the momentum whose velocity they
    /// allow).
    fn velocity(
        &self,
        _newton: &mut Newton,
        _t: f64,
        q: &SVector<f64, N>,
        p: &SVector<f64, N>,
        _guess: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, NewtonFailure> {
        let v = self.velocity_at(q, p);
        if v.iter().all(|x| x.is_finite()) {
            Ok(v)
        } else {
            Err(NewtonFailure::NonFinite)
        }
    }

    /// The momentum whose velocity `∂H/∂p(q, p)` is `v`, by Newton's method on the Legendre
    /// map from `p = v`; fails where `∂²H/∂p²` is singular (no Lagrangian counterpart: start
    /// from a momentum) or where the iteration does not converge.
    fn momentum(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, DiracError> {
        finite("initial position", q)?;
        finite("initial velocity", v)?;
        let hamiltonian = Hamiltonian(&self.system);
        let mut p = *v;
        let singular_map = || {
            DiracError::Unsupported(
                "a start from a velocity where ∂²H/∂p² is singular (the Legendre map \
                 p ↦ ∂H/∂p does not determine p there); start from a momentum"
                    .into(),
            )
        };
        for _ in 0..50 {
            let second = derivatives::hessian(&hamiltonian, q, &p);
            let mut matrix = DMatrix::from_fn(N, N, |r, c| second.vv[(r, c)]);
            let mut pivots = vec![0; N];
            if second.vv.amax() == 0.0
                || lu::factorise(&mut matrix, &mut pivots, &mut [0.0; N], 1e-13).is_err()
            {
                return Err(singular_map());
            }
            let mut step = second.gradient.v - v;
            if step.amax() <= 4.0 * f64::EPSILON * (1.0 + v.amax()) {
                finite("initial momentum", &p)?;
                return Ok(p);
            }
            lu::solve(&matrix, &pivots, step.as_mut_slice());
            p -= step;
            if step.amax() <= 4.0 * f64::EPSILON * (1.0 + p.amax()) {
                finite("initial momentum", &p)?;
                return Ok(p);
            }
        }
        Err(DiracError::InconsistentInitialState(
            "no momentum p with ∂H/∂p(q, p) = v was found from p = v in 50 Newton iterations; \
             start from a momentum"
                .into(),
        ))
    }

    /// The forces' work along the step's path, `h Σ_i b_i F(Q(c_i), P_i, t_i, u) ∘ Q̇(c_i)`
    /// (see [`StepWork`]); the constraints' only where there are none.
    fn work(&self, state: &State<N>, x: &DVector<f64>) -> Option<StepWork<N>> {
        let h = self.h;
        let mut forces = SVector::zeros();
        if S::FORCES {
            for i in 0..self.nodes() {
                let (c, b) = (self.quadrature.nodes()[i], self.quadrature.weights()[i]);
                let (_, q, v, p) = self.node(state, x, i);
                let (f, _, _) = self.force(&q, &p, state.t + c * h, false);
                forces += f.component_mul(&v) * (h * b);
            }
        }
        let unconstrained = S::ONE_FORMS == 0 && S::HOLONOMIC == 0;
        Some(StepWork {
            forces,
            constraints: unconstrained.then(SVector::zeros),
        })
    }

    /// `H(q, p̃)` at the momentum `p̃ = p + C(q)ᵀν` whose velocity the constraints allow
    /// (`C ∂H/∂p(q, p̃) = 0`, `C` the rows `dg_b` and `A_a`; `H(q, p)` without constraints).
    fn energy(&self, q: &SVector<f64, N>, p: &SVector<f64, N>, _v: &SVector<f64, N>) -> f64 {
        self.system.hamiltonian(q, &self.allowed_momentum(q, p))
    }

    fn inputs(&self) -> &[f64] {
        &self.inputs
    }

    fn inputs_mut(&mut self) -> &mut [f64] {
        &mut self.inputs
    }

    fn input_name(&self, i: usize) -> String {
        self.system.input_name(i)
    }
}
