//! The method of lines on a field's grid: the sine-Gordon field's semi-discrete equations of
//! motion, the same spatial discretisation as dirac's `Field`, integrated in time by the peers'
//! adaptive Runge–Kutta methods (Dop853, Dopri5). On one grid the two share their spatial error,
//! so their difference is the time integrators' alone: a work–precision comparison of the field's
//! explicit multisymplectic step against them, and of their energy over long runs.

use std::cell::RefCell;
use std::time::Instant;

use dirac::nalgebra::SVector;
use dirac::{Boundary, Composition, DiracError, Field};
use ode_solvers::dop_shared::OutputType;
use ode_solvers::{DVector, Dop853, Dopri5, System};

use super::field::{SineGordon, breather, kink};
use super::peers::Peer;

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
    /// The left end `a`.
    pub start: f64,
    /// The cells' width `Δx`.
    pub dx: f64,
    /// The number of cells `N` (`N + 1` nodes).
    pub cells: usize,
}

impl SineGordonLines {
    /// The field on `[a, b]` in `cells` cells.
    pub fn new((a, b): (f64, f64), cells: usize) -> Self {
        Self {
            start: a,
            dx: (b - a) / cells as f64,
            cells,
        }
    }

    /// `N + 1`.
    pub fn nodes(&self) -> usize {
        self.cells + 1
    }

    /// The node positions `x_j = a + j Δx`.
    pub fn positions(&self) -> Vec<f64> {
        (0..self.nodes())
            .map(|j| self.start + j as f64 * self.dx)
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
    pub end: DVector<f64>,
    pub steps: u64,
    pub energy_error: f64,
    pub seconds: f64,
}

/// Integrates `lines` from `y0` to `t_end` by `peer` (Dop853 or Dopri5) at relative and absolute
/// `tolerance`, with the crate's default controllers and no step limit: once with the energy
/// read at every accepted step, then timed without. Output is sparse (every accepted step is
/// stored, as the study's peers do): the crate's dense output at a few points off the steps
/// ended 1e-3 away from the solution on this grid.
pub fn integrate(
    lines: &SineGordonLines,
    peer: Peer,
    y0: &DVector<f64>,
    t_end: f64,
    tolerance: f64,
) -> Result<LinesRun, String> {
    let failed = |e: ode_solvers::dop_shared::IntegrationError| format!("{}: {e}", peer.name());
    let energy = RefCell::new((lines.energy(y0), 0.0));
    macro_rules! run {
        ($solver:ident, $beta:expr, $fac_min:expr, $fac_max:expr, $system:expr) => {{
            let mut solver = $solver::from_param(
                $system,
                0.0,
                t_end,
                0.0,
                y0.clone(),
                tolerance,
                tolerance,
                0.9,
                $beta,
                $fac_min,
                $fac_max,
                t_end,
                0.0,
                u32::MAX,
                1000,
                OutputType::Sparse,
            );
            let stats = solver.integrate().map_err(failed)?;
            let end = solver.y_out().last().cloned().ok_or("no output")?;
            (end, stats.accepted_steps as u64)
        }};
    }
    let watched = || Watched {
        lines,
        energy: &energy,
    };
    let (end, steps) = match peer {
        Peer::Dop853 => run!(Dop853, 0.0, 0.333, 6.0, watched()),
        Peer::Dopri5 => run!(Dopri5, 0.04, 0.2, 10.0, watched()),
        Peer::Bdf => return Err("the method of lines here is explicit: BDF is not run".into()),
    };
    let clock = Instant::now();
    match peer {
        Peer::Dop853 => run!(Dop853, 0.0, 0.333, 6.0, *lines),
        _ => run!(Dopri5, 0.04, 0.2, 10.0, *lines),
    };
    let seconds = clock.elapsed().as_secs_f64();
    Ok(LinesRun {
        end,
        steps,
        energy_error: energy.into_inner().1,
        seconds,
    })
}

/// A run of dirac's `Field` on the lines' grid: as [`LinesRun`], the energy read at every step.
pub fn field_run(
    lines: &SineGordonLines,
    composition: &Composition,
    dt: f64,
    y0: &DVector<f64>,
    t_end: f64,
) -> Result<LinesRun, DiracError> {
    let n = lines.nodes();
    let end = lines.start + lines.cells as f64 * lines.dx;
    let steps = (t_end / dt).round() as u64;
    let started = || -> Result<Field<SineGordon, 1>, DiracError> {
        let mut field = Field::new(
            SineGordon,
            (lines.start, end),
            lines.cells,
            Boundary::Free,
            dt,
        )?
        .with_composition(composition.clone());
        let pick = |offset: usize| -> Vec<SVector<f64, 1>> {
            (0..n).map(|j| SVector::from([y0[offset + j]])).collect()
        };
        field.start(&pick(0), &pick(n))?;
        Ok(field)
    };
    let mut field = started()?;
    let e0 = field.energy()?;
    let mut energy_error: f64 = 0.0;
    for _ in 0..steps {
        field.step()?;
        energy_error = energy_error.max((field.energy()? - e0).abs());
    }
    let (u, ut) = (field.u()?, field.velocities()?);
    let end_state = DVector::from_fn(2 * n, |i, _| if i < n { u[i][0] } else { ut[i - n][0] });
    let mut timed = started()?;
    let clock = Instant::now();
    timed.run(steps)?;
    let seconds = clock.elapsed().as_secs_f64();
    Ok(LinesRun {
        end: end_state,
        steps,
        energy_error,
        seconds,
    })
}

/// `max_i |a_i − b_i|`: the distance of two states (of `u` and `u̇` at every node).
pub fn distance(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax()
}
