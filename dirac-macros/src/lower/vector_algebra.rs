//! Vectors and 3×3 matrices in the expressions of a model on rotations and unit vectors.
//!
//! A rotation `R` (`R: SO3`) is a 3×3 matrix (body axes to space axes), `omega(R)` its body
//! angular velocity `Ω` and `dot(R)` its rate `R Ω̂`; a unit vector `n` (`n: S2`) and `dot(n)` are
//! 3-vectors, and `omega(n)` is `n × ṅ`. A parameter `[f64; 3]` is a vector where it is used
//! whole, `[[f64; 3]; 3]` a matrix, and `[a, b, c]` a vector. The operations are `+ -` of equal
//! shapes, `*` of a number and anything and of a matrix and a vector or matrix, `/` by a number,
//! unary `-`, `dot(u, v)`, `cross(u, v)`, `transpose(M)`, `trace(M)`, `norm(v)`,
//! `norm_squared(v)` (and the methods of the same names, `u.dot(v)`), and `v[i]`, `M[i][j]` with
//! integer literals. In one-forms and forces `dR` is the body angular differential (paired with
//! `Ω`: `dot(a, dR)` is the one-form `a·Ω`) and `dn` the unit vector's differential.
//!
//! Each expression is lowered, component by component, to scalar expressions over the entries
//! the generated code binds (the atoms, named by [`atom`]), which the scalar rewriter then emits
//! like any other expression; only a scalar may remain at the top.

use proc_macro2::Span;
use syn::spanned::Spanned;
use syn::{BinOp, Expr, Ident, Lit, UnOp, parse_quote_spanned};

use crate::internals::ast::{Coordinate, Kind, Length, Parameter, Shape};
use crate::internals::errors::Errors;
use crate::lower::atom::{DIFFERENTIAL, atom};
use crate::lower::expression::{Family, MAX_NESTING, bounds, is_reserved, reserved_message, spine};

/// A value of an expression: a number, a 3-vector or a 3×3 matrix, each entry a scalar
/// expression (values live while one expression is lowered; they are not boxed).
#[derive(Clone)]
#[allow(clippy::large_enum_variant)]
enum Value {
    Scalar(Expr),
    Vector([Expr; 3]),
    Matrix([[Expr; 3]; 3]),
    /// A subexpression with an error, already reported: what contains it reports nothing more.
    Invalid,
}

impl Value {
    fn shape(&self) -> &'static str {
        match self {
            Value::Scalar(_) => "a number",
            Value::Vector(_) => "a 3-vector",
            Value::Matrix(_) => "a 3×3 matrix",
            Value::Invalid => "invalid",
        }
    }
}

/// Where an expression stands.
pub struct Algebra<'a> {
    pub coordinates: &'a [Coordinate],
    pub parameters: &'a [Parameter],
    /// `None` where velocities may appear, else what to say when one does.
    pub no_velocities: Option<&'static str>,
    /// Whether differentials may appear (one-forms, forces).
    pub differentials: bool,
}

/// Lowers `expr` to one scalar expression; `None` after an error (pushed into `errors`).
pub fn lower(expr: &Expr, algebra: &Algebra, errors: &mut Errors) -> Option<Expr> {
    let before = errors.len();
    let mut lowering = Lowering {
        algebra,
        errors,
        too_deep: false,
    };
    let value = lowering.value(expr, 0);
    if lowering.errors.len() > before {
        return None;
    }
    match value {
        Value::Scalar(e) => Some(e),
        Value::Invalid => None,
        other => {
            let (start, end) = bounds(expr);
            errors.push_range(
                start,
                end,
                format!(
                    "this is {}, where a number is needed (take a component, dot(u, v), \
                     trace(M) or norm(v))",
                    other.shape()
                ),
            );
            None
        }
    }
}

/// A group coordinate's element: the coordinate, the element of an array, and its index among the
/// coordinates of its kind.
type Element = (Coordinate, Option<usize>, usize);

struct Lowering<'a, 'e> {
    algebra: &'a Algebra<'a>,
    errors: &'e mut Errors,
    too_deep: bool,
}

/// The literal `0.0`.
fn zero(span: Span) -> Expr {
    parse_quote_spanned!(span=> 0.0)
}

fn is_zero(e: &Expr) -> bool {
    matches!(e, Expr::Lit(l) if matches!(&l.lit, Lit::Float(f) if f.base10_digits() == "0"))
}

/// `e` in parentheses where it is a binary operation (an operand of `*`, `/` or unary `-`).
fn operand(e: Expr) -> Expr {
    match e {
        Expr::Binary(_) => Expr::Paren(syn::ExprParen {
            attrs: Vec::new(),
            paren_token: Default::default(),
            expr: Box::new(e),
        }),
        other => other,
    }
}

fn product(a: &Expr, b: &Expr, span: Span) -> Expr {
    if is_zero(a) || is_zero(b) {
        return zero(span);
    }
    let (a, b) = (operand(a.clone()), operand(b.clone()));
    parse_quote_spanned!(span=> #a * #b)
}

fn quotient(a: &Expr, b: &Expr, span: Span) -> Expr {
    if is_zero(a) {
        return zero(span);
    }
    let (a, b) = (operand(a.clone()), operand(b.clone()));
    parse_quote_spanned!(span=> #a / #b)
}

fn negated(a: &Expr, span: Span) -> Expr {
    if is_zero(a) {
        return zero(span);
    }
    let a = operand(a.clone());
    parse_quote_spanned!(span=> -#a)
}

/// `Σ ± terms`, zeros left out.
fn sum(terms: impl IntoIterator<Item = (bool, Expr)>, span: Span) -> Expr {
    let mut out: Option<Expr> = None;
    for (minus, term) in terms {
        if is_zero(&term) {
            continue;
        }
        // A sum as a later term is parenthesised: `a - (b + c)`.
        let term = match term {
            Expr::Binary(b) if matches!(b.op, BinOp::Add(_) | BinOp::Sub(_)) => {
                operand(Expr::Binary(b))
            }
            other => other,
        };
        out = Some(match (out, minus) {
            (None, false) => term,
            (None, true) => negated(&term, span),
            (Some(acc), false) => parse_quote_spanned!(span=> #acc + #term),
            (Some(acc), true) => parse_quote_spanned!(span=> #acc - #term),
        });
    }
    out.unwrap_or_else(|| zero(span))
}

fn dot(u: &[Expr; 3], v: &[Expr; 3], span: Span) -> Expr {
    sum((0..3).map(|i| (false, product(&u[i], &v[i], span))), span)
}

fn cross(u: &[Expr; 3], v: &[Expr; 3], span: Span) -> [Expr; 3] {
    std::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        sum(
            [
                (false, product(&u[j], &v[k], span)),
                (true, product(&u[k], &v[j], span)),
            ],
            span,
        )
    })
}

fn matrix_vector(m: &[[Expr; 3]; 3], v: &[Expr; 3], span: Span) -> [Expr; 3] {
    std::array::from_fn(|i| dot(&m[i], v, span))
}

fn matrix_matrix(a: &[[Expr; 3]; 3], b: &[[Expr; 3]; 3], span: Span) -> [[Expr; 3]; 3] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            sum(
                (0..3).map(|k| (false, product(&a[i][k], &b[k][j], span))),
                span,
            )
        })
    })
}

/// `ŵ`, the matrix of `w ×`.
fn hat(w: &[Expr; 3], span: Span) -> [[Expr; 3]; 3] {
    let z = || zero(span);
    [
        [z(), negated(&w[2], span), w[1].clone()],
        [w[2].clone(), z(), negated(&w[0], span)],
        [negated(&w[1], span), w[0].clone(), z()],
    ]
}

/// The integer literal `e`, if it is one.
fn literal_index(e: &Expr) -> Option<usize> {
    match e {
        Expr::Lit(syn::ExprLit {
            lit: Lit::Int(i), ..
        }) => i.base10_parse().ok(),
        _ => None,
    }
}

fn path_ident(e: &Expr) -> Option<&Ident> {
    match e {
        Expr::Path(p) if p.qself.is_none() => p.path.get_ident(),
        _ => None,
    }
}

impl Lowering<'_, '_> {
    fn error(&mut self, span: Span, message: impl std::fmt::Display) -> Value {
        self.errors.push(span, message);
        Value::Invalid
    }

    fn error_on(&mut self, expr: &Expr, message: impl std::fmt::Display) -> Value {
        let (start, end) = bounds(expr);
        self.errors.push_range(start, end, message);
        Value::Invalid
    }

    fn coordinate(&self, ident: &Ident) -> Option<&Coordinate> {
        self.algebra.coordinates.iter().find(|c| c.name == *ident)
    }

    /// The group coordinate (rotation or unit vector) named `ident`, with its index among those
    /// of its kind.
    fn group(&self, ident: &Ident) -> Option<(&Coordinate, usize)> {
        let coordinate = self.coordinate(ident).filter(|c| c.is_group())?;
        let before: usize = self
            .algebra
            .coordinates
            .iter()
            .take_while(|c| c.name != *ident)
            .filter(|c| c.kind == coordinate.kind)
            .map(length)
            .fold(0, usize::saturating_add);
        Some((coordinate, before))
    }

    /// A group coordinate named by `expr` (`R` or `bodies[1]`): the coordinate, the element of
    /// an array, and its index among those of its kind. `None` when `expr` names none; an error
    /// (pushed) for a bad element.
    fn group_element(&mut self, expr: &Expr) -> Option<Result<Element, ()>> {
        let (ident, index) = match expr {
            Expr::Index(ix) => (path_ident(&ix.expr)?, Some(&*ix.index)),
            other => (path_ident(other)?, None),
        };
        let (coordinate, first) = self.group(ident)?;
        let coordinate = coordinate.clone();
        Some(match (&coordinate.length, index) {
            (None, None) => Ok((coordinate, None, first)),
            (Some(Length::Literal(n, _)), Some(index)) => match literal_index(index) {
                Some(i) if i < *n => Ok((coordinate, Some(i), first.saturating_add(i))),
                Some(i) => {
                    let message = format!(
                        "index {i} is out of range: `{}` has {n} elements",
                        coordinate.name
                    );
                    self.error_on(index, message);
                    Err(())
                }
                None => {
                    self.error_on(index, "index an array of rotations or unit vectors with an integer literal, e.g. bodies[0]");
                    Err(())
                }
            },
            // A named length is reported where the coordinates are checked.
            (Some(Length::Named(_)), Some(_)) => Err(()),
            (Some(_), None) => {
                let message = format!(
                    "`{}` is an array: write one element, {}[i]",
                    coordinate.name, coordinate.name
                );
                self.error(ident.span(), message);
                Err(())
            }
            // `n[2]` of a single unit vector is a component, not an element.
            (None, Some(_)) => return None,
        })
    }

    /// The position of a group coordinate's element (`index` among those of its `kind`): a
    /// rotation's matrix or a unit vector.
    fn position(&self, kind: Kind, index: usize, span: Span) -> Value {
        match kind {
            Kind::Rotation => Value::Matrix(std::array::from_fn(|r| {
                std::array::from_fn(|k| leaf(atom("R", index, &[r, k], span)))
            })),
            _ => Value::Vector(std::array::from_fn(|k| leaf(atom("S", index, &[k], span)))),
        }
    }

    /// A rotation's body angular velocity, or a unit vector's velocity.
    fn rate(&self, kind: Kind, index: usize, span: Span) -> [Expr; 3] {
        let what = if kind == Kind::Rotation { "W" } else { "V" };
        std::array::from_fn(|k| leaf(atom(what, index, &[k], span)))
    }

    /// The differential of a group coordinate's element, paired with [`rate`](Self::rate): its
    /// numbers' indices among a tangent vector's.
    fn differential(&self, c: &Coordinate, index: usize, span: Span) -> Value {
        let reals: usize = self
            .algebra
            .coordinates
            .iter()
            .filter(|c| c.kind == Kind::Real)
            .map(length)
            .fold(0, usize::saturating_add);
        let rotations: usize = self
            .algebra
            .coordinates
            .iter()
            .filter(|c| c.kind == Kind::Rotation)
            .map(length)
            .fold(0, usize::saturating_add);
        // Saturating: an overlong array is refused elsewhere, and this must not overflow first.
        let triple = |n: usize| n.saturating_mul(3);
        let first = match c.kind {
            Kind::Rotation => reals.saturating_add(triple(index)),
            _ => reals
                .saturating_add(triple(rotations))
                .saturating_add(triple(index)),
        };
        Value::Vector(std::array::from_fn(|k| {
            leaf(Ident::new(
                &format!("{DIFFERENTIAL}{}", first.saturating_add(k)),
                span,
            ))
        }))
    }

    fn velocities_allowed(&mut self, expr: &Expr) -> bool {
        match self.algebra.no_velocities {
            None => true,
            Some(message) => {
                self.error_on(expr, message);
                false
            }
        }
    }

    fn value(&mut self, expr: &Expr, depth: usize) -> Value {
        if depth > MAX_NESTING {
            if !self.too_deep {
                self.too_deep = true;
                let (start, _) = bounds(expr);
                self.errors.push(
                    start,
                    format!(
                        "this expression nests more than {MAX_NESTING} levels deep; write it as \
                         a generic function and give `lagrangian = path::to::function`"
                    ),
                );
            }
            return Value::Invalid;
        }
        match expr {
            Expr::Paren(p) => match self.value(&p.expr, depth + 1) {
                Value::Scalar(e) => Value::Scalar(operand(e)),
                other => other,
            },
            Expr::Group(g) => self.value(&g.expr, depth + 1),
            Expr::Array(a) => {
                let items: Vec<Expr> = a
                    .elems
                    .iter()
                    .filter_map(|e| self.scalar(e, depth + 1, "a vector's component"))
                    .collect();
                match <[Expr; 3]>::try_from(items) {
                    Ok(v) if a.elems.len() == 3 => Value::Vector(v),
                    _ if a.elems.len() == 3 => Value::Invalid,
                    _ => self.error_on(expr, "a vector [a, b, c] has three numbers"),
                }
            }
            Expr::Path(_) => self.path(expr),
            Expr::Index(ix) => self.index(ix, expr, depth),
            Expr::Unary(syn::ExprUnary {
                op: UnOp::Neg(minus),
                expr: inner,
                ..
            }) => {
                let span = minus.span;
                match self.value(inner, depth + 1) {
                    Value::Scalar(e) => Value::Scalar(negated(&e, span)),
                    Value::Vector(v) => Value::Vector(v.map(|e| negated(&e, span))),
                    Value::Matrix(m) => Value::Matrix(m.map(|r| r.map(|e| negated(&e, span)))),
                    Value::Invalid => Value::Invalid,
                }
            }
            Expr::Binary(b) => self.binary(b, depth),
            Expr::Call(call) => self.call(call, expr, depth),
            Expr::MethodCall(m) => self.method(m, expr, depth),
            // Everything else is the scalar rewriter's to accept or report.
            other => Value::Scalar(other.clone()),
        }
    }

    /// `expr` as a number; `None` (after an error naming `what`) otherwise.
    fn scalar(&mut self, expr: &Expr, depth: usize, what: &str) -> Option<Expr> {
        match self.value(expr, depth) {
            Value::Scalar(e) => Some(e),
            Value::Invalid => None,
            other => {
                self.error_on(
                    expr,
                    format!("{what} is a number; this is {}", other.shape()),
                );
                None
            }
        }
    }

    fn vector(&mut self, expr: &Expr, depth: usize, what: &str) -> Option<[Expr; 3]> {
        match self.value(expr, depth) {
            Value::Vector(v) => Some(v),
            Value::Invalid => None,
            other => {
                self.error_on(
                    expr,
                    format!("{what} is a 3-vector; this is {}", other.shape()),
                );
                None
            }
        }
    }

    fn matrix(&mut self, expr: &Expr, depth: usize, what: &str) -> Option<[[Expr; 3]; 3]> {
        match self.value(expr, depth) {
            Value::Matrix(m) => Some(m),
            Value::Invalid => None,
            other => {
                self.error_on(
                    expr,
                    format!("{what} is a 3×3 matrix; this is {}", other.shape()),
                );
                None
            }
        }
    }

    fn path(&mut self, expr: &Expr) -> Value {
        let Some(ident) = path_ident(expr) else {
            return Value::Scalar(expr.clone());
        };
        if is_reserved(ident) && !self.algebra.parameters.iter().any(|p| p.name == *ident) {
            return self.error(ident.span(), reserved_message(ident));
        }
        if let Some(element) = self.group_element(expr) {
            return match element {
                Ok((c, _, index)) => self.position(c.kind, index, ident.span()),
                Err(()) => Value::Invalid,
            };
        }
        if let Some(value) = self.differential_of(expr, ident, None) {
            return value;
        }
        match self.algebra.parameters.iter().find(|p| p.name == *ident) {
            Some(p) if p.shape == Shape::Array(Some(3)) => Value::Vector(std::array::from_fn(
                |i| parse_quote_spanned!(ident.span()=> #ident[#i]),
            )),
            Some(p) if p.shape == Shape::Matrix(Some((3, 3))) => {
                Value::Matrix(std::array::from_fn(|i| {
                    std::array::from_fn(|j| parse_quote_spanned!(ident.span()=> #ident[#i][#j]))
                }))
            }
            _ => Value::Scalar(expr.clone()),
        }
    }

    /// `dR`, `dn` or `dbodies[i]`: the differential of a group coordinate, where differentials
    /// may appear; `None` if `ident` is no such name.
    fn differential_of(
        &mut self,
        expr: &Expr,
        ident: &Ident,
        index: Option<&Expr>,
    ) -> Option<Value> {
        let name = ident.to_string();
        // `d` alone, or `d` before what is no identifier (`d2`), names no coordinate.
        let mut target: Ident = syn::parse_str(name.strip_prefix('d')?).ok()?;
        target.set_span(ident.span());
        let named: Expr = match index {
            None => parse_quote_spanned!(ident.span()=> #target),
            Some(i) => parse_quote_spanned!(ident.span()=> #target[#i]),
        };
        let element = self.group_element(&named)?;
        if !self.algebra.differentials {
            return Some(self.error_on(
                expr,
                format!("`{name}` is a differential: differentials appear in constraints(...) and forces(...)"),
            ));
        }
        Some(match element {
            Ok((c, _, index)) => self.differential(&c, index, ident.span()),
            Err(()) => Value::Invalid,
        })
    }

    fn index(&mut self, ix: &syn::ExprIndex, expr: &Expr, depth: usize) -> Value {
        // A group coordinate's element, or its differential.
        if let Some(base) = path_ident(&ix.expr) {
            if let Some(element) = self.group_element(expr) {
                return match element {
                    Ok((c, _, index)) => self.position(c.kind, index, base.span()),
                    Err(()) => Value::Invalid,
                };
            }
            if let Some(value) = self.differential_of(expr, base, Some(&ix.index)) {
                return value;
            }
            // An element of a coordinate or parameter array: the scalar rewriter's.
            if self.coordinate(base).is_some_and(|c| !c.is_group())
                || self
                    .algebra
                    .parameters
                    .iter()
                    .any(|p| p.name == *base && p.shape != Shape::Array(Some(3)))
            {
                return Value::Scalar(expr.clone());
            }
        }
        // `J[i][j]` of a matrix parameter.
        if let Expr::Index(inner) = &*ix.expr
            && let Some(base) = path_ident(&inner.expr)
            && self.algebra.parameters.iter().any(|p| p.name == *base)
        {
            return Value::Scalar(expr.clone());
        }
        let span = ix.bracket_token.span.join();
        let Some(i) = literal_index(&ix.index) else {
            return self.error_on(
                &ix.index,
                "index a vector or matrix with an integer literal, 0, 1 or 2",
            );
        };
        if i > 2 {
            return self.error_on(
                &ix.index,
                format!(
                    "index {i} is out of range: vectors and matrices here have three rows, 0 to 2"
                ),
            );
        }
        match self.value(&ix.expr, depth + 1) {
            Value::Vector(v) => Value::Scalar(v[i].clone()),
            Value::Matrix(m) => Value::Vector(m[i].clone()),
            Value::Invalid => Value::Invalid,
            Value::Scalar(_) => self.error(
                span,
                "this indexes a number; only vectors and matrices have components",
            ),
        }
    }

    /// A chain `a op b op c ...` of one precedence, walked along its left spine (a sum of any
    /// length is one level deep), or another binary operator.
    fn binary(&mut self, b: &syn::ExprBinary, depth: usize) -> Value {
        let Some(family) = Family::of(&b.op) else {
            let (left, right) = (
                self.value(&b.left, depth + 1),
                self.value(&b.right, depth + 1),
            );
            return match (left, right) {
                (Value::Scalar(x), Value::Scalar(y)) => Value::Scalar(binary(x, b.op, y)),
                (Value::Invalid, _) | (_, Value::Invalid) => Value::Invalid,
                (l, r) => self.error(
                    b.op.span(),
                    format!(
                        "this operator does not apply to {} and {}",
                        l.shape(),
                        r.shape()
                    ),
                ),
            };
        };
        let (first, links) = spine(b, family);
        let mut value = self.value(first, depth + 1);
        for (op, operand) in links {
            let right = self.value(operand, depth + 1);
            value = self.apply(*op, value, right);
        }
        value
    }

    /// `left op right` for `+ - * /`.
    fn apply(&mut self, op: BinOp, left: Value, right: Value) -> Value {
        let span = op.span();
        use Value::{Matrix, Scalar, Vector};
        match (op, left, right) {
            (_, Scalar(x), Scalar(y)) => Scalar(binary(x, op, y)),
            (_, Value::Invalid, _) | (_, _, Value::Invalid) => Value::Invalid,
            (BinOp::Add(_) | BinOp::Sub(_), l, r) => {
                let minus = matches!(op, BinOp::Sub(_));
                let pair = |x: &Expr, y: &Expr| sum([(false, x.clone()), (minus, y.clone())], span);
                match (l, r) {
                    (Vector(u), Vector(v)) => Vector(std::array::from_fn(|i| pair(&u[i], &v[i]))),
                    (Matrix(m), Matrix(n)) => Matrix(std::array::from_fn(|i| {
                        std::array::from_fn(|j| pair(&m[i][j], &n[i][j]))
                    })),
                    (l, r) => self.error(
                        span,
                        format!("cannot add or subtract {} and {}", l.shape(), r.shape()),
                    ),
                }
            }
            (BinOp::Mul(_), l, r) => match (l, r) {
                (Scalar(s), Vector(v)) | (Vector(v), Scalar(s)) => {
                    Vector(v.map(|e| product(&s, &e, span)))
                }
                (Scalar(s), Matrix(m)) | (Matrix(m), Scalar(s)) => {
                    Matrix(m.map(|r| r.map(|e| product(&s, &e, span))))
                }
                (Matrix(m), Vector(v)) => Vector(matrix_vector(&m, &v, span)),
                (Matrix(m), Matrix(n)) => Matrix(matrix_matrix(&m, &n, span)),
                (Vector(_), Vector(_)) => self.error(
                    span,
                    "`*` of two vectors: write dot(u, v) or cross(u, v); to scale each \
                         component (a diagonal inertia `j`), declare the parameter as a matrix, \
                         `j: [[f64; 3]; 3]`, and `j * omega(R)` is its product with the vector",
                ),
                (Vector(_), Matrix(_)) => {
                    self.error(span, "a vector times a matrix: write transpose(M) * v")
                }
                (l, r) => self.error(
                    span,
                    format!("cannot multiply {} by {}", l.shape(), r.shape()),
                ),
            },
            (_, l, r) => match (l, r) {
                (Vector(v), Scalar(s)) => Vector(v.map(|e| quotient(&e, &s, span))),
                (Matrix(m), Scalar(s)) => Matrix(m.map(|r| r.map(|e| quotient(&e, &s, span)))),
                (l, r) => self.error(
                    span,
                    format!("cannot divide {} by {}", l.shape(), r.shape()),
                ),
            },
        }
    }

    fn call(&mut self, call: &syn::ExprCall, expr: &Expr, depth: usize) -> Value {
        let Some(name) = path_ident(&call.func) else {
            return Value::Scalar(expr.clone());
        };
        let arguments: Vec<&Expr> = call.args.iter().collect();
        let span = name.span();
        match (name.to_string().as_str(), &arguments[..]) {
            ("dot", [x]) => self.velocity(x, expr),
            ("omega", [x]) => self.angular_velocity(x, expr),
            ("dot", [u, v]) => self.vector_function("dot", u, Some(v), span, depth),
            ("cross" | "transpose" | "trace" | "norm" | "norm_squared", _) => {
                let (u, v) = (arguments.first().copied(), arguments.get(1).copied());
                match (name.to_string().as_str(), arguments.len(), u) {
                    ("cross", 2, Some(u)) => self.vector_function("cross", u, v, span, depth),
                    (f @ ("transpose" | "trace" | "norm" | "norm_squared"), 1, Some(u)) => {
                        self.vector_function(f, u, None, span, depth)
                    }
                    (f, _, _) => {
                        let arity = if f == "cross" { "two" } else { "one" };
                        self.error_on(expr, format!("`{f}` takes {arity} argument(s)"))
                    }
                }
            }
            _ => {
                // A scalar function of scalars: its arguments lowered.
                let mut call = call.clone();
                for argument in call.args.iter_mut() {
                    if let Some(e) =
                        self.scalar(argument, depth + 1, "an argument of this function")
                    {
                        *argument = e;
                    }
                }
                Value::Scalar(Expr::Call(call))
            }
        }
    }

    fn method(&mut self, m: &syn::ExprMethodCall, expr: &Expr, depth: usize) -> Value {
        let name = m.method.to_string();
        let span = m.method.span();
        let arguments: Vec<&Expr> = m.args.iter().collect();
        match (name.as_str(), &arguments[..]) {
            ("dot" | "cross", [v]) => {
                self.vector_function(&name, &m.receiver, Some(v), span, depth)
            }
            ("transpose" | "trace" | "norm" | "norm_squared", []) => {
                self.vector_function(&name, &m.receiver, None, span, depth)
            }
            ("dot" | "cross" | "transpose" | "trace" | "norm" | "norm_squared", _) => {
                self.error_on(expr, format!("wrong number of arguments to `{name}`"))
            }
            _ => {
                let mut m = m.clone();
                if let Some(e) = self.scalar(&m.receiver, depth + 1, "the receiver of this method")
                {
                    *m.receiver = e;
                }
                for argument in m.args.iter_mut() {
                    if let Some(e) = self.scalar(argument, depth + 1, "an argument of this method")
                    {
                        *argument = e;
                    }
                }
                Value::Scalar(Expr::MethodCall(m))
            }
        }
    }

    /// `dot`, `cross`, `transpose`, `trace`, `norm`, `norm_squared` of `u` (and `v`).
    fn vector_function(
        &mut self,
        name: &str,
        u: &Expr,
        v: Option<&Expr>,
        span: Span,
        depth: usize,
    ) -> Value {
        match (name, v) {
            ("dot", Some(v)) => {
                let (u, v) = (
                    self.vector(u, depth + 1, "an argument of dot"),
                    self.vector(v, depth + 1, "an argument of dot"),
                );
                match (u, v) {
                    (Some(u), Some(v)) => Value::Scalar(operand(dot(&u, &v, span))),
                    _ => Value::Invalid,
                }
            }
            ("cross", Some(v)) => {
                let (u, v) = (
                    self.vector(u, depth + 1, "an argument of cross"),
                    self.vector(v, depth + 1, "an argument of cross"),
                );
                match (u, v) {
                    (Some(u), Some(v)) => Value::Vector(cross(&u, &v, span)),
                    _ => Value::Invalid,
                }
            }
            ("transpose", None) => match self.matrix(u, depth + 1, "the argument of transpose") {
                Some(m) => Value::Matrix(std::array::from_fn(|i| {
                    std::array::from_fn(|j| m[j][i].clone())
                })),
                None => Value::Invalid,
            },
            ("trace", None) => match self.matrix(u, depth + 1, "the argument of trace") {
                Some(m) => {
                    Value::Scalar(operand(sum((0..3).map(|i| (false, m[i][i].clone())), span)))
                }
                None => Value::Invalid,
            },
            (f @ ("norm" | "norm_squared"), None) => {
                match self.vector(u, depth + 1, "the argument of norm") {
                    Some(u) => {
                        let squared = operand(dot(&u, &u, span));
                        match f {
                            "norm" => Value::Scalar(parse_quote_spanned!(span=> #squared.sqrt())),
                            _ => Value::Scalar(squared),
                        }
                    }
                    None => Value::Invalid,
                }
            }
            _ => Value::Invalid,
        }
    }

    /// `dot(x)`: a real coordinate's velocity (the scalar rewriter's), a rotation's rate
    /// `R Ω̂`, a unit vector's velocity.
    fn velocity(&mut self, x: &Expr, expr: &Expr) -> Value {
        match self.group_element(x) {
            None => Value::Scalar(expr.clone()),
            Some(Err(())) => Value::Invalid,
            Some(Ok((c, _, index))) => {
                if !self.velocities_allowed(expr) {
                    return Value::Invalid;
                }
                let span = x.span();
                let rate = self.rate(c.kind, index, span);
                match (c.kind, self.position(c.kind, index, span)) {
                    (Kind::Rotation, Value::Matrix(r)) => {
                        Value::Matrix(matrix_matrix(&r, &hat(&rate, span), span))
                    }
                    _ => Value::Vector(rate),
                }
            }
        }
    }

    /// `omega(R)`: a rotation's body angular velocity `Ω`; `omega(n)`: a unit vector's angular
    /// velocity `n × ṅ`.
    fn angular_velocity(&mut self, x: &Expr, expr: &Expr) -> Value {
        match self.group_element(x) {
            None => self.error_on(x, "omega(...) takes a rotation or a unit vector"),
            Some(Err(())) => Value::Invalid,
            Some(Ok((c, _, index))) => {
                if !self.velocities_allowed(expr) {
                    return Value::Invalid;
                }
                let span = x.span();
                let rate = self.rate(c.kind, index, span);
                match (c.kind, self.position(c.kind, index, span)) {
                    (Kind::Direction, Value::Vector(n)) => Value::Vector(cross(&n, &rate, span)),
                    _ => Value::Vector(rate),
                }
            }
        }
    }
}

/// `left op right` of two lowered numbers (built from its parts: cloning a long chain would
/// recurse as deep as it is long).
fn binary(left: Expr, op: BinOp, right: Expr) -> Expr {
    Expr::Binary(syn::ExprBinary {
        attrs: Vec::new(),
        left: Box::new(left),
        op,
        right: Box::new(right),
    })
}

fn leaf(ident: Ident) -> Expr {
    parse_quote_spanned!(ident.span()=> #ident)
}

/// The number of elements of a coordinate (1 for a single one; lengths here are literals).
fn length(c: &Coordinate) -> usize {
    match &c.length {
        Some(Length::Literal(n, _)) => *n,
        _ => 1,
    }
}
