//! Fields on the plane with known answers: the membrane (the wave equation on a rectangle) and
//! its modes, with the continuum's, the semi-discrete and the leapfrog's frequencies; two
//! membranes joined by springs (a Klein–Gordon mode beside a wave); a hand-written five-point
//! leapfrog for the bench; the struck drum of the tour.

use std::f64::consts::PI;

use dirac::nalgebra::SVector;
use dirac::{Boundary, DiracError, PlaneDensity, PlaneField, Scalar};

/// The wave equation on the plane, `ρ u_tt = κ (u_xx + u_yy)`:
/// `ℒ = ½ ρ u_t² − ½ κ (u_x² + u_y²)`.
#[derive(Debug, Clone, Copy)]
pub struct Membrane {
    /// Inertia per unit area.
    pub rho: f64,
    /// Tension.
    pub kappa: f64,
}

/// The membrane with `ρ = κ = 1`.
pub const DRUM: Membrane = Membrane {
    rho: 1.0,
    kappa: 1.0,
};

impl PlaneDensity<1> for Membrane {
    fn inertia(&self, _at: [f64; 2]) -> SVector<f64, 1> {
        SVector::from([self.rho])
    }
    fn potential<S: Scalar>(
        &self,
        _at: [f64; 2],
        _u: &SVector<S, 1>,
        ux: &SVector<S, 1>,
        uy: &SVector<S, 1>,
    ) -> S {
        (ux[0] * ux[0] + uy[0] * uy[0]) * (0.5 * self.kappa)
    }
}

/// The frequency of the mode `e^{i(k·x − ωt)}` of the membrane with `ρ = κ = 1`: `ω = |k|`.
pub fn frequency(k: [f64; 2]) -> f64 {
    k[0].hypot(k[1])
}

/// The mode's frequency on a grid of spacing `[Δx, Δy]` (the five-point Laplacian's):
/// `ω² = Σ_a (2 sin(k_a Δ_a/2)/Δ_a)²`.
pub fn semi_discrete_frequency(k: [f64; 2], spacing: [f64; 2]) -> f64 {
    let along = |a: usize| 2.0 * (0.5 * k[a] * spacing[a]).sin() / spacing[a];
    along(0).hypot(along(1))
}

/// The mode's frequency stepped by the leapfrog (Störmer–Verlet) with step `dt`:
/// `sin(ω Δt/2) = (Δt/2) ω_h`, `ω_h` the semi-discrete frequency.
pub fn discrete_frequency(k: [f64; 2], spacing: [f64; 2], dt: f64) -> f64 {
    2.0 / dt * (0.5 * dt * semi_discrete_frequency(k, spacing)).asin()
}

/// Two membranes side by side joined by springs of stiffness `k` per unit area:
/// `ℒ = ½ (u_t² + w_t²) − ½ (|∇u|² + |∇w|²) − ½ k (u − w)²`. `u + w` is a wave; `u − w` a
/// Klein–Gordon field of mass `√(2k)`.
#[derive(Debug, Clone, Copy)]
pub struct CoupledMembranes {
    /// The springs' stiffness per unit area.
    pub k: f64,
}

impl PlaneDensity<2> for CoupledMembranes {
    fn inertia(&self, _at: [f64; 2]) -> SVector<f64, 2> {
        SVector::from([1.0, 1.0])
    }
    fn potential<S: Scalar>(
        &self,
        _at: [f64; 2],
        u: &SVector<S, 2>,
        ux: &SVector<S, 2>,
        uy: &SVector<S, 2>,
    ) -> S {
        let stretch = u[0] - u[1];
        (ux.dot(ux) + uy.dot(uy) + stretch * stretch * self.k) * 0.5
    }
}

/// A hand-written step of the membrane (`ρ = κ = 1`) on a periodic grid of `nx × ny` nodes,
/// row by row, by Störmer–Verlet (the step [`PlaneField`] takes for [`DRUM`], written out): `u`
/// the field, `p` the rates, `force` the five-point Laplacian of `u`, kept between steps.
pub fn leapfrog_membrane([u, p, force]: [&mut [f64]; 3], nx: usize, spacing: [f64; 2], dt: f64) {
    for (p, f) in p.iter_mut().zip(force.iter()) {
        *p += 0.5 * dt * f;
    }
    for (u, p) in u.iter_mut().zip(p.iter()) {
        *u += dt * p;
    }
    laplacian(u, force, nx, spacing);
    for (p, f) in p.iter_mut().zip(force.iter()) {
        *p += 0.5 * dt * f;
    }
}

/// The five-point Laplacian of `u` on a periodic grid of rows of `nx` nodes.
pub fn laplacian(u: &[f64], out: &mut [f64], nx: usize, [dx, dy]: [f64; 2]) {
    let ny = u.len() / nx;
    let (cx, cy) = (1.0 / (dx * dx), 1.0 / (dy * dy));
    for j in 0..ny {
        let (below, above) = ((j + ny - 1) % ny * nx, (j + 1) % ny * nx);
        let row = j * nx;
        for i in 0..nx {
            let (left, right) = ((i + nx - 1) % nx, (i + 1) % nx);
            let centre = u[row + i];
            out[row + i] = (u[row + left] - 2.0 * centre + u[row + right]) * cx
                + (u[below + i] - 2.0 * centre + u[above + i]) * cy;
        }
    }
}

/// The drum of the tour: the rectangle `[0, 1.5] × [0, 1]` with its edges fixed, `cells_x`
/// cells along `x` (square cells), `Δt = 0.5 Δx`.
pub fn drum(cells_x: usize) -> Result<PlaneField<Membrane, 1>, DiracError> {
    let dx = 1.5 / cells_x as f64;
    let cells_y = (1.0 / dx).round() as usize;
    let fixed = [Boundary::Fixed; 2];
    PlaneField::new(
        DRUM,
        [(0.0, 1.5), (0.0, 1.0)],
        [cells_x, cells_y],
        fixed,
        0.5 * dx,
    )
}

/// The drum's modes `(2, 1)` and `(1, 3)`, `sin(mπx/1.5) sin(nπy)`, at rest, their amplitudes
/// 1 and ½: the field at `point` and the wave numbers.
pub fn two_modes(point: [f64; 2]) -> ([f64; 2], [[f64; 2]; 2]) {
    let k = [[2.0 * PI / 1.5, PI], [PI / 1.5, 3.0 * PI]];
    let shape = |k: [f64; 2]| (k[0] * point[0]).sin() * (k[1] * point[1]).sin();
    ([shape(k[0]), 0.5 * shape(k[1])], k)
}

/// The tour's row and its figure: the drum started in two of its modes, 120 × 80 cells, run to
/// `t = 4`. Its nodes follow the two modes at the leapfrog's discrete frequencies to round-off,
/// against which the continuum's are off by the grid's dispersion.
pub fn report() -> Result<super::Report, DiracError> {
    let mut drum = drum(120)?;
    let points = drum.points();
    let modes: Vec<([f64; 2], [[f64; 2]; 2])> = points.iter().map(|&p| two_modes(p)).collect();
    let u0: Vec<SVector<f64, 1>> = modes
        .iter()
        .map(|(u, _)| SVector::from([u[0] + u[1]]))
        .collect();
    drum.start(&u0, &vec![SVector::zeros(); u0.len()])?;
    let (spacing, dt) = (drum.spacing(), drum.dt());
    let steps = (4.0 / dt).round() as u64;
    let e0 = drum.energy()?;
    let (mut drift, mut wall) = (0.0_f64, std::time::Duration::ZERO);
    for _ in 0..10 {
        let clock = std::time::Instant::now();
        drum.run(steps / 10)?;
        wall += clock.elapsed();
        drift = drift.max((drum.energy()? - e0).abs());
    }
    let t = drum.t();
    let k = modes[0].1;
    let at = |omega: [f64; 2]| {
        let u = drum.u()?.iter().zip(&modes);
        let gap = u.map(|(u, (shape, _))| {
            let exact = shape[0] * (omega[0] * t).cos() + shape[1] * (omega[1] * t).cos();
            (u[0] - exact).abs()
        });
        Ok::<f64, DiracError>(gap.fold(0.0, f64::max))
    };
    let discrete = at(k.map(|k| discrete_frequency(k, spacing, dt)))?;
    let continuum = at(k.map(frequency))?;
    Ok(super::Report {
        scene: "membrane 120×80",
        quadrature: "Störmer–Verlet".into(),
        h: dt,
        steps: drum.steps(),
        max_energy_error: Some(drift),
        wall,
        check: format!("modes: {discrete:.1e} from leapfrog, {continuum:.1e} from continuum"),
    })
}

/// The drum (120 × 80 cells) at rest, struck at `(0.5, 0.5)` (a narrow Gaussian kick of the
/// velocity, zero on the fixed edges) and run to `t`: the node axes and the field, row by row.
pub fn struck(t: f64) -> Result<([Vec<f64>; 2], Vec<f64>), DiracError> {
    let mut drum = drum(120)?;
    let [nx, ny] = drum.nodes();
    let on_edge = |k: usize| {
        let (i, j) = (k % nx, k / nx);
        i == 0 || i == nx - 1 || j == 0 || j == ny - 1
    };
    // A Gaussian, zero on the fixed edges (which do not move).
    let kick = |(k, [x, y]): (usize, [f64; 2])| {
        let r2 = (x - 0.5).powi(2) + (y - 0.5).powi(2);
        let rate = if on_edge(k) { 0.0 } else { (-r2 / 0.005).exp() };
        SVector::from([rate])
    };
    let ut0: Vec<SVector<f64, 1>> = drum.points().into_iter().enumerate().map(kick).collect();
    drum.start(&vec![SVector::zeros(); ut0.len()], &ut0)?;
    drum.run((t / drum.dt()).round() as u64)?;
    Ok((drum.axes(), drum.u()?.iter().map(|u| u[0]).collect()))
}
