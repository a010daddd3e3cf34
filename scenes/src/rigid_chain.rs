//! A chain of two rigid bodies in gravity (a 3D double pendulum of bodies): the first turns about
//! a fixed pivot, the second hangs from a ball joint at `d` on the first. Its attitudes are an
//! array `links[2]: SO3`. The second body's centre of mass is at `R₁ d + R₂ ρ₂`, so its velocity
//! is `Ṙ₁ d + Ṙ₂ ρ₂` and
//! `L = ½ Ω₁ᵀ J₁ Ω₁ + ½ Ω₂ᵀ J₂ Ω₂ + ½ m₂ |Ṙ₁ d + Ṙ₂ ρ₂|² − g (m₁ e₃ᵀ R₁ ρ₁ + m₂ e₃ᵀ (R₁ d + R₂ ρ₂))`,
//! with `J₁` about the pivot and `J₂` about the second body's centre of mass.
//!
//! `RigidChain` writes `L` as an expression; `RigidChainByFunction` gives the same `L` as a
//! function of the typed points (`Configuration`, `Rates`), with `R (Ω × d)` for `Ṙ d`.

use dirac::prelude::*;

/// The chain, its Lagrangian an expression in the attitudes.
#[dirac_system(
    coordinates(links[2]: SO3),
    lagrangian = 0.5 * dot(omega(links[0]), j1 * omega(links[0]))
        + 0.5 * dot(omega(links[1]), j2 * omega(links[1]))
        + 0.5 * m2 * dot(dot(links[0]) * d + dot(links[1]) * rho2,
            dot(links[0]) * d + dot(links[1]) * rho2)
        - g * (m1 * (links[0] * rho1)[2] + m2 * (links[0] * d + links[1] * rho2)[2]),
)]
#[derive(Debug, Clone, Copy)]
pub struct RigidChain {
    pub j1: [[f64; 3]; 3],
    pub j2: [[f64; 3]; 3],
    pub m1: f64,
    pub m2: f64,
    pub g: f64,
    pub rho1: [f64; 3],
    pub rho2: [f64; 3],
    pub d: [f64; 3],
}

/// The same chain, its Lagrangian a function of the typed points.
#[dirac_system(coordinates(links[2]: SO3), lagrangian = chain_lagrangian)]
#[derive(Debug, Clone, Copy)]
pub struct RigidChainByFunction {
    pub j1: [[f64; 3]; 3],
    pub j2: [[f64; 3]; 3],
    pub m1: f64,
    pub m2: f64,
    pub g: f64,
    pub rho1: [f64; 3],
    pub rho2: [f64; 3],
    pub d: [f64; 3],
}

impl From<RigidChain> for RigidChainByFunction {
    fn from(c: RigidChain) -> Self {
        let RigidChain {
            j1,
            j2,
            m1,
            m2,
            g,
            rho1,
            rho2,
            d,
        } = c;
        Self {
            j1,
            j2,
            m1,
            m2,
            g,
            rho1,
            rho2,
            d,
        }
    }
}

/// `L` of [`RigidChain`] on `SO(3)²`.
pub fn chain_lagrangian<D: Scalar>(
    model: &RigidChainByFunction,
    q: &Configuration<D, 0, 2, 0>,
    v: &Rates<D, 0, 2, 0>,
) -> D {
    let c = model;
    let matrix = |m: [[f64; 3]; 3]| Matrix3::from_fn(|a, b| D::from(m[a][b]));
    let vector = |x: [f64; 3]| Vector3::from_fn(|a, _| D::from(x[a]));
    let (r1, r2) = (q.rotation[0], q.rotation[1]);
    let (w1, w2) = (v.rotation[0], v.rotation[1]);
    let (d, rho1, rho2) = (vector(c.d), vector(c.rho1), vector(c.rho2));
    let joint_velocity = r1 * w1.cross(&d) + r2 * w2.cross(&rho2);
    let kinetic = w1.dot(&(matrix(c.j1) * w1)) * 0.5
        + w2.dot(&(matrix(c.j2) * w2)) * 0.5
        + joint_velocity.dot(&joint_velocity) * (0.5 * c.m2);
    let height = (r1 * rho1)[2] * c.m1 + (r1 * d + r2 * rho2)[2] * c.m2;
    kinetic - height * c.g
}

/// Two unequal bodies, the second hanging from the first's far end.
pub const CHAIN: RigidChain = RigidChain {
    j1: [[0.6, 0.05, 0.0], [0.05, 0.5, 0.02], [0.0, 0.02, 0.2]],
    j2: [[0.3, 0.0, 0.01], [0.0, 0.25, 0.0], [0.01, 0.0, 0.1]],
    m1: 1.5,
    m2: 1.0,
    g: 9.81,
    rho1: [0.05, 0.0, -0.5],
    rho2: [0.0, 0.1, -0.4],
    d: [0.0, 0.0, -1.0],
};

/// The chain's start: both bodies tilted and spinning.
pub fn start() -> (Configuration<f64, 0, 2, 0>, Rates<f64, 0, 2, 0>) {
    (
        Configuration::new(
            SVector::zeros(),
            [
                Retraction::Exp.map(&Vector3::new(0.6, 0.1, 0.0)),
                Retraction::Exp.map(&Vector3::new(-0.3, 0.8, 0.2)),
            ],
            [],
        ),
        Rates::new(
            SVector::zeros(),
            [Vector3::new(0.5, -1.0, 2.0), Vector3::new(-1.5, 0.4, 3.0)],
            [],
        ),
    )
}

/// The total vertical angular momentum `e₃ · (R₁ Π₁ + R₂ Π₂)`, conserved: `L` is invariant under
/// turning both bodies about the vertical through the pivot.
pub fn vertical_momentum(q: &Configuration<f64, 0, 2, 0>, p: &Rates<f64, 0, 2, 0>) -> f64 {
    (q.spatial(p, 0) + q.spatial(p, 1))[2]
}

/// Where the chain is at one time: its joint `R₁ d` and the second body's centre of mass
/// `R₁ d + R₂ ρ₂` (the pivot at the origin).
#[derive(Debug, Clone, Copy)]
pub struct ChainPoints {
    pub t: f64,
    pub joint: Vector3<f64>,
    pub centre: Vector3<f64>,
}

/// The chain's points every `every` steps of a midpoint run of `steps` steps of `h` from
/// [`start`] on `space`.
pub fn points_in_space(
    space: Product<0, 2, 0>,
    h: f64,
    steps: u64,
    every: usize,
) -> Result<Vec<ChainPoints>, DiracError> {
    let mut stepper = Stepper::on_manifold(CHAIN, space, Quadrature::midpoint(), h)?;
    let (q0, v0) = start();
    stepper.start_from_velocity(q0, v0)?;
    let trajectory = stepper.solve(Run::steps(steps).every(every))?.trajectory;
    let (d, rho2) = (Vector3::from(CHAIN.d), Vector3::from(CHAIN.rho2));
    Ok(trajectory
        .t()
        .iter()
        .zip(trajectory.q())
        .map(|(&t, q)| {
            let joint = q.rotation[0] * d;
            ChainPoints {
                t,
                joint,
                centre: joint + q.rotation[1] * rho2,
            }
        })
        .collect())
}
