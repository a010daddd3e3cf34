//! Fields with known answers: the wave equation (its discrete dispersion relation), the
//! sine-Gordon kink (a closed form and its energy), a pair of strings coupled by springs (a
//! Klein–Gordon mode beside a wave), the kink–antikink collision (a closed form) and a
//! hand-written leapfrog for the bench.

use dirac::nalgebra::SVector;
use dirac::{Boundary, DiracError, Field, Scalar, SeparableDensity};

/// The wave equation `ρ u_tt = κ u_xx`: `ℒ = ½ ρ u_t² − ½ κ u_x²`.
#[derive(Debug, Clone, Copy)]
pub struct Wave {
    /// Inertia per unit length.
    pub rho: f64,
    /// Stiffness (tension).
    pub kappa: f64,
}

impl SeparableDensity<1> for Wave {
    fn inertia(&self, _x: f64) -> SVector<f64, 1> {
        SVector::from([self.rho])
    }
    fn potential<S: Scalar>(&self, _x: f64, _u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
        ux[0] * ux[0] * (0.5 * self.kappa)
    }
}

/// The frequency of the plane wave `cos(kx − ωt)` of the semi-discrete wave equation on a
/// grid of spacing `dx` (`ρ = κ = 1`): `ω = 2 sin(k dx/2)/dx`.
pub fn semi_discrete_frequency(k: f64, dx: f64) -> f64 {
    2.0 * (0.5 * k * dx).sin() / dx
}

/// The frequency of the plane wave `cos(kx_j − ωt_n)` of the leapfrog (Störmer–Verlet) on a
/// grid `dx`, `dt` (`ρ = κ = 1`): `sin(ω dt/2)/dt = sin(k dx/2)/dx`.
pub fn discrete_frequency(k: f64, dx: f64, dt: f64) -> f64 {
    2.0 / dt * (dt / dx * (0.5 * k * dx).sin()).asin()
}

/// The sine-Gordon field: `ℒ = ½ u_t² − ½ u_x² − (1 − cos u)`.
#[derive(Debug, Clone, Copy)]
pub struct SineGordon;

impl SeparableDensity<1> for SineGordon {
    fn inertia(&self, _x: f64) -> SVector<f64, 1> {
        SVector::from([1.0])
    }
    fn potential<S: Scalar>(&self, _x: f64, u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
        ux[0] * ux[0] * 0.5 - u[0].cos() + 1.0
    }
}

/// The sine-Gordon kink moving at speed `v` (|v| < 1) through `x = 0` at `t = 0`:
/// `u = 4 arctan exp(γ(x − vt))`, `γ = 1/√(1 − v²)`; returns `(u, u_t)`.
pub fn kink(v: f64, t: f64, x: f64) -> (f64, f64) {
    let gamma = 1.0 / (1.0 - v * v).sqrt();
    let e = (gamma * (x - v * t)).exp();
    (4.0 * e.atan(), -4.0 * gamma * v * e / (1.0 + e * e))
}

/// The kink's energy `8γ`.
pub fn kink_energy(v: f64) -> f64 {
    8.0 / (1.0 - v * v).sqrt()
}

/// The sine-Gordon breather of frequency `ω` (0 < ω < 1), a kink and an antikink bound to each
/// other, at rest and centred at `x = 0`:
/// `u = 4 arctan(√(1 − ω²) sin(ωt) / (ω cosh(√(1 − ω²) x)))`; returns `(u, u_t)`.
pub fn breather(omega: f64, t: f64, x: f64) -> (f64, f64) {
    let k = (1.0 - omega * omega).sqrt();
    let (sin, cos) = (omega * t).sin_cos();
    let width = (k * x).cosh();
    let ratio = k * sin / (omega * width);
    let rate = 4.0 * k * cos / (width * (1.0 + ratio * ratio));
    (4.0 * ratio.atan(), rate)
}

/// The breather's energy `16 √(1 − ω²)`.
pub fn breather_energy(omega: f64) -> f64 {
    16.0 * (1.0 - omega * omega).sqrt()
}

/// The kink–antikink collision of Perring and Skyrme: `u = 4 arctan(sinh(γvt) / (v cosh γx))`,
/// an antikink and a kink approaching at speeds `±v` for `t < 0`, passing through each other at
/// `t = 0` and parting; returns `(u, u_t)`.
pub fn collision(v: f64, t: f64, x: f64) -> (f64, f64) {
    let gamma = 1.0 / (1.0 - v * v).sqrt();
    let ratio = (gamma * v * t).sinh() / (v * (gamma * x).cosh());
    let rate = 4.0 * gamma * (gamma * v * t).cosh() / ((gamma * x).cosh() * (1.0 + ratio * ratio));
    (4.0 * ratio.atan(), rate)
}

/// A run of the collision at speed 0.5 on `[−20, 20]` (free ends) from `t = −t_end` to `t_end`
/// in `cells` cells with `Δt = 0.4 Δx`.
#[derive(Debug, Clone)]
pub struct CollisionRun {
    /// The nodes' positions.
    pub x: Vec<f64>,
    /// `(t, u at the nodes)`, about `snapshots` of them, the first and the last included.
    pub snapshots: Vec<(f64, Vec<f64>)>,
    /// The energy at each snapshot.
    pub energy: Vec<f64>,
    /// `max_j |u_j − u(t_end, x_j)|` against the closed form.
    pub error: f64,
    /// The steps taken.
    pub steps: u64,
    /// The wall time of the steps.
    pub wall: std::time::Duration,
}

impl CollisionRun {
    /// The largest `|E − E_0|` over the snapshots.
    pub fn energy_error(&self) -> f64 {
        let e0 = self.energy[0];
        self.energy
            .iter()
            .map(|e| (e - e0).abs())
            .fold(0.0, f64::max)
    }
}

/// The kink–antikink collision ([`collision`]) stepped by [`Field`] with `cells` cells, with a
/// progress bar on a terminal.
pub fn collision_run(
    cells: usize,
    t_end: f64,
    snapshots: usize,
) -> Result<CollisionRun, DiracError> {
    let v = 0.5;
    let dx = 40.0 / cells as f64;
    let steps = (2.0 * t_end / (0.4 * dx)).ceil() as u64;
    let dt = 2.0 * t_end / steps as f64;
    let mut field =
        Field::new(SineGordon, (-20.0, 20.0), cells, Boundary::Free, dt)?.with_parallel(true);
    let x = field.positions();
    let at = |f: fn(f64, f64, f64) -> (f64, f64),
              t: f64,
              pick: fn((f64, f64)) -> f64|
     -> Vec<SVector<f64, 1>> {
        x.iter()
            .map(|&x| SVector::from([pick(f(v, t, x))]))
            .collect()
    };
    field.start(
        &at(collision, -t_end, |p| p.0),
        &at(collision, -t_end, |p| p.1),
    )?;
    let every = (steps / snapshots.max(1) as u64).max(1);
    let level = |field: &Field<SineGordon, 1>| -> Result<(f64, Vec<f64>), DiracError> {
        Ok((field.t() - t_end, field.u()?.iter().map(|u| u[0]).collect()))
    };
    let mut taken = vec![level(&field)?];
    let mut energy = vec![field.energy()?];
    let mut wall = std::time::Duration::ZERO;
    let bar = super::progress::bar(0.0, 2.0 * t_end, dt);
    while field.steps() < steps {
        let clock = std::time::Instant::now();
        field.run(every.min(steps - field.steps()))?;
        wall += clock.elapsed();
        taken.push(level(&field)?);
        energy.push(field.energy()?);
        bar.set_position(field.steps());
        bar.set_message(format!("t = {:.1}", field.t() - t_end));
    }
    bar.finish_and_clear();
    let exact = at(collision, t_end, |p| p.0);
    let u = field.u()?;
    let error = u
        .iter()
        .zip(&exact)
        .map(|(u, e)| (u - e).amax())
        .fold(0.0, f64::max);
    Ok(CollisionRun {
        x,
        snapshots: taken,
        energy,
        error,
        steps,
        wall,
    })
}

/// The tour's row: the collision on 800 cells from `t = −8` to `8`, against the closed form,
/// with the energy's largest error.
pub fn report() -> Result<super::Report, DiracError> {
    let run = collision_run(800, 8.0, 200)?;
    let drift = run.energy_error();
    Ok(super::Report {
        scene: "sine-Gordon 800",
        quadrature: "Störmer–Verlet".into(),
        h: 16.0 / run.steps as f64,
        steps: run.steps,
        max_energy_error: Some(drift),
        wall: run.wall,
        check: format!("|u(8) − Perring–Skyrme| = {:.1e}", run.error),
    })
}

/// Two strings side by side, joined along their length by springs of stiffness `k`:
/// `ℒ = ½ (u_t² + w_t²) − ½ (u_x² + w_x²) − ½ k (u − w)²`. `u + w` is a wave; `u − w` a
/// Klein–Gordon field of mass `√(2k)`.
#[derive(Debug, Clone, Copy)]
pub struct CoupledStrings {
    /// The coupling springs' stiffness per unit length.
    pub k: f64,
}

impl SeparableDensity<2> for CoupledStrings {
    fn inertia(&self, _x: f64) -> SVector<f64, 2> {
        SVector::from([1.0, 1.0])
    }
    fn potential<S: Scalar>(&self, _x: f64, u: &SVector<S, 2>, ux: &SVector<S, 2>) -> S {
        let stretch = u[0] - u[1];
        (ux[0] * ux[0] + ux[1] * ux[1] + stretch * stretch * self.k) * 0.5
    }
}

/// A hand-written step of the sine-Gordon field on a periodic grid by Störmer–Verlet (the
/// step [`dirac::Field`] takes for [`SineGordon`], written out): `u` the field, `p` the rates.
pub fn leapfrog_sine_gordon(u: &mut [f64], p: &mut [f64], force: &mut [f64], dx: f64, dt: f64) {
    for (p, f) in p.iter_mut().zip(force.iter()) {
        *p += 0.5 * dt * f;
    }
    for (u, p) in u.iter_mut().zip(p.iter()) {
        *u += dt * p;
    }
    sine_gordon_force(u, force, dx);
    for (p, f) in p.iter_mut().zip(force.iter()) {
        *p += 0.5 * dt * f;
    }
}

/// `−∂Φ/∂u_j / Δx` of the sine-Gordon field on a periodic grid: `(u_{j+1} − 2u_j + u_{j−1})/Δx² −
/// sin u_j`.
pub fn sine_gordon_force(u: &[f64], force: &mut [f64], dx: f64) {
    let n = u.len();
    let inverse = 1.0 / (dx * dx);
    for j in 0..n {
        let (left, right) = (u[(j + n - 1) % n], u[(j + 1) % n]);
        force[j] = (left - 2.0 * u[j] + right) * inverse - u[j].sin();
    }
}
