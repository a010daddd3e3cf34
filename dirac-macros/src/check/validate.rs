//! Checks the attribute and the struct, collecting every error with the span of the user's tokens.

use std::borrow::Cow;
use std::collections::HashSet;

use proc_macro2::{Span, TokenStream};
use quote::{ToTokens, quote};
use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::{Expr, Fields, GenericParam, Ident, Meta, Token, Type};

use crate::check::model::Model;
use crate::internals::ast::{Arguments, Coordinate, Lagrangian, Length, Parameter, Shape, Term};
use crate::internals::errors::Errors;
use crate::lower::expression::{
    Context, Hoisted, Rewriter, Scope, bounds, is_reserved, reserved_message,
};
use crate::lower::symbolic;
use crate::lower::vector_algebra::{self, Algebra};
use crate::lower::{expression, one_form, quadrature};

const KEYS: &str = "`coordinates(...)`, `lagrangian = ...`, `hamiltonian = ...`, `quadrature = ...`, \
     `constraints(...)`, `holonomic(...)`, `forces(...)`, `inputs(...)`, `constraint_at = ...`, \
     `subsystems(...)`, `junctions(...)` and `crate = ...`";

/// What validation produced: a model, or errors plus the coordinates when they were readable
/// (so a stub implementation can stop the errors from cascading into the user's code).
pub enum Outcome {
    Valid(Box<Model>),
    /// A model made of subsystems.
    Composite(Box<crate::check::subsystems::Composite>),
    Invalid {
        errors: Errors,
        coordinates: Option<Vec<Coordinate>>,
        /// The struct as it is to be emitted (without a repeated attribute).
        item: Box<syn::ItemStruct>,
        /// Whether the model is given by a Hamiltonian (the stub implements its trait).
        hamiltonian: bool,
        /// The path of the runtime (for the stub).
        krate: syn::Path,
    },
}

/// The arguments by key, before their contents are checked.
#[derive(Default)]
struct Entries {
    /// `Some((span, None))`: given but unreadable (already reported).
    coordinates: Option<(Span, Option<Vec<Coordinate>>)>,
    lagrangian: Option<Expr>,
    hamiltonian: Option<Expr>,
    quadrature: Option<Expr>,
    constraints: Option<Vec<Expr>>,
    holonomic: Option<Vec<Expr>>,
    forces: Option<Vec<Expr>>,
    inputs: Option<Vec<Ident>>,
    /// An input was written as an array (reported): the forces, which would read it as one,
    /// are not lowered, so that no error follows from the first.
    input_array: bool,
    constraint_at: Option<Expr>,
    krate: Option<Expr>,
    subsystems: Option<Vec<Ident>>,
    junctions: Option<Vec<Expr>>,
}

/// An entry of `inputs(...)`: a name, and the brackets of `u[3]` where one is written as an
/// array (refused with the fix, the name kept so that the forces reading it raise nothing more).
struct InputName {
    name: Ident,
    brackets: Option<Span>,
}

impl syn::parse::Parse for InputName {
    fn parse(input: syn::parse::ParseStream) -> syn::Result<Self> {
        let name: Ident = input.parse()?;
        let brackets = if input.peek(syn::token::Bracket) {
            let content;
            let bracket = syn::bracketed!(content in input);
            let _: proc_macro2::TokenStream = content.parse()?;
            Some(bracket.span.join())
        } else {
            None
        };
        Ok(Self { name, brackets })
    }
}

/// The items of `key(a, b, ...)`; `empty` is the message for an empty list.
fn list<T: syn::parse::Parse>(
    list: &syn::MetaList,
    empty: &str,
    errors: &mut Errors,
) -> Option<Vec<T>> {
    match list.parse_args_with(Punctuated::<T, Token![,]>::parse_terminated) {
        Ok(items) if items.is_empty() => {
            errors.push_range(list.path.span(), list.delimiter.span().close(), empty);
            None
        }
        Ok(items) => Some(items.into_iter().collect()),
        Err(e) => {
            errors.add(e);
            None
        }
    }
}

const LEAVE_OUT: &str = "the list is empty; leave the argument out instead";

fn entries(arguments: Arguments, errors: &mut Errors) -> Entries {
    let mut e = Entries::default();
    let mut seen = HashSet::new();
    for entry in arguments.entries {
        let key = entry
            .path()
            .get_ident()
            .map(|i| i.to_string())
            .unwrap_or_default();
        let span = entry.path().span();
        if !seen.insert(key.clone()) {
            errors.push(span, format!("`{key}` is given twice"));
            continue;
        }
        match (key.as_str(), entry) {
            ("coordinates", Meta::List(l)) => {
                let empty = "a system needs at least one coordinate, e.g. coordinates(x) or \
                             coordinates(x, theta[4])";
                e.coordinates = Some((span, list(&l, empty, errors)));
            }
            ("constraints", Meta::List(l)) => e.constraints = list(&l, LEAVE_OUT, errors),
            ("holonomic", Meta::List(l)) => e.holonomic = list(&l, LEAVE_OUT, errors),
            ("forces", Meta::List(l)) => e.forces = list(&l, LEAVE_OUT, errors),
            ("inputs", Meta::List(l)) => {
                e.inputs = list::<InputName>(&l, LEAVE_OUT, errors).map(|names| {
                    names
                        .into_iter()
                        .map(|input| {
                            if let Some(span) = input.brackets {
                                e.input_array = true;
                                let u = &input.name;
                                errors.push(
                                    span,
                                    format!(
                                        "an input is one number: name each one, e.g. \
                                         `inputs({u}_x, {u}_y, {u}_z)`, and read them in the \
                                         forces as `[{u}_x, {u}_y, {u}_z]` (arrays of inputs \
                                         are not supported yet)"
                                    ),
                                );
                            }
                            input.name
                        })
                        .collect()
                })
            }
            ("subsystems", Meta::List(l)) => {
                let empty = "a model made of subsystems needs at least one, e.g. subsystems(a, b)";
                e.subsystems = list(&l, empty, errors).or(Some(Vec::new()));
            }
            ("junctions", Meta::List(l)) => e.junctions = list(&l, LEAVE_OUT, errors),
            ("lagrangian", Meta::NameValue(nv)) => e.lagrangian = Some(nv.value),
            ("hamiltonian", Meta::NameValue(nv)) => e.hamiltonian = Some(nv.value),
            ("quadrature", Meta::NameValue(nv)) => e.quadrature = Some(nv.value),
            ("constraint_at", Meta::NameValue(nv)) => e.constraint_at = Some(nv.value),
            ("crate", Meta::NameValue(nv)) => e.krate = Some(nv.value),
            (
                "coordinates" | "constraints" | "holonomic" | "forces" | "inputs" | "subsystems"
                | "junctions",
                other,
            ) => errors.push(
                other.span(),
                format!("write `{key}` as a list: {key}(a, b, ...)"),
            ),
            ("lagrangian" | "hamiltonian" | "quadrature" | "constraint_at" | "crate", other) => {
                errors.push(other.span(), format!("write `{key} = ...`"))
            }
            (_, other) => errors.push(
                other.path().span(),
                format!("unknown argument `{key}`; expected {KEYS}"),
            ),
        }
    }
    e
}

/// Reports every further `#[dirac_system]` on the struct and removes it (it would expand again).
fn repeated_attributes(item: &mut syn::ItemStruct, errors: &mut Errors) {
    item.attrs.retain(|attr| {
        let repeated = attr
            .path()
            .segments
            .last()
            .is_some_and(|s| s.ident == "dirac_system");
        if repeated {
            errors.push_range(
                attr.pound_token.span,
                attr.bracket_token.span.close(),
                "`#[dirac_system]` is applied twice; remove this one",
            );
        }
        !repeated
    });
}

/// Whether `form` (a one-form in differentials) names no coordinate outside its differentials,
/// in the expressions the attribute reads (literals, parameters, constants, arithmetic and
/// calls of them): its coefficients are then the same at every `q`. Anything else counts as
/// depending on `q`.
fn names_no_coordinate(form: &Expr, coordinates: &[Coordinate]) -> bool {
    expression::subexpressions(form).all(|e| match e {
        Expr::Path(p) => p
            .path
            .get_ident()
            .is_none_or(|name| !coordinates.iter().any(|c| c.name == *name)),
        Expr::Lit(_)
        | Expr::Paren(_)
        | Expr::Group(_)
        | Expr::Unary(_)
        | Expr::Binary(_)
        | Expr::Index(_) => true,
        Expr::Call(c) => !matches!(&*c.func, Expr::Path(f) if f.path.is_ident("dot")),
        Expr::MethodCall(_) => true,
        _ => false,
    })
}

/// A model made of subsystems: the arguments of a model given by its own coordinates are
/// refused, the rest is read by [`subsystems::model`](crate::check::subsystems::model).
fn composite(
    e: Entries,
    subsystems: Vec<Ident>,
    item: syn::ItemStruct,
    krate: syn::Path,
    mut errors: Errors,
) -> Outcome {
    const OWN: &str = "a model made of subsystems takes its coordinates, Lagrangian, constraints, \
                       forces and inputs from them: leave this out";
    let spans = [
        e.coordinates.as_ref().map(|(span, _)| *span),
        e.lagrangian.as_ref().map(Spanned::span),
        e.hamiltonian.as_ref().map(Spanned::span),
        e.constraints
            .as_ref()
            .and_then(|c| c.first())
            .map(Spanned::span),
        e.holonomic
            .as_ref()
            .and_then(|c| c.first())
            .map(Spanned::span),
        e.forces.as_ref().and_then(|c| c.first()).map(Spanned::span),
        e.inputs.as_ref().and_then(|c| c.first()).map(Spanned::span),
        e.constraint_at.as_ref().map(Spanned::span),
    ];
    for span in spans.into_iter().flatten() {
        errors.push(span, OWN);
    }
    if let Some(expr) = e
        .quadrature
        .as_ref()
        .filter(|e| quadrature::explicit(e).is_some())
    {
        errors.push(
            expr.span(),
            "explicit steps are not offered for a model made of subsystems (its junctions are \
             constraints): name a quadrature",
        );
    }
    let quadrature = e
        .quadrature
        .filter(|expr| quadrature::explicit(expr).is_none())
        .and_then(|expr| match quadrature::parse(&expr) {
            Ok(tokens) => Some(tokens),
            Err(err) => {
                errors.add(err);
                None
            }
        });
    let junctions = e.junctions.unwrap_or_default();
    let composite = crate::check::subsystems::model(
        &subsystems,
        &junctions,
        quadrature,
        item.clone(),
        krate.clone(),
        &mut errors,
    );
    match composite {
        Some(composite) if errors.is_empty() => Outcome::Composite(Box::new(composite)),
        _ => Outcome::Invalid {
            errors,
            coordinates: None,
            item: Box::new(item),
            hamiltonian: false,
            krate,
        },
    }
}

/// Validates the arguments against the struct.
pub fn model(arguments: Arguments, mut item: syn::ItemStruct) -> Outcome {
    let mut errors = Errors::default();
    let hoisted = Hoisted::default();
    repeated_attributes(&mut item, &mut errors);
    let mut e = entries(arguments, &mut errors);
    let krate = runtime_path(e.krate.take(), &mut errors);
    if let Some(subsystems) = e.subsystems.take() {
        return composite(e, subsystems, item, krate, errors);
    }
    if let Some(junctions) = &e.junctions {
        let span = junctions.first().map_or(Span::call_site(), Spanned::span);
        errors.push(
            span,
            "junctions(...) join subsystems: name them in subsystems(...)",
        );
    }
    let parameters = parameters(&item, &mut errors);
    let const_params = const_params(&item);
    if e.forces.is_some() {
        for p in parameters.iter().filter(|p| p.name == "t") {
            errors.push(
                p.name.span(),
                "a field named `t` would hide the time `t` of forces(...); rename the field",
            );
        }
    }
    let coordinates = match e.coordinates {
        Some((_, Some(list))) => {
            check_coordinates(&list, &parameters, &const_params, &mut errors);
            check_product(&list, e.holonomic.as_deref(), &mut errors);
            Some(list)
        }
        Some((_, None)) => None,
        None => {
            errors.push(
                Span::call_site(),
                "missing `coordinates(...)`: name the coordinates, e.g. coordinates(x, theta[4])",
            );
            None
        }
    };
    let inputs = e.inputs.unwrap_or_default();
    check_inputs(
        &inputs,
        coordinates.as_deref().unwrap_or_default(),
        &parameters,
        &mut errors,
    );
    let forces_free_of_velocity = e
        .forces
        .iter()
        .flatten()
        .all(|force| !expression_reads_velocity(force));
    let one_forms = e.constraints.is_some() || e.holonomic.is_some() || e.forces.is_some();
    check_differential_names(
        coordinates.as_deref().unwrap_or_default(),
        parameters.iter().map(|p| &p.name).chain(&inputs),
        one_forms,
        &mut errors,
    );
    let hamiltonian = e.hamiltonian.is_some();
    if hamiltonian {
        let coordinates = coordinates.as_deref().unwrap_or_default();
        hamiltonian_route(e.lagrangian.as_ref(), coordinates, &mut errors);
    }
    // The rate of a coordinate: its velocity dot(x), or for a Hamiltonian its momentum p(x).
    let rate = if hamiltonian { "p" } else { "dot" };
    let mut closed_form = None;
    // A component without energy (a resistor, a source, a damper) gives only its forces: its
    // Lagrangian is zero, written in its first coordinate.
    let energy_less = match (&e.forces, &coordinates) {
        (Some(_), Some(coordinates)) if e.lagrangian.is_none() && !is_product(coordinates) => {
            coordinates.first().map(|c| {
                let name = &c.name;
                let expr: Expr = match c.length {
                    None => syn::parse_quote!(0.0 * #name),
                    Some(_) => syn::parse_quote!(0.0 * #name[0]),
                };
                expr
            })
        }
        _ => None,
    };
    let written = e.hamiltonian.take().or(e.lagrangian.take());
    let lagrangian = match (written.or(energy_less), &coordinates) {
        (None, _) => {
            errors.push(Span::call_site(), "missing `lagrangian = ...`: an expression in the coordinates, dot(coordinate) and the parameters, or the path of a generic function (or `hamiltonian = ...`, in the coordinates and their momenta p(coordinate)); a component without energy gives only `forces(...)`");
            None
        }
        // Refused in `hamiltonian_route`; its expression is not read.
        (Some(_), Some(coordinates)) if hamiltonian && is_product(coordinates) => None,
        (Some(expr), Some(coordinates)) => {
            let n =
                literal_dimension(coordinates).filter(|_| !is_product(coordinates) && !hamiltonian);
            let closed = match n {
                Some(n) => symbolic::closed_form(&expr, coordinates, n),
                // On rotations: the expression lowered to the matrices' entries (its errors
                // are reported by `lagrangian_of` below, not twice).
                None if is_product(coordinates) && !hamiltonian => {
                    let algebra = Algebra {
                        coordinates,
                        parameters: &parameters,
                        no_velocities: None,
                        differentials: false,
                    };
                    vector_algebra::lower(&expr, &algebra, &mut Errors::default()).and_then(
                        |lowered| symbolic::closed_form_in_body_frame(&lowered, coordinates),
                    )
                }
                None => None,
            };
            let lagrangian = lagrangian_of(
                expr,
                coordinates,
                &parameters,
                &const_params,
                &hoisted,
                rate,
                &mut errors,
            );
            // A function path has no expression to differentiate.
            if matches!(lagrangian, Some(Lagrangian::Expression(_))) {
                closed_form = closed;
            }
            lagrangian
        }
        (Some(_), None) => None,
    };
    // `explicit(...)`: the composition, and where it was named; `Stepper::from_system` is then
    // refused with the constructor to call.
    let mut explicit = None;
    let quadrature = match e.quadrature {
        None => Some(quote!(::core::result::Result::Ok(
            __dirac::Quadrature::midpoint()
        ))),
        Some(expr) => match quadrature::explicit(&expr) {
            Some(Ok(composition)) => {
                explicit = Some((composition, expr.span()));
                Some(quote!(::core::result::Result::Err(
                    __dirac::DiracError::InvalidQuadrature(::std::string::String::from(
                        "the model names an explicit step (quadrature = explicit(...)): step it \
                         with Stepper::explicit_from_system(model, h), or pass a quadrature to \
                         Stepper::new (a model made of it names its own with quadrature = ...)"
                    ))
                )))
            }
            Some(Err(err)) => {
                errors.add(err);
                None
            }
            None => match quadrature::parse(&expr) {
                Ok(tokens) => Some(tokens),
                Err(err) => {
                    errors.add(err);
                    None
                }
            },
        },
    };
    let constraint_point = e.constraint_at.and_then(|expr| match &expr {
        Expr::Path(p) if p.path.is_ident("start") => Some(quote!(__dirac::ConstraintPoint::Start)),
        Expr::Path(p) if p.path.is_ident("midpoint") => {
            Some(quote!(__dirac::ConstraintPoint::Midpoint))
        }
        Expr::Path(p) if p.path.is_ident("end") => Some(quote!(__dirac::ConstraintPoint::End)),
        other => {
            errors.push(
                other.span(),
                "expected `start` (q_k), `midpoint` or `end` (q_{k+1})",
            );
            None
        }
    });
    let fields: Vec<Ident> = parameters.iter().map(|p| p.name.clone()).collect();
    let mut constant_one_forms = Vec::new();
    let mut one_form_derivatives = None;
    let mut forces_affine = false;
    let one_form_names: Vec<String> = e
        .constraints
        .iter()
        .flatten()
        .map(|form| quote!(#form).to_string())
        .collect();
    let (one_forms, holonomic, forces) = match &coordinates {
        Some(coordinates) => {
            let product = is_product(coordinates);
            const NO_VELOCITIES: &str = "constraints depend on positions only: velocities (dot(...), omega(...)) cannot appear here";
            let positions = Scope {
                coordinates,
                inputs: &[],
                fields: &fields,
                const_params: &const_params,
                no_velocities: Some(NO_VELOCITIES),
                rate,
                elsewhere: "",
                context: Context::Positions,
                hoisted: &hoisted,
                atoms: product,
            };
            // On rotations and unit vectors, one-forms and forces are lowered to scalars first.
            let algebra = |no_velocities| {
                product.then_some(Algebra {
                    coordinates,
                    parameters: &parameters,
                    no_velocities,
                    differentials: true,
                })
            };
            let (positions_algebra, state_algebra) = (algebra(Some(NO_VELOCITIES)), algebra(None));
            // Closed-form derivatives where every one-form has them (not on the Hamiltonian
            // route, whose trait has no such method).
            // The forces affine with constant coefficients (not on the Hamiltonian route, whose
            // trait has no such constant, nor on rotations and unit vectors, whose steps solve
            // with Newton's method throughout).
            forces_affine = !product
                && !hamiltonian
                && !e.input_array
                && literal_dimension(coordinates).is_some_and(|n| {
                    let varying: Vec<String> = std::iter::once("t".to_string())
                        .chain(inputs.iter().map(|u| u.to_string()))
                        .collect();
                    let forms = e.forces.as_deref().unwrap_or_default();
                    !forms.is_empty() && symbolic::forces_affine(forms, coordinates, n, &varying)
                });
            one_form_derivatives = literal_dimension(coordinates)
                .filter(|_| !product && !hamiltonian)
                .and_then(|n| {
                    e.constraints
                        .iter()
                        .flatten()
                        .map(|form| symbolic::one_form_with_derivative(form, coordinates, n))
                        .collect::<Option<Vec<_>>>()
                })
                .filter(|forms| !forms.is_empty());
            constant_one_forms = match product {
                true => Vec::new(),
                false => e
                    .constraints
                    .iter()
                    .flatten()
                    .map(|form| names_no_coordinate(form, coordinates))
                    .collect(),
            };
            let one_forms: Vec<Vec<Term>> = e
                .constraints
                .unwrap_or_default()
                .iter()
                .map(
                    |form| match lowered(form, positions_algebra.as_ref(), &mut errors) {
                        Some(form) => {
                            one_form::terms(&form, &mut Rewriter::new(&positions, &mut errors))
                        }
                        None => Vec::new(),
                    },
                )
                .collect();
            // (Refused with rotations or unit vectors, in `check_product`.)
            let holonomic = match product {
                true => Vec::new(),
                false => e
                    .holonomic
                    .unwrap_or_default()
                    .iter()
                    .filter_map(|g| holonomic_of(g, &positions, &mut errors))
                    .collect(),
            };
            let state = Scope {
                coordinates,
                inputs: &inputs,
                fields: &fields,
                const_params: &const_params,
                no_velocities: None,
                rate,
                elsewhere: "",
                context: Context::Force,
                hoisted: &hoisted,
                atoms: product,
            };
            let forces = e
                .forces
                .filter(|_| !e.input_array)
                .unwrap_or_default()
                .iter()
                .flat_map(
                    |form| match lowered(form, state_algebra.as_ref(), &mut errors) {
                        Some(form) => {
                            one_form::terms(&form, &mut Rewriter::new(&state, &mut errors))
                        }
                        None => Vec::new(),
                    },
                )
                .collect();
            (one_forms, holonomic, forces)
        }
        None => Default::default(),
    };
    if let (Some((_, span)), Some(coordinates)) = (&explicit, &coordinates) {
        let refusal = if hamiltonian {
            Some("explicit steps take a Lagrangian: name a quadrature for a Hamiltonian")
        } else if is_product(coordinates) {
            Some("explicit steps are not offered on rotations and unit vectors: name a quadrature")
        } else if !one_forms.is_empty() || !holonomic.is_empty() {
            Some("explicit steps are not offered with constraints: name a quadrature")
        } else if !forces_free_of_velocity {
            Some(
                "explicit steps need forces of the positions, time and inputs alone: a force \
                 reading dot(x) makes the step implicit; name a quadrature",
            )
        } else if !closed_form.as_ref().is_some_and(|c| c.separable) {
            Some(
                "explicit steps need a separable Lagrangian ½ vᵀ M v + bᵀ v − V(q) with constant \
                 M and b; this one's ∂²L/∂v² or ∂²L/∂q∂v is not constant (or its derivatives \
                 could not be derived): name a quadrature",
            )
        } else {
            None
        };
        if let Some(refusal) = refusal {
            errors.push(*span, refusal);
        }
    }
    match (coordinates, lagrangian, quadrature) {
        (Some(coordinates), Some(lagrangian), Some(quadrature)) if errors.is_empty() => {
            Outcome::Valid(Box::new(Model {
                item,
                coordinates,
                lagrangian,
                hamiltonian,
                quadrature,
                explicit: explicit.map(|(composition, _)| composition),
                parameters,
                one_forms,
                constant_one_forms,
                one_form_derivatives,
                one_form_names,
                holonomic,
                forces,
                forces_free_of_velocity,
                forces_affine,
                inputs,
                constraint_point,
                closed_form,
                parts: hoisted.parts.into_inner(),
                index_checks: hoisted.index_checks.into_inner().into_values().collect(),
                krate,
            }))
        }
        (coordinates, ..) => Outcome::Invalid {
            errors,
            coordinates,
            item: Box::new(item),
            hamiltonian,
            krate,
        },
    }
}

/// The path the generated code reaches the runtime by: `crate = path` (for users who depend on
/// `dirac-runtime` and `dirac-macros` directly, or on a re-export), `::dirac` by default.
fn runtime_path(given: Option<Expr>, errors: &mut Errors) -> syn::Path {
    match given {
        None => syn::parse_quote!(::dirac),
        Some(Expr::Path(path)) if path.qself.is_none() && path.attrs.is_empty() => path.path,
        Some(other) => {
            errors.push(
                other.span(),
                "`crate = ...` takes the path of the runtime crate, e.g. crate = dirac_runtime",
            );
            syn::parse_quote!(::dirac)
        }
    }
}

/// What the Hamiltonian route does not offer, reported on the user's tokens: both a Lagrangian
/// and a Hamiltonian, rotations or unit vectors.
fn hamiltonian_route(lagrangian: Option<&Expr>, coordinates: &[Coordinate], errors: &mut Errors) {
    if let Some(lagrangian) = lagrangian {
        let (start, end) = bounds(lagrangian);
        errors.push_range(
            start,
            end,
            "give either `lagrangian = ...` or `hamiltonian = ...`, not both",
        );
    }
    if let Some(c) = coordinates.iter().find(|c| c.is_group()) {
        errors.push(
            c.name.span(),
            "`hamiltonian = ...` is offered on real coordinates; write a model with rotations or \
             unit vectors with `lagrangian = ...`",
        );
    }
}

/// A holonomic constraint `g(q)`: an expression of the positions, not a one-form.
fn holonomic_of(g: &Expr, scope: &Scope, errors: &mut Errors) -> Option<TokenStream> {
    if one_form::has_differential(g, scope.coordinates) {
        let (start, end) = bounds(g);
        errors.push_range(
            start,
            end,
            "holonomic constraints are functions g(q) = 0 of the coordinates; write one-forms in constraints(...)",
        );
        return None;
    }
    expression::rewrite(g, scope, errors)
}

fn check_inputs(
    inputs: &[Ident],
    coordinates: &[Coordinate],
    parameters: &[Parameter],
    errors: &mut Errors,
) {
    let mut seen = HashSet::new();
    for input in inputs {
        if !seen.insert(input.to_string()) {
            errors.push(input.span(), format!("duplicate input `{input}`"));
        } else if is_reserved(input) {
            errors.push(input.span(), reserved_message(input));
        } else if coordinates.iter().any(|c| c.name == *input)
            || parameters.iter().any(|p| p.name == *input)
            || input == "t"
        {
            errors.push(
                input.span(),
                format!(
                    "input `{input}` has the name of a coordinate, a parameter or the time `t`; \
                     rename it"
                ),
            );
        }
    }
}

/// The number of coordinates when every array length is a literal.
fn literal_dimension(coordinates: &[Coordinate]) -> Option<usize> {
    coordinates
        .iter()
        .try_fold(0usize, |sum, c| match &c.length {
            None => sum.checked_add(1),
            Some(Length::Literal(n, _)) => sum.checked_add(*n),
            Some(Length::Named(_)) => None,
        })
}

/// A bare path naming no coordinate or parameter is a function; anything else an expression.
fn lagrangian_of(
    expr: Expr,
    coordinates: &[Coordinate],
    parameters: &[Parameter],
    const_params: &[Ident],
    hoisted: &Hoisted,
    rate: &'static str,
    errors: &mut Errors,
) -> Option<Lagrangian> {
    if let Expr::Path(p) = &expr {
        let known = p.path.get_ident().is_some_and(|i| {
            coordinates.iter().any(|c| c.name == *i) || parameters.iter().any(|q| q.name == *i)
        });
        if !known {
            return Some(Lagrangian::Function(p.path.clone()));
        }
    }
    let fields: Vec<Ident> = parameters.iter().map(|p| p.name.clone()).collect();
    let product = is_product(coordinates);
    let scope = Scope {
        coordinates,
        inputs: &[],
        fields: &fields,
        const_params,
        no_velocities: None,
        rate,
        elsewhere: "; for other code write a generic function and give \
                    `lagrangian = path::to::function`",
        context: Context::Lagrangian,
        hoisted,
        atoms: product,
    };
    let expr = match product {
        false => expr,
        true => {
            let algebra = Algebra {
                coordinates,
                parameters,
                no_velocities: None,
                differentials: false,
            };
            vector_algebra::lower(&expr, &algebra, errors)?
        }
    };
    expression::rewrite(&expr, &scope, errors).map(Lagrangian::Expression)
}

/// `form` lowered from vectors and matrices (a model on rotations and unit vectors, `algebra`
/// given), or `form` itself (borrowed: cloning a long chain would recurse as deep as it is long).
fn lowered<'f>(
    form: &'f Expr,
    algebra: Option<&Algebra>,
    errors: &mut Errors,
) -> Option<Cow<'f, Expr>> {
    match algebra {
        None => Some(Cow::Borrowed(form)),
        Some(algebra) => vector_algebra::lower(form, algebra, errors).map(Cow::Owned),
    }
}

/// Whether the model has rotations or unit vectors (its manifold is a `Product`).
pub fn is_product(coordinates: &[Coordinate]) -> bool {
    coordinates.iter().any(Coordinate::is_group)
}

/// A parameter or input named `d` and a coordinate's name would read as that coordinate's
/// differential wherever differentials are read: in constraints and forces, and in every
/// expression of a model with rotations or unit vectors (`dR`). Refused there, naming both.
fn check_differential_names<'a>(
    coordinates: &[Coordinate],
    names: impl Iterator<Item = &'a Ident>,
    one_forms: bool,
    errors: &mut Errors,
) {
    for name in names {
        let text = name.to_string();
        let Some(rest) = text.strip_prefix('d') else {
            continue;
        };
        if let Some(c) = coordinates
            .iter()
            .find(|c| c.name == rest && (one_forms || c.is_group()))
        {
            errors.push(
                name.span(),
                format!(
                    "`{name}` reads as the differential of coordinate `{}` in constraints(...), \
                     forces(...) and expressions of rotations or unit vectors; rename it",
                    c.name
                ),
            );
        }
    }
}

/// Arrays of rotations or unit vectors are at most this long: the macro writes out each
/// element's entries.
const MAX_GROUP_ARRAY: usize = 1000;

/// A model on rotations and unit vectors sizes its product space by literals (arrays of at
/// most [`MAX_GROUP_ARRAY`] rotations or unit vectors) and has no holonomic constraints.
fn check_product(coordinates: &[Coordinate], holonomic: Option<&[Expr]>, errors: &mut Errors) {
    if !is_product(coordinates) {
        return;
    }
    for c in coordinates {
        match &c.length {
            Some(Length::Named(n)) => errors.push(
                n.span(),
                "a model with rotations or unit vectors sizes its arrays by integer literals",
            ),
            Some(Length::Literal(n, span)) if c.is_group() && *n > MAX_GROUP_ARRAY => errors.push(
                *span,
                format!(
                    "an array of rotations or unit vectors has at most {MAX_GROUP_ARRAY} \
                         elements (each element's entries are written out)"
                ),
            ),
            _ => {}
        }
    }
    if let Some(first) = holonomic.and_then(|h| h.first()) {
        let (start, _) = bounds(first);
        errors.push(
            start,
            "holonomic constraints are not offered with rotations or unit vectors: write their \
             differentials as one-forms in constraints(...)",
        );
    }
}

fn check_coordinates(
    list: &[Coordinate],
    parameters: &[Parameter],
    const_params: &[Ident],
    errors: &mut Errors,
) {
    let mut seen = HashSet::new();
    for c in list {
        if !seen.insert(c.name.to_string()) {
            errors.push(c.name.span(), format!("duplicate coordinate `{}`", c.name));
        } else if is_reserved(&c.name) {
            errors.push(c.name.span(), reserved_message(&c.name));
        } else if c.name == "t" {
            errors.push(
                c.name.span(),
                "`t` names the time (in forces(...)); give the coordinate another name",
            );
        } else if parameters.iter().any(|p| p.name == c.name) {
            errors.push(
                c.name.span(),
                format!(
                    "`{}` is both a coordinate and a parameter field; rename one",
                    c.name
                ),
            );
        }
        if let Some(Length::Literal(0, span)) = &c.length {
            errors.push(*span, "a coordinate array needs at least one element");
        }
    }
    // A generic struct: the dimension must be one const parameter, not an expression of it.
    let generic_length = list.iter().find_map(|c| match &c.length {
        Some(Length::Named(n)) if const_params.contains(n) => Some(n.clone()),
        _ => None,
    });
    if let (Some(n), true) = (generic_length, list.len() > 1) {
        errors.push(
            n.span(),
            format!(
                "a system generic in `{n}` must have one coordinate array `name[{n}]`: \
                 stable Rust cannot size a vector by an expression of a const parameter"
            ),
        );
    }
}

/// The struct's const parameters.
fn const_params(item: &syn::ItemStruct) -> Vec<Ident> {
    item.generics
        .params
        .iter()
        .filter_map(|g| match g {
            GenericParam::Const(c) => Some(c.ident.clone()),
            _ => None,
        })
        .collect()
}

/// The struct's fields, each `f64` or `[f64; K]`; other shapes are errors.
fn parameters(item: &syn::ItemStruct, errors: &mut Errors) -> Vec<Parameter> {
    for g in &item.generics.params {
        if !matches!(g, GenericParam::Const(_)) {
            errors.push(
                g.span(),
                "a system may be generic only in const parameters (e.g. the length of a chain)",
            );
        }
    }
    let fields = match &item.fields {
        Fields::Named(named) => &named.named,
        Fields::Unit => return Vec::new(),
        Fields::Unnamed(f) => {
            errors.push(
                f.span(),
                "parameters need names: use a struct with named fields",
            );
            return Vec::new();
        }
    };
    let is_f64 =
        |ty: &Type| matches!(ty, Type::Path(p) if p.qself.is_none() && p.path.is_ident("f64"));
    let literal = |len: &Expr| match len {
        Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        }) => i.base10_parse::<usize>().ok(),
        _ => None,
    };
    fields
        .iter()
        .filter_map(|field| {
            let name = field.ident.clone()?;
            if is_reserved(&name) {
                errors.push(name.span(), reserved_message(&name));
            }
            let shape = match &field.ty {
                ty if is_f64(ty) => Some(Shape::Scalar),
                Type::Array(a) if is_f64(&a.elem) => Some(Shape::Array(literal(&a.len))),
                Type::Array(outer) => match &*outer.elem {
                    Type::Array(inner) if is_f64(&inner.elem) => {
                        Some(Shape::Matrix(literal(&outer.len).zip(literal(&inner.len))))
                    }
                    _ => None,
                },
                _ => None,
            };
            match shape {
                Some(shape) => Some(Parameter { name, shape }),
                None => {
                    errors.push(
                        field.ty.span(),
                        format!(
                            "parameter `{name}` must be `f64`, `[f64; K]` or `[[f64; C]; R]`: \
                             parameters are real numbers"
                        ),
                    );
                    None
                }
            }
        })
        .collect()
}

/// Whether `expr` reads a velocity: a call `dot(x)` of one argument or `omega(R)`, a method
/// `.dot(..)`, or one in an expression of a kind the walk does not look into (read on its
/// tokens). Walked with an explicit stack, so that a force of ten thousand terms costs no depth.
fn expression_reads_velocity(expr: &Expr) -> bool {
    expression::subexpressions(expr).any(|e| match e {
        Expr::Call(call) => match &*call.func {
            Expr::Path(path) => {
                path.path.is_ident("omega") || (path.path.is_ident("dot") && call.args.len() == 1)
            }
            other => reads_velocity(other.to_token_stream()),
        },
        Expr::MethodCall(method) => method.method == "dot",
        Expr::Lit(_)
        | Expr::Path(_)
        | Expr::Paren(_)
        | Expr::Group(_)
        | Expr::Unary(_)
        | Expr::Binary(_)
        | Expr::Index(_) => false,
        other => reads_velocity(other.to_token_stream()),
    })
}

/// Whether `tokens` read a velocity: a call `dot(x)` of one argument (`dot(u, v)` is the scalar
/// product) or `omega(R)`, at any depth. Read on the tokens, so that a method call `a.dot(b)`
/// counts too: the answer errs only towards "reads one".
fn reads_velocity(tokens: proc_macro2::TokenStream) -> bool {
    use proc_macro2::{Delimiter, TokenTree};
    let tokens: Vec<TokenTree> = tokens.into_iter().collect();
    tokens.iter().enumerate().any(|(i, token)| match token {
        TokenTree::Ident(name) if name == "dot" || name == "omega" => match tokens.get(i + 1) {
            Some(TokenTree::Group(group)) if group.delimiter() == Delimiter::Parenthesis => {
                let top_level_comma = group
                    .stream()
                    .into_iter()
                    .any(|t| matches!(&t, TokenTree::Punct(p) if p.as_char() == ','));
                name == "omega" || !top_level_comma || reads_velocity(group.stream())
            }
            _ => false,
        },
        TokenTree::Group(group) => reads_velocity(group.stream()),
        _ => false,
    })
}
