//! The model as validation leaves it: everything `expand` needs, its expressions already
//! lowered.

use proc_macro2::{Ident, TokenStream};

use crate::internals::ast::{Coordinate, Lagrangian, Parameter, Term};
use crate::lower::expression::Part;
use crate::lower::symbolic::ClosedForm;

/// Everything `expand` needs, validated; expressions already rewritten for the scalar `__D`.
pub struct Model {
    pub item: syn::ItemStruct,
    pub coordinates: Vec<Coordinate>,
    /// The Lagrangian, or the Hamiltonian when `hamiltonian` (its second slot is then `p`).
    pub lagrangian: Lagrangian,
    /// Whether the model is given by a Hamiltonian (`impl HamiltonianSystem`).
    pub hamiltonian: bool,
    pub quadrature: TokenStream,
    /// The composition `quadrature = explicit(...)` names (`impl ExplicitSystem`).
    pub explicit: Option<TokenStream>,
    pub parameters: Vec<Parameter>,
    /// Constraint one-forms, each a list of terms.
    pub one_forms: Vec<Vec<Term>>,
    /// Whether each one-form's coefficients name no coordinate (the same covector at every `q`).
    pub constant_one_forms: Vec<bool>,
    /// The bodies of `one_form_with_derivative`, one per one-form, where every one-form has
    /// them in closed form.
    pub one_form_derivatives: Option<Vec<proc_macro2::TokenStream>>,
    /// Each one-form as written, for error messages.
    pub one_form_names: Vec<String>,
    /// Holonomic constraints `g(q)`.
    pub holonomic: Vec<TokenStream>,
    /// Terms of all force one-forms together.
    pub forces: Vec<Term>,
    /// Whether no force reads a velocity (`dot(x)`, `omega(R)`): the forces are functions of
    /// the positions, the time and the inputs alone.
    pub forces_free_of_velocity: bool,
    /// Whether the forces are affine in the positions and velocities with constant
    /// coefficients (`F = K q + D v + f(t, u)`): their part of a step's Jacobian never changes.
    pub forces_affine: bool,
    pub inputs: Vec<Ident>,
    /// `__dirac::ConstraintPoint::...` when `constraint_at` is given.
    pub constraint_point: Option<TokenStream>,
    /// The Lagrangian's derivatives in closed form, where the expression has them.
    pub closed_form: Option<ClosedForm>,
    /// Continuations of long chains, each emitted as a method of its own.
    pub parts: Vec<Part>,
    /// Constant items asserting indices rustc checks, emitted beside the struct.
    pub index_checks: Vec<TokenStream>,
    /// The path of the runtime crate (`crate = ...`, `::dirac` by default), bound to `__dirac`
    /// in the generated code.
    pub krate: syn::Path,
}
