//! Hidden constraints across the components of a modular interconnection, and how its step
//! holds them.
//!
//! A coordinate without kinetic energy `d` has an Euler–Lagrange row without acceleration,
//! `R_d(q, v, t) + Σ ν a_d = 0`, with the impulses `ν` of its component's own constraints and
//! of the junctions through it (see [`hidden_constraint`](crate::discrete::hidden_constraint)). Over the
//! degenerate coordinates `D` of all components, the combinations `w` of their rows that no
//! impulse reaches (`B w = 0`, with the rows of `B` the components' forms and the junctions
//! restricted to `D`) are equations without multipliers: where they contain no velocity, constraints on `q`,
//! `c(q) = Wᵀ R_D(q) = 0`. Two capacitors in parallel, each a component and joined by KCL, give
//! `q_c1/c1 − q_c3/c3 = 0`: no junction's impulse enters it, since their common current is
//! free.
//!
//! The step imposes the rows at its midpoint, so, as in one model, the end points drift along
//! `W` (a parasitic mode of root −1) unless held. After each step's solve, the end point is
//! moved along the free directions `W` (displacements of the degenerate coordinates that no
//! constraint and no junction sees) until `c(q_{k+1}) = 0`, by Newton's method with the
//! minimal-norm update ([`hold`], the routine a model holds its own hidden constraints with);
//! the junctions' rows are unchanged by the move, and the Lagrangian must stay finite at the
//! moved end. The velocities satisfy `dc(q) v = 0` besides the junctions, with a multiplier
//! each.
//!
//! `W` is found at the start by a sparse elimination on the forms (`O(K)` along a chain), then
//! orthonormalised (dense in the constraints' coordinates) and kept: the step holds hidden
//! constraints where the forms of the components with degenerate coordinates are constant and
//! the rows combined contain no velocity (circuits). Otherwise, where they depend on time, and
//! above [`MOST`] constraints (the projection is dense in their number), the start is refused.

use std::collections::{BTreeMap, HashMap};

use nalgebra::{DMatrix, DVector};

use super::{Component, Coupling, in_component};
use crate::base::error::DiracError;
use crate::base::float::{exceeds, largest};
use crate::discrete::hidden_constraint::{Projection, hold};

/// The most hidden constraints across components the modular step holds: its projection
/// solves a dense system in their number.
pub(super) const MOST: usize = 256;

/// Hidden constraints across components, found at a start.
#[derive(Debug, Clone)]
pub(super) struct Hidden {
    /// The degenerate coordinates they combine, `(component, coordinate)`.
    dead: Vec<(usize, usize)>,
    /// The components among them: each with its coordinates in `dead` and where they sit there.
    owners: Vec<Owner>,
    /// `W` (rows over `dead`, orthonormal columns): column `k` combines the rows into
    /// constraint `k`, and moves the coordinates along free direction `k`.
    basis: DMatrix<f64>,
    /// `instance.coordinate` of `dead`, for messages.
    names: String,
}

/// A component with coordinates among a [`Hidden`]'s.
#[derive(Debug, Clone)]
struct Owner {
    component: usize,
    /// Its coordinates in the constraints.
    coordinates: Vec<usize>,
    /// Where they sit among the constraints' coordinates.
    at: Vec<usize>,
}

/// Where the rows are read: a state given for every coordinate, or the components' proposed
/// states (a step's end before it is accepted).
#[derive(Clone, Copy)]
enum At<'s> {
    Given(&'s [f64], &'s [f64]),
    Proposed,
}

/// `c`, its differential and what goes with it at one point.
struct Evaluation {
    /// `c = Wᵀ R_D`.
    value: DVector<f64>,
    /// The size of the terms summed into `R_D`.
    scale: f64,
    /// Per owner, `∂R_D/∂q` over its coordinates (with `jacobians`).
    by_q: Vec<DMatrix<f64>>,
}

impl Hidden {
    /// The hidden constraints across `components` joined by `junctions` at `(q, v)` (all
    /// coordinates), or `None`. Refuses what the step does not hold (see the
    /// [module](self) documentation) and an initial state that violates them or their
    /// velocity form (to `tolerance` of their terms), naming the coordinates.
    pub(super) fn find(
        components: &[Component],
        junctions: &[Coupling],
        (q, v): (&[f64], &[f64]),
        tolerance: f64,
    ) -> Result<Option<Self>, DiracError> {
        let mut dead: Vec<(usize, usize)> = Vec::new();
        let mut forms: Vec<Vec<(usize, f64)>> = Vec::new();
        // The first component with degenerate coordinates whose forms are not constant.
        let mut varying: Option<usize> = None;
        for (c, component) in components.iter().enumerate() {
            let found = component
                .part
                .degenerate(&q[positions_of(component)], &v[range_of(component)]);
            let name =
                |i: usize| format!("{}.{}", component.name, component.part.coordinate_name(i));
            if let Some(i) = found.turning {
                return Err(DiracError::Unsupported(format!(
                    "the modular step on {}, whose Lagrangian is linear in its velocity with a \
                     momentum ∂L/∂v that depends on the position (first-order rows are \
                     collocated only in a model stepped on its own)",
                    name(i)
                )));
            }
            if let Some(&(i, momentum)) = found.momenta.iter().find(|(_, p)| *p != 0.0) {
                return Err(DiracError::Unsupported(format!(
                    "the modular step on {}, whose Lagrangian is linear in its velocity with \
                     the momentum {momentum} (first-order rows are collocated only in a model \
                     stepped on its own)",
                    name(i)
                )));
            }
            if !found.coordinates.is_empty()
                && !component.part.constant_forms(&q[positions_of(component)])
            {
                varying.get_or_insert(c);
            }
            let base = dead.len();
            dead.extend(found.coordinates.iter().map(|&i| (c, i)));
            for row in found.forms.row_iter() {
                let entries = found.coordinates.iter().enumerate();
                forms.push(entries.map(|(k, &i)| (base + k, row[i])).collect());
            }
        }
        if dead.is_empty() {
            return Ok(None);
        }
        let column: HashMap<(usize, usize), usize> =
            dead.iter().enumerate().map(|(k, &d)| (d, k)).collect();
        for junction in junctions {
            let entries = junction
                .terms
                .iter()
                .filter_map(|&(c, i, a)| Some((*column.get(&(c, i))?, a)));
            forms.push(entries.collect());
        }
        let name = |&(c, i): &(usize, usize)| {
            let component: &Component = &components[c];
            format!("{}.{}", component.name, component.part.coordinate_name(i))
        };
        let basis = match null_space(forms, dead.len(), MOST) {
            Ok(basis) if basis.is_empty() => return Ok(None),
            Ok(basis) => basis,
            Err(count) => {
                return Err(DiracError::Unsupported(format!(
                    "the modular step with {count} hidden constraints across the components \
                     (combinations of the rows of coordinates without kinetic energy that no \
                     impulse enters): it holds at most {MOST}; step the interconnection \
                     monolithically"
                )));
            }
        };
        // The coordinates the constraints combine, in the order of `dead` (components first).
        let mut support: Vec<usize> = basis.iter().flatten().map(|e| e.0).collect();
        support.sort_unstable();
        support.dedup();
        let place: HashMap<usize, usize> =
            support.iter().enumerate().map(|(k, &d)| (d, k)).collect();
        let mut w = DMatrix::zeros(support.len(), basis.len());
        for (k, vector) in basis.iter().enumerate() {
            for &(d, x) in vector {
                w[(place[&d], k)] = x;
            }
        }
        let dead: Vec<(usize, usize)> = support.iter().map(|&d| dead[d]).collect();
        let mut owners: Vec<Owner> = Vec::new();
        for (k, &(c, i)) in dead.iter().enumerate() {
            match owners.last_mut() {
                Some(owner) if owner.component == c => {
                    owner.coordinates.push(i);
                    owner.at.push(k);
                }
                _ => owners.push(Owner {
                    component: c,
                    coordinates: vec![i],
                    at: vec![k],
                }),
            }
        }
        let names: Vec<String> = dead.iter().map(name).collect();
        let hidden = Self {
            basis: w.qr().q(),
            dead,
            owners,
            names: names.join(", "),
        };
        if let Some(c) = varying {
            // Forms that vary would change which combinations no impulse reaches.
            hidden.unsupported(format!(
                "where {}'s constraint forms are not constant (one-forms that depend on the \
                 position, or holonomic constraints)",
                components[c].name
            ))?;
        }
        hidden.check(components, (q, v), tolerance)?;
        Ok(Some(hidden))
    }

    /// The refusals of [`find`](Self::find) once the constraints are known.
    fn check(
        &self,
        components: &[Component],
        (q, v): (&[f64], &[f64]),
        tolerance: f64,
    ) -> Result<(), DiracError> {
        let unsupported = |why: String| self.unsupported(why);
        for owner in &self.owners {
            let component = &components[owner.component];
            let range = range_of(component);
            // A second velocity, every coordinate moved: rows linear in v show it there.
            let other: Vec<f64> = v[range.clone()].iter().map(|x| x + 1.0 + x.abs()).collect();
            for velocity in [&v[range.clone()], &other[..]] {
                let rows = component.part.degenerate_rows(
                    &q[positions_of(component)],
                    velocity,
                    0.0,
                    &owner.coordinates,
                    true,
                );
                if rows.by_v.iter().any(|x| *x != 0.0) {
                    return unsupported(format!(
                        "where the rows of {} contain velocities (first-order equations, e.g. a \
                         resistor beside a capacitor)",
                        component.name
                    ));
                }
            }
        }
        let start = self.evaluate(components, At::Given(q, v), 0.0, true)?;
        let values = start.value.iter().copied();
        if let Some(value) = values.clone().find(|c| !c.is_finite()) {
            return Err(DiracError::NonFinite {
                what: format!("the hidden constraint across components of {}", self.names),
                value,
            });
        }
        // c must not depend on t explicitly (a force on a degenerate coordinate that does):
        // its velocity form would miss ∂c/∂t. Probed at incommensurate times, at q and at a
        // point moved along the free directions (a force f(t) q_c vanishes at q_c = 0).
        let mut moved = q.to_vec();
        let size = 1e-2 * (1.0 + largest(q.iter().copied()));
        let shift = &self.basis * DVector::from_element(self.count(), size);
        for (k, &(c, i)) in self.dead.iter().enumerate() {
            moved[components[c].position + i] += shift[k];
        }
        for point in [q, &moved[..]] {
            let Ok(here) = self.evaluate(components, At::Given(point, v), 0.0, false) else {
                continue;
            };
            if !here.value.iter().all(|c| c.is_finite()) {
                continue;
            }
            for t in [-1.0, 0.371, 1.13, 2.9, 17.3] {
                let there = self.evaluate(components, At::Given(point, v), t, false)?;
                let change = largest((&there.value - &here.value).iter().copied());
                if exceeds(change, 1e-12 * here.scale) {
                    return unsupported("that depend on time explicitly".into());
                }
            }
        }
        let residual = largest(values);
        if exceeds(residual, tolerance * start.scale) {
            return Err(DiracError::InconsistentInitialState(format!(
                "the initial positions violate the hidden constraint across the components of \
                 {} (their rows combine to {residual:.3e}, terms of size {:.3e}; e.g. parallel \
                 capacitors at different voltages)",
                self.names, start.scale
            )));
        }
        let (rate, size) = self.rates(components, &start.by_q, v);
        if exceeds(rate, tolerance * size) {
            return Err(DiracError::InconsistentInitialState(format!(
                "the initial velocities violate the velocity form of the hidden constraint \
                 across the components of {}: dc·v = {rate:.3e}",
                self.names
            )));
        }
        Ok(())
    }

    /// `Err(Unsupported)` saying why the step does not hold these constraints.
    fn unsupported(&self, why: String) -> Result<(), DiracError> {
        Err(DiracError::Unsupported(format!(
            "the modular step with hidden constraints across the components (the rows of {} \
             combine into equations that no junction's impulse enters) {why}; step the \
             interconnection monolithically",
            self.names
        )))
    }

    /// The number of constraints.
    pub(super) fn count(&self) -> usize {
        self.basis.ncols()
    }

    /// `c`, and with `jacobians` each owner's `∂R_D/∂q`, at `at` and time `t`.
    fn evaluate(
        &self,
        components: &[Component],
        at: At<'_>,
        t: f64,
        jacobians: bool,
    ) -> Result<Evaluation, DiracError> {
        let mut rows = DVector::zeros(self.dead.len());
        let mut scale: f64 = 0.0;
        let mut by_q = Vec::with_capacity(if jacobians { self.owners.len() } else { 0 });
        for owner in &self.owners {
            let component = &components[owner.component];
            let (q, v) = match at {
                At::Given(q, v) => (&q[positions_of(component)], &v[range_of(component)]),
                At::Proposed => component.part.proposed().ok_or_else(|| {
                    in_component(
                        &component.name,
                        DiracError::Unsupported("no proposed state to project".into()),
                    )
                })?,
            };
            let found = component
                .part
                .degenerate_rows(q, v, t, &owner.coordinates, jacobians);
            for (r, &k) in owner.at.iter().enumerate() {
                rows[k] = found.value[r];
            }
            scale = scale.max(found.scale);
            if jacobians {
                by_q.push(found.by_q);
            }
        }
        Ok(Evaluation {
            value: self.basis.tr_mul(&rows),
            scale,
            by_q,
        })
    }

    /// `max_k |dc_k · v|` and the size of its terms, with each owner's `∂R_D/∂q`.
    fn rates(&self, components: &[Component], by_q: &[DMatrix<f64>], v: &[f64]) -> (f64, f64) {
        let (mut rate, mut size): (f64, f64) = (0.0, 0.0);
        for row in self.differential(components, by_q) {
            let terms = row.iter().map(|&(c, i, a)| a * v[components[c].first + i]);
            let (sum, terms) = terms.fold((0.0, 0.0), |(s, z), x: f64| (s + x, z + x.abs()));
            rate = largest([rate, sum]);
            size = size.max(terms);
        }
        (rate, size)
    }

    /// The rows of `dc = Wᵀ ∂R_D/∂q` as `(component, coordinate, coefficient)` terms.
    fn differential(
        &self,
        components: &[Component],
        by_q: &[DMatrix<f64>],
    ) -> Vec<Vec<(usize, usize, f64)>> {
        (0..self.count())
            .map(|k| {
                let mut terms = Vec::new();
                for (owner, by_q) in self.owners.iter().zip(by_q) {
                    let n = components[owner.component].part.coordinates();
                    for e in 0..n {
                        let a: f64 = owner
                            .at
                            .iter()
                            .enumerate()
                            .map(|(r, &d)| self.basis[(d, k)] * by_q[(r, e)])
                            .sum();
                        if a != 0.0 {
                            terms.push((owner.component, e, a));
                        }
                    }
                }
                terms
            })
            .collect()
    }

    /// Moves the components' proposed end points along the free directions until the
    /// constraints hold at time `t` (see [`hold`]); `Err(Projection)` says why not (the
    /// proposed states may have moved: discard them).
    pub(super) fn project(
        &self,
        components: &mut [Component],
        t: f64,
        step: u64,
    ) -> Result<(), DiracError> {
        let mut across = Across {
            hidden: self,
            components,
            t,
        };
        hold(&mut across).map_err(|why| DiracError::Projection {
            step,
            why: format!("{why} (across the components: {})", self.names),
        })?;
        for owner in &self.owners {
            let component = &components[owner.component];
            component
                .part
                .check_proposed(step)
                .map_err(|e| in_component(&component.name, e))?;
        }
        Ok(())
    }

    /// The velocity form `dc(q) v = 0` at the components' current states, one junction-like row
    /// each (its multiplier enters the Legendre rows as a junction's), named after the
    /// coordinates; ranked after `ranked` junctions. Each row spans every component of the
    /// constraints (the basis is orthonormalised), which widens the velocity solve's band.
    pub(super) fn velocity_rows(
        &self,
        components: &[Component],
        ranked: usize,
    ) -> Result<Vec<Coupling>, DiracError> {
        let mut q = vec![0.0; components.iter().map(|c| c.part.positions()).sum()];
        let mut v = vec![0.0; components.iter().map(|c| c.part.coordinates()).sum()];
        for owner in &self.owners {
            let component = &components[owner.component];
            q[positions_of(component)].copy_from_slice(&component.part.q());
            v[range_of(component)].copy_from_slice(&component.part.velocity_hint());
        }
        let at = self.evaluate(components, At::Given(&q, &v), 0.0, true)?;
        let rows = self.differential(components, &at.by_q);
        Ok(rows
            .into_iter()
            .enumerate()
            .filter(|(_, terms)| !terms.is_empty())
            .map(|(k, terms)| Coupling {
                name: format!("the hidden constraint {k} across {}", self.names),
                terms,
                rank: ranked + k,
                joint: None,
            })
            .collect())
    }
}

/// The constraints at the components' proposed states, held by [`hold`].
struct Across<'a> {
    hidden: &'a Hidden,
    components: &'a mut [Component],
    t: f64,
}

impl Across<'_> {
    fn at(&self, jacobians: bool) -> Result<Evaluation, String> {
        self.hidden
            .evaluate(self.components, At::Proposed, self.t, jacobians)
            .map_err(|e| e.to_string())
    }
}

impl Projection for Across<'_> {
    fn residual(&mut self) -> Result<Option<(f64, f64)>, String> {
        let e = self.at(false)?;
        Ok(Some((largest(e.value.iter().copied()), e.scale)))
    }

    fn linearise(&mut self) -> Result<(DVector<f64>, DMatrix<f64>, f64), String> {
        let e = self.at(true)?;
        // Wᵀ (∂R_D/∂q_D) W, ∂R_D/∂q_D block-diagonal by owner.
        let w = &self.hidden.basis;
        let mut jw = DMatrix::zeros(w.nrows(), w.ncols());
        for (owner, by_q) in self.hidden.owners.iter().zip(&e.by_q) {
            for (r, &d) in owner.at.iter().enumerate() {
                for (&f, &i) in owner.at.iter().zip(&owner.coordinates) {
                    let entry = by_q[(r, i)];
                    if entry != 0.0 {
                        for k in 0..w.ncols() {
                            jw[(d, k)] += entry * w[(f, k)];
                        }
                    }
                }
            }
        }
        Ok((e.value, w.tr_mul(&jw), e.scale))
    }

    fn shift(&mut self, alpha: &DVector<f64>) {
        let delta = &self.hidden.basis * alpha;
        for owner in &self.hidden.owners {
            let part = &mut self.components[owner.component].part;
            for (&i, &d) in owner.coordinates.iter().zip(&owner.at) {
                part.shift_proposed(i, delta[d]);
            }
        }
    }
}

/// The coordinates of `component` among all.
fn range_of(component: &Component) -> std::ops::Range<usize> {
    component.first..component.first + component.part.coordinates()
}

/// The position numbers of `component` among all (its coordinates, on `Rⁿ`).
fn positions_of(component: &Component) -> std::ops::Range<usize> {
    component.position..component.position + component.part.positions()
}

/// A basis of the null space of the matrix of sparse `rows` (`(column, value)` entries) over
/// `columns` columns: one vector per column without a pivot, as `(column, value)` entries, or
/// `Err(count)` where there are more than `most`. Gaussian elimination with partial pivoting on
/// the sparse rows (an entry at or below `1e-10` of its row's largest makes no pivot: its column
/// is free), then back-substitution from each free column (1 there, 0 at the others), with
/// every entry of the pivot rows, those of earlier free columns too. Rows of a
/// chain's junctions touch neighbours only, so the elimination costs `O(columns)` there.
fn null_space(
    rows: Vec<Vec<(usize, f64)>>,
    columns: usize,
    most: usize,
) -> Result<Vec<Vec<(usize, f64)>>, usize> {
    // Exact zeros are no entries; a row without entries constrains nothing.
    let rows: Vec<Vec<(usize, f64)>> = rows
        .into_iter()
        .map(|row| row.into_iter().filter(|e| e.1 != 0.0).collect::<Vec<_>>())
        .filter(|row| !row.is_empty())
        .collect();
    let scales: Vec<f64> = rows
        .iter()
        .map(|row| row.iter().fold(0.0, |m: f64, e| m.max(e.1.abs())))
        .collect();
    let mut rows: Vec<BTreeMap<usize, f64>> = rows
        .into_iter()
        .map(|row| row.into_iter().collect())
        .collect();
    let mut holding: Vec<Vec<usize>> = vec![Vec::new(); columns];
    for (r, row) in rows.iter().enumerate() {
        for &k in row.keys() {
            holding[k].push(r);
        }
    }
    let mut used = vec![false; rows.len()];
    // (column, row) of each pivot, and the columns without one.
    let mut pivots: Vec<(usize, usize)> = Vec::with_capacity(columns);
    let mut free: Vec<usize> = Vec::new();
    for k in 0..columns {
        // A NaN (a form that is not finite) never makes a pivot.
        let relative = |r: usize| {
            let found = rows[r].get(&k).map_or(0.0, |v| v.abs() / scales[r]);
            if found.is_nan() { 0.0 } else { found }
        };
        let best = holding[k]
            .iter()
            .copied()
            .filter(|&r| !used[r])
            .max_by(|&a, &b| relative(a).total_cmp(&relative(b)));
        let Some(p) = best.filter(|&p| relative(p) > 1e-10) else {
            free.push(k);
            continue;
        };
        used[p] = true;
        pivots.push((k, p));
        let pivot_row = rows[p].clone();
        let pivot = pivot_row[&k];
        for r in std::mem::take(&mut holding[k]) {
            if used[r] {
                continue;
            }
            let Some(value) = rows[r].remove(&k) else {
                continue;
            };
            let factor = value / pivot;
            for (&l, &v) in pivot_row.range(k + 1..) {
                let entry = rows[r].entry(l).or_insert_with(|| {
                    holding[l].push(r);
                    0.0
                });
                *entry -= factor * v;
            }
        }
    }
    if free.len() > most {
        return Err(free.len());
    }
    // A pivot row holds its column, later columns and entries too small to pivot in earlier
    // free columns.
    Ok(free
        .iter()
        .map(|&f| {
            let mut x = vec![0.0; columns];
            x[f] = 1.0;
            for &(j, p) in pivots.iter().rev() {
                let others = rows[p].iter().filter(|&(&l, _)| l != j);
                let sum: f64 = others.map(|(&l, &v)| v * x[l]).sum();
                x[j] = -sum / rows[p][&j];
            }
            (0..columns)
                .filter(|&j| x[j] != 0.0)
                .map(|j| (j, x[j]))
                .collect()
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The columns each basis vector moves.
    fn supports(rows: Vec<Vec<(usize, f64)>>, columns: usize) -> Vec<Vec<usize>> {
        let basis = null_space(rows, columns, usize::MAX).unwrap();
        basis
            .into_iter()
            .map(|v| v.into_iter().map(|e| e.0).collect())
            .collect()
    }

    #[test]
    fn null_spaces_of_sparse_rows() {
        // x₀ − x₁ = 0, x₁ − x₂ = 0 over three columns: (1, 1, 1).
        let chain = vec![vec![(0, 1.0), (1, -1.0)], vec![(1, 1.0), (2, -1.0)]];
        assert_eq!(supports(chain.clone(), 3), vec![vec![0, 1, 2]]);
        let mut pinned = chain;
        pinned.push(vec![(2, 1.0)]);
        assert!(supports(pinned, 3).is_empty());
        assert_eq!(supports(vec![vec![(0, 2.0)]], 2), vec![vec![1]]);
        let swap = vec![vec![(1, 1.0)], vec![(0, 1.0)]];
        assert!(supports(swap, 2).is_empty());
        let zeros = vec![vec![(0, 0.0)], vec![(0, 1.0), (1, 1.0)], vec![(1, 1.0)]];
        assert!(supports(zeros, 2).is_empty());
        assert_eq!(supports(vec![vec![(0, f64::NAN)]], 1), vec![vec![0]]);
        let twice = vec![vec![(0, 1.0), (1, 1.0)], vec![(0, 2.0), (1, 2.0)]];
        assert_eq!(supports(twice, 2), vec![vec![0, 1]]);
        // KCL at a node of three branches over four columns, column 3 untouched: a
        // two-dimensional null space plus the free column.
        let node = vec![vec![(0, 1.0), (1, -1.0), (2, -1.0)]];
        let basis = null_space(node.clone(), 4, usize::MAX).unwrap();
        assert_eq!(basis.len(), 3);
        for vector in &basis {
            let dense: Vec<f64> = (0..4)
                .map(|j| vector.iter().find(|e| e.0 == j).map_or(0.0, |e| e.1))
                .collect();
            assert!((dense[0] - dense[1] - dense[2]).abs() < 1e-15, "{dense:?}");
        }
        assert_eq!(null_space(node, 4, 2), Err(3));
    }

    #[test]
    fn a_pivot_row_that_holds_an_earlier_free_column_is_solved_with_it() {
        // An entry too small to pivot (1e-12 of its row) leaves column 0 without a pivot but
        // stays in the row that pivots column 1: the back-substitution takes it.
        let rows = vec![vec![(0, 1e-12), (1, 1.0)], vec![(1, 1.0), (2, -1.0)]];
        let basis = null_space(rows.clone(), 3, usize::MAX).unwrap();
        for vector in &basis {
            let x = |j: usize| vector.iter().find(|e| e.0 == j).map_or(0.0, |e| e.1);
            for row in &rows {
                let r: f64 = row.iter().map(|&(j, a)| a * x(j)).sum();
                assert!(r.abs() < 1e-9, "{vector:?}");
            }
        }
    }
}
