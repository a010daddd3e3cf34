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
//! Σ_c a_j^c · ξ^c              = 0      (junction j, ξ^c = q_{k+1}^c − q_k^c on Rⁿ)
//! ```
//!
//! and `p_{k+1}^c` gains `(1 − σ) Σ_j μ_j a_j^c`: exactly the monolithic equations. Newton's
//! method solves them with a [`Bordered`] Jacobian: each `∂R_c/∂x_c` is factorised on its own
//! and the junctions' Schur complement, a band matrix along a chain, couples them, so a chain
//! of `K` components costs `O(K)` per step. Joints ([`Modular::connect`]) are junctions whose
//! rows are holonomic constraints on the components' positions, held as SHAKE holds them
//! (`σ = 1`, `g(q_{k+1}) = 0`): mechanisms in maximal coordinates. The components can be assembled, factorised and
//! solved in parallel (rayon, [`Modular::with_parallel`]). Hidden constraints across the components
//! (parallel capacitors in different components) are held at every step's end as a model holds
//! its own (see `hidden`).
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

mod component;
mod hidden;

use std::collections::{HashMap, HashSet};

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::base::float::{exceeds, largest};
use crate::base::runs::{Runs, in_runs};
use crate::discrete::discrete_lagrangian::DiscreteLagrangian;
use crate::model::interconnection::Junction;
use crate::model::joint::Joint;
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;
use crate::solve::banded::Banded;
use crate::solve::bordered::{BlockMatrix, Bordered};
use crate::solve::jacobian::Jacobian;
use crate::solve::newton::{Newton, NewtonFailure, NewtonOptions, NewtonReport};
use crate::solve::predictor::Predictor;
use crate::space::configuration_space::ConfigurationSpace;
use crate::space::manifold::Manifold;
use crate::step::euler_lagrange::EulerLagrange;
use crate::step::group_euler_lagrange::GroupEulerLagrange;
use crate::step::ledger::{ComponentBalance, Ledger};
use component::{Model, Part};
use hidden::Hidden;

/// Components per parallel task, at least: a pass over this many takes tens of microseconds,
/// above the cost of handing the task to another thread. Measured on 2 cores (the chain of
/// `examples/modular_scaling.rs`), 1 000 components in two tasks still step slower than on one
/// thread.
const MIN_GRAIN: usize = 1024;

/// Parallel tasks per thread in a pass, at most: enough that a thread done early finds more work.
const TASKS_PER_THREAD: usize = 4;

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
    /// Instance name → component.
    instances: HashMap<String, usize>,
    /// The names of included interconnections (their components are `name.instance`).
    nested: HashSet<String>,
    /// The joints, their rows among `junctions`.
    joints: Vec<JointRows>,
    /// The junctions' and joints' names.
    junction_names: HashSet<String>,
    /// The first component with one-forms: the others' must be held at its constraint point.
    constrained: Option<usize>,
    /// The number of coordinates of all components.
    total: usize,
    /// The number of position numbers of all components.
    total_positions: usize,
    /// The run (boxed: a step takes it out and puts it back).
    run: Option<Box<Running>>,
    /// Whether the components hold the states of a run (or of a start under way).
    begun: bool,
}

/// A named component and where it sits.
#[derive(Debug)]
struct Component {
    name: String,
    part: Box<dyn Part>,
    /// Its first coordinate among all.
    first: usize,
    /// Its first position number among all.
    position: usize,
    /// Its first unknown among a step's.
    offset: usize,
    /// The junction terms on it: `(junction, coordinate, coefficient)`.
    couplings: Vec<(usize, usize, f64)>,
    /// The junctions touching it, ascending by rank (its borders' order in the Jacobian).
    touching: Vec<usize>,
    /// The junctions' impulse on its coordinates (scratch of an evaluation).
    impulse: Vec<f64>,
    /// The size of its residual's terms at the last evaluation.
    scale: f64,
}

/// A junction resolved to its components' coordinates.
#[derive(Debug, Clone)]
struct Coupling {
    name: String,
    /// `(component, coordinate, coefficient)`: a joint's row's at the current state.
    terms: Vec<(usize, usize, f64)>,
    /// Where its multiplier sits among the junctions' unknowns of a step (set at a start).
    rank: usize,
    /// `(joint, row)` where it is a joint's row.
    joint: Option<(usize, usize)>,
}

/// A joint resolved to its components' positions.
#[derive(Debug, Clone)]
struct JointRows {
    joint: Joint,
    /// Each end's component (`None`: fixed in space).
    ends: [Option<usize>; 2],
    /// The indices, among its component's positions, of what each end's anchor reads.
    at: [Vec<usize>; 2],
    /// Its first row among the junctions (its rows follow).
    first: usize,
    /// Its rows at the point last read, and the buffers they are read with.
    read: JointRead,
}

/// A joint's rows at a point of its components (each end's positions and their derivatives in
/// its chart, as scratch), their values and each end's derivatives in its chart (rows × the
/// component's coordinates).
#[derive(Debug, Clone)]
struct JointRead {
    positions: [Vec<f64>; 2],
    derivatives: [DMatrix<f64>; 2],
    values: Vec<f64>,
    chart: [DMatrix<f64>; 2],
}

/// A run: the solver sized for its unknowns and what the steps carry.
#[derive(Debug)]
struct Running {
    newton: Newton<Bordered>,
    unknowns: DVector<f64>,
    /// The history of the steps' unknowns (the junctions' as impulses at the steps' nodes).
    predictor: Predictor,
    steps: u64,
    /// The junctions' multipliers (impulses) of the last step.
    multipliers: Vec<f64>,
    /// The junctions' rows in the order of their multipliers: `(unknown, coefficient)` of the
    /// step's end point, row `k`'s at `row_starts[k]..row_starts[k + 1]` (none for a joint's
    /// row, which is evaluated as it stands).
    row_terms: Vec<(usize, f64)>,
    row_starts: Vec<usize>,
    /// Each component's proposed step in its chart, laid out as its unknowns (scratch).
    moved: Vec<f64>,
    violation: f64,
    report: Option<NewtonReport>,
    /// The hidden constraints across the components, held at every step's end.
    hidden: Option<Hidden>,
    /// Each component's energy at the start.
    initial: Vec<f64>,
}

/// What the controller of [`Modular::run_controlled`] reads before each step: the state the
/// step starts from.
#[derive(Debug, Clone, Copy)]
pub struct ModularFeedback<'s> {
    /// The steps taken since the start, before this one.
    pub steps: u64,
    /// The time the step starts from.
    pub t: f64,
    /// Every position number, in the order of [`Modular::position_names`].
    pub q: &'s DVector<f64>,
    /// Every coordinate's velocity, in the order of [`Modular::coordinate_names`] (see
    /// [`Modular::velocities`]).
    pub v: &'s DVector<f64>,
    /// The junctions' multipliers of the last step (zeros before the first).
    pub multipliers: &'s [f64],
}

/// The flows and work through the junctions over the last step of a [`Modular`]
/// interconnection: efforts `e_j = μ_j / h` and each component's port work
/// `W_c = Σ_j e_j ⟨a_j^c, ξ^c⟩`, `ξ^c` the component's step in its chart (`q_{k+1}^c − q_k^c` on
/// `Rⁿ`, read off the stored positions).
#[derive(Debug, Clone, PartialEq)]
pub struct PortWork {
    /// The junctions' efforts.
    pub efforts: Vec<f64>,
    /// The work done on each component through the junctions.
    pub work: Vec<f64>,
    /// The size of the terms summed into the work, `Σ_j Σ_c |e_j a_j^c · Δq^c|` (termwise):
    /// Tellegen's `Σ_c W_c = 0` holds to round-off of this (the junctions are linear rows, which
    /// Newton's updates hold to round-off).
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
            instances: HashMap::new(),
            nested: HashSet::new(),
            joints: Vec::new(),
            junction_names: HashSet::new(),
            constrained: None,
            total: 0,
            total_positions: 0,
            run: None,
            begun: false,
        })
    }

    /// Newton's options for the steps (validated).
    pub fn with_newton_options(mut self, options: NewtonOptions) -> Result<Self, DiracError> {
        options.validate()?;
        self.options = options;
        self.end_run();
        Ok(self)
    }

    /// Whether the components are assembled, factorised, solved and advanced in parallel
    /// (rayon): each pass splits the components into runs of consecutive ones, each with its
    /// unknowns, and the junctions' rows and Newton's passes over its vectors likewise; the
    /// junctions' band (the Schur complement) is factorised and solved on one thread. By default
    /// not. The steps are the same bit for bit. A pass is split into a few tasks per thread, none
    /// of fewer than about 512 components, so a model of at most 1 024 components is stepped on
    /// one thread all the same. `examples/modular_scaling.rs` measures it on a chain of tethered
    /// masses.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = Some(parallel);
        self.end_run();
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
        self.check_name(name)?;
        let discrete = DiscreteLagrangian::new(system, self.quadrature.clone(), self.h);
        self.insert(name, Box::new(Model::new(EulerLagrange::new(discrete)?)))
    }

    /// Adds the component `system`, a model on the configuration space `space` (rotations, with
    /// ordinary coordinates or not: a [`Product`](crate::space::product::Product)), stepped by its
    /// discrete Euler–Lagrange equations in the moving chart
    /// ([`GroupEulerLagrange`]), as the instance `name`.
    ///
    /// Its coordinates, which junctions name, are the chart's: a rotation `R` gives
    /// `name.R_x`, `name.R_y`, `name.R_z`, the body angular velocity `Ω` (`Ṙ = R Ω̂`), so a
    /// junction on them is a fixed covector of `Ω` (a shaft along a body axis). Its velocities
    /// and momenta ([`velocities`](Self::velocities), [`p`](Self::p)) are `Ω` and the body
    /// angular momentum; its positions ([`q`](Self::q)) are its point's numbers, a rotation's
    /// nine entries row by row ([`position_names`](Self::position_names)). A step holds a
    /// junction `a · ξ = …` on the step's chart increment `ξ` (`R_{k+1} = R_k τ(ξ)`); its
    /// impulse acts as `a` in the body's axes at both ends of the step (half at each, with the
    /// midpoint). So, as a constant form on `Rⁿ`, a junction gives the same positions wherever
    /// on the step its impulse is held: those of one model on the product space whose one-forms
    /// are the junctions read in the chart at the step's start (`ConstraintPoint::Start`), whose
    /// multiplier at a step is `(1 − σ) μ_{k−1} + σ μ_k` of the multipliers `μ` here (`μ_{−1} = 0`).
    ///
    /// Fails as [`add`](Self::add) does, on a space without rotations (use `add`), and on a
    /// space with unit vectors (their chart's frame turns with the point: a junction on it would
    /// not be a fixed form). A component with a coordinate without kinetic energy is refused at
    /// the start.
    ///
    /// ```
    /// use dirac_runtime::modular::Modular;
    /// use dirac_runtime::product::{Configuration, Product, Rates};
    /// use dirac_runtime::{DiracSystem, Junction, Quadrature, Scalar};
    /// use nalgebra::SVector;
    ///
    /// /// A free rigid body, L = ½ Ωᵀ J Ω, with its rotation named R.
    /// struct Body;
    /// impl DiracSystem<3, Product<0, 1, 0>> for Body {
    ///     fn lagrangian<D: Scalar>(&self, _q: &Configuration<D, 0, 1, 0>, v: &Rates<D, 0, 1, 0>) -> D {
    ///         let w = v.rotation[0];
    ///         (w[0] * w[0] + w[1] * w[1] * 2.0 + w[2] * w[2] * 3.0) * 0.5
    ///     }
    ///     fn coordinate_name(&self, _i: usize) -> String {
    ///         "R".into()
    ///     }
    /// }
    /// /// A flywheel on the body's third axis.
    /// struct Wheel;
    /// impl DiracSystem<1> for Wheel {
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5
    ///     }
    /// }
    /// let mut model = Modular::new(Quadrature::midpoint(), 0.01)?;
    /// model.add_on_space("body", Body, Product::cayley())?;
    /// model.add("wheel", Wheel)?;
    /// model.join(Junction::new("shaft").flow("body.R_z", 1.0).flow("wheel.q0", -1.0))?;
    /// assert_eq!(model.coordinate_names(), ["body.R_x", "body.R_y", "body.R_z", "wheel.q0"]);
    /// assert_eq!(model.positions(), 10);
    /// // At rest, spinning about the third axis at 1 rad/s.
    /// let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    /// model.start_from_velocity(&identity, &[0.0, 0.0, 1.0, 1.0])?;
    /// model.run(100)?;
    /// // About a principal axis the spin stays: about one radian turned, by the body and the wheel.
    /// let (q, v) = (model.q(), model.velocities()?);
    /// assert!((q[0] - 1.0_f64.cos()).abs() < 1e-4 && (q[9] - 1.0).abs() < 1e-4);
    /// assert!((v[2] - 1.0).abs() < 1e-12 && (v[3] - 1.0).abs() < 1e-12);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn add_on_space<S, C, const N: usize>(
        &mut self,
        name: &str,
        system: S,
        space: C,
    ) -> Result<(), DiracError>
    where
        S: DiracSystem<N, C::Manifold> + Send + 'static,
        C: ConfigurationSpace<N> + Send + 'static,
    {
        self.check_name(name)?;
        if <C::Manifold as Manifold<N>>::VARIABLES == N {
            return Err(DiracError::Unsupported(format!(
                "{name}: add_on_space takes spaces with rotations; add a model on Rⁿ with `add`"
            )));
        }
        let tangent = <C::Manifold as Manifold<N>>::zero::<f64>();
        if <C::Manifold as Manifold<N>>::tangent_components(&tangent).len() != N {
            return Err(DiracError::Unsupported(format!(
                "{name}: unit vectors in a modular interconnection (their chart's frame turns \
                 with the point, so a junction on its coordinates would not be a fixed form)"
            )));
        }
        let discrete = DiscreteLagrangian::on_space(system, space, self.quadrature.clone(), self.h);
        self.insert(
            name,
            Box::new(Model::new(GroupEulerLagrange::new(discrete)?)),
        )
    }

    /// Refuses an instance name that is empty, contains `.`, or is taken.
    fn check_name(&self, name: &str) -> Result<(), DiracError> {
        let invalid = |why: String| Err(DiracError::InvalidInterconnection(why));
        if name.is_empty() || name.contains('.') {
            return invalid(format!(
                "the instance name {name:?} must be non-empty and without '.'"
            ));
        }
        if self.instances.contains_key(name) || self.nested.contains(name) {
            return invalid(format!("two instances are named {name:?}: name them apart"));
        }
        Ok(())
    }

    /// Adds `part` as the instance `name` (checked).
    fn insert(&mut self, name: &str, part: Box<dyn Part>) -> Result<(), DiracError> {
        let invalid = |why: String| Err(DiracError::InvalidInterconnection(why));
        if let Some(other) = self.constrained.map(|c| &self.components[c])
            && part.one_forms()
            && other.part.point() != part.point()
        {
            return invalid(format!(
                "{} holds its one-forms at {:?} and {name} at {:?}: the components need one \
                 constraint point",
                other.name,
                other.part.point(),
                part.point()
            ));
        }
        let m = part.coordinates();
        let coordinates: Vec<String> = (0..m)
            .map(|i| format!("{name}.{}", part.coordinate_name(i)))
            .collect();
        if let Some((i, coordinate)) = coordinates
            .iter()
            .enumerate()
            .find(|(i, c)| coordinates[..*i].contains(c))
        {
            return invalid(format!(
                "{name} has two coordinates named {coordinate:?} (the {i}th and an earlier \
                 one): a junction could not tell them apart"
            ));
        }
        let index = self.components.len();
        for (i, coordinate) in coordinates.into_iter().enumerate() {
            self.lookup.insert(coordinate, (index, i));
        }
        self.instances.insert(name.to_string(), index);
        if part.one_forms() && self.constrained.is_none() {
            self.constrained = Some(index);
        }
        let positions = part.positions();
        self.components.push(Component {
            name: name.to_string(),
            part,
            first: self.total,
            position: self.total_positions,
            offset: 0,
            couplings: Vec::new(),
            touching: Vec::new(),
            impulse: vec![0.0; m],
            scale: 0.0,
        });
        self.total += m;
        self.total_positions += positions;
        self.end_run();
        Ok(())
    }

    /// Adds the interconnection `other` as the instance `name`, a component made of components
    /// (a hierarchy): its components become `name.instance` (coordinates
    /// `name.instance.coordinate`, inputs `name.instance.input`) and its junctions
    /// `name.junction`, so junctions of this interconnection can reach into it. The
    /// interconnection of interconnections is one interconnection: the steps are those of the
    /// same components and junctions added here one by one. Fails on a name that is empty,
    /// contains `.`, or is taken, on another quadrature or step, and on components holding their
    /// one-forms at another constraint point. `other`'s run, if any, is not carried over.
    ///
    /// ```
    /// use dirac_runtime::modular::Modular;
    /// use dirac_runtime::{DiracSystem, Junction, Quadrature, Scalar};
    /// use nalgebra::SVector;
    /// struct Mass;
    /// impl DiracSystem<1> for Mass {
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5
    ///     }
    /// }
    /// let mut pair = Modular::new(Quadrature::midpoint(), 0.1)?;
    /// pair.add("a", Mass)?;
    /// pair.add("b", Mass)?;
    /// pair.join(Junction::new("glue").flow("a.q0", 1.0).flow("b.q0", -1.0))?;
    /// let mut whole = Modular::new(Quadrature::midpoint(), 0.1)?;
    /// whole.include("left", pair)?;
    /// whole.add("c", Mass)?;
    /// whole.join(Junction::new("tie").flow("left.b.q0", 1.0).flow("c.q0", -1.0))?;
    /// assert_eq!(whole.coordinate_names(), ["left.a.q0", "left.b.q0", "c.q0"]);
    /// assert_eq!(whole.junction_names(), ["left.glue", "tie"]);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn include(&mut self, name: &str, other: Modular) -> Result<(), DiracError> {
        let invalid = |why: String| Err(DiracError::InvalidInterconnection(why));
        self.check_name(name)?;
        if other.quadrature != self.quadrature || other.h != self.h {
            return invalid(format!(
                "{name} steps with {} and h = {}, this interconnection with {} and h = {}",
                other.quadrature.name(),
                other.h,
                self.quadrature.name(),
                self.h
            ));
        }
        let prefix = format!("{name}.");
        let theirs = other.junctions.iter().map(|j| &j.name);
        let joints = other.joints.iter().map(|j| j.joint.name());
        if let Some(name) = theirs
            .map(String::as_str)
            .chain(joints)
            .find(|name| self.junction_names.contains(&format!("{prefix}{name}")))
        {
            return invalid(format!("two junctions are named {prefix}{name}"));
        }
        if let (Some(mine), Some(theirs)) = (self.constrained, other.constrained) {
            let (mine, theirs) = (&self.components[mine], &other.components[theirs]);
            if mine.part.point() != theirs.part.point() {
                return invalid(format!(
                    "{} holds its one-forms at {:?} and {prefix}{} at {:?}: the components need \
                     one constraint point",
                    mine.name,
                    mine.part.point(),
                    theirs.name,
                    theirs.part.point()
                ));
            }
        }
        let base = self.components.len();
        self.nested.insert(name.to_string());
        if self.constrained.is_none() {
            self.constrained = other.constrained.map(|c| base + c);
        }
        for mut component in other.components {
            component.name = format!("{prefix}{}", component.name);
            component.first = self.total;
            component.position = self.total_positions;
            self.total_positions += component.part.positions();
            for i in 0..component.part.coordinates() {
                let coordinate =
                    format!("{}.{}", component.name, component.part.coordinate_name(i));
                self.lookup.insert(coordinate, (self.components.len(), i));
            }
            self.instances
                .insert(component.name.clone(), self.components.len());
            self.total += component.part.coordinates();
            component.part.stop();
            self.components.push(component);
        }
        let (first_junction, first_joint) = (self.junctions.len(), self.joints.len());
        for mut junction in other.junctions {
            junction.name = format!("{prefix}{}", junction.name);
            junction.rank = self.junctions.len();
            junction.terms.iter_mut().for_each(|t| t.0 += base);
            if let Some((joint, _)) = &mut junction.joint {
                *joint += first_joint;
            }
            self.junction_names.insert(junction.name.clone());
            self.junctions.push(junction);
        }
        for mut rows in other.joints {
            rows.joint.rename(format!("{prefix}{}", rows.joint.name()));
            rows.ends.iter_mut().flatten().for_each(|c| *c += base);
            rows.first += first_junction;
            self.junction_names.insert(rows.joint.name().to_string());
            self.joints.push(rows);
        }
        self.end_run();
        Ok(())
    }

    /// Adds the junction `junction`, a constant one-form over the components' coordinates
    /// (`instance.coordinate`); an `Err(InvalidInterconnection)` names an unknown instance or
    /// coordinate, a coordinate twice, a zero or non-finite coefficient, no terms, or a name
    /// taken. Junctions that depend on each other are refused at the start.
    pub fn join(&mut self, junction: Junction) -> Result<(), DiracError> {
        if self.junction_names.contains(junction.name()) {
            return Err(DiracError::InvalidInterconnection(format!(
                "two junctions are named {:?}",
                junction.name()
            )));
        }
        // What there is, said only when a coordinate is unknown.
        let known = |coordinate: &str| {
            // The longest instance the name begins with (an included one's are dotted).
            let instance = coordinate
                .rmatch_indices('.')
                .map(|(k, _)| &coordinate[..k])
                .find(|prefix| self.instances.contains_key(*prefix))
                .unwrap_or_else(|| coordinate.split('.').next().unwrap_or_default());
            match self.instances.get(instance) {
                Some(&c) => {
                    let part = &self.components[c].part;
                    let theirs: Vec<String> = (0..part.coordinates())
                        .map(|i| format!("{instance}.{}", part.coordinate_name(i)))
                        .collect();
                    format!("{instance} has {}", theirs.join(", "))
                }
                None => {
                    let names: Vec<&str> =
                        self.components.iter().map(|c| c.name.as_str()).collect();
                    format!("the instances are {}", names.join(", "))
                }
            }
        };
        let index = |coordinate: &str| {
            let &(c, i) = self.lookup.get(coordinate)?;
            Some(self.components[c].first + i)
        };
        let terms = junction
            .resolve_terms(index, known)?
            .into_iter()
            .map(|(global, a)| {
                let c = self.components.partition_point(|c| c.first <= global) - 1;
                (c, global - self.components[c].first, a)
            })
            .collect();
        self.junction_names.insert(junction.name().to_string());
        self.junctions.push(Coupling {
            rank: self.junctions.len(),
            name: junction.name().to_string(),
            terms,
            joint: None,
        });
        self.end_run();
        Ok(())
    }

    /// Adds the joint `joint`, a holonomic constraint between points its components carry (see
    /// [`joint`](crate::joint)): its rows are junctions named `joint[k]`, held as SHAKE holds a
    /// holonomic constraint, `g(q_{k+1}) = 0` with the impulse `G(q_k)ᵀ μ` on the row of `p_k`.
    /// With a joint, every junction's impulse is taken on that row (a constant form gives the
    /// same positions either way). An `Err(InvalidInterconnection)` names an anchor's unknown
    /// instance or position (listing those there are), a joint of one component with itself, a
    /// name taken, and the joint's own faults ([`Joint`]); at the start, the positions must
    /// satisfy it and the velocities its differential.
    ///
    /// ```
    /// use dirac_runtime::joint::{Anchor, Joint};
    /// use dirac_runtime::modular::Modular;
    /// use dirac_runtime::{DiracSystem, Quadrature, Scalar};
    /// use nalgebra::SVector;
    ///
    /// /// A unit point mass in the plane under gravity 1.
    /// struct Bob;
    /// impl DiracSystem<2> for Bob {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1]) * 0.5 - q[1]
    ///     }
    ///     fn coordinate_name(&self, i: usize) -> String {
    ///         ["x", "y"][i].into()
    ///     }
    /// }
    /// // A pendulum of length 1, released at rest from 0.1 rad: about the period 2π.
    /// let mut pendulum = Modular::new(Quadrature::midpoint(), 0.001)?;
    /// pendulum.add("bob", Bob)?;
    /// let origin = Anchor::fixed([0.0, 0.0]);
    /// pendulum.connect(Joint::rod("rod", origin, Anchor::point("bob", ["x", "y"]), 1.0))?;
    /// let (s, c) = 0.1_f64.sin_cos();
    /// pendulum.start_from_velocity(&[s, -c], &[0.0, 0.0])?;
    /// pendulum.run(6283)?;
    /// let q = pendulum.q();
    /// assert!((q[0] * q[0] + q[1] * q[1] - 1.0).abs() < 1e-12);
    /// assert!((q[0] - s).abs() < 1e-3);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn connect(&mut self, joint: Joint) -> Result<(), DiracError> {
        let invalid = |why: String| Err(DiracError::InvalidInterconnection(why));
        joint.check()?;
        let name = joint.name().to_string();
        let rows = (0..joint.rows()).map(|row| joint.row_name(row));
        if let Some(taken) = std::iter::once(name.clone())
            .chain(rows)
            .find(|n| self.junction_names.contains(n))
        {
            return invalid(format!("two junctions or joints are named {taken:?}"));
        }
        let mut ends = [None, None];
        let mut at = [Vec::new(), Vec::new()];
        for (e, anchor) in joint.ends().iter().enumerate() {
            let Some(instance) = anchor.instance() else {
                continue;
            };
            let Some(&c) = self.instances.get(instance) else {
                let names: Vec<&str> = self.components.iter().map(|c| c.name.as_str()).collect();
                return invalid(format!(
                    "joint {name}: no instance {instance:?} (the instances are {})",
                    names.join(", ")
                ));
            };
            let part = &self.components[c].part;
            let theirs: Vec<String> = (0..part.positions())
                .map(|i| part.position_name(i))
                .collect();
            for wanted in anchor.position_names() {
                let Some(i) = theirs.iter().position(|p| *p == wanted) else {
                    return invalid(format!(
                        "joint {name}: {instance} has no position {wanted:?} (its positions are \
                         {})",
                        theirs.join(", ")
                    ));
                };
                at[e].push(i);
            }
            ends[e] = Some(c);
        }
        if ends[0].is_some() && ends[0] == ends[1] {
            return invalid(format!("joint {name} joins a component with itself"));
        }
        let first = self.junctions.len();
        let index = self.joints.len();
        for row in 0..joint.rows() {
            let terms = ends
                .iter()
                .flatten()
                .flat_map(|&c| (0..self.components[c].part.coordinates()).map(move |i| (c, i, 0.0)))
                .collect();
            self.junctions.push(Coupling {
                name: joint.row_name(row),
                terms,
                rank: first + row,
                joint: Some((index, row)),
            });
        }
        self.junction_names.insert(name);
        self.junction_names
            .extend((0..joint.rows()).map(|row| joint.row_name(row)));
        let k = joint.rows();
        let sized = |f: &dyn Fn(&dyn Part) -> (usize, usize)| {
            ends.map(|end| end.map_or((0, 0), |c| f(&*self.components[c].part)))
        };
        let [pa, pb] = sized(&|p| (p.positions(), p.coordinates()));
        let read = JointRead {
            positions: [vec![0.0; pa.0], vec![0.0; pb.0]],
            derivatives: [DMatrix::zeros(pa.0, pa.1), DMatrix::zeros(pb.0, pb.1)],
            values: vec![0.0; k],
            chart: [DMatrix::zeros(k, pa.1), DMatrix::zeros(k, pb.1)],
        };
        self.joints.push(JointRows {
            joint,
            ends,
            at,
            first,
            read,
        });
        self.end_run();
        Ok(())
    }

    /// Reads the joints' rows at the current state (after a start and after every step) into
    /// their junctions' coefficients, and each component's terms from the junctions.
    fn refresh_joints(&mut self) {
        if !self.joints.is_empty() {
            let (components, joints) = (&self.components, &mut self.joints);
            read_joints(components, joints, &mut self.junctions, None, 0.0)
                .expect("no check without positions");
            self.couple();
        }
    }

    /// `Unsupported` where a joint holds a component with coordinates without kinetic energy
    /// at the positions `q` and velocities `v`: their hidden constraints and projections would
    /// move the step's end after the joint was solved there.
    fn check_jointed(&self, q: &[f64], v: &[f64]) -> Result<(), DiracError> {
        for rows in &self.joints {
            for c in rows.ends.iter().flatten() {
                let component = &self.components[*c];
                let (part, at) = (&component.part, component.position);
                let velocities = &v[component.first..component.first + part.coordinates()];
                let dead = part.degenerate(&q[at..at + part.positions()], velocities);
                if let Some(&i) = dead.coordinates.first() {
                    return Err(DiracError::Unsupported(format!(
                        "joint {} on {}, whose coordinate {} has no kinetic energy (a joint's \
                         component must determine its own step)",
                        rows.joint.name(),
                        component.name,
                        part.coordinate_name(i)
                    )));
                }
            }
        }
        Ok(())
    }

    /// Each component's junction terms and the junctions touching it, from the junctions.
    fn couple(&mut self) {
        for component in &mut self.components {
            component.couplings.clear();
            component.touching.clear();
        }
        for junction in &self.junctions {
            for &(c, i, a) in &junction.terms {
                self.components[c].couplings.push((junction.rank, i, a));
                self.components[c].touching.push(junction.rank);
            }
        }
        for component in &mut self.components {
            component.touching.sort_unstable();
            component.touching.dedup();
        }
    }

    /// The number of coordinates of all components.
    pub fn coordinates(&self) -> usize {
        self.total
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

    /// The number of position numbers of all components: a coordinate each on `Rⁿ`, a
    /// rotation's nine entries (see [`add_on_space`](Self::add_on_space)).
    pub fn positions(&self) -> usize {
        self.total_positions
    }

    /// `instance.number` for every position number, in the components' order (a rotation `R`
    /// of instance `body`: `body.R_11`, `body.R_12`, …, `body.R_33`); on `Rⁿ` these are the
    /// [`coordinate_names`](Self::coordinate_names).
    pub fn position_names(&self) -> Vec<String> {
        self.components
            .iter()
            .flat_map(|c| {
                (0..c.part.positions())
                    .map(move |i| format!("{}.{}", c.name, c.part.position_name(i)))
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

    /// Sets the input named `instance.input` (e.g. a voltage source's `drive.u`) from the
    /// next step on; `UnknownInput` lists the inputs there are, `NonFinite` refuses a value.
    pub fn set_input(&mut self, name: &str, value: f64) -> Result<(), DiracError> {
        // The instance is a prefix up to some dot: a component's own input names may carry
        // dots too (an `Interconnection` component's `source.u`).
        let found = name.match_indices('.').find_map(|(k, _)| {
            let c = *self.instances.get(&name[..k])?;
            let part = &self.components[c].part;
            let i = (0..part.inputs()).find(|&i| part.input_name(i) == name[k + 1..])?;
            Some((c, i))
        });
        let Some((c, i)) = found else {
            let inputs: Vec<String> = self
                .components
                .iter()
                .flat_map(|c| {
                    (0..c.part.inputs()).map(|i| format!("{}.{}", c.name, c.part.input_name(i)))
                })
                .collect();
            return Err(DiracError::UnknownInput(format!(
                "{name:?}; the inputs are {}",
                if inputs.is_empty() {
                    "none".to_string()
                } else {
                    inputs.join(", ")
                }
            )));
        };
        if !value.is_finite() {
            return Err(DiracError::NonFinite {
                what: format!("input {name}"),
                value,
            });
        }
        self.set_input_at(c, i, value);
        Ok(())
    }

    /// Sets input `i` of component `c` to the finite `value`.
    fn set_input_at(&mut self, c: usize, i: usize, value: f64) {
        if self.components[c].part.set_input(i, value)
            && let Some(run) = self.run.as_mut()
        {
            // A step after a change of inputs is predicted from the last one alone.
            run.predictor.restart();
        }
    }

    /// Every component's inputs, `instance.input`, in the order of [`inputs`](Self::inputs).
    pub fn input_names(&self) -> Vec<String> {
        self.components
            .iter()
            .flat_map(|c| {
                (0..c.part.inputs()).map(|i| format!("{}.{}", c.name, c.part.input_name(i)))
            })
            .collect()
    }

    /// The inputs' current values, in the order of [`input_names`](Self::input_names).
    pub fn inputs(&self) -> Vec<f64> {
        self.components
            .iter()
            .flat_map(|c| (0..c.part.inputs()).map(|i| c.part.input(i)))
            .collect()
    }

    /// Sets every input, in the order of [`input_names`](Self::input_names). A wrong count or a
    /// value that is not finite is refused and sets none.
    pub fn set_inputs(&mut self, values: &[f64]) -> Result<(), DiracError> {
        let names = self.input_names();
        if values.len() != names.len() {
            return Err(DiracError::Dimension(format!(
                "{} input values for the {} inputs {}",
                values.len(),
                names.len(),
                names.join(", ")
            )));
        }
        if let Some((name, &value)) = names.iter().zip(values).find(|(_, v)| !v.is_finite()) {
            return Err(DiracError::NonFinite {
                what: format!("input {name}"),
                value,
            });
        }
        let mut k = 0;
        for c in 0..self.components.len() {
            for i in 0..self.components[c].part.inputs() {
                self.set_input_at(c, i, values[k]);
                k += 1;
            }
        }
        Ok(())
    }

    /// Advances `steps` steps with a feedback inside the run: before each step `controller`
    /// reads the state the step starts from ([`ModularFeedback`]: the time, the positions, the
    /// velocities and the last step's junction multipliers) and sets the inputs (in the order of
    /// [`input_names`](Self::input_names)), which are held over the step as
    /// [`Run::control`](crate::Run::control)'s are. Stops at the first error with the state of
    /// the step before it; a value that is not finite is refused before its step.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Modular, Quadrature, Scalar};
    /// use nalgebra::SVector;
    /// /// A unit mass on a unit spring pushed by u: L = (ẋ² − x²)/2, F = u dx.
    /// struct Pushed;
    /// impl DiracSystem<1> for Pushed {
    ///     const FORCES: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, _v: &SVector<D, 1>, _t: f64, u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([u[0]])
    ///     }
    ///     fn coordinate_name(&self, _i: usize) -> String { "x".into() }
    ///     fn input_name(&self, _i: usize) -> String { "u".into() }
    /// }
    /// let mut parts = Modular::new(Quadrature::midpoint(), 0.05)?;
    /// parts.add("mass", Pushed)?;
    /// parts.start_from_velocity(&[1.0], &[0.0])?;
    /// assert_eq!(parts.input_names(), ["mass.u"]);
    /// // A damper by feedback, u = −ẋ: the oscillation dies out.
    /// parts.run_controlled(2000, |now, u| u[0] = -now.v[0])?;
    /// assert!(parts.q()[0].abs() < 1e-10 && parts.ledger()?.components[0].forces < -0.49);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn run_controlled(
        &mut self,
        steps: u64,
        mut controller: impl FnMut(&ModularFeedback<'_>, &mut [f64]),
    ) -> Result<(), DiracError> {
        let mut inputs = self.inputs();
        for _ in 0..steps {
            let (q, v) = (self.q(), self.velocities()?);
            let run = self.running()?;
            let feedback = ModularFeedback {
                steps: run.steps,
                t: self.t(),
                q: &q,
                v: &v,
                multipliers: &run.multipliers,
            };
            controller(&feedback, &mut inputs);
            self.set_inputs(&inputs)?;
            self.step()?;
        }
        Ok(())
    }

    /// Starts a run at time 0 from the positions `q` (in the order of
    /// [`position_names`](Self::position_names): on `Rⁿ` the coordinates') and the velocities
    /// `v` of every coordinate (in the order of [`coordinate_names`](Self::coordinate_names): on
    /// a rotation the body angular velocity). Each component's state
    /// is checked as a [`Stepper`](crate::Stepper) checks a model's, its degenerate rows
    /// excepted; the junctions must hold, `a_j · v = 0`. Coordinates without kinetic energy
    /// whose rows no impulse reaches combine into hidden constraints across the components
    /// (parallel capacitors: equal voltages), held at every step's end; the state must satisfy
    /// them and their velocity form. Refused: such combinations that contain velocities (a
    /// resistor beside a capacitor) or depend on time, where a component with coordinates
    /// without kinetic energy has constraint forms that are not constant, or more than 256 of
    /// them (step the interconnection monolithically);
    /// coordinates whose Lagrangian is linear in their velocity with a momentum that is not
    /// zero; and junctions that depend on each other or on the components' own constraints
    /// (the first step's Schur complement is singular). A state or a model refused by the
    /// checks changes nothing; one refused by the first step's trial solve (singular) leaves
    /// the interconnection not started.
    pub fn start_from_velocity(&mut self, q: &[f64], v: &[f64]) -> Result<(), DiracError> {
        let (n, m) = (self.coordinates(), self.positions());
        if q.len() != m || v.len() != n {
            return Err(DiracError::Dimension(format!(
                "{} positions and {} velocities for {m} position numbers and {n} coordinates",
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
            let at = component.position..component.position + component.part.positions();
            let state = component
                .part
                .checked_start(&q[at], &v[range], tolerance)
                .map_err(|e| in_component(&component.name, e))?;
            started.push(state);
        }
        self.check_jointed(q, v)?;
        let mut junctions = self.junctions.clone();
        let (components, joints) = (&self.components, &mut self.joints);
        read_joints(components, joints, &mut junctions, Some(q), tolerance)?;
        Self::check_junctions(&self.components, &junctions, v, tolerance)?;
        let hidden = Hidden::find(&self.components, &junctions, (q, v), tolerance)?;
        self.junctions = junctions;
        // From here a failure leaves no run (the components begin afresh).
        self.run = None;
        self.begun = true;
        for (component, state) in self.components.iter_mut().zip(started) {
            component.part.begin(state);
        }
        let initial = self
            .components
            .iter()
            .map(|c| c.part.energy(&v[c.first..c.first + c.part.coordinates()]))
            .collect();
        // The layout of a step: each component's unknowns, then the junctions' multipliers.
        let mut offset = 0;
        for component in &mut self.components {
            component.offset = offset;
            offset += component.part.unknowns();
        }
        // The junctions' multipliers in the order of the components they join (the first, then
        // the last, then the name), whatever order they were joined in: along a chain or a
        // ladder the Schur complement is then a narrow band (a junction between distant
        // components still widens it to their distance).
        let span = |j: &Coupling| {
            let components = j.terms.iter().map(|t| t.0);
            (components.clone().min(), components.max(), j.name.clone())
        };
        let mut order: Vec<usize> = (0..self.junctions.len()).collect();
        order.sort_by_key(|&j| span(&self.junctions[j]));
        for (rank, &j) in order.iter().enumerate() {
            self.junctions[j].rank = rank;
        }
        self.couple();
        // The step's end point is a component's first unknowns (degree 1).
        let (mut row_terms, mut row_starts) = (Vec::new(), vec![0]);
        for &j in &order {
            let junction = &self.junctions[j];
            if junction.joint.is_none() {
                let terms = junction.terms.iter();
                row_terms.extend(terms.map(|&(c, i, a)| (self.components[c].offset + i, a)));
            }
            row_starts.push(row_terms.len());
        }
        let jacobian = match self.bordered() {
            Ok(jacobian) => jacobian,
            Err(error) => {
                self.end_run();
                return Err(error);
            }
        };
        let unknowns = jacobian.size();
        let mut newton = Newton::with_jacobian(jacobian, self.options)?;
        // The contraction test on the components' unknowns, not the joints' impulses.
        let measured = (!self.joints.is_empty()).then(|| unknowns - self.junctions.len());
        newton.measure_contraction_on(measured);
        let mut run = Box::new(Running {
            newton,
            unknowns: DVector::zeros(unknowns),
            predictor: Predictor::new(unknowns),
            steps: 0,
            multipliers: vec![0.0; self.junctions.len()],
            row_terms,
            row_starts,
            moved: vec![0.0; unknowns - self.junctions.len()],
            violation: 0.0,
            report: None,
            hidden,
            initial,
        });
        let multipliers = unknowns - self.junctions.len()..unknowns;
        let share = self.junction_share();
        run.predictor.share_impulses(Some((multipliers, share)));
        // A model the step does not determine (dependent junctions, a component singular on
        // its own) is refused here, before the first step, naming the unknowns.
        let trial = self.solve(&mut run, true);
        for component in &mut self.components {
            component.part.discard();
        }
        if let Err(error @ (DiracError::SingularJacobian { .. } | DiracError::Unsupported(_))) =
            trial
        {
            self.end_run();
            return Err(error);
        }
        run.newton = Newton::with_jacobian(self.bordered()?, self.options)?;
        run.newton.measure_contraction_on(measured);
        self.run = Some(run);
        Ok(())
    }

    /// Ends the run (a change of the model): the components forget their states. Without a
    /// run it touches nothing, so that building a model of `K` components costs `O(K)`.
    fn end_run(&mut self) {
        self.run = None;
        if std::mem::take(&mut self.begun) {
            self.components.iter_mut().for_each(|c| c.part.stop());
        }
    }

    /// Whether the components are stepped in parallel.
    fn parallel(&self) -> bool {
        self.parallel.unwrap_or(false)
    }

    /// Components per parallel task of a pass (`usize::MAX`: one after another): about
    /// [`TASKS_PER_THREAD`] tasks for each of rayon's threads, none below [`MIN_GRAIN`]
    /// components, so that a model too small to gain from threads is stepped on one.
    fn grain(&self) -> usize {
        if !self.parallel() {
            return usize::MAX;
        }
        let tasks = TASKS_PER_THREAD * rayon::current_num_threads();
        self.components.len().div_ceil(tasks).max(MIN_GRAIN)
    }

    /// The share `σ` of every junction's impulse on the row of `p_k`: with joints 1 (SHAKE),
    /// else that of the constrained components' constraint point (they agree), or the
    /// midpoint's, as in the monolithic interconnection.
    fn junction_share(&self) -> f64 {
        if !self.joints.is_empty() {
            return 1.0;
        }
        let point = self.constrained.map_or(ConstraintPoint::Midpoint, |c| {
            self.components[c].part.point()
        });
        point.share()
    }

    /// The block-bordered Jacobian of a step: a block per component, the junctions' rows and
    /// columns.
    fn bordered(&self) -> Result<Bordered, DiracError> {
        let share = self.junction_share();
        let sizes: Vec<usize> = self.components.iter().map(|c| c.part.unknowns()).collect();
        let borders = |component: &Component| {
            let rows = component
                .couplings
                .iter()
                .map(|&(j, i, a)| (i, j, share * a));
            let columns = component.couplings.iter().map(|&(j, i, a)| (j, i, a));
            (rows.collect(), columns.collect())
        };
        let (rows, columns): (Vec<Vec<_>>, Vec<Vec<_>>) =
            self.components.iter().map(borders).unzip();
        let grain = self.grain();
        Ok(Bordered::new(&sizes, &rows, &columns)?.parallel(grain))
    }

    /// `a_j · v = 0` for every junction, to the start's tolerance.
    fn check_junctions(
        components: &[Component],
        junctions: &[Coupling],
        v: &[f64],
        tolerance: f64,
    ) -> Result<(), DiracError> {
        for junction in junctions {
            let terms = junction
                .terms
                .iter()
                .map(|&(c, i, a)| a * v[components[c].first + i]);
            let (rate, size) = sum_and_size(terms);
            if exceeds(rate.abs(), tolerance * size) {
                return Err(DiracError::InconsistentInitialState(format!(
                    "the initial velocity violates junction {}: a·v = {rate:.3e}",
                    junction.name
                )));
            }
        }
        Ok(())
    }

    /// Solves the next step from the components' states into `run`'s unknowns and lets each
    /// component propose its next state (the states themselves do not change).
    /// `trial`: the start's trial step, where a component singular on its own is refused as
    /// `Unsupported` (a later step reports a singular block as `SingularJacobian`).
    fn solve(&mut self, run: &mut Running, trial: bool) -> Result<(NewtonReport, f64), DiracError> {
        let first = run.unknowns.len() - self.junctions.len();
        let previous = run.predictor.predict();
        let grain = self.grain();
        let (unknowns, multipliers) = run.unknowns.as_mut_slice().split_at_mut(first);
        let predict = |parts: Parts<'_>, run: &mut [f64]| {
            parts.each(run, |component, _, own| {
                let range = component.offset..component.offset + own.len();
                component
                    .part
                    .predict(previous.map(|p| &p.as_slice()[range]));
                own.copy_from_slice(component.part.unknowns_of_step());
            });
        };
        let parts = Parts {
            components: &mut self.components,
            blocks: None,
        };
        in_runs(parts, unknowns, grain, &predict, &|(), ()| ());
        match previous {
            Some(p) => multipliers.copy_from_slice(&p.as_slice()[first..]),
            None => multipliers.fill(0.0),
        }
        let share = self.junction_share();
        let components = &mut self.components;
        let (joints, junctions) = (&mut self.joints, &self.junctions);
        let (row_terms, row_starts) = (&run.row_terms, &run.row_starts);
        let evaluate = |x: &DVector<f64>,
                        r: &mut DVector<f64>,
                        mut blocks: Option<&mut Vec<BlockMatrix>>| {
            let x = x.as_slice();
            let mu = &x[first..];
            let (own, rows) = r.as_mut_slice().split_at_mut(first);
            let assemble = |parts: Parts<'_>, run: &mut [f64]| {
                let mut scale: f64 = 0.0;
                parts.each(run, |component, block, own| {
                    component.impulse.fill(0.0);
                    for &(j, i, a) in &component.couplings {
                        component.impulse[i] += a * mu[j];
                    }
                    let range = component.offset..component.offset + own.len();
                    let part = &mut component.part;
                    component.scale = part.assemble(&component.impulse, share, &x[range], block);
                    own.copy_from_slice(part.residual());
                    scale = scale.max(component.scale);
                });
                scale
            };
            let parts = Parts {
                components: &mut components[..],
                blocks: blocks.as_deref_mut().map(|b| &mut b[..]),
            };
            let scale = in_runs(parts, own, grain, &assemble, &f64::max);
            // The junctions' rows, in the order of their multipliers.
            let junction = |(k, row): (usize, &mut f64)| {
                let terms = &row_terms[row_starts[k]..row_starts[k + 1]];
                let (value, size) = sum_and_size(terms.iter().map(|&(u, a)| a * x[u]));
                *row = value;
                size
            };
            let size = if grain < rows.len() {
                let each = rows.par_iter_mut().enumerate().with_min_len(grain);
                each.map(junction).reduce(|| 0.0, f64::max)
            } else {
                rows.iter_mut()
                    .enumerate()
                    .map(junction)
                    .fold(0.0, f64::max)
            };
            // The joints' rows in place of those their coefficients at `q_k` give, and their
            // borders: `G` at the step's end, `E = σ G(q_k)ᵀ`.
            let components = &components[..];
            let step = |c: usize| {
                let at = components[c].offset;
                &x[at..at + components[c].part.coordinates()]
            };
            let mut joined: f64 = 0.0;
            for joint in joints.iter_mut() {
                let size = joint_value(components, joint, |_| None, step);
                for (row, &g) in joint.read.values.iter().enumerate() {
                    let coupling = &junctions[joint.first + row];
                    rows[coupling.rank] = g;
                    let Some(blocks) = blocks.as_deref_mut() else {
                        continue;
                    };
                    for &(c, i, a) in &coupling.terms {
                        let touching = &components[c].touching;
                        let t = touching
                            .binary_search(&coupling.rank)
                            .expect("it touches c");
                        let e = usize::from(joint.ends[0] != Some(c));
                        blocks[c].g[(t, i)] = joint.read.chart[e][(row, i)];
                        blocks[c].e[(i, t)] = share * a;
                    }
                }
                joined = joined.max(size);
            }
            scale.max(size).max(joined)
        };
        let report = run.newton.solve(&mut run.unknowns, evaluate);
        let names = |column: usize| self.unknown_name(column, first);
        let report = report.map_err(|failure| match failure {
            // A component's block singular on its own: the junctions may determine what its
            // equations do not (a wire without energy), but the Schur complement needs it regular.
            NewtonFailure::Singular(pivot) if trial && pivot.column < first => {
                let unknowns: Vec<String> = pivot.involved.iter().map(|&c| names(c)).collect();
                DiracError::Unsupported(format!(
                    "the modular step: a component's own step equations are singular at the \
                     start (the unknowns {} are not determined by its equations alone); each \
                     component must determine its own step, given the junctions' impulses: step \
                     the interconnection monolithically",
                    unknowns.join(", ")
                ))
            }
            failure => failure.into_error(
                "the modular discrete Euler–Lagrange equations",
                run.steps,
                &self.options,
                &names,
            ),
        })?;
        let x = run.unknowns.as_slice();
        let advance = |component: &mut Component| {
            let range = component.offset..component.offset + component.part.unknowns();
            component.part.advance(&x[range], run.steps)
        };
        // Each component's violation, or the first component's error.
        let advanced: Result<f64, (usize, DiracError)> = if grain < self.components.len() {
            let components = self.components.par_iter_mut().with_min_len(grain);
            let each = components
                .enumerate()
                .map(|(c, component)| advance(component).map_err(|e| (c, e)));
            each.reduce(|| Ok(0.0), worse)
        } else {
            let each = self.components.iter_mut().enumerate();
            let mut each = each.map(|(c, component)| advance(component).map_err(|e| (c, e)));
            each.try_fold(0.0, |v, r| worse(Ok(v), r))
        };
        let violation = match advanced {
            Ok(violation) => violation,
            Err((c, error)) => {
                let name = self.components[c].name.clone();
                self.components.iter_mut().for_each(|c| c.part.discard());
                return Err(in_component(&name, error));
            }
        };
        if let Some(hidden) = &run.hidden {
            let t = (run.steps + 1) as f64 * self.h;
            if let Err(error) = hidden.project(&mut self.components, t, run.steps) {
                self.components.iter_mut().for_each(|c| c.part.discard());
                return Err(error);
            }
        }
        // The junctions' violation by the proposed steps (as moved by the projection).
        let steps = |parts: Parts<'_>, run: &mut [f64]| {
            parts.each(run, |component, _, own| {
                let coordinates = component.part.coordinates();
                for (i, moved) in own[..coordinates].iter_mut().enumerate() {
                    *moved = component.part.proposed_step(i);
                }
            });
        };
        let parts = Parts {
            components: &mut self.components,
            blocks: None,
        };
        in_runs(parts, &mut run.moved, grain, &steps, &|(), ()| ());
        let (moved, row_terms, row_starts) = (&run.moved, &run.row_terms, &run.row_starts);
        let junction = |k: usize| {
            let terms = &row_terms[row_starts[k]..row_starts[k + 1]];
            terms.iter().map(|&(u, a)| a * moved[u]).sum::<f64>().abs()
        };
        let junctions = self.junctions.len();
        let violations = if grain < junctions {
            let each = (0..junctions).into_par_iter().with_min_len(grain);
            each.map(junction).reduce(|| 0.0, |a, b| largest([a, b]))
        } else {
            largest((0..junctions).map(junction))
        };
        // The joints' `|g(q_{k+1})|`.
        let components = &self.components;
        let step = |c: usize| {
            let at = components[c].offset;
            &moved[at..at + components[c].part.coordinates()]
        };
        let mut joints: f64 = 0.0;
        for joint in &mut self.joints {
            joint_value(components, joint, |_| None, step);
            joints = largest(joint.read.values.iter().map(|g| g.abs()).chain([joints]));
        }
        Ok((report, largest([violation, violations, joints])))
    }

    /// The name of unknown `column` of a step (`first`: the junctions' first).
    fn unknown_name(&self, column: usize, first: usize) -> String {
        if let Some(junction) = self.junctions.iter().find(|j| first + j.rank == column) {
            let kind = if junction.joint.is_some() {
                "joint"
            } else {
                "junction"
            };
            return format!("the multiplier of {kind} {}", junction.name);
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
        self.on_workers(|modular| modular.advance())
    }

    /// Advances `steps` steps; stops at the first error, with the state of the step before it.
    pub fn run(&mut self, steps: u64) -> Result<(), DiracError> {
        self.on_workers(|modular| (0..steps).try_for_each(|_| modular.advance()))
    }

    /// Runs `work` on one of rayon's threads where the step is parallel, so that the passes of a
    /// step hand their halves to the other threads from inside the pool (from outside it, each
    /// pass would wait for a thread to wake and to wake the caller back).
    fn on_workers<F>(&mut self, work: F) -> Result<(), DiracError>
    where
        F: FnOnce(&mut Self) -> Result<(), DiracError> + Send,
    {
        if self.grain() < self.components.len() {
            rayon::scope(|_| work(self))
        } else {
            work(self)
        }
    }

    /// Advances one step (see [`Modular::step`]).
    fn advance(&mut self) -> Result<(), DiracError> {
        let mut run = self.run.take().ok_or(DiracError::NotStarted)?;
        let solved = self.solve(&mut run, false);
        let (report, violation) = match solved {
            Ok(solved) => solved,
            Err(error) => {
                self.run = Some(run);
                return Err(error);
            }
        };
        let t = (run.steps + 1) as f64 * self.h;
        let accept = |component: &mut Component| component.part.accept(t);
        let grain = self.grain();
        if grain < self.components.len() {
            let components = self.components.par_iter_mut().with_min_len(grain);
            components.for_each(accept);
        } else {
            self.components.iter_mut().for_each(accept);
        }
        let first = run.unknowns.len() - self.junctions.len();
        run.predictor.record(&run.unknowns);
        for (multiplier, junction) in run.multipliers.iter_mut().zip(&self.junctions) {
            *multiplier = run.unknowns[first + junction.rank];
        }
        run.steps += 1;
        run.violation = violation;
        run.report = Some(report);
        self.run = Some(run);
        self.refresh_joints();
        Ok(())
    }

    fn running(&self) -> Result<&Running, DiracError> {
        self.run.as_deref().ok_or(DiracError::NotStarted)
    }

    /// The time of the current state (0 before a start).
    pub fn t(&self) -> f64 {
        self.run
            .as_ref()
            .map_or(0.0, |run| run.steps as f64 * self.h)
    }

    /// The steps taken since the start.
    pub fn steps(&self) -> u64 {
        self.run.as_ref().map_or(0, |run| run.steps)
    }

    /// Every position number, in the order of [`position_names`](Self::position_names): on
    /// `Rⁿ` the coordinates' positions (zeros before a start; a rotation's identity).
    pub fn q(&self) -> DVector<f64> {
        let mut all = DVector::zeros(self.positions());
        for component in &self.components {
            let values = component.part.q();
            all.as_mut_slice()[component.position..component.position + values.len()]
                .copy_from_slice(&values);
        }
        all
    }

    /// Every coordinate's momentum, in the order of
    /// [`coordinate_names`](Self::coordinate_names) (on a rotation, the body angular
    /// momentum).
    pub fn p(&self) -> DVector<f64> {
        let mut all = DVector::zeros(self.coordinates());
        for component in &self.components {
            let values = component.part.p();
            all.as_mut_slice()[component.first..component.first + values.len()]
                .copy_from_slice(&values);
        }
        all
    }

    /// The junctions' multipliers of the last step: their impulses over it (zeros before the
    /// first step). With the midpoint's share `σ = ½` they can alternate step by step about
    /// the smooth impulses at the steps' nodes, `(μ_{k−1} + μ_k)/2`, by a mode the start leaves
    /// where the impulse changes fast (about 1 % of them on the shafted body; nothing visible on
    /// the LC circuits); the positions depend on the node impulses only, and each step's energy
    /// balance holds with its own `μ_k`.
    pub fn multipliers(&self) -> Result<&[f64], DiracError> {
        Ok(&self.running()?.multipliers)
    }

    /// The largest constraint violation of the last step: the components' own (as
    /// [`Stepper::constraint_violation`](crate::Stepper::constraint_violation)), the
    /// junctions' `|Σ_c a_j^c · ξ^c|` (`ξ^c` the component's step in its chart, `q_{k+1}^c −
    /// q_k^c` on `Rⁿ`) and the joints' `|g(q_{k+1})|`.
    pub fn constraint_violation(&self) -> Result<f64, DiracError> {
        Ok(self.running()?.violation)
    }

    /// How Newton's method went on the last step.
    pub fn report(&self) -> Option<NewtonReport> {
        self.run.as_ref().and_then(|run| run.report)
    }

    /// The velocity of every coordinate at the current state (in the order of
    /// [`coordinate_names`](Self::coordinate_names)): the Legendre transform inverted with the
    /// constraints, `∂L_c/∂v(q_c, v_c) = p_c + C_cᵀ ν_c + Σ_j ν_j a_j^c` for every component
    /// `c` (its own one-forms and holonomic differentials `C_c`), `C_c v_c = 0`, the
    /// junctions `Σ_c a_j^c · v_c = 0` and the velocity forms `dc(q) v = 0` of hidden
    /// constraints across the components (each with a multiplier, as a junction's, and each
    /// spanning every component it combines), solved by Newton's method from the last step's
    /// velocities (a joint's rows are its differential at the current positions). Its matrix
    /// is a band matrix with each junction's row beside the components
    /// it joins (a chain costs `O(K)`), factorised with partial pivoting, so components without
    /// kinetic energy, whose velocities only the junctions fix, need no block of their own.
    pub fn velocities(&self) -> Result<DVector<f64>, DiracError> {
        let run = self.running()?;
        // The hidden constraints' velocity forms join the junctions' rows.
        let rows = match &run.hidden {
            Some(hidden) => {
                let mut rows = self.junctions.clone();
                rows.extend(hidden.velocity_rows(&self.components, self.junctions.len())?);
                std::borrow::Cow::Owned(rows)
            }
            None => std::borrow::Cow::Borrowed(&self.junctions),
        };
        let layout = VelocityLayout::of(&self.components, &rows, self.junctions.len());
        let mut newton = Newton::with_jacobian(layout.band()?, self.options)?;
        let mut x = DVector::zeros(layout.size);
        for (component, &at) in self.components.iter().zip(&layout.components) {
            let guess = component.part.velocity_hint();
            x.as_mut_slice()[at..at + guess.len()].copy_from_slice(&guess);
        }
        let (components, junctions) = (&self.components, &rows[..]);
        let solved = newton.solve(&mut x, |x, r, band| {
            layout.assemble(components, junctions, x.as_slice(), r.as_mut_slice(), band)
        });
        let names = |column: usize| layout.unknown_name(components, junctions, column);
        solved.map_err(|failure| {
            failure.into_error(
                "the modular velocity solve",
                run.steps,
                &self.options,
                &names,
            )
        })?;
        let mut v = DVector::zeros(self.total);
        for (component, &at) in self.components.iter().zip(&layout.components) {
            let n = component.part.coordinates();
            v.as_mut_slice()[component.first..component.first + n]
                .copy_from_slice(&x.as_slice()[at..at + n]);
        }
        Ok(v)
    }

    /// Each component's energy `E_c = ⟨∂L_c/∂v, v_c⟩ − L_c` at the current state, with the
    /// [`velocities`](Self::velocities). On `Rⁿ`, with the midpoint rule, quadratic Lagrangians
    /// and the constraint point `Midpoint`, `E_c(k+1) − E_c(k)` equals the component's port work
    /// over the step ([`ports`](Self::ports)) to round-off (on rotations it does not: the
    /// energy's error is of second order).
    pub fn energies(&self) -> Result<Vec<f64>, DiracError> {
        let v = self.velocities()?;
        Ok(self
            .components
            .iter()
            .map(|c| {
                let n = c.part.coordinates();
                c.part.energy(&v.as_slice()[c.first..c.first + n])
            })
            .collect())
    }

    /// Each component's energy balance since the start (see [`Ledger`]): its stored energy,
    /// the work of its own forces and inputs, and the work through its ports, summed over the
    /// steps. `NotStarted` before a start; `Unsupported` where a component's steps do not
    /// report their work.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Junction, Modular, Quadrature, Scalar};
    /// use nalgebra::SVector;
    /// /// A capacitor, L = −q²/2.
    /// struct Capacitor;
    /// impl DiracSystem<1> for Capacitor {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, _v: &SVector<D, 1>) -> D {
    ///         -q[0] * q[0] * 0.5
    ///     }
    ///     fn coordinate_name(&self, _i: usize) -> String { "q".into() }
    /// }
    /// /// An inductor with a series resistance 0.2: L = q̇²/2, F = −0.2 q̇ dq.
    /// struct Coil;
    /// impl DiracSystem<1> for Coil {
    ///     const FORCES: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>, _t: f64, _u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([v[0] * -0.2])
    ///     }
    ///     fn coordinate_name(&self, _i: usize) -> String { "q".into() }
    /// }
    /// let mut circuit = Modular::new(Quadrature::midpoint(), 0.01)?;
    /// circuit.add("c", Capacitor)?;
    /// circuit.add("coil", Coil)?;
    /// circuit.join(Junction::new("kcl").flow("c.q", 1.0).flow("coil.q", 1.0))?;
    /// circuit.start_from_velocity(&[1.0, -1.0], &[0.0, 0.0])?;
    /// circuit.run(1000)?;
    /// let ledger = circuit.ledger()?;
    /// assert!(ledger.components[1].forces < -0.2); // the resistance took most of the 0.5
    /// assert!(ledger.max_defect() < 1e-14 && ledger.net_port_work().abs() < 1e-14);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn ledger(&self) -> Result<Ledger, DiracError> {
        let run = self.running()?;
        let energies = self.energies()?;
        let components = self
            .components
            .iter()
            .zip(run.initial.iter().zip(energies))
            .map(|(c, (&initial, energy))| {
                let unknown = || {
                    DiracError::Unsupported(format!(
                        "the work of component {}: its steps do not report it",
                        c.name
                    ))
                };
                let (forces, ports) = c.part.work().ok_or_else(unknown)?;
                Ok(ComponentBalance {
                    name: c.name.clone(),
                    initial,
                    energy,
                    forces,
                    ports: ports.ok_or_else(unknown)?,
                })
            })
            .collect::<Result<Vec<_>, DiracError>>()?;
        Ok(Ledger { components })
    }

    /// The junctions' efforts and each component's port work over the last step (see
    /// [`PortWork`]); `NotStarted` before a start and zeros before the first step.
    pub fn ports(&self) -> Result<PortWork, DiracError> {
        let run = self.running()?;
        if !self.joints.is_empty() {
            return Err(DiracError::Unsupported(
                "the port work of an interconnection with joints (their rows' coefficients \
                 change over a step; the ledger gives each component's balance)"
                    .into(),
            ));
        }
        let efforts: Vec<f64> = run.multipliers.iter().map(|mu| mu / self.h).collect();
        let mut work = vec![0.0; self.components.len()];
        let mut scale: f64 = 0.0;
        for (junction, effort) in self.junctions.iter().zip(&efforts) {
            for &(c, i, a) in &junction.terms {
                let term = effort * a * self.components[c].part.last_step(i);
                work[c] += term;
                scale += term.abs();
            }
        }
        Ok(PortWork {
            efforts,
            work,
            scale,
        })
    }
}

/// A joint's rows at the point each end's chart reaches with `xi(c)` from the positions `q(c)`
/// (the current ones where `None`), into its `read`; the size of their terms.
fn joint_value<'q>(
    components: &[Component],
    rows: &mut JointRows,
    q: impl Fn(usize) -> Option<&'q [f64]>,
    xi: impl Fn(usize) -> &'q [f64],
) -> f64 {
    let read = &mut rows.read;
    for (e, end) in rows.ends.iter().enumerate() {
        if let Some(c) = *end {
            let (positions, derivatives) = (&mut read.positions[e], &mut read.derivatives[e]);
            components[c]
                .part
                .chart_positions(q(c), xi(c), positions, derivatives);
        }
    }
    let positions = (&read.positions[0][..], &read.positions[1][..]);
    read.chart.iter_mut().for_each(|c| c.fill(0.0));
    let (chart, derivatives) = (&mut read.chart, &read.derivatives);
    // ∂g/∂ξ = ∂g/∂q · ∂q/∂ξ, a position's term at a time.
    let add = |row: usize, end: usize, position: usize, a: f64| {
        let d = &derivatives[end];
        for i in 0..d.ncols() {
            chart[end][(row, i)] += a * d[(position, i)];
        }
    };
    rows.joint
        .evaluate(positions, &rows.at, &mut read.values, add)
}

/// The joints' rows read at the positions `q` (every component's, in the order of
/// [`Modular::position_names`]; the current ones where `None`) into their junctions'
/// coefficients: the rows' differentials in the charts there. `Err(InconsistentInitialState)`
/// where given positions violate a joint by more than `tolerance` times its terms' size.
fn read_joints(
    components: &[Component],
    joints: &mut [JointRows],
    junctions: &mut [Coupling],
    q: Option<&[f64]>,
    tolerance: f64,
) -> Result<(), DiracError> {
    // The charts' origin, without an allocation for components of up to 64 coordinates.
    const ORIGIN: [f64; 64] = [0.0; 64];
    let largest = components.iter().map(|c| c.part.coordinates()).max();
    let many;
    let zeros: &[f64] = match largest.unwrap_or(0) {
        n if n <= ORIGIN.len() => &ORIGIN,
        n => {
            many = vec![0.0; n];
            &many
        }
    };
    for rows in joints {
        let own = |c: usize| {
            let at = components[c].position;
            q.map(|q| &q[at..at + components[c].part.positions()])
        };
        let origin = |c: usize| &zeros[..components[c].part.coordinates()];
        let size = joint_value(components, rows, own, origin);
        if q.is_some()
            && let Some(row) = (0..rows.joint.rows())
                .find(|&row| exceeds(rows.read.values[row].abs(), tolerance * size))
        {
            return Err(DiracError::InconsistentInitialState(format!(
                "the initial positions violate joint {}: g = {:.3e}",
                rows.joint.row_name(row),
                rows.read.values[row]
            )));
        }
        for row in 0..rows.joint.rows() {
            for term in &mut junctions[rows.first + row].terms {
                let e = usize::from(rows.ends[0] != Some(term.0));
                term.2 = rows.read.chart[e][(row, term.1)];
            }
        }
    }
    Ok(())
}

/// `Σ t` over `terms` and the size of what it sums, `Σ |t|` (a residual row and its scale).
fn sum_and_size(terms: impl Iterator<Item = f64>) -> (f64, f64) {
    terms.fold((0.0, 0.0), |(sum, size), t| (sum + t, size + t.abs()))
}

/// The larger of two violations (NaN wins), or the error of the first component of two that
/// failed.
fn worse(
    a: Result<f64, (usize, DiracError)>,
    b: Result<f64, (usize, DiracError)>,
) -> Result<f64, (usize, DiracError)> {
    match (a, b) {
        (Ok(a), Ok(b)) => Ok(largest([a, b])),
        (Err(a), Err(b)) => Err(if a.0 <= b.0 { a } else { b }),
        (Err(e), _) | (_, Err(e)) => Err(e),
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

/// Components, with their Jacobian blocks where they are assembled, each owning its unknowns'
/// run of a step's vectors.
struct Parts<'a> {
    components: &'a mut [Component],
    blocks: Option<&'a mut [BlockMatrix]>,
}

impl Runs for Parts<'_> {
    fn count(&self) -> usize {
        self.components.len()
    }

    fn start(&self, i: usize) -> usize {
        self.components[i].offset
    }

    fn halve(self, mid: usize) -> (Self, Self) {
        let (left, right) = self.components.split_at_mut(mid);
        let (first, second) = match self.blocks {
            Some(blocks) => {
                let (first, second) = blocks.split_at_mut(mid);
                (Some(first), Some(second))
            }
            None => (None, None),
        };
        let left = Self {
            components: left,
            blocks: first,
        };
        let right = Self {
            components: right,
            blocks: second,
        };
        (left, right)
    }
}

impl Parts<'_> {
    /// `f(component, its block, its unknowns' run of run)` for each component, `run` beginning
    /// at the first one's unknowns.
    fn each(
        self,
        run: &mut [f64],
        mut f: impl FnMut(&mut Component, Option<&mut DMatrix<f64>>, &mut [f64]),
    ) {
        let Some(start) = self.components.first().map(|c| c.offset) else {
            return;
        };
        let mut blocks = self.blocks.map(|b| b.iter_mut());
        for component in self.components {
            let at = component.offset - start;
            let own = &mut run[at..at + component.part.unknowns()];
            let block = blocks.as_mut().and_then(|b| b.next());
            f(component, block.map(|b| &mut b.own), own);
        }
    }
}

/// Where the velocity solve's unknowns sit: each component's velocities then its own
/// multipliers, and each junction's multiplier right after the last component it touches, so
/// that along a chain the matrix is a band.
struct VelocityLayout {
    /// The first unknown of each component.
    components: Vec<usize>,
    /// The unknown (and row) of each junction.
    junctions: Vec<usize>,
    /// The number of junctions proper (rows after them are hidden constraints').
    joined: usize,
    size: usize,
    lower: usize,
    upper: usize,
}

impl VelocityLayout {
    /// The layout of `junctions`, of which the first `joined` are junctions proper.
    fn of(components: &[Component], junctions: &[Coupling], joined: usize) -> Self {
        let mut last = vec![Vec::new(); components.len()];
        for (j, junction) in junctions.iter().enumerate() {
            let c = junction
                .terms
                .iter()
                .map(|t| t.0)
                .max()
                .expect("a junction has terms");
            last[c].push(j);
        }
        // Beside each component, its junctions in the order of their multipliers.
        last.iter_mut()
            .for_each(|theirs| theirs.sort_by_key(|&j| junctions[j].rank));
        let (mut at, mut starts, mut places) = (0, Vec::new(), vec![0; junctions.len()]);
        for (component, theirs) in components.iter().zip(&last) {
            starts.push(at);
            at += component.part.coordinates() + component.part.constraints();
            for &j in theirs {
                places[j] = at;
                at += 1;
            }
        }
        let mut layout = Self {
            components: starts,
            junctions: places,
            joined,
            size: at,
            lower: 0,
            upper: 0,
        };
        // The band: each component's own block, and each junction's row and column.
        for component in components {
            let width = component.part.coordinates() + component.part.constraints();
            layout.lower = layout.lower.max(width.saturating_sub(1));
            layout.upper = layout.upper.max(width.saturating_sub(1));
        }
        for (j, junction) in junctions.iter().enumerate() {
            for &(c, i, _) in &junction.terms {
                let spread = layout.junctions[j].abs_diff(layout.components[c] + i);
                layout.lower = layout.lower.max(spread);
                layout.upper = layout.upper.max(spread);
            }
        }
        layout
    }

    fn band(&self) -> Result<Banded, DiracError> {
        Banded::within_memory(self.size, self.lower, self.upper, "the velocity solve")
    }

    /// The residual at `x` into `r` and, when asked, the Jacobian into `band`; the size of the
    /// residual's terms.
    fn assemble(
        &self,
        components: &[Component],
        junctions: &[Coupling],
        x: &[f64],
        r: &mut [f64],
        mut band: Option<&mut Banded>,
    ) -> f64 {
        let mut scale: f64 = 0.0;
        for (component, &at) in components.iter().zip(&self.components) {
            let (n, m) = (component.part.coordinates(), component.part.constraints());
            let rows = component.part.legendre(&x[at..at + n]);
            let p = component.part.p();
            for i in 0..n {
                r[at + i] = rows.momentum[i] - p[i];
                scale = scale.max(p[i].abs()).max(rows.momentum[i].abs());
                for (a, nu) in x[at + n..at + n + m].iter().enumerate() {
                    r[at + i] -= rows.forms[(a, i)] * nu;
                }
            }
            for a in 0..m {
                let terms = (0..n).map(|k| rows.forms[(a, k)] * x[at + k]);
                let (row, size) = sum_and_size(terms);
                r[at + n + a] = row;
                scale = scale.max(size);
            }
            if let Some(band) = band.as_deref_mut() {
                for i in 0..n {
                    for k in 0..n {
                        band.add(at + i, at + k, rows.hessian[(i, k)]);
                    }
                    for a in 0..m {
                        band.add(at + i, at + n + a, -rows.forms[(a, i)]);
                        band.add(at + n + a, at + i, rows.forms[(a, i)]);
                    }
                }
            }
        }
        for (junction, &row) in junctions.iter().zip(&self.junctions) {
            let (mut value, mut size) = (0.0, 0.0);
            for &(c, i, a) in &junction.terms {
                let column = self.components[c] + i;
                r[column] -= a * x[row];
                value += a * x[column];
                size += (a * x[column]).abs();
                if let Some(band) = band.as_deref_mut() {
                    band.add(column, row, -a);
                    band.add(row, column, a);
                }
            }
            r[row] = value;
            scale = scale.max(size);
        }
        scale
    }

    /// The name of unknown `column`.
    fn unknown_name(
        &self,
        components: &[Component],
        junctions: &[Coupling],
        column: usize,
    ) -> String {
        if let Some(j) = self.junctions.iter().position(|&at| at == column) {
            // The rows after the junctions are hidden constraints' (`Hidden::velocity_rows`).
            let name = &junctions[j].name;
            return if j < self.joined {
                format!("the multiplier of junction {name}")
            } else {
                format!("the multiplier of {name}")
            };
        }
        let c = self.components.partition_point(|&at| at <= column) - 1;
        let (component, i) = (&components[c], column - self.components[c]);
        if i < component.part.coordinates() {
            format!(
                "{}.{} (velocity)",
                component.name,
                component.part.coordinate_name(i)
            )
        } else {
            format!(
                "{}: the multiplier of its constraint {}",
                component.name,
                i - component.part.coordinates()
            )
        }
    }
}
