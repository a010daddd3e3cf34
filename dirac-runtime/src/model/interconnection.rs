//! Interconnection: two models written separately, joined through ports into one model.
//!
//! Two Lagrange–Dirac systems `(Q₁, L₁, Δ₁)` and `(Q₂, L₂, Δ₂)` interconnect to the system on
//! `Q₁ × Q₂` with
//!
//! ```text
//! L(q₁, q₂, v₁, v₂) = L₁(q₁, v₁) + L₂(q₂, v₂),      Δ = (Δ₁ × Δ₂) ∩ Δ_int,
//! ```
//!
//! where `Δ_int` is cut out by the *junctions*: constant one-forms `Σ_i c_i dq_i` over both
//! models' coordinates (Kirchhoff's current law at a node, a shared velocity at a joint, a port
//! equating two flows). Forces, inputs and holonomic constraints are the components' own. The
//! result is a [`DiracSystem`] like any other: it steps with every quadrature, and it can itself
//! be a component of a larger interconnection (a hierarchy).
//!
//! **Ports.** On a step the junction `j` carries the impulse `μ_j` (its multiplier, a
//! [`Stepper::multipliers`](crate::Stepper::multipliers) entry); its effort is `e_j = μ_j / h`.
//! The work done on component `A` over the step is `W_A = Σ_j e_j ⟨c_j^A, q_{k+1}^A − q_k^A⟩`
//! (its rows' part on `A`'s coordinates), and likewise for `B`. Since the step holds every
//! junction, `Σ_j c_j (q_{k+1} − q_k) = 0`, Tellegen's theorem holds step by step:
//! `W_A + W_B = Σ_j e_j c_j (q_{k+1} − q_k) = 0`. With the midpoint rule at the constraint
//! point `Midpoint` (the impulse split `σ = ½`) and components whose Lagrangians are quadratic
//! and who have no holonomic constraints, each component's energy then changes over the step by
//! exactly its port work plus its own forces' work: `E_A(k+1) − E_A(k) = W_A` for a
//! conservative component (`tests/suite/interconnection.rs` checks both to round-off). For a
//! nonlinear component the balance holds to the method's order.
//!
//! ```
//! use dirac_runtime::interconnection::{Interconnection, Junction};
//! use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
//! use nalgebra::{SVector, vector};
//!
//! /// A mass on a spring to the ground, L = ½ m ẋ² − ½ k x².
//! struct MassSpring { m: f64, k: f64 }
//! impl DiracSystem<1> for MassSpring {
//!     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
//!         v[0] * v[0] * (0.5 * self.m) - q[0] * q[0] * (0.5 * self.k)
//!     }
//!     fn coordinate_name(&self, _i: usize) -> String { "x".into() }
//! }
//!
//! // Two masses glued together: one mass 2 on springs 1 + 1, ω = 1.
//! let glued = Interconnection::new(
//!     ("left", MassSpring { m: 1.0, k: 1.0 }),
//!     ("right", MassSpring { m: 1.0, k: 1.0 }),
//!     [Junction::new("glue").flow("left.x", 1.0).flow("right.x", -1.0)],
//! )?;
//! let mut stepper = Stepper::new(glued, Quadrature::galerkin(2)?, 0.1)?;
//! stepper.start_from_velocity(vector![1.0, 1.0], vector![0.0, 0.0])?;
//! stepper.run(10)?;
//! assert!((stepper.q()[0] - 1.0_f64.cos()).abs() < 1e-6); // x(1) = cos 1, order 4
//! assert!((stepper.q()[0] - stepper.q()[1]).abs() < 1e-14);
//! # Ok::<(), dirac_runtime::DiracError>(())
//! ```
//!
//! The coordinates are `A`'s then `B`'s, named `instance.coordinate`; the one-forms are `A`'s,
//! then `B`'s, then the junctions; the holonomic constraints and the inputs are `A`'s then
//! `B`'s. The number of coordinates `N` must be `NA + NB` (checked when the program is
//! compiled); it and the number of junctions `C` are usually inferred from the state vectors
//! and the junction array.

use nalgebra::SVector;

use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::base::scalar::Scalar;
use crate::model::closed_form::{LagrangianGradient, LagrangianHessian};
use crate::model::slot::Slot;
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;

/// One interconnection constraint: the one-form `Σ_i c_i dq_i` over the instances' coordinates,
/// named as `instance.coordinate`, held at zero (`Σ_i c_i q̇_i = 0`).
///
/// ```
/// use dirac_runtime::interconnection::Junction;
/// // Kirchhoff's current law at a node: what flows in through C2 leaves through C1 and C3.
/// let kcl = Junction::new("kcl")
///     .flow("loop.q_c2", 1.0)
///     .flow("parallel.q_c1", -1.0)
///     .flow("parallel.q_c3", -1.0);
/// assert_eq!(kcl.name(), "kcl");
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Junction {
    name: String,
    terms: Vec<(String, f64)>,
}

impl Junction {
    /// A junction named `name` with no terms yet.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            terms: Vec::new(),
        }
    }

    /// Adds the term `coefficient · dq` of the coordinate named `coordinate`
    /// (`instance.coordinate`).
    pub fn flow(mut self, coordinate: impl Into<String>, coefficient: f64) -> Self {
        self.terms.push((coordinate.into(), coefficient));
        self
    }

    /// The junction's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The junction's terms as `(coordinate, coefficient)`, each coordinate's index found by
    /// `index`: an `Err(InvalidInterconnection)` for no terms, a coordinate `index` does not
    /// know (the message adds what `known` says of it), a zero or non-finite coefficient, and
    /// a coordinate named twice.
    pub(crate) fn resolve_terms(
        &self,
        index: impl Fn(&str) -> Option<usize>,
        known: impl Fn(&str) -> String,
    ) -> Result<Vec<(usize, f64)>, DiracError> {
        let invalid = |why: String| Err(DiracError::InvalidInterconnection(why));
        if self.terms.is_empty() {
            return invalid(format!("junction {:?} has no terms", self.name));
        }
        let mut resolved: Vec<(usize, f64)> = Vec::with_capacity(self.terms.len());
        for (coordinate, coefficient) in &self.terms {
            let Some(i) = index(coordinate) else {
                return invalid(format!(
                    "junction {:?} names {coordinate:?}, which is not a coordinate of the \
                     interconnection ({})",
                    self.name,
                    known(coordinate)
                ));
            };
            if !coefficient.is_finite() || *coefficient == 0.0 {
                return invalid(format!(
                    "junction {:?} gives {coordinate} the coefficient {coefficient}: it must be \
                     finite and nonzero",
                    self.name
                ));
            }
            if resolved.iter().any(|&(k, _)| k == i) {
                return invalid(format!("junction {:?} names {coordinate} twice", self.name));
            }
            resolved.push((i, *coefficient));
        }
        Ok(resolved)
    }
}

/// The model made of the component `A` (on `R^NA`) and the component `B` (on `R^NB`) joined by
/// `C` [`Junction`]s: a [`DiracSystem`] on `R^N`, `N = NA + NB` (see the
/// [module](self) documentation for the mathematics and an example).
#[derive(Debug, Clone)]
pub struct Interconnection<A, B, const NA: usize, const NB: usize, const N: usize, const C: usize> {
    instances: [String; 2],
    a: A,
    b: B,
    junctions: Junctions<N, C>,
}

/// What crossed the `C` junctions of a model made of `K` components over one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ports<const C: usize, const K: usize = 2> {
    /// The effort of each junction, `e_j = μ_j / h` (the constraint force along its one-form).
    pub efforts: [f64; C],
    /// The work done through the ports on each component over the step (for an
    /// [`Interconnection`], on `A` and on `B`).
    pub work: [f64; K],
    /// The size of the terms summed into the work, each an effort times a flow read from
    /// positions (`|e_j c_ji| max(|q_k,i|, |q_{k+1},i|)`): the work's round-off floor is a few
    /// ulps of this.
    pub scale: f64,
}

impl<const C: usize, const K: usize> Ports<C, K> {
    /// The net work through all ports over the step, `Σ W_c`: zero by Tellegen's theorem (to
    /// round-off of [`scale`](Self::scale) when the junctions hold).
    pub fn net_work(&self) -> f64 {
        self.work.iter().sum()
    }
}

/// A model on `R^N` made of `K` components joined by `C` junctions ([`Interconnection`],
/// [`Repeated`](crate::model::repeated::Repeated)): each component's energy, and what crossed the
/// ports over a step.
pub trait Interconnected<const N: usize, const K: usize, const C: usize>: DiracSystem<N> {
    /// The junctions.
    fn junctions(&self) -> &Junctions<N, C>;

    /// Each component's energy `E = ⟨∂L/∂v, v⟩ − L` at position `q` with velocity `v` (the
    /// state's exact velocity is [`Stepper::v`](crate::Stepper::v)).
    fn energies(&self, q: &SVector<f64, N>, v: &SVector<f64, N>) -> [f64; K];

    /// The component of coordinate `i`.
    fn component_of(&self, i: usize) -> usize;

    /// The name of component `c` (`0 <= c < K`), for reports: its instance's name.
    fn component_name(&self, c: usize) -> String {
        format!("component {c}")
    }

    /// What crossed the ports over the step of size `h` from `q_k` to `q_{k+1}` whose
    /// multipliers are `multipliers` ([`Stepper::multipliers`](crate::Stepper::multipliers) after
    /// the step): the efforts and each component's port work. An `Err(Unsupported)` for a
    /// quadrature that holds the one-forms at several nodes of a step (the Galerkin rules).
    fn ports(
        &self,
        q_k: &SVector<f64, N>,
        q_next: &SVector<f64, N>,
        multipliers: &[f64],
        h: f64,
    ) -> Result<Ports<C, K>, DiracError> {
        let junctions = self.junctions();
        let impulses = junctions.multipliers(multipliers, Self::ONE_FORMS, Self::HOLONOMIC)?;
        junctions.ports(q_k, q_next, impulses, h, |i| self.component_of(i))
    }
}

/// `C` junctions resolved against the coordinates of a model on `R^N`: their names and their
/// rows (covectors), checked (see [`Interconnection::new`] for what is refused).
#[derive(Debug, Clone)]
pub struct Junctions<const N: usize, const C: usize> {
    names: [String; C],
    rows: [SVector<f64, N>; C],
}

impl<const N: usize, const C: usize> Junctions<N, C> {
    /// Resolves `junctions` over the coordinates named `coordinates` (`instance.coordinate`,
    /// `N` of them) of the instances named `instances`.
    pub fn resolve(
        junctions: [Junction; C],
        instances: &[String],
        coordinates: &[String],
    ) -> Result<Self, DiracError> {
        let invalid = |why: String| Err(DiracError::InvalidInterconnection(why));
        for (k, name) in instances.iter().enumerate() {
            if name.is_empty() || name.contains('.') {
                return invalid(format!(
                    "the instance name {name:?} must be non-empty and without '.'"
                ));
            }
            if instances[..k].contains(name) {
                return invalid(format!("two instances are named {name:?}: name them apart"));
            }
        }
        if let Some((k, name)) = coordinates
            .iter()
            .enumerate()
            .find(|(k, name)| coordinates[..*k].contains(name))
        {
            let first = coordinates[..k].iter().position(|n| n == name).unwrap_or(k);
            return invalid(format!(
                "coordinates {first} and {k} are both named {name:?}: a junction could not tell \
                 them apart (name a component's coordinates apart)"
            ));
        }
        let mut rows = [SVector::<f64, N>::zeros(); C];
        for (j, junction) in junctions.iter().enumerate() {
            if junctions[..j]
                .iter()
                .any(|other| other.name == junction.name)
            {
                return invalid(format!("two junctions are named {:?}", junction.name));
            }
            let known = |coordinate: &str| {
                let instance = coordinate.split('.').next().unwrap_or_default();
                if instances.iter().any(|n| n == instance) {
                    let prefix = format!("{instance}.");
                    let theirs: Vec<&str> = coordinates
                        .iter()
                        .filter(|n| n.starts_with(&prefix))
                        .map(String::as_str)
                        .collect();
                    format!("{instance} has {}", theirs.join(", "))
                } else {
                    format!("the instances are {}", instances.join(", "))
                }
            };
            let index = |coordinate: &str| coordinates.iter().position(|n| n == coordinate);
            for (i, coefficient) in junction.resolve_terms(index, known)? {
                rows[j][i] = coefficient;
            }
        }
        let names: [String; C] = std::array::from_fn(|j| junctions[j].name.clone());
        if let Some((dependent, on)) = dependent_row(&rows) {
            let on: Vec<&str> = on.iter().map(|&j| names[j].as_str()).collect();
            return invalid(format!(
                "junction {:?} is a combination of {}: the junctions over-determine the \
                 system (drop one)",
                names[dependent],
                if on.is_empty() {
                    "none (it is zero)".to_string()
                } else {
                    on.join(", ")
                }
            ));
        }
        Ok(Self { names, rows })
    }

    /// Junctions given as `(junction, coordinate index, coefficient)` terms, already checked
    /// (`#[dirac_system(subsystems(...))]` checks them when the program compiles).
    pub fn from_terms(names: [String; C], terms: &[(usize, usize, f64)]) -> Self {
        let mut rows = [SVector::<f64, N>::zeros(); C];
        for &(j, i, coefficient) in terms {
            rows[j][i] = coefficient;
        }
        Self { names, rows }
    }

    /// The junctions' names, in the order of their multipliers.
    pub fn names(&self) -> &[String; C] {
        &self.names
    }

    /// `junction name` for junction `j`, for error messages.
    pub fn name(&self, j: usize) -> String {
        match self.names.get(j) {
            Some(name) => format!("junction {name}"),
            None => format!("junction {j}"),
        }
    }

    /// Junction `j` as a covector on `R^N` (its coefficients).
    pub fn row(&self, j: usize) -> &SVector<f64, N> {
        &self.rows[j]
    }

    /// The junctions' multipliers among a stepper's `multipliers` of a model with `one_forms`
    /// one-forms (the junctions last) and `holonomic` holonomic constraints: an `Err` for a
    /// quadrature that holds the one-forms at several nodes of a step (the Galerkin rules),
    /// whose multipliers are one per node.
    pub fn multipliers<'m>(
        &self,
        multipliers: &'m [f64],
        one_forms: usize,
        holonomic: usize,
    ) -> Result<&'m [f64; C], DiracError> {
        if multipliers.len() != one_forms + holonomic || one_forms < C {
            return Err(DiracError::Unsupported(format!(
                "port readings from {} multipliers: the interconnection has {one_forms} \
                 one-forms and {holonomic} holonomic constraints, held once per step by degree-1 \
                 quadratures (midpoint, trapezoid) only",
                multipliers.len(),
            )));
        }
        multipliers[one_forms - C..one_forms]
            .try_into()
            .map_err(|_| DiracError::Dimension("junction multipliers".into()))
    }

    /// What crossed the junctions over the step of size `h` from `q_k` to `q_{k+1}` with the
    /// junctions' `impulses`, the work summed per component, `part(i)` the component of
    /// coordinate `i` (below `K`); an `Err(InvalidStep)` for `h` not positive and finite.
    pub fn ports<const K: usize>(
        &self,
        q_k: &SVector<f64, N>,
        q_next: &SVector<f64, N>,
        impulses: &[f64; C],
        h: f64,
        part: impl Fn(usize) -> usize,
    ) -> Result<Ports<C, K>, DiracError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(DiracError::InvalidStep { h });
        }
        let step = q_next - q_k;
        let mut work = [0.0; K];
        let mut scale: f64 = 0.0;
        for (row, &impulse) in self.rows.iter().zip(impulses) {
            for i in (0..N).filter(|&i| row[i] != 0.0) {
                let force = impulse / h * row[i];
                work[part(i)] += force * step[i];
                // A flow is a difference of positions: its round-off is that of the positions.
                let size = step[i].abs().max(q_k[i].abs()).max(q_next[i].abs());
                scale = scale.max((force * size).abs());
            }
        }
        Ok(Ports {
            efforts: impulses.map(|impulse| impulse / h),
            work,
            scale,
        })
    }

    /// Junction `j` over the scalar `D` (zero for `j >= C`).
    pub fn one_form<D: Scalar>(&self, j: usize) -> SVector<D, N> {
        match self.rows.get(j) {
            Some(row) => row.map(D::from),
            None => SVector::from_element(D::from(0.0)),
        }
    }
}

impl<A, B, const NA: usize, const NB: usize, const N: usize, const C: usize>
    Interconnection<A, B, NA, NB, N, C>
where
    A: DiracSystem<NA>,
    B: DiracSystem<NB>,
{
    /// Joins the named instances `a` and `b` by `junctions`.
    ///
    /// An `Err(InvalidInterconnection)` says what is wrong, naming the junctions involved:
    /// instance names empty, equal or containing a `.`; a term naming an unknown instance or
    /// coordinate (the message lists the coordinates there are), naming a coordinate twice, or
    /// with a coefficient zero or not finite; a junction without terms or with another's name;
    /// junctions that depend on each other (one is a combination of others: the system would be
    /// over-determined and its multipliers not unique); components that hold their one-forms
    /// at different [`ConstraintPoint`]s.
    pub fn new(a: (&str, A), b: (&str, B), junctions: [Junction; C]) -> Result<Self, DiracError> {
        const {
            assert!(
                N == NA + NB,
                "an interconnection of models on R^NA and R^NB is on R^(NA + NB)"
            )
        };
        let instances = [a.0.to_string(), b.0.to_string()];
        let (a, b) = (a.1, b.1);
        if A::ONE_FORMS > 0 && B::ONE_FORMS > 0 && a.constraint_point() != b.constraint_point() {
            return Err(DiracError::InvalidInterconnection(format!(
                "{} holds its one-forms at {:?} and {} at {:?}: the interconnection needs one \
                 constraint point",
                instances[0],
                a.constraint_point(),
                instances[1],
                b.constraint_point()
            )));
        }
        let coordinates: Vec<String> = (0..N)
            .map(|i| {
                Self::A
                    .coordinate_name(&a, &instances[0], i)
                    .or_else(|| Self::B.coordinate_name(&b, &instances[1], i))
                    .unwrap_or_default()
            })
            .collect();
        let junctions = Junctions::resolve(junctions, &instances, &coordinates)?;
        Ok(Self {
            instances,
            a,
            b,
            junctions,
        })
    }

    /// The component `A`.
    pub fn a(&self) -> &A {
        &self.a
    }

    /// The component `B`.
    pub fn b(&self) -> &B {
        &self.b
    }

    /// The instances' names, `A`'s then `B`'s.
    pub fn instances(&self) -> &[String; 2] {
        &self.instances
    }

    /// Splits a vector of the interconnection (a position, velocity or momentum) into `A`'s
    /// part and `B`'s part.
    pub fn split<D: Scalar>(&self, x: &SVector<D, N>) -> (SVector<D, NA>, SVector<D, NB>) {
        (Self::A.part(x), Self::B.part(x))
    }
}

impl<A, B, const NA: usize, const NB: usize, const N: usize, const C: usize> Interconnected<N, 2, C>
    for Interconnection<A, B, NA, NB, N, C>
where
    A: DiracSystem<NA>,
    B: DiracSystem<NB>,
{
    fn junctions(&self) -> &Junctions<N, C> {
        &self.junctions
    }

    fn energies(&self, q: &SVector<f64, N>, v: &SVector<f64, N>) -> [f64; 2] {
        [Self::A.energy(&self.a, q, v), Self::B.energy(&self.b, q, v)]
    }

    fn component_of(&self, i: usize) -> usize {
        usize::from(i >= NA)
    }

    fn component_name(&self, c: usize) -> String {
        self.instances
            .get(c)
            .cloned()
            .unwrap_or_else(|| format!("component {c}"))
    }
}

/// The first row of `rows` that is a combination of the rows before it, with the rows it
/// combines: `None` when they are independent. Gram–Schmidt with a second pass on the rows
/// scaled to a largest entry of 1 (so that no coefficient overflows or underflows), each basis
/// vector carrying its expression in the rows; a row whose remainder is below 1e-10 of its
/// norm is dependent, on the rows of weight above 1e-9 of the largest in that remainder.
pub(crate) fn dependent_row<const N: usize>(
    rows: &[SVector<f64, N>],
) -> Option<(usize, Vec<usize>)> {
    let mut basis: Vec<(SVector<f64, N>, Vec<f64>)> = Vec::new();
    for (j, row) in rows.iter().enumerate() {
        let scaled = row / row.amax();
        let mut rest = scaled;
        let mut expression = vec![0.0; rows.len()];
        expression[j] = 1.0;
        for _ in 0..2 {
            for (e, combination) in &basis {
                let c = e.dot(&rest);
                rest -= e * c;
                expression
                    .iter_mut()
                    .zip(combination)
                    .for_each(|(x, y)| *x -= c * y);
            }
        }
        let norm = rest.norm();
        if norm <= 1e-10 * scaled.norm() {
            let largest = expression[..j].iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let on = (0..j)
                .filter(|&k| expression[k].abs() > 1e-9 * largest)
                .collect();
            return Some((j, on));
        }
        expression.iter_mut().for_each(|x| *x /= norm);
        basis.push((rest / norm, expression));
    }
    None
}

impl<A, B, const NA: usize, const NB: usize, const N: usize, const C: usize>
    Interconnection<A, B, NA, NB, N, C>
where
    A: DiracSystem<NA>,
    B: DiracSystem<NB>,
{
    /// `A`'s place among the interconnection's coordinates, one-forms, constraints, inputs.
    const A: Slot = Slot::FIRST;
    /// `B`'s place.
    const B: Slot = Slot::FIRST.after::<A, NA>();
}

impl<A, B, const NA: usize, const NB: usize, const N: usize, const C: usize> DiracSystem<N>
    for Interconnection<A, B, NA, NB, N, C>
where
    A: DiracSystem<NA>,
    B: DiracSystem<NB>,
{
    const ONE_FORMS: usize = A::ONE_FORMS + B::ONE_FORMS + C;
    const HOLONOMIC: usize = A::HOLONOMIC + B::HOLONOMIC;
    const FORCES: bool = A::FORCES || B::FORCES;
    const INPUTS: usize = A::INPUTS + B::INPUTS;
    // L = L_A + L_B, F = F_A + F_B: quadratic, and affine, where both are.
    const QUADRATIC: bool = A::QUADRATIC && B::QUADRATIC;
    const FORCES_AFFINE: bool =
        (!A::FORCES || A::FORCES_AFFINE) && (!B::FORCES || B::FORCES_AFFINE);

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, N>, v: &SVector<D, N>) -> D {
        Self::A.lagrangian(&self.a, q, v) + Self::B.lagrangian(&self.b, q, v)
    }

    fn lagrangian_gradient(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<LagrangianGradient<N>> {
        let mut gradient = LagrangianGradient::zero();
        Self::A.add_gradient(&self.a, q, v, &mut gradient)?;
        Self::B.add_gradient(&self.b, q, v, &mut gradient)?;
        Some(gradient)
    }

    fn lagrangian_hessian(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<LagrangianHessian<N>> {
        let mut hessian = LagrangianHessian::zero();
        Self::A.add_hessian(&self.a, q, v, &mut hessian)?;
        Self::B.add_hessian(&self.b, q, v, &mut hessian)?;
        Some(hessian)
    }

    fn one_form<D: Scalar>(&self, q: &SVector<D, N>, index: usize) -> SVector<D, N> {
        Self::A
            .one_form(&self.a, q, index)
            .or_else(|| Self::B.one_form(&self.b, q, index))
            .unwrap_or_else(|| {
                self.junctions
                    .one_form(index.saturating_sub(A::ONE_FORMS + B::ONE_FORMS))
            })
    }

    fn one_form_name(&self, index: usize) -> String {
        let [a, b] = &self.instances;
        Self::A
            .one_form_name(&self.a, a, index)
            .or_else(|| Self::B.one_form_name(&self.b, b, index))
            .unwrap_or_else(|| {
                self.junctions
                    .name(index.saturating_sub(A::ONE_FORMS + B::ONE_FORMS))
            })
    }

    /// The components' answer for theirs; the junctions are constant.
    fn one_form_is_constant(&self, index: usize) -> bool {
        Self::A
            .one_form_is_constant(&self.a, index)
            .or_else(|| Self::B.one_form_is_constant(&self.b, index))
            .unwrap_or(true)
    }

    fn holonomic<D: Scalar>(&self, q: &SVector<D, N>, index: usize) -> D {
        Self::A
            .holonomic(&self.a, q, index)
            .or_else(|| Self::B.holonomic(&self.b, q, index))
            .unwrap_or(D::from(0.0))
    }

    fn force<D: Scalar>(
        &self,
        q: &SVector<D, N>,
        v: &SVector<D, N>,
        t: f64,
        inputs: &[D],
    ) -> SVector<D, N> {
        let mut force = SVector::from_element(D::from(0.0));
        Self::A.place_force(&self.a, q, v, t, inputs, &mut force);
        Self::B.place_force(&self.b, q, v, t, inputs, &mut force);
        force
    }

    fn input_name(&self, i: usize) -> String {
        let [a, b] = &self.instances;
        Self::A
            .input_name(&self.a, a, i)
            .or_else(|| Self::B.input_name(&self.b, b, i))
            .unwrap_or_else(|| format!("u{i}"))
    }

    /// The constrained components' constraint point (they agree: checked when built), or the
    /// midpoint.
    fn constraint_point(&self) -> ConstraintPoint {
        if A::ONE_FORMS > 0 {
            self.a.constraint_point()
        } else if B::ONE_FORMS > 0 {
            self.b.constraint_point()
        } else {
            ConstraintPoint::Midpoint
        }
    }

    fn coordinate_name(&self, i: usize) -> String {
        let [a, b] = &self.instances;
        Self::A
            .coordinate_name(&self.a, a, i)
            .or_else(|| Self::B.coordinate_name(&self.b, b, i))
            .unwrap_or_else(|| format!("q{i}"))
    }

    fn parameters(&self) -> Vec<(String, f64)> {
        let mut parameters = Vec::new();
        Slot::parameters(&self.a, &self.instances[0], &mut parameters);
        Slot::parameters(&self.b, &self.instances[1], &mut parameters);
        parameters
    }

    /// The components' quadrature when they name the same one; an `Err` naming both otherwise
    /// (pass one to [`Stepper::new`](crate::Stepper::new)).
    fn quadrature(&self) -> Result<Quadrature, DiracError> {
        common_quadrature(&[
            (&self.instances[0], self.a.quadrature()?),
            (&self.instances[1], self.b.quadrature()?),
        ])
    }
}

/// The quadrature the named components agree on, or an `Err` naming two that differ.
pub fn common_quadrature(named: &[(&str, Quadrature)]) -> Result<Quadrature, DiracError> {
    let Some((first, quadrature)) = named.first() else {
        return Ok(Quadrature::midpoint());
    };
    match named.iter().find(|(_, other)| other != quadrature) {
        None => Ok(quadrature.clone()),
        Some((other, theirs)) => Err(DiracError::InvalidQuadrature(format!(
            "{first} names {} and {other} names {}: pass one quadrature for the interconnection",
            quadrature.name(),
            theirs.name()
        ))),
    }
}
