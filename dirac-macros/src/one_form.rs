//! One-forms written in differentials, `sin(phi)*dx - cos(phi)*dy` or `-r * dot(q_l) * dq_l`:
//! checked to be linear in the differentials and split into one coefficient per coordinate.

use proc_macro2::{Span, TokenStream};
use quote::quote;
use syn::spanned::Spanned;
use syn::{BinOp, Expr, Ident};

use crate::ast::Coordinate;

/// One term of a one-form: the coordinate's flat index (an expression) and its coefficient.
pub struct Term {
    pub index: TokenStream,
    pub coefficient: Expr,
}

/// Splits `expr` into terms `coefficient · d(coordinate)`; every error carries the user's span.
pub fn terms(
    expr: &Expr,
    coordinates: &[Coordinate],
    offsets: &[TokenStream],
) -> syn::Result<Vec<Term>> {
    let splitter = Splitter {
        coordinates,
        offsets,
    };
    if !splitter.contains(expr) {
        return Err(splitter.no_differential(expr));
    }
    splitter.split(expr)
}

struct Splitter<'a> {
    coordinates: &'a [Coordinate],
    offsets: &'a [TokenStream],
}

impl Splitter<'_> {
    /// The coordinate whose differential `ident` is (`dx` for `x`).
    fn differential(&self, ident: &Ident) -> Option<usize> {
        let name = ident.to_string();
        let rest = name.strip_prefix('d')?;
        self.coordinates.iter().position(|c| c.name == rest)
    }

    /// `dx`, or `dtheta[i]` for an array coordinate: the flat index.
    fn as_differential(&self, expr: &Expr) -> Option<syn::Result<TokenStream>> {
        match expr {
            Expr::Path(p) => {
                let k = self.differential(p.path.get_ident()?)?;
                let offset = &self.offsets[k];
                Some(match self.coordinates[k].length {
                    None => Ok(offset.clone()),
                    Some(_) => Err(syn::Error::new(
                        p.span(),
                        format!(
                            "`{}` is an array: write the differential of one element, e.g. d{}[0]",
                            self.coordinates[k].name, self.coordinates[k].name
                        ),
                    )),
                })
            }
            Expr::Index(ix) => {
                let Expr::Path(p) = &*ix.expr else {
                    return None;
                };
                let k = self.differential(p.path.get_ident()?)?;
                let offset = &self.offsets[k];
                let index = &ix.index;
                Some(match self.coordinates[k].length {
                    Some(_) => Ok(quote!((#offset + #index))),
                    None => Err(syn::Error::new(
                        ix.span(),
                        format!(
                            "`{}` is a single coordinate, not an array",
                            self.coordinates[k].name
                        ),
                    )),
                })
            }
            _ => None,
        }
    }

    /// Whether a differential occurs anywhere in `expr`.
    fn contains(&self, expr: &Expr) -> bool {
        if self.as_differential(expr).is_some() {
            return true;
        }
        match expr {
            Expr::Paren(p) => self.contains(&p.expr),
            Expr::Group(g) => self.contains(&g.expr),
            Expr::Unary(u) => self.contains(&u.expr),
            Expr::Binary(b) => self.contains(&b.left) || self.contains(&b.right),
            Expr::Call(c) => c.args.iter().any(|a| self.contains(a)),
            Expr::MethodCall(m) => {
                self.contains(&m.receiver) || m.args.iter().any(|a| self.contains(a))
            }
            Expr::Index(ix) => self.contains(&ix.expr),
            _ => false,
        }
    }

    /// An identifier `d…` in `expr` that is not the differential of a coordinate.
    fn stray_differential(&self, expr: &Expr) -> Option<Ident> {
        match expr {
            Expr::Path(p) => p
                .path
                .get_ident()
                .filter(|i| {
                    let name = i.to_string();
                    name.len() > 1 && name.starts_with('d') && self.differential(i).is_none()
                })
                .cloned(),
            Expr::Paren(p) => self.stray_differential(&p.expr),
            Expr::Group(g) => self.stray_differential(&g.expr),
            Expr::Unary(u) => self.stray_differential(&u.expr),
            Expr::Binary(b) => self
                .stray_differential(&b.left)
                .or_else(|| self.stray_differential(&b.right)),
            Expr::Index(ix) => self.stray_differential(&ix.expr),
            _ => None,
        }
    }

    fn no_differential(&self, expr: &Expr) -> syn::Error {
        if let Some(stray) = self.stray_differential(expr) {
            let names: Vec<String> = self
                .coordinates
                .iter()
                .map(|c| format!("`{}`", c.name))
                .collect();
            return syn::Error::new(
                stray.span(),
                format!(
                    "`{stray}` is not the differential of a coordinate; the coordinates are {}",
                    names.join(", ")
                ),
            );
        }
        let names: Vec<String> = self
            .coordinates
            .iter()
            .map(|c| format!("`d{}`", c.name))
            .collect();
        syn::Error::new(
            expr.span(),
            format!(
                "this term has no differential: a one-form is a sum of terms, each a coefficient \
                 times one of {}",
                names.join(", ")
            ),
        )
    }

    fn not_linear(span: Span, why: &str) -> syn::Error {
        syn::Error::new(
            span,
            format!("a one-form must be linear in the differentials: {why}"),
        )
    }

    fn scaled(terms: Vec<Term>, f: impl Fn(&Expr) -> Expr) -> Vec<Term> {
        terms
            .into_iter()
            .map(|t| Term {
                coefficient: f(&t.coefficient),
                index: t.index,
            })
            .collect()
    }

    fn split(&self, expr: &Expr) -> syn::Result<Vec<Term>> {
        if let Some(index) = self.as_differential(expr) {
            let span = expr.span();
            return Ok(vec![Term {
                index: index?,
                coefficient: syn::parse_quote_spanned!(span=> 1.0),
            }]);
        }
        match expr {
            Expr::Paren(p) => self.split(&p.expr),
            Expr::Group(g) => self.split(&g.expr),
            Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => Ok(Self::scaled(
                self.split(&u.expr)?,
                |c| syn::parse_quote_spanned!(u.span()=> -(#c)),
            )),
            Expr::Binary(b) => {
                let (left, right) = (self.contains(&b.left), self.contains(&b.right));
                match (&b.op, left, right) {
                    (BinOp::Add(_) | BinOp::Sub(_), true, true) => {
                        let mut terms = self.split(&b.left)?;
                        let rest = self.split(&b.right)?;
                        if matches!(b.op, BinOp::Sub(_)) {
                            terms.extend(Self::scaled(
                                rest,
                                |c| syn::parse_quote_spanned!(b.op.span()=> -(#c)),
                            ));
                        } else {
                            terms.extend(rest);
                        }
                        Ok(terms)
                    }
                    (BinOp::Add(_) | BinOp::Sub(_), false, _) => Err(self.no_differential(&b.left)),
                    (BinOp::Add(_) | BinOp::Sub(_), _, false) => {
                        Err(self.no_differential(&b.right))
                    }
                    (BinOp::Mul(_), true, true) => Err(Self::not_linear(
                        b.op.span(),
                        "this multiplies two differentials",
                    )),
                    (BinOp::Mul(_), false, true) => {
                        let factor = &b.left;
                        Ok(Self::scaled(
                            self.split(&b.right)?,
                            |c| syn::parse_quote_spanned!(b.op.span()=> (#factor) * (#c)),
                        ))
                    }
                    (BinOp::Mul(_), true, false) => {
                        let factor = &b.right;
                        Ok(Self::scaled(
                            self.split(&b.left)?,
                            |c| syn::parse_quote_spanned!(b.op.span()=> (#c) * (#factor)),
                        ))
                    }
                    (BinOp::Div(_), true, false) => {
                        let divisor = &b.right;
                        Ok(Self::scaled(
                            self.split(&b.left)?,
                            |c| syn::parse_quote_spanned!(b.op.span()=> (#c) / (#divisor)),
                        ))
                    }
                    (BinOp::Div(_), _, true) => Err(Self::not_linear(
                        b.right.span(),
                        "this divides by a differential",
                    )),
                    _ => Err(Self::not_linear(
                        b.op.span(),
                        "only +, −, ·, / combine its terms",
                    )),
                }
            }
            other if self.contains(other) => Err(Self::not_linear(
                other.span(),
                "a differential appears inside a function or method call",
            )),
            other => Err(self.no_differential(other)),
        }
    }
}
