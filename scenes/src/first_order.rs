//! The scenes of the speed/accuracy study as first-order systems `y' = f(y)`, for the integrators
//! users would otherwise pick (`peers.rs`). The equations of motion are derived by hand from each
//! scene's Lagrangian and constraints, independently of dirac's discrete Lagrangian; each form
//! also gives its energy and its state as dirac's `(q, v, p)`.
//!
//! A form may end in algebraic rows (`0 = f_i(y)`, a semi-explicit index-1 DAE) for the BDF
//! peer; the explicit Runge–Kutta peers take the forms without them.

use dirac::prelude::*;
use dirac::{Sample, Scalar};

use super::chain::Chain;
use super::circuit::LcCircuit;
use super::double_pendulum::DoublePendulum;
use super::kepler::Kepler;
use super::knife_edge::KnifeEdge;
use super::pendulum::Pendulum;

/// A scene as `y' = f(y)` in its first `DIFFERENTIAL` rows and `0 = f_i(y)` in the others;
/// `Y` state entries, `N` coordinates of the dirac model.
pub trait FirstOrder<const Y: usize, const N: usize>: Sync {
    /// The rows that are differential equations; the rest are algebraic.
    const DIFFERENTIAL: usize = Y;
    /// The initial state (consistent with the algebraic rows).
    fn initial(&self) -> [f64; Y];
    /// The right-hand side, generic so that dual numbers give its Jacobian.
    fn rhs<D: Scalar>(&self, y: &[D; Y]) -> [D; Y];
    /// The energy.
    fn energy(&self, y: &[f64; Y]) -> f64;
    /// The state as the dirac model's position, velocity and momentum `∂L/∂v` at time `t`.
    fn sample(&self, t: f64, y: &[f64; Y]) -> Sample<N>;
    /// How far the state is off the model's constraints (0 for an unconstrained model).
    fn violation(&self, _y: &[f64; Y]) -> f64 {
        0.0
    }
    /// The state at time `t` in closed form, where the scene has one.
    fn exact(&self, _t: f64) -> Option<[f64; Y]> {
        None
    }
}

/// Solves `M x = b` for a symmetric positive definite `M` (Cholesky, in any scalar).
fn solve_spd<D: Scalar, const L: usize>(mut m: [[D; L]; L], mut b: [D; L]) -> [D; L] {
    for k in 0..L {
        let pivot = m[k][k].sqrt();
        for row in &mut m[k..] {
            row[k] /= pivot;
        }
        for j in k + 1..L {
            for i in j..L {
                let update = m[i][k] * m[j][k];
                m[i][j] -= update;
            }
        }
    }
    for i in 0..L {
        for k in 0..i {
            let update = m[i][k] * b[k];
            b[i] -= update;
        }
        b[i] /= m[i][i];
    }
    for i in (0..L).rev() {
        for k in i + 1..L {
            let update = m[k][i] * b[k];
            b[i] -= update;
        }
        b[i] /= m[i][i];
    }
    b
}

fn sample<const N: usize>(t: f64, q: [f64; N], v: [f64; N], p: [f64; N]) -> Sample<N> {
    Sample {
        t,
        q: SVector::from(q),
        v: SVector::from(v),
        p: SVector::from(p),
    }
}

/// The pendulum `m l² θ̈ = −m g l sin θ`, y = (θ, θ̇).
#[derive(Debug, Clone, Copy)]
pub struct PendulumOde {
    pub pendulum: Pendulum,
    pub theta0: f64,
}

impl FirstOrder<2, 1> for PendulumOde {
    fn initial(&self) -> [f64; 2] {
        [self.theta0, 0.0]
    }
    fn rhs<D: Scalar>(&self, y: &[D; 2]) -> [D; 2] {
        let Pendulum { l, g, .. } = self.pendulum;
        [y[1], -y[0].sin() * (g / l)]
    }
    fn energy(&self, y: &[f64; 2]) -> f64 {
        let Pendulum { m, l, g } = self.pendulum;
        0.5 * m * l * l * y[1] * y[1] - m * g * l * y[0].cos()
    }
    fn sample(&self, t: f64, y: &[f64; 2]) -> Sample<1> {
        let Pendulum { m, l, .. } = self.pendulum;
        sample(t, [y[0]], [y[1]], [m * l * l * y[1]])
    }
}

/// The double pendulum `M(θ) θ̈ = f(θ, θ̇)`, y = (θ₁, θ₂, θ̇₁, θ̇₂), from rest at `theta0`.
#[derive(Debug, Clone, Copy)]
pub struct DoublePendulumOde {
    pub pendulum: DoublePendulum,
    pub theta0: [f64; 2],
}

impl DoublePendulumOde {
    fn mass<D: Scalar>(&self, theta1: D, theta2: D) -> [[D; 2]; 2] {
        let DoublePendulum { m1, m2, l1, l2, .. } = self.pendulum;
        let coupling = (theta1 - theta2).cos() * (m2 * l1 * l2);
        [
            [D::from((m1 + m2) * l1 * l1), coupling],
            [coupling, D::from(m2 * l2 * l2)],
        ]
    }

    fn momentum(&self, y: &[f64; 4]) -> [f64; 2] {
        let m = self.mass(y[0], y[1]);
        [
            m[0][0] * y[2] + m[0][1] * y[3],
            m[1][0] * y[2] + m[1][1] * y[3],
        ]
    }
}

impl FirstOrder<4, 2> for DoublePendulumOde {
    fn initial(&self) -> [f64; 4] {
        [self.theta0[0], self.theta0[1], 0.0, 0.0]
    }
    fn rhs<D: Scalar>(&self, y: &[D; 4]) -> [D; 4] {
        let DoublePendulum {
            m1, m2, l1, l2, g, ..
        } = self.pendulum;
        let sin = (y[0] - y[1]).sin() * (m2 * l1 * l2);
        let force = [
            -sin * y[3] * y[3] - y[0].sin() * ((m1 + m2) * g * l1),
            sin * y[2] * y[2] - y[1].sin() * (m2 * g * l2),
        ];
        let [a1, a2] = solve_spd(self.mass(y[0], y[1]), force);
        [y[2], y[3], a1, a2]
    }
    fn energy(&self, y: &[f64; 4]) -> f64 {
        let DoublePendulum {
            m1, m2, l1, l2, g, ..
        } = self.pendulum;
        let p = self.momentum(y);
        0.5 * (p[0] * y[2] + p[1] * y[3])
            - (m1 + m2) * g * l1 * y[0].cos()
            - m2 * g * l2 * y[1].cos()
    }
    fn sample(&self, t: f64, y: &[f64; 4]) -> Sample<2> {
        sample(t, [y[0], y[1]], [y[2], y[3]], self.momentum(y))
    }
}

/// Kepler's problem `q̈ = −μ q/|q|³` from pericentre of an orbit of eccentricity `e` and
/// semi-major axis 1: q0 = (1 − e, 0), q̇0 = (0, √(μ(1 + e)/(1 − e))); y = (q, q̇).
#[derive(Debug, Clone, Copy)]
pub struct KeplerOde {
    pub kepler: Kepler,
    pub e: f64,
}

impl FirstOrder<4, 2> for KeplerOde {
    fn initial(&self) -> [f64; 4] {
        let speed = (self.kepler.mu * (1.0 + self.e) / (1.0 - self.e)).sqrt();
        [1.0 - self.e, 0.0, 0.0, speed]
    }
    fn rhs<D: Scalar>(&self, y: &[D; 4]) -> [D; 4] {
        let r2 = y[0] * y[0] + y[1] * y[1];
        let mu_over_r3 = (r2 * r2.sqrt()).recip() * self.kepler.mu;
        [y[2], y[3], -y[0] * mu_over_r3, -y[1] * mu_over_r3]
    }
    fn energy(&self, y: &[f64; 4]) -> f64 {
        0.5 * (y[2] * y[2] + y[3] * y[3]) - self.kepler.mu / (y[0] * y[0] + y[1] * y[1]).sqrt()
    }
    fn sample(&self, t: f64, y: &[f64; 4]) -> Sample<2> {
        sample(t, [y[0], y[1]], [y[2], y[3]], [y[2], y[3]])
    }
    /// Kepler's equation `E − e sin E = n t` (mean motion `n = √μ`) solved by Newton from
    /// `E = n t`: `q = (cos E − e, √(1 − e²) sin E)`,
    /// `q̇ = n (−sin E, √(1 − e²) cos E)/(1 − e cos E)`.
    fn exact(&self, t: f64) -> Option<[f64; 4]> {
        let (e, n) = (self.e, self.kepler.mu.sqrt());
        let mean = n * t;
        let mut anomaly = mean;
        for _ in 0..100 {
            let update = (anomaly - e * anomaly.sin() - mean) / (1.0 - e * anomaly.cos());
            anomaly -= update;
            if update.abs() < 1e-15 * anomaly.abs().max(1.0) {
                break;
            }
        }
        let (sin, cos) = anomaly.sin_cos();
        let (b, rate) = ((1.0 - e * e).sqrt(), n / (1.0 - e * cos));
        Some([cos - e, b * sin, -sin * rate, b * cos * rate])
    }
}

/// The n-link chain in absolute angles: `M_jk = m l² (n − max(j, k)) cos(θ_j − θ_k)`,
/// `(M θ̈)_j = −Σ_k m l² (n − max(j, k)) sin(θ_j − θ_k) θ̇_k² − m g l (n − j) sin θ_j`
/// (links counted from 0), from rest at `theta0`; y = (θ, θ̇), `Y = 2n`.
#[derive(Debug, Clone, Copy)]
pub struct ChainOde<const L: usize> {
    pub chain: Chain<L>,
    pub theta0: [f64; L],
}

impl<const L: usize> ChainOde<L> {
    /// `m l² (n − max(j, k))`: the mass the links j and k both carry, times l².
    fn carried(&self, j: usize, k: usize) -> f64 {
        self.chain.m * self.chain.l * self.chain.l * (L - j.max(k)) as f64
    }

    fn mass<D: Scalar>(&self, theta: &[D]) -> [[D; L]; L] {
        std::array::from_fn(|j| {
            std::array::from_fn(|k| (theta[j] - theta[k]).cos() * self.carried(j, k))
        })
    }

    fn momentum<const Y: usize>(&self, y: &[f64; Y]) -> [f64; L] {
        let m = self.mass(&y[..L]);
        std::array::from_fn(|j| (0..L).map(|k| m[j][k] * y[L + k]).sum())
    }
}

/// `FirstOrder` needs `Y = 2L` as its own constant: the study's 8-link chain.
impl FirstOrder<16, 8> for ChainOde<8> {
    fn initial(&self) -> [f64; 16] {
        std::array::from_fn(|i| if i < 8 { self.theta0[i] } else { 0.0 })
    }
    fn rhs<D: Scalar>(&self, y: &[D; 16]) -> [D; 16] {
        let Chain { m, l, g } = self.chain;
        let (theta, omega) = y.split_at(8);
        let force: [D; 8] = std::array::from_fn(|j| {
            let mut f = -theta[j].sin() * (m * g * l * (8 - j) as f64);
            for k in 0..8 {
                f -= (theta[j] - theta[k]).sin() * omega[k] * omega[k] * self.carried(j, k);
            }
            f
        });
        let acceleration = solve_spd(self.mass(theta), force);
        std::array::from_fn(|i| if i < 8 { omega[i] } else { acceleration[i - 8] })
    }
    fn energy(&self, y: &[f64; 16]) -> f64 {
        let Chain { m, l, g } = self.chain;
        let p = self.momentum(y);
        let kinetic: f64 = (0..8).map(|k| 0.5 * p[k] * y[8 + k]).sum();
        let potential: f64 = (0..8)
            .map(|k| -m * g * l * (8 - k) as f64 * y[k].cos())
            .sum();
        kinetic + potential
    }
    fn sample(&self, t: f64, y: &[f64; 16]) -> Sample<8> {
        let q = std::array::from_fn(|i| y[i]);
        let v = std::array::from_fn(|i| y[8 + i]);
        sample(t, q, v, self.momentum(y))
    }
}

/// The LC circuit with the constraints solved: the inductor current `i` flows through C2 and
/// splits between the parallel C1 and C3 in proportion to their capacitances;
/// y = (q_l, q_c1, q_c2, q_c3, i), from charges `q0` with no current.
#[derive(Debug, Clone, Copy)]
pub struct LcOde {
    pub circuit: LcCircuit,
    pub q0: [f64; 4],
}

impl LcOde {
    fn velocity(&self, i: f64) -> [f64; 4] {
        let LcCircuit { c1, c3, .. } = self.circuit;
        [i, i * c1 / (c1 + c3), i, i * c3 / (c1 + c3)]
    }
}

/// The LC circuit's energy `l i²/2 + Σ q²/(2c)` at charges `q` and current `i`.
fn lc_energy(circuit: &LcCircuit, q: [f64; 4], i: f64) -> f64 {
    let LcCircuit { l, c1, c2, c3 } = *circuit;
    0.5 * l * i * i + 0.5 * (q[1] * q[1] / c1 + q[2] * q[2] / c2 + q[3] * q[3] / c3)
}

impl FirstOrder<5, 4> for LcOde {
    fn initial(&self) -> [f64; 5] {
        let [a, b, c, d] = self.q0;
        let y = [a, b, c, d, 0.0];
        debug_assert!(
            self.violation(&y) < 1e-12,
            "C1 and C3 must start at one voltage"
        );
        y
    }
    fn rhs<D: Scalar>(&self, y: &[D; 5]) -> [D; 5] {
        let LcCircuit { l, c1, c2, c3 } = self.circuit;
        let i = y[4];
        [
            i,
            i * (c1 / (c1 + c3)),
            i,
            i * (c3 / (c1 + c3)),
            -(y[2] / c2 + y[1] / c1) / l,
        ]
    }
    fn energy(&self, y: &[f64; 5]) -> f64 {
        lc_energy(&self.circuit, [y[0], y[1], y[2], y[3]], y[4])
    }
    fn sample(&self, t: f64, y: &[f64; 5]) -> Sample<4> {
        let l = self.circuit.l;
        let q = [y[0], y[1], y[2], y[3]];
        sample(t, q, self.velocity(y[4]), [l * y[4], 0.0, 0.0, 0.0])
    }
    /// The hidden constraint: C1 and C3 in parallel share their voltage.
    fn violation(&self, y: &[f64; 5]) -> f64 {
        (y[1] / self.circuit.c1 - y[3] / self.circuit.c3).abs()
    }
    /// For the tour's circuit (unit elements, charge 1 on C2): `q_c2 = 1/3 + (2/3) cos(√1.5 t)`,
    /// `q_c1 = q_c3 = (q_c2 − 1)/2`, `q_l = q_c2 − 1`, `i = q̇_c2`.
    fn exact(&self, t: f64) -> Option<[f64; 5]> {
        let unit = LcCircuit {
            l: 1.0,
            c1: 1.0,
            c2: 1.0,
            c3: 1.0,
        };
        let tour = (
            self.circuit.l,
            self.circuit.c1,
            self.circuit.c2,
            self.circuit.c3,
        ) == (unit.l, unit.c1, unit.c2, unit.c3)
            && self.q0 == [0.0, 0.0, 1.0, 0.0];
        if !tour {
            return None;
        }
        let w = 1.5f64.sqrt();
        let q_c2 = 1.0 / 3.0 + 2.0 / 3.0 * (w * t).cos();
        let i = -2.0 / 3.0 * w * (w * t).sin();
        let q_c1 = (q_c2 - 1.0) / 2.0;
        Some([q_c2 - 1.0, q_c1, q_c2, q_c1, i])
    }
}

/// The LC circuit as the index-1 DAE a circuit simulator builds: y = (q_l, q_c2, i | q_c1,
/// q_c3), with the inductor's equation differential and, as algebraic rows, charge conservation
/// at the C1–C2–C3 node and the equal voltages of the parallel C1 and C3.
#[derive(Debug, Clone, Copy)]
pub struct LcDae(pub LcOde);

impl FirstOrder<5, 4> for LcDae {
    const DIFFERENTIAL: usize = 3;
    fn initial(&self) -> [f64; 5] {
        let [ql, q1, q2, q3] = self.0.q0;
        [ql, q2, 0.0, q1, q3]
    }
    fn rhs<D: Scalar>(&self, y: &[D; 5]) -> [D; 5] {
        let LcCircuit { l, c1, c2, c3 } = self.0.circuit;
        let [_, q1, q2, q3] = self.0.q0;
        let i = y[2];
        [
            i,
            i,
            -(y[1] / c2 + y[3] / c1) / l,
            y[3] + y[4] - y[1] - (q1 + q3 - q2),
            y[3] / c1 - y[4] / c3,
        ]
    }
    fn energy(&self, y: &[f64; 5]) -> f64 {
        lc_energy(&self.0.circuit, [y[0], y[3], y[1], y[4]], y[2])
    }
    fn sample(&self, t: f64, y: &[f64; 5]) -> Sample<4> {
        self.0.sample(t, &[y[0], y[3], y[1], y[4], y[2]])
    }
    fn violation(&self, y: &[f64; 5]) -> f64 {
        self.0.violation(&[y[0], y[3], y[1], y[4], y[2]])
    }
}

/// The knife edge with its multiplier solved from the differentiated constraint:
/// `m ẍ = m g sin α + λ sin φ`, `m ÿ = −λ cos φ`, `J φ̈ = 0`,
/// `λ/m = −φ̇ (ẋ cos φ + ẏ sin φ) − g sin α sin φ`; y = (x, y, φ, ẋ, ẏ, φ̇), from rest at the
/// origin spinning at `omega`.
#[derive(Debug, Clone, Copy)]
pub struct KnifeEdgeOde {
    pub knife: KnifeEdge,
    pub omega: f64,
}

impl KnifeEdgeOde {
    /// `λ/m` from the differentiated constraint.
    fn multiplier<D: Scalar>(&self, y: &[D]) -> D {
        let KnifeEdge { g, alpha, .. } = self.knife;
        let (sin, cos) = y[2].sin_cos();
        -y[5] * (y[3] * cos + y[4] * sin) - sin * (g * alpha.sin())
    }

    /// The accelerations for a given `λ/m`.
    fn acceleration<D: Scalar>(&self, y: &[D], lambda: D) -> [D; 3] {
        let KnifeEdge { g, alpha, .. } = self.knife;
        let (sin, cos) = y[2].sin_cos();
        [lambda * sin + g * alpha.sin(), -lambda * cos, D::from(0.0)]
    }
}

fn knife_energy(knife: &KnifeEdge, y: &[f64]) -> f64 {
    let KnifeEdge { m, j, g, alpha } = *knife;
    0.5 * m * (y[3] * y[3] + y[4] * y[4]) + 0.5 * j * y[5] * y[5] - m * g * alpha.sin() * y[0]
}

fn knife_sample(knife: &KnifeEdge, t: f64, y: &[f64]) -> Sample<3> {
    let KnifeEdge { m, j, .. } = *knife;
    sample(
        t,
        [y[0], y[1], y[2]],
        [y[3], y[4], y[5]],
        [m * y[3], m * y[4], j * y[5]],
    )
}

/// `|ẋ sin φ − ẏ cos φ|`: the velocity across the blade.
fn knife_violation(y: &[f64]) -> f64 {
    (y[3] * y[2].sin() - y[4] * y[2].cos()).abs()
}

impl FirstOrder<6, 3> for KnifeEdgeOde {
    fn initial(&self) -> [f64; 6] {
        [0.0, 0.0, 0.0, 0.0, 0.0, self.omega]
    }
    fn rhs<D: Scalar>(&self, y: &[D; 6]) -> [D; 6] {
        let [ax, ay, aphi] = self.acceleration(y, self.multiplier(y));
        [y[3], y[4], y[5], ax, ay, aphi]
    }
    fn energy(&self, y: &[f64; 6]) -> f64 {
        knife_energy(&self.knife, y)
    }
    fn sample(&self, t: f64, y: &[f64; 6]) -> Sample<3> {
        knife_sample(&self.knife, t, y)
    }
    fn violation(&self, y: &[f64; 6]) -> f64 {
        knife_violation(y)
    }
    /// `φ = Ωt`, `x = k sin² Ωt`, `y = k (Ωt − ½ sin 2Ωt)` with `k = g sin α/(2Ω²)`.
    fn exact(&self, t: f64) -> Option<[f64; 6]> {
        let KnifeEdge { g, alpha, .. } = self.knife;
        let w = self.omega;
        let k = g * alpha.sin() / (2.0 * w * w);
        let (sin2, cos2) = (2.0 * w * t).sin_cos();
        Some([
            k * (w * t).sin().powi(2),
            k * (w * t - 0.5 * sin2),
            w * t,
            k * w * sin2,
            k * w * (1.0 - cos2),
            w,
        ])
    }
}

/// The knife edge as an index-1 DAE with its multiplier `λ/m` as the algebraic unknown:
/// y = (x, y, φ, ẋ, ẏ, φ̇ | λ/m), the last row the differentiated constraint.
#[derive(Debug, Clone, Copy)]
pub struct KnifeEdgeDae(pub KnifeEdgeOde);

impl FirstOrder<7, 3> for KnifeEdgeDae {
    const DIFFERENTIAL: usize = 6;
    fn initial(&self) -> [f64; 7] {
        let y = self.0.initial();
        [y[0], y[1], y[2], y[3], y[4], y[5], self.0.multiplier(&y)]
    }
    fn rhs<D: Scalar>(&self, y: &[D; 7]) -> [D; 7] {
        let [ax, ay, aphi] = self.0.acceleration(y, y[6]);
        [y[3], y[4], y[5], ax, ay, aphi, y[6] - self.0.multiplier(y)]
    }
    fn energy(&self, y: &[f64; 7]) -> f64 {
        knife_energy(&self.0.knife, y)
    }
    fn sample(&self, t: f64, y: &[f64; 7]) -> Sample<3> {
        knife_sample(&self.0.knife, t, y)
    }
    fn violation(&self, y: &[f64; 7]) -> f64 {
        knife_violation(y)
    }
}
