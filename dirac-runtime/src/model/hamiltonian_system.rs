//! The trait a model written with a Hamiltonian implements: `H(q, p)`, constraint one-forms,
//! forces and inputs, on `Rᴺ`.

use nalgebra::SVector;

use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::base::scalar::Scalar;
use crate::quadrature::Quadrature;

/// A model on `Rᴺ` given by its Hamiltonian `H(q, p)` and, where it has them, constraint
/// one-forms `A(q) q̇ = 0`, forces `F(q, p, t, u)` and named inputs `u`: the model the discrete
/// Hamiltonian route ([`Hamilton`](crate::step::hamilton::Hamilton)) steps.
///
/// `#[dirac_system(hamiltonian = ...)]` implements this trait (momenta are written `p(x)`);
/// writing the `impl` by hand works the same way. Only [`hamiltonian`](Self::hamiltonian) is
/// required. `H` need not come from a Lagrangian: `∂²H/∂p²` may be singular (e.g. `H = p f(q)`,
/// the cotangent lift of `q̇ = f(q)`). Holonomic constraints are not offered on this route
/// (write them as one-forms `dg`, or use a [`DiracSystem`](crate::DiracSystem)).
///
/// ```
/// use dirac_runtime::{HamiltonianSystem, Quadrature, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
///
/// /// H = (q² + 1)(p² + 1)/2: not separable.
/// struct Coupled;
///
/// impl HamiltonianSystem<1> for Coupled {
///     fn hamiltonian<D: Scalar>(&self, q: &SVector<D, 1>, p: &SVector<D, 1>) -> D {
///         (q[0] * q[0] + 1.0) * (p[0] * p[0] + 1.0) * 0.5
///     }
/// }
///
/// let mut stepper = Stepper::hamiltonian(Coupled, Quadrature::galerkin(2)?, 0.05)?;
/// stepper.start_from_momentum(vector![0.5], vector![0.0])?;
/// let trajectory = stepper.run(200)?;
/// let drift = trajectory.energy().iter().map(|e| (e - 0.625).abs()).fold(0.0, f64::max);
/// assert!(drift < 1e-6);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[diagnostic::on_unimplemented(
    message = "`{Self}` is not a model given by a Hamiltonian",
    label = "not a `HamiltonianSystem<{N}>`",
    note = "`Stepper::hamiltonian` and `Stepper::hamiltonian_from_system` take models with `hamiltonian = ...` in `#[dirac_system(...)]` (or an impl of `HamiltonianSystem<N>`); a model given by a Lagrangian is stepped by `Stepper::new` or `Stepper::from_system`"
)]
pub trait HamiltonianSystem<const N: usize> {
    /// Number of constraint one-forms `w^a(q)` (rows of `A(q)`).
    const ONE_FORMS: usize = 0;
    /// Number of holonomic constraints `g_b(q) = 0`.
    const HOLONOMIC: usize = 0;
    /// Whether [`force`](Self::force) is nonzero.
    const FORCES: bool = false;
    /// Number of named inputs the forces read.
    const INPUTS: usize = 0;

    /// The Hamiltonian `H(q, p)` at position `q` and momentum `p`.
    fn hamiltonian<D: Scalar>(&self, q: &SVector<D, N>, p: &SVector<D, N>) -> D;

    /// Constraint one-form `a` (`0 <= a < ONE_FORMS`) at `q`: the row `A_a(q)` of
    /// `A(q) q̇ = 0`.
    fn one_form<D: Scalar>(&self, q: &SVector<D, N>, a: usize) -> SVector<D, N> {
        let _ = (q, a);
        SVector::from_element(D::zero())
    }

    /// Holonomic constraint `b` (`0 <= b < HOLONOMIC`): the function `g_b(q)` held at zero.
    fn holonomic<D: Scalar>(&self, q: &SVector<D, N>, b: usize) -> D {
        let _ = (q, b);
        D::zero()
    }

    /// The force one-form `F(q, p, t, u)`, with the inputs' current values in `inputs` (of the
    /// same scalar type as `q` and `p`).
    fn force<D: Scalar>(
        &self,
        q: &SVector<D, N>,
        p: &SVector<D, N>,
        t: f64,
        inputs: &[D],
    ) -> SVector<D, N> {
        let _ = (q, p, t, inputs);
        SVector::from_element(D::zero())
    }

    /// The name of input `i`, used by [`Stepper::set_input`](crate::Stepper::set_input).
    fn input_name(&self, i: usize) -> String {
        format!("u{i}")
    }

    /// Where the constraint one-forms are evaluated on a step of degree 1 (default: the
    /// midpoint).
    fn constraint_point(&self) -> ConstraintPoint {
        ConstraintPoint::Midpoint
    }

    /// The name of coordinate `i`, used in CSV headers and error messages.
    fn coordinate_name(&self, i: usize) -> String {
        format!("q{i}")
    }

    /// The model's parameters by name, checked to be finite when a stepper is built.
    fn parameters(&self) -> Vec<(String, f64)> {
        Vec::new()
    }

    /// The quadrature a stepper uses when none is named
    /// ([`Stepper::hamiltonian_from_system`](crate::Stepper::hamiltonian_from_system)).
    fn quadrature(&self) -> Result<Quadrature, DiracError> {
        Ok(Quadrature::midpoint())
    }
}
