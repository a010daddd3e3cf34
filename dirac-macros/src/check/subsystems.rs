//! A model made of subsystems: `#[dirac_system(subsystems(a, b, ...), junctions(...))]` on a
//! struct whose fields are the subsystems (each a `#[dirac_system]` model on `Rⁿ`). Its
//! Lagrangian is the sum of theirs, its one-forms theirs then the junctions (constant one-forms
//! over `instance.dcoordinate`), its constraints, forces and inputs theirs: the attribute
//! implements `DiracSystem` through each subsystem's `Slot` (the runtime's place of a part among
//! the whole's coordinates), and exposes the model as a subsystem in turn (a hierarchy).
//!
//! A field that is an array of models, `sections: [Section; 3]`, is that many subsystems,
//! `sections[0]`, `sections[1]`, …; a junction may be written once over an index,
//! `for i in 0..2 { node = s[i].l.dq - s[i + 1].l.dq }`, which is one junction per index
//! (`node[0]`, `node[1]`), the index read in `+` and `-` of integers.
//!
//! Checked here, on the user's tokens: subsystems that are not fields (or fields that are not
//! subsystems), arrays of subsystems without a literal length, junction terms naming an unknown
//! instance (an element past an array's end), an index loop that is not over a range of
//! integer literals, terms that are not `c * a.dx` with a
//! number literal `c`, zero coefficients, a coordinate twice in one junction, two junctions of
//! one name, and junctions that combine others (over-determined). A coordinate unknown to its
//! subsystem is reported when the program compiles, on the term, by a constant evaluation that
//! names it.

use proc_macro2::{Span, TokenStream};
use quote::quote;

use syn::spanned::Spanned;
use syn::{BinOp, Expr, Fields, Ident, Lit, Member, Pat, RangeLimits, Stmt, Type, UnOp};

use crate::internals::errors::Errors;

/// One term `coefficient · d(instance.path)` of a junction.
pub struct Term {
    /// Index of the subsystem among `subsystems(...)`.
    pub instance: usize,
    /// The coordinate's path inside the subsystem (`q`, `r.q`, `theta[2]`).
    pub path: String,
    pub coefficient: f64,
    pub span: Span,
}

/// A junction: a named constant one-form over the subsystems' coordinates.
pub struct Junction {
    pub name: String,
    pub span: Span,
    pub terms: Vec<Term>,
}

/// One subsystem: a field, or an element of a field that is an array of models.
pub struct Subsystem {
    pub field: Ident,
    /// The element, for a field that is an array.
    pub index: Option<usize>,
    /// The model's type.
    pub ty: Type,
}

impl Subsystem {
    /// Its instance name: `field` or `field[index]`.
    pub fn label(&self) -> String {
        match self.index {
            None => self.field.to_string(),
            Some(i) => format!("{}[{i}]", self.field),
        }
    }

    /// The expression that reads it from `self`.
    pub fn access(&self) -> TokenStream {
        let field = &self.field;
        match self.index {
            None => quote!(self.#field),
            Some(i) => quote!(self.#field[#i]),
        }
    }
}

/// The most elements an array of subsystems may have (each is expanded into the model's code).
const MAX_ELEMENTS: usize = 1000;

/// A validated model made of subsystems.
pub struct Composite {
    pub item: syn::ItemStruct,
    /// The subsystems, in the order of `subsystems(...)` (an array's elements in order).
    pub subsystems: Vec<Subsystem>,
    pub junctions: Vec<Junction>,
    /// The default quadrature's expression, when the attribute names one.
    pub quadrature: Option<TokenStream>,
    pub krate: syn::Path,
}

/// Reads `subsystems(...)` against the struct's fields and `junctions(...)` against the
/// subsystems, pushing every error into `errors`.
pub fn model(
    names: &[Ident],
    junctions: &[Expr],
    quadrature: Option<TokenStream>,
    item: syn::ItemStruct,
    krate: syn::Path,
    errors: &mut Errors,
) -> Option<Composite> {
    let before = errors.len();
    if let Some(g) = item.generics.params.first() {
        errors.push(
            g.span(),
            "a model made of subsystems may not be generic (its subsystems' sizes must be known)",
        );
    }
    let fields: Vec<(Ident, Type)> = match &item.fields {
        Fields::Named(named) => named
            .named
            .iter()
            .filter_map(|f| Some((f.ident.clone()?, f.ty.clone())))
            .collect(),
        other => {
            errors.push(
                other.span(),
                "subsystems are named fields: use a struct with named fields",
            );
            Vec::new()
        }
    };
    let mut subsystems: Vec<Subsystem> = Vec::new();
    for name in names {
        if subsystems.iter().any(|s| &s.field == name) {
            errors.push(name.span(), format!("`{name}` is listed twice"));
            continue;
        }
        match fields.iter().find(|(field, _)| field == name) {
            Some((_, Type::Array(array))) => match literal(&array.len) {
                Some(n) if n.fract() == 0.0 && (1.0..=MAX_ELEMENTS as f64).contains(&n) => {
                    subsystems.extend((0..n as usize).map(|i| Subsystem {
                        field: name.clone(),
                        index: Some(i),
                        ty: (*array.elem).clone(),
                    }))
                }
                _ => errors.push(
                    array.len.span(),
                    format!(
                        "an array of subsystems needs a literal length from 1 to {MAX_ELEMENTS}, \
                         e.g. `[Section; 3]`"
                    ),
                ),
            },
            Some((_, ty)) => subsystems.push(Subsystem {
                field: name.clone(),
                index: None,
                ty: ty.clone(),
            }),
            None => errors.push(
                name.span(),
                format!("`{name}` is not a field of the struct: a subsystem is a field whose type is a model"),
            ),
        }
    }
    for (field, _) in &fields {
        if !names.contains(field) {
            errors.push(
                field.span(),
                format!("field `{field}` is not among subsystems(...): every field of a model made of subsystems is one"),
            );
        }
    }
    let instances: Vec<String> = subsystems.iter().map(Subsystem::label).collect();
    let mut numbered = 0;
    let mut found = Vec::new();
    for expr in junctions {
        for (form, index) in unrolled(expr, errors) {
            if let Some(junction) = junction(&form, numbered, index, &instances, errors) {
                found.push(junction);
            }
            numbered += 1;
        }
    }
    let junctions = found;
    for (j, junction) in junctions.iter().enumerate() {
        if junctions[..j]
            .iter()
            .any(|other| other.name == junction.name)
        {
            errors.push(
                junction.span,
                format!("two junctions are named `{}`", junction.name),
            );
        }
    }
    if let Some((dependent, on)) = dependent(&junctions) {
        let on: Vec<String> = on
            .iter()
            .map(|&k| format!("`{}`", junctions[k].name))
            .collect();
        errors.push(
            junctions[dependent].span,
            format!(
                "junction `{}` is a combination of {}: the junctions over-determine the system \
                 (drop one)",
                junctions[dependent].name,
                if on.is_empty() {
                    "none (it is zero)".to_string()
                } else {
                    on.join(", ")
                }
            ),
        );
    }
    (errors.len() == before).then_some(Composite {
        item,
        subsystems,
        junctions,
        quadrature,
        krate,
    })
}

/// An index of an unrolled junction: the loop variable and its value.
type Index<'a> = Option<(&'a Ident, i64)>;

/// The junctions `expr` stands for: itself, or for `for i in a..b { … }` each junction of its
/// body at each `i` (its expressions, separated by `;` or `,`).
fn unrolled<'a>(expr: &'a Expr, errors: &mut Errors) -> Vec<(Expr, Index<'a>)> {
    let Expr::ForLoop(for_loop) = expr else {
        return vec![(expr.clone(), None)];
    };
    let Pat::Ident(variable) = &*for_loop.pat else {
        errors.push(
            for_loop.pat.span(),
            "the index of a junction loop is a name: `for i in 0..3 { ... }`",
        );
        return Vec::new();
    };
    let range = match &*for_loop.expr {
        Expr::Range(range) => {
            let end = |e: &Option<Box<Expr>>| e.as_deref().and_then(literal);
            match (end(&range.start), end(&range.end)) {
                (Some(a), Some(b))
                    if a.fract() == 0.0 && b.fract() == 0.0 && a.abs().max(b.abs()) <= 1e9 =>
                {
                    let b = match range.limits {
                        RangeLimits::HalfOpen(_) => b as i64,
                        RangeLimits::Closed(_) => b as i64 + 1,
                    };
                    Some((a as i64, b))
                }
                _ => None,
            }
        }
        _ => None,
    };
    let Some((start, end)) = range.filter(|(a, b)| b - a <= MAX_ELEMENTS as i64) else {
        errors.push(
            for_loop.expr.span(),
            format!(
                "a junction loop runs over a range of integer literals of at most \
                 {MAX_ELEMENTS} values, e.g. `0..3`"
            ),
        );
        return Vec::new();
    };
    let mut forms = Vec::new();
    for statement in &for_loop.body.stmts {
        match statement {
            Stmt::Expr(form, _) => forms.push(form.clone()),
            other => errors.push(
                other.span(),
                "the body of a junction loop holds junctions: `name = a[i].dq - b[i].dx`",
            ),
        }
    }
    let variable = &variable.ident;
    (start..end)
        .flat_map(|i| {
            forms
                .iter()
                .map(move |form| (form.clone(), Some((variable, i))))
        })
        .collect()
}

/// `name = form` or `form` (named `junction_j`), its terms read at `index` (a loop's junction is
/// named `name[i]`).
fn junction(
    expr: &Expr,
    j: usize,
    index: Index<'_>,
    instances: &[String],
    errors: &mut Errors,
) -> Option<Junction> {
    let (name, form) = match expr {
        Expr::Assign(assign) => match &*assign.left {
            Expr::Path(p) if p.path.get_ident().is_some() => {
                let name = p.path.get_ident()?.to_string();
                let name = match index {
                    Some((_, i)) => format!("{name}[{i}]"),
                    None => name,
                };
                (name, &*assign.right)
            }
            other => {
                errors.push(
                    other.span(),
                    "a junction's name is an identifier: `kcl = ...`",
                );
                return None;
            }
        },
        form => (format!("junction_{j}"), form),
    };
    let before = errors.len();
    let mut terms = Vec::new();
    collect(form, 1.0, index, instances, &mut terms, errors);
    for (k, term) in terms.iter().enumerate() {
        let seen = terms[..k]
            .iter()
            .any(|t| t.instance == term.instance && t.path == term.path);
        if seen {
            errors.push(
                term.span,
                format!(
                    "junction `{name}` names `{}.{}` twice: write one term",
                    instances[term.instance], term.path
                ),
            );
        }
    }
    (errors.len() == before && !terms.is_empty()).then(|| Junction {
        name,
        span: expr.span(),
        terms,
    })
}

const FORM: &str = "a junction is a sum of terms `c * instance.dx` (a number literal `c`, the \
                    differential `dx` of the subsystem's coordinate `x`, e.g. \
                    `loop.dq - pair.c1.dq`)";

/// The terms of `form` with their signs, at `index`.
fn collect(
    form: &Expr,
    sign: f64,
    index: Index<'_>,
    instances: &[String],
    terms: &mut Vec<Term>,
    errors: &mut Errors,
) {
    match form {
        Expr::Paren(p) => collect(&p.expr, sign, index, instances, terms, errors),
        Expr::Group(g) => collect(&g.expr, sign, index, instances, terms, errors),
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => {
            collect(&u.expr, -sign, index, instances, terms, errors)
        }
        Expr::Binary(b) if matches!(b.op, BinOp::Add(_) | BinOp::Sub(_)) => {
            collect(&b.left, sign, index, instances, terms, errors);
            let right = if matches!(b.op, BinOp::Sub(_)) {
                -sign
            } else {
                sign
            };
            collect(&b.right, right, index, instances, terms, errors);
        }
        Expr::Binary(b) if matches!(b.op, BinOp::Mul(_)) => {
            let (number, differential) = match (literal(&b.left), literal(&b.right)) {
                (Some(c), None) => (c, &*b.right),
                (None, Some(c)) => (c, &*b.left),
                _ => return errors.push(form.span(), FORM),
            };
            if number == 0.0 || !number.is_finite() {
                return errors.push(
                    form.span(),
                    "a junction's coefficient must be finite and nonzero",
                );
            }
            collect(differential, sign * number, index, instances, terms, errors);
        }
        other => match differential(other, index) {
            Some((instance, span, path)) => match instances.iter().position(|i| *i == instance) {
                Some(position) => terms.push(Term {
                    instance: position,
                    path,
                    coefficient: sign,
                    span: other.span(),
                }),
                None => errors.push(
                    span,
                    format!(
                        "unknown subsystem `{instance}`; the subsystems are {}",
                        instances
                            .iter()
                            .map(|i| format!("`{i}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ),
            },
            None => errors.push(other.span(), FORM),
        },
    }
}

/// A number literal (integer or float), possibly negated.
fn literal(expr: &Expr) -> Option<f64> {
    match expr {
        Expr::Lit(l) => match &l.lit {
            Lit::Float(f) => f.base10_parse().ok(),
            Lit::Int(i) => i.base10_parse::<f64>().ok(),
            _ => None,
        },
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => literal(&u.expr).map(|x| -x),
        Expr::Paren(p) => literal(&p.expr),
        _ => None,
    }
}

/// The value of an index: an integer literal, the loop's variable, or their sums and
/// differences.
fn index_value(expr: &Expr, index: Index<'_>) -> Option<i64> {
    match expr {
        Expr::Path(p) => {
            let (variable, value) = index?;
            p.path.is_ident(variable).then_some(value)
        }
        Expr::Paren(p) => index_value(&p.expr, index),
        Expr::Binary(b) if matches!(b.op, BinOp::Add(_)) => {
            index_value(&b.left, index)?.checked_add(index_value(&b.right, index)?)
        }
        Expr::Binary(b) if matches!(b.op, BinOp::Sub(_)) => {
            index_value(&b.left, index)?.checked_sub(index_value(&b.right, index)?)
        }
        other => literal(other)
            .filter(|k| k.fract() == 0.0 && k.abs() <= 1e15)
            .map(|k| k as i64),
    }
}

/// `instance.(path.)dx` or `instance.(path.)dx[i]`, the instance possibly an array's element
/// `a[k]`: the instance's name, its span and the coordinate's path inside it (`x`, `path.x`,
/// `x[i]`), the indices read at `index`.
fn differential(expr: &Expr, at: Index<'_>) -> Option<(String, Span, String)> {
    let (field, index) = match expr {
        Expr::Index(i) => match (&*i.expr, index_value(&i.index, at)) {
            (Expr::Field(f), Some(k)) if k >= 0 => (f, Some(k as usize)),
            _ => return None,
        },
        Expr::Field(f) => (f, None),
        _ => return None,
    };
    let Member::Named(member) = &field.member else {
        return None;
    };
    let coordinate = member.to_string().strip_prefix('d')?.to_string();
    if coordinate.is_empty() {
        return None;
    }
    let mut segments = Vec::new();
    let mut base = &*field.base;
    let instance = loop {
        match base {
            Expr::Field(f) => match &f.member {
                Member::Named(m) => {
                    segments.push(m.to_string());
                    base = &f.base;
                }
                Member::Unnamed(_) => return None,
            },
            Expr::Path(p) => {
                let name = p.path.get_ident()?;
                break (name.to_string(), name.span());
            }
            Expr::Index(i) => match (&*i.expr, index_value(&i.index, at)) {
                (Expr::Path(p), Some(k)) => {
                    let name = p.path.get_ident()?;
                    break (format!("{name}[{k}]"), base.span());
                }
                _ => return None,
            },
            _ => return None,
        }
    };
    segments.reverse();
    segments.push(match index {
        Some(k) => format!("{coordinate}[{k}]"),
        None => coordinate,
    });
    let (instance, span) = instance;
    Some((instance, span, segments.join(".")))
}

/// The first junction that combines the ones before it (Gram–Schmidt over the coordinates'
/// paths, relative tolerance 1e-10), with the junctions it combines.
fn dependent(junctions: &[Junction]) -> Option<(usize, Vec<usize>)> {
    let mut keys: Vec<(usize, &str)> = Vec::new();
    for t in junctions.iter().flat_map(|j| &j.terms) {
        if !keys.contains(&(t.instance, t.path.as_str())) {
            keys.push((t.instance, &t.path));
        }
    }
    let row = |j: &Junction| -> Vec<f64> {
        keys.iter()
            .map(|&(i, p)| {
                j.terms
                    .iter()
                    .filter(|t| t.instance == i && t.path == p)
                    .map(|t| t.coefficient)
                    .sum()
            })
            .collect()
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    // Orthonormal basis, each with its expression in the junctions' rows.
    let mut basis: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    for (j, junction) in junctions.iter().enumerate() {
        // Scaled to a largest entry of 1: no coefficient overflows or underflows.
        let original = row(junction);
        let largest = original.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let original: Vec<f64> = original.iter().map(|x| x / largest).collect();
        let mut rest = original.clone();
        let mut expression = vec![0.0; junctions.len()];
        expression[j] = 1.0;
        for _ in 0..2 {
            for (e, combination) in &basis {
                let c = dot(e, &rest);
                rest.iter_mut().zip(e).for_each(|(r, x)| *r -= c * x);
                expression
                    .iter_mut()
                    .zip(combination)
                    .for_each(|(r, x)| *r -= c * x);
            }
        }
        let norm = dot(&rest, &rest).sqrt();
        if norm <= 1e-10 * dot(&original, &original).sqrt() {
            // rest = Σ expression_k row_k ≈ 0: the row combines those with weight in it.
            let largest = expression.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let on = (0..j)
                .filter(|&k| expression[k].abs() > 1e-9 * largest)
                .collect();
            return Some((j, on));
        }
        rest.iter_mut().for_each(|x| *x /= norm);
        expression.iter_mut().for_each(|x| *x /= norm);
        basis.push((rest, expression));
    }
    None
}
