//! The performance limit of the generated steppers: steps written by hand with analytic
//! derivatives of `L` and of the one-forms, solved by the same Newton solver from the same
//! predictor (the cubic through the last four solutions). Three of them: the double pendulum
//! under the midpoint rule and under `galerkin(2)`, and the knife edge under the midpoint rule
//! with its one-form at the midpoint.

use dirac::nalgebra::{DMatrix, DVector, SMatrix};
use dirac::{Newton, NewtonFailure, NewtonOptions};

use super::double_pendulum::DoublePendulum;
use super::knife_edge::KnifeEdge;

/// The equations of one step on `N` coordinates, written by hand: the unknowns are the path's
/// points as increments from `q_k` (the end point last among them), then the multipliers.
pub trait HandEquations<const N: usize> {
    /// Number of unknowns.
    const UNKNOWNS: usize;
    /// Where the end point's increment `q_{k+1} − q_k` starts in the unknowns.
    const END: usize;

    /// The momentum `∂L/∂v` at `(q, v)`.
    fn momentum(&self, q: &SVector<N>, v: &SVector<N>) -> SVector<N>;

    /// The residual at `x` of the step from `(q0, p0)` over `h`, with its Jacobian (added into
    /// the zeroed matrix Newton hands over) when asked for; writes `p_{k+1}` into `p1` and returns the size of the residual's terms.
    #[allow(clippy::too_many_arguments)]
    fn assemble(
        &self,
        h: f64,
        q0: &SVector<N>,
        p0: &SVector<N>,
        x: &DVector<f64>,
        r: &mut DVector<f64>,
        j: Option<&mut DMatrix<f64>>,
        p1: &mut SVector<N>,
    ) -> f64;
}

/// A vector of `N` reals.
type SVector<const N: usize> = dirac::nalgebra::SVector<f64, N>;

/// A stepper written by hand around equations `E`.
pub struct HandStepper<E, const N: usize> {
    pub equations: E,
    pub h: f64,
    pub q: SVector<N>,
    pub p: SVector<N>,
    /// Up to four accepted solutions, newest first, and how many there are.
    solutions: [DVector<f64>; 4],
    count: usize,
    newton: Newton,
    x: DVector<f64>,
    /// Newton evaluations of the last step.
    pub last_iterations: usize,
}

impl<E: HandEquations<N>, const N: usize> HandStepper<E, N> {
    /// Starts at `(q0, v0)` with `p0 = ∂L/∂v`; the first predictor is the path along `v0`.
    pub fn new(equations: E, h: f64, q0: SVector<N>, v0: SVector<N>) -> Self {
        let p = equations.momentum(&q0, &v0);
        let n = E::UNKNOWNS;
        let mut first = DVector::zeros(n);
        let points = E::END / N + 1;
        for j in 1..=points {
            let c = j as f64 / points as f64;
            first.rows_mut((j - 1) * N, N).copy_from(&(v0 * (c * h)));
        }
        Self {
            equations,
            h,
            q: q0,
            p,
            solutions: [
                first,
                DVector::zeros(n),
                DVector::zeros(n),
                DVector::zeros(n),
            ],
            count: 0,
            newton: Newton::new(n, NewtonOptions::default())
                .expect("the default options are valid"),
            x: DVector::zeros(n),
            last_iterations: 0,
        }
    }

    /// One step.
    pub fn step(&mut self) -> Result<(), NewtonFailure> {
        const WEIGHTS: [&[f64]; 5] = [
            &[1.0],
            &[1.0],
            &[2.0, -1.0],
            &[3.0, -3.0, 1.0],
            &[4.0, -6.0, 4.0, -1.0],
        ];
        self.x.fill(0.0);
        for (w, s) in WEIGHTS[self.count].iter().zip(&self.solutions) {
            self.x.axpy(*w, s, 1.0);
        }
        let (q0, p0, h, equations) = (self.q, self.p, self.h, &self.equations);
        let mut p1 = SVector::zeros();
        let report = self.newton.solve(&mut self.x, |x, r, j| {
            equations.assemble(h, &q0, &p0, x, r, j, &mut p1)
        })?;
        self.last_iterations = report.iterations;
        self.solutions.rotate_right(1);
        self.solutions[0].copy_from(&self.x);
        self.count = (self.count + 1).min(4);
        self.q = q0 + self.x.fixed_rows::<N>(E::END);
        self.p = p1;
        Ok(())
    }
}

/// `(L_q, L_v, L_qq, L_qv, L_vv)` of the double pendulum at `(q, v)`; `L_qv[a][b] = ∂²L/∂q_a∂v_b`.
#[allow(clippy::type_complexity)]
fn derivatives(
    s: &DoublePendulum,
    q: &SVector<2>,
    v: &SVector<2>,
) -> (
    SVector<2>,
    SVector<2>,
    SMatrix<f64, 2, 2>,
    SMatrix<f64, 2, 2>,
    SMatrix<f64, 2, 2>,
) {
    let a = (s.m1 + s.m2) * s.l1 * s.l1;
    let b = s.m2 * s.l2 * s.l2;
    let c = s.m2 * s.l1 * s.l2;
    let (g1, g2) = ((s.m1 + s.m2) * s.g * s.l1, s.m2 * s.g * s.l2);
    let (sd, cd) = (q[0] - q[1]).sin_cos();
    let (s1, c1) = q[0].sin_cos();
    let (s2, c2) = q[1].sin_cos();
    let (w1, w2) = (v[0], v[1]);
    let lq = SVector::<2>::new(-c * w1 * w2 * sd - g1 * s1, c * w1 * w2 * sd - g2 * s2);
    let lv = SVector::<2>::new(a * w1 + c * w2 * cd, b * w2 + c * w1 * cd);
    let k = c * w1 * w2 * cd;
    let lqq = SMatrix::<f64, 2, 2>::new(-k - g1 * c1, k, k, -k - g2 * c2);
    let lqv = SMatrix::<f64, 2, 2>::new(-c * w2 * sd, -c * w1 * sd, c * w2 * sd, c * w1 * sd);
    let lvv = SMatrix::<f64, 2, 2>::new(a, c * cd, c * cd, b);
    (lq, lv, lqq, lqv, lvv)
}

/// The midpoint rule for the double pendulum: `p_k + h/2 L_q − L_v = 0` at the midpoint for
/// `q_{k+1}`, then `p_{k+1} = h/2 L_q + L_v`.
pub struct Midpoint(pub DoublePendulum);

impl HandEquations<2> for Midpoint {
    const UNKNOWNS: usize = 2;
    const END: usize = 0;

    fn momentum(&self, q: &SVector<2>, v: &SVector<2>) -> SVector<2> {
        derivatives(&self.0, q, v).1
    }

    fn assemble(
        &self,
        h: f64,
        q0: &SVector<2>,
        p0: &SVector<2>,
        x: &DVector<f64>,
        r: &mut DVector<f64>,
        j: Option<&mut DMatrix<f64>>,
        p1: &mut SVector<2>,
    ) -> f64 {
        let xi = x.fixed_rows::<2>(0).into_owned();
        let (lq, lv, lqq, lqv, lvv) = derivatives(&self.0, &(q0 + xi * 0.5), &(xi / h));
        r.copy_from(&(p0 + lq * (0.5 * h) - lv));
        if let Some(j) = j {
            j.copy_from(&(lqq * (0.25 * h) + lqv * 0.5 - lqv.transpose() * 0.5 - lvv / h));
        }
        *p1 = lq * (0.5 * h) + lv;
        p0.abs().sup(&lv.abs()).amax()
    }
}

/// `galerkin(2)` for the double pendulum: the quadratic through `q_k`, `q_{k+1/2}`, `q_{k+1}`,
/// `L` at the two Gauss–Legendre nodes. With `φ_j` the quadratic Lagrange basis on `0, ½, 1` and
/// `D_j L_d = h Σ_i w_i (φ_j(c_i) L_q + φ_j'(c_i)/h L_v)`, the rows are `p_k + D_0 L_d = 0` and
/// `D_1 L_d = 0` in `ξ = (q_{k+1/2} − q_k, q_{k+1} − q_k)`; then `p_{k+1} = D_2 L_d`.
pub struct Galerkin2(pub DoublePendulum);

impl Galerkin2 {
    /// The Gauss–Legendre nodes on `[0, 1]` (their weights are ½).
    const NODES: [f64; 2] = [0.5 - 0.288_675_134_594_812_9, 0.5 + 0.288_675_134_594_812_9];

    /// `(φ_j(c), φ_j'(c))` for `j = 0, 1, 2`.
    fn basis(c: f64) -> [(f64, f64); 3] {
        [
            (2.0 * (c - 0.5) * (c - 1.0), 4.0 * c - 3.0),
            (-4.0 * c * (c - 1.0), 4.0 - 8.0 * c),
            (2.0 * c * (c - 0.5), 4.0 * c - 1.0),
        ]
    }
}

impl HandEquations<2> for Galerkin2 {
    const UNKNOWNS: usize = 4;
    const END: usize = 2;

    fn momentum(&self, q: &SVector<2>, v: &SVector<2>) -> SVector<2> {
        derivatives(&self.0, q, v).1
    }

    fn assemble(
        &self,
        h: f64,
        q0: &SVector<2>,
        p0: &SVector<2>,
        x: &DVector<f64>,
        r: &mut DVector<f64>,
        mut j: Option<&mut DMatrix<f64>>,
        p1: &mut SVector<2>,
    ) -> f64 {
        let xi = [
            x.fixed_rows::<2>(0).into_owned(),
            x.fixed_rows::<2>(2).into_owned(),
        ];
        // D_j L_d for j = 0, 1, 2, and the size of their terms.
        let mut slots = [SVector::<2>::zeros(); 3];
        let mut size = p0.amax();
        for c in Self::NODES {
            let phi = Self::basis(c);
            let q = q0 + xi[0] * phi[1].0 + xi[1] * phi[2].0;
            let v = (xi[0] * phi[1].1 + xi[1] * phi[2].1) / h;
            let (lq, lv, lqq, lqv, lvv) = derivatives(&self.0, &q, &v);
            let w = 0.5 * h;
            for (slot, (f, df)) in slots.iter_mut().zip(phi) {
                *slot += (lq * f + lv * (df / h)) * w;
            }
            size = size.max(lv.amax());
            let Some(j) = j.as_deref_mut() else { continue };
            // Row block b holds D_b L_d (b = 0, 1); column block m the increment ξ_m.
            for b in 0..2 {
                let (f, df) = phi[b];
                for m in 0..2 {
                    let (g, dg) = phi[m + 1];
                    let block = lqq * (f * g)
                        + lqv * (f * dg / h)
                        + lqv.transpose() * (df * g / h)
                        + lvv * (df * dg / (h * h));
                    let mut target = j.fixed_view_mut::<2, 2>(2 * b, 2 * m);
                    target += block * w;
                }
            }
        }
        r.fixed_rows_mut::<2>(0).copy_from(&(p0 + slots[0]));
        r.fixed_rows_mut::<2>(2).copy_from(&slots[1]);
        *p1 = slots[2];
        size
    }
}

/// The knife edge under the midpoint rule with its one-form `A(q) = (sin φ, −cos φ, 0)` at the
/// midpoint `q_c = q_k + ξ/2` (σ = ½): `p_k + h/2 L_q − Mξ/h + ½ A(q_c)ᵀμ = 0`,
/// `A(q_c) ξ = 0`, then `p_{k+1} = h/2 L_q + Mξ/h + ½ A(q_c)ᵀμ`, with `M = diag(m, m, j)` and
/// `L_q = (m g sin α, 0, 0)`.
pub struct KnifeEdgeMidpoint(pub KnifeEdge);

impl HandEquations<3> for KnifeEdgeMidpoint {
    const UNKNOWNS: usize = 4;
    const END: usize = 0;

    fn momentum(&self, _q: &SVector<3>, v: &SVector<3>) -> SVector<3> {
        let s = &self.0;
        SVector::<3>::new(s.m * v[0], s.m * v[1], s.j * v[2])
    }

    fn assemble(
        &self,
        h: f64,
        q0: &SVector<3>,
        p0: &SVector<3>,
        x: &DVector<f64>,
        r: &mut DVector<f64>,
        j: Option<&mut DMatrix<f64>>,
        p1: &mut SVector<3>,
    ) -> f64 {
        let s = &self.0;
        let xi = x.fixed_rows::<3>(0).into_owned();
        let mu = x[3];
        let (sin, cos) = (q0[2] + 0.5 * xi[2]).sin_cos();
        let a = SVector::<3>::new(sin, -cos, 0.0);
        let lq = SVector::<3>::new(s.m * s.g * s.alpha.sin(), 0.0, 0.0);
        let mv = self.momentum(q0, &(xi / h));
        let impulse = a * (0.5 * mu);
        r.fixed_rows_mut::<3>(0)
            .copy_from(&(p0 + lq * (0.5 * h) - mv + impulse));
        r[3] = a.dot(&xi);
        if let Some(j) = j {
            // Newton hands the Jacobian over zeroed.
            let masses = [s.m, s.m, s.j];
            // ∂A/∂φ = (cos φ, sin φ, 0), at the midpoint: half of it per unit of ξ_φ.
            let da = SVector::<3>::new(cos, sin, 0.0);
            for i in 0..3 {
                j[(i, i)] = -masses[i] / h;
                j[(i, 2)] += 0.25 * mu * da[i];
                j[(i, 3)] = 0.5 * a[i];
                j[(3, i)] = a[i];
            }
            j[(3, 2)] += 0.5 * da.dot(&xi);
        }
        *p1 = lq * (0.5 * h) + mv + impulse;
        p0.abs().sup(&mv.abs()).amax()
    }
}
