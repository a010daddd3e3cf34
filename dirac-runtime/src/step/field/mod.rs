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
//! (a node at a free end has one cell, hence half a node's mass; a node at a fixed end does not
//! move and has none). The discrete Euler–Lagrange
//! equations at every node are then the Störmer–Verlet step of the semi-discrete Lagrangian
//! `K(u̇) − Φ(u)`, `K = ½ Σ_j m_j |u̇_j|²` with `m_j = w_j ρ(x_j)` (`w_j = Δx`, or `Δx/2` at a free end)
//! and `Φ = Δx Σ_cells ½ [U(x_j, u_j, D u) + U(x_{j+1}, u_{j+1}, D u)]`: one gradient of `Φ`
//! per step, each node's from its two cells, so a step costs `O(N)` and solves nothing. Being
//! the flow of a discrete action on cells, the step keeps the discrete multisymplectic form
//! formula (Marsden, Patrick and Shkoller 1998); compositions of it
//! ([`Composition`]) raise the order in time, and cells of higher degree
//! ([`Field::with_degree`], the field at each cell's Gauss–Lobatto points) the order in space,
//! which is 2 for these trapezoidal cells.
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
//! string.run(100)?; // to t = 0.5, a quarter period: u = 0
//! assert!(string.u()?[50][0].abs() < 3e-4);
//! # Ok::<(), dirac_runtime::DiracError>(())
//! ```

use nalgebra::{Const, SVector, U1};
use num_dual::{Derivative, HyperDualSVec64};
use rayon::prelude::*;

use crate::base::error::DiracError;
use crate::model::density::SeparableDensity;
use crate::step::composition::Composition;
use elements::Elements;
use leapfrog::{GRAIN, Grid, PARALLEL_BLOCKS, Running, is_zero};

pub use elements::MOST_DEGREE;

mod elements;
mod leapfrog;
pub mod plane;

/// How the ends of a field's interval are held, or the edges of a rectangle along one axis
/// ([`PlaneField`](plane::PlaneField)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// `u(t, b) = u(t, a)`: the last cell's last point is node 0 (on a line of cells of degree
    /// `r`, `N r` nodes); the density must be periodic too.
    Periodic,
    /// Both end nodes keep their initial values (`N r + 1` nodes on a line), the ends at rest.
    Fixed,
    /// No force holds the ends (the natural boundary condition `∂U/∂u_x = 0` in the limit):
    /// `N r + 1` nodes on a line, each end node carrying its share of its one cell (half a cell
    /// for the trapezoidal cell, `Δx / (r (r + 1))` for degree `r`).
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
    /// The Gauss–Lobatto points of a cell (the trapezoidal cell by default).
    elements: Elements,
    boundary: Boundary,
    dt: f64,
    composition: Composition,
    parallel: bool,
    /// Point masses joined to the free ends.
    end_masses: [f64; 2],
    /// `m_j = w_j ρ(x_j)`, by node, with the end masses; zero at a fixed end (it does not move).
    mass: Vec<SVector<f64, C>>,
    /// Per block of [`GRAIN`] nodes, the shares of `∂Φ/∂u` of the cells that touch them, cell
    /// by cell and point by point.
    run: Option<Running<C, Vec<Vec<SVector<f64, C>>>>>,
}

/// Numbers that carry the derivatives along `u` and along `u_x` at once.
type Pair<const C: usize> = HyperDualSVec64<C, C>;

impl<D: SeparableDensity<C>, const C: usize> Field<D, C> {
    /// The field of `density` on `interval = (a, b)` cut into `cells` cells, its ends held by
    /// `boundary`, stepped by Störmer–Verlet with step `dt`. Refused: `InvalidStep` for a `dt`
    /// that is not positive and finite, `Dimension` for fewer than 2 cells (3 when periodic),
    /// `InvalidRun` for an interval that is empty or not finite, or cells of a width that is not,
    /// `NonFinite` for an inertia or a node's mass that is not positive and finite, `Dimension`
    /// for more nodes than can be counted or held in memory.
    ///
    /// The step is explicit, so it is stable only below a limit on `dt` that depends on the
    /// density: about `Δx √(ρ/κ)` for a string of tension `κ` (the leapfrog's CFL condition),
    /// less for compositions with large coefficients and for stiff on-site terms. Above it the
    /// field grows from step to step until a step is refused as `NonFinite`; watch the energy.
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
        if !(dx > 0.0 && dx.is_finite()) {
            return Err(DiracError::InvalidRun(format!(
                "the cells of ({a}, {b}) cut into {cells} have width {dx}: it must be positive and \
                 finite"
            )));
        }
        node_count(cells, boundary, 1)?;
        let mut field = Self {
            density,
            start: a,
            dx,
            cells,
            elements: Elements::new(1)?,
            boundary,
            dt,
            composition: Composition::verlet(),
            parallel: false,
            end_masses: [0.0; 2],
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
    /// (by default not), in blocks of 4 096 nodes. The steps are the same bit for bit; a field
    /// of fewer than 16 384 nodes is stepped on one thread all the same.
    /// `cargo bench --bench step -- field_step` measures the gain.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }

    /// Point masses `left` and `right` (each component's inertia) joined to the free ends: a
    /// rigid body at each end of a string or bar, added to the end nodes' shares of their cells.
    /// The ends' condition becomes `M u_tt = ±∂U/∂u_x` (measured order 2 against the modes of a
    /// string with end masses on trapezoidal cells, `tests/suite/field.rs`). `Unsupported` unless the ends are
    /// [`Boundary::Free`]; `NonFinite` for a mass that is negative or not finite. Ends a run.
    ///
    /// ```
    /// use dirac_runtime::{Boundary, Field, Scalar, SeparableDensity};
    /// use nalgebra::SVector;
    ///
    /// /// A string: `ℒ = ½ u_t² − ½ u_x²`.
    /// struct String;
    /// impl SeparableDensity<1> for String {
    ///     fn inertia(&self, _x: f64) -> SVector<f64, 1> {
    ///         SVector::from([1.0])
    ///     }
    ///     fn potential<S: Scalar>(&self, _x: f64, _u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
    ///         ux[0] * ux[0] * 0.5
    ///     }
    /// }
    /// let mut beads = Field::new(String, (0.0, 1.0), 100, Boundary::Free, 0.005)?
    ///     .with_end_masses(2.0, 0.0)?;
    /// // A uniform motion: the whole string and its bead, mass 1 + 2.
    /// beads.start(&vec![SVector::zeros(); 101], &vec![SVector::from([1.0]); 101])?;
    /// assert!((beads.energy()? - 1.5).abs() < 1e-12);
    /// assert!(Field::new(String, (0.0, 1.0), 100, Boundary::Fixed, 0.005)?.with_end_masses(1.0, 1.0).is_err());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_end_masses(mut self, left: f64, right: f64) -> Result<Self, DiracError> {
        if self.boundary != Boundary::Free {
            return Err(DiracError::Unsupported(format!(
                "masses at the ends of a field with {:?} ends: they join free ends",
                self.boundary
            )));
        }
        if let Some(bad) = [left, right]
            .into_iter()
            .find(|m| !(*m >= 0.0 && m.is_finite()))
        {
            return Err(DiracError::NonFinite {
                what: "a mass at an end (it must be finite and not negative)".into(),
                value: bad,
            });
        }
        // A second call replaces the first's end masses.
        self.end_masses = [left, right];
        self.mass = self.masses()?;
        self.run = None;
        Ok(self)
    }

    /// The same field with cells of degree `degree` in space (1 to [`MOST_DEGREE`]; by default
    /// 1, the trapezoidal cell): each cell carries the field at its `degree + 1` Gauss–Lobatto
    /// points, and its action is integrated by that rule (spectral elements with the mass
    /// lumped on the points, a variational discretisation). The nodes are the cells' points,
    /// `N · degree` of them when periodic, else one more. `Unsupported` for a degree outside
    /// 1 to [`MOST_DEGREE`], `Dimension` for more nodes than can be counted or held,
    /// `NonFinite` as [`Field::new`] for the new nodes' masses. Ends a
    /// run.
    ///
    /// The points crowd a cell's ends (the closest are 0.17 Δx apart at degree 4, 0.05 Δx at
    /// degree 8), so the step's stability limit falls as `Δx / r²` roughly: a string of unit wave speed on cells
    /// of degree 4 needs `Δt` below about `Δx/6`. The measured orders in space are in
    /// `docs/mathematics.md`.
    ///
    /// ```
    /// use dirac_runtime::{Boundary, Field, Scalar, SeparableDensity};
    /// use nalgebra::SVector;
    ///
    /// /// A string: `ℒ = ½ u_t² − ½ u_x²`.
    /// struct String;
    /// impl SeparableDensity<1> for String {
    ///     fn inertia(&self, _x: f64) -> SVector<f64, 1> {
    ///         SVector::from([1.0])
    ///     }
    ///     fn potential<S: Scalar>(&self, _x: f64, _u: &SVector<S, 1>, ux: &SVector<S, 1>) -> S {
    ///         ux[0] * ux[0] * 0.5
    ///     }
    /// }
    /// // Ten cells of degree 4 on a fixed string: 41 nodes.
    /// let mut string = Field::new(String, (0.0, 1.0), 10, Boundary::Fixed, 0.01)?.with_degree(4)?;
    /// assert_eq!(string.nodes(), 41);
    /// let pi = std::f64::consts::PI;
    /// let u0: Vec<_> = string.positions().iter().map(|&x| SVector::from([(pi * x).sin()])).collect();
    /// string.start(&u0, &vec![SVector::zeros(); 41])?;
    /// string.run(100)?; // to t = 1, half a period: u = −sin(πx)
    /// let error = string.u()?.iter().zip(&u0).map(|(u, u0)| (u[0] + u0[0]).abs()).fold(0.0, f64::max);
    /// assert!(error < 1e-4); // the step's error in time; in space, 1e-9
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_degree(mut self, degree: usize) -> Result<Self, DiracError> {
        let elements = Elements::new(degree)?;
        node_count(self.cells, self.boundary, degree)?;
        self.elements = elements;
        self.mass = self.masses()?;
        self.run = None;
        Ok(self)
    }

    /// The degree of the cells in space.
    pub fn degree(&self) -> usize {
        self.elements.degree()
    }

    /// The node masses `w_j ρ(x_j)` with the end masses, checked: `w_j = w_m Δx` at point `m`
    /// inside a cell, `2 w_0 Δx` where two cells meet, `w_0 Δx` at a free end.
    fn masses(&self) -> Result<Vec<SVector<f64, C>>, DiracError> {
        let nodes = self.nodes();
        leapfrog::node_masses(nodes, |j| {
            let x = self.position(j);
            let rho = self.density.inertia(x);
            if let Some(&bad) = rho.iter().find(|r| !(**r > 0.0 && r.is_finite())) {
                return Err(DiracError::NonFinite {
                    what: format!("the inertia at x = {x} (it must be positive and finite)"),
                    value: bad,
                });
            }
            let weight = self.elements.node_weight(self.boundary, nodes, j, self.dx);
            let end = j == 0 || j == nodes - 1;
            let mass = match (self.boundary, end) {
                (Boundary::Fixed, true) => return Ok(SVector::zeros()),
                (Boundary::Free, true) => {
                    let end_mass = self.end_masses[usize::from(j > 0)];
                    (rho * weight).add_scalar(end_mass)
                }
                _ => rho * weight,
            };
            match mass.iter().find(|m| !(**m > 0.0 && m.is_finite())) {
                Some(&bad) => Err(DiracError::NonFinite {
                    what: format!("the mass of node {j} (ρ Δx must be positive and finite)"),
                    value: bad,
                }),
                None => Ok(mass),
            }
        })
    }

    /// The number of nodes: `N r` when periodic, else `N r + 1`, for cells of degree `r`.
    pub fn nodes(&self) -> usize {
        node_count(self.cells, self.boundary, self.degree())
            .expect("counted when the cells and their degree were set")
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

    /// The position of node `j`, point `m = j mod r` of cell `e = j / r`: `a + (e + c_m) Δx`.
    fn position(&self, j: usize) -> f64 {
        let r = self.degree();
        self.point(j / r, j % r)
    }

    /// The position of point `m` of cell `e`.
    fn point(&self, e: usize, m: usize) -> f64 {
        self.start + (e as f64 + self.elements.points[m]) * self.dx
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
        let (nodes, r) = (self.nodes(), self.degree());
        // The cells that touch a block's nodes: those they are inside, and one on each side.
        let blocks = (0..nodes.div_ceil(GRAIN)).map(|k| {
            let nodes_in_block = GRAIN.min(nodes - k * GRAIN);
            vec![SVector::zeros(); (nodes_in_block.div_ceil(r) + 2) * (r + 1)]
        });
        self.run = Some(leapfrog::start(self, u, ut, blocks.collect())?);
        Ok(())
    }

    /// [`Grid::force_and_kick`] on block `k`, whose nodes' forces and momenta are `f` and `p`:
    /// the shares of the cells that touch its nodes (from the cell before its first node's, the
    /// last cell of a periodic field before node 0), then each node's sum of its cells' shares.
    fn block_force_and_kick(
        &self,
        k: usize,
        u: &[SVector<f64, C>],
        f: &mut [SVector<f64, C>],
        p: &mut [SVector<f64, C>],
        shares: &mut [SVector<f64, C>],
        kick: f64,
    ) {
        let (r, first) = (self.degree(), k * GRAIN);
        let periodic = self.boundary == Boundary::Periodic;
        // Slot `s` holds the shares of cell `first_cell + s`; cell −1 is the last cell of a
        // periodic field, none otherwise.
        let first_cell = first.checked_sub(1).map_or(-1, |j| (j / r) as isize);
        let last_cell = ((first + f.len() - 1) / r).min(self.cells - 1) as isize;
        for (cell, slot) in (first_cell..=last_cell).zip(shares.chunks_mut(r + 1)) {
            match cell {
                -1 if periodic => self.cell_gradient(self.cells - 1, u, slot),
                -1 => slot.fill(SVector::zeros()),
                cell => self.cell_gradient(cell as usize, u, slot),
            }
        }
        let share =
            |cell: usize, m: usize| shares[(cell as isize - first_cell) as usize * (r + 1) + m];
        // Node `j` is point `m` of `cell`, counted along (no division a node).
        let (mut cell, mut m) = (first / r, first % r);
        for (j, (f, p)) in (first..).zip(f.iter_mut().zip(p.iter_mut())) {
            *f = match (is_zero(&self.mass[j]), m) {
                (true, _) => SVector::zeros(),
                (false, 0) => {
                    // Where two cells meet: the last point of the one before and the first of
                    // this one (neither past an end).
                    let before = match cell {
                        0 => shares[r],
                        _ => share(cell - 1, r),
                    };
                    let own = match cell < self.cells {
                        true => share(cell, 0),
                        false => SVector::zeros(),
                    };
                    -(before + own)
                }
                (false, m) => -share(cell, m),
            };
            *p += *f * kick;
            m += 1;
            if m == r {
                (cell, m) = (cell + 1, 0);
            }
        }
    }

    /// Cell `e`'s shares of `∂Φ/∂u` at its points, into `out`: the derivatives of
    /// `Δx Σ_q w_q U(x_q, u_q, Σ_m D_qm u_m / Δx)`.
    fn cell_gradient(&self, e: usize, u: &[SVector<f64, C>], out: &mut [SVector<f64, C>]) {
        let (cell, r) = (&self.elements, self.degree());
        if r == 1 {
            // The trapezoidal cell, its sums written out: the general loop below costs 1.4 times
            // as much at this degree (32 against 23 ns a node, 10⁵ sine-Gordon cells).
            let (left, right) = (&u[e], &u[(e + 1) % u.len()]);
            let slope = (right - left) / self.dx;
            let (u_left, slope_left) = self.potential_gradient(self.point(e, 0), left, &slope);
            let (u_right, slope_right) = self.potential_gradient(self.point(e, 1), right, &slope);
            let flux = (slope_left + slope_right) * 0.5;
            let half = 0.5 * self.dx;
            out[0] = u_left * half - flux;
            out[1] = u_right * half + flux;
            return;
        }
        // The cell's values (its last point is node 0 on the last cell of a periodic field).
        let mut values = [SVector::zeros(); MOST_DEGREE + 1];
        let first = e * r;
        let inside = u.len().min(first + r + 1) - first;
        values[..inside].copy_from_slice(&u[first..first + inside]);
        if inside == r {
            values[r] = u[0];
        }
        // At each point, the derivatives in the field and in the slope, weighted.
        let mut own = [SVector::zeros(); MOST_DEGREE + 1];
        let mut flux = [SVector::zeros(); MOST_DEGREE + 1];
        let rows = cell.derivative.chunks(r + 1).zip(&cell.weights);
        for (q, (d, &weight)) in rows.enumerate() {
            let slope = values[..=r]
                .iter()
                .zip(d)
                .fold(SVector::zeros(), |s, (v, d)| s + v * *d);
            let slope = slope / self.dx;
            let (by_u, by_slope) = self.potential_gradient(self.point(e, q), &values[q], &slope);
            own[q] = by_u * (weight * self.dx);
            flux[q] = by_slope * weight;
        }
        // Each point's share: its own term and every point's flux through `D`'s column.
        for (m, out) in out[..=r].iter_mut().enumerate() {
            let column = (0..=r).map(|q| cell.derivative[q * (r + 1) + m]);
            *out = flux[..=r]
                .iter()
                .zip(column)
                .fold(own[m], |s, (f, d)| s + f * d);
        }
    }

    /// `(∂U/∂u, ∂U/∂u_x)` at `(x, u, u_x)`, in one pass of hyper-dual numbers: `u` moves along
    /// the first infinitesimals, `u_x` along the second (their product, where it arises, is not
    /// read).
    fn potential_gradient(
        &self,
        x: f64,
        u: &SVector<f64, C>,
        ux: &SVector<f64, C>,
    ) -> (SVector<f64, C>, SVector<f64, C>) {
        let unit = |i: usize| SVector::<f64, C>::from_fn(|j, _| if i == j { 1.0 } else { 0.0 });
        let u = SVector::from_fn(|i, _| {
            Pair::new(
                u[i],
                Derivative::some(unit(i)),
                Derivative::none(),
                Derivative::none(),
            )
        });
        let ux = SVector::from_fn(|i, _| {
            let along = Derivative::some(unit(i).transpose());
            Pair::new(ux[i], Derivative::none(), along, Derivative::none())
        });
        let value = self.density.potential(x, &u, &ux);
        let by_u = value.eps1.unwrap_generic(Const::<C>, U1);
        let by_ux = value.eps2.unwrap_generic(U1, Const::<C>).transpose();
        (by_u, by_ux)
    }

    /// Advances one step. On error nothing changes: `NotStarted` before a start, `NonFinite`
    /// where the step reaches a value that is not finite (try a smaller step).
    pub fn step(&mut self) -> Result<(), DiracError> {
        self.run(1)
    }

    /// Advances `steps` steps; stops at the first error, with the state of the step before it.
    pub fn run(&mut self, steps: u64) -> Result<(), DiracError> {
        let mut run = self.run.take().ok_or(DiracError::NotStarted)?;
        let field = &*self;
        let taken = leapfrog::run_steps(self.in_parallel(), steps, || {
            leapfrog::advance(field, &field.composition, field.dt, &mut run)
        });
        self.run = Some(run);
        taken
    }

    fn running(&self) -> Result<&Running<C, Vec<Vec<SVector<f64, C>>>>, DiracError> {
        self.run.as_ref().ok_or(DiracError::NotStarted)
    }

    /// The field at the nodes.
    pub fn u(&self) -> Result<&[SVector<f64, C>], DiracError> {
        Ok(&self.running()?.now.u)
    }

    /// The momenta `m_j u̇_j` of the nodes (`m_j = w_j ρ(x_j)`, zero at a fixed end).
    pub fn momenta(&self) -> Result<&[SVector<f64, C>], DiracError> {
        Ok(&self.running()?.now.p)
    }

    /// The rates `u̇_j = p_j / m_j` at the nodes (zero at a fixed end).
    pub fn velocities(&self) -> Result<Vec<SVector<f64, C>>, DiracError> {
        Ok(leapfrog::rates(&self.running()?.now.p, &self.mass))
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
        let kinetic = leapfrog::kinetic(&run.now.p, &self.mass);
        let (u, r, cell) = (&run.now.u, self.degree(), &self.elements);
        let value = |e: usize, m: usize| &u[(e * r + m) % u.len()];
        let potential: f64 = (0..self.cells)
            .map(|e| {
                let at = |q: usize| {
                    let slope =
                        (0..=r).fold(SVector::zeros(), |s, m| s + value(e, m) * cell.d(q, m));
                    let slope = slope / self.dx;
                    cell.weights[q]
                        * self
                            .density
                            .potential(self.point(e, q), value(e, q), &slope)
                };
                self.dx * (0..=r).map(at).sum::<f64>()
            })
            .sum();
        Ok(kinetic + potential)
    }
}

impl<D: SeparableDensity<C>, const C: usize> Grid<C> for Field<D, C> {
    type Scratch = Vec<Vec<SVector<f64, C>>>;

    fn mass(&self) -> &[SVector<f64, C>] {
        &self.mass
    }

    fn in_parallel(&self) -> bool {
        self.parallel && self.nodes() >= PARALLEL_BLOCKS * GRAIN
    }

    /// A block of [`GRAIN`] nodes at a time: each block takes the shares of the cells that touch
    /// its nodes into its own `shares` (a cell at a block's edge is taken by both blocks, alike).
    fn force_and_kick(
        &self,
        u: &[SVector<f64, C>],
        f: &mut [SVector<f64, C>],
        p: &mut [SVector<f64, C>],
        shares: &mut Self::Scratch,
        kick: f64,
    ) {
        if self.in_parallel() {
            let blocks = f.par_chunks_mut(GRAIN).zip(p.par_chunks_mut(GRAIN));
            let blocks = blocks.zip(shares.par_iter_mut()).enumerate();
            blocks.for_each(|(k, ((f, p), shares))| {
                self.block_force_and_kick(k, u, f, p, shares, kick)
            });
        } else {
            let blocks = f.chunks_mut(GRAIN).zip(p.chunks_mut(GRAIN));
            let blocks = blocks.zip(shares.iter_mut()).enumerate();
            blocks.for_each(|(k, ((f, p), shares))| {
                self.block_force_and_kick(k, u, f, p, shares, kick)
            });
        }
    }
}

/// The number of nodes of `cells` of degree `r`: `N r` when periodic, else `N r + 1`;
/// `Dimension` where it cannot be counted.
fn node_count(cells: usize, boundary: Boundary, r: usize) -> Result<usize, DiracError> {
    let points = cells.checked_mul(r);
    let nodes = match boundary {
        Boundary::Periodic => points,
        Boundary::Fixed | Boundary::Free => points.and_then(|n| n.checked_add(1)),
    };
    nodes.ok_or_else(|| {
        DiracError::Dimension(format!(
            "{cells} cells of degree {r} make more nodes than can be counted"
        ))
    })
}
