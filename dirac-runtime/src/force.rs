//! Discrete Lagrange–d'Alembert forces: the virtual work of `F(q, v, t, u)` along the step's path,
//! `Σ_i h b_i F(q_i, v_i, t_i) · δq(c_i)`, gives the force on point `Q_j`:
//! `f_j = h Σ_i b_i ℓ_j(c_i) F_i` (for the midpoint rule `f^- = f^+ = (h/2) F(q̄, Δq/h)`).

use nalgebra::{Const, DMatrix, DVector, SMatrix, SVector, U1};

use crate::derivatives::lift;
use crate::discrete_lagrangian::DiscreteLagrangian;
use crate::system::DiracSystem;

impl<S: DiracSystem<N>, const N: usize> DiscreteLagrangian<S, N> {
    /// Adds `f_j` to the residual rows of points `j = 0..s−1` and their derivatives in the
    /// unknowns `Z_1..Z_s` to the Jacobian; returns the total impulse `Σ_j f_j = h Σ_i b_i F_i`
    /// and the size of its terms. `t` is the time at the start of the step.
    pub(crate) fn add_forces(
        &self,
        base: &SVector<f64, N>,
        increments: &[SVector<f64, N>],
        t: f64,
        inputs: &[f64],
        residual: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> (SVector<f64, N>, f64) {
        let quad = self.quadrature();
        let (h, s) = (self.h(), quad.degree());
        let mut impulse = SVector::zeros();
        let mut scale = 0.0_f64;
        for (i, (&b, &c)) in quad.weights().iter().zip(quad.nodes()).enumerate() {
            let w = h * b;
            let (q, v) = self.node(i, base, increments);
            for k in 1..=s {
                // F along the direction of the unknown Z_k: value and ∂F/∂Z_k.
                let (a, d) = (quad.ell(i, k), quad.ell_prime(i, k) / h);
                let f = self
                    .system()
                    .force(&lift(&q, a), &lift(&v, d), t + c * h, inputs);
                let value = f.map(|x| x.re);
                let derivative = SMatrix::<f64, N, N>::from_fn(|m, l| {
                    f[m].eps.unwrap_generic(Const::<N>, U1)[l]
                });
                if k == 1 {
                    impulse += value * w;
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
        (impulse, scale)
    }
}
