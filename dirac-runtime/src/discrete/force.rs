//! Discrete Lagrange–d'Alembert forces: the virtual work of `F(q, v, t, u)` along the step's path,
//! `Σ_i h b_i F(q_i, v_i, t_i) · δq(c_i)`, gives the force on point `ξ_j`:
//! `f_j = h Σ_i b_i ℓ_j(c_i) F̃_i`, with `F̃ = (T_ξ R_{q_k})ᵀ F` the force read in the chart (on
//! `Rⁿ`, `F` itself; for the midpoint rule `f^- = f^+ = (h/2) F(q̄, Δq/h)`).

use nalgebra::{Const, DMatrix, DVector, SMatrix, SVector, U1};

use crate::base::scalar::Scalar;
use crate::space::configuration_space::{ConfigurationSpace, Point, StepCovectors};
use crate::space::manifold::{Manifold, Vectors};
use num_dual::{Dual64, HyperDual64};

use crate::discrete::discrete_lagrangian::{DiscreteLagrangian, SlotBlocks};
use crate::model::derivatives::{Dual, lift};
use crate::model::system::DiracSystem;

impl<S: DiracSystem<N, C::Manifold>, C: ConfigurationSpace<N>, const N: usize>
    DiscreteLagrangian<S, N, C>
{
    /// Adds `f_j` to the residual rows of points `j = 0..s−1` and their derivatives in the
    /// unknowns `ξ_1..ξ_s` to the Jacobian; returns the forces' slot covectors (total and on the
    /// end point) and the size of their terms. `t` is the time at the start of the step.
    pub(crate) fn add_forces(
        &self,
        base: &Point<C, N, f64>,
        increments: &[SVector<f64, N>],
        t: f64,
        inputs: &[Dual<N>],
        residual: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> (StepCovectors<N>, f64) {
        let quad = self.quadrature();
        let (h, s) = (self.h(), quad.degree());
        let space = self.space();
        let mut impulse = SVector::zeros();
        let mut end = SVector::zeros();
        let mut scale = 0.0_f64;
        for (i, (&b, &c)) in quad.weights().iter().zip(quad.nodes()).enumerate() {
            let w = h * b;
            let (xi, xi_dot) = self.node(i, increments);
            for k in 1..=s {
                // F̃ along the direction of the unknown ξ_k: value and ∂F̃/∂ξ_k.
                let (a, d) = (quad.ell(i, k), quad.ell_prime(i, k) / h);
                let (xi, xi_dot) = (lift(&xi, a), lift(&xi_dot, d));
                let q = space.retract(base, &xi);
                let v = space.push_forward(base, &xi, &xi_dot);
                let f = space.pull_back(base, &xi, &self.system().force(&q, &v, t + c * h, inputs));
                let value = f.map(|x| x.re);
                let derivative = SMatrix::<f64, N, N>::from_fn(|m, l| {
                    f[m].eps.unwrap_generic(Const::<N>, U1)[l]
                });
                if k == 1 {
                    impulse += value * w;
                    end += value * (w * quad.ell(i, s));
                    scale = scale.max(value.amax() * w);
                }
                for j in 0..s {
                    let lj = quad.ell(i, j);
                    if k == 1 {
                        let mut r = residual.rows_mut(j * N, N);
                        r += value * (w * lj);
                    }
                    let mut block = jacobian.fixed_view_mut::<N, N>(j * N, (k - 1) * N);
                    block += derivative * (w * lj);
                }
            }
        }
        (StepCovectors { impulse, end }, scale)
    }

    /// The forces on every point of the step, `f_j = h Σ_i b_i ℓ_j(c_i) F̃_i` (`j = 0..=s`), in the
    /// chart at `base` carried by `g(δ)` to a start at `R_q(δ)`
    /// ([`ConfigurationSpace::carried`]), over any scalar: their derivatives in `δ`, the
    /// points `ξ_1..ξ_s` and the inputs `u` by dual numbers. `None` where the space's charts
    /// are not carried. `t` is the time at the start of the step.
    pub(crate) fn carried_forces<D: Scalar>(
        &self,
        base: &Point<C, N, f64>,
        points: &[SVector<D, N>],
        delta: &SVector<D, N>,
        t: f64,
        inputs: &[D],
    ) -> Option<Vec<SVector<D, N>>> {
        let quad = self.quadrature();
        let (h, s, space) = (self.h(), quad.degree(), self.space());
        let zero = D::from(0.0);
        let mut forces = vec![SVector::<D, N>::from_element(zero); s + 1];
        for (i, (&b, &c)) in quad.weights().iter().zip(quad.nodes()).enumerate() {
            let mut xi = SVector::<D, N>::from_element(zero);
            let mut xi_dot = SVector::<D, N>::from_element(zero);
            for (j, point) in points.iter().enumerate() {
                let (a, d) = (quad.ell(i, j + 1), quad.ell_prime(i, j + 1) / h);
                xi += point * D::from(a);
                xi_dot += point * D::from(d);
            }
            let point = space.retract(base, &xi);
            let v = space.push_forward(base, &xi, &xi_dot);
            let (q, v) = space.carried(base, delta, &point, &v)?;
            let force = self.system().force(&q, &v, t + c * h, inputs);
            // F̃: the force paired with the carried chart's coordinate directions.
            let mut pulled = SVector::<D, N>::from_element(zero);
            for r in 0..N {
                let e = SVector::<D, N>::from_fn(|k, _| D::from(if k == r { 1.0 } else { 0.0 }));
                let direction = space.push_forward(base, &xi, &e);
                let (_, direction) = space.carried(base, delta, &point, &direction)?;
                pulled[r] = <C::Manifold as Manifold<N>>::pair(&force, &direction);
            }
            for (j, f) in forces.iter_mut().enumerate() {
                *f += pulled * D::from(h * b * quad.ell(i, j));
            }
        }
        Some(forces)
    }

    /// The forces' work over the step on each chart coordinate `r`,
    /// `h Σ_i b_i F̃(q_i, v_i, t_i, u)_r ξ̇_{i,r}`: the work `∫ ⟨F, q̇⟩ dt` along the step's path
    /// by the quadrature, split by coordinate, at the increments `ξ_1..ξ_s` from `base`; `t` is
    /// the time at the start of the step.
    pub(crate) fn force_work(
        &self,
        base: &Point<C, N, f64>,
        increments: &[SVector<f64, N>],
        t: f64,
        inputs: &[f64],
    ) -> SVector<f64, N> {
        let quad = self.quadrature();
        let (h, space) = (self.h(), self.space());
        let mut work = SVector::zeros();
        for (i, (&b, &c)) in quad.weights().iter().zip(quad.nodes()).enumerate() {
            let (xi, xi_dot) = self.node(i, increments);
            let q = space.retract(base, &xi);
            let v = space.push_forward(base, &xi, &xi_dot);
            let f = space.pull_back(base, &xi, &self.system().force(&q, &v, t + c * h, inputs));
            work += f.component_mul(&xi_dot) * (h * b);
        }
        work
    }
}

impl<S: DiracSystem<N>, C: ConfigurationSpace<N, Manifold = Vectors>, const N: usize>
    DiscreteLagrangian<S, N, C>
{
    /// Adds the forces' slot derivatives `∂f_j/∂ξ_m` (`j, m = 0..=s`, `ξ_0 = 0`) to `blocks`:
    /// `h Σ_i b_i ℓ_j(c_i) (∂_q F ℓ_m(c_i) + ∂_v F ℓ'_m(c_i)/h)` at the nodes, on a translation
    /// chart (`Rⁿ`).
    pub(crate) fn add_force_slot_derivatives(
        &self,
        base: &SVector<f64, N>,
        increments: &[SVector<f64, N>],
        t: f64,
        inputs: &[f64],
        blocks: &mut SlotBlocks<N>,
    ) {
        let quad = self.quadrature();
        let h = self.h();
        let inputs: Vec<Dual<N>> = inputs.iter().map(|&u| Dual::from(u)).collect();
        let inputs = &inputs[..];
        let jacobian = |f: SVector<Dual<N>, N>| {
            SMatrix::<f64, N, N>::from_fn(|m, l| f[m].eps.unwrap_generic(Const::<N>, U1)[l])
        };
        for (i, (&b, &c)) in quad.weights().iter().zip(quad.nodes()).enumerate() {
            let w = h * b;
            let (xi, xi_dot) = self.node(i, increments);
            let q = base + xi;
            let time = t + c * h;
            let f_q =
                jacobian(
                    self.system()
                        .force(&lift(&q, 1.0), &lift(&xi_dot, 0.0), time, inputs),
                );
            let f_v =
                jacobian(
                    self.system()
                        .force(&lift(&q, 0.0), &lift(&xi_dot, 1.0), time, inputs),
                );
            blocks.add(|j, m| {
                (f_q * quad.ell(i, m) + f_v * (quad.ell_prime(i, m) / h)) * (w * quad.ell(i, j))
            });
        }
    }

    /// The forces' derivatives in the inputs, `∂f_j/∂u` (`j = 0..=s`, `N × inputs` each):
    /// `h Σ_i b_i ℓ_j(c_i) ∂F/∂u` at the nodes, one input direction at a time.
    pub(crate) fn force_input_derivatives(
        &self,
        base: &SVector<f64, N>,
        increments: &[SVector<f64, N>],
        t: f64,
        inputs: &[f64],
    ) -> Vec<DMatrix<f64>> {
        let quad = self.quadrature();
        let (h, s) = (self.h(), quad.degree());
        let mut blocks = vec![DMatrix::zeros(N, inputs.len()); s + 1];
        for (i, (&b, &c)) in quad.weights().iter().zip(quad.nodes()).enumerate() {
            let w = h * b;
            let (xi, xi_dot) = self.node(i, increments);
            let q = (base + xi).map(Dual64::from);
            let v = xi_dot.map(Dual64::from);
            for m in 0..inputs.len() {
                let seeded: Vec<Dual64> = inputs
                    .iter()
                    .enumerate()
                    .map(|(k, &u)| Dual64::new(u, if k == m { 1.0 } else { 0.0 }))
                    .collect();
                let f = self.system().force(&q, &v, t + c * h, &seeded);
                for (j, block) in blocks.iter_mut().enumerate() {
                    for r in 0..N {
                        block[(r, m)] += f[r].eps * (w * quad.ell(i, j));
                    }
                }
            }
        }
        blocks
    }

    /// The forces' second derivatives along two displacements of the step's points (`d[k][m]`
    /// moves point `m`, `m = 0..=s`) on a translation chart: `D²f_j[d_0, d_1]` for `j = 0..=s`,
    /// `h Σ_i b_i ℓ_j(c_i) D²F(q_i, v_i)` along the node displacements, by hyper-dual numbers.
    pub(crate) fn force_second_derivatives(
        &self,
        base: &SVector<f64, N>,
        increments: &[SVector<f64, N>],
        t: f64,
        inputs: &[f64],
        d: [&[SVector<f64, N>]; 2],
    ) -> Vec<SVector<f64, N>> {
        let quad = self.quadrature();
        let (h, s) = (self.h(), quad.degree());
        let inputs: Vec<HyperDual64> = inputs.iter().map(|&u| HyperDual64::from(u)).collect();
        let mut out = vec![SVector::<f64, N>::zeros(); s + 1];
        for (i, (&b, &c)) in quad.weights().iter().zip(quad.nodes()).enumerate() {
            let w = h * b;
            let (xi, xi_dot) = self.node(i, increments);
            let [(q1, v1), (q2, v2)] = d.map(|points| self.node_displacement(i, points));
            let q = base + xi;
            let lift = |x: &SVector<f64, N>, a: &SVector<f64, N>, b: &SVector<f64, N>| {
                SVector::<HyperDual64, N>::from_fn(|r, _| HyperDual64::new(x[r], a[r], b[r], 0.0))
            };
            let f = self.system().force(
                &lift(&q, &q1, &q2),
                &lift(&xi_dot, &v1, &v2),
                t + c * h,
                &inputs,
            );
            let second = f.map(|x| x.eps1eps2);
            for (j, total) in out.iter_mut().enumerate() {
                *total += second * (w * quad.ell(i, j));
            }
        }
        out
    }
}
