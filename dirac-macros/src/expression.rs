//! Rewrites a Lagrangian written like the mathematics into code generic over the scalar `__D`:
//! `dot(x)` becomes the velocity of `x`, `sin(x)` the dual-number method, numeric literals
//! `__D` values. Every rewritten piece keeps the span of the user's tokens, so type errors point
//! at them.

use proc_macro2::{Literal, Span, TokenStream};
use quote::{format_ident, quote_spanned};
use syn::spanned::Spanned;
use syn::visit_mut::{self, VisitMut};
use syn::{BinOp, Expr, ExprCall, Ident, Lit};

use crate::ast::Coordinate;
use crate::quadrature::callee;

/// Functions of one argument, mapped to the method of the same name on dual numbers.
pub const UNARY: &[&str] = &[
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh",
    "exp", "exp2", "exp_m1", "ln", "ln_1p", "log2", "log10", "sqrt", "cbrt", "recip", "abs",
];

/// Functions of two arguments: (name, method, whether the second argument is a scalar of the
/// Lagrangian (`true`) or kept as written (an `i32` or `f64` constant, `false`)).
pub const BINARY: &[(&str, &str, bool)] =
    &[("powi", "powi", false), ("powf", "powf", false), ("pow", "powd", true), ("atan2", "atan2", true)];

/// The identifier bound to the velocity of coordinate `name`.
pub fn velocity_ident(name: &Ident) -> Ident {
    format_ident!("__dot_{}", name)
}

/// Rewrites `expr` in place; returns the errors found (all of them).
pub fn rewrite(expr: &mut Expr, coordinates: &[Coordinate]) -> Vec<syn::Error> {
    let mut rewriter = Rewriter { coordinates, errors: Vec::new() };
    rewriter.visit_expr_mut(expr);
    rewriter.errors
}

struct Rewriter<'a> {
    coordinates: &'a [Coordinate],
    errors: Vec<syn::Error>,
}

impl Rewriter<'_> {
    fn coordinate(&self, ident: &Ident) -> Option<&Coordinate> {
        self.coordinates.iter().find(|c| c.name == *ident)
    }

    fn names(&self) -> String {
        self.coordinates.iter().map(|c| format!("`{}`", c.name)).collect::<Vec<_>>().join(", ")
    }

    /// `dot(x)`, `dot(theta)` or `dot(theta[i])`.
    fn velocity(&mut self, call: &ExprCall) -> Option<Expr> {
        if call.args.len() != 1 {
            let message = "dot(...) takes one coordinate, e.g. dot(x) or dot(theta[i])";
            self.errors.push(syn::Error::new(call.span(), message));
            return None;
        }
        let arg = &call.args[0];
        let (ident, index) = match arg {
            Expr::Path(p) => (p.path.get_ident(), None),
            Expr::Index(ix) => match &*ix.expr {
                Expr::Path(p) => (p.path.get_ident(), Some(&ix.index)),
                _ => (None, None),
            },
            _ => (None, None),
        };
        let Some(ident) = ident else {
            let message = format!("dot(...) takes a coordinate, one of {}", self.names());
            self.errors.push(syn::Error::new(arg.span(), message));
            return None;
        };
        let Some(coordinate) = self.coordinate(ident) else {
            let message =
                format!("`{ident}` is not a coordinate; the coordinates are {}", self.names());
            self.errors.push(syn::Error::new(ident.span(), message));
            return None;
        };
        let velocity = velocity_ident(&coordinate.name);
        let velocity = Ident::new(&velocity.to_string(), ident.span());
        match (index, coordinate.length.is_some()) {
            (Some(index), true) => Some(syn::parse_quote_spanned!(arg.span()=> #velocity[#index])),
            (None, _) => Some(syn::parse_quote_spanned!(arg.span()=> #velocity)),
            (Some(_), false) => {
                let message = format!("`{ident}` is a single coordinate, not an array");
                self.errors.push(syn::Error::new(arg.span(), message));
                None
            }
        }
    }

    /// A known function applied to the right number of arguments, as a method call.
    fn function(&mut self, name: &str, call: &mut ExprCall) -> Option<Expr> {
        let span = call.func.span();
        if UNARY.contains(&name) {
            if call.args.len() != 1 {
                let message = format!("{name} takes one argument, got {}", call.args.len());
                self.errors.push(syn::Error::new(call.span(), message));
                return None;
            }
            let mut arg = call.args[0].clone();
            self.visit_expr_mut(&mut arg);
            let method = Ident::new(name, span);
            return Some(syn::parse_quote_spanned!(span=> (#arg).#method()));
        }
        let &(_, method, scalar) = BINARY.iter().find(|(n, _, _)| *n == name)?;
        if call.args.len() != 2 {
            let message = format!("{name} takes two arguments, got {}", call.args.len());
            self.errors.push(syn::Error::new(call.span(), message));
            return None;
        }
        let mut base = call.args[0].clone();
        let mut exponent = call.args[1].clone();
        self.visit_expr_mut(&mut base);
        if scalar {
            self.visit_expr_mut(&mut exponent);
        }
        let method = Ident::new(method, span);
        Some(syn::parse_quote_spanned!(span=> (#base).#method(#exponent)))
    }
}

/// A numeric literal as a value of the scalar type, spanned on the literal.
fn scalar_literal(lit: &Lit) -> Option<Result<Expr, syn::Error>> {
    let (value, span): (syn::Result<f64>, Span) = match lit {
        Lit::Float(f) => (f.base10_parse(), f.span()),
        Lit::Int(i) => (i.base10_parse::<i64>().map(|v| v as f64), i.span()),
        _ => return None,
    };
    Some(value.map(|value| {
        let mut literal = Literal::f64_suffixed(value);
        literal.set_span(span);
        syn::parse_quote_spanned!(span=> <__D as ::core::convert::From<f64>>::from(#literal))
    }))
}

impl VisitMut for Rewriter<'_> {
    fn visit_expr_mut(&mut self, expr: &mut Expr) {
        let replacement = match expr {
            Expr::Lit(lit) => match scalar_literal(&lit.lit) {
                Some(Ok(e)) => Some(e),
                Some(Err(e)) => {
                    self.errors.push(e);
                    None
                }
                None => None,
            },
            Expr::Call(call) => match callee(call).as_deref() {
                Some("dot") => self.velocity(call),
                Some(name) if UNARY.contains(&name) || BINARY.iter().any(|b| b.0 == name) => {
                    self.function(name, call)
                }
                _ => {
                    visit_mut::visit_expr_call_mut(self, call);
                    None
                }
            },
            // Arguments of methods keep their own types (`x.powi(2)`), indices stay integers,
            // ranges stay ranges.
            Expr::MethodCall(m) => {
                self.visit_expr_mut(&mut m.receiver);
                None
            }
            Expr::Index(ix) => {
                self.visit_expr_mut(&mut ix.expr);
                None
            }
            Expr::Range(_) | Expr::Macro(_) => None,
            Expr::Binary(b) if matches!(b.op, BinOp::BitXor(_)) => {
                let message = "`^` is exclusive or in Rust; write powers as powi(x, 2) or x.powi(2)";
                self.errors.push(syn::Error::new(b.op.span(), message));
                None
            }
            _ => {
                visit_mut::visit_expr_mut(self, expr);
                None
            }
        };
        if let Some(new) = replacement {
            *expr = new;
        }
    }
}

/// Binds a coordinate's position and velocity (`__D`, or `[__D; K]` for an array) from `__q`, `__v`.
pub fn bind_coordinate(coordinate: &Coordinate, offset: &TokenStream) -> TokenStream {
    let name = &coordinate.name;
    let velocity = velocity_ident(name);
    let span = name.span();
    match &coordinate.length {
        None => quote_spanned! {span=>
            let #name: __D = __q[#offset];
            let #velocity: __D = __v[#offset];
        },
        Some(length) => {
            let length = length.tokens();
            quote_spanned! {span=>
                let #name: [__D; #length] = ::core::array::from_fn(|__i| __q[#offset + __i]);
                let #velocity: [__D; #length] = ::core::array::from_fn(|__i| __v[#offset + __i]);
            }
        }
    }
}
