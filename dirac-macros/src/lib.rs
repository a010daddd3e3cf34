//! The `#[dirac_system(...)]` attribute, in four layers, each using only those below it:
//! `internals` (the attribute's syntax as parsed, and the error collector every stage pushes
//! into), `lower` (the Lagrangian and the one-forms rewritten into generic scalar code, vectors
//! and matrices lowered to their entries, closed-form derivatives where the expression allows,
//! the quadrature), `check` (the attribute and the struct validated into a model, every error
//! collected with its span) and `expand` (the `impl dirac::DiracSystem`). It never panics on
//! input.

use proc_macro::TokenStream;

mod check;
mod expand;
mod internals;
mod lower;

/// Turns a struct of parameters into a `dirac::DiracSystem`.
///
/// Arguments, in any order:
/// - `coordinates(x, y, theta[8])`: the coordinates, single or arrays (an array length is a
///   literal, a constant, or the struct's const parameter); `R: SO3` is a rotation and `n: S2` a
///   unit vector (arrays of them too, `links[3]: SO3`, with literal lengths): the model is then
///   on a `Product` of vectors, rotations and unit vectors, and its expressions may use 3-vectors
///   and 3×3 matrices (`R`, `omega(R)` the body angular velocity, `dot(R)`, `n`, `dot(n)`,
///   `omega(n)`, parameters `[f64; 3]` and `[[f64; 3]; 3]`, `[a, b, c]`, `+ - * /`, `dot`,
///   `cross`, `transpose`, `trace`, `norm`, `v[i]`, `M[i][j]`), and one-forms and forces the
///   differentials `dR` (paired with `Ω`) and `dn`;
/// - `lagrangian = EXPR`: the Lagrangian in the coordinates, their velocities `dot(x)`,
///   `dot(theta[i])`, and the fields (parameters, `f64` or `[f64; K]`), with `+ - * /`, numeric
///   literals, `sin cos tan asin acos atan sinh cosh tanh asinh acosh atanh exp exp2 exp_m1 ln
///   ln_1p log2 log10 sqrt cbrt recip abs` of one argument, `powi(x, n)`, `powf(x, c)`,
///   `pow(x, y)`, `atan2(y, x)`, and methods of the same names (`dot(x).powi(2)`);
///   or `lagrangian = path::to::function`, a generic
///   `fn<D: Scalar>(&Model, &SVector<D, N>, &SVector<D, N>) -> D` for big models (with rotations
///   or unit vectors `fn<D: Scalar>(&Model, &Configuration<D, K, A, B>, &Rates<D, K, A, B>) -> D`);
/// - `quadrature = midpoint | trapezoid | galerkin(s) | galerkin(s, gauss_legendre(r)) |
///   galerkin(s, gauss_lobatto(r))`: the default quadrature (`midpoint` if omitted);
/// - `subsystems(a, b, ...)` and `junctions(name = a.dx - 2.0 * b.c.dy, ...)`, instead of the
///   arguments above: the struct's fields `a, b, ...` are `#[dirac_system]` models, and the
///   struct is their interconnection (the sum of their Lagrangians, their constraints, forces
///   and inputs, and the junctions: constant one-forms over `instance.dcoordinate`, written with
///   number literals, `instance.sub.dx` inside a subsystem made of subsystems);
/// - `crate = path`: where the generated code finds the runtime (`::dirac` by default;
///   `crate = dirac_runtime` for a crate that depends on `dirac-runtime` and `dirac-macros`
///   directly).
///
/// Every malformed input is a compile error on the offending tokens.
///
/// ```
/// use dirac::prelude::*;
///
/// #[dirac_system(
///     coordinates(theta1, theta2),
///     lagrangian = 0.5 * (m1 + m2) * l1 * l1 * dot(theta1).powi(2)
///         + 0.5 * m2 * l2 * l2 * dot(theta2).powi(2)
///         + m2 * l1 * l2 * dot(theta1) * dot(theta2) * cos(theta1 - theta2)
///         + (m1 + m2) * g * l1 * cos(theta1)
///         + m2 * g * l2 * cos(theta2),
///     quadrature = galerkin(2),
/// )]
/// struct DoublePendulum { m1: f64, m2: f64, l1: f64, l2: f64, g: f64 }
///
/// let model = DoublePendulum { m1: 1.0, m2: 1.0, l1: 1.0, l2: 1.0, g: 9.81 };
/// assert_eq!(model.coordinate_name(1), "theta2");
/// let mut stepper = Stepper::from_system(model, 0.01)?;
/// stepper.start_from_velocity(vector![0.5, 0.0], vector![0.0, 0.0])?;
/// stepper.run(100)?;
/// # Ok::<(), DiracError>(())
/// ```
/// A rotation works the same way:
///
/// ```
/// use dirac::prelude::*;
///
/// /// A heavy top: L = ½ Ωᵀ J Ω − m g e₃ᵀ R ρ.
/// #[dirac_system(
///     coordinates(R: SO3),
///     lagrangian = 0.5 * dot(omega(R), j * omega(R)) - m * g * dot([0.0, 0.0, 1.0], R * rho),
/// )]
/// struct Top { j: [[f64; 3]; 3], m: f64, g: f64, rho: [f64; 3] }
///
/// let top = Top { j: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]], m: 1.0, g: 9.81, rho: [0.0, 0.0, 0.3] };
/// let mut stepper = Stepper::on_manifold(top, Product::cayley(), Quadrature::midpoint(), 0.01)?;
/// let tilted = Retraction::Exp.map(&Vector3::new(0.4, 0.0, 0.0));
/// stepper.start_from_velocity(Configuration::of_rotation(tilted), Rates::of_rotation(Vector3::new(0.0, 0.0, 20.0)))?;
/// stepper.run(100)?;
/// # Ok::<(), DiracError>(())
/// ```
#[proc_macro_attribute]
pub fn dirac_system(args: TokenStream, item: TokenStream) -> TokenStream {
    expand::dirac_system(args.into(), item.into()).into()
}

#[cfg(test)]
mod tests;
