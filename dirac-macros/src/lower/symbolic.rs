//! Closed-form derivatives of a Lagrangian written as an expression, taken at compile time.
//!
//! The expression becomes a graph of operations in which equal subexpressions are one node
//! (`Graph`). It is differentiated by the chain rule, node by node, with sums of zero, products
//! by zero or one and numbers folded away, and emitted as straight-line `f64` code: `L`,
//! `∂L/∂q`, `∂L/∂v` (`lagrangian_gradient`) and with them `∂²L/∂q²`, `∂²L/∂q∂v`, `∂²L/∂v²`
//! (`lagrangian_hessian`). The runtime takes these instead of evaluating `L` over dual numbers.
//!
//! Expressions the graph does not cover get no closed form, and the runtime keeps its dual
//! numbers for them: calls of the user's functions, `pow` with an exponent that depends on the
//! state, coordinate arrays whose length or index is not a literal, and graphs beyond a size
//! bound (a long Lagrangian then costs no more compile time than before).

use std::collections::HashMap;

use proc_macro2::{Literal, TokenStream};
use quote::{ToTokens, quote};
use syn::{BinOp, Expr, Lit, UnOp};

use crate::internals::ast::{Coordinate, Length};
use crate::lower::expression::{Family, spine};

/// Most nodes of the Lagrangian's own graph that get a closed form.
const MAX_SOURCE: usize = 1_000;
/// Most variables (entries, angular velocities, coordinates and velocities) of a Lagrangian on
/// rotations that gets a closed form: eight rotations, or fewer with vectors.
const MAX_BODY_VARIABLES: usize = 96;
/// Most nodes the graph may hold with every derivative (beyond it: no closed form).
const MAX_GRAPH: usize = 8_000;

type Id = usize;

/// The functions of one argument the graph differentiates, by the `f64` method of that name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Function {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Asinh,
    Acosh,
    Atanh,
    Exp,
    Exp2,
    ExpM1,
    Ln,
    Ln1p,
    Log2,
    Log10,
    Sqrt,
    Cbrt,
    Recip,
    Abs,
    Signum,
}

const FUNCTIONS: &[(&str, Function)] = &[
    ("sin", Function::Sin),
    ("cos", Function::Cos),
    ("tan", Function::Tan),
    ("asin", Function::Asin),
    ("acos", Function::Acos),
    ("atan", Function::Atan),
    ("sinh", Function::Sinh),
    ("cosh", Function::Cosh),
    ("tanh", Function::Tanh),
    ("asinh", Function::Asinh),
    ("acosh", Function::Acosh),
    ("atanh", Function::Atanh),
    ("exp", Function::Exp),
    ("exp2", Function::Exp2),
    ("exp_m1", Function::ExpM1),
    ("ln", Function::Ln),
    ("ln_1p", Function::Ln1p),
    ("log2", Function::Log2),
    ("log10", Function::Log10),
    ("sqrt", Function::Sqrt),
    ("cbrt", Function::Cbrt),
    ("recip", Function::Recip),
    ("abs", Function::Abs),
    ("signum", Function::Signum),
];

impl Function {
    fn of(name: &str) -> Option<Self> {
        FUNCTIONS.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
    }

    fn method(self) -> proc_macro2::Ident {
        let name = FUNCTIONS
            .iter()
            .find(|(_, f)| *f == self)
            .map(|(n, _)| *n)
            .unwrap_or("signum");
        proc_macro2::Ident::new(name, proc_macro2::Span::call_site())
    }
}

/// One operation of the graph; its operands are earlier nodes.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
enum Node {
    /// A number, by its bits.
    Number(u64),
    /// A parameter, a `const` or a path, emitted as the user wrote it.
    Constant(usize),
    /// `q_i` for `i < N`, `v_{i−N}` above.
    Variable(usize),
    Add(Id, Id),
    Sub(Id, Id),
    Mul(Id, Id),
    Div(Id, Id),
    Neg(Id),
    Call(Function, Id),
    Powi(Id, i32),
    /// `x^c` with `c` free of the state.
    Powf(Id, Id),
    /// `atan2(y, x)`.
    Atan2(Id, Id),
}

/// A graph of operations with one node per distinct subexpression.
struct Graph {
    /// Number of coordinates.
    n: usize,
    nodes: Vec<Node>,
    index: HashMap<Node, Id>,
    /// Whether each node depends on the state.
    state: Vec<bool>,
    constants: Vec<TokenStream>,
    constant_index: HashMap<String, usize>,
    derivatives: HashMap<(Id, usize), Id>,
}

impl Graph {
    fn new(n: usize) -> Self {
        Self {
            n,
            nodes: Vec::new(),
            index: HashMap::new(),
            state: Vec::new(),
            constants: Vec::new(),
            constant_index: HashMap::new(),
            derivatives: HashMap::new(),
        }
    }

    fn intern(&mut self, node: Node) -> Id {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        let state = match &node {
            Node::Number(_) | Node::Constant(_) => false,
            Node::Variable(_) => true,
            Node::Neg(a) | Node::Call(_, a) | Node::Powi(a, _) => self.state[*a],
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Powf(a, b)
            | Node::Atan2(a, b) => self.state[*a] || self.state[*b],
        };
        let id = self.nodes.len();
        self.nodes.push(node.clone());
        self.state.push(state);
        self.index.insert(node, id);
        id
    }

    fn number(&mut self, x: f64) -> Id {
        // `-0.0` and `0.0` are one number here: a derivative never needs the sign of zero.
        let x = if x == 0.0 { 0.0 } else { x };
        self.intern(Node::Number(x.to_bits()))
    }

    fn value(&self, id: Id) -> Option<f64> {
        match self.nodes[id] {
            Node::Number(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    fn is(&self, id: Id, x: f64) -> bool {
        self.value(id) == Some(x)
    }

    /// Whether `abs` or `signum` is applied to something that depends on a variable `of`
    /// accepts (a kink the closed-form derivatives step over; variables `0..n` are positions,
    /// `n..2n` velocities).
    fn kinks(&self, of: impl Fn(usize) -> bool) -> bool {
        // Operands come before the nodes that use them: one pass in order.
        let mut depends = vec![false; self.nodes.len()];
        for (id, node) in self.nodes.iter().enumerate() {
            depends[id] = match node {
                Node::Number(_) | Node::Constant(_) => false,
                Node::Variable(i) => of(*i),
                Node::Call(Function::Abs | Function::Signum, a) if depends[*a] => return true,
                Node::Neg(a) | Node::Call(_, a) | Node::Powi(a, _) => depends[*a],
                Node::Add(a, b)
                | Node::Sub(a, b)
                | Node::Mul(a, b)
                | Node::Div(a, b)
                | Node::Powf(a, b)
                | Node::Atan2(a, b) => depends[*a] || depends[*b],
            };
        }
        false
    }

    /// Whether every node is finite wherever the state is (short of overflow): sums, products,
    /// integer powers, division by what the state does not change and functions defined on
    /// every real; no division by the state, root, logarithm or inverse with a bounded domain.
    fn entire(&self) -> bool {
        use Function::*;
        self.nodes.iter().enumerate().all(|(id, node)| {
            !self.state[id]
                || match node {
                    Node::Number(_)
                    | Node::Constant(_)
                    | Node::Variable(_)
                    | Node::Add(..)
                    | Node::Sub(..)
                    | Node::Mul(..)
                    | Node::Neg(_) => true,
                    Node::Powi(_, k) => *k >= 0,
                    Node::Div(_, b) => !self.state[*b],
                    Node::Call(f, _) => matches!(
                        f,
                        Sin | Cos
                            | Atan
                            | Sinh
                            | Cosh
                            | Tanh
                            | Asinh
                            | Exp
                            | Exp2
                            | ExpM1
                            | Cbrt
                            | Abs
                            | Signum
                    ),
                    Node::Powf(..) | Node::Atan2(..) => false,
                }
        })
    }

    /// `f(a, b)` folded when both are numbers and the result is finite.
    fn folded(&mut self, a: Id, b: Id, f: fn(f64, f64) -> f64) -> Option<Id> {
        let x = f(self.value(a)?, self.value(b)?);
        x.is_finite().then(|| self.number(x))
    }

    fn constant(&mut self, tokens: TokenStream) -> Id {
        let key = tokens.to_string();
        let k = match self.constant_index.get(&key) {
            Some(&k) => k,
            None => {
                self.constants.push(tokens);
                self.constant_index.insert(key, self.constants.len() - 1);
                self.constants.len() - 1
            }
        };
        self.intern(Node::Constant(k))
    }

    /// Operands of a commutative operation in a fixed order, so `a + b` and `b + a` are one node.
    fn ordered(a: Id, b: Id) -> (Id, Id) {
        (a.min(b), a.max(b))
    }

    fn add(&mut self, a: Id, b: Id) -> Id {
        if self.is(a, 0.0) {
            return b;
        }
        if self.is(b, 0.0) {
            return a;
        }
        if let Some(x) = self.folded(a, b, |x, y| x + y) {
            return x;
        }
        let (a, b) = Self::ordered(a, b);
        self.intern(Node::Add(a, b))
    }

    fn sub(&mut self, a: Id, b: Id) -> Id {
        if self.is(b, 0.0) {
            return a;
        }
        if self.is(a, 0.0) {
            return self.neg(b);
        }
        if let Some(x) = self.folded(a, b, |x, y| x - y) {
            return x;
        }
        self.intern(Node::Sub(a, b))
    }

    fn mul(&mut self, a: Id, b: Id) -> Id {
        if self.is(a, 0.0) || self.is(b, 0.0) {
            return self.number(0.0);
        }
        if self.is(a, 1.0) {
            return b;
        }
        if self.is(b, 1.0) {
            return a;
        }
        if self.is(a, -1.0) {
            return self.neg(b);
        }
        if self.is(b, -1.0) {
            return self.neg(a);
        }
        if let Some(x) = self.folded(a, b, |x, y| x * y) {
            return x;
        }
        let (a, b) = Self::ordered(a, b);
        self.intern(Node::Mul(a, b))
    }

    fn div(&mut self, a: Id, b: Id) -> Id {
        if self.is(a, 0.0) {
            return self.number(0.0);
        }
        if self.is(b, 1.0) {
            return a;
        }
        if let Some(x) = self.folded(a, b, |x, y| x / y) {
            return x;
        }
        self.intern(Node::Div(a, b))
    }

    /// `1/a`, one node for every use.
    fn reciprocal(&mut self, a: Id) -> Id {
        let one = self.number(1.0);
        self.div(one, a)
    }

    fn neg(&mut self, a: Id) -> Id {
        match self.nodes[a] {
            Node::Number(bits) => self.number(-f64::from_bits(bits)),
            Node::Neg(inner) => inner,
            _ => self.intern(Node::Neg(a)),
        }
    }

    fn call(&mut self, f: Function, a: Id) -> Id {
        self.intern(Node::Call(f, a))
    }

    fn powi(&mut self, a: Id, n: i32) -> Id {
        match n {
            0 => self.number(1.0),
            1 => a,
            _ => self.intern(Node::Powi(a, n)),
        }
    }

    fn square(&mut self, a: Id) -> Id {
        self.powi(a, 2)
    }

    /// `∂a/∂x_var`, memoised.
    fn derivative(&mut self, a: Id, var: usize) -> Id {
        if !self.state[a] {
            return self.number(0.0);
        }
        if let Some(&d) = self.derivatives.get(&(a, var)) {
            return d;
        }
        let d = match self.nodes[a].clone() {
            Node::Number(_) | Node::Constant(_) => self.number(0.0),
            Node::Variable(i) => self.number(if i == var { 1.0 } else { 0.0 }),
            Node::Add(x, y) => {
                let (dx, dy) = (self.derivative(x, var), self.derivative(y, var));
                self.add(dx, dy)
            }
            Node::Sub(x, y) => {
                let (dx, dy) = (self.derivative(x, var), self.derivative(y, var));
                self.sub(dx, dy)
            }
            Node::Mul(x, y) => {
                let (dx, dy) = (self.derivative(x, var), self.derivative(y, var));
                let (l, r) = (self.mul(dx, y), self.mul(x, dy));
                self.add(l, r)
            }
            Node::Div(x, y) => {
                // (x/y)' = x' r − (x r)(y' r) with r = 1/y: one division for every derivative of
                // every order (the node `1/y` is shared), where x'/y − (x/y) y'/y takes one for
                // each variable. The value x/y keeps the user's division.
                let (dx, dy) = (self.derivative(x, var), self.derivative(y, var));
                let r = self.reciprocal(y);
                let left = self.mul(dx, r);
                let (xr, dyr) = (self.mul(x, r), self.mul(dy, r));
                let right = self.mul(xr, dyr);
                self.sub(left, right)
            }
            Node::Neg(x) => {
                let dx = self.derivative(x, var);
                self.neg(dx)
            }
            Node::Call(f, x) => {
                let dx = self.derivative(x, var);
                if self.is(dx, 0.0) {
                    dx
                } else {
                    let outer = self.outer_derivative(f, x, a);
                    self.mul(outer, dx)
                }
            }
            Node::Powi(x, n) => {
                // (xⁿ)' = n xⁿ⁻¹ x'
                let dx = self.derivative(x, var);
                let n_f = self.number(f64::from(n));
                let lower = self.powi(x, n - 1);
                let outer = self.mul(n_f, lower);
                self.mul(outer, dx)
            }
            Node::Powf(x, c) => {
                // (x^c)' = c x^(c−1) x'
                let dx = self.derivative(x, var);
                let one = self.number(1.0);
                let exponent = self.sub(c, one);
                let lower = self.intern(Node::Powf(x, exponent));
                let outer = self.mul(c, lower);
                self.mul(outer, dx)
            }
            Node::Atan2(y, x) => {
                // atan2(y, x)' = (x y' − y x') / (x² + y²)
                let (dy, dx) = (self.derivative(y, var), self.derivative(x, var));
                let (l, r) = (self.mul(x, dy), self.mul(y, dx));
                let numerator = self.sub(l, r);
                let (xx, yy) = (self.square(x), self.square(y));
                let denominator = self.add(xx, yy);
                self.div(numerator, denominator)
            }
        };
        self.derivatives.insert((a, var), d);
        d
    }

    /// `f'(x)`, where node `fx` is `f(x)`.
    fn outer_derivative(&mut self, f: Function, x: Id, fx: Id) -> Id {
        let one = self.number(1.0);
        // 1 / sqrt(s · (1 − x²)) or similar: `reciprocal_root(u)` = 1/√u.
        let reciprocal_root = |g: &mut Graph, u: Id| {
            let root = g.call(Function::Sqrt, u);
            g.reciprocal(root)
        };
        match f {
            Function::Sin => self.call(Function::Cos, x),
            Function::Cos => {
                let s = self.call(Function::Sin, x);
                self.neg(s)
            }
            Function::Tan => {
                let t2 = self.square(fx);
                self.add(one, t2)
            }
            Function::Asin => {
                let x2 = self.square(x);
                let u = self.sub(one, x2);
                reciprocal_root(self, u)
            }
            Function::Acos => {
                let x2 = self.square(x);
                let u = self.sub(one, x2);
                let r = reciprocal_root(self, u);
                self.neg(r)
            }
            Function::Atan => {
                let x2 = self.square(x);
                let u = self.add(one, x2);
                self.reciprocal(u)
            }
            Function::Sinh => self.call(Function::Cosh, x),
            Function::Cosh => self.call(Function::Sinh, x),
            Function::Tanh => {
                let t2 = self.square(fx);
                self.sub(one, t2)
            }
            Function::Asinh => {
                let x2 = self.square(x);
                let u = self.add(x2, one);
                reciprocal_root(self, u)
            }
            Function::Acosh => {
                let x2 = self.square(x);
                let u = self.sub(x2, one);
                reciprocal_root(self, u)
            }
            Function::Atanh => {
                let x2 = self.square(x);
                let u = self.sub(one, x2);
                self.reciprocal(u)
            }
            Function::Exp => fx,
            Function::Exp2 => {
                let ln2 = self.number(std::f64::consts::LN_2);
                self.mul(fx, ln2)
            }
            Function::ExpM1 => self.call(Function::Exp, x),
            Function::Ln => self.reciprocal(x),
            Function::Ln1p => {
                let u = self.add(one, x);
                self.reciprocal(u)
            }
            Function::Log2 => {
                let ln2 = self.number(std::f64::consts::LN_2);
                let u = self.mul(x, ln2);
                self.reciprocal(u)
            }
            Function::Log10 => {
                let ln10 = self.number(std::f64::consts::LN_10);
                let u = self.mul(x, ln10);
                self.reciprocal(u)
            }
            Function::Sqrt => {
                // ½ (1/√x): the reciprocal a quotient by √x shares.
                let half = self.number(0.5);
                let r = self.reciprocal(fx);
                self.mul(half, r)
            }
            Function::Cbrt => {
                let three = self.number(3.0);
                let u = self.mul(three, x);
                self.div(fx, u)
            }
            Function::Recip => {
                let r2 = self.square(fx);
                self.neg(r2)
            }
            Function::Abs => self.call(Function::Signum, x),
            Function::Signum => self.number(0.0),
        }
    }
}

/// Reads the user's expression into the graph; `None` where it leaves the graph's language.
struct Reader<'a> {
    graph: &'a mut Graph,
    /// Each coordinate's name, flat offset and length (`None`: a single coordinate).
    coordinates: Vec<(syn::Ident, usize, Option<usize>)>,
    n: usize,
    /// Whether a differential `dx`, `dtheta[i]` reads as the rate of its coordinate (a one-form).
    differentials: bool,
    /// A force one-form's reading: velocities `dot(x)` are variables `n..2n`, differentials
    /// `2n..3n`, and the names in `varying` (the time, the inputs) `3n..`.
    forces: Option<Vec<String>>,
}

impl Reader<'_> {
    fn coordinate(&self, ident: &syn::Ident) -> Option<&(syn::Ident, usize, Option<usize>)> {
        self.coordinates.iter().find(|(name, ..)| name == ident)
    }

    /// The coordinate whose differential `ident` is (`dx` for `x`), where differentials are read.
    fn differential(&self, ident: &syn::Ident) -> Option<&(syn::Ident, usize, Option<usize>)> {
        let name = ident.to_string();
        let rest = name.strip_prefix('d').filter(|_| self.differentials)?;
        self.coordinates.iter().find(|(name, ..)| name == rest)
    }

    /// The rate variable of a differential `dx` or `dtheta[i]` (literal `i`).
    fn rate(&mut self, expr: &Expr) -> Option<Id> {
        let i = match expr {
            Expr::Path(p) => {
                let (_, offset, length) = self.differential(p.path.get_ident()?)?;
                length.is_none().then_some(*offset)?
            }
            Expr::Index(ix) => {
                let Expr::Path(p) = &*ix.expr else {
                    return None;
                };
                let (_, offset, length) = self.differential(p.path.get_ident()?)?;
                let i = literal_index(&ix.index)?;
                (i < (*length)?).then_some(offset + i)?
            }
            _ => return None,
        };
        let rates = if self.forces.is_some() {
            2 * self.n
        } else {
            self.n
        };
        Some(self.graph.intern(Node::Variable(rates + i)))
    }

    /// Which of a force's varying names (the time, an input) `p` is.
    fn varying(&self, p: &syn::ExprPath) -> Option<usize> {
        let name = p.path.get_ident()?.to_string();
        self.forces.as_ref()?.iter().position(|v| *v == name)
    }

    /// An entry `m[i][j]` of a parameter's array of arrays (literal indices): a constant. `None`
    /// where a coordinate is indexed.
    fn entry(&mut self, ix: &syn::ExprIndex) -> Option<Id> {
        let mut base = &*ix.expr;
        literal_index(&ix.index)?;
        while let Expr::Index(inner) = base {
            literal_index(&inner.index)?;
            base = &inner.expr;
        }
        let Expr::Path(p) = base else {
            return None;
        };
        let ident = p.path.get_ident()?;
        if self.coordinate(ident).is_some() || self.differential(ident).is_some() {
            return None;
        }
        Some(self.graph.constant(ix.to_token_stream()))
    }

    /// The flat index of `x` or `theta[i]` (literal `i`).
    fn flat_index(&self, expr: &Expr) -> Option<usize> {
        match expr {
            Expr::Path(p) => {
                let (_, offset, length) = self.coordinate(p.path.get_ident()?)?;
                length.is_none().then_some(*offset)
            }
            Expr::Index(ix) => {
                let Expr::Path(p) = &*ix.expr else {
                    return None;
                };
                let (_, offset, length) = self.coordinate(p.path.get_ident()?)?;
                let i = literal_index(&ix.index)?;
                (i < (*length)?).then_some(offset + i)
            }
            Expr::Paren(p) => self.flat_index(&p.expr),
            Expr::Group(g) => self.flat_index(&g.expr),
            _ => None,
        }
    }

    fn read(&mut self, expr: &Expr) -> Option<Id> {
        if self.graph.nodes.len() > MAX_SOURCE {
            return None;
        }
        match expr {
            Expr::Lit(lit) => {
                let digits = match &lit.lit {
                    Lit::Float(f) => f.base10_digits().to_string(),
                    Lit::Int(i) => i.base10_digits().to_string(),
                    _ => return None,
                };
                let x: f64 = digits.parse().ok()?;
                x.is_finite().then(|| self.graph.number(x))
            }
            // In a one-form a differential comes first, as the form's splitter reads it: `dx`
            // is `x`'s differential even beside a coordinate named `dx`.
            Expr::Path(p)
                if p.path
                    .get_ident()
                    .and_then(|i| self.differential(i))
                    .is_some() =>
            {
                self.rate(expr)
            }
            Expr::Path(p) => match p.path.get_ident().and_then(|i| self.coordinate(i)) {
                Some(_) => Some(self.graph.intern(Node::Variable(self.flat_index(expr)?))),
                None => match self.varying(p) {
                    Some(k) => Some(self.graph.intern(Node::Variable(3 * self.n + k))),
                    None => Some(self.graph.constant(p.to_token_stream())),
                },
            },
            Expr::Index(ix) => {
                let Expr::Path(p) = &*ix.expr else {
                    return self.entry(ix);
                };
                let ident = p.path.get_ident();
                if ident.and_then(|i| self.differential(i)).is_some() {
                    return self.rate(expr);
                }
                match ident.and_then(|i| self.coordinate(i)) {
                    Some(_) => Some(self.graph.intern(Node::Variable(self.flat_index(expr)?))),
                    None => Some(self.graph.constant(ix.to_token_stream())),
                }
            }
            Expr::Paren(p) => self.read(&p.expr),
            Expr::Group(g) => self.read(&g.expr),
            Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => {
                let a = self.read(&u.expr)?;
                Some(self.graph.neg(a))
            }
            Expr::Binary(b) => {
                let family = Family::of(&b.op)?;
                let (first, links) = spine(b, family);
                let mut total = self.read(first)?;
                for (op, operand) in links {
                    let x = self.read(operand)?;
                    total = match op {
                        BinOp::Add(_) => self.graph.add(total, x),
                        BinOp::Sub(_) => self.graph.sub(total, x),
                        BinOp::Mul(_) => self.graph.mul(total, x),
                        BinOp::Div(_) => self.graph.div(total, x),
                        _ => return None,
                    };
                }
                Some(total)
            }
            Expr::Call(call) => {
                let Expr::Path(p) = &*call.func else {
                    return None;
                };
                let name = p.path.get_ident()?.to_string();
                let arguments: Vec<&Expr> = call.args.iter().collect();
                if name == "dot" && (!self.differentials || self.forces.is_some()) {
                    let [arg] = arguments[..] else {
                        return None;
                    };
                    let i = self.flat_index(arg)?;
                    return Some(self.graph.intern(Node::Variable(self.n + i)));
                }
                self.function(&name, &arguments)
            }
            Expr::MethodCall(m) if m.turbofish.is_none() => {
                let mut arguments = vec![&*m.receiver];
                arguments.extend(m.args.iter());
                self.function(&m.method.to_string(), &arguments)
            }
            _ => None,
        }
    }

    fn function(&mut self, name: &str, arguments: &[&Expr]) -> Option<Id> {
        match (name, arguments) {
            ("powi", [x, n]) => {
                // Exponents far from zero stay with dual numbers (and `n − 1` cannot overflow).
                let n = i32::try_from(signed_literal(n)?)
                    .ok()
                    .filter(|n| n.abs() <= 1 << 20)?;
                let x = self.read(x)?;
                Some(self.graph.powi(x, n))
            }
            ("powf" | "pow", [x, c]) => {
                let (x, c) = (self.read(x)?, self.read(c)?);
                if self.graph.state[c] {
                    return None;
                }
                Some(self.graph.intern(Node::Powf(x, c)))
            }
            ("atan2", [y, x]) => {
                let (y, x) = (self.read(y)?, self.read(x)?);
                Some(self.graph.intern(Node::Atan2(y, x)))
            }
            (name, [x]) => {
                let f = Function::of(name).filter(|f| *f != Function::Signum)?;
                let x = self.read(x)?;
                Some(self.graph.call(f, x))
            }
            _ => None,
        }
    }
}

fn literal_index(expr: &Expr) -> Option<usize> {
    match expr {
        Expr::Lit(syn::ExprLit {
            lit: Lit::Int(i), ..
        }) => i.base10_parse().ok(),
        _ => None,
    }
}

/// An integer literal, possibly negated or parenthesised.
fn signed_literal(expr: &Expr) -> Option<i64> {
    match expr {
        Expr::Lit(syn::ExprLit {
            lit: Lit::Int(i), ..
        }) => i.base10_parse().ok(),
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => signed_literal(&u.expr).map(|x| -x),
        Expr::Paren(p) => signed_literal(&p.expr),
        Expr::Group(g) => signed_literal(&g.expr),
        _ => None,
    }
}

/// The generated code of one closed form: `let` statements, then the outputs as expressions.
struct Emitted {
    statements: TokenStream,
    outputs: Vec<TokenStream>,
}

impl Graph {
    /// A node as an operand: leaves inline, other nodes by their `let`.
    fn operand(&self, id: Id) -> TokenStream {
        match &self.nodes[id] {
            Node::Number(bits) => {
                let x = f64::from_bits(*bits);
                let literal = Literal::f64_suffixed(x.abs());
                if x < 0.0 {
                    quote!((-#literal))
                } else {
                    literal.into_token_stream()
                }
            }
            Node::Constant(k) => {
                let tokens = &self.constants[*k];
                quote!((#tokens))
            }
            Node::Variable(i) if *i < self.n => quote!(__q[#i]),
            Node::Variable(i) => {
                let i = i - self.n;
                quote!(__v[#i])
            }
            _ => {
                let name = quote::format_ident!("__s{}", id);
                quote!(#name)
            }
        }
    }

    /// Straight-line code computing `outputs`: one `let` per operation they reach.
    fn emit(&self, outputs: &[Id]) -> Emitted {
        let mut needed = vec![false; self.nodes.len()];
        let mut stack: Vec<Id> = outputs.to_vec();
        while let Some(id) = stack.pop() {
            if needed[id] {
                continue;
            }
            needed[id] = true;
            match &self.nodes[id] {
                Node::Number(_) | Node::Constant(_) | Node::Variable(_) => {}
                Node::Neg(a) | Node::Call(_, a) | Node::Powi(a, _) => stack.push(*a),
                Node::Add(a, b)
                | Node::Sub(a, b)
                | Node::Mul(a, b)
                | Node::Div(a, b)
                | Node::Powf(a, b)
                | Node::Atan2(a, b) => stack.extend([*a, *b]),
            }
        }
        // `sin x` and `cos x` both needed: one `sin_cos` call gives the pair (libm computes
        // them together for about the price of one).
        let partner = |id: Id| match self.nodes[id] {
            Node::Call(f @ (Function::Sin | Function::Cos), a) => {
                let other = if f == Function::Sin {
                    Function::Cos
                } else {
                    Function::Sin
                };
                self.index
                    .get(&Node::Call(other, a))
                    .copied()
                    .filter(|&o| needed[o])
                    .map(|o| (f, a, o))
            }
            _ => None,
        };
        let mut statements = TokenStream::new();
        for (id, node) in self.nodes.iter().enumerate().filter(|(id, _)| needed[*id]) {
            if let Some((f, a, other)) = partner(id) {
                if other < id {
                    continue; // emitted with its partner
                }
                let (sin, cos) = match f {
                    Function::Sin => (id, other),
                    _ => (other, id),
                };
                let (sin, cos) = (
                    quote::format_ident!("__s{}", sin),
                    quote::format_ident!("__s{}", cos),
                );
                let a = self.operand(a);
                statements.extend(quote!(let (#sin, #cos): (f64, f64) = #a.sin_cos();));
                continue;
            }
            let value = match node {
                Node::Number(_) | Node::Constant(_) | Node::Variable(_) => continue,
                Node::Add(a, b) => binary(self.operand(*a), quote!(+), self.operand(*b)),
                Node::Sub(a, b) => binary(self.operand(*a), quote!(-), self.operand(*b)),
                Node::Mul(a, b) => binary(self.operand(*a), quote!(*), self.operand(*b)),
                Node::Div(a, b) => binary(self.operand(*a), quote!(/), self.operand(*b)),
                Node::Neg(a) => {
                    let a = self.operand(*a);
                    quote!(-#a)
                }
                Node::Call(f, a) => {
                    let (a, method) = (self.operand(*a), f.method());
                    quote!(#a.#method())
                }
                Node::Powi(a, n) => {
                    let a = self.operand(*a);
                    quote!(#a.powi(#n))
                }
                Node::Powf(a, c) => {
                    let (a, c) = (self.operand(*a), self.operand(*c));
                    quote!(#a.powf(#c))
                }
                Node::Atan2(y, x) => {
                    let (y, x) = (self.operand(*y), self.operand(*x));
                    quote!(#y.atan2(#x))
                }
            };
            let name = quote::format_ident!("__s{}", id);
            statements.extend(quote!(let #name: f64 = #value;));
        }
        Emitted {
            statements,
            outputs: outputs.iter().map(|&id| self.operand(id)).collect(),
        }
    }
}

fn binary(a: TokenStream, op: TokenStream, b: TokenStream) -> TokenStream {
    quote!(#a #op #b)
}

/// The bodies of `lagrangian_gradient` and `lagrangian_hessian` for a Lagrangian expression, in
/// a scope where the parameters are bound by name and `__q`, `__v` are the `f64` state.
pub struct ClosedForm {
    pub gradient: TokenStream,
    /// Whether `L` is finite at every finite state short of overflow ([`Graph::entire`]).
    pub entire: bool,
    /// `None` when the second derivatives exceed the size bound.
    pub hessian: Option<TokenStream>,
    /// Which entries of `∂²L/∂q²`, `∂²L/∂q∂v`, `∂²L/∂v²` vanish identically, each block by
    /// `[i][j]` (known with the Hessian; none otherwise).
    pub zeros: [Vec<Vec<bool>>; 3],
    /// Whether `∂²L/∂q∂v` vanishes and `∂²L/∂v²` depends on nothing but numbers and parameters:
    /// `L = ½ vᵀ M v + bᵀ v − V(q)` with constant `M` and `b` (known with the Hessian).
    pub separable: bool,
    /// Whether every second derivative depends on nothing but numbers and parameters and no
    /// `abs` or `signum` reads the state: `L` is a quadratic polynomial in `(q, v)` (known with
    /// the Hessian).
    pub quadratic: bool,
}

/// A coordinate's length: `Some(None)` for a single coordinate, `Some(Some(k))` for an array of
/// literal length `k`, `None` for a length named by a constant parameter.
fn literal_length(c: &Coordinate) -> Option<Option<usize>> {
    match &c.length {
        None => Some(None),
        Some(Length::Literal(k, _)) => Some(Some(*k)),
        Some(Length::Named(_)) => None,
    }
}

/// Each coordinate's name, flat offset and literal length; `None` where a length is not a
/// literal or the lengths do not add up to `n`.
fn layout(coordinates: &[Coordinate], n: usize) -> Option<Vec<(syn::Ident, usize, Option<usize>)>> {
    let mut offset = 0usize;
    let mut layout = Vec::new();
    for c in coordinates {
        let length = literal_length(c)?;
        layout.push((c.name.clone(), offset, length));
        offset += length.unwrap_or(1);
    }
    (offset == n).then_some(layout)
}

/// `expr` read into a new graph over `n` coordinates (differentials as rates where
/// `differentials`), with its node; `None` where it leaves the graph's language.
fn graph_of(
    expr: &Expr,
    coordinates: &[Coordinate],
    n: usize,
    differentials: bool,
) -> Option<(Graph, Id)> {
    let mut graph = Graph::new(n);
    let id = Reader {
        graph: &mut graph,
        coordinates: layout(coordinates, n)?,
        n,
        differentials,
        forces: None,
    }
    .read(expr)?;
    Some((graph, id))
}

/// Whether the force one-forms `Σ_i F_i(q, v, t, u) dq_i` are affine in the state with
/// constant coefficients, `F = K q + D v + f(t, u)`: each form linear in the differentials, every
/// derivative of a coefficient in a position or a velocity free of the state, the time and the
/// inputs (`varying`), and no `abs` or `signum` of the state. The forces' part of a step's
/// Jacobian is then the same at every step. `false` where a form leaves the graph's language
/// (a function of the runtime, an index not written as a literal).
pub fn forces_affine(
    forms: &[Expr],
    coordinates: &[Coordinate],
    n: usize,
    varying: &[String],
) -> bool {
    let Some(layout) = layout(coordinates, n) else {
        return false;
    };
    let mut graph = Graph::new(n);
    for form in forms {
        let Some(form) = (Reader {
            graph: &mut graph,
            coordinates: layout.clone(),
            n,
            differentials: true,
            forces: Some(varying.to_vec()),
        })
        .read(form) else {
            return false;
        };
        if graph.kinks(|i| i < 2 * n) {
            return false;
        }
        for i in 0..n {
            let coefficient = graph.derivative(form, 2 * n + i);
            for x in 0..2 * n {
                let slope = graph.derivative(coefficient, x);
                if graph.state[slope] {
                    return false;
                }
            }
            // Linear in the differentials.
            for k in 0..n {
                let moved = graph.derivative(coefficient, 2 * n + k);
                if !graph.is(moved, 0.0) {
                    return false;
                }
            }
            if graph.nodes.len() > MAX_GRAPH {
                return false;
            }
        }
    }
    true
}

/// The closed forms of `L`, or `None` where the expression leaves the graph's language.
pub fn closed_form(expr: &Expr, coordinates: &[Coordinate], n: usize) -> Option<ClosedForm> {
    let (mut graph, lagrangian) = graph_of(expr, coordinates, n, false)?;
    // Read before any derivative joins the graph: the property is the Lagrangian's own.
    let entire = graph.entire();
    let first: Vec<Id> = (0..2 * n)
        .map(|i| graph.derivative(lagrangian, i))
        .collect();
    if graph.nodes.len() > MAX_GRAPH {
        return None;
    }
    let vector = |values: &[TokenStream]| quote!(__dirac::nalgebra::SVector::<f64, #n>::from([#(#values),*]));
    let gradient = {
        let mut outputs = vec![lagrangian];
        outputs.extend(&first);
        let code = graph.emit(&outputs);
        let (statements, value) = (&code.statements, &code.outputs[0]);
        let (q, v) = (vector(&code.outputs[1..=n]), vector(&code.outputs[n + 1..]));
        quote! {
            #statements
            ::core::option::Option::Some(__dirac::LagrangianGradient { value: #value, q: #q, v: #v })
        }
    };
    // The second derivatives: ∂²L/∂x_i∂x_j for i ≤ j over x = (q, v).
    let mut second = Vec::new();
    for (i, &derivative) in first.iter().enumerate() {
        for j in i..2 * n {
            second.push((i, j, graph.derivative(derivative, j)));
            if graph.nodes.len() > MAX_GRAPH {
                return Some(ClosedForm {
                    gradient,
                    entire,
                    hessian: None,
                    zeros: Default::default(),
                    separable: false,
                    quadratic: false,
                });
            }
        }
    }
    let mut outputs = vec![lagrangian];
    outputs.extend(&first);
    outputs.extend(second.iter().map(|(_, _, id)| *id));
    let code = graph.emit(&outputs);
    let statements = &code.statements;
    let value = &code.outputs[0];
    let (q, v) = (
        vector(&code.outputs[1..=n]),
        vector(&code.outputs[n + 1..=2 * n]),
    );
    let entries = second
        .iter()
        .zip(&code.outputs[2 * n + 1..])
        .filter(|((_, _, id), _)| !graph.is(*id, 0.0))
        .map(|(&(i, j, _), x)| {
            let (block, i, j) = match (i < n, j < n) {
                (true, true) => (quote!(__qq), i, j),
                (true, false) => (quote!(__qv), i, j - n),
                _ => (quote!(__vv), i - n, j - n),
            };
            let mirrored = i != j && block.to_string() != "__qv";
            match mirrored {
                true => quote!(#block[(#i, #j)] = #x; #block[(#j, #i)] = #x;),
                false => quote!(#block[(#i, #j)] = #x;),
            }
        });
    let mut zeros: [Vec<Vec<bool>>; 3] = std::array::from_fn(|_| vec![vec![false; n]; n]);
    for &(i, j, id) in &second {
        let zero = graph.is(id, 0.0);
        match (i < n, j < n) {
            (true, true) => (zeros[0][i][j], zeros[0][j][i]) = (zero, zero),
            (true, false) => zeros[1][i][j - n] = zero,
            _ => (zeros[2][i - n][j - n], zeros[2][j - n][i - n]) = (zero, zero),
        }
    }
    // `abs` and `signum` of a velocity have derivatives that vanish almost everywhere but jump
    // (`c |v|` is linear in v on each side of 0 with a momentum offset that changes sign): not
    // separable, whatever the graph's second derivatives say.
    let separable = !graph.kinks(|i| i >= n)
        && second.iter().all(|&(i, j, id)| match (i < n, j < n) {
            (true, false) => graph.is(id, 0.0),
            (false, false) => !graph.state[id],
            _ => true,
        });
    // Every second derivative free of the state, and no kink anywhere: `L` is a quadratic
    // polynomial in `(q, v)`.
    let quadratic = !graph.kinks(|_| true) && second.iter().all(|&(_, _, id)| !graph.state[id]);
    let zero = quote!(__dirac::nalgebra::SMatrix::<f64, #n, #n>::zeros());
    let hessian = quote! {
        #statements
        let mut __qq = #zero;
        let mut __qv = #zero;
        let mut __vv = #zero;
        #(#entries)*
        ::core::option::Option::Some(__dirac::LagrangianHessian {
            gradient: __dirac::LagrangianGradient { value: #value, q: #q, v: #v },
            qq: __qq,
            qv: __qv,
            vv: __vv,
        })
    };
    Some(ClosedForm {
        gradient,
        entire,
        hessian: Some(hessian),
        zeros,
        separable,
        quadratic,
    })
}

/// The closed forms of `L` on `Rᴷ × SO(3)ᴬ` in the body frame, from `expr` lowered to the
/// atoms (the rotations' entries `R_rc` and angular velocities `Ω_c`): the graph's variables
/// are the vectors' coordinates and the entries (`K + 9A` positions, numbered as the runtime's
/// `BodyFrame` numbers them) and the rates (`K + 3A`, the chart's order); the emitted code
/// hands every derivative that is not identically zero to a `BodyFrame`, which turns them into
/// body-frame ones. `None` with unit vectors, a length that is not a literal, more than
/// [`MAX_BODY_VARIABLES`] variables, or where the expression leaves the graph's language.
pub fn closed_form_in_body_frame(expr: &Expr, coordinates: &[Coordinate]) -> Option<ClosedForm> {
    use crate::internals::ast::Kind;
    use crate::lower::atom::atom;
    let (mut reals, mut rotations) = (0usize, 0usize);
    let mut layout = Vec::new();
    for c in coordinates {
        let length = literal_length(c)?;
        let count = length.unwrap_or(1);
        match c.kind {
            Kind::Real => {
                layout.push((c.name.clone(), reals, length));
                reals = reals.checked_add(count)?;
            }
            Kind::Rotation => rotations = rotations.checked_add(count)?,
            Kind::Direction => return None,
        }
        // Every pair of the variables gets a second derivative: past this many, compile time
        // grows with their square for a Hessian the runtime can take by dual numbers.
        if reals.saturating_mul(2) > MAX_BODY_VARIABLES || rotations > MAX_BODY_VARIABLES / 12 {
            return None;
        }
    }
    let positions = reals + 9 * rotations;
    let n = reals + 3 * rotations;
    if positions + n > MAX_BODY_VARIABLES {
        return None;
    }
    // Each atom is a coordinate of its own: an entry a position, an angular velocity a rate
    // (variables from `positions` on are rates).
    let span = proc_macro2::Span::call_site();
    for a in 0..rotations {
        for r in 0..3 {
            for c in 0..3 {
                let entry = atom("R", a, &[r, c], span);
                layout.push((entry, reals + 9 * a + 3 * r + c, None));
            }
        }
        for c in 0..3 {
            layout.push((
                atom("W", a, &[c], span),
                positions + reals + 3 * a + c,
                None,
            ));
        }
    }
    let mut graph = Graph::new(positions);
    let lagrangian = Reader {
        graph: &mut graph,
        coordinates: layout,
        n: positions,
        differentials: false,
        forces: None,
    }
    .read(expr)?;
    let variables: Vec<usize> = (0..positions).chain(positions..positions + n).collect();
    let first: Vec<Id> = variables
        .iter()
        .map(|&x| graph.derivative(lagrangian, x))
        .collect();
    let mut second = Vec::new();
    for (i, &derivative) in first.iter().enumerate() {
        for (j, &y) in variables.iter().enumerate().skip(i) {
            second.push((i, j, graph.derivative(derivative, y)));
            if graph.nodes.len() > MAX_GRAPH {
                return None;
            }
        }
    }
    let hands = |i: usize| match i < positions {
        true => (quote!(position), i),
        false => (quote!(velocity), i - positions),
    };
    let bindings = {
        let point = (0..reals)
            .map(|k| quote!(__point.vector[#k]))
            .chain((0..rotations).flat_map(|a| {
                (0..9usize).map(move |e| {
                    let (r, c) = (e / 3, e % 3);
                    quote!(__point.rotation[#a][(#r, #c)])
                })
            }));
        let rates = (0..reals).map(|k| quote!(__rates.vector[#k])).chain(
            (0..rotations).flat_map(|a| (0..3usize).map(move |c| quote!(__rates.rotation[#a][#c]))),
        );
        quote! {
            let (__point, __rates) = (__q, __v);
            let __q: [f64; #positions] = [#(#point),*];
            let __v: [f64; #n] = [#(#rates),*];
        }
    };
    let body = |with_hessian: bool| {
        let mut outputs = vec![lagrangian];
        outputs.extend(&first);
        if with_hessian {
            outputs.extend(second.iter().map(|&(.., id)| id));
        }
        let code = graph.emit(&outputs);
        let statements = &code.statements;
        let value = &code.outputs[0];
        let gradient = first
            .iter()
            .zip(&code.outputs[1..=first.len()])
            .enumerate()
            .filter(|(_, (id, _))| !graph.is(**id, 0.0))
            .map(|(i, (_, x))| {
                let (hand, i) = hands(i);
                quote!(__forms.#hand(#i, #x);)
            });
        let hessian = second
            .iter()
            .zip(code.outputs.iter().skip(1 + first.len()))
            .filter(|((.., id), _)| !graph.is(*id, 0.0))
            .map(|(&(i, j, _), x)| {
                let ((a, i), (b, j)) = (hands(i), hands(j));
                let method = quote::format_ident!("{}_{}", a.to_string(), b.to_string());
                quote!(__forms.#method(#i, #j, #x);)
            });
        let finish = match with_hessian {
            true => quote!(hessian),
            false => quote!(gradient),
        };
        quote! {
            #bindings
            #statements
            let mut __forms =
                __dirac::body_frame::BodyFrame::<#n, #reals, #rotations>::new(__point, #value);
            #(#gradient)*
            #(#hessian)*
            ::core::option::Option::Some(__forms.#finish())
        }
    };
    Some(ClosedForm {
        gradient: body(false),
        entire: false,
        hessian: Some(body(true)),
        zeros: Default::default(),
        separable: false,
        quadratic: false,
    })
}

/// The body of `one_form_with_derivative` for a one-form `Σ_i A_i(q) dq_i` written in
/// differentials (in a scope where the parameters are bound by name, `__q` is the `f64` position
/// and `__entry(i, j, x)` takes `∂A_i/∂q_j`): straight-line `f64` code handing over the entries
/// that are not identically zero and returning the row `A(q)`, from one graph (a `sin` and a
/// `cos` shared by the row and its derivative are one call). `None` where the form leaves the
/// graph's language or is not linear in the differentials with coefficients of the positions
/// alone.
pub fn one_form_with_derivative(
    form: &Expr,
    coordinates: &[Coordinate],
    n: usize,
) -> Option<TokenStream> {
    let (mut graph, form) = graph_of(form, coordinates, n, true)?;
    let mut coefficients = Vec::new();
    let mut entries = Vec::new();
    for i in 0..n {
        let coefficient = graph.derivative(form, n + i);
        // Linear in the differentials: no coefficient moves with a rate.
        for k in 0..n {
            let moved = graph.derivative(coefficient, n + k);
            if !graph.is(moved, 0.0) {
                return None;
            }
        }
        for j in 0..n {
            let entry = graph.derivative(coefficient, j);
            if !graph.is(entry, 0.0) {
                entries.push((i, j, entry));
            }
        }
        coefficients.push(coefficient);
        if graph.nodes.len() > MAX_GRAPH {
            return None;
        }
    }
    let mut outputs = coefficients;
    outputs.extend(entries.iter().map(|&(.., id)| id));
    let code = graph.emit(&outputs);
    let statements = &code.statements;
    let row = &code.outputs[..n];
    let calls = entries
        .iter()
        .zip(&code.outputs[n..])
        .map(|(&(i, j, _), x)| quote!(__entry(#i, #j, #x);));
    Some(quote! {
        #statements
        #(#calls)*
        __dirac::nalgebra::SVector::<f64, #n>::from([#(#row),*])
    })
}
