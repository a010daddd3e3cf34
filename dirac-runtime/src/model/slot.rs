//! A component's place in a model made of components: where its coordinates, one-forms,
//! holonomic constraints and inputs start among the whole model's. An interconnection (the
//! [`Interconnection`](crate::model::interconnection::Interconnection) type, or a struct with
//! `#[dirac_system(subsystems(...))]`) asks each component's slot for that component's share of
//! `L`, its one-forms, constraints and forces, read from and placed into the whole model's
//! vectors.
//!
//! ```
//! use dirac_runtime::slot::Slot;
//! use dirac_runtime::{DiracSystem, Scalar};
//! use nalgebra::{SVector, vector};
//!
//! struct Spring;
//! impl DiracSystem<2> for Spring {
//!     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 2>, v: &SVector<D, 2>) -> D {
//!         (v[0] * v[0] + v[1] * v[1] - (q[1] - q[0]) * (q[1] - q[0])) * 0.5
//!     }
//! }
//! // Two springs side by side: the second's coordinates are the whole model's 2 and 3.
//! const SECOND: Slot = Slot::FIRST.after::<Spring, 2>();
//! assert_eq!(SECOND.coordinate, 2);
//! let q = vector![0.0, 0.0, 1.0, 3.0];
//! let mine: SVector<f64, 2> = SECOND.part(&q);
//! assert_eq!(mine, vector![1.0, 3.0]);
//! assert_eq!(SECOND.lagrangian(&Spring, &q, &SVector::zeros()), -2.0);
//! ```

use nalgebra::{SMatrix, SVector};

use crate::base::constraint_point::ConstraintPoint;
use crate::base::scalar::Scalar;
use crate::model::closed_form::{LagrangianGradient, LagrangianHessian};
use crate::model::legendre;
use crate::model::system::DiracSystem;

/// Where a component's coordinates, one-forms, holonomic constraints and inputs start among
/// those of the model it is part of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    /// Index of its first coordinate.
    pub coordinate: usize,
    /// Index of its first one-form.
    pub one_form: usize,
    /// Index of its first holonomic constraint.
    pub holonomic: usize,
    /// Index of its first input.
    pub input: usize,
}

impl Slot {
    /// The first component's slot: everything starts at 0.
    pub const FIRST: Slot = Slot {
        coordinate: 0,
        one_form: 0,
        holonomic: 0,
        input: 0,
    };

    /// The slot of the component after one of type `S` (on `Rᴹ`) in this slot.
    pub const fn after<S: DiracSystem<M>, const M: usize>(self) -> Slot {
        Slot {
            coordinate: self.coordinate + M,
            one_form: self.one_form + S::ONE_FORMS,
            holonomic: self.holonomic + S::HOLONOMIC,
            input: self.input + S::INPUTS,
        }
    }

    /// The slot of copy `i` of a component of type `S` (on `Rᴹ`) among copies side by side.
    pub const fn nth<S: DiracSystem<M>, const M: usize>(i: usize) -> Slot {
        Slot {
            coordinate: i * M,
            one_form: i * S::ONE_FORMS,
            holonomic: i * S::HOLONOMIC,
            input: i * S::INPUTS,
        }
    }

    /// The component's part of the whole model's vector `x` (a position, velocity, momentum).
    pub fn part<D: Scalar, const N: usize, const M: usize>(
        &self,
        x: &SVector<D, N>,
    ) -> SVector<D, M> {
        SVector::from_fn(|i, _| x[self.coordinate + i])
    }

    /// Writes the component's vector `x` into its part of the whole model's `into`.
    pub fn place<D: Scalar, const N: usize, const M: usize>(
        &self,
        into: &mut SVector<D, N>,
        x: &SVector<D, M>,
    ) {
        for i in 0..M {
            into[self.coordinate + i] = x[i];
        }
    }

    /// The component's Lagrangian at the whole model's `(q, v)`.
    pub fn lagrangian<S: DiracSystem<M>, D: Scalar, const N: usize, const M: usize>(
        &self,
        component: &S,
        q: &SVector<D, N>,
        v: &SVector<D, N>,
    ) -> D {
        component.lagrangian(&self.part(q), &self.part(v))
    }

    /// The component's energy at the whole model's `(q, v)`.
    pub fn energy<S: DiracSystem<M>, const N: usize, const M: usize>(
        &self,
        component: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
    ) -> f64 {
        legendre::energy(component, &self.part(q), &self.part(v))
    }

    /// Adds the component's closed-form `L` and gradient into the whole model's `into`;
    /// `None` when the component has none.
    pub fn add_gradient<S: DiracSystem<M>, const N: usize, const M: usize>(
        &self,
        component: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        into: &mut LagrangianGradient<N>,
    ) -> Option<()> {
        let mine = component.lagrangian_gradient(&self.part(q), &self.part(v))?;
        into.value += mine.value;
        self.place(&mut into.q, &mine.q);
        self.place(&mut into.v, &mine.v);
        Some(())
    }

    /// Adds the component's closed-form `L`, gradient and Hessian (diagonal blocks) into the
    /// whole model's `into`; `None` when the component has none.
    pub fn add_hessian<S: DiracSystem<M>, const N: usize, const M: usize>(
        &self,
        component: &S,
        q: &SVector<f64, N>,
        v: &SVector<f64, N>,
        into: &mut LagrangianHessian<N>,
    ) -> Option<()> {
        let mine = component.lagrangian_hessian(&self.part(q), &self.part(v))?;
        into.gradient.value += mine.gradient.value;
        self.place(&mut into.gradient.q, &mine.gradient.q);
        self.place(&mut into.gradient.v, &mine.gradient.v);
        let c = self.coordinate;
        let block = |into: &mut SMatrix<f64, N, N>, mine: &SMatrix<f64, M, M>| {
            into.fixed_view_mut::<M, M>(c, c).copy_from(mine);
        };
        block(&mut into.qq, &mine.qq);
        block(&mut into.qv, &mine.qv);
        block(&mut into.vv, &mine.vv);
        Some(())
    }

    /// The component's own index of the whole model's one-form `index`, when it is one of its.
    fn own_one_form<S: DiracSystem<M>, const M: usize>(&self, index: usize) -> Option<usize> {
        index
            .checked_sub(self.one_form)
            .filter(|&a| a < S::ONE_FORMS)
    }

    /// The whole model's one-form `index` when it is one of the component's (`None` otherwise).
    pub fn one_form<S: DiracSystem<M>, D: Scalar, const N: usize, const M: usize>(
        &self,
        component: &S,
        q: &SVector<D, N>,
        index: usize,
    ) -> Option<SVector<D, N>> {
        let own = self.own_one_form::<S, M>(index)?;
        let mut form = SVector::from_element(D::from(0.0));
        self.place(&mut form, &component.one_form(&self.part(q), own));
        Some(form)
    }

    /// The name of the whole model's one-form `index` when it is one of the component's:
    /// `name of instance`.
    pub fn one_form_name<S: DiracSystem<M>, const M: usize>(
        &self,
        component: &S,
        instance: &str,
        index: usize,
    ) -> Option<String> {
        let own = self.own_one_form::<S, M>(index)?;
        Some(format!("{} of {instance}", component.one_form_name(own)))
    }

    /// Whether the whole model's one-form `index`, when it is one of the component's, is
    /// constant (`None` when it is not the component's).
    pub fn one_form_is_constant<S: DiracSystem<M>, const M: usize>(
        &self,
        component: &S,
        index: usize,
    ) -> Option<bool> {
        let own = self.own_one_form::<S, M>(index)?;
        Some(component.one_form_is_constant(own))
    }

    /// The whole model's holonomic constraint `index` when it is one of the component's.
    pub fn holonomic<S: DiracSystem<M>, D: Scalar, const N: usize, const M: usize>(
        &self,
        component: &S,
        q: &SVector<D, N>,
        index: usize,
    ) -> Option<D> {
        let own = index
            .checked_sub(self.holonomic)
            .filter(|&b| b < S::HOLONOMIC)?;
        Some(component.holonomic(&self.part(q), own))
    }

    /// Writes the component's force (from its own inputs among the whole model's `inputs`)
    /// into its part of `into`; nothing when the component has no forces.
    #[allow(clippy::too_many_arguments)]
    pub fn place_force<S: DiracSystem<M>, D: Scalar, const N: usize, const M: usize>(
        &self,
        component: &S,
        q: &SVector<D, N>,
        v: &SVector<D, N>,
        t: f64,
        inputs: &[D],
        into: &mut SVector<D, N>,
    ) {
        if S::FORCES {
            let own = &inputs[self.input..self.input + S::INPUTS];
            self.place(into, &component.force(&self.part(q), &self.part(v), t, own));
        }
    }

    /// The name of the whole model's input `i` when it is one of the component's:
    /// `instance.input`.
    pub fn input_name<S: DiracSystem<M>, const M: usize>(
        &self,
        component: &S,
        instance: &str,
        i: usize,
    ) -> Option<String> {
        let own = i.checked_sub(self.input).filter(|&u| u < S::INPUTS)?;
        Some(format!("{instance}.{}", component.input_name(own)))
    }

    /// The name of the whole model's coordinate `i` when it is one of the component's:
    /// `instance.coordinate`.
    pub fn coordinate_name<S: DiracSystem<M>, const M: usize>(
        &self,
        component: &S,
        instance: &str,
        i: usize,
    ) -> Option<String> {
        let own = i.checked_sub(self.coordinate).filter(|&k| k < M)?;
        Some(format!("{instance}.{}", component.coordinate_name(own)))
    }

    /// The component's parameters, named `instance.parameter`, appended to `into`.
    pub fn parameters<S: DiracSystem<M>, const M: usize>(
        component: &S,
        instance: &str,
        into: &mut Vec<(String, f64)>,
    ) {
        into.extend(
            component
                .parameters()
                .into_iter()
                .map(|(name, value)| (format!("{instance}.{name}"), value)),
        );
    }
}

/// The index of the coordinate named `path` (`x`, or `theta[2]` for an element of an array)
/// among `coordinates`, each given as `(name, Some(length) for an array, index of its first
/// element)`: `None` when there is no such coordinate. A `const fn`, so that the attribute's
/// junctions name coordinates that are checked when the program compiles.
///
/// ```
/// use dirac_runtime::slot::coordinate_index;
/// const COORDINATES: [(&str, Option<usize>, usize); 2] = [("x", None, 0), ("theta", Some(3), 1)];
/// assert_eq!(coordinate_index("x", &COORDINATES), Some(0));
/// assert_eq!(coordinate_index("theta[2]", &COORDINATES), Some(3));
/// assert_eq!(coordinate_index("theta[3]", &COORDINATES), None);
/// assert_eq!(coordinate_index("y", &COORDINATES), None);
/// ```
pub const fn coordinate_index(
    path: &str,
    coordinates: &[(&str, Option<usize>, usize)],
) -> Option<usize> {
    let path = path.as_bytes();
    let mut k = 0;
    while k < coordinates.len() {
        let (name, length, first) = coordinates[k];
        let name = name.as_bytes();
        match length {
            None if equal(path, name) => return Some(first),
            Some(length) if path.len() > name.len() + 2 => {
                let (head, tail) = path.split_at(name.len());
                if equal(head, name) && tail[0] == b'[' && tail[tail.len() - 1] == b']' {
                    let mut element = 0usize;
                    let mut i = 1;
                    while i < tail.len() - 1 {
                        if !tail[i].is_ascii_digit() || element > usize::MAX / 10 - 1 {
                            return None;
                        }
                        element = element * 10 + (tail[i] - b'0') as usize;
                        i += 1;
                    }
                    return if element < length {
                        Some(first + element)
                    } else {
                        None
                    };
                }
            }
            _ => {}
        }
        k += 1;
    }
    None
}

/// The rest of `path` after `instance.` (`Some("r.q")` for `"drive.r.q"` and `"drive"`), or
/// `None` when `path` does not start with that instance.
///
/// ```
/// use dirac_runtime::slot::descend;
/// assert_eq!(descend("drive.r.q", "drive"), Some("r.q"));
/// assert_eq!(descend("driver.q", "drive"), None);
/// ```
pub const fn descend<'p>(path: &'p str, instance: &str) -> Option<&'p str> {
    let (bytes, name) = (path.as_bytes(), instance.as_bytes());
    if bytes.len() <= name.len() + 1 {
        return None;
    }
    let (head, tail) = bytes.split_at(name.len());
    if !equal(head, name) || tail[0] != b'.' {
        return None;
    }
    match core::str::from_utf8(tail.split_at(1).1) {
        Ok(rest) => Some(rest),
        Err(_) => None,
    }
}

/// Byte-wise equality, in a `const fn`.
const fn equal(a: &[u8], b: &[u8]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The constraint point the constrained parts of a model agree on (`Ok(None)` when none has
/// one-forms), or `Err(i)` with the first part `i` that disagrees with the constrained parts
/// before it: a `const fn`, so that the attribute's models made of subsystems refuse
/// disagreeing subsystems when the program compiles.
///
/// ```
/// use dirac_runtime::ConstraintPoint::{End, Midpoint};
/// use dirac_runtime::slot::common_point;
/// assert_eq!(common_point(&[None, Some(End), Some(End)]), Ok(Some(End)));
/// assert_eq!(common_point(&[Some(End), None, Some(Midpoint)]), Err(2));
/// ```
pub const fn common_point(
    points: &[Option<ConstraintPoint>],
) -> Result<Option<ConstraintPoint>, usize> {
    let mut found: Option<ConstraintPoint> = None;
    let mut i = 0;
    while i < points.len() {
        if let Some(point) = points[i] {
            match found {
                None => found = Some(point),
                Some(first) if first as u8 != point as u8 => return Err(i),
                Some(_) => {}
            }
        }
        i += 1;
    }
    Ok(found)
}
