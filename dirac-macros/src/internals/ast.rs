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

/// What a coordinate is: a real number, a rotation (`SO3`) or a unit vector (`S2`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Real,
    Rotation,
    Direction,
}

/// One entry of `coordinates(...)`: `x`, `theta[8]`, `R: SO3`, `n: S2` or `bodies[3]: SO3`.
#[derive(Clone)]
pub struct Coordinate {
    pub name: Ident,
    pub length: Option<Length>,
    pub kind: Kind,
}

impl Coordinate {
    /// Whether it is a rotation or a unit vector.
    pub fn is_group(&self) -> bool {
        self.kind != Kind::Real
    }
}

const SPACES: &str = "a coordinate is real (`x`), a rotation (`R: SO3`) or a unit vector (`n: S2`)";

impl Parse for Coordinate {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let name: Ident = input.parse().map_err(|e| {
            syn::Error::new(
                e.span(),
                "expected a coordinate: a name such as `x`, an array such as `theta[4]`, or a \
                 rotation or unit vector such as `R: SO3`, `n: S2`",
            )
        })?;
        let length = match input.peek(syn::token::Bracket) {
            true => Some(Self::length(input)?),
            false => None,
        };
        let kind = match input.peek(Token![:]) {
            false => Kind::Real,
            true => {
                input.parse::<Token![:]>()?;
                let space: Ident = input.parse().map_err(|e| {
                    syn::Error::new(e.span(), format!("expected `SO3` or `S2`: {SPACES}"))
                })?;
                match space.to_string().as_str() {
                    "SO3" => Kind::Rotation,
                    "S2" => Kind::Direction,
                    other => {
                        return Err(syn::Error::new(
                            space.span(),
                            format!("unknown space `{other}`: {SPACES}"),
                        ));
                    }
                }
            }
        };
        Ok(Self { name, length, kind })
    }
}

impl Coordinate {
    /// `[n]` after a coordinate's name.
    fn length(input: ParseStream) -> syn::Result<Length> {
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
        Ok(length)
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

/// A parameter field of the struct: `f64`, `[f64; K]` or `[[f64; C]; R]`.
pub struct Parameter {
    pub name: Ident,
    pub shape: Shape,
}

/// The shape of a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    Scalar,
    /// `[f64; K]`, with `K` when it is a literal (a 3-vector where `K = 3`).
    Array(Option<usize>),
    /// `[[f64; C]; R]`, with `(R, C)` when both are literals (a matrix where both are 3).
    Matrix(Option<(usize, usize)>),
}

/// Number of coordinates as a const expression (a literal when every length is one). A rotation
/// has three chart coordinates and a unit vector two.
pub fn dimension(coordinates: &[Coordinate]) -> TokenStream {
    let width = |c: &Coordinate| match c.kind {
        Kind::Real => 1,
        Kind::Rotation => 3,
        Kind::Direction => 2,
    };
    // `None` also when the sum overflows: rustc then reports the overflow in the expression.
    let literal: Option<usize> = coordinates
        .iter()
        .try_fold(0usize, |sum, c| match &c.length {
            None => sum.checked_add(width(c)),
            Some(Length::Literal(n, _)) => sum.checked_add(n.checked_mul(width(c))?),
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

/// Where each coordinate starts among those of its kind (expressions): a real coordinate's index
/// in `q` (on a product, in its vector part), a rotation's or unit vector's index among the
/// rotations or unit vectors.
pub fn offsets(coordinates: &[Coordinate]) -> Vec<TokenStream> {
    let mut next =
        [Kind::Real, Kind::Rotation, Kind::Direction].map(|k| (k, quote::quote!(0usize)));
    coordinates
        .iter()
        .map(|c| {
            let (_, offset) = next
                .iter_mut()
                .find(|(k, _)| *k == c.kind)
                .expect("every kind has a counter");
            let this = offset.clone();
            let length = c
                .length
                .as_ref()
                .map_or(quote::quote!(1usize), Length::tokens);
            *offset = quote::quote!(#offset + #length);
            this
        })
        .collect()
}

/// Each coordinate's index among those of its kind (the first element's, for an array): where a
/// rotation or unit vector sits in a product point. Named lengths count 0 (they are refused on
/// products, and real coordinates do not use the index).
pub fn kind_indices(coordinates: &[Coordinate]) -> Vec<usize> {
    let mut next = [
        (Kind::Real, 0usize),
        (Kind::Rotation, 0),
        (Kind::Direction, 0),
    ];
    coordinates
        .iter()
        .map(|c| {
            let (_, index) = next
                .iter_mut()
                .find(|(k, _)| *k == c.kind)
                .expect("every kind has a counter");
            let this = *index;
            // Saturating: real arrays may be as long as `usize` allows (rustc then refuses
            // them), and their indices are not used.
            *index = index.saturating_add(match c.length {
                None => 1,
                Some(Length::Literal(n, _)) => n,
                Some(Length::Named(_)) => 0,
            });
            this
        })
        .collect()
}

/// The sizes `(K, A, B)` of a product model: its real coordinates, rotations and unit vectors
/// (every length a literal: checked before).
pub fn product_sizes(coordinates: &[Coordinate]) -> (usize, usize, usize) {
    let count = |kind: Kind| {
        coordinates
            .iter()
            .filter(|c| c.kind == kind)
            .map(|c| match &c.length {
                Some(Length::Literal(n, _)) => *n,
                _ => 1,
            })
            .fold(0, usize::saturating_add)
    };
    (
        count(Kind::Real),
        count(Kind::Rotation),
        count(Kind::Direction),
    )
}
