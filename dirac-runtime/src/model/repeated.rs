//! `K` copies of one component joined by junctions: a lattice, a ladder, a chain, a ring — the
//! interconnection of identical cells (see [`interconnection`](crate::model::interconnection) for the
//! mathematics). Copy `i` is the instance `name[i]`; its coordinates are `name[i].coordinate`.
//!
//! ```
//! use dirac_runtime::interconnection::Junction;
//! use dirac_runtime::repeated::Repeated;
//! use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
//! use nalgebra::{SVector, vector};
//!
//! /// A unit mass on a unit spring to the ground.
//! struct Bob;
//! impl DiracSystem<1> for Bob {
//!     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
//!         (v[0] * v[0] - q[0] * q[0]) * 0.5
//!     }
//!     fn coordinate_name(&self, _i: usize) -> String { "x".into() }
//! }
//!
//! // Three bobs glued into one of mass 3 on springs 3: still ω = 1.
//! let glue = |i: usize| {
//!     Junction::new(format!("glue{i}"))
//!         .flow(format!("bob[{i}].x"), 1.0)
//!         .flow(format!("bob[{}].x", i + 1), -1.0)
//! };
//! let bobs = Repeated::<Bob, 3, 1, 3, 2>::new("bob", [Bob, Bob, Bob], [glue(0), glue(1)])?;
//! let mut stepper = Stepper::new(bobs, Quadrature::midpoint(), 0.01)?;
//! stepper.start_from_velocity(vector![1.0, 1.0, 1.0], SVector::zeros())?;
//! stepper.run(100)?;
//! assert!((stepper.q()[2] - 1.0_f64.cos()).abs() < 1e-4);
//! # Ok::<(), dirac_runtime::DiracError>(())
//! ```

use nalgebra::SVector;

use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::base::scalar::Scalar;
use crate::model::closed_form::{LagrangianGradient, LagrangianHessian};
use crate::model::interconnection::{Interconnected, Junction, Junctions, common_quadrature};
use crate::model::slot::Slot;
use crate::model::system::DiracSystem;
use crate::quadrature::Quadrature;

/// `K` copies of the component `S` (on `Rᴹ`) joined by `C` [`Junction`]s: a [`DiracSystem`]
/// on `R^N`, `N = K M` (see the [module](self) documentation).
#[derive(Debug, Clone)]
pub struct Repeated<S, const K: usize, const M: usize, const N: usize, const C: usize> {
    instances: [String; K],
    parts: [S; K],
    junctions: Junctions<N, C>,
}

impl<S: DiracSystem<M>, const K: usize, const M: usize, const N: usize, const C: usize>
    Repeated<S, K, M, N, C>
{
    /// The copies `parts`, named `name[0]`, `name[1]`, …, joined by `junctions` over their
    /// coordinates `name[i].coordinate`; an `Err(InvalidInterconnection)` as
    /// [`Interconnection::new`](crate::model::interconnection::Interconnection::new) (and for a `name`
    /// that is empty or contains `.` or `[`, and copies holding their one-forms at different
    /// constraint points).
    pub fn new(name: &str, parts: [S; K], junctions: [Junction; C]) -> Result<Self, DiracError> {
        const { assert!(N == K * M, "K copies of a model on R^M are on R^(K M)") };
        if name.is_empty() || name.contains(['.', '[']) {
            return Err(DiracError::InvalidInterconnection(format!(
                "the name {name:?} of the copies must be non-empty and without '.' or '['"
            )));
        }
        let instances: [String; K] = std::array::from_fn(|i| format!("{name}[{i}]"));
        let point = parts[0].constraint_point();
        if let Some(i) = (0..K).find(|&i| S::ONE_FORMS > 0 && parts[i].constraint_point() != point)
        {
            return Err(DiracError::InvalidInterconnection(format!(
                "{} holds its one-forms at {point:?} and {} at {:?}: the copies need one \
                 constraint point",
                instances[0],
                instances[i],
                parts[i].constraint_point()
            )));
        }
        let coordinates: Vec<String> = (0..N)
            .map(|i| {
                format!(
                    "{}.{}",
                    instances[i / M],
                    parts[i / M].coordinate_name(i % M)
                )
            })
            .collect();
        let junctions = Junctions::resolve(junctions, &instances, &coordinates)?;
        Ok(Self {
            instances,
            parts,
            junctions,
        })
    }

    /// The copies.
    pub fn parts(&self) -> &[S; K] {
        &self.parts
    }

    /// Where copy `i` sits.
    const fn slot(i: usize) -> Slot {
        Slot::nth::<S, M>(i)
    }
}

impl<S: DiracSystem<M>, const K: usize, const M: usize, const N: usize, const C: usize>
    Interconnected<N, K, C> for Repeated<S, K, M, N, C>
{
    fn junctions(&self) -> &Junctions<N, C> {
        &self.junctions
    }

    fn energies(&self, q: &SVector<f64, N>, v: &SVector<f64, N>) -> [f64; K] {
        std::array::from_fn(|i| Self::slot(i).energy(&self.parts[i], q, v))
    }

    fn component_of(&self, i: usize) -> usize {
        i / M
    }

    fn component_name(&self, c: usize) -> String {
        self.instances
            .get(c)
            .cloned()
            .unwrap_or_else(|| format!("component {c}"))
    }
}

impl<S: DiracSystem<M>, const K: usize, const M: usize, const N: usize, const C: usize>
    DiracSystem<N> for Repeated<S, K, M, N, C>
{
    const ONE_FORMS: usize = K * S::ONE_FORMS + C;
    const HOLONOMIC: usize = K * S::HOLONOMIC;
    const FORCES: bool = S::FORCES;
    const INPUTS: usize = K * S::INPUTS;
    const QUADRATIC: bool = S::QUADRATIC;
    const FORCES_AFFINE: bool = S::FORCES_AFFINE;

    fn lagrangian<D: Scalar>(&self, q: &SVector<D, N>, v: &SVector<D, N>) -> D {
        (0..K).fold(D::from(0.0), |sum, i| {
            sum + Self::slot(i).lagrangian(&self.parts[i], q, v)
        })
    }

    fn lagrangian_gradient(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<LagrangianGradient<N>> {
        let mut gradient = LagrangianGradient::zero();
        for (i, part) in self.parts.iter().enumerate() {
            Self::slot(i).add_gradient(part, q, v, &mut gradient)?;
        }
        Some(gradient)
    }

    fn lagrangian_hessian(
        &self,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> Option<LagrangianHessian<N>> {
        let mut hessian = LagrangianHessian::zero();
        for (i, part) in self.parts.iter().enumerate() {
            Self::slot(i).add_hessian(part, q, v, &mut hessian)?;
        }
        Some(hessian)
    }

    fn one_form<D: Scalar>(&self, q: &SVector<D, N>, index: usize) -> SVector<D, N> {
        match index.checked_sub(K * S::ONE_FORMS) {
            Some(j) => self.junctions.one_form(j),
            None => {
                let i = index / S::ONE_FORMS;
                Self::slot(i)
                    .one_form(&self.parts[i], q, index)
                    .unwrap_or_else(|| SVector::from_element(D::from(0.0)))
            }
        }
    }

    fn one_form_name(&self, index: usize) -> String {
        match index.checked_sub(K * S::ONE_FORMS) {
            Some(j) => self.junctions.name(j),
            None => {
                let i = index / S::ONE_FORMS;
                Self::slot(i)
                    .one_form_name(&self.parts[i], &self.instances[i], index)
                    .unwrap_or_else(|| format!("one-form {index}"))
            }
        }
    }

    /// The copies' answer for theirs; the junctions are constant.
    fn one_form_is_constant(&self, index: usize) -> bool {
        let i = index / S::ONE_FORMS.max(1);
        self.parts
            .get(i)
            .and_then(|part| Self::slot(i).one_form_is_constant(part, index))
            .unwrap_or(true)
    }

    fn holonomic<D: Scalar>(&self, q: &SVector<D, N>, index: usize) -> D {
        let i = index / S::HOLONOMIC.max(1);
        self.parts
            .get(i)
            .and_then(|part| Self::slot(i).holonomic(part, q, index))
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
        for (i, part) in self.parts.iter().enumerate() {
            Self::slot(i).place_force(part, q, v, t, inputs, &mut force);
        }
        force
    }

    fn input_name(&self, i: usize) -> String {
        let copy = i / S::INPUTS.max(1);
        self.parts
            .get(copy)
            .and_then(|part| Self::slot(copy).input_name(part, &self.instances[copy], i))
            .unwrap_or_else(|| format!("u{i}"))
    }

    /// The copies' constraint point (they agree: checked when built), or the midpoint when
    /// they have no one-forms of their own.
    fn constraint_point(&self) -> ConstraintPoint {
        match S::ONE_FORMS {
            0 => ConstraintPoint::Midpoint,
            _ => self.parts[0].constraint_point(),
        }
    }

    fn coordinate_name(&self, i: usize) -> String {
        let copy = i / M;
        self.parts
            .get(copy)
            .and_then(|part| Self::slot(copy).coordinate_name(part, &self.instances[copy], i))
            .unwrap_or_else(|| format!("q{i}"))
    }

    fn parameters(&self) -> Vec<(String, f64)> {
        let mut parameters = Vec::new();
        for (part, instance) in self.parts.iter().zip(&self.instances) {
            Slot::parameters(part, instance, &mut parameters);
        }
        parameters
    }

    /// The quadrature the copies agree on, or an `Err` naming two that differ.
    fn quadrature(&self) -> Result<Quadrature, DiracError> {
        let named = self
            .instances
            .iter()
            .zip(&self.parts)
            .map(|(name, part)| Ok((name.as_str(), part.quadrature()?)))
            .collect::<Result<Vec<_>, DiracError>>()?;
        common_quadrature(&named)
    }
}
