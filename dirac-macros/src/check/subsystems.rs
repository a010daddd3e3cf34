//! A model made of subsystems: `#[dirac_system(subsystems(a, b, ...), junctions(...))]` on a
//! struct whose fields are the subsystems (each a `#[dirac_system]` model on `Rⁿ`). Its
//! Lagrangian is the sum of theirs, its one-forms theirs then the junctions (constant one-forms
//! over `instance.dcoordinate`), its constraints, forces and inputs theirs: the attribute
//! implements `DiracSystem` through each subsystem's `Slot` (the runtime's place of a part among
//! the whole's coordinates), and exposes the model as a subsystem in turn (a hierarchy).
//!
//! Checked here, on the user's tokens: subsystems that are not fields (or fields that are not
//! subsystems), junction terms naming an unknown instance, terms that are not `c * a.dx` with a
//! number literal `c`, zero coefficients, a coordinate twice in one junction, two junctions of
//! one name, and junctions that combine others (over-determined). A coordinate unknown to its
//! subsystem is reported when the program compiles, on the term, by a constant evaluation that
//! names it.

use proc_macro2::{Span, TokenStream};
use quote::{format_ident, quote, quote_spanned};
use syn::spanned::Spanned;
use syn::{BinOp, Expr, Fields, Ident, Lit, Member, Type, UnOp};

use crate::internals::errors::Errors;

/// One term `coefficient · d(instance.path)` of a junction.
struct Term {
    /// Index of the subsystem among `subsystems(...)`.
    instance: usize,
    /// The coordinate's path inside the subsystem (`q`, `r.q`, `theta[2]`).
    path: String,
    coefficient: f64,
    span: Span,
}

/// A junction: a named constant one-form over the subsystems' coordinates.
struct Junction {
    name: String,
    span: Span,
    terms: Vec<Term>,
}

/// A validated model made of subsystems.
pub struct Composite {
    item: syn::ItemStruct,
    /// The subsystems' fields and types, in the order of `subsystems(...)`.
    subsystems: Vec<(Ident, Type)>,
    junctions: Vec<Junction>,
    /// The default quadrature's expression, when the attribute names one.
    quadrature: Option<TokenStream>,
    krate: syn::Path,
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
    let mut subsystems = Vec::new();
    for name in names {
        if subsystems.iter().any(|(n, _): &(Ident, Type)| n == name) {
            errors.push(name.span(), format!("`{name}` is listed twice"));
            continue;
        }
        match fields.iter().find(|(field, _)| field == name) {
            Some((_, ty @ Type::Array(_))) => errors.push(
                ty.span(),
                "arrays of subsystems are not supported yet: name each subsystem as a field",
            ),
            Some((_, ty)) => subsystems.push((name.clone(), ty.clone())),
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
    let instances: Vec<&Ident> = subsystems.iter().map(|(name, _)| name).collect();
    let junctions: Vec<Junction> = junctions
        .iter()
        .enumerate()
        .filter_map(|(j, expr)| junction(expr, j, &instances, errors))
        .collect();
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

/// `name = form` or `form` (named `junction_j`), its terms read.
fn junction(expr: &Expr, j: usize, instances: &[&Ident], errors: &mut Errors) -> Option<Junction> {
    let (name, form) = match expr {
        Expr::Assign(assign) => match &*assign.left {
            Expr::Path(p) if p.path.get_ident().is_some() => {
                (p.path.get_ident()?.to_string(), &*assign.right)
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
    collect(form, 1.0, instances, &mut terms, errors);
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

/// The terms of `form` with their signs.
fn collect(
    form: &Expr,
    sign: f64,
    instances: &[&Ident],
    terms: &mut Vec<Term>,
    errors: &mut Errors,
) {
    match form {
        Expr::Paren(p) => collect(&p.expr, sign, instances, terms, errors),
        Expr::Group(g) => collect(&g.expr, sign, instances, terms, errors),
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => {
            collect(&u.expr, -sign, instances, terms, errors)
        }
        Expr::Binary(b) if matches!(b.op, BinOp::Add(_) | BinOp::Sub(_)) => {
            collect(&b.left, sign, instances, terms, errors);
            let right = if matches!(b.op, BinOp::Sub(_)) {
                -sign
            } else {
                sign
            };
            collect(&b.right, right, instances, terms, errors);
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
            collect(differential, sign * number, instances, terms, errors);
        }
        other => match differential(other) {
            Some((instance, path)) => match instances.iter().position(|i| **i == instance) {
                Some(index) => terms.push(Term {
                    instance: index,
                    path,
                    coefficient: sign,
                    span: other.span(),
                }),
                None => errors.push(
                    instance.span(),
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

/// `instance.(path.)dx` or `instance.(path.)dx[i]`: the instance and the coordinate's path
/// inside it (`x`, `path.x`, `x[i]`).
fn differential(expr: &Expr) -> Option<(Ident, String)> {
    let (field, index) = match expr {
        Expr::Index(i) => match (&*i.expr, literal(&i.index)) {
            (Expr::Field(f), Some(k)) if k >= 0.0 && k.fract() == 0.0 => (f, Some(k as usize)),
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
            Expr::Path(p) => break p.path.get_ident()?.clone(),
            _ => return None,
        }
    };
    segments.reverse();
    segments.push(match index {
        Some(k) => format!("{coordinate}[{k}]"),
        None => coordinate,
    });
    Some((instance, segments.join(".")))
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

/// The struct and its `impl DiracSystem`, in a block where `__dirac` names the runtime.
pub fn expand(model: &Composite) -> TokenStream {
    let item = &model.item;
    let name = &item.ident;
    let krate = &model.krate;
    let k = model.subsystems.len();
    let fields: Vec<&Ident> = model.subsystems.iter().map(|(f, _)| f).collect();
    let types: Vec<&Type> = model.subsystems.iter().map(|(_, t)| t).collect();
    let labels: Vec<String> = fields.iter().map(|f| f.to_string()).collect();
    let sizes: Vec<Ident> = (0..k).map(|i| format_ident!("__N_{}", i)).collect();
    let slots: Vec<Ident> = (0..k).map(|i| format_ident!("__SLOT_{}", i)).collect();
    let size_items = types
        .iter()
        .zip(&sizes)
        .map(|(ty, n)| quote_spanned!(ty.span()=> const #n: usize = <#ty>::__DIRAC_COORDINATES;));
    let slot_items = (0..k).map(|i| {
        let slot = &slots[i];
        match i {
            0 => quote!(const #slot: __dirac::slot::Slot = __dirac::slot::Slot::FIRST;),
            _ => {
                let (previous, ty, n) = (&slots[i - 1], types[i - 1], &sizes[i - 1]);
                quote!(const #slot: __dirac::slot::Slot = #previous.after::<#ty, { #n }>();)
            }
        }
    });
    let end = match k {
        0 => quote!(__dirac::slot::Slot::FIRST),
        _ => {
            let (last, ty, n) = (&slots[k - 1], types[k - 1], &sizes[k - 1]);
            quote!(#last.after::<#ty, { #n }>())
        }
    };
    let junction_count = model.junctions.len();
    let terms: Vec<TokenStream> = model
        .junctions
        .iter()
        .enumerate()
        .flat_map(|(j, junction)| junction.terms.iter().map(move |term| (j, term)))
        .map(|(j, term)| {
            let (ty, slot, path, c) = (
                types[term.instance],
                &slots[term.instance],
                &term.path,
                term.coefficient,
            );
            let message = format!(
                "subsystem `{}` has no coordinate `{}`",
                labels[term.instance], path
            );
            quote_spanned! {term.span=>
                (#j, #slot.coordinate + match <#ty>::__dirac_coordinate(#path) {
                    ::core::option::Option::Some(__i) => __i,
                    ::core::option::Option::None => ::core::panic!(#message),
                }, #c)
            }
        })
        .collect();
    let term_count = terms.len();
    let vector = |scalar: TokenStream| quote!(__dirac::nalgebra::SVector<#scalar, { __N }>);
    let (dual, real) = (vector(quote!(__D)), vector(quote!(f64)));
    let zero = quote!(<__D as ::core::convert::From<f64>>::from(0.0));
    let system = |i: usize| {
        let (ty, n) = (types[i], &sizes[i]);
        quote!(<#ty as __dirac::DiracSystem<{ #n }>>)
    };
    let systems: Vec<TokenStream> = (0..k).map(system).collect();
    let quadrature = match &model.quadrature {
        Some(q) => q.clone(),
        None => quote! {
            __dirac::interconnection::common_quadrature(&[
                #((#labels, self.#fields.quadrature()?)),*
            ])
        },
    };
    let lookups = fields.iter().zip(&types).zip(&slots).map(|((field, ty), slot)| {
        let label = field.to_string();
        quote! {
            if let ::core::option::Option::Some(__rest) = __dirac::slot::descend(__path, #label) {
                return match <#ty>::__dirac_coordinate(__rest) {
                    ::core::option::Option::Some(__i) => ::core::option::Option::Some(#slot.coordinate + __i),
                    ::core::option::Option::None => ::core::option::Option::None,
                };
            }
        }
    });
    let disagreements = labels.iter().enumerate().map(|(i, label)| {
        let message = format!(
            "subsystem `{label}` holds its one-forms at another constraint point than the \
             constrained subsystems before it: give them one `constraint_at`"
        );
        quote_spanned!(fields[i].span()=> if __i == #i { ::core::panic!(#message) })
    });
    let own_point = match junction_count {
        0 => quote!(__POINT),
        _ => quote! {
            match __POINT {
                ::core::option::Option::None => ::core::option::Option::Some(__dirac::ConstraintPoint::Midpoint),
                __point => __point,
            }
        },
    };
    let junction_labels: Vec<&str> = model.junctions.iter().map(|j| j.name.as_str()).collect();
    let implementation = quote! {
        #(#size_items)*
        const __POINT: ::core::option::Option<__dirac::ConstraintPoint> =
            match __dirac::slot::common_point(&[#(<#types>::__DIRAC_CONSTRAINT_POINT),*]) {
                ::core::result::Result::Ok(__point) => __point,
                ::core::result::Result::Err(__i) => {
                    #(#disagreements)*
                    ::core::panic!("subsystems hold their one-forms at different constraint points")
                }
            };
        const __N: usize = 0usize #(+ #sizes)*;
        #(#slot_items)*
        const __END: __dirac::slot::Slot = #end;
        const __TERMS: [(usize, usize, f64); #term_count] = [#(#terms),*];

        #[automatically_derived]
        impl #name {
            #[doc(hidden)]
            pub const __DIRAC_COORDINATES: usize = __N;

            #[doc(hidden)]
            pub const fn __dirac_coordinate(__path: &str) -> ::core::option::Option<usize> {
                #(#lookups)*
                ::core::option::Option::None
            }

            #[doc(hidden)]
            pub const __DIRAC_CONSTRAINT_POINT: ::core::option::Option<__dirac::ConstraintPoint> = #own_point;
        }

        #[automatically_derived]
        #[allow(clippy::all)]
        impl __dirac::DiracSystem<{ __N }> for #name {
            const ONE_FORMS: usize = __END.one_form + #junction_count;
            const HOLONOMIC: usize = __END.holonomic;
            const FORCES: bool = false #(|| #systems::FORCES)*;
            const INPUTS: usize = __END.input;

            fn lagrangian<__D: __dirac::Scalar>(&self, __q: &#dual, __v: &#dual) -> __D {
                let mut __l = #zero;
                #(__l = __l + #slots.lagrangian(&self.#fields, __q, __v);)*
                __l
            }

            fn lagrangian_gradient(
                &self,
                __q: &#real,
                __v: &#real,
            ) -> ::core::option::Option<__dirac::LagrangianGradient<{ __N }>> {
                let mut __g = __dirac::LagrangianGradient::zero();
                #(#slots.add_gradient(&self.#fields, __q, __v, &mut __g)?;)*
                ::core::option::Option::Some(__g)
            }

            fn lagrangian_hessian(
                &self,
                __q: &#real,
                __v: &#real,
            ) -> ::core::option::Option<__dirac::LagrangianHessian<{ __N }>> {
                let mut __h = __dirac::LagrangianHessian::zero();
                #(#slots.add_hessian(&self.#fields, __q, __v, &mut __h)?;)*
                ::core::option::Option::Some(__h)
            }

            fn one_form<__D: __dirac::Scalar>(&self, __q: &#dual, __a: usize) -> #dual {
                #(
                    if let ::core::option::Option::Some(__w) = #slots.one_form(&self.#fields, __q, __a) {
                        return __w;
                    }
                )*
                let __row = __a - __END.one_form;
                let mut __w = <#dual>::from_element(#zero);
                for &(__j, __i, __c) in __TERMS.iter() {
                    if __j == __row {
                        __w[__i] = <__D as ::core::convert::From<f64>>::from(__c);
                    }
                }
                __w
            }

            fn one_form_name(&self, __a: usize) -> ::std::string::String {
                #(
                    if let ::core::option::Option::Some(__name) = #slots.one_form_name(&self.#fields, #labels, __a) {
                        return __name;
                    }
                )*
                const __JUNCTION_NAMES: [&str; #junction_count] = [#(#junction_labels),*];
                match __a.checked_sub(__END.one_form).and_then(|__j| __JUNCTION_NAMES.get(__j)) {
                    ::core::option::Option::Some(__name) => ::std::format!("junction {}", __name),
                    ::core::option::Option::None => ::std::format!("one-form {}", __a),
                }
            }

            fn one_form_is_constant(&self, __a: usize) -> bool {
                #(
                    if let ::core::option::Option::Some(__c) = #slots.one_form_is_constant(&self.#fields, __a) {
                        return __c;
                    }
                )*
                true
            }

            fn holonomic<__D: __dirac::Scalar>(&self, __q: &#dual, __b: usize) -> __D {
                #(
                    if let ::core::option::Option::Some(__g) = #slots.holonomic(&self.#fields, __q, __b) {
                        return __g;
                    }
                )*
                #zero
            }

            fn force<__D: __dirac::Scalar>(
                &self,
                __q: &#dual,
                __v: &#dual,
                __t: f64,
                __u: &[__D],
            ) -> #dual {
                let mut __f = <#dual>::from_element(#zero);
                #(#slots.place_force(&self.#fields, __q, __v, __t, __u, &mut __f);)*
                __f
            }

            fn input_name(&self, __i: usize) -> ::std::string::String {
                #(
                    if let ::core::option::Option::Some(__name) = #slots.input_name(&self.#fields, #labels, __i) {
                        return __name;
                    }
                )*
                ::std::format!("u{}", __i)
            }

            fn coordinate_name(&self, __i: usize) -> ::std::string::String {
                #(
                    if let ::core::option::Option::Some(__name) = #slots.coordinate_name(&self.#fields, #labels, __i) {
                        return __name;
                    }
                )*
                ::std::format!("q{}", __i)
            }

            fn constraint_point(&self) -> __dirac::ConstraintPoint {
                match __POINT {
                    ::core::option::Option::Some(__point) => __point,
                    ::core::option::Option::None => __dirac::ConstraintPoint::Midpoint,
                }
            }

            fn parameters(&self) -> ::std::vec::Vec<(::std::string::String, f64)> {
                let mut __p = ::std::vec::Vec::new();
                #(__dirac::slot::Slot::parameters(&self.#fields, #labels, &mut __p);)*
                __p
            }

            fn quadrature(&self) -> ::core::result::Result<__dirac::Quadrature, __dirac::DiracError> {
                #quadrature
            }
        }
    };
    let junction_names = model.junctions.iter().map(|j| j.name.as_str());
    let indices = 0..k;
    let interconnected = quote! {
        #[automatically_derived]
        impl __dirac::Interconnected<{ __N }, #k, #junction_count> for #name {
            fn junctions(&self) -> &__dirac::Junctions<{ __N }, #junction_count> {
                static __JUNCTIONS: ::std::sync::OnceLock<__dirac::Junctions<{ __N }, #junction_count>> =
                    ::std::sync::OnceLock::new();
                __JUNCTIONS.get_or_init(|| {
                    __dirac::Junctions::from_terms(
                        [#(::std::string::String::from(#junction_names)),*],
                        &__TERMS,
                    )
                })
            }

            fn energies(&self, __q: &#real, __v: &#real) -> [f64; #k] {
                [#(#slots.energy(&self.#fields, __q, __v)),*]
            }

            fn component_of(&self, __i: usize) -> usize {
                let mut __c = 0;
                #(
                    if __i >= #slots.coordinate {
                        __c = #indices;
                    }
                )*
                __c
            }
        }
    };
    let implementation = quote! {
        const _: () = {
            use #krate as __dirac;
            #implementation
            #interconnected
        };
    };
    quote!(#item #implementation)
}
