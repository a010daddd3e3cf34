//! The modular step of an interconnection: each component's step equations assembled and
//! factorised on its own, coupled only through the junctions' multipliers.
//!
//! An [`Interconnection`](crate::Interconnection) is one model on `Q₁ × Q₂`, stepped by one
//! Newton solve over all its coordinates. [`Modular`] steps the same equations by parts. With
//! the junctions `Σ_c a_j^c · q̇^c = 0` constant one-forms and their impulses `μ_j`, a step of
//! a degree-1 rule is, per component `c` (its own one-forms and holonomic constraints inside
//! `R_c`),
//!
//! ```text
//! R_c(x_c) + σ Σ_j μ_j a_j^c = 0      (the rows of p_k's equation; σ the impulse's share)
//! Σ_c a_j^c · ξ^c              = 0      (junction j, ξ^c = q_{k+1}^c − q_k^c)
//! ```
//!
//! and `p_{k+1}^c` gains `(1 − σ) Σ_j μ_j a_j^c`: exactly the monolithic equations. Newton's
//! method solves them with a [`Bordered`] Jacobian: each `∂R_c/∂x_c` is factorised on its own
//! and the junctions' Schur complement, a band matrix along a chain, couples them, so a chain
//! of `K` components costs `O(K)` per step. The components are assembled and factorised in
//! parallel (rayon) when there are many ([`Modular::with_parallel`]).
//!
//! ```
//! use dirac_runtime::modular::Modular;
//! use dirac_runtime::{DiracSystem, Junction, Quadrature, Scalar};
//! use nalgebra::SVector;
//!
//! struct Inductor;
//! impl DiracSystem<1> for Inductor {
//!     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
//!         v[0] * v[0] * 0.5
//!     }
//! }
//! struct Capacitor;
//! impl DiracSystem<1> for Capacitor {
//!     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, _v: &SVector<D, 1>) -> D {
//!         -(q[0] * q[0]) * 0.5
//!     }
//! }
//! // An LC loop (ω = 1): one current through both.
//! let mut lc = Modular::new(Quadrature::midpoint(), 0.01)?;
//! lc.add("l", Inductor)?;
//! lc.add("c", Capacitor)?;
//! lc.join(Junction::new("series").flow("l.q0", 1.0).flow("c.q0", -1.0))?;
//! lc.start_from_velocity(&[1.0, 1.0], &[0.0, 0.0])?;
//! lc.run(100)?;
//! assert!((lc.q()[1] - 1.0_f64.cos()).abs() < 1e-4);
//! # Ok::<(), dirac_runtime::DiracError>(())
//! ```

use std::collections::HashMap;

use nalgebra::{DMatrix, DVector, SVector};
use rayon::prelude::*;

use crate::bordered::Bordered;
use crate::configuration_space::Euclidean;
use crate::constraint_point::ConstraintPoint;
use crate::derivatives::degenerate;
use crate::discrete_lagrangian::DiscreteLagrangian;
use crate::error::DiracError;
use crate::euler_lagrange::EulerLagrange;
use crate::hidden_constraint::{HiddenConstraints, null_space};
use crate::interconnection::Junction;
use crate::jacobian::Jacobian;
use crate::newton::{Newton, NewtonOptions, NewtonReport, exceeds, largest};
use crate::predictor::Predictor;
use crate::quadrature::Quadrature;
use crate::step_equations::{State, StepEquations};
use crate::system::DiracSystem;

/// Components, from this many on, are assembled and factorised in parallel by default.
const PARALLEL_FROM: usize = 64;

/// The relative consistency an initial state must have (as a [`Stepper`](crate::Stepper)'s).
const START_TOLERANCE: f64 = 1e-9;

/// Components joined by junctions, stepped modularly (see the [module](self) documentation).
#[derive(Debug)]
pub struct Modular {
    quadrature: Quadrature,
    h: f64,
    options: NewtonOptions,
    parallel: Option<bool>,
    components: Vec<Component>,
    junctions: Vec<Coupling>,
    /// `instance.coordinate` → (component, coordinate).
    lookup: HashMap<String, (usize, usize)>,
    run: Option<Running>,
}

/// A named component and where it sits.
#[derive(Debug)]
struct Component {
    name: String,
    part: Box<dyn Part>,
    /// Its first coordinate among all.
    first: usize,
    /// Its first unknown among a step's.
    offset: usize,
    /// The junction terms on it: `(junction, coordinate, coefficient)`.
    couplings: Vec<(usize, usize, f64)>,
    /// The junctions' impulse on its coordinates (scratch of an evaluation).
    impulse: Vec<f64>,
    /// The size of its residual's terms at the last evaluation.
    scale: f64,
}

/// A junction resolved to its components' coordinates.
#[derive(Debug, Clone)]
struct Coupling {
    name: String,
    /// `(component, coordinate, coefficient)`.
    terms: Vec<(usize, usize, f64)>,
}

/// A run: the solver sized for its unknowns and what the steps carry.
#[derive(Debug)]
struct Running {
    newton: Newton<Bordered>,
    unknowns: DVector<f64>,
    predictor: Predictor,
    start: f64,
    steps: u64,
    /// The junctions' multipliers (impulses) of the last step.
    multipliers: Vec<f64>,
    violation: f64,
    report: Option<NewtonReport>,
}

/// The flows and work through the junctions over the last step of a [`Modular`]
/// interconnection: efforts `e_j = μ_j / h` and each component's port work
/// `W_c = Σ_j e_j ⟨a_j^c, q_{k+1}^c − q_k^c⟩`.
#[derive(Debug, Clone, PartialEq)]
pub struct PortWork {
    /// The junctions' efforts.
    pub efforts: Vec<f64>,
    /// The work done on each component through the junctions.
    pub work: Vec<f64>,
    /// The size of the terms summed into the work (`Σ |e_j a_j^c Δq^c|`): Tellegen's
    /// `Σ_c W_c = 0` holds to round-off of this.
    pub scale: f64,
}

impl PortWork {
    /// `Σ_c W_c` (Tellegen's theorem: zero).
    pub fn net_work(&self) -> f64 {
        self.work.iter().sum()
    }
}

impl Modular {
    /// An empty interconnection to be stepped by `quadrature` with step `h`. Fails on a step
    /// that is not positive and finite, and on a quadrature of degree above 1 (the junctions
    /// are held at the step's ends; a Galerkin step is solved monolithically, with
    /// [`Interconnection`](crate::Interconnection)).
    pub fn new(quadrature: Quadrature, h: f64) -> Result<Self, DiracError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(DiracError::InvalidStep { h });
        }
        if quadrature.degree() != 1 {
            return Err(DiracError::Unsupported(format!(
                "the modular step with {}: it takes quadratures of degree 1 (midpoint, \
                 trapezoid); step a Galerkin rule's interconnection monolithically",
                quadrature.name()
            )));
        }
        Ok(Self {
            quadrature,
            h,
            options: NewtonOptions::default(),
            parallel: None,
            components: Vec::new(),
            junctions: Vec::new(),
            lookup: HashMap::new(),
            run: None,
        })
    }

    /// Newton's options for the steps (validated).
    pub fn with_newton_options(mut self, options: NewtonOptions) -> Result<Self, DiracError> {
        options.validate()?;
        self.options = options;
        self.run = None;
        Ok(self)
    }

    /// Whether the components are assembled and factorised in parallel (by default, from
    /// 64 components on).
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = Some(parallel);
        self
    }

    /// Adds the component `system` (a model on `R^M`, stepped by its discrete Euler–Lagrange
    /// equations) as the instance `name`; its coordinates are `name.coordinate`. Fails on a
    /// name that is empty, contains `.`, or is taken, and where the model's own step equations
    /// refuse the quadrature. Components added after a start join the next start.
    pub fn add<S, const M: usize>(&mut self, name: &str, system: S) -> Result<(), DiracError>
    where
        S: DiracSystem<M> + Send + 'static,
    {
        let invalid = |why: String| Err(DiracError::InvalidInterconnection(why));
        if name.is_empty() || name.contains('.') {
            return invalid(format!(
                "the instance name {name:?} must be non-empty and without '.'"
            ));
        }
        if self.components.iter().any(|c| c.name == name) {
            return invalid(format!("two instances are named {name:?}: name them apart"));
        }
        let discrete = DiscreteLagrangian::new(system, self.quadrature.clone(), self.h);
        let part: Box<dyn Part> = Box::new(Model::new(EulerLagrange::new(discrete)?));
        if let Some(other) = self
            .components
            .iter()
            .find(|c| c.part.one_forms() && part.one_forms() && c.part.point() != part.point())
        {
            return invalid(format!(
                "{} holds its one-forms at {:?} and {name} at {:?}: the components need one \
                 constraint point",
                other.name,
                other.part.point(),
                part.point()
            ));
        }
        let index = self.components.len();
        let first = self.coordinates();
        for i in 0..M {
            let coordinate = format!("{name}.{}", part.coordinate_name(i));
            if self.lookup.insert(coordinate.clone(), (index, i)).is_some() {
                return invalid(format!(
                    "{name} has two coordinates named {coordinate:?}: a junction could not tell \
                     them apart"
                ));
            }
        }
        self.components.push(Component {
            name: name.to_string(),
            part,
            first,
            offset: 0,
            couplings: Vec::new(),
            impulse: vec![0.0; M],
            scale: 0.0,
        });
        self.run = None;
        Ok(())
    }

    /// Adds the junction `junction`, a constant one-form over the components' coordinates
    /// (`instance.coordinate`); an `Err(InvalidInterconnection)` names an unknown instance or
    /// coordinate, a coordinate twice, a zero or non-finite coefficient, no terms, or a name
    /// taken. Junctions that depend on each other are refused at the start.
    pub fn join(&mut self, junction: Junction) -> Result<(), DiracError> {
        if self.junctions.iter().any(|j| j.name == junction.name()) {
            return Err(DiracError::InvalidInterconnection(format!(
                "two junctions are named {:?}",
                junction.name()
            )));
        }
        let names: Vec<&str> = self.components.iter().map(|c| c.name.as_str()).collect();
        let known = |coordinate: &str| {
            let instance = coordinate.split('.').next().unwrap_or_default();
            match names.iter().position(|n| *n == instance) {
                Some(c) => format!(
                    "{instance} has {}",
                    (0..self.components[c].part.coordinates())
                        .map(|i| format!(
                            "{instance}.{}",
                            self.components[c].part.coordinate_name(i)
                        ))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                None => format!("the instances are {}", names.join(", ")),
            }
        };
        let coordinates: Vec<(usize, usize)> = self.lookup.values().copied().collect();
        let index = |coordinate: &str| {
            let &(c, i) = self.lookup.get(coordinate)?;
            Some(self.components[c].first + i)
        };
        let terms = junction
            .resolve_terms(index, known)?
            .into_iter()
            .map(|(global, a)| {
                let &(c, i) = coordinates
                    .iter()
                    .find(|&&(c, i)| self.components[c].first + i == global)
                    .expect("resolved");
                (c, i, a)
            })
            .collect();
        self.junctions.push(Coupling {
            name: junction.name().to_string(),
            terms,
        });
        self.run = None;
        Ok(())
    }

    /// The number of coordinates of all components.
    pub fn coordinates(&self) -> usize {
        self.components.iter().map(|c| c.part.coordinates()).sum()
    }

    /// `instance.coordinate` for every coordinate, in the components' order.
    pub fn coordinate_names(&self) -> Vec<String> {
        self.components
            .iter()
            .flat_map(|c| {
                (0..c.part.coordinates())
                    .map(move |i| format!("{}.{}", c.name, c.part.coordinate_name(i)))
            })
            .collect()
    }

    /// The junctions' names, in the order of their multipliers.
    pub fn junction_names(&self) -> Vec<String> {
        self.junctions.iter().map(|j| j.name.clone()).collect()
    }

    /// The step size.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// Starts a run at time 0 from the positions `q` and velocities `v` of every coordinate
    /// (in the order of [`coordinate_names`](Self::coordinate_names)). Each component's state
    /// is checked as a [`Stepper`](crate::Stepper) checks a model's, its degenerate rows
    /// excepted; the junctions must hold, `a_j · v = 0`. Refused: coordinates without kinetic
    /// energy whose rows the constraints do not determine (hidden constraints across the
    /// components, which the modular step does not project onto: step the interconnection
    /// monolithically), coordinates whose Lagrangian is linear in their velocity with a
    /// momentum that is not zero, and junctions that depend on each other or on the
    /// components' own constraints (the first step's Schur complement is singular). On error
    /// nothing changes.
    pub fn start_from_velocity(&mut self, q: &[f64], v: &[f64]) -> Result<(), DiracError> {
        let n = self.coordinates();
        if q.len() != n || v.len() != n {
            return Err(DiracError::Dimension(format!(
                "{} positions and {} velocities for {n} coordinates",
                q.len(),
                v.len()
            )));
        }
        if self.components.is_empty() {
            return Err(DiracError::InvalidInterconnection(
                "an interconnection without components".into(),
            ));
        }
        let tolerance = START_TOLERANCE.max(100.0 * self.options.residual_tolerance);
        let mut started = Vec::with_capacity(self.components.len());
        for component in &self.components {
            let range = component.first..component.first + component.part.coordinates();
            let state = component
                .part
                .checked_start(&q[range.clone()], &v[range], tolerance)
                .map_err(|e| in_component(&component.name, e))?;
            started.push(state);
        }
        self.check_junctions(v, tolerance)?;
        self.check_degenerate(q, v)?;
        for (component, state) in self.components.iter_mut().zip(started) {
            component.part.begin(state);
        }
        // The layout of a step: each component's unknowns, then the junctions' multipliers.
        let mut offset = 0;
        for component in &mut self.components {
            component.offset = offset;
            offset += component.part.unknowns();
            component.couplings.clear();
        }
        for (j, junction) in self.junctions.iter().enumerate() {
            for &(c, i, a) in &junction.terms {
                self.components[c].couplings.push((j, i, a));
            }
        }
        let jacobian = self.bordered();
        let unknowns = jacobian.size();
        let mut run = Running {
            newton: Newton::with_jacobian(jacobian, self.options)?,
            unknowns: DVector::zeros(unknowns),
            predictor: Predictor::new(unknowns),
            start: 0.0,
            steps: 0,
            multipliers: vec![0.0; self.junctions.len()],
            violation: 0.0,
            report: None,
        };
        // A model the step does not determine (dependent junctions, a component singular on
        // its own) is refused here, before the first step, naming the unknowns.
        let trial = self.solve(&mut run);
        for component in &mut self.components {
            component.part.discard();
        }
        if let Err(error @ DiracError::SingularJacobian { .. }) = trial {
            for component in &mut self.components {
                component.part.stop();
            }
            return Err(error);
        }
        run.newton = Newton::with_jacobian(self.bordered(), self.options)?;
        self.run = Some(run);
        Ok(())
    }

    /// The block-bordered Jacobian of a step: a block per component, the junctions' rows and
    /// columns.
    fn bordered(&self) -> Bordered {
        let sizes: Vec<usize> = self.components.iter().map(|c| c.part.unknowns()).collect();
        let borders = |component: &Component| {
            let share = component.part.point().share();
            let rows = component
                .couplings
                .iter()
                .map(|&(j, i, a)| (i, j, share * a));
            let columns = component.couplings.iter().map(|&(j, i, a)| (j, i, a));
            (rows.collect(), columns.collect())
        };
        let (rows, columns): (Vec<Vec<_>>, Vec<Vec<_>>) =
            self.components.iter().map(borders).unzip();
        Bordered::new(&sizes, &rows, &columns)
    }

    /// `a_j · v = 0` for every junction, to the start's tolerance.
    fn check_junctions(&self, v: &[f64], tolerance: f64) -> Result<(), DiracError> {
        for junction in &self.junctions {
            let terms = junction
                .terms
                .iter()
                .map(|&(c, i, a)| a * v[self.components[c].first + i]);
            let (rate, size) = terms.fold((0.0, 0.0), |(r, s), t: f64| (r + t, s + t.abs()));
            if exceeds(rate.abs(), tolerance * size) {
                return Err(DiracError::InconsistentInitialState(format!(
                    "the initial velocity violates junction {}: a·v = {rate:.3e}",
                    junction.name
                )));
            }
        }
        Ok(())
    }

    /// Refuses coordinates without kinetic energy whose Euler–Lagrange rows the constraints'
    /// impulses do not determine: where the forms restricted to those coordinates, `A_D`, have
    /// a null vector `w`, the combination `Σ_d w_d R_d` of their rows is a hidden constraint
    /// (no impulse enters it), which the modular step does not project onto.
    fn check_degenerate(&self, q: &[f64], v: &[f64]) -> Result<(), DiracError> {
        let mut dead: Vec<(usize, usize)> = Vec::new();
        let mut forms: Vec<Vec<(usize, f64)>> = Vec::new();
        for (c, component) in self.components.iter().enumerate() {
            let range = component.first..component.first + component.part.coordinates();
            let found = component.part.degenerate(&q[range.clone()], &v[range]);
            if let Some(&(i, momentum)) = found.momenta.iter().find(|(_, p)| *p != 0.0) {
                return Err(DiracError::Unsupported(format!(
                    "the modular step on {}.{}, whose Lagrangian is linear in its velocity with \
                     the momentum {momentum} (first-order rows are collocated only in a \
                     model stepped on its own)",
                    component.name,
                    component.part.coordinate_name(i)
                )));
            }
            let base = dead.len();
            dead.extend(found.coordinates.iter().map(|&i| (c, i)));
            for row in found.forms.row_iter() {
                let entries = found.coordinates.iter().enumerate();
                forms.push(entries.map(|(k, &i)| (base + k, row[i])).collect());
            }
        }
        if dead.is_empty() {
            return Ok(());
        }
        for junction in &self.junctions {
            let entries = junction
                .terms
                .iter()
                .filter_map(|&(c, i, a)| Some((dead.iter().position(|&d| d == (c, i))?, a)));
            forms.push(entries.collect());
        }
        let matrix = DMatrix::from_fn(forms.len(), dead.len(), |r, k| {
            forms[r].iter().find(|e| e.0 == k).map_or(0.0, |e| e.1)
        });
        let null = null_space(&matrix);
        if null.ncols() == 0 {
            return Ok(());
        }
        let names: Vec<String> = (0..dead.len())
            .filter(|&k| null.row(k).iter().any(|w| w.abs() > 1e-8))
            .map(|k| {
                let (c, i) = dead[k];
                let component = &self.components[c];
                format!("{}.{}", component.name, component.part.coordinate_name(i))
            })
            .collect();
        Err(DiracError::Unsupported(format!(
            "the modular step with hidden constraints across the components: the rows of {} \
             (coordinates without kinetic energy) combine into {} constraint(s) that no \
             junction's impulse enters (e.g. parallel capacitors); step the interconnection \
             monolithically (Interconnection), which projects onto them",
            names.join(", "),
            null.ncols()
        )))
    }

    /// Solves the next step from the components' states into `run`'s unknowns and lets each
    /// component propose its next state (the states themselves do not change).
    fn solve(&mut self, run: &mut Running) -> Result<(NewtonReport, f64), DiracError> {
        let first = run.unknowns.len() - self.junctions.len();
        let previous = run.predictor.predict();
        for component in &mut self.components {
            let range = component.offset..component.offset + component.part.unknowns();
            let before = previous.map(|p| &p.as_slice()[range.clone()]);
            component
                .part
                .predict(before, &mut run.unknowns.as_mut_slice()[range]);
        }
        match previous {
            Some(p) => run.unknowns.as_mut_slice()[first..].copy_from_slice(&p.as_slice()[first..]),
            None => run.unknowns.as_mut_slice()[first..].fill(0.0),
        }
        let parallel = self
            .parallel
            .unwrap_or(self.components.len() >= PARALLEL_FROM);
        let (components, junctions) = (&mut self.components, &self.junctions);
        let evaluate =
            |x: &DVector<f64>, r: &mut DVector<f64>, blocks: Option<&mut Vec<DMatrix<f64>>>| {
                let x = x.as_slice();
                let mu = &x[first..];
                let assemble = |component: &mut Component, block: Option<&mut DMatrix<f64>>| {
                    component.impulse.fill(0.0);
                    for &(j, i, a) in &component.couplings {
                        component.impulse[i] += a * mu[j];
                    }
                    let range = component.offset..component.offset + component.part.unknowns();
                    component.scale = component
                        .part
                        .assemble(&component.impulse, &x[range], block);
                };
                match (blocks, parallel) {
                    (Some(blocks), true) => components
                        .par_iter_mut()
                        .zip(blocks.par_iter_mut())
                        .with_min_len(16)
                        .for_each(|(c, b)| assemble(c, Some(b))),
                    (None, true) => components
                        .par_iter_mut()
                        .with_min_len(16)
                        .for_each(|c| assemble(c, None)),
                    (Some(blocks), false) => components
                        .iter_mut()
                        .zip(blocks.iter_mut())
                        .for_each(|(c, b)| assemble(c, Some(b))),
                    (None, false) => components.iter_mut().for_each(|c| assemble(c, None)),
                }
                let mut scale: f64 = 0.0;
                for component in components.iter() {
                    let residual = component.part.residual();
                    r.as_mut_slice()[component.offset..component.offset + residual.len()]
                        .copy_from_slice(residual);
                    scale = scale.max(component.scale);
                }
                for (j, junction) in junctions.iter().enumerate() {
                    let terms = junction.terms.iter().map(|&(c, i, a)| {
                        // The step's end point is a component's first unknowns (degree 1).
                        a * x[components[c].offset + i]
                    });
                    let (row, size) = terms.fold((0.0, 0.0), |(r, s), t: f64| (r + t, s + t.abs()));
                    r[first + j] = row;
                    scale = scale.max(size);
                }
                scale
            };
        let report = run.newton.solve(&mut run.unknowns, evaluate);
        let names = |column: usize| self.unknown_name(column, first);
        let report = report.map_err(|failure| {
            failure.into_error(
                "the modular discrete Euler–Lagrange equations",
                run.steps,
                &self.options,
                names,
            )
        })?;
        let mut violation: f64 = 0.0;
        for component in &mut self.components {
            let range = component.offset..component.offset + component.part.unknowns();
            match component
                .part
                .advance(&run.unknowns.as_slice()[range], run.steps)
            {
                Ok(v) => violation = largest([violation, v]),
                Err(error) => {
                    let name = component.name.clone();
                    self.components.iter_mut().for_each(|c| c.part.discard());
                    return Err(in_component(&name, error));
                }
            }
        }
        let junction_violation = self.junctions.iter().map(|junction| {
            let moved = junction.terms.iter().map(|&(c, i, a)| {
                let component = &self.components[c];
                a * component.part.proposed_step(i)
            });
            moved.sum::<f64>().abs()
        });
        Ok((
            report,
            largest(std::iter::once(violation).chain(junction_violation)),
        ))
    }

    /// The name of unknown `column` of a step (`first`: the junctions' first).
    fn unknown_name(&self, column: usize, first: usize) -> String {
        if column >= first {
            return format!(
                "the multiplier of junction {}",
                self.junctions[column - first].name
            );
        }
        let component = self
            .components
            .iter()
            .rev()
            .find(|c| c.offset <= column)
            .expect("a column of a component");
        format!(
            "{}: {}",
            component.name,
            component.part.unknown_name(column - component.offset)
        )
    }

    /// Advances one step. On error nothing changes.
    pub fn step(&mut self) -> Result<(), DiracError> {
        let mut run = self.run.take().ok_or(DiracError::NotStarted)?;
        let solved = self.solve(&mut run);
        let (report, violation) = match solved {
            Ok(solved) => solved,
            Err(error) => {
                self.run = Some(run);
                return Err(error);
            }
        };
        let t = run.start + (run.steps + 1) as f64 * self.h;
        for component in &mut self.components {
            component.part.accept(t);
        }
        let first = run.unknowns.len() - self.junctions.len();
        run.multipliers
            .copy_from_slice(&run.unknowns.as_slice()[first..]);
        run.predictor.record(&run.unknowns);
        run.steps += 1;
        run.violation = violation;
        run.report = Some(report);
        self.run = Some(run);
        Ok(())
    }

    /// Advances `steps` steps; stops at the first error, with the state of the step before it.
    pub fn run(&mut self, steps: u64) -> Result<(), DiracError> {
        (0..steps).try_for_each(|_| self.step())
    }

    fn running(&self) -> Result<&Running, DiracError> {
        self.run.as_ref().ok_or(DiracError::NotStarted)
    }

    /// The time of the current state (0 before a start).
    pub fn t(&self) -> f64 {
        self.run
            .as_ref()
            .map_or(0.0, |run| run.start + run.steps as f64 * self.h)
    }

    /// The steps taken since the start.
    pub fn steps(&self) -> u64 {
        self.run.as_ref().map_or(0, |run| run.steps)
    }

    /// Every coordinate's position, in the order of
    /// [`coordinate_names`](Self::coordinate_names) (zeros before a start).
    pub fn q(&self) -> DVector<f64> {
        self.gather(|part| part.q())
    }

    /// Every coordinate's momentum.
    pub fn p(&self) -> DVector<f64> {
        self.gather(|part| part.p())
    }

    fn gather(&self, read: impl Fn(&dyn Part) -> Vec<f64>) -> DVector<f64> {
        let mut all = DVector::zeros(self.coordinates());
        for component in &self.components {
            let values = read(component.part.as_ref());
            all.as_mut_slice()[component.first..component.first + values.len()]
                .copy_from_slice(&values);
        }
        all
    }

    /// The junctions' multipliers of the last step: their impulses over it (zeros before the
    /// first step).
    pub fn multipliers(&self) -> Result<&[f64], DiracError> {
        Ok(&self.running()?.multipliers)
    }

    /// The largest constraint violation of the last step: the components' own (as
    /// [`Stepper::constraint_violation`](crate::Stepper::constraint_violation)) and the
    /// junctions' `|Σ_c a_j^c · (q_{k+1}^c − q_k^c)|`.
    pub fn constraint_violation(&self) -> Result<f64, DiracError> {
        Ok(self.running()?.violation)
    }

    /// How Newton's method went on the last step.
    pub fn report(&self) -> Option<NewtonReport> {
        self.run.as_ref().and_then(|run| run.report)
    }

    /// The junctions' efforts and each component's port work over the last step (see
    /// [`PortWork`]); `NotStarted` before a start and zeros before the first step.
    pub fn ports(&self) -> Result<PortWork, DiracError> {
        let run = self.running()?;
        let efforts: Vec<f64> = run.multipliers.iter().map(|mu| mu / self.h).collect();
        let mut work = vec![0.0; self.components.len()];
        let mut scale: f64 = 0.0;
        for (junction, effort) in self.junctions.iter().zip(&efforts) {
            for &(c, i, a) in &junction.terms {
                let term = effort * a * self.components[c].part.last_step(i);
                work[c] += term;
                scale = scale.max(term.abs());
            }
        }
        Ok(PortWork {
            efforts,
            work,
            scale,
        })
    }
}

/// An error of component `name`, said to be its.
fn in_component(name: &str, error: DiracError) -> DiracError {
    match error {
        DiracError::InconsistentInitialState(why) => {
            DiracError::InconsistentInitialState(format!("component {name}: {why}"))
        }
        DiracError::Unsupported(why) => DiracError::Unsupported(format!("component {name}: {why}")),
        DiracError::NonFinite { what, value } => DiracError::NonFinite {
            what: format!("{what} of component {name}"),
            value,
        },
        other => other,
    }
}

/// What [`Part::degenerate`] finds at a start.
struct Degenerate {
    /// The coordinates without kinetic energy.
    coordinates: Vec<usize>,
    /// Their momenta `∂L/∂v` (must be zero).
    momenta: Vec<(usize, f64)>,
    /// The component's one-forms and holonomic differentials (rows over its coordinates).
    forms: DMatrix<f64>,
}

/// A component's step equations and state, behind a type-erased face: components of different
/// models and sizes sit in one interconnection.
trait Part: Send + std::fmt::Debug {
    fn coordinates(&self) -> usize;
    fn coordinate_name(&self, i: usize) -> String;
    fn one_forms(&self) -> bool;
    fn point(&self) -> ConstraintPoint;
    /// The number of unknowns of a step (after [`begin`](Self::begin)).
    fn unknowns(&self) -> usize;
    fn unknown_name(&self, column: usize) -> String;
    /// The checked state at `(q, v)` (its momentum `∂L/∂v`), at time 0.
    fn checked_start(&self, q: &[f64], v: &[f64], tolerance: f64) -> Result<Started, DiracError>;
    /// The degenerate coordinates at `(q, v)`.
    fn degenerate(&self, q: &[f64], v: &[f64]) -> Degenerate;
    /// Begins a run from a state [`checked_start`](Self::checked_start) returned.
    fn begin(&mut self, state: Started);
    /// Forgets the run (a start that failed after `begin`).
    fn stop(&mut self);
    /// Prepares the step and writes its predictor.
    fn predict(&mut self, previous: Option<&[f64]>, x: &mut [f64]);
    /// The residual at `x` with the junctions' impulse (into its own buffer), the Jacobian
    /// into `jacobian`; the size of the residual's terms.
    fn assemble(&mut self, impulse: &[f64], x: &[f64], jacobian: Option<&mut DMatrix<f64>>) -> f64;
    fn residual(&self) -> &[f64];
    /// Proposes the state after the step solved by `x`; its constraint violation.
    fn advance(&mut self, x: &[f64], step: u64) -> Result<f64, DiracError>;
    /// Coordinate `i` of the proposed step `q_{k+1} − q_k`.
    fn proposed_step(&self, i: usize) -> f64;
    /// Makes the proposed state current, at time `t`.
    fn accept(&mut self, t: f64);
    /// Drops a proposed state.
    fn discard(&mut self);
    /// Coordinate `i` of the last step taken, `q_{k+1} − q_k` (0 before one).
    fn last_step(&self, i: usize) -> f64;
    fn q(&self) -> Vec<f64>;
    fn p(&self) -> Vec<f64>;
}

/// A checked initial state, type-erased.
type Started = Box<dyn std::any::Any + Send>;

/// A model on `R^M` as a component.
struct Model<S: DiracSystem<M>, const M: usize> {
    equations: EulerLagrange<S, M, Euclidean>,
    state: Option<State<M>>,
    before: Option<State<M>>,
    proposed: Option<State<M>>,
    x: DVector<f64>,
    residual: DVector<f64>,
    previous: DVector<f64>,
}

impl<S: DiracSystem<M>, const M: usize> std::fmt::Debug for Model<S, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Model")
            .field("coordinates", &M)
            .field("state", &self.state)
            .finish()
    }
}

impl<S: DiracSystem<M>, const M: usize> Model<S, M> {
    fn new(equations: EulerLagrange<S, M, Euclidean>) -> Self {
        let n = equations.unknowns();
        Self {
            equations,
            state: None,
            before: None,
            proposed: None,
            x: DVector::zeros(n),
            residual: DVector::zeros(n),
            previous: DVector::zeros(n),
        }
    }

    fn state(&self) -> &State<M> {
        self.state
            .as_ref()
            .expect("a component steps only in a run")
    }
}

impl<S: DiracSystem<M> + Send, const M: usize> Part for Model<S, M> {
    fn coordinates(&self) -> usize {
        M
    }

    fn coordinate_name(&self, i: usize) -> String {
        self.equations.coordinate_name(i)
    }

    fn one_forms(&self) -> bool {
        S::ONE_FORMS > 0
    }

    fn point(&self) -> ConstraintPoint {
        self.equations.constraint_point()
    }

    fn unknowns(&self) -> usize {
        self.equations.unknowns()
    }

    fn unknown_name(&self, column: usize) -> String {
        self.equations.unknown_name(column)
    }

    fn checked_start(&self, q: &[f64], v: &[f64], tolerance: f64) -> Result<Started, DiracError> {
        let (q, v) = (SVector::from_column_slice(q), SVector::from_column_slice(v));
        let p = self.equations.momentum(&q, &v)?;
        let state = State::<M>::new(0.0, q, p, v);
        self.equations.check_component_start(&state, tolerance)?;
        Ok(Box::new(state))
    }

    fn degenerate(&self, q: &[f64], v: &[f64]) -> Degenerate {
        let (q, v) = (SVector::from_column_slice(q), SVector::from_column_slice(v));
        let system = self.equations.discrete().system();
        let coordinates = degenerate(system, &q, &v);
        let p = crate::legendre::momentum(system, &q, &v);
        Degenerate {
            momenta: coordinates.iter().map(|&i| (i, p[i])).collect(),
            coordinates,
            forms: HiddenConstraints::forms(system, &q),
        }
    }

    fn begin(&mut self, state: Started) {
        let state = *state
            .downcast::<State<M>>()
            .expect("this component's state");
        self.equations.begin_as_component(&state);
        let n = self.equations.unknowns();
        (self.x, self.residual, self.previous) =
            (DVector::zeros(n), DVector::zeros(n), DVector::zeros(n));
        self.state = Some(state);
        (self.before, self.proposed) = (None, None);
    }

    fn stop(&mut self) {
        (self.state, self.before, self.proposed) = (None, None, None);
    }

    fn predict(&mut self, previous: Option<&[f64]>, x: &mut [f64]) {
        let state = *self.state();
        let previous = previous.map(|p| {
            self.previous.copy_from_slice(p);
            &self.previous
        });
        self.equations.predict(&state, previous, &mut self.x);
        x.copy_from_slice(self.x.as_slice());
    }

    fn assemble(&mut self, impulse: &[f64], x: &[f64], jacobian: Option<&mut DMatrix<f64>>) -> f64 {
        let state = *self.state();
        self.equations
            .set_coupling(&SVector::from_column_slice(impulse));
        self.x.copy_from_slice(x);
        self.equations
            .assemble(&state, &self.x, &mut self.residual, jacobian)
    }

    fn residual(&self) -> &[f64] {
        self.residual.as_slice()
    }

    fn advance(&mut self, x: &[f64], step: u64) -> Result<f64, DiracError> {
        let state = *self.state();
        self.x.copy_from_slice(x);
        let (next, violation) = self.equations.advance(&state, &self.x, step)?;
        self.proposed = Some(next);
        Ok(violation)
    }

    fn proposed_step(&self, i: usize) -> f64 {
        self.proposed
            .as_ref()
            .map_or(0.0, |next| next.q[i] - self.state().q[i])
    }

    fn accept(&mut self, t: f64) {
        if let Some(mut next) = self.proposed.take() {
            next.t = t;
            self.before = self.state.replace(next);
        }
    }

    fn discard(&mut self) {
        self.proposed = None;
    }

    fn last_step(&self, i: usize) -> f64 {
        match (&self.before, &self.state) {
            (Some(before), Some(now)) => now.q[i] - before.q[i],
            _ => 0.0,
        }
    }

    fn q(&self) -> Vec<f64> {
        self.state
            .as_ref()
            .map_or(vec![0.0; M], |s| s.q.as_slice().to_vec())
    }

    fn p(&self) -> Vec<f64> {
        self.state
            .as_ref()
            .map_or(vec![0.0; M], |s| s.p.as_slice().to_vec())
    }
}
