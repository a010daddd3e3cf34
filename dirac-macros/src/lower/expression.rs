//! Rewrites a Lagrangian written like the mathematics into code generic over the scalar `__D`:
//! `dot(x)` becomes the velocity of `x`, `sin(x)` and `x.sin()` the method of that name.
//! Subexpressions of parameters, constants and literals alone stay `f64` (no dual-number work for
//! them) and are combined with state-dependent ones as `D op f64`.
//!
//! A sum or product is walked as a loop over its left spine and emitted as flat tokens, so an
//! expression of any length costs no recursion here or in rustc; only nesting (parentheses, calls,
//! unary minus) recurses, and it is capped at [`MAX_NESTING`]. Every emitted token keeps the span
//! of the user's token it comes from, so type errors point at them.

use std::cell::RefCell;
use std::collections::BTreeMap;

use proc_macro2::{Delimiter, Group, Literal, Span, TokenStream, TokenTree};
use quote::{ToTokens, format_ident, quote, quote_spanned};
use syn::{BinOp, Expr, ExprBinary, Ident, Lit, UnOp};

use crate::internals::ast::{Coordinate, Length};
use crate::internals::errors::Errors;

/// Functions of one argument, mapped to the method of the same name on dual numbers.
pub const UNARY: &[&str] = &[
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh",
    "exp", "exp2", "exp_m1", "ln", "ln_1p", "log2", "log10", "sqrt", "cbrt", "recip", "abs",
];

/// Functions of two arguments, each with how to call it.
pub const BINARY: &[(&str, &str)] = &[
    ("powi", "powi(x, 2) or x.powi(2), with an integer exponent"),
    ("powf", "powf(x, 1.5) or x.powf(1.5)"),
    ("pow", "pow(x, y) or x.pow(y)"),
    ("atan2", "atan2(y, x) or y.atan2(x)"),
];

/// Deepest nesting of parentheses, calls and unary minus in one expression. A sum or product of
/// any length is one level.
pub const MAX_NESTING: usize = 64;

/// Deepest nesting of brackets of any kind in the macro's arguments, checked before parsing: the
/// expression's levels plus the argument lists and indices around it.
pub const MAX_TOKEN_NESTING: usize = MAX_NESTING + 8;

const SUPPORTED: &str = "numbers, parameters and constants, coordinates, dot(coordinate), \
     + - * /, unary minus, parentheses, and the functions sin cos tan asin acos atan sinh cosh \
     tanh asinh acosh atanh exp exp2 exp_m1 ln ln_1p log2 log10 sqrt cbrt recip abs powi powf \
     pow atan2 (also as methods, x.sin())";

/// The identifier bound to the velocity of coordinate `name`.
pub fn velocity_ident(name: &Ident) -> Ident {
    format_ident!("__dot_{}", name)
}

/// Whether a name is reserved for the generated code.
pub fn is_reserved(ident: &Ident) -> bool {
    ident.to_string().starts_with("__")
}

/// Whether `tokens`, groups included, hold an identifier `named` accepts.
fn mentions(tokens: &TokenStream, named: &impl Fn(&Ident) -> bool) -> bool {
    tokens.clone().into_iter().any(|t| match t {
        TokenTree::Ident(i) => named(&i),
        TokenTree::Group(g) => mentions(&g.stream(), named),
        _ => false,
    })
}

/// The error for a reserved name.
pub fn reserved_message(ident: &Ident) -> String {
    format!("names starting with `__` are reserved for the generated code; rename `{ident}`")
}

/// Whether a subexpression depends on the state (`Dual`: a `__D` value) or only on parameters,
/// constants and literals (`Constant`: a plain `f64`, computed without dual-number arithmetic).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    Constant,
    Dual,
}

/// Where an expression stands.
pub struct Scope<'a> {
    pub coordinates: &'a [Coordinate],
    /// The model's inputs where they may appear (forces), as dual numbers: the step's
    /// derivatives with respect to them are exact.
    pub inputs: &'a [Ident],
    /// The struct's fields (a reserved one is reported on the field, not where it is used).
    pub fields: &'a [Ident],
    /// The struct's const parameters: an index or a length that names one is known only after
    /// monomorphisation (see [`Rewriter::checked_index`]).
    pub const_params: &'a [Ident],
    /// `None` where velocities are allowed, else what to say when `dot(...)` appears.
    pub no_velocities: Option<&'static str>,
    /// The name of the rate of a coordinate: `dot` (a velocity, for a Lagrangian) or `p` (a
    /// momentum, for a Hamiltonian); the generated code binds either from the second slot.
    pub rate: &'static str,
    /// Appended to the message for an unsupported expression (where else to write code).
    pub elsewhere: &'static str,
    /// The generated method the expression is emitted into.
    pub context: Context,
    /// What the model's expressions hoist out of their methods.
    pub hoisted: &'a Hoisted,
    /// Whether the expression was lowered from vectors and matrices (a model on rotations and
    /// unit vectors), so that its atoms are bound scalars (see `vector_algebra`).
    pub atoms: bool,
}

/// What a model's expressions hoist out of the methods they are emitted into, shared by every
/// expression of the model.
#[derive(Default)]
pub struct Hoisted {
    /// Continuations of long chains, each emitted as a method of its own.
    pub parts: RefCell<Vec<Part>>,
    /// Constant items asserting indices (see [`Rewriter::checked_index`]), emitted beside the
    /// struct; keyed by their message, so that an index written many times is asserted once.
    pub index_checks: RefCell<BTreeMap<String, TokenStream>>,
}

/// The generated method an expression is emitted into, which fixes what its hoisted parts are
/// passed: the Lagrangian's `(q, v)`, the forces' `(q, v, t, inputs)`, or the constraints' `q`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Context {
    Lagrangian,
    Force,
    Positions,
}

impl Context {
    /// The arguments a hoisted part is called with, each followed by a comma.
    fn arguments(self) -> TokenStream {
        match self {
            Context::Lagrangian => quote!(__q, __v,),
            Context::Force => quote!(__q, __v, t, __inputs,),
            Context::Positions => quote!(__q,),
        }
    }
}

/// A continuation of a long chain, emitted as a method of its own (`__dirac_part_k`) that takes
/// the chain so far and returns it continued by [`CHUNK`] operands. LLVM's optimisation of one
/// function grows faster than linearly with its size; a chain of any length then costs many
/// bounded functions (and one call per [`CHUNK`] operands at run time).
pub struct Part {
    pub context: Context,
    /// `__chain op x op x ...`.
    pub body: TokenStream,
    /// The chain's type: `__D`, or `f64` for a chain of constants.
    pub scalar: TokenStream,
}

/// The name of hoisted part `k`.
pub fn part_ident(k: usize) -> Ident {
    format_ident!("__dirac_part_{}", k)
}

/// How tightly emitted tokens bind, loosest first: they are parenthesised where an operator
/// needs tighter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Binding {
    Sum,
    Product,
    Prefix,
    Atom,
}

/// `+ -` or `* /`: the operators of one precedence that a chain is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    Sum,
    Product,
}

impl Family {
    pub fn of(op: &BinOp) -> Option<Family> {
        match op {
            BinOp::Add(_) | BinOp::Sub(_) => Some(Family::Sum),
            BinOp::Mul(_) | BinOp::Div(_) => Some(Family::Product),
            _ => None,
        }
    }

    /// The binding an operand of this family's operators needs.
    fn operand(self) -> Binding {
        match self {
            Family::Sum => Binding::Product,
            Family::Product => Binding::Prefix,
        }
    }

    fn binding(self) -> Binding {
        match self {
            Family::Sum => Binding::Sum,
            Family::Product => Binding::Product,
        }
    }
}

/// The left spine of same-family operators under `b`, walked in a loop: `a - b + c` is
/// `(a, [(-, b), (+, c)])`.
pub fn spine(b: &ExprBinary, family: Family) -> (&Expr, Vec<(&BinOp, &Expr)>) {
    let mut links = Vec::new();
    let mut node = b;
    let first = loop {
        links.push((&node.op, &*node.right));
        match &*node.left {
            Expr::Binary(left) if Family::of(&left.op) == Some(family) => node = left,
            left => break left,
        }
    };
    links.reverse();
    (first, links)
}

/// Every subexpression the macro looks into, `expr` first, visited with an explicit stack.
pub fn subexpressions(expr: &Expr) -> impl Iterator<Item = &Expr> {
    let mut stack = vec![expr];
    std::iter::from_fn(move || {
        let next = stack.pop()?;
        match next {
            Expr::Paren(p) => stack.push(&p.expr),
            Expr::Group(g) => stack.push(&g.expr),
            Expr::Unary(u) => stack.push(&u.expr),
            Expr::Binary(b) => stack.extend([&*b.right, &*b.left]),
            Expr::Call(c) => stack.extend(c.args.iter().rev()),
            Expr::MethodCall(m) => {
                stack.extend(m.args.iter().rev());
                stack.push(&m.receiver);
            }
            Expr::Index(ix) => stack.extend([&*ix.index, &*ix.expr]),
            _ => {}
        }
        Some(next)
    })
}

/// The spans of the first and last tokens of `expr`, found without tokenising all of it.
pub fn bounds(expr: &Expr) -> (Span, Span) {
    let edge = |tokens: TokenStream, last: bool| {
        let mut spans = tokens.into_iter().map(|t| t.span());
        let span = if last { spans.last() } else { spans.next() };
        span.unwrap_or_else(Span::call_site)
    };
    let mut first = expr;
    let start = loop {
        first = match first {
            Expr::Binary(b) => &b.left,
            Expr::MethodCall(m) => &m.receiver,
            Expr::Index(ix) => &ix.expr,
            Expr::Call(c) => &c.func,
            Expr::Field(f) => &f.base,
            Expr::Cast(c) => &c.expr,
            Expr::Unary(u) => break edge(u.op.to_token_stream(), false),
            Expr::Paren(p) => break p.paren_token.span.open(),
            other => break edge(other.to_token_stream(), false),
        }
    };
    let mut last = expr;
    let end = loop {
        last = match last {
            Expr::Binary(b) => &b.right,
            Expr::Unary(u) => &u.expr,
            Expr::Cast(c) => break edge(c.ty.to_token_stream(), true),
            Expr::Call(c) => break c.paren_token.span.close(),
            Expr::MethodCall(m) => break m.paren_token.span.close(),
            Expr::Index(ix) => break ix.bracket_token.span.close(),
            Expr::Paren(p) => break p.paren_token.span.close(),
            other => break edge(other.to_token_stream(), true),
        }
    };
    (start, end)
}

/// `tokens` in parentheses spanned at `span`.
fn parenthesised(tokens: TokenStream, span: Span) -> TokenStream {
    let mut group = Group::new(Delimiter::Parenthesis, tokens);
    group.set_span(span);
    TokenTree::Group(group).into()
}

/// A rewritten subexpression: its tokens, whether they are a `__D` or an `f64`, how tightly they
/// bind, and the span of the user's token they start at.
#[derive(Clone)]
pub struct Piece {
    tokens: TokenStream,
    class: Class,
    binding: Binding,
    span: Span,
}

impl Piece {
    fn atom(tokens: TokenStream, class: Class, span: Span) -> Self {
        Self {
            tokens,
            class,
            binding: Binding::Atom,
            span,
        }
    }

    /// Stands in for a subexpression with an error; never emitted.
    fn invalid(span: Span) -> Self {
        Self::atom(TokenStream::new(), Class::Dual, span)
    }

    /// The literal `1.0`, the coefficient of a bare differential.
    pub fn one(span: Span) -> Self {
        Self::atom(quote_spanned!(span=> 1.0f64), Class::Constant, span)
    }

    /// The tokens, parenthesised unless they bind at least as tightly as `binding`.
    fn at(self, binding: Binding) -> TokenStream {
        if self.binding >= binding {
            self.tokens
        } else {
            parenthesised(self.tokens, self.span)
        }
    }

    /// `-self`, spanned at the minus sign `span`.
    pub fn negated(self, span: Span) -> Self {
        let class = self.class;
        let inner = self.at(Binding::Prefix);
        Self {
            tokens: quote_spanned!(span=> -#inner),
            class,
            binding: Binding::Prefix,
            span,
        }
    }

    /// As a `__D`: a constant is converted.
    fn lifted(self) -> Self {
        match self.class {
            Class::Dual => self,
            Class::Constant => {
                let span = self.span;
                let value = self.tokens;
                Self::atom(
                    quote_spanned!(span=> <__D as ::core::convert::From<f64>>::from(#value)),
                    Class::Dual,
                    span,
                )
            }
        }
    }

    /// The span of the user's token it starts at.
    pub fn span(&self) -> Span {
        self.span
    }

    /// The final tokens, of type `__D`.
    pub fn into_scalar(self) -> TokenStream {
        self.lifted().tokens
    }

    /// `self.method(arguments)`.
    fn method(self, method: &Ident, arguments: TokenStream, class: Class) -> Self {
        let span = self.span;
        let receiver = self.at(Binding::Atom);
        let arguments = parenthesised(arguments, method.span());
        Self::atom(quote!(#receiver . #method #arguments), class, span)
    }
}

/// Rewrites expressions of one scope, pushing every error into the shared context.
pub struct Rewriter<'a> {
    pub scope: &'a Scope<'a>,
    pub errors: &'a mut Errors,
    /// Whether the nesting limit was reported (once per expression is enough).
    too_deep: bool,
}

/// Rewrites `expr` into tokens of type `__D`; `None` when it had errors (pushed into `errors`).
pub fn rewrite(expr: &Expr, scope: &Scope, errors: &mut Errors) -> Option<TokenStream> {
    let before = errors.len();
    let mut rewriter = Rewriter::new(scope, errors);
    let piece = rewriter.expr(expr, 0);
    (errors.len() == before).then(|| piece.into_scalar())
}

impl<'a> Rewriter<'a> {
    pub fn new(scope: &'a Scope<'a>, errors: &'a mut Errors) -> Self {
        Self {
            scope,
            errors,
            too_deep: false,
        }
    }

    pub fn coordinate(&self, ident: &Ident) -> Option<&'a Coordinate> {
        self.scope.coordinates.iter().find(|c| c.name == *ident)
    }

    fn names(&self) -> String {
        let names: Vec<String> = self
            .scope
            .coordinates
            .iter()
            .map(|c| match c.length {
                None => format!("`{}`", c.name),
                Some(_) => format!("`{}[i]`", c.name),
            })
            .collect();
        names.join(", ")
    }

    fn error(&mut self, span: Span, message: impl std::fmt::Display) -> Piece {
        self.errors.push(span, message);
        Piece::invalid(span)
    }

    /// An error underlining all of `expr`.
    fn error_on(&mut self, expr: &Expr, message: impl std::fmt::Display) -> Piece {
        let (start, end) = bounds(expr);
        self.errors.push_range(start, end, message);
        Piece::invalid(start)
    }

    /// Whether `depth` is within [`MAX_NESTING`]; reports the first excess.
    pub fn within_nesting(&mut self, expr: &Expr, depth: usize) -> bool {
        if depth <= MAX_NESTING {
            return true;
        }
        if !self.too_deep {
            self.too_deep = true;
            let (start, _) = bounds(expr);
            self.errors.push(
                start,
                format!(
                    "this expression nests more than {MAX_NESTING} levels deep; write it as a \
                     generic function and give `lagrangian = path::to::function`, or name parts \
                     of it as parameters"
                ),
            );
        }
        false
    }

    /// Checks that `index` is an integer constant, within `coordinate`'s length when both are
    /// literals. Returns whether it is.
    pub fn index(&mut self, coordinate: &Coordinate, index: &Expr) -> bool {
        if !self.integer_constant(
            index,
            "an index is an integer constant: a literal or a `const`, e.g. x[0] or x[N - 1]",
        ) {
            return false;
        }
        let literal = match index {
            Expr::Lit(syn::ExprLit {
                lit: Lit::Int(i), ..
            }) => i.base10_parse::<usize>().ok().map(|v| (v, i.span())),
            _ => None,
        };
        match (&coordinate.length, literal) {
            // A zero length is reported on the coordinate.
            (Some(Length::Literal(n, _)), Some((i, span))) if i >= *n && *n > 0 => {
                self.errors.push(
                    span,
                    format!(
                        "index {i} is out of range: `{}` has {n} elements, `{}[0]` to `{}[{}]`",
                        coordinate.name,
                        coordinate.name,
                        coordinate.name,
                        n - 1
                    ),
                );
                false
            }
            _ => true,
        }
    }

    /// The tokens of `index` into the array `coordinate`, once [`index`](Self::index) accepted
    /// it. A literal index into an array of literal length was checked by `index`; rustc checks
    /// any other on the user's tokens (its `unconditional_panic` lint on an array index fires
    /// only when code is generated, and not at all in generic code):
    /// - where neither the index nor the length names one of the struct's const parameters or
    ///   `Self`, a constant item beside the struct asserts the bound, so `cargo check` reports it;
    /// - else an inline constant asserts it in the generated method, when the struct is used
    ///   with its parameters (a build, not `cargo check`).
    pub fn checked_index(&self, coordinate: &Coordinate, index: &Expr) -> TokenStream {
        let Some(length) = &coordinate.length else {
            return index.to_token_stream();
        };
        if let (Length::Literal(..), Expr::Lit(_)) = (length, index) {
            return index.to_token_stream();
        }
        let (at, _) = bounds(index);
        let length = length.tokens();
        let message = format!(
            "index `{}` is out of range: `{}` has `{}` elements",
            index.to_token_stream(),
            coordinate.name,
            length
        )
        .replace('{', "{{")
        .replace('}', "}}");
        let assertion = quote_spanned!(at=> ::core::assert!((#index) < (#length), #message));
        // A const parameter, or an associated constant through `Self`, is out of a free item's
        // reach.
        let local = |i: &Ident| i == "Self" || self.scope.const_params.contains(i);
        if mentions(&index.to_token_stream(), &local) || mentions(&length, &local) {
            return quote_spanned!(at=> { const { #assertion }; #index });
        }
        self.scope
            .hoisted
            .index_checks
            .borrow_mut()
            .entry(message)
            .or_insert_with(|| quote_spanned!(at=> const _: () = #assertion;));
        index.to_token_stream()
    }

    /// `base[index]` for the element `ix` of the array `coordinate`, the index checked as by
    /// [`checked_index`](Self::checked_index) and the brackets spanning the user's.
    fn checked_element(
        &self,
        base: TokenStream,
        coordinate: &Coordinate,
        ix: &syn::ExprIndex,
    ) -> TokenStream {
        let mut bracket = Group::new(
            Delimiter::Bracket,
            self.checked_index(coordinate, &ix.index),
        );
        bracket.set_span(ix.bracket_token.span.join());
        quote!(#base #bracket)
    }

    /// Whether `expr` is an integer constant (integer literals, names that are not coordinates,
    /// parameters or inputs, `+ - * / %`, unary minus, parentheses); reports `message` on it if
    /// not.
    fn integer_constant(&mut self, expr: &Expr, message: &str) -> bool {
        let valid = subexpressions(expr).all(|e| match e {
            Expr::Lit(l) => matches!(&l.lit, Lit::Int(_)),
            Expr::Path(p) => p.path.get_ident().is_none_or(|i| {
                self.coordinate(i).is_none()
                    && !is_reserved(i)
                    && !self.scope.fields.contains(i)
                    && !self.scope.inputs.contains(i)
            }),
            Expr::Paren(_) | Expr::Group(_) => true,
            Expr::Unary(u) => matches!(u.op, UnOp::Neg(_)),
            Expr::Binary(b) => matches!(
                b.op,
                BinOp::Add(_) | BinOp::Sub(_) | BinOp::Mul(_) | BinOp::Div(_) | BinOp::Rem(_)
            ),
            _ => false,
        });
        if !valid {
            self.error_on(expr, message);
        }
        valid
    }

    /// `dot(x)` or `dot(theta[i])` (`p(x)`, `p(theta[i])` for a Hamiltonian).
    fn velocity(&mut self, call: &syn::ExprCall, whole: &Expr) -> Piece {
        let rate = self.scope.rate;
        if let Some(message) = self.scope.no_velocities {
            return self.error_on(whole, message);
        }
        let [arg] = call.args.iter().collect::<Vec<_>>()[..] else {
            let message =
                format!("{rate}(...) takes one coordinate, e.g. {rate}(x) or {rate}(theta[i])");
            return self.error_on(whole, message);
        };
        let (ident, index) = match arg {
            Expr::Path(p) => (p.path.get_ident(), None),
            Expr::Index(ix) => match &*ix.expr {
                Expr::Path(p) => (p.path.get_ident(), Some(ix)),
                _ => (None, None),
            },
            _ => (None, None),
        };
        let Some(ident) = ident else {
            let message = format!("{rate}(...) takes a coordinate, one of {}", self.names());
            return self.error_on(arg, message);
        };
        let Some(coordinate) = self.coordinate(ident) else {
            let message = format!(
                "`{ident}` is not a coordinate; the coordinates are {}",
                self.names()
            );
            return self.error(ident.span(), message);
        };
        let velocity = Ident::new(&velocity_ident(&coordinate.name).to_string(), ident.span());
        match (index, &coordinate.length) {
            (None, None) => Piece::atom(velocity.into_token_stream(), Class::Dual, ident.span()),
            (Some(ix), Some(_)) => {
                if !self.index(coordinate, &ix.index) {
                    return Piece::invalid(ident.span());
                }
                let element = self.checked_element(velocity.into_token_stream(), coordinate, ix);
                Piece::atom(element, Class::Dual, ident.span())
            }
            (Some(_), None) => {
                let message = format!("`{ident}` is a single coordinate, not an array");
                self.error_on(arg, message)
            }
            (None, Some(_)) => {
                let message = format!(
                    "`{ident}` is an array of coordinates: write the velocity of one element, \
                     {rate}({ident}[i])"
                );
                self.error(ident.span(), message)
            }
        }
    }

    /// A known function, `name(arguments)` or `arguments[0].name(rest)`.
    fn function(
        &mut self,
        name: &Ident,
        arguments: &[&Expr],
        method: bool,
        whole: &Expr,
        depth: usize,
    ) -> Piece {
        let label = name.to_string();
        let (arity, usage) = match BINARY.iter().find(|(n, _)| *n == label) {
            Some((_, usage)) => (2, usage.to_string()),
            None => (1, format!("{label}(x) or x.{label}()")),
        };
        if arguments.len() != arity {
            let (expected, got) = match method {
                true => (arity - 1, arguments.len() - 1),
                false => (arity, arguments.len()),
            };
            let message = format!(
                "`{label}` takes {expected} argument{}, got {got}: write {usage}",
                if expected == 1 { "" } else { "s" }
            );
            return self.error_on(whole, message);
        }
        let base = self.expr(arguments[0], depth + 1);
        if arity == 1 {
            let class = base.class;
            return base.method(name, TokenStream::new(), class);
        }
        let other = arguments[1];
        let method = |m: &str| Ident::new(m, name.span());
        if label == "powi" {
            let message = "the exponent of powi is an integer constant, e.g. powi(x, 2); \
                           for a real exponent write powf(x, 1.5)";
            if !self.integer_constant(other, message) {
                return Piece::invalid(name.span());
            }
            let class = base.class;
            return base.method(name, other.to_token_stream(), class);
        }
        let other = self.expr(other, depth + 1);
        match (label.as_str(), base.class, other.class) {
            // `pow` is `powf` on f64 and on a dual base with a constant exponent.
            ("powf" | "pow", class, Class::Constant) => {
                base.method(&method("powf"), other.at(Binding::Sum), class)
            }
            ("powf" | "pow", _, Class::Dual) => {
                base.lifted()
                    .method(&method("powd"), other.at(Binding::Sum), Class::Dual)
            }
            (_, Class::Constant, Class::Constant) => {
                base.method(name, other.at(Binding::Sum), Class::Constant)
            }
            _ => base.lifted().method(
                &method(&label),
                other.lifted().at(Binding::Sum),
                Class::Dual,
            ),
        }
    }

    /// A call of a function that is not built in: a user function generic over the scalar, so
    /// its arguments are converted to `__D`.
    fn user_function(&mut self, call: &syn::ExprCall, depth: usize) -> Piece {
        let mut arguments = TokenStream::new();
        for pair in call.args.pairs() {
            let argument = self.expr(pair.value(), depth + 1);
            arguments.extend(argument.into_scalar());
            arguments.extend(pair.punct().map(ToTokens::to_token_stream));
        }
        let func = call.func.to_token_stream();
        let arguments = parenthesised(arguments, call.paren_token.span.join());
        let span = bounds(&call.func).0;
        Piece::atom(quote!(#func #arguments), Class::Dual, span)
    }

    /// `a + b - c ...` or `a * b / c ...` as one flat chain.
    fn chain(&mut self, b: &ExprBinary, family: Family, depth: usize) -> Piece {
        let (first, links) = spine(b, family);
        let first = self.expr(first, depth + 1);
        let links = links
            .into_iter()
            .map(|(op, operand)| (*op, self.expr(operand, depth + 1)))
            .collect();
        self.combine(family, first, links)
    }

    /// Rewrites one expression at nesting `depth` and classifies it.
    pub fn expr(&mut self, expr: &Expr, depth: usize) -> Piece {
        if !self.within_nesting(expr, depth) {
            return Piece::invalid(Span::call_site());
        }
        match expr {
            Expr::Lit(lit) => self.literal(&lit.lit, expr),
            Expr::Path(p) => self.path(p, expr),
            Expr::Paren(p) => {
                let inner = self.expr(&p.expr, depth + 1);
                let span = p.paren_token.span.join();
                Piece::atom(parenthesised(inner.tokens, span), inner.class, span)
            }
            Expr::Group(g) => self.expr(&g.expr, depth + 1),
            Expr::Unary(syn::ExprUnary {
                op: UnOp::Neg(minus),
                expr: inner,
                ..
            }) => self.expr(inner, depth + 1).negated(minus.span),
            Expr::Binary(b) => match Family::of(&b.op) {
                Some(family) => self.chain(b, family, depth),
                None => self.operator(b),
            },
            Expr::Call(call) => match &*call.func {
                Expr::Path(p) => match p.path.get_ident() {
                    Some(name) if name == self.scope.rate => self.velocity(call, expr),
                    Some(name) if name == "dot" => self.error_on(
                        expr,
                        "a Hamiltonian is written in the coordinates and their momenta p(x), \
                         not velocities dot(x)",
                    ),
                    Some(name) if is_known(name) => {
                        let arguments: Vec<&Expr> = call.args.iter().collect();
                        self.function(name, &arguments, false, expr, depth)
                    }
                    _ => self.user_function(call, depth),
                },
                _ => self.unsupported(expr),
            },
            Expr::MethodCall(m) if m.turbofish.is_none() && is_known(&m.method) => {
                let mut arguments = vec![&*m.receiver];
                arguments.extend(m.args.iter());
                self.function(&m.method, &arguments, true, expr, depth)
            }
            Expr::MethodCall(m) => {
                let known: Vec<String> = UNARY
                    .iter()
                    .copied()
                    .chain(BINARY.iter().map(|b| b.0))
                    .map(String::from)
                    .collect();
                let message = format!(
                    "unknown method `{}`; the methods are {}",
                    m.method,
                    known.join(", ")
                );
                self.error(m.method.span(), message)
            }
            Expr::Index(ix) => self.index_expr(ix, expr),
            Expr::Field(f) if matches!(&*f.base, Expr::Path(p) if p.path.is_ident("self")) => {
                let member = f.member.to_token_stream();
                self.error_on(
                    expr,
                    format!("write `{member}`: parameters are in scope by their names"),
                )
            }
            _ => self.unsupported(expr),
        }
    }

    fn literal(&mut self, lit: &Lit, expr: &Expr) -> Piece {
        let (digits, suffix, span) = match lit {
            Lit::Float(f) => (f.base10_digits(), f.suffix(), f.span()),
            Lit::Int(i) => (i.base10_digits(), i.suffix(), i.span()),
            _ => return self.unsupported(expr),
        };
        if !matches!(suffix, "" | "f64") {
            return self.error(
                span,
                format!("numbers here are `f64`: write `{digits}` without the suffix `{suffix}`"),
            );
        }
        match digits.parse::<f64>() {
            Ok(value) if value.is_finite() => {
                let mut literal = Literal::f64_suffixed(value);
                literal.set_span(span);
                Piece::atom(literal.into_token_stream(), Class::Constant, span)
            }
            _ => self.error(
                span,
                format!(
                    "`{digits}` is not a finite `f64` (the largest is about 1.8e308); \
                     write a smaller number"
                ),
            ),
        }
    }

    /// A coordinate or an input is a dual number; every other name or path (parameters,
    /// `const`s, `std::f64::consts::PI`, `t`) a constant.
    fn path(&mut self, p: &syn::ExprPath, expr: &Expr) -> Piece {
        let tokens = p.to_token_stream();
        let span = bounds(expr).0;
        let Some(ident) = p.path.get_ident() else {
            return Piece::atom(tokens, Class::Constant, span);
        };
        if self.scope.atoms && crate::lower::atom::is_atom(ident) {
            return Piece::atom(tokens, Class::Dual, span);
        }
        if is_reserved(ident) && !self.scope.fields.contains(ident) {
            return self.error(ident.span(), reserved_message(ident));
        }
        if ident == "self" {
            return self.error(
                ident.span(),
                "write a parameter by its name, e.g. `m` for the field `m`",
            );
        }
        if self.scope.inputs.contains(ident) {
            return Piece::atom(tokens, Class::Dual, span);
        }
        match self.coordinate(ident).map(|c| &c.length) {
            None => Piece::atom(tokens, Class::Constant, span),
            Some(None) => Piece::atom(tokens, Class::Dual, span),
            Some(Some(_)) => self.error(
                ident.span(),
                format!("`{ident}` is an array of coordinates: write one element, {ident}[i]"),
            ),
        }
    }

    /// `theta[i]` of a coordinate array is a dual number, `m[i]` of a parameter array a constant.
    fn index_expr(&mut self, ix: &syn::ExprIndex, expr: &Expr) -> Piece {
        // `J[i][j]` of a parameter `[[f64; C]; R]`: a constant.
        if let Expr::Index(inner) = &*ix.expr
            && let Expr::Path(p) = &*inner.expr
            && p.path
                .get_ident()
                .is_some_and(|i| self.scope.fields.contains(i))
        {
            let message = "an index is an integer constant: a literal or a `const`, e.g. j[0][1]";
            if !self.integer_constant(&inner.index, message)
                || !self.integer_constant(&ix.index, message)
            {
                return Piece::invalid(bounds(expr).0);
            }
            return Piece::atom(ix.to_token_stream(), Class::Constant, bounds(expr).0);
        }
        let Expr::Path(p) = &*ix.expr else {
            return self.unsupported(expr);
        };
        let span = bounds(&ix.expr).0;
        match p.path.get_ident().and_then(|i| self.coordinate(i)) {
            Some(coordinate) if coordinate.length.is_none() => {
                let message = format!("`{}` is a single coordinate, not an array", coordinate.name);
                self.error_on(expr, message)
            }
            Some(coordinate) => {
                if !self.index(coordinate, &ix.index) {
                    return Piece::invalid(span);
                }
                let element = self.checked_element(ix.expr.to_token_stream(), coordinate, ix);
                Piece::atom(element, Class::Dual, span)
            }
            None => {
                let reserved = |i: &&Ident| is_reserved(i) && !self.scope.fields.contains(i);
                if let Some(ident) = p.path.get_ident().filter(reserved) {
                    return self.error(ident.span(), reserved_message(ident));
                }
                if !self.integer_constant(
                    &ix.index,
                    "an index is an integer constant: a literal or a `const`, e.g. m[0]",
                ) {
                    return Piece::invalid(span);
                }
                Piece::atom(ix.to_token_stream(), Class::Constant, span)
            }
        }
    }

    /// A binary operator other than `+ - * /`.
    fn operator(&mut self, b: &ExprBinary) -> Piece {
        let span = b.op.to_token_stream().into_iter().next().map(|t| t.span());
        let span = span.unwrap_or_else(Span::call_site);
        let op = b.op.to_token_stream();
        match b.op {
            BinOp::BitXor(_) => self.error(
                span,
                "`^` is exclusive or in Rust; write powers as powi(x, 2) or x.powi(2)",
            ),
            _ => self.error(
                span,
                format!("`{op}` is not supported here; the operators are + - * /"),
            ),
        }
    }

    fn unsupported(&mut self, expr: &Expr) -> Piece {
        let kind = match expr {
            Expr::Macro(_) => "a macro",
            Expr::Block(_) | Expr::Unsafe(_) | Expr::Const(_) => "a block",
            Expr::If(_) | Expr::Match(_) => "a conditional",
            Expr::Closure(_) => "a closure",
            Expr::Cast(_) => "a cast",
            Expr::Field(_) => "a field access",
            Expr::Lit(_) => "a non-numeric literal",
            Expr::Reference(_) | Expr::Unary(_) => "this operator",
            Expr::MethodCall(_) => "a method with type arguments",
            Expr::Index(_) => "indexing something other than an array by name",
            _ => "this expression",
        };
        let message = format!(
            "{kind} is not supported here: write {SUPPORTED}{}",
            self.scope.elsewhere
        );
        self.error_on(expr, message)
    }
}

/// Whether `ident` names a built-in function.
fn is_known(ident: &Ident) -> bool {
    let name = ident.to_string();
    UNARY.contains(&name.as_str()) || BINARY.iter().any(|(n, _)| *n == name)
}

/// Operands per statement of a long chain.
const CHUNK: usize = 64;

impl Rewriter<'_> {
    /// Emits `first op1 x1 op2 x2 ...` with constants kept in `f64`. Dual numbers implement
    /// `D op f64` but not `f64 op D`, so a constant prefix followed by a dual operand `d` is moved
    /// after it: `c - d ...` becomes `-d + c ...`, `c / d ...` becomes `d.recip() * c ...`.
    pub fn combine(&self, family: Family, first: Piece, links: Vec<(BinOp, Piece)>) -> Piece {
        let operand = family.operand();
        let span = first.span;
        let lead = match first.class {
            Class::Dual => None,
            Class::Constant => links.iter().position(|(_, p)| p.class == Class::Dual),
        };
        let class = match (first.class, lead) {
            (Class::Constant, None) => Class::Constant,
            _ => Class::Dual,
        };
        // The operands in the order emitted, each after its operator.
        let mut sequence = Vec::with_capacity(links.len() + 1);
        let mut rest = links.into_iter();
        match lead {
            None => sequence.push(first.at(operand)),
            Some(k) => {
                let mut prefix = first.at(operand);
                for (op, piece) in rest.by_ref().take(k) {
                    prefix.extend(op.into_token_stream());
                    prefix.extend(piece.at(operand));
                }
                let constant = match k {
                    0 => prefix,
                    _ => parenthesised(prefix, span),
                };
                if let Some((op, dual)) = rest.next() {
                    let op_span = op
                        .to_token_stream()
                        .into_iter()
                        .next()
                        .map_or(span, |t| t.span());
                    sequence.push(match op {
                        BinOp::Sub(_) => dual.negated(op_span).tokens,
                        BinOp::Div(_) => {
                            let recip = Ident::new("recip", op_span);
                            dual.method(&recip, TokenStream::new(), Class::Dual).tokens
                        }
                        _ => dual.at(operand),
                    });
                    sequence.push(match family {
                        Family::Sum => quote_spanned!(op_span=> + #constant),
                        Family::Product => quote_spanned!(op_span=> * #constant),
                    });
                }
            }
        }
        sequence.extend(rest.map(|(op, piece)| {
            let piece = piece.at(operand);
            quote!(#op #piece)
        }));
        let binding = match sequence.len() > CHUNK {
            true => Binding::Atom,
            false => family.binding(),
        };
        Piece {
            tokens: self.chunked(sequence, class, span),
            class,
            binding,
            span,
        }
    }

    /// A chain's tokens: flat up to [`CHUNK`] operands; longer, its first [`CHUNK`] operands
    /// and then one call per [`CHUNK`] more, each a hoisted [`Part`] (rustc recurses on a flat chain
    /// as deep as it is long, and LLVM slows down more than linearly on one long function).
    fn chunked(&self, sequence: Vec<TokenStream>, class: Class, span: Span) -> TokenStream {
        if sequence.len() <= CHUNK {
            return sequence.into_iter().collect();
        }
        let chain = Ident::new("__chain", span);
        let scalar = match class {
            Class::Dual => quote_spanned!(span=> __D),
            Class::Constant => quote_spanned!(span=> f64),
        };
        let arguments = self.scope.context.arguments();
        let mut parts = self.scope.hoisted.parts.borrow_mut();
        let mut chunks = sequence.chunks(CHUNK);
        let first = chunks.next().unwrap_or_default();
        let calls: Vec<TokenStream> = chunks
            .map(|chunk| {
                let name = part_ident(parts.len());
                parts.push(Part {
                    context: self.scope.context,
                    body: quote!(#chain #(#chunk)*),
                    scalar: scalar.clone(),
                });
                quote!(let #chain = self.#name(#arguments #chain);)
            })
            .collect();
        quote!({ let #chain: #scalar = #(#first)*; #(#calls)* #chain })
    }
}

/// Binds a coordinate's position and velocity (`__D`, or `[__D; K]` for an array) from `__q`, `__v`
/// (on a product, their vector parts); a rotation or unit vector binds its entries as the atoms of
/// `vector_algebra`. Without `velocities` only the position is bound (for one-forms and
/// holonomic constraints).
pub fn bind_coordinate(
    coordinate: &Coordinate,
    offset: &TokenStream,
    kind_index: usize,
    velocities: bool,
    product: bool,
) -> TokenStream {
    let name = &coordinate.name;
    let velocity = velocity_ident(name);
    let span = name.span();
    let (q, v) = match product {
        true => (
            quote_spanned!(span=> __q.vector),
            quote_spanned!(span=> __v.vector),
        ),
        false => (quote_spanned!(span=> __q), quote_spanned!(span=> __v)),
    };
    if coordinate.is_group() {
        return bind_group(coordinate, kind_index, velocities);
    }
    match (&coordinate.length, velocities) {
        (None, true) => quote_spanned! {span=>
            let #name: __D = #q[#offset];
            let #velocity: __D = #v[#offset];
        },
        (None, false) => quote_spanned!(span=> let #name: __D = #q[#offset];),
        (Some(length), velocities) => {
            let length = length.tokens();
            let velocity = velocities.then(|| {
                quote_spanned! {span=>
                    let #velocity: [__D; #length] = ::core::array::from_fn(|__i| #v[#offset + __i]);
                }
            });
            quote_spanned! {span=>
                let #name: [__D; #length] = ::core::array::from_fn(|__i| #q[#offset + __i]);
                #velocity
            }
        }
    }
}

/// The atoms of a rotation (its matrix's entries and body angular velocity) or of a unit vector
/// (its components and velocity), for each element of an array (lengths are literals here);
/// `first` is the coordinate's index among those of its kind.
fn bind_group(coordinate: &Coordinate, first: usize, velocities: bool) -> TokenStream {
    use crate::internals::ast::Kind;
    use crate::lower::atom::atom;
    let span = coordinate.name.span();
    let count = match &coordinate.length {
        Some(Length::Literal(n, _)) => *n,
        _ => 1,
    };
    let mut out = TokenStream::new();
    for at in first..first.saturating_add(count) {
        match coordinate.kind {
            Kind::Rotation => {
                for r in 0..3usize {
                    for c in 0..3usize {
                        let entry = atom("R", at, &[r, c], span);
                        out.extend(quote!(let #entry: __D = __q.rotation[#at][(#r, #c)];));
                    }
                }
                for c in (0..3usize).filter(|_| velocities) {
                    let rate = atom("W", at, &[c], span);
                    out.extend(quote!(let #rate: __D = __v.rotation[#at][#c];));
                }
            }
            _ => {
                for c in 0..3usize {
                    let entry = atom("S", at, &[c], span);
                    out.extend(quote!(let #entry: __D = __q.direction[#at][#c];));
                }
                for c in (0..3usize).filter(|_| velocities) {
                    let rate = atom("V", at, &[c], span);
                    out.extend(quote!(let #rate: __D = __v.direction[#at][#c];));
                }
            }
        }
    }
    out
}
