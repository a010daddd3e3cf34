//! The explicit multisymplectic step of a field on a rectangle of the plane.
//!
//! The rectangle `[a, b] × [c, d]` is cut into `N_x × N_y` cells of size `Δx × Δy`, time into
//! steps `Δt`; the field lives at the nodes `(x_i, y_j)`. The discrete action is a sum over
//! space–time boxes `[x_i, x_{i+1}] × [y_j, y_{j+1}] × [t_n, t_{n+1}]`, each with the trapezoidal
//! rule over its eight corners. At a corner of a cell the slope is read along the cell's two
//! edges that meet there: at `(x_i, y_j)` of the cell above and to the right,
//! `u_x = (u_{i+1,j} − u_{i,j})/Δx` and `u_y = (u_{i,j+1} − u_{i,j})/Δy`, and alike at the other
//! three corners. So
//!
//! ```text
//! L_d = Δt ΔxΔy/4 Σ_corners [ ½ ρ |(u^{n+1} − u^n)/Δt|² − ½ Σ_{m=n,n+1} U(x, y, u^m, u_x^m, u_y^m) ]
//! ```
//!
//! and, as on the line, the discrete Euler–Lagrange equations at every node are the
//! Störmer–Verlet step of `K(u̇) − Φ(u)`: node masses `m = w_x w_y ρ` (`w = Δx`, or `Δx/2` at a
//! free edge, `0` at a fixed one), `Φ = ΔxΔy/4 Σ_cells Σ_corners U`. Each node's force is the sum
//! of what its own four corners and its four neighbours' corners give it, so a step costs `O(N)`
//! and solves nothing. For the membrane `U = ½ κ (u_x² + u_y²)` the corners make the five-point
//! Laplacian, whose standing and travelling waves the step keeps with the leapfrog's discrete
//! dispersion relation exactly. Being the flow of a discrete action on cells, the step keeps
//! the discrete multisymplectic form formula; its order is 2 in space, and in time that of the
//! [`Composition`]. Cells of higher degree ([`PlaneField::with_degree`]: the field at the
//! tensor-product Gauss–Lobatto points of each cell, the action by that rule) raise the order
//! in space.
//!
//! ```
//! use dirac_runtime::nalgebra::SVector;
//! use dirac_runtime::{Boundary, PlaneDensity, PlaneField, Scalar};
//!
//! /// The membrane `u_tt = u_xx + u_yy`.
//! struct Membrane;
//! impl PlaneDensity<1> for Membrane {
//!     fn inertia(&self, _at: [f64; 2]) -> SVector<f64, 1> {
//!         SVector::from([1.0])
//!     }
//!     fn potential<S: Scalar>(&self, _at: [f64; 2], _u: &SVector<S, 1>, ux: &SVector<S, 1>, uy: &SVector<S, 1>) -> S {
//!         (ux[0] * ux[0] + uy[0] * uy[0]) * 0.5
//!     }
//! }
//! // The square drum's first mode: u = sin(πx) sin(πy) cos(√2 π t).
//! let fixed = [Boundary::Fixed; 2];
//! let mut drum = PlaneField::new(Membrane, [(0.0, 1.0), (0.0, 1.0)], [50, 50], fixed, 0.005)?;
//! let pi = std::f64::consts::PI;
//! let u0: Vec<_> = drum.points().iter().map(|[x, y]| SVector::from([(pi * x).sin() * (pi * y).sin()])).collect();
//! drum.start(&u0, &vec![SVector::zeros(); u0.len()])?;
//! let quarter = 1.0 / (2.0 * 2f64.sqrt()); // a quarter period: u = 0
//! drum.run((quarter / 0.005).round() as u64)?;
//! assert!(drum.u()?.iter().all(|u| u[0].abs() < 1e-2));
//! # Ok::<(), dirac_runtime::DiracError>(())
//! ```

use nalgebra::{Const, SVector, U1};
use num_dual::{Derivative, DualSVec64, HyperDualSVec64};
use rayon::prelude::*;

use super::Boundary;
use super::elements::{Elements, MOST_DEGREE};
use super::leapfrog::{self, GRAIN, Grid, Running, is_zero};
use crate::base::error::DiracError;
use crate::model::density::PlaneDensity;
use crate::step::composition::Composition;

/// What a node's four corners give to `∂Φ/∂u`, by receiving node: itself ([`OWN`]) and its
/// neighbours to the right, left, above and below ([`RIGHT`], [`LEFT`], [`UP`], [`DOWN`]).
type Sends<const C: usize> = [SVector<f64, C>; 5];
const OWN: usize = 0;
const RIGHT: usize = 1;
const LEFT: usize = 2;
const UP: usize = 3;
const DOWN: usize = 4;

/// A field on a rectangle of the plane with a separable Lagrangian density, stepped explicitly
/// (see the [module](self) documentation). A failed step leaves the state as it was.
///
/// Nodes are numbered row by row: node `(i, j)`, at `(x_i, y_j)`, is `j · n_x + i`, where `n_x`
/// is the number of nodes along `x` ([`PlaneField::nodes`]).
#[derive(Debug, Clone)]
pub struct PlaneField<D, const C: usize> {
    density: D,
    origin: [f64; 2],
    spacing: [f64; 2],
    cells: [usize; 2],
    /// The numbers of nodes `[n_x, n_y]`.
    nodes: [usize; 2],
    boundary: [Boundary; 2],
    dt: f64,
    composition: Composition,
    parallel: bool,
    /// The Gauss–Lobatto points of the cells along each axis (degree 1: the box cell's corners).
    elements: Elements,
    /// `m = w_x w_y ρ`, by node; zero at a node on a fixed edge (it does not move).
    mass: Vec<SVector<f64, C>>,
    /// Per band of rows, a [`Window`].
    run: Option<Running<C, Vec<Window<C>>>>,
}

/// The [`Sends`] of three rows of nodes: the row below the one being gathered, that row, and
/// the row above.
type Window<const C: usize> = [Vec<Sends<C>>; 3];

/// Nodes a band of rows holds at least when the passes are split across threads: each band
/// evaluates the corners of the rows just outside it again, one row on each side.
const BAND: usize = 4 * GRAIN;

/// Bands a field needs for its passes to be split across threads.
const PARALLEL_BANDS: usize = 2;

/// Numbers that carry the derivatives along `u` and along `u_x` at once.
type Pair<const C: usize> = HyperDualSVec64<C, C>;

impl<D: PlaneDensity<C>, const C: usize> PlaneField<D, C> {
    /// The field of `density` on the rectangle `[a, b] × [c, d]` (`rectangle = [(a, b), (c, d)]`)
    /// cut into `cells = [N_x, N_y]` cells, its edges along `x` and along `y` held by
    /// `boundary = [at x = a and b, at y = c and d]`, stepped by Störmer–Verlet with step `dt`.
    /// Refused: `InvalidStep` for a `dt` that is not positive and finite, `Dimension` for fewer
    /// than 2 cells along an axis (3 when periodic) or more nodes than can be counted or held in
    /// memory, `InvalidRun` for sides that are empty or not finite, `NonFinite` for an inertia or
    /// a node's mass that is not positive and finite.
    ///
    /// The step is explicit, so it is stable only below a limit on `dt`: about
    /// `√(ρ/κ) / √(1/Δx² + 1/Δy²)` for a membrane of tension `κ`, less for compositions with
    /// large coefficients and for stiff on-site terms. Above it the field grows from step to
    /// step until a step is refused as `NonFinite`; watch the energy.
    pub fn new(
        density: D,
        rectangle: [(f64, f64); 2],
        cells: [usize; 2],
        boundary: [Boundary; 2],
        dt: f64,
    ) -> Result<Self, DiracError> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(DiracError::InvalidStep { h: dt });
        }
        let mut spacing = [0.0; 2];
        for axis in 0..2 {
            let (name, (a, b)) = (["x", "y"][axis], rectangle[axis]);
            let least = if boundary[axis] == Boundary::Periodic {
                3
            } else {
                2
            };
            if cells[axis] < least {
                return Err(DiracError::Dimension(format!(
                    "a field needs at least {least} cells along {name} with {:?} edges, got {}",
                    boundary[axis], cells[axis]
                )));
            }
            if !(a.is_finite() && b.is_finite() && b > a) {
                return Err(DiracError::InvalidRun(format!(
                    "a field's side along {name} must be finite and not empty, got ({a}, {b})"
                )));
            }
            spacing[axis] = (b - a) / cells[axis] as f64;
            if !(spacing[axis] > 0.0 && spacing[axis].is_finite()) {
                return Err(DiracError::InvalidRun(format!(
                    "the cells of ({a}, {b}) cut into {} have width {}: it must be positive and \
                     finite",
                    cells[axis], spacing[axis]
                )));
            }
        }
        let nodes = node_counts(cells, boundary, 1)?;
        let mut field = Self {
            density,
            origin: rectangle.map(|side| side.0),
            spacing,
            cells,
            nodes,
            boundary,
            dt,
            composition: Composition::verlet(),
            parallel: false,
            elements: Elements::new(1)?,
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

    /// Whether the passes of a step over the nodes are split across rayon's threads (by default
    /// not), in bands of rows of about 16 384 nodes (of cells, for cells of degree 2 and above:
    /// [`with_degree`](Self::with_degree)). The steps are the same bit for bit; a field of fewer
    /// than 32 768 nodes (one band) is stepped on one thread all the same. `cargo bench --bench
    /// step -- plane_field_step` measures the gain.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }

    /// The same field with cells of degree `degree` along each axis (1 to [`MOST_DEGREE`]; by
    /// default 1, the box cell): each cell carries the field at the `(degree + 1)²` points of the
    /// tensor-product Gauss–Lobatto rule, the field inside it is the polynomial of that degree in
    /// `x` and in `y` through them, and its action is integrated by that rule, the kinetic energy
    /// lumped on the points (spectral elements on quadrilaterals). Degree 1 is the box cell.
    /// The nodes are the cells' points: `N r` along a periodic axis, else `N r + 1`.
    /// `Unsupported` for a degree outside 1 to [`MOST_DEGREE`], `Dimension` for more nodes than
    /// can be counted, `NonFinite` as [`PlaneField::new`] for the new nodes' masses. Ends a run.
    ///
    /// As on a line, the points crowd the cells' edges and the stability limit on `Δt` falls
    /// about as `1/r²`. The measured
    /// orders in space are in `docs/mathematics.md`.
    ///
    /// ```
    /// use dirac_runtime::nalgebra::SVector;
    /// use dirac_runtime::{Boundary, PlaneDensity, PlaneField, Scalar};
    ///
    /// struct Membrane;
    /// impl PlaneDensity<1> for Membrane {
    ///     fn inertia(&self, _at: [f64; 2]) -> SVector<f64, 1> {
    ///         SVector::from([1.0])
    ///     }
    ///     fn potential<S: Scalar>(&self, _at: [f64; 2], _u: &SVector<S, 1>, ux: &SVector<S, 1>, uy: &SVector<S, 1>) -> S {
    ///         (ux[0] * ux[0] + uy[0] * uy[0]) * 0.5
    ///     }
    /// }
    /// // The square drum on 4 × 4 cells of degree 4: 17 × 17 nodes.
    /// let fixed = [Boundary::Fixed; 2];
    /// let mut drum = PlaneField::new(Membrane, [(0.0, 1.0), (0.0, 1.0)], [4, 4], fixed, 0.005)?
    ///     .with_degree(4)?;
    /// assert_eq!(drum.nodes(), [17, 17]);
    /// let pi = std::f64::consts::PI;
    /// let mode = |[x, y]: [f64; 2]| SVector::from([(pi * x).sin() * (pi * y).sin()]);
    /// let u0: Vec<_> = drum.points().into_iter().map(mode).collect();
    /// drum.start(&u0, &vec![SVector::zeros(); u0.len()])?;
    /// let period = 2f64.sqrt(); // of the first mode, ω = √2 π
    /// drum.run((period / 0.005).round() as u64)?; // to t = 1.415, about a period
    /// let error = drum.u()?.iter().zip(&u0).map(|(u, u0)| (u - u0).amax()).fold(0.0, f64::max);
    /// assert!(error < 1e-4, "{error}"); // back where it started
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn with_degree(mut self, degree: usize) -> Result<Self, DiracError> {
        let elements = Elements::new(degree)?;
        self.nodes = node_counts(self.cells, self.boundary, degree)?;
        self.elements = elements;
        self.mass = self.masses()?;
        self.run = None;
        Ok(self)
    }

    /// The degree of the cells in space.
    pub fn degree(&self) -> usize {
        self.elements.degree()
    }

    /// The weight of the nodes of index `i` along `axis` ([`Elements::node_weight`]).
    fn weight(&self, axis: usize, i: usize) -> f64 {
        let (n, width) = (self.nodes[axis], self.spacing[axis]);
        (self.elements).node_weight(self.boundary[axis], n, i, width)
    }

    /// The node masses `w_x w_y ρ`, checked.
    fn masses(&self) -> Result<Vec<SVector<f64, C>>, DiracError> {
        let [nx, ny] = self.nodes;
        leapfrog::node_masses(nx * ny, |k| {
            let at = self.position(k);
            let rho = self.density.inertia(at);
            if let Some(&bad) = rho.iter().find(|r| !(**r > 0.0 && r.is_finite())) {
                return Err(DiracError::NonFinite {
                    what: format!("the inertia at {at:?} (it must be positive and finite)"),
                    value: bad,
                });
            }
            let (wx, wy) = (self.weight(0, k % nx), self.weight(1, k / nx));
            let mass = rho * (wx * wy);
            let fixed = wx == 0.0 || wy == 0.0;
            match mass.iter().find(|m| !(fixed || **m > 0.0 && m.is_finite())) {
                Some(&bad) => Err(DiracError::NonFinite {
                    what: format!("the mass of node {k} (ρ w_x w_y must be positive and finite)"),
                    value: bad,
                }),
                None => Ok(mass),
            }
        })
    }

    /// The numbers of nodes `[n_x, n_y]`: `N r` along a periodic axis, else `N r + 1`, for cells
    /// of degree `r`.
    pub fn nodes(&self) -> [usize; 2] {
        self.nodes
    }

    /// The numbers of cells `[N_x, N_y]`.
    pub fn cells(&self) -> [usize; 2] {
        self.cells
    }

    /// How the edges are held: `[at x = a and b, at y = c and d]`.
    pub fn boundary(&self) -> [Boundary; 2] {
        self.boundary
    }

    /// The cell size `[Δx, Δy]`.
    pub fn spacing(&self) -> [f64; 2] {
        self.spacing
    }

    /// The time step `Δt`.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The composition each step takes.
    pub fn composition(&self) -> &Composition {
        &self.composition
    }

    /// The position `[x_i, y_j]` of node `k = j n_x + i`.
    fn position(&self, k: usize) -> [f64; 2] {
        let nx = self.nodes[0];
        self.point(k % nx, k / nx)
    }

    /// The position `[x_i, y_j]` of node `(i, j)`.
    fn point(&self, i: usize, j: usize) -> [f64; 2] {
        [self.coordinate(0, i), self.coordinate(1, j)]
    }

    /// The coordinate along `axis` of the nodes of index `i` along it, point `m = i mod r` of
    /// cell `e = i / r`: `a + (e + c_m) Δx`.
    fn coordinate(&self, axis: usize, i: usize) -> f64 {
        let r = self.degree();
        let (e, m) = (i / r, i % r);
        self.origin[axis] + (e as f64 + self.elements.points[m]) * self.spacing[axis]
    }

    /// The positions `[x, y]` of the nodes, row by row.
    pub fn points(&self) -> Vec<[f64; 2]> {
        let [nx, ny] = self.nodes();
        (0..nx * ny).map(|k| self.position(k)).collect()
    }

    /// The positions `x_i` and `y_j` of the nodes along each axis.
    pub fn axes(&self) -> [Vec<f64>; 2] {
        let nodes = self.nodes();
        [0, 1].map(|a| (0..nodes[a]).map(|i| self.coordinate(a, i)).collect())
    }

    /// The neighbour of index `i` along `axis`, a step `+1` or `−1` away, where there is one.
    fn neighbour(&self, axis: usize, i: usize, up: bool) -> Option<usize> {
        let n = self.nodes[axis];
        let periodic = self.boundary[axis] == Boundary::Periodic;
        match (up, i) {
            (true, i) if i + 1 < n => Some(i + 1),
            (true, _) => periodic.then_some(0),
            (false, 0) => periodic.then_some(n - 1),
            (false, i) => Some(i - 1),
        }
    }

    /// Starts a run from the field `u` and its rate `u_t` at the nodes, row by row (momenta
    /// `m u_t`). Refused with nothing changed: `Dimension` for a slice that is not one value per
    /// node, `NonFinite` for a value that is not finite, `InconsistentInitialState` for a node
    /// on a fixed edge that moves.
    pub fn start(
        &mut self,
        u: &[SVector<f64, C>],
        ut: &[SVector<f64, C>],
    ) -> Result<(), DiracError> {
        // Cells of higher degree keep their scratch on the stack, one a pass.
        let row = vec![[SVector::zeros(); 5]; if self.degree() == 1 { self.nodes[0] } else { 0 }];
        let bands = if self.in_parallel() {
            self.bands().1
        } else {
            1
        };
        let windows = vec![[row.clone(), row.clone(), row]; bands];
        self.run = Some(leapfrog::start(self, u, ut, windows)?);
        Ok(())
    }

    /// The shares of `∂Φ/∂u` that node `k`'s corners (`k` the node, `u` the field) give to it
    /// and to its neighbours.
    fn sends(&self, (k, i, j): (usize, usize, usize), u: &[SVector<f64, C>]) -> Sends<C> {
        let nx = self.nodes[0];
        let [dx, dy] = self.spacing;
        let at = self.point(i, j);
        let here = &u[k];
        // The slopes along the node's edges that exist, each with its `∂slope/∂u` at the far
        // node and the send that goes there.
        let edge = |far: Option<usize>, rate: f64, to: usize| {
            far.map(|far| ((u[far] - here) * rate, rate, to))
        };
        let (right, left) = (self.neighbour(0, i, true), self.neighbour(0, i, false));
        let (above, below) = (self.neighbour(1, j, true), self.neighbour(1, j, false));
        let along_x = [
            edge(right.map(|r| j * nx + r), 1.0 / dx, RIGHT),
            edge(left.map(|l| j * nx + l), -1.0 / dx, LEFT),
        ];
        let along_y = [
            edge(above.map(|a| a * nx + i), 1.0 / dy, UP),
            edge(below.map(|b| b * nx + i), -1.0 / dy, DOWN),
        ];
        let mut sends = [SVector::zeros(); 5];
        for (ux, rate_x, to_x) in along_x.iter().flatten() {
            for (uy, rate_y, to_y) in along_y.iter().flatten() {
                let (by_u, by_ux, by_uy) = self.potential_gradient(at, here, ux, uy);
                let (to_far_x, to_far_y) = (by_ux * *rate_x, by_uy * *rate_y);
                sends[OWN] += by_u - to_far_x - to_far_y;
                sends[*to_x] += to_far_x;
                sends[*to_y] += to_far_y;
            }
        }
        let weight = 0.25 * dx * dy;
        sends.map(|s| s * weight)
    }

    /// The rows in a band of the passes split across threads (the last band may hold fewer), and
    /// the number of bands.
    fn bands(&self) -> (usize, usize) {
        let [nx, ny] = self.nodes;
        // As many bands as `BAND`s of nodes, of 8 rows at least, their rows shared out evenly.
        let bands = (nx * ny / BAND).clamp(1, ny.div_ceil(8));
        let rows = ny.div_ceil(bands);
        (rows, ny.div_ceil(rows))
    }

    /// The [`Sends`] of every node of row `j` into `row`.
    fn send_row(&self, j: usize, u: &[SVector<f64, C>], row: &mut [Sends<C>]) {
        let nx = self.nodes[0];
        for (i, sends) in row.iter_mut().enumerate() {
            *sends = self.sends((j * nx + i, i, j), u);
        }
    }

    /// The forces `f` on the rows of a band from row `first` on, gathered from the [`Sends`]
    /// of their nodes and their neighbours (rolled through `window` row by row), and the kick
    /// `p += kick · f`.
    fn band(
        &self,
        first: usize,
        u: &[SVector<f64, C>],
        (f, p): (&mut [SVector<f64, C>], &mut [SVector<f64, C>]),
        window: &mut Window<C>,
        kick: f64,
    ) {
        let nx = self.nodes[0];
        let rows = f.len() / nx;
        if let Some(below) = self.neighbour(1, first, false) {
            self.send_row(below, u, &mut window[0]);
        }
        self.send_row(first, u, &mut window[1]);
        let rows_of_nodes = f.chunks_mut(nx).zip(p.chunks_mut(nx));
        for (j, (f, p)) in (first..first + rows).zip(rows_of_nodes) {
            let above = self.neighbour(1, j, true);
            if let Some(above) = above {
                self.send_row(above, u, &mut window[2]);
            }
            let below = self.neighbour(1, j, false);
            let [from_below, here, from_above] = &*window;
            for (i, (f, p)) in f.iter_mut().zip(p.iter_mut()).enumerate() {
                let k = j * nx + i;
                if is_zero(&self.mass[k]) {
                    *f = SVector::zeros();
                    continue;
                }
                let mut sum = here[i][OWN];
                if let Some(left) = self.neighbour(0, i, false) {
                    sum += here[left][RIGHT];
                }
                if let Some(right) = self.neighbour(0, i, true) {
                    sum += here[right][LEFT];
                }
                if below.is_some() {
                    sum += from_below[i][UP];
                }
                if above.is_some() {
                    sum += from_above[i][DOWN];
                }
                *f = -sum;
                *p += *f * kick;
            }
            window.rotate_left(1);
        }
    }

    /// `(∂U/∂u, ∂U/∂u_x, ∂U/∂u_y)` at `(at, u, u_x, u_y)`: one pass of hyper-dual numbers with
    /// `u` along the first infinitesimals and `u_x` along the second, one of dual numbers along
    /// `u_y`.
    fn potential_gradient(
        &self,
        at: [f64; 2],
        u: &SVector<f64, C>,
        ux: &SVector<f64, C>,
        uy: &SVector<f64, C>,
    ) -> (SVector<f64, C>, SVector<f64, C>, SVector<f64, C>) {
        let unit = |i: usize| SVector::<f64, C>::from_fn(|j, _| if i == j { 1.0 } else { 0.0 });
        let pair_u = SVector::from_fn(|i, _| {
            let along = Derivative::some(unit(i));
            Pair::new(u[i], along, Derivative::none(), Derivative::none())
        });
        let pair_ux = SVector::from_fn(|i, _| {
            let along = Derivative::some(unit(i).transpose());
            Pair::new(ux[i], Derivative::none(), along, Derivative::none())
        });
        let pair_uy = uy.map(Pair::from_re);
        let value = self.density.potential(at, &pair_u, &pair_ux, &pair_uy);
        let by_u = value.eps1.unwrap_generic(Const::<C>, U1);
        let by_ux = value.eps2.unwrap_generic(U1, Const::<C>).transpose();
        let plain = |v: &SVector<f64, C>| v.map(DualSVec64::<C>::from_re);
        let dual_uy = SVector::from_fn(|i, _| DualSVec64::new(uy[i], Derivative::some(unit(i))));
        let value = self.density.potential(at, &plain(u), &plain(ux), &dual_uy);
        let by_uy = value.eps.unwrap_generic(Const::<C>, U1);
        (by_u, by_ux, by_uy)
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

    fn running(&self) -> Result<&Running<C, Vec<Window<C>>>, DiracError> {
        self.run.as_ref().ok_or(DiracError::NotStarted)
    }

    /// The field at the nodes, row by row.
    pub fn u(&self) -> Result<&[SVector<f64, C>], DiracError> {
        Ok(&self.running()?.now.u)
    }

    /// The momenta `m u̇` of the nodes (`m = w_x w_y ρ`, zero on a fixed edge).
    pub fn momenta(&self) -> Result<&[SVector<f64, C>], DiracError> {
        Ok(&self.running()?.now.p)
    }

    /// The force `−∂Φ/∂u` on the nodes (zero on a fixed edge): what the cells' potential pulls
    /// each node with.
    pub fn force(&self) -> Result<&[SVector<f64, C>], DiracError> {
        Ok(&self.running()?.now.force)
    }

    /// The rates `u̇ = p / m` at the nodes (zero on a fixed edge).
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

    /// The energy of the semi-discrete field, `Σ |p|²_{m⁻¹}/2 + Φ(u)`. The step does not keep it
    /// exactly; it keeps a nearby modified energy, so its error stays bounded (of the order of
    /// `Δt^order`) over long runs.
    pub fn energy(&self) -> Result<f64, DiracError> {
        let run = self.running()?;
        let u = &run.now.u;
        let kinetic = leapfrog::kinetic(&run.now.p, &self.mass);
        if self.degree() > 1 {
            return Ok(kinetic + self.cells_potential(u));
        }
        let nx = self.nodes()[0];
        let [dx, dy] = self.spacing;
        let corners = |k: usize| {
            let (i, j) = (k % nx, k / nx);
            let mut sum = 0.0;
            for (sx, across) in [1.0, -1.0].map(|s| (s, self.neighbour(0, i, s > 0.0))) {
                for (sy, above) in [1.0, -1.0].map(|s| (s, self.neighbour(1, j, s > 0.0))) {
                    if let (Some(across), Some(above)) = (across, above) {
                        let ux = (u[j * nx + across] - u[k]) * (sx / dx);
                        let uy = (u[above * nx + i] - u[k]) * (sy / dy);
                        sum += self.density.potential(self.position(k), &u[k], &ux, &uy);
                    }
                }
            }
            sum
        };
        let potential: f64 = (0..u.len()).map(corners).sum();
        Ok(kinetic + 0.25 * dx * dy * potential)
    }

    /// The values of cell `(e_x, e_y)` at its points, `[n][m]` for point `(c_m, c_n)`, and the
    /// slopes there, `u_x = Σ_l D_ml u_ln / Δx` and `u_y = Σ_l D_nl u_ml / Δy`, into `cell`.
    fn cell_values(&self, [ex, ey]: [usize; 2], u: &[SVector<f64, C>], cell: &mut CellScratch<C>) {
        let (r, [nx, ny]) = (self.degree(), self.nodes);
        let d = |q: usize, m: usize| self.elements.d(q, m);
        for n in 0..=r {
            // The last cell's last points are the first nodes along a periodic axis.
            let row = ((ey * r + n) % ny) * nx;
            for m in 0..=r {
                cell.u[n][m] = u[row + (ex * r + m) % nx];
            }
        }
        let [dx, dy] = self.spacing;
        for n in 0..=r {
            for m in 0..=r {
                let (mut ux, mut uy) = (SVector::zeros(), SVector::zeros());
                for l in 0..=r {
                    ux += cell.u[n][l] * d(m, l);
                    uy += cell.u[l][m] * d(n, l);
                }
                cell.ux[n][m] = ux / dx;
                cell.uy[n][m] = uy / dy;
            }
        }
    }

    /// The position of point `(c_m, c_n)` of cell `(e_x, e_y)`.
    fn cell_point(&self, [ex, ey]: [usize; 2], m: usize, n: usize) -> [f64; 2] {
        let r = self.degree();
        [
            self.coordinate(0, ex * r + m),
            self.coordinate(1, ey * r + n),
        ]
    }

    /// `Φ(u) = ΔxΔy Σ_cells Σ_{m,n} w_m w_n U(x_mn, u_mn, u_x, u_y)` for cells of degree 2 and
    /// above.
    fn cells_potential(&self, u: &[SVector<f64, C>]) -> f64 {
        let (r, w) = (self.degree(), &self.elements.weights);
        let [dx, dy] = self.spacing;
        let (mut sum, mut cell) = (0.0, CellScratch::new());
        for ey in 0..self.cells[1] {
            for ex in 0..self.cells[0] {
                self.cell_values([ex, ey], u, &mut cell);
                for n in 0..=r {
                    for m in 0..=r {
                        let at = self.cell_point([ex, ey], m, n);
                        let (v, ux, uy) = (&cell.u[n][m], &cell.ux[n][m], &cell.uy[n][m]);
                        sum += w[m] * w[n] * self.density.potential(at, v, ux, uy);
                    }
                }
            }
        }
        sum * dx * dy
    }

    /// Subtracts from `f` cell `(e_x, e_y)`'s share of `∂Φ/∂u` at each of its points `(a, b)`:
    /// `ΔxΔy [w_a w_b ∂U/∂u + Σ_m w_m w_b ∂U/∂u_x(m, b) D_ma/Δx + Σ_n w_a w_n ∂U/∂u_y(a, n) D_nb/Δy]`,
    /// where `f` holds the rows of nodes from `first_row` on (the shares to other rows are not
    /// taken).
    fn cell_force(
        &self,
        at: [usize; 2],
        u: &[SVector<f64, C>],
        (f, first_row): (&mut [SVector<f64, C>], usize),
        cell: &mut CellScratch<C>,
    ) {
        let (r, w) = (self.degree(), &self.elements.weights);
        let ([dx, dy], [nx, ny]) = (self.spacing, self.nodes);
        self.cell_values(at, u, cell);
        // At each point: the weighted derivatives in the field and in the two slopes.
        let CellScratch {
            u: values,
            ux: slope_x,
            uy: slope_y,
            own,
            flux_x,
            flux_y,
        } = cell;
        for n in 0..=r {
            for m in 0..=r {
                let point = self.cell_point(at, m, n);
                let (v, ux, uy) = (&values[n][m], &slope_x[n][m], &slope_y[n][m]);
                let (by_u, by_ux, by_uy) = self.potential_gradient(point, v, ux, uy);
                let weight = w[m] * w[n];
                own[n][m] = by_u * (weight * dx * dy);
                flux_x[n][m] = by_ux * (weight * dy);
                flux_y[n][m] = by_uy * (weight * dx);
            }
        }
        let [ex, ey] = at;
        for b in 0..=r {
            let Some(row) = ((ey * r + b) % ny)
                .checked_sub(first_row)
                .map(|row| row * nx)
                .filter(|&start| start < f.len())
            else {
                continue;
            };
            for a in 0..=r {
                let mut share = own[b][a];
                for l in 0..=r {
                    share +=
                        flux_x[b][l] * self.elements.d(l, a) + flux_y[l][a] * self.elements.d(l, b);
                }
                f[row + (ex * r + a) % nx] -= share;
            }
        }
    }

    /// The rows of cells in a band of the passes split across threads (the last band may hold
    /// fewer), and the number of bands, for cells of degree 2 and above.
    fn cell_bands(&self) -> (usize, usize) {
        let ([nx, ny], rows_of_cells) = (self.nodes, self.cells[1]);
        // As many bands as `BAND`s of nodes, of 4 rows of cells at least.
        let bands = (nx * ny / BAND).clamp(1, rows_of_cells.div_ceil(4));
        let rows = rows_of_cells.div_ceil(bands);
        (rows, rows_of_cells.div_ceil(rows))
    }

    /// `f = −∂Φ/∂u` by cells of degree 2 and above, then `p += kick · f` at every node that
    /// moves: the whole field, or, split across threads, a band of rows of cells to a thread,
    /// each writing the rows of nodes from its first cells' lowest on.
    fn cells_force_and_kick(
        &self,
        u: &[SVector<f64, C>],
        f: &mut [SVector<f64, C>],
        p: &mut [SVector<f64, C>],
        kick: f64,
    ) {
        if self.in_parallel() {
            let (rows, _) = self.cell_bands();
            let nodes = rows * self.degree() * self.nodes[0];
            let bands = f.par_chunks_mut(nodes).zip(p.par_chunks_mut(nodes));
            bands.enumerate().for_each(|(b, (f, p))| {
                self.cells_band(b * rows, u, (f, p), kick);
            });
        } else {
            self.cells_band(0, u, (f, p), kick);
        }
    }

    /// [`cells_force_and_kick`](Self::cells_force_and_kick) on the rows of nodes of `f` and `p`,
    /// from the lowest of row of cells `first` on. Each node gathers its cells' shares in the
    /// order of a pass over all the cells, so the split steps equal the whole's bit for bit: the
    /// row of cells below the band first, the band's own, then, where the band holds the first
    /// row of a periodic field, the last row of cells, whose upper edge that row is.
    fn cells_band(
        &self,
        first: usize,
        u: &[SVector<f64, C>],
        (f, p): (&mut [SVector<f64, C>], &mut [SVector<f64, C>]),
        kick: f64,
    ) {
        let ([nx, _], [cells_x, cells_y], r) = (self.nodes, self.cells, self.degree());
        let first_row = first * r;
        f.fill(SVector::zeros());
        // Each cell overwrites the points it reads: set once a pass.
        let mut cell = CellScratch::new();
        // The rows of cells whose points reach the band's rows of nodes.
        let last = (first + f.len().div_ceil(r * nx)).min(cells_y);
        let below = first.checked_sub(1);
        let wrap = (first == 0 && self.boundary[1] == Boundary::Periodic && last < cells_y)
            .then_some(cells_y - 1);
        for ey in below.into_iter().chain(first..last).chain(wrap) {
            for ex in 0..cells_x {
                self.cell_force([ex, ey], u, (f, first_row), &mut cell);
            }
        }
        let mass = &self.mass[first_row * nx..first_row * nx + f.len()];
        for ((f, p), mass) in f.iter_mut().zip(p.iter_mut()).zip(mass) {
            if is_zero(mass) {
                *f = SVector::zeros();
            } else {
                *p += *f * kick;
            }
        }
    }
}

/// A cell's values at its points and the slopes there, `[n][m]` for point `(c_m, c_n)`, and the
/// derivatives of its potential there: written by each cell over the last's, kept over a pass.
struct CellScratch<const C: usize> {
    u: PointValues<C>,
    ux: PointValues<C>,
    uy: PointValues<C>,
    /// `ΔxΔy w_m w_n ∂U/∂u` at each point.
    own: PointValues<C>,
    /// `Δy w_m w_n ∂U/∂u_x` at each point.
    flux_x: PointValues<C>,
    /// `Δx w_m w_n ∂U/∂u_y` at each point.
    flux_y: PointValues<C>,
}

/// A value at each point `(c_m, c_n)` of a cell, `[n][m]`, for any degree up to the last.
type PointValues<const C: usize> = [[SVector<f64, C>; MOST_DEGREE + 1]; MOST_DEGREE + 1];

impl<const C: usize> CellScratch<C> {
    fn new() -> Self {
        let zeros = [[SVector::zeros(); MOST_DEGREE + 1]; MOST_DEGREE + 1];
        Self {
            u: zeros,
            ux: zeros,
            uy: zeros,
            own: zeros,
            flux_x: zeros,
            flux_y: zeros,
        }
    }
}

/// The numbers of nodes `[n_x, n_y]` of `cells` of degree `r` held by `boundary`: `N r` along a
/// periodic axis, else `N r + 1`; `Dimension` where they cannot be counted.
fn node_counts(
    cells: [usize; 2],
    boundary: [Boundary; 2],
    r: usize,
) -> Result<[usize; 2], DiracError> {
    let nodes = [0, 1].map(|axis| super::node_count(cells[axis], boundary[axis], r).ok());
    match nodes {
        [Some(nx), Some(ny)] if nx.checked_mul(ny).is_some() => Ok([nx, ny]),
        _ => Err(DiracError::Dimension(format!(
            "{cells:?} cells of degree {r} make more nodes than can be counted"
        ))),
    }
}

impl<D: PlaneDensity<C>, const C: usize> Grid<C> for PlaneField<D, C> {
    type Scratch = Vec<Window<C>>;

    fn mass(&self) -> &[SVector<f64, C>] {
        &self.mass
    }

    fn in_parallel(&self) -> bool {
        let bands = match self.degree() {
            1 => self.bands().1,
            _ => self.cell_bands().1,
        };
        self.parallel && bands >= PARALLEL_BANDS
    }

    /// A band of rows at a time (the whole field when not split across threads), row by row:
    /// the [`Sends`] of the row above, then the gathered forces and kicks of the row.
    fn force_and_kick(
        &self,
        u: &[SVector<f64, C>],
        f: &mut [SVector<f64, C>],
        p: &mut [SVector<f64, C>],
        windows: &mut Self::Scratch,
        kick: f64,
    ) {
        if self.degree() > 1 {
            self.cells_force_and_kick(u, f, p, kick);
        } else if self.in_parallel() {
            let (rows, bands) = self.bands();
            if windows.len() < bands {
                // Split across threads during a run: a window for every band, once.
                windows.resize(bands, windows[0].clone());
            }
            let nodes = rows * self.nodes[0];
            let bands = f.par_chunks_mut(nodes).zip(p.par_chunks_mut(nodes));
            let bands = bands.zip(windows.par_iter_mut()).enumerate();
            bands.for_each(|(b, (band, window))| self.band(b * rows, u, band, window, kick));
        } else {
            self.band(0, u, (f, p), &mut windows[0], kick);
        }
    }
}
