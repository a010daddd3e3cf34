//! One-forms written in differentials, `sin(phi)*dx - cos(phi)*dy` or `-r * dot(q_l) * dq_l`:
//! checked to be linear in the differentials and split into one coefficient per differential,
//! each rewritten like the Lagrangian. Sums and products are walked as loops over their left
//! spine; only nesting recurses, capped like the Lagrangian's.

use proc_macro2::{Span, TokenStream};
use quote::quote_spanned;
use syn::{BinOp, Expr, ExprIndex, UnOp};

use crate::internals::ast::{Coordinate, Term, offsets};
use crate::lower::atom::differential_index;
use crate::lower::expression::{Family, Piece, Rewriter, bounds, spine, subexpressions};

/// Splits `form` into terms `coefficient · d(coordinate)`; errors go into the rewriter's context.
pub fn terms(form: &Expr, rewriter: &mut Rewriter) -> Vec<Term> {
    let offsets = offsets(rewriter.scope.coordinates);
    let mut splitter = Splitter { rewriter, offsets };
    if !splitter.contains(form) {
        splitter.no_differential(form);
        return Vec::new();
    }
    let parts = splitter.split(form, 0);
    collected(parts, splitter.rewriter)
        .into_iter()
        .map(|(index, coefficient)| Term {
            index,
            span: coefficient.span(),
            coefficient: coefficient.into_scalar(),
        })
        .collect()
}

/// The terms of one differential summed into one coefficient, in order of first appearance:
/// `Σ_k c_k dx` is one statement `w[x] += Σ_k c_k` (a chain the rewriter emits in bounded
/// chunks), not one statement per term, which LLVM optimises in time growing faster than
/// linearly with the number of statements.
fn collected(parts: Vec<Part>, rewriter: &Rewriter) -> Vec<Part> {
    let mut groups: Vec<(String, TokenStream, Vec<Piece>)> = Vec::new();
    for (index, coefficient) in parts {
        let key = index.to_string();
        match groups.iter_mut().find(|(k, ..)| *k == key) {
            Some((.., pieces)) => pieces.push(coefficient),
            None => groups.push((key, index, vec![coefficient])),
        }
    }
    groups
        .into_iter()
        .filter_map(|(_, index, pieces)| {
            let mut pieces = pieces.into_iter();
            let first = pieces.next()?;
            let links: Vec<(BinOp, Piece)> = pieces
                .map(|p| (BinOp::Add(syn::Token![+](p.span())), p))
                .collect();
            let sum = if links.is_empty() {
                first
            } else {
                rewriter.combine(Family::Sum, first, links)
            };
            Some((index, sum))
        })
        .collect()
}

/// Whether the differential of one of `coordinates` occurs in `expr` (or a lowered differential
/// of a rotation or unit vector).
pub fn has_differential(expr: &Expr, coordinates: &[Coordinate]) -> bool {
    subexpressions(expr).any(|e| differential(coordinates, e).is_some() || lowered(e).is_some())
}

/// The index among a tangent vector's numbers of a lowered differential `dR`, `dn` (see
/// `vector_algebra`).
fn lowered(expr: &Expr) -> Option<usize> {
    match expr {
        Expr::Path(p) => differential_index(p.path.get_ident()?),
        _ => None,
    }
}

/// `dx` or `dtheta[i]`: the coordinate's position and the indexing, not yet checked.
fn differential<'e>(
    coordinates: &[Coordinate],
    expr: &'e Expr,
) -> Option<(usize, Option<&'e ExprIndex>)> {
    let (path, index) = match expr {
        Expr::Path(p) => (p, None),
        Expr::Index(ix) => match &*ix.expr {
            Expr::Path(p) => (p, Some(ix)),
            _ => return None,
        },
        _ => return None,
    };
    let name = path.path.get_ident()?.to_string();
    let rest = name.strip_prefix('d')?;
    let k = coordinates.iter().position(|c| c.name == rest)?;
    Some((k, index))
}

struct Splitter<'r, 'a> {
    rewriter: &'r mut Rewriter<'a>,
    offsets: Vec<TokenStream>,
}

/// A term being split: the flat index of its differential and its coefficient.
type Part = (TokenStream, Piece);

impl Splitter<'_, '_> {
    fn coordinates(&self) -> &[Coordinate] {
        self.rewriter.scope.coordinates
    }

    fn contains(&self, expr: &Expr) -> bool {
        has_differential(expr, self.coordinates())
    }

    fn names(&self, prefix: &str) -> String {
        let names: Vec<String> = self
            .coordinates()
            .iter()
            .map(|c| format!("`{prefix}{}`", c.name))
            .collect();
        names.join(", ")
    }

    fn error(&mut self, span: Span, message: impl std::fmt::Display) -> Vec<Part> {
        self.rewriter.errors.push(span, message);
        Vec::new()
    }

    fn not_linear(&mut self, expr: &Expr, why: &str) -> Vec<Part> {
        let (start, end) = bounds(expr);
        self.rewriter.errors.push_range(
            start,
            end,
            format!("a one-form must be linear in the differentials: {why}"),
        );
        Vec::new()
    }

    /// Reports a term without a differential, naming a stray `dz` if it has one.
    fn no_differential(&mut self, expr: &Expr) {
        let stray = subexpressions(expr).find_map(|e| match e {
            Expr::Path(p) => p.path.get_ident().filter(|i| {
                let name = i.to_string();
                name.len() > 1 && name.starts_with('d')
            }),
            _ => None,
        });
        if let Some(stray) = stray {
            let message = format!(
                "`{stray}` is not the differential of a coordinate; the coordinates are {}",
                self.names("")
            );
            self.rewriter.errors.push(stray.span(), message);
            return;
        }
        let (start, end) = bounds(expr);
        let message = format!(
            "this term has no differential: a one-form is a sum of terms, each a coefficient \
             times one of {}",
            self.names("d")
        );
        self.rewriter.errors.push_range(start, end, message);
    }

    /// The flat index of `dx` or `dtheta[i]` with coefficient one; an index the macro cannot check
    /// is checked by rustc ([`Rewriter::checked_index`]).
    fn differential(&mut self, k: usize, index: Option<&ExprIndex>, expr: &Expr) -> Vec<Part> {
        let coordinate = &self.rewriter.scope.coordinates[k];
        let offset = self.offsets[k].clone();
        let (span, _) = bounds(expr);
        match (&coordinate.length, index) {
            (None, None) => vec![(offset, Piece::one(span))],
            (Some(_), Some(ix)) => {
                if !self.rewriter.index(coordinate, &ix.index) {
                    return Vec::new();
                }
                let i = self.rewriter.checked_index(coordinate, &ix.index);
                let (at, _) = bounds(&ix.index);
                let index = quote_spanned!(at=> #offset + #i);
                vec![(index, Piece::one(span))]
            }
            (Some(_), None) => {
                let message = format!(
                    "`{0}` is an array: write the differential of one element, e.g. d{0}[0]",
                    coordinate.name
                );
                self.error(span, message)
            }
            (None, Some(_)) => {
                let message = format!("`{}` is a single coordinate, not an array", coordinate.name);
                self.error(span, message)
            }
        }
    }

    /// Splits `expr`, which contains a differential, at nesting `depth`.
    fn split(&mut self, expr: &Expr, depth: usize) -> Vec<Part> {
        if !self.rewriter.within_nesting(expr, depth) {
            return Vec::new();
        }
        if let Some((k, index)) = differential(self.coordinates(), expr) {
            return self.differential(k, index, expr);
        }
        if let Some(index) = lowered(expr) {
            let span = bounds(expr).0;
            return vec![(quote_spanned!(span=> #index), Piece::one(span))];
        }
        match expr {
            Expr::Paren(p) => self.split(&p.expr, depth + 1),
            Expr::Group(g) => self.split(&g.expr, depth + 1),
            Expr::Unary(syn::ExprUnary {
                op: UnOp::Neg(minus),
                expr: inner,
                ..
            }) => negated(self.split(inner, depth + 1), minus.span),
            Expr::Binary(b) => match Family::of(&b.op) {
                Some(Family::Sum) => self.sum(b, depth),
                Some(Family::Product) => self.product(b, expr, depth),
                None => self.not_linear(expr, "only + - * / combine its terms"),
            },
            _ => self.not_linear(
                expr,
                "a differential appears inside a function or method call",
            ),
        }
    }

    /// `a ± b ± ...`: every term must have a differential.
    fn sum(&mut self, b: &syn::ExprBinary, depth: usize) -> Vec<Part> {
        let (first, links) = spine(b, Family::Sum);
        let mut parts = Vec::new();
        for (op, operand) in
            std::iter::once((None, first)).chain(links.into_iter().map(|(op, e)| (Some(op), e)))
        {
            if !self.contains(operand) {
                self.no_differential(operand);
                continue;
            }
            let split = self.split(operand, depth + 1);
            match op {
                Some(BinOp::Sub(minus)) => parts.extend(negated(split, minus.span)),
                _ => parts.extend(split),
            }
        }
        parts
    }

    /// `a * b / c ...` with exactly one factor, not a divisor, holding the differentials: each of
    /// its terms becomes the product with that factor replaced by the term's coefficient.
    fn product(&mut self, b: &syn::ExprBinary, expr: &Expr, depth: usize) -> Vec<Part> {
        let (first, links) = spine(b, Family::Product);
        let factors: Vec<(Option<&BinOp>, &Expr)> = std::iter::once((None, first))
            .chain(links.iter().map(|&(op, e)| (Some(op), e)))
            .collect();
        let with: Vec<usize> = (0..factors.len())
            .filter(|&i| self.contains(factors[i].1))
            .collect();
        let j = match with[..] {
            [j] => j,
            [_, second, ..] => {
                return self.not_linear(factors[second].1, "this multiplies two differentials");
            }
            [] => {
                self.no_differential(expr);
                return Vec::new();
            }
        };
        if let (Some(BinOp::Div(_)), factor) = factors[j] {
            return self.not_linear(factor, "this divides by a differential");
        }
        let mut rewrite = |i: usize, e: &Expr| (i != j).then(|| self.rewriter.expr(e, depth + 1));
        let first = rewrite(0, first);
        let links: Vec<(BinOp, Option<Piece>)> = links
            .iter()
            .enumerate()
            .map(|(i, &(op, e))| (*op, rewrite(i + 1, e)))
            .collect();
        let inner = self.split(factors[j].1, depth + 1);
        inner
            .into_iter()
            .map(|(index, coefficient)| {
                let or_coefficient = |p: &Option<Piece>| p.clone().unwrap_or(coefficient.clone());
                let links = links
                    .iter()
                    .map(|(op, p)| (*op, or_coefficient(p)))
                    .collect();
                (
                    index,
                    self.rewriter
                        .combine(Family::Product, or_coefficient(&first), links),
                )
            })
            .collect()
    }
}

fn negated(parts: Vec<Part>, minus: Span) -> Vec<Part> {
    parts
        .into_iter()
        .map(|(index, coefficient)| (index, coefficient.negated(minus)))
        .collect()
}
