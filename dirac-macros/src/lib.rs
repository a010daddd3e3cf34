//! The `#[dirac_system(...)]` attribute. It parses the model ([`ast`]), checks it and collects
//! every error with its span ([`validate`]), rewrites the Lagrangian into generic scalar code
//! ([`expression`]) and implements `dirac::DiracSystem` ([`expand`]). It never panics on input.

use proc_macro::TokenStream;

mod ast;
mod expand;
mod expression;
mod quadrature;
mod validate;

/// Turns a struct of parameters into a `dirac::DiracSystem`.
///
/// ```ignore
/// #[dirac_system(
///     coordinates(theta1, theta2),
///     lagrangian = 0.5 * m * dot(theta1).powi(2) + m * g * l * cos(theta1) + ...,
///     quadrature = galerkin(2),
/// )]
/// struct DoublePendulum { m: f64, l: f64, g: f64 }
/// ```
///
/// See the `dirac` crate for the full syntax.
#[proc_macro_attribute]
pub fn dirac_system(args: TokenStream, item: TokenStream) -> TokenStream {
    expand::dirac_system(args.into(), item.into()).into()
}
