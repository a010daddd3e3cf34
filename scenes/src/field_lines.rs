//! The method of lines on a field's grid: the sine-Gordon field's semi-discrete equations of
//! motion, the same spatial discretisation as dirac's `Field`, integrated in time by the peers'
//! adaptive Runge–Kutta methods (Dop853, Dopri5). On one grid the two share their spatial error,
//! so their difference is the time integrators' alone: a work–precision comparison of the field's
//! explicit multisymplectic step against them, and of their energy over long runs.

use std::cell::RefCell;
use std::time::Instant;

use dirac::nalgebra::SVector;
use dirac::{Boundary, Composition, DiracError, Field};
use ode_solvers::{DVector, System};

use super::field::{SineGordon, breather, kink};
use super::peers::{Peer, adaptive};

/// The sine-Gordon field `u_tt = u_xx − sin u` on `[a, b]` with free ends, cut into `cells`
/// cells of width `Δx`: the semi-discrete equations of dirac's `Field`. Its nodes carry masses
/// `Δx` (`Δx/2` at the ends) and its potential `Φ` sums the density over each cell by the
/// trapezoidal rule, so
///
/// ```text
/// ü_j = (u_{j+1} − 2 u_j + u_{j−1}) / Δx² − sin u_j,    ü_0 = 2 (u_1 − u_0) / Δx² − sin u_0
/// ```
///
/// (and `ü_N` likewise), as a first-order system in `y = (u_0, …, u_N, u̇_0, …, u̇_N)`.
#[derive(Debug, Clone, Copy)]
pub struct SineGordonLines {
    /// `[a, b]`.
    pub interval: (f64, f64),
    /// The cells' width `Δx`.
    pub dx: f64,
    /// The number of cells `N` (`N + 1` nodes).
    pub cells: usize,
}

impl SineGordonLines {
    /// The field on `[a, b]` in `cells` cells; `Err` for no cells or an empty interval.
    pub fn new((a, b): (f64, f64), cells: usize) -> Result<Self, String> {
        if cells == 0 || a.partial_cmp(&b) != Some(std::cmp::Ordering::Less) {
            return Err(format!(
                "{cells} cells on [{a}, {b}]: a field needs cells and a < b"
            ));
        }
        Ok(Self {
            interval: (a, b),
            dx: (b - a) / cells as f64,
            cells,
        })
    }

    /// `N + 1`.
    pub fn nodes(&self) -> usize {
        self.cells + 1
    }

    /// The node positions `x_j = a + j Δx`.
    pub fn positions(&self) -> Vec<f64> {
        (0..self.nodes())
            .map(|j| self.interval.0 + j as f64 * self.dx)
            .collect()
    }

    /// The breather of frequency `omega` ([`breather`]) at time `t`, sampled at the nodes: `y`.
    pub fn breather(&self, omega: f64, t: f64) -> DVector<f64> {
        self.sampled(|x| breather(omega, t, x))
    }

    /// `(u, u_t)` of `at(x)` at the nodes, as `y`.
    fn sampled(&self, at: impl Fn(f64) -> (f64, f64)) -> DVector<f64> {
        let n = self.nodes();
        let values: Vec<(f64, f64)> = self.positions().into_iter().map(at).collect();
        DVector::from_fn(
            2 * n,
            |i, _| if i < n { values[i].0 } else { values[i - n].1 },
        )
    }

    /// The kink moving at speed `v` ([`kink`]) at time `t`, sampled at the nodes: `y`.
    pub fn kink(&self, v: f64, t: f64) -> DVector<f64> {
        self.sampled(|x| kink(v, t, x))
    }

    /// The semi-discrete energy `Σ_j ½ m_j u̇_j² + Φ(u)`, `Φ = Δx Σ_cells [½ (D u)² +
    /// ½ (1 − cos u_j) + ½ (1 − cos u_{j+1})]`: the `Field`'s `energy` on the same grid.
    pub fn energy(&self, y: &DVector<f64>) -> f64 {
        let (n, dx) = (self.nodes(), self.dx);
        let mass = |j: usize| if j == 0 || j == n - 1 { 0.5 * dx } else { dx };
        let kinetic: f64 = (0..n).map(|j| 0.5 * mass(j) * y[n + j] * y[n + j]).sum();
        let potential: f64 = (0..self.cells)
            .map(|j| {
                let slope = (y[j + 1] - y[j]) / dx;
                dx * (0.5 * slope * slope + 1.0 - 0.5 * (y[j].cos() + y[j + 1].cos()))
            })
            .sum();
        kinetic + potential
    }
}

impl System<f64, DVector<f64>> for SineGordonLines {
    fn system(&self, _t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        let n = self.nodes();
        let k = 1.0 / (self.dx * self.dx);
        for j in 0..n {
            dy[j] = y[n + j];
        }
        let u = |j: usize| y[j];
        dy[n] = 2.0 * k * (u(1) - u(0)) - u(0).sin();
        for j in 1..n - 1 {
            dy[n + j] = k * (u(j + 1) - 2.0 * u(j) + u(j - 1)) - u(j).sin();
        }
        dy[2 * n - 1] = 2.0 * k * (u(n - 2) - u(n - 1)) - u(n - 1).sin();
    }
}

/// The lines with the largest energy error seen at the solver's accepted steps.
struct Watched<'a> {
    lines: &'a SineGordonLines,
    /// `(E_0, max |E − E_0|)`.
    energy: &'a RefCell<(f64, f64)>,
}

impl System<f64, DVector<f64>> for Watched<'_> {
    fn system(&self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        self.lines.system(t, y, dy);
    }

    fn solout(&mut self, _t: f64, y: &DVector<f64>, _dy: &DVector<f64>) -> bool {
        let mut energy = self.energy.borrow_mut();
        energy.1 = energy.1.max((self.lines.energy(y) - energy.0).abs());
        false
    }
}

/// A run on the field's grid: the end state `y`, the steps, the largest energy error over the
/// steps, and the wall time of a run that does not read the energy.
#[derive(Debug, Clone)]
pub struct LinesRun {
    /// `y = (u, u̇)` at the end.
    pub end: DVector<f64>,
    /// Steps taken (accepted steps for a peer).
    pub steps: u64,
    /// `max |E − E_0|` over the steps.
    pub energy_error: f64,
    /// Wall time of the run that does not read the energy.
    pub seconds: f64,
}

/// Integrates `lines` from `y0` to `t_end` by `peer` (Dop853 or Dopri5; BDF is refused) at
/// relative and absolute `tolerance`, as the study runs them (every accepted step stored): once
/// with the energy read at every accepted step, then timed without.
pub fn integrate(
    lines: &SineGordonLines,
    peer: Peer,
    y0: &DVector<f64>,
    t_end: f64,
    tolerance: f64,
) -> Result<LinesRun, String> {
    let energy = RefCell::new((lines.energy(y0), 0.0));
    let watched = Watched {
        lines,
        energy: &energy,
    };
    let (end, steps) = adaptive!(peer, watched, y0.clone(), t_end, tolerance)?;
    let clock = Instant::now();
    adaptive!(peer, *lines, y0.clone(), t_end, tolerance)?;
    let seconds = clock.elapsed().as_secs_f64();
    Ok(LinesRun {
        end,
        steps,
        energy_error: energy.into_inner().1,
        seconds,
    })
}

impl SineGordonLines {
    /// dirac's `Field` on this grid (free ends), stepped by `composition` with step `dt`, started
    /// from `y`.
    pub fn field(
        &self,
        composition: &Composition,
        dt: f64,
        y: &DVector<f64>,
    ) -> Result<Field<SineGordon, 1>, DiracError> {
        let n = self.nodes();
        if y.len() != 2 * n {
            return Err(DiracError::Dimension(format!(
                "y has {} entries, the grid's (u, u_t) {}",
                y.len(),
                2 * n
            )));
        }
        let mut field = Field::new(SineGordon, self.interval, self.cells, Boundary::Free, dt)?
            .with_composition(composition.clone());
        let pick = |offset: usize| -> Vec<SVector<f64, 1>> {
            (0..n).map(|j| SVector::from([y[offset + j]])).collect()
        };
        field.start(&pick(0), &pick(n))?;
        Ok(field)
    }
}

/// A run of dirac's `Field` on the lines' grid from `y0` to `t_end` (a whole number of steps
/// `dt`, else `InvalidRun`): as [`LinesRun`], the energy read at every step.
pub fn field_run(
    lines: &SineGordonLines,
    composition: &Composition,
    dt: f64,
    y0: &DVector<f64>,
    t_end: f64,
) -> Result<LinesRun, DiracError> {
    let steps = (t_end / dt).round() as u64;
    if steps == 0 || (steps as f64 * dt - t_end).abs() > 1e-9 * t_end {
        return Err(DiracError::InvalidRun(format!(
            "steps of {dt} do not reach {t_end} in a whole number"
        )));
    }
    let n = lines.nodes();
    let mut field = lines.field(composition, dt, y0)?;
    let e0 = field.energy()?;
    let mut energy_error: f64 = 0.0;
    for _ in 0..steps {
        field.step()?;
        energy_error = energy_error.max((field.energy()? - e0).abs());
    }
    let (u, ut) = (field.u()?, field.velocities()?);
    let end = DVector::from_fn(2 * n, |i, _| if i < n { u[i][0] } else { ut[i - n][0] });
    let mut timed = lines.field(composition, dt, y0)?;
    let clock = Instant::now();
    timed.run(steps)?;
    let seconds = clock.elapsed().as_secs_f64();
    Ok(LinesRun {
        end,
        steps,
        energy_error,
        seconds,
    })
}

/// `max_i |a_i − b_i|`: the distance of two states (of `u` and `u̇` at every node).
pub fn distance(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax()
}
