//! The names the generated code binds for the entries of rotations and unit vectors and for
//! differentials (the atoms): made by the vector algebra, recognised by the scalar rewriter and
//! the one-form splitter.

use proc_macro2::{Ident, Span};

/// The prefix of the atoms' names (reserved: users cannot write names starting with `__`).
pub const ATOM: &str = "__g";

/// The prefix of a differential atom's name, followed by its index among a tangent vector's
/// numbers (`Rates`' order).
pub const DIFFERENTIAL: &str = "__gd_";

/// The name of an atom: `what` (`R` for a rotation's entry, `W` for its angular velocity, `S`
/// for a unit vector's component, `V` for its velocity) of the rotation or unit vector with
/// index `element` among those of its kind, at `indices`. Numbers only after the prefix: no two
/// coordinates' atoms can share a name, whatever the coordinates are called.
pub fn atom(what: &str, element: usize, indices: &[usize], span: Span) -> Ident {
    let indices: String = indices.iter().map(|i| format!("_{i}")).collect();
    Ident::new(&format!("{ATOM}{what}{element}{indices}"), span)
}

/// Whether `ident` is an atom the generated code binds.
pub fn is_atom(ident: &Ident) -> bool {
    ident.to_string().starts_with(ATOM)
}

/// The index among a tangent vector's numbers of a differential atom.
pub fn differential_index(ident: &Ident) -> Option<usize> {
    ident.to_string().strip_prefix(DIFFERENTIAL)?.parse().ok()
}
