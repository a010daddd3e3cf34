//! The performance limit for the midpoint double pendulum: a stepper written by hand with analytic
//! derivatives of L, using the same Newton solver as the generated one.

use dirac::nalgebra::{DVector, SMatrix, SVector};
use dirac::{Newton, NewtonOptions};

use super::double_pendulum::DoublePendulum;

/// `(L_q, L_v, L_qq, L_qv, L_vv)` of the double pendulum at `(q, v)`; `L_qv[a][b] = ∂²L/∂q_a∂v_b`.
#[allow(clippy::type_complexity)]
fn derivatives(
    s: &DoublePendulum,
    q: &SVector<f64, 2>,
    v: &SVector<f64, 2>,
) -> (
    SVector<f64, 2>,
    SVector<f64, 2>,
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
    let lq = SVector::<f64, 2>::new(-c * w1 * w2 * sd - g1 * s1, c * w1 * w2 * sd - g2 * s2);
    let lv = SVector::<f64, 2>::new(a * w1 + c * w2 * cd, b * w2 + c * w1 * cd);
    let k = c * w1 * w2 * cd;
    let lqq = SMatrix::<f64, 2, 2>::new(-k - g1 * c1, k, k, -k - g2 * c2);
    let lqv = SMatrix::<f64, 2, 2>::new(-c * w2 * sd, -c * w1 * sd, c * w2 * sd, c * w1 * sd);
    let lvv = SMatrix::<f64, 2, 2>::new(a, c * cd, c * cd, b);
    (lq, lv, lqq, lqv, lvv)
}

/// Midpoint variational integrator for the double pendulum, by hand.
pub struct HandMidpoint {
    pub system: DoublePendulum,
    pub h: f64,
    pub q: SVector<f64, 2>,
    pub p: SVector<f64, 2>,
    increment: SVector<f64, 2>,
    /// The increment of the step before (none at the start): the predictor extrapolates the
    /// last two, as the generated stepper does.
    earlier: Option<SVector<f64, 2>>,
    newton: Newton,
    x: DVector<f64>,
    /// Newton iterations of the last step.
    pub last_iterations: usize,
}

impl HandMidpoint {
    /// Starts at `(q0, v0)` with `p0 = ∂L/∂v` and the predictor `q1 ≈ q0 + h v0`.
    pub fn new(system: DoublePendulum, h: f64, q0: SVector<f64, 2>, v0: SVector<f64, 2>) -> Self {
        let p0 = derivatives(&system, &q0, &v0).1;
        Self {
            system,
            h,
            q: q0,
            p: p0,
            increment: v0 * h,
            earlier: None,
            newton: Newton::new(2, NewtonOptions::default())
                .expect("the default options are valid"),
            x: DVector::zeros(2),
            last_iterations: 0,
        }
    }

    /// One step: solve `p_k + h/2 L_q − L_v = 0` at the midpoint for `q_{k+1}`, then
    /// `p_{k+1} = h/2 L_q + L_v`.
    pub fn step(&mut self) -> Result<(), dirac::NewtonFailure> {
        let (q0, p0, h, system) = (self.q, self.p, self.h, &self.system);
        let predicted = match self.earlier {
            Some(earlier) => self.increment * 2.0 - earlier,
            None => self.increment,
        };
        self.x.copy_from(&(q0 + predicted));
        let mut p1 = SVector::zeros();
        let report = self.newton.solve(&mut self.x, |x, r, j| {
            let q1 = SVector::<f64, 2>::new(x[0], x[1]);
            let (lq, lv, lqq, lqv, lvv) = derivatives(system, &((q0 + q1) * 0.5), &((q1 - q0) / h));
            r.copy_from(&(p0 + lq * (0.5 * h) - lv));
            if let Some(j) = j {
                j.copy_from(&(lqq * (0.25 * h) + lqv * 0.5 - lqv.transpose() * 0.5 - lvv / h));
            }
            p1 = lq * (0.5 * h) + lv;
            p0.abs().sup(&lv.abs()).amax()
        })?;
        self.last_iterations = report.iterations;
        let q1 = SVector::<f64, 2>::new(self.x[0], self.x[1]);
        self.earlier = Some(self.increment);
        self.increment = q1 - q0;
        self.q = q1;
        self.p = p1;
        Ok(())
    }
}
