//! The model as the attribute describes it, before validation.

use proc_macro2::{Span, TokenStream};
use syn::parse::{Parse, ParseStream};
use syn::punctuated::Punctuated;
use syn::{Expr, Ident, Token, bracketed};

/// Length of a coordinate array: a literal or the name of a constant (or const parameter).
#[derive(Clone)]
pub enum Length {
    Literal(usize, Span),
    Named(Ident),
}

impl Length {
    /// The length as an expression.
    pub fn tokens(&self) -> TokenStream {
        match self {
            Length::Literal(n, span) => quote::quote_spanned!(*span=> #n),
            Length::Named(ident) => quote::quote!(#ident),
        }
    }
}

/// One entry of `coordinates(...)`: `x` or `theta[8]`.
#[derive(Clone)]
pub struct Coordinate {
    pub name: Ident,
    pub length: Option<Length>,
}

impl Parse for Coordinate {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let name: Ident = input.parse().map_err(|e| {
            syn::Error::new(
                e.span(),
                "expected a coordinate: a name such as `x` or an array such as `theta[4]`",
            )
        })?;
        if !input.peek(syn::token::Bracket) {
            return Ok(Self { name, length: None });
        }
        let content;
        bracketed!(content in input);
        let length = match content.parse::<Expr>()? {
            Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Int(lit),
                ..
            }) => Length::Literal(lit.base10_parse()?, lit.span()),
            Expr::Path(p) if p.path.get_ident().is_some() => {
                Length::Named(p.path.get_ident().cloned().expect("checked above"))
            }
            other => {
                return Err(syn::Error::new_spanned(
                    other,
                    "an array length must be an integer literal or the name of a constant",
                ));
            }
        };
        Ok(Self {
            name,
            length: Some(length),
        })
    }
}

/// One term of a one-form: the coordinate's flat index and its coefficient (both expressions),
/// and the span of the user's term.
pub struct Term {
    pub index: TokenStream,
    pub coefficient: TokenStream,
    pub span: Span,
}

/// The attribute's arguments, each kept with its key for error reporting.
pub struct Arguments {
    pub entries: Vec<syn::Meta>,
}

impl Parse for Arguments {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let entries = Punctuated::<syn::Meta, Token![,]>::parse_terminated(input)?;
        Ok(Self {
            entries: entries.into_iter().collect(),
        })
    }
}

/// How the Lagrangian is given.
pub enum Lagrangian {
    /// An expression over coordinates, `dot(...)` velocities and parameters, rewritten to a `__D`.
    Expression(TokenStream),
    /// A generic function `fn(&Self, &SVector<D, N>, &SVector<D, N>) -> D`.
    Function(syn::Path),
}

/// A parameter field of the struct: `f64` or `[f64; K]`.
pub struct Parameter {
    pub name: Ident,
    pub array: bool,
}

/// Everything `expand` needs, validated; expressions already rewritten for the scalar `__D`.
pub struct Model {
    pub item: syn::ItemStruct,
    pub coordinates: Vec<Coordinate>,
    pub lagrangian: Lagrangian,
    pub quadrature: TokenStream,
    pub parameters: Vec<Parameter>,
    /// Constraint one-forms, each a list of terms.
    pub one_forms: Vec<Vec<Term>>,
    /// Holonomic constraints `g(q)`.
    pub holonomic: Vec<TokenStream>,
    /// Terms of all force one-forms together.
    pub forces: Vec<Term>,
    pub inputs: Vec<Ident>,
    /// `__dirac::ConstraintPoint::...` when `constraint_at` is given.
    pub constraint_point: Option<TokenStream>,
    /// The Lagrangian's derivatives in closed form, where the expression has them.
    pub closed_form: Option<crate::symbolic::ClosedForm>,
    /// Continuations of long chains, each emitted as a method of its own.
    pub parts: Vec<crate::expression::Part>,
    /// The path of the runtime crate (`crate = ...`, `::dirac` by default), bound to `__dirac`
    /// in the generated code.
    pub krate: syn::Path,
}

/// Number of coordinates as a const expression (a literal when every length is one).
pub fn dimension(coordinates: &[Coordinate]) -> TokenStream {
    // `None` also when the sum overflows: rustc then reports the overflow in the expression.
    let literal: Option<usize> = coordinates
        .iter()
        .try_fold(0usize, |sum, c| match &c.length {
            None => sum.checked_add(1),
            Some(Length::Literal(n, _)) => sum.checked_add(*n),
            Some(Length::Named(_)) => None,
        });
    match (literal, coordinates) {
        (Some(n), _) => quote::quote!(#n),
        (None, [single]) => single
            .length
            .as_ref()
            .map(Length::tokens)
            .unwrap_or_default(),
        (None, _) => {
            let terms = coordinates.iter().map(|c| {
                c.length
                    .as_ref()
                    .map_or(quote::quote!(1usize), Length::tokens)
            });
            quote::quote!({ 0usize #(+ #terms)* })
        }
    }
}

/// Offset of each coordinate in `q` (expressions).
pub fn offsets(coordinates: &[Coordinate]) -> Vec<TokenStream> {
    let mut offset = quote::quote!(0usize);
    coordinates
        .iter()
        .map(|c| {
            let this = offset.clone();
            let length = c
                .length
                .as_ref()
                .map_or(quote::quote!(1usize), Length::tokens);
            offset = quote::quote!(#offset + #length);
            this
        })
        .collect()
}
