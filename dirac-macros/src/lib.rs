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

// The reference and examples are a markdown file so that the facade, which re-exports the
// attribute, runs the examples as its doctests (this crate's doctests are off: see Cargo.toml).
#[doc = include_str!("dirac_system.md")]
#[proc_macro_attribute]
pub fn dirac_system(args: TokenStream, item: TokenStream) -> TokenStream {
    expand::dirac_system(args.into(), item.into()).into()
}

#[cfg(test)]
mod tests;
