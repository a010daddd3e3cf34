//! Checks the attribute and the struct, collecting every error with the span of the user's tokens.

use std::collections::HashSet;

use proc_macro2::{Span, TokenStream};
use quote::quote;
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::{Expr, Fields, GenericParam, Meta, Token, Type};

use crate::ast::{Arguments, Coordinate, Lagrangian, Length, Model, Parameter};
use crate::{expression, quadrature};

const KEYS: &str = "`coordinates(...)`, `lagrangian = ...` and `quadrature = ...`";

/// Collected errors; reported together.
#[derive(Default)]
pub struct Errors(Vec<syn::Error>);

impl Errors {
    pub fn push(&mut self, span: Span, message: impl std::fmt::Display) {
        self.0.push(syn::Error::new(span, message));
    }

    pub fn extend(&mut self, errors: Vec<syn::Error>) {
        self.0.extend(errors);
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn to_compile_errors(&self) -> TokenStream {
        self.0.iter().map(syn::Error::to_compile_error).collect()
    }
}

/// What validation produced: a model, or errors plus the coordinates when they were readable
/// (so a stub implementation can stop the errors from cascading into the user's code).
pub enum Outcome {
    Valid(Box<Model>),
    Invalid {
        errors: Errors,
        coordinates: Option<Vec<Coordinate>>,
    },
}

/// Validates the arguments against the struct.
pub fn model(arguments: Arguments, item: syn::ItemStruct) -> Outcome {
    let mut errors = Errors::default();
    let mut coordinates: Option<(Span, Vec<Coordinate>)> = None;
    let mut lagrangian: Option<(Span, Expr)> = None;
    let mut quadrature_expr: Option<(Span, Expr)> = None;
    for entry in arguments.entries {
        let key = entry
            .path()
            .get_ident()
            .map(|i| i.to_string())
            .unwrap_or_default();
        let span = entry.path().span();
        let duplicate = match key.as_str() {
            "coordinates" => coordinates.is_some(),
            "lagrangian" => lagrangian.is_some(),
            "quadrature" => quadrature_expr.is_some(),
            _ => false,
        };
        if duplicate {
            errors.push(span, format!("`{key}` is given twice"));
            continue;
        }
        match (key.as_str(), entry) {
            ("coordinates", Meta::List(list)) => {
                match list.parse_args_with(Punctuated::<Coordinate, Token![,]>::parse_terminated) {
                    Ok(list) => coordinates = Some((span, list.into_iter().collect())),
                    Err(e) => errors.0.push(e),
                }
            }
            ("lagrangian", Meta::NameValue(nv)) => lagrangian = Some((span, nv.value)),
            ("quadrature", Meta::NameValue(nv)) => quadrature_expr = Some((span, nv.value)),
            ("coordinates", other) => errors.push(
                other.span(),
                "write the coordinates as a list: coordinates(x, y, theta[8])",
            ),
            ("lagrangian" | "quadrature", other) => {
                errors.push(other.span(), format!("write `{key} = ...`"))
            }
            (_, other) => errors.push(
                other.path().span(),
                format!("unknown argument `{key}`; expected {KEYS}"),
            ),
        }
    }

    let parameters = parameters(&item, &mut errors);
    let coordinates = match coordinates {
        Some((span, list)) => {
            check_coordinates(span, &list, &parameters, &item, &mut errors);
            Some(list)
        }
        None => {
            errors.push(
                Span::call_site(),
                "missing `coordinates(...)`: name the coordinates, e.g. coordinates(x, theta[4])",
            );
            None
        }
    };
    let lagrangian = match (lagrangian, &coordinates) {
        (None, _) => {
            errors.push(Span::call_site(), "missing `lagrangian = ...`: an expression in the coordinates, dot(coordinate) and the parameters, or the path of a generic function");
            None
        }
        (Some((_, expr)), Some(coordinates)) => {
            lagrangian_of(expr, coordinates, &parameters, &mut errors)
        }
        (Some(_), None) => None,
    };
    let quadrature = match quadrature_expr {
        None => Some(quote!(::dirac::Quadrature::midpoint())),
        Some((_, expr)) => match quadrature::parse(&expr) {
            Ok(tokens) => Some(tokens),
            Err(e) => {
                errors.0.push(e);
                None
            }
        },
    };
    match (coordinates, lagrangian, quadrature) {
        (Some(coordinates), Some(lagrangian), Some(quadrature)) if errors.is_empty() => {
            Outcome::Valid(Box::new(Model {
                item,
                coordinates,
                lagrangian,
                quadrature,
                parameters,
            }))
        }
        (coordinates, ..) => Outcome::Invalid {
            errors,
            coordinates,
        },
    }
}

/// A bare path naming no coordinate or parameter is a function; anything else an expression.
fn lagrangian_of(
    expr: Expr,
    coordinates: &[Coordinate],
    parameters: &[Parameter],
    errors: &mut Errors,
) -> Option<Lagrangian> {
    if let Expr::Path(p) = &expr {
        let known = p.path.get_ident().is_some_and(|i| {
            coordinates.iter().any(|c| c.name == *i) || parameters.iter().any(|q| q.name == *i)
        });
        if !known {
            return Some(Lagrangian::Function(p.path.clone()));
        }
    }
    let names: Vec<_> = parameters.iter().map(|p| p.name.clone()).collect();
    match expression::rewrite(&expr, coordinates, &names) {
        Ok(expr) => Some(Lagrangian::Expression(expr)),
        Err(found) => {
            errors.extend(found);
            None
        }
    }
}

fn check_coordinates(
    span: Span,
    list: &[Coordinate],
    parameters: &[Parameter],
    item: &syn::ItemStruct,
    errors: &mut Errors,
) {
    if list.is_empty() {
        errors.push(span, "a system needs at least one coordinate");
    }
    let mut seen = HashSet::new();
    for c in list {
        if !seen.insert(c.name.to_string()) {
            errors.push(c.name.span(), format!("duplicate coordinate `{}`", c.name));
        }
        if parameters.iter().any(|p| p.name == c.name) {
            errors.push(
                c.name.span(),
                format!(
                    "`{}` is both a coordinate and a parameter field; rename one",
                    c.name
                ),
            );
        }
        if let Some(Length::Literal(0, span)) = &c.length {
            errors.push(*span, "a coordinate array needs at least one element");
        }
    }
    // A generic struct: the dimension must be one const parameter, not an expression of it.
    let const_params: Vec<_> = item
        .generics
        .params
        .iter()
        .filter_map(|g| match g {
            GenericParam::Const(c) => Some(c.ident.clone()),
            _ => None,
        })
        .collect();
    let generic_length = list.iter().find_map(|c| match &c.length {
        Some(Length::Named(n)) if const_params.contains(n) => Some(n.clone()),
        _ => None,
    });
    if let (Some(n), true) = (generic_length, list.len() > 1) {
        errors.push(
            n.span(),
            format!(
                "a system generic in `{n}` must have one coordinate array `name[{n}]`: \
                 stable Rust cannot size a vector by an expression of a const parameter"
            ),
        );
    }
}

/// The struct's fields, each `f64` or `[f64; K]`; other shapes are errors.
fn parameters(item: &syn::ItemStruct, errors: &mut Errors) -> Vec<Parameter> {
    for g in &item.generics.params {
        if !matches!(g, GenericParam::Const(_)) {
            errors.push(
                g.span(),
                "a system may be generic only in const parameters (e.g. the length of a chain)",
            );
        }
    }
    let fields = match &item.fields {
        Fields::Named(named) => &named.named,
        Fields::Unit => return Vec::new(),
        Fields::Unnamed(f) => {
            errors.push(
                f.span(),
                "parameters need names: use a struct with named fields",
            );
            return Vec::new();
        }
    };
    let is_f64 =
        |ty: &Type| matches!(ty, Type::Path(p) if p.qself.is_none() && p.path.is_ident("f64"));
    fields
        .iter()
        .filter_map(|field| {
            let name = field.ident.clone()?;
            match &field.ty {
                ty if is_f64(ty) => Some(Parameter { name, array: false }),
                Type::Array(a) if is_f64(&a.elem) => Some(Parameter { name, array: true }),
                other => {
                    errors.push(
                        other.span(),
                        format!("parameter `{name}` must be `f64` or `[f64; K]`: parameters are real numbers"),
                    );
                    None
                }
            }
        })
        .collect()
}
