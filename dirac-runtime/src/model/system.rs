//! The trait a model implements: its Lagrangian, coordinate names, parameters and default quadrature.

use crate::base::constraint_point::ConstraintPoint;
use crate::base::error::DiracError;
use crate::base::scalar::Scalar;
use crate::model::closed_form::{LagrangianGradient, LagrangianHessian};
use crate::quadrature::Quadrature;
use crate::space::manifold::{Manifold, Vectors};

/// A mechanical or electrical model on a [`Manifold`] of dimension `N` (`Rᴺ` unless named): its
/// continuous Lagrangian `L(q, v)` and, where it has them, constraint one-forms `A(q) v = 0`,
/// holonomic constraints `g(q) = 0`, forces `F(q, v, t, u)` and named inputs `u`.
///
/// On `Rᴺ` (`M = Vectors`, the default) points and velocities are `SVector<D, N>`. On a product
/// of vectors, rotations and unit vectors (`M = Product<K, A, B>`, see
/// [`product`](crate::space::product)) they are a [`Configuration`](crate::space::product::Configuration) and
/// [`Rates`](crate::space::product::Rates): attitudes with their body angular velocities, unit vectors
/// with their velocities. One-forms and forces are covectors in the velocities'
/// representation (for a rotation, a body torque).
///
/// `#[dirac_system(...)]` implements this trait; writing the `impl` by hand works the same way.
/// Only [`lagrangian`](Self::lagrangian) is required; everything else defaults to "none", and a
/// model without constraints or forces pays nothing for them (the stepper branches on the
/// associated constants, which are known at compile time). Every function is generic over the
/// [`Scalar`] so the runtime can differentiate it exactly with dual numbers.
///
/// ```
/// use dirac_runtime::{DiracSystem, Scalar, Quadrature, Stepper};
/// use nalgebra::{SVector, vector};
///
/// /// A harmonic oscillator, L = m v²/2 − k q²/2.
/// struct Oscillator { m: f64, k: f64 }
///
/// impl DiracSystem<1> for Oscillator {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * (0.5 * self.m) - q[0] * q[0] * (0.5 * self.k)
///     }
/// }
///
/// let mut stepper = Stepper::new(Oscillator { m: 1.0, k: 1.0 }, Quadrature::midpoint(), 0.1)?;
/// stepper.start_from_momentum(vector![1.0], vector![0.0])?;
/// stepper.step()?;
/// assert!((stepper.q()[0] - 0.1_f64.cos()).abs() < 1e-3);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[diagnostic::on_unimplemented(
    message = "`{Self}` is not a model on the configuration space `{M}`",
    label = "not a `DiracSystem<{N}, {M}>`",
    note = "`Stepper::new` and `Stepper::from_system` take models given by a Lagrangian on Rⁿ; a model with rotations (`SO3`) or directions (`S2`) among its coordinates is stepped by `Stepper::on_manifold(model, space, quadrature, h)`, and one given by a Hamiltonian by `Stepper::hamiltonian(model, quadrature, h)`",
    note = "a model is a struct under `#[dirac_system(...)]`, or implements `DiracSystem<N>` by hand"
)]
pub trait DiracSystem<const N: usize, M: Manifold<N> = Vectors> {
    /// Number of constraint one-forms `w^a(q)` (rows of `A(q)`).
    const ONE_FORMS: usize = 0;
    /// Number of holonomic constraints `g_b(q) = 0`.
    const HOLONOMIC: usize = 0;
    /// Whether [`force`](Self::force) is nonzero.
    const FORCES: bool = false;
    /// Number of named inputs the forces read.
    const INPUTS: usize = 0;

    /// Whether `L` is finite at every finite `(q, v)` short of overflow: built from sums,
    /// products, integer powers, division by what the state does not change and functions
    /// defined on every real (no root, logarithm or division by the state). A step then skips
    /// the check that `L` is finite at its end, since there is no domain to leave. `false` by
    /// default; `#[dirac_system]` derives it from a Lagrangian written as an expression.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// struct Pendulum;
    /// impl DiracSystem<1> for Pendulum {
    ///     // v²/2 + cos q is finite wherever q and v are.
    ///     const LAGRANGIAN_ENTIRE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5 + q[0].cos()
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Pendulum, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// stepper.run(10)?;
    /// assert!(stepper.energy()?.is_finite());
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    const LAGRANGIAN_ENTIRE: bool = false;

    /// The entries of the Lagrangian's Hessian that vanish identically ([`HessianZeros`]; none by
    /// default): a degree-1 step with closed-form derivatives skips their products.
    /// `#[dirac_system]` reads them off the expression.
    ///
    /// [`HessianZeros`]: crate::HessianZeros
    const LAGRANGIAN_HESSIAN_ZEROS: crate::model::closed_form::HessianZeros<N> =
        crate::model::closed_form::HessianZeros::NONE;

    /// Whether `L = ½ vᵀ M v + bᵀ v − V(q)` with a constant mass matrix `M` and constant `b`
    /// (`∂²L/∂q∂v = 0` and `∂²L/∂v²` constant): such a model admits the explicit variational
    /// step of [`Stepper::explicit`](crate::Stepper::explicit). `false` by default;
    /// `#[dirac_system]` derives it from a Lagrangian written as an expression, and the explicit
    /// step checks the claim at the start of every run.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Scalar};
    /// use nalgebra::SVector;
    /// struct Pendulum;
    /// impl DiracSystem<1> for Pendulum {
    ///     const SEPARABLE: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5 + q[0].cos()
    ///     }
    /// }
    /// assert!(<Pendulum as DiracSystem<1>>::SEPARABLE);
    /// ```
    const SEPARABLE: bool = false;

    /// Whether `L` is a quadratic polynomial in `(q, v)`: every second derivative a constant
    /// (circuits of linear elements, oscillators, linearised models). On `Rⁿ`, with constant
    /// one-forms, no holonomic constraints, and no forces or forces affine with constant
    /// coefficients ([`FORCES_AFFINE`](Self::FORCES_AFFINE)), the step equations are then
    /// linear with constant coefficients, and a [`Stepper`](crate::Stepper) keeps their
    /// factorised Jacobian from one step to the next rather than evaluating it at every step.
    /// `false` by default;
    /// `#[dirac_system]` derives it from a Lagrangian written as an expression. To Newton's
    /// method a wrong claim never gives a wrong answer: a kept Jacobian that is not the
    /// equations' is evaluated again where it contracts too slowly, and a solve that still
    /// cannot converge fails as any other. A stepper
    /// [`with_step_map`](crate::Stepper::with_step_map) trusts the claim between the readings
    /// of its map, which check it (up to 1 024 steps).
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Scalar};
    /// use nalgebra::SVector;
    /// /// An LC loop: inductor and capacitor on one charge.
    /// struct Loop;
    /// impl DiracSystem<1> for Loop {
    ///     const QUADRATIC: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5 - q[0] * q[0] * 0.5
    ///     }
    /// }
    /// assert!(<Loop as DiracSystem<1>>::QUADRATIC);
    /// ```
    const QUADRATIC: bool = false;

    /// Whether the [`force`](Self::force) does not depend on the velocity: a function of the
    /// position, the time and the inputs alone (a potential force written as a force, a
    /// source, an actuator). The explicit step ([`Stepper::explicit`](crate::Stepper::explicit))
    /// takes such forces and refuses others. `false` by default; `#[dirac_system]` derives it
    /// (no `dot(x)` or `omega(R)` in `forces(...)`), and the explicit step checks the claim at
    /// the start of every run.
    const FORCES_FREE_OF_VELOCITY: bool = false;

    /// Whether the [`force`](Self::force) is affine in the position and the velocity with
    /// constant coefficients, `F = K q + D v + f(t, u)` (resistors, dampers, linear springs
    /// written as forces, sources): its part of a step's Jacobian is the same at every step, so
    /// with a [`QUADRATIC`](Self::QUADRATIC) Lagrangian the step equations stay linear with
    /// constant coefficients. `false` by default; `#[dirac_system]` derives it from the forces'
    /// expressions (no product of the state with itself, the time or an input, and no
    /// `abs` or `signum` of the state). As for `QUADRATIC`, a wrong claim never gives a wrong
    /// answer: the kept Jacobian is evaluated again where it contracts too slowly, and a solve
    /// that still cannot converge fails as any other (where Newton's method, which a cheap
    /// Jacobian would otherwise get, might have converged).
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Scalar};
    /// use nalgebra::SVector;
    /// /// An RL loop driven by a voltage `u`: L = ½ l q̇², F = u − r q̇.
    /// struct Rl;
    /// impl DiracSystem<1> for Rl {
    ///     const QUADRATIC: bool = true;
    ///     const FORCES: bool = true;
    ///     const FORCES_AFFINE: bool = true;
    ///     const INPUTS: usize = 1;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5
    ///     }
    ///     fn force<D: Scalar>(
    ///         &self,
    ///         _q: &SVector<D, 1>,
    ///         v: &SVector<D, 1>,
    ///         _t: f64,
    ///         u: &[D],
    ///     ) -> SVector<D, 1> {
    ///         SVector::from([u[0] - v[0] * 2.0])
    ///     }
    /// }
    /// assert!(<Rl as DiracSystem<1>>::FORCES_AFFINE);
    /// ```
    const FORCES_AFFINE: bool = false;

    /// Whether [`one_form_with_derivative`](Self::one_form_with_derivative) gives the one-forms'
    /// derivatives in closed form (`false` by default: dual numbers take them).
    const ONE_FORM_DERIVATIVES: bool = false;

    /// The continuous Lagrangian `L(q, v)` at position `q` and velocity `v`.
    fn lagrangian<D: Scalar>(&self, q: &M::Point<D>, v: &M::Tangent<D>) -> D;

    /// `L` and its gradient at `(q, v)` in closed form, where the model has them:
    /// `#[dirac_system]` derives them at compile time from a Lagrangian written as an
    /// expression, on `Rᴺ` and on vectors and rotations (`Rᴷ × SO(3)ᴬ`). `None` (the default)
    /// lets the runtime take them by dual numbers. They must be the derivatives of
    /// [`lagrangian`](Self::lagrangian): a stepper compares the two at the start of every run
    /// ([`closed_form::check`](crate::model::closed_form::check)).
    ///
    /// On rotations the position derivatives are read in the body frame, along `R exp(ŵ)`, and
    /// the velocity derivatives along `Ω` ([`body_frame`](crate::model::body_frame)); a degree-1
    /// Lie group step reads them, and compares them with dual numbers along `R exp(ŵ)` at its
    /// start. With unit vectors the runtime reads no closed forms.
    fn lagrangian_gradient(
        &self,
        q: &M::Point<f64>,
        v: &M::Tangent<f64>,
    ) -> Option<LagrangianGradient<N>> {
        let _ = (q, v);
        None
    }

    /// `L` with its first and second derivatives at `(q, v)` in closed form, where the model
    /// has them (as [`lagrangian_gradient`](Self::lagrangian_gradient)).
    fn lagrangian_hessian(
        &self,
        q: &M::Point<f64>,
        v: &M::Tangent<f64>,
    ) -> Option<LagrangianHessian<N>> {
        let _ = (q, v);
        None
    }

    /// Constraint one-form `a` (`0 <= a < ONE_FORMS`) at `q`: the row `A_a(q)` of `A(q) v = 0`
    /// (a covector, paired with the velocity).
    fn one_form<D: Scalar>(&self, q: &M::Point<D>, a: usize) -> M::Tangent<D> {
        let _ = (q, a);
        M::zero()
    }

    /// One-form `a` at `q` with its derivative, in closed form where a model on `Rᴺ` has it
    /// (`ONE_FORM_DERIVATIVES = true`): hands each entry `∂A_a,i/∂q_j` that is not identically
    /// zero to `entry(i, j, value)` and returns the row `A_a(q)`. By default the row of
    /// [`one_form`](Self::one_form) without entries, and the runtime takes the derivative by
    /// dual numbers. `#[dirac_system]` derives it at compile time from one-forms written in
    /// differentials: a degree-1 step then reads the row and its derivative from one piece of
    /// straight-line code, and its Jacobian touches only the entries given. It must agree with
    /// [`one_form`](Self::one_form): a stepper compares the two at the start of every run
    /// ([`closed_form::check`](crate::model::closed_form::check)).
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    ///
    /// /// A knife edge in the plane: sin φ ẋ − cos φ ẏ = 0.
    /// struct KnifeEdge;
    /// impl DiracSystem<3> for KnifeEdge {
    ///     const ONE_FORMS: usize = 1;
    ///     const ONE_FORM_DERIVATIVES: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 3>, v: &SVector<D, 3>) -> D {
    ///         (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * 0.5
    ///     }
    ///     fn one_form<D: Scalar>(&self, q: &SVector<D, 3>, _a: usize) -> SVector<D, 3> {
    ///         SVector::from([q[2].sin(), -q[2].cos(), D::from(0.0)])
    ///     }
    ///     fn one_form_with_derivative(
    ///         &self,
    ///         q: &SVector<f64, 3>,
    ///         _a: usize,
    ///         mut entry: impl FnMut(usize, usize, f64),
    ///     ) -> SVector<f64, 3> {
    ///         let (sin, cos) = q[2].sin_cos();
    ///         entry(0, 2, cos);
    ///         entry(1, 2, sin);
    ///         vector![sin, -cos, 0.0]
    ///     }
    /// }
    /// let mut stepper = Stepper::new(KnifeEdge, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![0.0, 0.0, 0.0], vector![1.0, 0.0, 1.0])?;
    /// stepper.run(10)?;
    /// assert!(stepper.constraint_violation() < 1e-12);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    fn one_form_with_derivative(
        &self,
        q: &M::Point<f64>,
        a: usize,
        entry: impl FnMut(usize, usize, f64),
    ) -> M::Tangent<f64> {
        let _ = entry;
        self.one_form(q, a)
    }

    /// The name of one-form `a`, for error messages (by default `one-form a`; the attribute
    /// names a constraint by its text, an interconnection a junction by its name).
    fn one_form_name(&self, a: usize) -> String {
        format!("one-form {a}")
    }

    /// Whether one-form `a` is the same covector at every `q` (Kirchhoff's laws, junctions):
    /// the runtime then reads it in `f64` without differentiating it. `false` by default;
    /// `#[dirac_system]` says `true` for a one-form whose coefficients name no coordinate, and
    /// interconnections for their junctions. A stepper checks the claim at the start of every
    /// run (a one-form said constant whose derivative is not zero there is refused).
    fn one_form_is_constant(&self, a: usize) -> bool {
        let _ = a;
        false
    }

    /// Holonomic constraint `b` (`0 <= b < HOLONOMIC`): the value `g_b(q)`, zero on the
    /// constraint set. Its one-form `dg_b` is derived by dual numbers.
    fn holonomic<D: Scalar>(&self, q: &M::Point<D>, b: usize) -> D {
        let _ = (q, b);
        D::zero()
    }

    /// The force one-form `F(q, v, t, u)` (generalised forces, e.g. `−r q̇_l dq_l` for a
    /// resistor), with the inputs' current values in `inputs`. The inputs are of the same scalar
    /// type as `q` and `v`, so that the derivatives of a step with respect to them are exact.
    fn force<D: Scalar>(
        &self,
        q: &M::Point<D>,
        v: &M::Tangent<D>,
        t: f64,
        inputs: &[D],
    ) -> M::Tangent<D> {
        let _ = (q, v, t, inputs);
        M::zero()
    }

    /// The name of input `i`, used by [`Stepper::set_input`](crate::Stepper::set_input).
    fn input_name(&self, i: usize) -> String {
        format!("u{i}")
    }

    /// Where the constraint one-forms are evaluated on a step (default: the midpoint).
    fn constraint_point(&self) -> ConstraintPoint {
        ConstraintPoint::Midpoint
    }

    /// The name of variable `i`, used in CSV headers and error messages: on `Rᴺ` coordinate `i`
    /// (`0 <= i < N`); on a product, the `K` coordinates, then the rotations, then the unit
    /// vectors ([`Manifold::VARIABLES`] in all).
    fn coordinate_name(&self, i: usize) -> String {
        format!("q{i}")
    }

    /// The model's parameters by name, checked to be finite when a stepper is built.
    fn parameters(&self) -> Vec<(String, f64)> {
        Vec::new()
    }

    /// The quadrature a stepper uses when none is named ([`Stepper::from_system`](crate::Stepper::from_system)):
    /// an `Err` when the model names an invalid one.
    fn quadrature(&self) -> Result<Quadrature, DiracError> {
        Ok(Quadrature::midpoint())
    }
}
