//! The explicit multisymplectic step of a field with a separable Lagrangian density.
//!
//! The interval `[a, b]` is cut into `N` cells of width `Δx`, time into steps `Δt`; the field
//! lives at the nodes `x_j`, `u_j^n ≈ u(nΔt, x_j)`. The discrete action is a sum over space–time
//! cells `[x_j, x_{j+1}] × [t_n, t_{n+1}]`, each with the trapezoidal rule in space and time over
//! its four corners:
//!
//! ```text
//! L_d = Δt Δx [ ½ Σ_{k=j,j+1} ½ ρ(x_k) |(u_k^{n+1} − u_k^n)/Δt|²
//!              − ¼ Σ_{k=j,j+1} Σ_{m=n,n+1} U(x_k, u_k^m, (u_{j+1}^m − u_j^m)/Δx) ]
//! ```
//!
//! (a node at a fixed or free end carries the half of its one cell). The discrete Euler–Lagrange
//! equations at every node are then the Störmer–Verlet step of the semi-discrete Lagrangian
//! `K(u̇) − Φ(u)`, `K = ½ Σ_j m_j |u̇_j|²` with `m_j = w_j ρ(x_j)` (`w_j = Δx`, or `Δx/2` at an end)
//! and `Φ = Δx Σ_cells ½ [U(x_j, u_j, D u) + U(x_{j+1}, u_{j+1}, D u)]`: one gradient of `Φ`
//! per step, each node's from its two cells, so a step costs `O(N)` and solves nothing. Being
//! the flow of a discrete action on cells, the step keeps the discrete multisymplectic form
//! formula (Marsden, Patrick and Shkoller 1998); compositions of it
//! ([`Composition`]) raise the order in time, the order in space stays 2.
//!
//! ```
//! use dirac_runtime::nalgebra::SVector;
//! use dirac_runtime::{Boundary, Field, Scalar, SeparableDensity};
//!
//! /// The wave equation `u_tt = u_xx`.
//! struct Wave;
//! impl SeparableDensity<1> for Wave {
//!     fn inertia(&self, _x: f64) -> SVector<f64, 1> {
//!         SVector::from([1.0])
//!     }
//!     fn potential<S: Scalar>(&self, _x: f64, _u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
//!         ux[0] * ux[0] * 0.5
//!     }
//! }
//! // A standing wave on a string fixed at both ends: u = sin(πx) cos(ωt).
//! let mut string = Field::new(Wave, (0.0, 1.0), 100, Boundary::Fixed, 0.005)?;
//! let u0: Vec<_> = string.positions().iter().map(|&x| SVector::from([(std::f64::consts::PI * x).sin()])).collect();
//! string.start(&u0, &vec![SVector::zeros(); u0.len()])?;
//! string.run(200)?; // to t = 1, half a period: u = −sin(πx)
//! assert!((string.u()?[50][0] + 1.0).abs() < 1e-3);
//! # Ok::<(), dirac_runtime::DiracError>(())
//! ```

use nalgebra::SVector;
use rayon::prelude::*;

use crate::base::error::DiracError;
use crate::model::density::SeparableDensity;
use crate::model::derivatives::{gradient, lift};
use crate::step::composition::Composition;

/// Nodes or cells per parallel task: a pass over this many takes tens of microseconds.
const GRAIN: usize = 4096;

/// How the ends of a field's interval are held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// `u(t, b) = u(t, a)`: `N` nodes, the last cell joining node `N − 1` to node 0; the density
    /// must be periodic too.
    Periodic,
    /// Both end nodes keep their initial values: `N + 1` nodes, the two ends at rest.
    Fixed,
    /// No force holds the ends (the natural boundary condition `∂U/∂u_x = 0` in the limit):
    /// `N + 1` nodes, each end carrying half a cell.
    Free,
}

/// A field with a separable Lagrangian density, stepped explicitly (see the
/// [module](self) documentation). A failed step leaves the state as it was.
#[derive(Debug, Clone)]
pub struct Field<D, const C: usize> {
    density: D,
    start: f64,
    dx: f64,
    cells: usize,
    boundary: Boundary,
    dt: f64,
    composition: Composition,
    parallel: bool,
    /// `m_j = w_j ρ(x_j)`, by node; zero at a fixed end (it does not move).
    mass: Vec<SVector<f64, C>>,
    run: Option<Running<C>>,
}

/// The state of a run, and the buffers a step writes into before it is accepted.
#[derive(Debug, Clone)]
struct Running<const C: usize> {
    /// The field at the nodes.
    u: Vec<SVector<f64, C>>,
    /// The momenta `m_j u̇_j` of the nodes.
    p: Vec<SVector<f64, C>>,
    /// `−∂Φ/∂u_j` at `u`.
    force: Vec<SVector<f64, C>>,
    /// The step being taken: field, momenta, force.
    next: (
        Vec<SVector<f64, C>>,
        Vec<SVector<f64, C>>,
        Vec<SVector<f64, C>>,
    ),
    /// Each cell's `∂(Δx ½[U_left + U_right])/∂u` at its left and right node.
    cells: Vec<[SVector<f64, C>; 2]>,
    steps: u64,
}

impl<D: SeparableDensity<C>, const C: usize> Field<D, C> {
    /// The field of `density` on `interval = (a, b)` cut into `cells` cells, its ends held by
    /// `boundary`, stepped by Störmer–Verlet with step `dt`. Refused: `InvalidStep` for a `dt`
    /// that is not positive and finite, `Dimension` for fewer than 2 cells (3 when periodic),
    /// `InvalidRun` for an interval that is empty or not finite, `NonFinite` for an inertia
    /// that is not positive and finite at a node.
    pub fn new(
        density: D,
        interval: (f64, f64),
        cells: usize,
        boundary: Boundary,
        dt: f64,
    ) -> Result<Self, DiracError> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(DiracError::InvalidStep { h: dt });
        }
        let least = if boundary == Boundary::Periodic { 3 } else { 2 };
        if cells < least {
            return Err(DiracError::Dimension(format!(
                "a field needs at least {least} cells with {boundary:?} ends, got {cells}"
            )));
        }
        let (a, b) = interval;
        if !(a.is_finite() && b.is_finite() && b > a) {
            return Err(DiracError::InvalidRun(format!(
                "a field's interval must be finite and not empty, got ({a}, {b})"
            )));
        }
        let dx = (b - a) / cells as f64;
        let mut field = Self {
            density,
            start: a,
            dx,
            cells,
            boundary,
            dt,
            composition: Composition::verlet(),
            parallel: false,
            mass: Vec::new(),
            run: None,
        };
        field.mass = field.masses()?;
        Ok(field)
    }

    /// The same field stepped by `composition` of Störmer–Verlet steps (order in time
    /// `composition.order()`; by default [`Composition::verlet`], order 2). Ends a run.
    pub fn with_composition(mut self, composition: Composition) -> Self {
        self.composition = composition;
        self.run = None;
        self
    }

    /// Whether the passes of a step over the cells and nodes are split across rayon's threads
    /// (by default not). The steps are the same bit for bit; a field of fewer than about 8 000
    /// nodes is stepped on one thread all the same.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }

    /// The node masses `w_j ρ(x_j)`, checked.
    fn masses(&self) -> Result<Vec<SVector<f64, C>>, DiracError> {
        let nodes = self.nodes();
        (0..nodes)
            .map(|j| {
                let x = self.position(j);
                let rho = self.density.inertia(x);
                if let Some(&bad) = rho.iter().find(|r| !(**r > 0.0 && r.is_finite())) {
                    return Err(DiracError::NonFinite {
                        what: format!("the inertia at x = {x} (it must be positive and finite)"),
                        value: bad,
                    });
                }
                let end = j == 0 || j == nodes - 1;
                Ok(match (self.boundary, end) {
                    (Boundary::Periodic, _) | (_, false) => rho * self.dx,
                    (Boundary::Fixed, true) => SVector::zeros(),
                    (Boundary::Free, true) => rho * (0.5 * self.dx),
                })
            })
            .collect()
    }

    /// The number of nodes: `N` when periodic, else `N + 1`.
    pub fn nodes(&self) -> usize {
        match self.boundary {
            Boundary::Periodic => self.cells,
            Boundary::Fixed | Boundary::Free => self.cells + 1,
        }
    }

    /// The number of cells `N`.
    pub fn cells(&self) -> usize {
        self.cells
    }

    /// The cell width `Δx`.
    pub fn dx(&self) -> f64 {
        self.dx
    }

    /// The time step `Δt`.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The composition each step takes.
    pub fn composition(&self) -> &Composition {
        &self.composition
    }

    /// The position of node `j`.
    fn position(&self, j: usize) -> f64 {
        self.start + j as f64 * self.dx
    }

    /// The positions `x_j` of the nodes.
    pub fn positions(&self) -> Vec<f64> {
        (0..self.nodes()).map(|j| self.position(j)).collect()
    }

    /// Starts a run from the field `u` and its rate `u_t` at the nodes (momenta `m_j u_t`).
    /// Refused with nothing changed: `Dimension` for a slice that is not one value per node,
    /// `NonFinite` for a value that is not finite, `InconsistentInitialState` for a fixed end
    /// that moves.
    pub fn start(
        &mut self,
        u: &[SVector<f64, C>],
        ut: &[SVector<f64, C>],
    ) -> Result<(), DiracError> {
        let nodes = self.nodes();
        for (what, values) in [("u", u), ("u_t", ut)] {
            if values.len() != nodes {
                return Err(DiracError::Dimension(format!(
                    "{what} has {} values, the field has {nodes} nodes",
                    values.len()
                )));
            }
            for (j, value) in values.iter().enumerate() {
                if let Some(&bad) = value.iter().find(|v| !v.is_finite()) {
                    return Err(DiracError::NonFinite {
                        what: format!("{what} at node {j}"),
                        value: bad,
                    });
                }
            }
        }
        if self.boundary == Boundary::Fixed {
            for j in [0, nodes - 1] {
                if !is_zero(&ut[j]) {
                    return Err(DiracError::InconsistentInitialState(format!(
                        "the field's ends are fixed, but u_t at node {j} is {:?}",
                        ut[j].as_slice()
                    )));
                }
            }
        }
        let p = ut.iter().zip(&self.mass).map(|(v, m)| v.component_mul(m));
        let zeros = vec![SVector::zeros(); nodes];
        let mut run = Running {
            u: u.to_vec(),
            p: p.collect(),
            force: zeros.clone(),
            next: (zeros.clone(), zeros.clone(), zeros),
            cells: vec![[SVector::zeros(); 2]; self.cells],
            steps: 0,
        };
        let mut force = std::mem::take(&mut run.force);
        self.force(&run.u, &mut run.cells, &mut force);
        if let Some((j, bad)) = first_not_finite(&force) {
            return Err(DiracError::NonFinite {
                what: format!("the force on node {j} of the initial field"),
                value: bad,
            });
        }
        run.force = force;
        self.run = Some(run);
        Ok(())
    }

    /// `−∂Φ/∂u` at `u` into `force` (zero at a fixed end), through each cell's shares
    /// (`cells`).
    fn force(
        &self,
        u: &[SVector<f64, C>],
        cells: &mut [[SVector<f64, C>; 2]],
        force: &mut [SVector<f64, C>],
    ) {
        let nodes = u.len();
        self.for_each(cells, |i, shares| {
            *shares = self.cell_gradient(i, &u[i], &u[(i + 1) % nodes]);
        });
        let cells = &*cells;
        self.for_each(force, |j, f| {
            let own = cells.get(j).map_or_else(SVector::zeros, |c| c[0]);
            let left = match j {
                0 if self.boundary == Boundary::Periodic => cells[nodes - 1][1],
                0 => SVector::zeros(),
                _ => cells[j - 1][1],
            };
            *f = match is_zero(&self.mass[j]) {
                true => SVector::zeros(),
                false => -(own + left),
            };
        });
    }

    /// Cell `i`'s share of `∂Φ/∂u` at its left node (field `left`) and its right node (`right`):
    /// the derivatives of `Δx ½ [U(x_i, u_i, D) + U(x_{i+1}, u_{i+1}, D)]`, `D = (u_{i+1} − u_i)/Δx`.
    fn cell_gradient(
        &self,
        i: usize,
        left: &SVector<f64, C>,
        right: &SVector<f64, C>,
    ) -> [SVector<f64, C>; 2] {
        let slope = (right - left) / self.dx;
        let (u_left, slope_left) = self.potential_gradient(self.position(i), left, &slope);
        let (u_right, slope_right) = self.potential_gradient(self.position(i + 1), right, &slope);
        let flux = (slope_left + slope_right) * 0.5;
        let half = 0.5 * self.dx;
        [u_left * half - flux, u_right * half + flux]
    }

    /// `(∂U/∂u, ∂U/∂u_x)` at `(x, u, u_x)`, by dual numbers.
    fn potential_gradient(
        &self,
        x: f64,
        u: &SVector<f64, C>,
        ux: &SVector<f64, C>,
    ) -> (SVector<f64, C>, SVector<f64, C>) {
        let (lifted_u, lifted_ux) = (lift(u, 1.0), lift(ux, 1.0));
        let (constant_u, constant_ux) = (lift(u, 0.0), lift(ux, 0.0));
        let by_u = self.density.potential(x, &lifted_u, &constant_ux);
        let by_ux = self.density.potential(x, &constant_u, &lifted_ux);
        (gradient(&by_u), gradient(&by_ux))
    }

    /// `f(j, &mut values[j])` for every `j`, across threads where the field is parallel.
    fn for_each<T: Send>(&self, values: &mut [T], f: impl Fn(usize, &mut T) + Sync + Send) {
        if self.parallel && GRAIN < values.len() {
            let each = values.par_iter_mut().enumerate().with_min_len(GRAIN);
            each.for_each(|(j, v)| f(j, v));
        } else {
            values.iter_mut().enumerate().for_each(|(j, v)| f(j, v));
        }
    }

    /// Advances one step. On error nothing changes: `NotStarted` before a start, `NonFinite`
    /// where the step reaches a value that is not finite (try a smaller step).
    pub fn step(&mut self) -> Result<(), DiracError> {
        self.run(1)
    }

    /// Advances `steps` steps; stops at the first error, with the state of the step before it.
    pub fn run(&mut self, steps: u64) -> Result<(), DiracError> {
        if self.parallel && GRAIN < self.nodes() {
            // Steps handed out from inside rayon's pool: one hand-off for the run, not one a pass.
            rayon::scope(|_| (0..steps).try_for_each(|_| self.advance()))
        } else {
            (0..steps).try_for_each(|_| self.advance())
        }
    }

    /// One step (see [`Field::step`]).
    fn advance(&mut self) -> Result<(), DiracError> {
        let mut run = self.run.take().ok_or(DiracError::NotStarted)?;
        let (mut u, mut p, mut f) = std::mem::take(&mut run.next);
        u.copy_from_slice(&run.u);
        p.copy_from_slice(&run.p);
        f.copy_from_slice(&run.force);
        let mass = &self.mass;
        for &gamma in self.composition.coefficients() {
            let tau = gamma * self.dt;
            self.for_each(&mut p, |j, p| *p += f[j] * (0.5 * tau));
            self.for_each(&mut u, |j, u| {
                if !is_zero(&mass[j]) {
                    *u += p[j].component_div(&mass[j]) * tau;
                }
            });
            self.force(&u, &mut run.cells, &mut f);
            self.for_each(&mut p, |j, p| *p += f[j] * (0.5 * tau));
        }
        let bad = [("field", &u), ("momentum", &p), ("force", &f)]
            .into_iter()
            .find_map(|(what, values)| first_not_finite(values).map(|(j, v)| (what, j, v)));
        if let Some((what, j, value)) = bad {
            let step = run.steps;
            run.next = (u, p, f);
            self.run = Some(run);
            return Err(DiracError::NonFinite {
                what: format!("the {what} at node {j} after step {step} (try a smaller step)"),
                value,
            });
        }
        std::mem::swap(&mut run.u, &mut u);
        std::mem::swap(&mut run.p, &mut p);
        std::mem::swap(&mut run.force, &mut f);
        run.next = (u, p, f);
        run.steps += 1;
        self.run = Some(run);
        Ok(())
    }

    fn running(&self) -> Result<&Running<C>, DiracError> {
        self.run.as_ref().ok_or(DiracError::NotStarted)
    }

    /// The field at the nodes.
    pub fn u(&self) -> Result<&[SVector<f64, C>], DiracError> {
        Ok(&self.running()?.u)
    }

    /// The momenta `m_j u̇_j` of the nodes (`m_j = w_j ρ(x_j)`, zero at a fixed end).
    pub fn momenta(&self) -> Result<&[SVector<f64, C>], DiracError> {
        Ok(&self.running()?.p)
    }

    /// The rates `u̇_j = p_j / m_j` at the nodes (zero at a fixed end).
    pub fn velocities(&self) -> Result<Vec<SVector<f64, C>>, DiracError> {
        let run = self.running()?;
        let rate = |(p, m): (&SVector<f64, C>, &SVector<f64, C>)| match is_zero(m) {
            true => SVector::zeros(),
            false => p.component_div(m),
        };
        Ok(run.p.iter().zip(&self.mass).map(rate).collect())
    }

    /// The time `n Δt` of the current state (0 before a start).
    pub fn t(&self) -> f64 {
        self.run.as_ref().map_or(0.0, |r| r.steps as f64 * self.dt)
    }

    /// The number of steps taken since the start.
    pub fn steps(&self) -> u64 {
        self.run.as_ref().map_or(0, |r| r.steps)
    }

    /// The energy of the semi-discrete field, `Σ_j |p_j|²_{m_j⁻¹}/2 + Φ(u)`. The step does not
    /// keep it exactly; it keeps a nearby modified energy, so its error stays bounded (of the
    /// order of `Δt^order`) over long runs.
    pub fn energy(&self) -> Result<f64, DiracError> {
        let run = self.running()?;
        let kinetic: f64 = (run.p.iter().zip(&self.mass))
            .filter(|(_, m)| !is_zero(m))
            .map(|(p, m)| 0.5 * p.component_mul(&p.component_div(m)).sum())
            .sum();
        let nodes = run.u.len();
        let potential: f64 = (0..self.cells)
            .map(|i| {
                let (left, right) = (&run.u[i], &run.u[(i + 1) % nodes]);
                let slope = (right - left) / self.dx;
                let density = &self.density;
                let ends = density.potential(self.position(i), left, &slope)
                    + density.potential(self.position(i + 1), right, &slope);
                0.5 * self.dx * ends
            })
            .sum();
        Ok(kinetic + potential)
    }
}

/// The first entry that is not finite, with its node.
fn first_not_finite<const C: usize>(values: &[SVector<f64, C>]) -> Option<(usize, f64)> {
    values
        .iter()
        .enumerate()
        .find_map(|(j, v)| v.iter().find(|x| !x.is_finite()).map(|&x| (j, x)))
}

/// Whether every entry of `v` is zero (a fixed end's mass).
fn is_zero<const C: usize>(v: &SVector<f64, C>) -> bool {
    v.iter().all(|x| *x == 0.0)
}
