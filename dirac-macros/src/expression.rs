//! Rewrites a Lagrangian written like the mathematics into code generic over the scalar `__D`:
//! `dot(x)` becomes the velocity of `x`, `sin(x)` the method of the same name. Subexpressions of
//! parameters and literals alone stay `f64` (no dual-number work for them), and are combined with
//! state-dependent ones as `D op f64`. Every rewritten piece keeps the span of the user's tokens,
//! so type errors point at them.

use proc_macro2::{Literal, Span, TokenStream};
use quote::{format_ident, quote_spanned};
use syn::spanned::Spanned;
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
pub const BINARY: &[(&str, &str, bool)] = &[
    ("powi", "powi", false),
    ("powf", "powf", false),
    ("pow", "powd", true),
    ("atan2", "atan2", true),
];

/// The identifier bound to the velocity of coordinate `name`.
pub fn velocity_ident(name: &Ident) -> Ident {
    format_ident!("__dot_{}", name)
}

/// Whether a subexpression depends on the state (`Dual`: a `__D` value) or only on parameters
/// and literals (`Constant`: a plain `f64`, computed once without dual-number arithmetic).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    Constant,
    Dual,
}

/// Where an expression stands: which names are plain `f64` constants (parameters, and for forces
/// the inputs and `t`) and whether velocities `dot(...)` may appear.
pub struct Scope<'a> {
    pub coordinates: &'a [Coordinate],
    pub constants: &'a [Ident],
    /// `None` where velocities are allowed, else what to say when `dot(...)` appears.
    pub no_velocities: Option<&'static str>,
}

/// Rewrites `expr`; returns the new expression (of type `__D`) or every error found.
pub fn rewrite(expr: &Expr, scope: &Scope) -> Result<Expr, Vec<syn::Error>> {
    let mut rewriter = Rewriter {
        coordinates: scope.coordinates,
        parameters: scope.constants,
        no_velocities: scope.no_velocities,
        errors: Vec::new(),
    };
    let (expr, class) = rewriter.expr(expr);
    let expr = lift(expr, class);
    if rewriter.errors.is_empty() {
        Ok(expr)
    } else {
        Err(rewriter.errors)
    }
}

struct Rewriter<'a> {
    coordinates: &'a [Coordinate],
    parameters: &'a [Ident],
    no_velocities: Option<&'static str>,
    errors: Vec<syn::Error>,
}

/// A constant as a `__D` value; a dual expression unchanged.
fn lift(expr: Expr, class: Class) -> Expr {
    match class {
        Class::Dual => expr,
        Class::Constant => {
            let span = expr.span();
            syn::parse_quote_spanned!(span=> <__D as ::core::convert::From<f64>>::from(#expr))
        }
    }
}

impl Rewriter<'_> {
    fn coordinate(&self, ident: &Ident) -> Option<&Coordinate> {
        self.coordinates.iter().find(|c| c.name == *ident)
    }

    fn names(&self) -> String {
        self.coordinates
            .iter()
            .map(|c| format!("`{}`", c.name))
            .collect::<Vec<_>>()
            .join(", ")
    }

    fn error(
        &mut self,
        span: Span,
        message: impl std::fmt::Display,
        original: &Expr,
    ) -> (Expr, Class) {
        self.errors.push(syn::Error::new(span, message));
        (original.clone(), Class::Dual)
    }

    /// `dot(x)`, `dot(theta)` or `dot(theta[i])`.
    fn velocity(&mut self, call: &ExprCall, original: &Expr) -> (Expr, Class) {
        if let Some(message) = self.no_velocities {
            return self.error(call.span(), message, original);
        }
        if call.args.len() != 1 {
            let message = "dot(...) takes one coordinate, e.g. dot(x) or dot(theta[i])";
            return self.error(call.span(), message, original);
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
            return self.error(arg.span(), message, original);
        };
        let Some(coordinate) = self.coordinate(ident) else {
            let message = format!(
                "`{ident}` is not a coordinate; the coordinates are {}",
                self.names()
            );
            return self.error(ident.span(), message, original);
        };
        let velocity = Ident::new(&velocity_ident(&coordinate.name).to_string(), ident.span());
        match (index, coordinate.length.is_some()) {
            (Some(index), true) => (
                syn::parse_quote_spanned!(arg.span()=> #velocity[#index]),
                Class::Dual,
            ),
            (None, _) => (
                syn::parse_quote_spanned!(arg.span()=> #velocity),
                Class::Dual,
            ),
            (Some(_), false) => {
                let message = format!("`{ident}` is a single coordinate, not an array");
                self.error(arg.span(), message, original)
            }
        }
    }

    /// A known function applied to the right number of arguments, as a method call.
    fn function(&mut self, name: &str, call: &ExprCall, original: &Expr) -> (Expr, Class) {
        let span = call.func.span();
        if UNARY.contains(&name) {
            if call.args.len() != 1 {
                let message = format!("{name} takes one argument, got {}", call.args.len());
                return self.error(call.span(), message, original);
            }
            let (arg, class) = self.expr(&call.args[0]);
            let method = Ident::new(name, span);
            return (syn::parse_quote_spanned!(span=> (#arg).#method()), class);
        }
        let Some(&(_, method, scalar)) = BINARY.iter().find(|(n, _, _)| *n == name) else {
            return self.error(span, format!("unknown function `{name}`"), original);
        };
        if call.args.len() != 2 {
            let message = format!("{name} takes two arguments, got {}", call.args.len());
            return self.error(call.span(), message, original);
        }
        let (base, base_class) = self.expr(&call.args[0]);
        let method = Ident::new(method, span);
        if !scalar {
            // powi(x, n), powf(x, c): the exponent is an integer or a real constant, as written.
            let exponent = &call.args[1];
            return (
                syn::parse_quote_spanned!(span=> (#base).#method(#exponent)),
                base_class,
            );
        }
        let (other, other_class) = self.expr(&call.args[1]);
        if (base_class, other_class) == (Class::Constant, Class::Constant) {
            // Both constant: the f64 method (`pow` is `powf` on f64).
            let method = if name == "pow" {
                Ident::new("powf", span)
            } else {
                method
            };
            return (
                syn::parse_quote_spanned!(span=> (#base).#method(#other)),
                Class::Constant,
            );
        }
        let (base, other) = (lift(base, base_class), lift(other, other_class));
        (
            syn::parse_quote_spanned!(span=> (#base).#method(#other)),
            Class::Dual,
        )
    }

    /// `a op b` with constants kept in `f64` and every dual–constant pair written with the dual
    /// on the left (dual numbers implement `D op f64`, not `f64 op D`).
    fn binary(&mut self, b: &syn::ExprBinary, original: &Expr) -> (Expr, Class) {
        let (left, lc) = self.expr(&b.left);
        let (right, rc) = self.expr(&b.right);
        let op = &b.op;
        let span = b.op.span();
        let arithmetic = matches!(
            op,
            BinOp::Add(_) | BinOp::Sub(_) | BinOp::Mul(_) | BinOp::Div(_)
        );
        if matches!(op, BinOp::BitXor(_)) {
            let message = "`^` is exclusive or in Rust; write powers as powi(x, 2) or x.powi(2)";
            return self.error(span, message, original);
        }
        match (lc, rc) {
            (Class::Constant, Class::Constant) => (
                syn::parse_quote_spanned!(span=> #left #op #right),
                Class::Constant,
            ),
            (Class::Dual, Class::Constant) if arithmetic => (
                syn::parse_quote_spanned!(span=> #left #op #right),
                Class::Dual,
            ),
            (Class::Constant, Class::Dual) if arithmetic => {
                let expr = match op {
                    BinOp::Add(_) | BinOp::Mul(_) => {
                        syn::parse_quote_spanned!(span=> #right #op #left)
                    }
                    BinOp::Sub(_) => syn::parse_quote_spanned!(span=> -(#right) + #left),
                    _ => syn::parse_quote_spanned!(span=> (#right).recip() * #left),
                };
                (expr, Class::Dual)
            }
            _ => {
                let (left, right) = (lift(left, lc), lift(right, rc));
                (
                    syn::parse_quote_spanned!(span=> #left #op #right),
                    Class::Dual,
                )
            }
        }
    }

    /// Rewrites one expression and classifies it.
    fn expr(&mut self, expr: &Expr) -> (Expr, Class) {
        match expr {
            Expr::Lit(lit) => match scalar_literal(&lit.lit) {
                Some(Ok(e)) => (e, Class::Constant),
                Some(Err(e)) => {
                    self.errors.push(e);
                    (expr.clone(), Class::Constant)
                }
                None => (expr.clone(), Class::Dual),
            },
            Expr::Path(p) => {
                let constant = p
                    .path
                    .get_ident()
                    .is_some_and(|i| self.parameters.contains(i));
                (
                    expr.clone(),
                    if constant {
                        Class::Constant
                    } else {
                        Class::Dual
                    },
                )
            }
            Expr::Paren(p) => {
                let (inner, class) = self.expr(&p.expr);
                (syn::parse_quote_spanned!(p.span()=> (#inner)), class)
            }
            Expr::Group(g) => self.expr(&g.expr),
            Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => {
                let (inner, class) = self.expr(&u.expr);
                (syn::parse_quote_spanned!(u.span()=> -#inner), class)
            }
            Expr::Binary(b) => self.binary(b, expr),
            Expr::Call(call) => match callee(call).as_deref() {
                Some("dot") => self.velocity(call, expr),
                Some(name) if UNARY.contains(&name) || BINARY.iter().any(|b| b.0 == name) => {
                    self.function(name, call, expr)
                }
                _ => {
                    // A user function, generic over the scalar: its arguments are lifted.
                    let mut call = call.clone();
                    for arg in call.args.iter_mut() {
                        let (new, class) = self.expr(arg);
                        *arg = lift(new, class);
                    }
                    (Expr::Call(call), Class::Dual)
                }
            },
            // Arguments of methods keep their own types (`x.powi(2)`); the receiver decides.
            Expr::MethodCall(m) => {
                let (receiver, class) = self.expr(&m.receiver);
                let mut m = m.clone();
                *m.receiver = receiver;
                (Expr::MethodCall(m), class)
            }
            // `m[i]` of a parameter array is a constant, `theta[i]` of a coordinate array is not.
            Expr::Index(ix) => {
                let (_, class) = self.expr(&ix.expr);
                (expr.clone(), class)
            }
            _ => (expr.clone(), Class::Dual),
        }
    }
}

/// A numeric literal as an `f64` literal, spanned on the user's literal.
fn scalar_literal(lit: &Lit) -> Option<Result<Expr, syn::Error>> {
    let (value, span): (syn::Result<f64>, Span) = match lit {
        Lit::Float(f) => (f.base10_parse(), f.span()),
        Lit::Int(i) => (i.base10_parse::<i64>().map(|v| v as f64), i.span()),
        _ => return None,
    };
    Some(value.map(|value| {
        let mut literal = Literal::f64_suffixed(value);
        literal.set_span(span);
        syn::parse_quote_spanned!(span=> #literal)
    }))
}

/// Binds a coordinate's position and velocity (`__D`, or `[__D; K]` for an array) from `__q`, `__v`.
/// Without `velocities` only the position is bound (for one-forms and holonomic constraints).
pub fn bind_coordinate(
    coordinate: &Coordinate,
    offset: &TokenStream,
    velocities: bool,
) -> TokenStream {
    let name = &coordinate.name;
    let velocity = velocity_ident(name);
    let span = name.span();
    match (&coordinate.length, velocities) {
        (None, true) => quote_spanned! {span=>
            let #name: __D = __q[#offset];
            let #velocity: __D = __v[#offset];
        },
        (None, false) => quote_spanned!(span=> let #name: __D = __q[#offset];),
        (Some(length), velocities) => {
            let length = length.tokens();
            let velocity = velocities.then(|| quote_spanned! {span=>
                let #velocity: [__D; #length] = ::core::array::from_fn(|__i| __v[#offset + __i]);
            });
            quote_spanned! {span=>
                let #name: [__D; #length] = ::core::array::from_fn(|__i| __q[#offset + __i]);
                #velocity
            }
        }
    }
}
