//! `quadrature = midpoint | trapezoid | galerkin(s) | galerkin(s, gauss_legendre(r)) |
//! galerkin(s, gauss_lobatto(r))`, checked at compile time with the runtime's rules; and
//! `quadrature = explicit(name | order)`, the explicit step of a separable Lagrangian.

use proc_macro2::TokenStream;
use quote::{quote, quote_spanned};
use syn::spanned::Spanned;
use syn::{Expr, ExprCall, ExprLit, Lit};

/// Same limits as `dirac_runtime::quadrature`.
const MAX_DEGREE: usize = 8;
const MAX_NODES: usize = 16;

const EXPECTED: &str = "expected `midpoint`, `trapezoid`, `galerkin(s)`, \
     `galerkin(s, gauss_legendre(r))`, `galerkin(s, gauss_lobatto(r))` or `explicit(8)`";

/// The tokens building the runtime `Quadrature` named by `expr`.
pub fn parse(expr: &Expr) -> syn::Result<TokenStream> {
    let span = expr.span();
    match expr {
        Expr::Path(p) if p.path.is_ident("midpoint") => {
            Ok(quote_spanned!(span=> ::core::result::Result::Ok(__dirac::Quadrature::midpoint())))
        }
        Expr::Path(p) if p.path.is_ident("trapezoid") => {
            Ok(quote_spanned!(span=> ::core::result::Result::Ok(__dirac::Quadrature::trapezoid())))
        }
        Expr::Call(call) if callee(call).as_deref() == Some("galerkin") => galerkin(call),
        _ => Err(syn::Error::new(
            span,
            format!("unknown quadrature; {EXPECTED}"),
        )),
    }
}

/// The compositions `explicit(...)` may name, with the runtime's constructor of each.
const COMPOSITIONS: &[&str] = &[
    "verlet",
    "triple_jump",
    "suzuki",
    "kahan_li_6",
    "mclachlan_8",
    "kahan_li_8",
    "sofroniou_spaletta_10",
];

/// For `explicit(name)` or `explicit(order)`: the tokens building the runtime `Composition`
/// (`None` for any other expression).
pub fn explicit(expr: &Expr) -> Option<syn::Result<TokenStream>> {
    let Expr::Call(call) = expr else {
        return None;
    };
    if callee(call).as_deref() != Some("explicit") {
        return None;
    }
    let expected = format!(
        "explicit takes a composition, one of `{}`, or its order: 2, 4, 6, 8 or 10",
        COMPOSITIONS.join("`, `")
    );
    let args: Vec<&Expr> = call.args.iter().collect();
    let [arg] = args[..] else {
        return Some(Err(syn::Error::new(call.span(), expected)));
    };
    let name = match arg {
        Expr::Path(p) => p
            .path
            .get_ident()
            .map(|i| i.to_string())
            .filter(|n| COMPOSITIONS.contains(&n.as_str())),
        Expr::Lit(ExprLit {
            lit: Lit::Int(lit), ..
        }) => match lit.base10_parse::<usize>() {
            Ok(2) => Some("verlet".to_string()),
            Ok(4) => Some("suzuki".to_string()),
            Ok(6) => Some("kahan_li_6".to_string()),
            Ok(8) => Some("kahan_li_8".to_string()),
            Ok(10) => Some("sofroniou_spaletta_10".to_string()),
            _ => None,
        },
        _ => None,
    };
    Some(match name {
        Some(name) => {
            let constructor = syn::Ident::new(&name, arg.span());
            Ok(quote_spanned!(arg.span()=> __dirac::Composition::#constructor()))
        }
        None => Err(syn::Error::new(arg.span(), expected)),
    })
}

/// The name of a call's function when it is a bare identifier.
pub fn callee(call: &ExprCall) -> Option<String> {
    match &*call.func {
        Expr::Path(p) => p.path.get_ident().map(|i| i.to_string()),
        _ => None,
    }
}

fn count(expr: &Expr, what: &str) -> syn::Result<usize> {
    match expr {
        Expr::Lit(ExprLit {
            lit: Lit::Int(lit), ..
        }) => lit.base10_parse(),
        _ => Err(syn::Error::new(
            expr.span(),
            format!("the {what} must be an integer literal"),
        )),
    }
}

fn galerkin(call: &ExprCall) -> syn::Result<TokenStream> {
    let args: Vec<&Expr> = call.args.iter().collect();
    if args.is_empty() || args.len() > 2 {
        return Err(syn::Error::new(
            call.span(),
            "galerkin takes the degree and optionally a rule: galerkin(s) or galerkin(s, gauss_legendre(r))",
        ));
    }
    let degree = count(args[0], "degree")?;
    if degree == 0 || degree > MAX_DEGREE {
        return Err(syn::Error::new(
            args[0].span(),
            format!("the degree must be between 1 and {MAX_DEGREE}"),
        ));
    }
    let (lobatto, nodes, rule_span) = match args.get(1) {
        None => (false, degree, call.span()),
        Some(Expr::Call(rule))
            if matches!(
                callee(rule).as_deref(),
                Some("gauss_legendre" | "gauss_lobatto")
            ) =>
        {
            if rule.args.len() != 1 {
                return Err(syn::Error::new(
                    rule.span(),
                    "a rule takes its number of nodes: gauss_legendre(r)",
                ));
            }
            let nodes = count(&rule.args[0], "number of nodes")?;
            (
                callee(rule).as_deref() == Some("gauss_lobatto"),
                nodes,
                rule.span(),
            )
        }
        Some(other) => {
            return Err(syn::Error::new(
                other.span(),
                "unknown rule; expected `gauss_legendre(r)` or `gauss_lobatto(r)`",
            ));
        }
    };
    let needed = if lobatto { degree + 1 } else { degree };
    if nodes < needed || nodes > MAX_NODES {
        return Err(syn::Error::new(
            rule_span,
            format!(
                "degree {degree} needs between {needed} and {MAX_NODES} nodes of this rule \
                 (it has {} internal point(s) to determine), got {nodes}",
                degree - 1
            ),
        ));
    }
    let rule = if lobatto {
        quote!(__dirac::Rule::GaussLobatto(#nodes))
    } else {
        quote!(__dirac::Rule::GaussLegendre(#nodes))
    };
    Ok(quote_spanned!(call.span()=> __dirac::Quadrature::galerkin_with_rule(#degree, #rule)))
}
