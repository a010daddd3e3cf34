//! Emits the struct unchanged and its `impl __dirac::DiracSystem<N>` (or, for a model given by
//! a Hamiltonian, `impl __dirac::HamiltonianSystem<N>`; for a model of subsystems, see
//! `subsystems`).

mod subsystems;

use proc_macro2::{Span, TokenStream};
use quote::{quote, quote_spanned};
use syn::spanned::Spanned;

use crate::check::model::Model;
use crate::check::validate::{self, Outcome};
use crate::internals::ast::{
    Arguments, Coordinate, Kind, Lagrangian, Shape, dimension, offsets, product_sizes,
};
use crate::lower::expression::{
    Context, MAX_NESTING, MAX_TOKEN_NESTING, bind_coordinate, part_ident,
};

/// Entry point: parse, validate, expand; on error the struct, the errors and a stub impl.
pub fn dirac_system(args: TokenStream, item: TokenStream) -> TokenStream {
    let item: syn::ItemStruct = match syn::parse2(item.clone()) {
        Ok(item) => item,
        Err(_) => {
            let error = syn::Error::new(
                Span::call_site(),
                "#[dirac_system] applies to a struct whose fields are the model's parameters",
            )
            .to_compile_error();
            return quote!(#error #item);
        }
    };
    if let Some(error) = too_deep(&args) {
        let error = error.to_compile_error();
        return quote!(#error #item);
    }
    let arguments: Arguments = match syn::parse2(args) {
        Ok(arguments) => arguments,
        Err(error) => {
            let error = error.to_compile_error();
            return quote!(#error #item);
        }
    };
    match validate::model(arguments, item) {
        Outcome::Valid(model) => expand(&model),
        Outcome::Composite(composite) => subsystems::expand(&composite),
        Outcome::Invalid {
            errors,
            coordinates,
            item,
            hamiltonian,
            krate,
        } => {
            let errors = errors.to_compile_errors();
            let stub = coordinates
                .filter(|c| !c.is_empty())
                .map(|c| in_scope(&krate, stub(&item, &c, hamiltonian)));
            quote!(#errors #item #stub)
        }
    }
}

/// The generated `items` in a block where `__dirac` names the runtime crate `krate`.
fn in_scope(krate: &syn::Path, items: TokenStream) -> TokenStream {
    quote! {
        const _: () = {
            use #krate as __dirac;
            #items
        };
    }
}

/// The types the generated code is written in: on `Rⁿ`, vectors; with rotations or unit vectors,
/// the `Product` space's points and tangent vectors.
struct Space {
    /// `DiracSystem<N>` or `DiracSystem<N, Product<K, A, B>>`.
    trait_: TokenStream,
    /// The type of `__q` (over `__D`).
    point: TokenStream,
    /// The type of `__v` and of one-forms and forces (over `__D`).
    tangent: TokenStream,
    /// A zero tangent vector over `__D`.
    zero: TokenStream,
    /// Whether the space is a `Product` (real coordinates are then in `__q.vector`).
    product: bool,
}

impl Space {
    /// The space of `coordinates`, for a model given by a Lagrangian or, when `hamiltonian`,
    /// by a Hamiltonian (on `Rⁿ`).
    fn of(coordinates: &[Coordinate], hamiltonian: bool) -> Self {
        let n = dimension(coordinates);
        if !validate::is_product(coordinates) || hamiltonian {
            let trait_ = match hamiltonian {
                true => quote!(__dirac::HamiltonianSystem<#n>),
                false => quote!(__dirac::DiracSystem<#n>),
            };
            let vector = quote!(__dirac::nalgebra::SVector<__D, #n>);
            let zero = quote!(<__D as ::core::convert::From<f64>>::from(0.0));
            return Self {
                trait_,
                point: vector.clone(),
                tangent: vector.clone(),
                zero: quote!(__dirac::nalgebra::SVector::<__D, #n>::from_element(#zero)),
                product: false,
            };
        }
        let (k, a, b) = product_sizes(coordinates);
        Self {
            trait_: quote!(__dirac::DiracSystem<#n, __dirac::Product<#k, #a, #b>>),
            point: quote!(__dirac::Configuration<__D, #k, #a, #b>),
            tangent: quote!(__dirac::Rates<__D, #k, #a, #b>),
            zero: quote!(__dirac::Rates::<__D, #k, #a, #b>::zero()),
            product: true,
        }
    }
}

fn header(item: &syn::ItemStruct, space: &Space) -> TokenStream {
    let name = &item.ident;
    let trait_ = &space.trait_;
    let (impl_generics, ty_generics, where_clause) = item.generics.split_for_impl();
    quote!(impl #impl_generics #trait_ for #name #ty_generics #where_clause)
}

/// The first bracket nested deeper than [`MAX_TOKEN_NESTING`], as an error on its tokens.
///
/// Checked before parsing: the parser recurses once per bracket, so an absurdly deep input would
/// exhaust the compiler's stack before the expression's own nesting check could report it.
fn too_deep(args: &TokenStream) -> Option<syn::Error> {
    let mut pending: Vec<(TokenStream, usize)> = vec![(args.clone(), 0)];
    while let Some((stream, depth)) = pending.pop() {
        for tree in stream {
            if let proc_macro2::TokenTree::Group(group) = tree {
                if depth + 1 > MAX_TOKEN_NESTING {
                    return Some(syn::Error::new(
                        group.span_open(),
                        format!(
                            "brackets nested more than {MAX_TOKEN_NESTING} deep; an expression \
                             nests at most {MAX_NESTING} levels: write it as a generic function or name \
                             parts of it as parameters"
                        ),
                    ));
                }
                pending.push((group.stream(), depth + 1));
            }
        }
    }
    None
}

fn expand(model: &Model) -> TokenStream {
    let item = &model.item;
    let n = dimension(&model.coordinates);
    let space = Space::of(&model.coordinates, model.hamiltonian);
    let header = header(item, &space);
    let function = match model.hamiltonian {
        true => quote!(hamiltonian),
        false => quote!(lagrangian),
    };
    let offsets = offsets(&model.coordinates);
    let kind_indices = crate::internals::ast::kind_indices(&model.coordinates);
    let bindings = |velocities: bool| {
        // Parameters stay f64: constant subexpressions cost no dual-number work.
        let parameters = model.parameters.iter().map(|p| {
            let name = &p.name;
            quote_spanned!(name.span()=> let #name = self.#name;)
        });
        let coordinates = model
            .coordinates
            .iter()
            .zip(&offsets)
            .zip(&kind_indices)
            .map(move |((c, o), &k)| bind_coordinate(c, o, k, velocities, space.product));
        quote!(#(#parameters)* #(#coordinates)*)
    };
    let body = match &model.lagrangian {
        Lagrangian::Function(path) => quote_spanned!(path.span()=> #path(self, __q, __v)),
        Lagrangian::Expression(expr) => {
            let bindings = bindings(true);
            quote! {
                #bindings
                let __lagrangian: __D = #expr;
                __lagrangian
            }
        }
    };
    let dirac = dirac_items(model, &space, &bindings);
    let closed_form = closed_form(model, &n);
    let parts = parts(model, &space, &bindings);
    let names = variable_names(&model.coordinates);
    let parameters = model.parameters.iter().map(|p| {
        let name = &p.name;
        let label = name.to_string();
        match p.shape {
            Shape::Scalar => quote!(__p.push((::std::string::String::from(#label), self.#name));),
            Shape::Array(_) => quote! {
                for (__k, __x) in self.#name.iter().enumerate() {
                    __p.push((::std::format!("{}[{}]", #label, __k), *__x));
                }
            },
            Shape::Matrix(_) => quote! {
                for (__r, __row) in self.#name.iter().enumerate() {
                    for (__c, __x) in __row.iter().enumerate() {
                        __p.push((::std::format!("{}[{}][{}]", #label, __r, __c), *__x));
                    }
                }
            },
        }
    });
    let quadrature = &model.quadrature;
    let (point, tangent) = (&space.point, &space.tangent);
    let component = component(model, &n);
    let explicit = model.explicit.as_ref().map(|composition| {
        let name = &item.ident;
        let (impl_generics, ty_generics, where_clause) = item.generics.split_for_impl();
        quote! {
            #[automatically_derived]
            impl #impl_generics __dirac::ExplicitSystem<#n> for #name #ty_generics #where_clause {
                fn composition(&self) -> __dirac::Composition {
                    #composition
                }
            }
        }
    });
    let implementation = quote! {
        #parts

        #[automatically_derived]
        #header {
            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn #function<__D: __dirac::Scalar>(
                &self,
                __q: &#point,
                __v: &#tangent,
            ) -> __D {
                #body
            }

            #[allow(clippy::all)]
            fn coordinate_name(&self, __i: usize) -> ::std::string::String {
                #names
                ::std::format!("q{}", __i)
            }

            #[allow(clippy::all)]
            fn parameters(&self) -> ::std::vec::Vec<(::std::string::String, f64)> {
                let mut __p = ::std::vec::Vec::new();
                #(#parameters)*
                __p
            }

            fn quadrature(&self) -> ::core::result::Result<__dirac::Quadrature, __dirac::DiracError> {
                #quadrature
            }

            #dirac
            #closed_form
        }

        #component
        #explicit
    };
    let implementation = in_scope(&model.krate, implementation);
    let index_checks = &model.index_checks;
    quote!(#item #(#index_checks)* #implementation)
}

/// What a model on `Rⁿ` given by a Lagrangian offers as a subsystem of
/// `#[dirac_system(subsystems(...))]`: its number of coordinates, and a `const fn` finding a
/// coordinate by name (so that junctions are checked when the program compiles). Hidden.
fn component(model: &Model, n: &TokenStream) -> TokenStream {
    if model.hamiltonian || validate::is_product(&model.coordinates) {
        return TokenStream::new();
    }
    let item = &model.item;
    let name = &item.ident;
    let (impl_generics, ty_generics, where_clause) = item.generics.split_for_impl();
    let point = match (model.one_forms.is_empty(), &model.constraint_point) {
        (true, _) => quote!(::core::option::Option::None),
        (false, Some(point)) => quote!(::core::option::Option::Some(#point)),
        (false, None) => quote!(::core::option::Option::Some(
            __dirac::ConstraintPoint::Midpoint
        )),
    };
    let entries = model
        .coordinates
        .iter()
        .zip(offsets(&model.coordinates))
        .map(|(c, offset)| {
            let label = c.name.to_string();
            let length = match &c.length {
                None => quote!(::core::option::Option::None),
                Some(length) => {
                    let length = length.tokens();
                    quote!(::core::option::Option::Some(#length))
                }
            };
            quote!((#label, #length, #offset))
        });
    quote! {
        #[automatically_derived]
        impl #impl_generics #name #ty_generics #where_clause {
            #[doc(hidden)]
            pub const __DIRAC_COORDINATES: usize = #n;

            #[doc(hidden)]
            pub const fn __dirac_coordinate(__path: &str) -> ::core::option::Option<usize> {
                __dirac::slot::coordinate_index(__path, &[#(#entries),*])
            }

            #[doc(hidden)]
            pub const __DIRAC_CONSTRAINT_POINT: ::core::option::Option<__dirac::ConstraintPoint> = #point;
        }
    }
}

/// The body of `coordinate_name`: the model's variables in the manifold's order (on a product,
/// the real coordinates, then the rotations, then the unit vectors), array elements as `x[i]`.
fn variable_names(coordinates: &[Coordinate]) -> TokenStream {
    let mut next = quote!(0usize);
    let mut arms = Vec::new();
    for kind in [Kind::Real, Kind::Rotation, Kind::Direction] {
        for c in coordinates.iter().filter(|c| c.kind == kind) {
            let name = c.name.to_string();
            let offset = next.clone();
            arms.push(match &c.length {
                None => {
                    next = quote!(#next + 1usize);
                    quote!(if __i == #offset { return ::std::string::String::from(#name); })
                }
                Some(length) => {
                    let length = length.tokens();
                    next = quote!(#next + #length);
                    quote! {
                        if __i >= #offset && __i < #offset + #length {
                            return ::std::format!("{}[{}]", #name, __i - (#offset));
                        }
                    }
                }
            });
        }
    }
    quote!(#(#arms)*)
}

/// `lagrangian_gradient` and `lagrangian_hessian` where the Lagrangian has closed forms: the
/// parameters bound by name, then straight-line `f64` code.
fn closed_form(model: &Model, n: &TokenStream) -> TokenStream {
    let parameters = model.parameters.iter().map(|p| {
        let name = &p.name;
        quote!(let #name = self.#name;)
    });
    let parameters = quote!(#(#parameters)*);
    let vector = quote!(&__dirac::nalgebra::SVector<f64, #n>);
    // On rotations the closed forms are read at the `Product`'s points and rates.
    let (point, rates) = match validate::is_product(&model.coordinates) {
        false => (vector.clone(), vector.clone()),
        true => {
            let (k, a, b) = crate::internals::ast::product_sizes(&model.coordinates);
            (
                quote!(&__dirac::Configuration<f64, #k, #a, #b>),
                quote!(&__dirac::Rates<f64, #k, #a, #b>),
            )
        }
    };
    let one_forms = model.one_form_derivatives.as_ref().map(|derivatives| {
        let arms = derivatives
            .iter()
            .enumerate()
            .map(|(a, body)| quote!(#a => { #body }));
        quote! {
            const ONE_FORM_DERIVATIVES: bool = true;

            #[inline]
            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn one_form_with_derivative(
                &self,
                __q: #vector,
                __a: usize,
                mut __entry: impl FnMut(usize, usize, f64),
            ) -> __dirac::nalgebra::SVector<f64, #n> {
                #parameters
                match __a {
                    #(#arms)*
                    _ => __dirac::nalgebra::SVector::<f64, #n>::zeros(),
                }
            }
        }
    });
    let Some(closed) = &model.closed_form else {
        return quote!(#one_forms);
    };
    let gradient = &closed.gradient;
    let hessian = closed.hessian.as_ref().map(|hessian| {
        quote! {
            #[inline]
            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn lagrangian_hessian(
                &self,
                __q: #point,
                __v: #rates,
            ) -> ::core::option::Option<__dirac::LagrangianHessian<#n>> {
                #parameters
                #hessian
            }
        }
    });
    let entire = closed.entire.then(|| {
        quote!(
            const LAGRANGIAN_ENTIRE: bool = true;
        )
    });
    let separable = closed.separable.then(|| {
        quote!(
            const SEPARABLE: bool = true;
        )
    });
    let quadratic = closed.quadratic.then(|| {
        quote!(
            const QUADRATIC: bool = true;
        )
    });
    let any = closed.zeros.iter().flatten().flatten().any(|&zero| zero);
    let zeros = (closed.hessian.is_some() && any).then(|| {
        let [qq, qv, vv] = closed.zeros.clone().map(|block| {
            let rows = block.into_iter().map(|row| quote!([#(#row),*]));
            quote!([#(#rows),*])
        });
        quote!(
            const LAGRANGIAN_HESSIAN_ZEROS: __dirac::HessianZeros<#n> =
                __dirac::HessianZeros { qq: #qq, qv: #qv, vv: #vv };
        )
    });
    quote! {
        #entire
        #separable
        #quadratic
        #zeros
        #one_forms

        #[inline]
        #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
        fn lagrangian_gradient(
            &self,
            __q: #point,
            __v: #rates,
        ) -> ::core::option::Option<__dirac::LagrangianGradient<#n>> {
            #parameters
            #gradient
        }

        #hessian
    }
}

/// The inputs bound by name for the forces.
fn input_bindings(model: &Model) -> TokenStream {
    let inputs = model
        .inputs
        .iter()
        .enumerate()
        .map(|(i, u)| quote!(let #u: __D = __inputs[#i];));
    quote!(#(#inputs)*)
}

/// The hoisted continuations of long chains, as private methods of the model (none for a model
/// without chains longer than one chunk). Each binds what its context's method binds.
fn parts(model: &Model, space: &Space, bindings: &dyn Fn(bool) -> TokenStream) -> TokenStream {
    if model.parts.is_empty() {
        return TokenStream::new();
    }
    let (point, tangent) = (&space.point, &space.tangent);
    let methods = model.parts.iter().enumerate().map(|(k, part)| {
        let (parameters, prelude) = match part.context {
            Context::Lagrangian => (quote!(__q: &#point, __v: &#tangent,), bindings(true)),
            Context::Force => {
                let state = bindings(true);
                let inputs = input_bindings(model);
                (
                    quote!(__q: &#point, __v: &#tangent, t: f64, __inputs: &[__D],),
                    quote!(#state #inputs),
                )
            }
            Context::Positions => (quote!(__q: &#point,), bindings(false)),
        };
        let (name, body, scalar) = (part_ident(k), &part.body, &part.scalar);
        quote! {
            #[doc(hidden)]
            #[inline(never)]
            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn #name<__D: __dirac::Scalar>(&self, #parameters __chain: #scalar) -> #scalar {
                #prelude
                #body
            }
        }
    });
    let name = &model.item.ident;
    let (impl_generics, ty_generics, where_clause) = model.item.generics.split_for_impl();
    quote! {
        #[automatically_derived]
        impl #impl_generics #name #ty_generics #where_clause {
            #(#methods)*
        }
    }
}

/// `Σ_k c_k · e_{i_k}` into a vector named `target`.
fn accumulate(target: &TokenStream, terms: &[crate::internals::ast::Term]) -> TokenStream {
    let terms = terms.iter().map(|t| {
        let (index, coefficient) = (&t.index, &t.coefficient);
        quote_spanned!(t.span=> #target[#index] += #coefficient;)
    });
    quote!(#(#terms)*)
}

/// The one-forms, holonomic constraints, forces and inputs: only those the model names.
fn dirac_items(
    model: &Model,
    space: &Space,
    bindings: &dyn Fn(bool) -> TokenStream,
) -> TokenStream {
    let mut items = TokenStream::new();
    let zero = quote!(<__D as ::core::convert::From<f64>>::from(0.0));
    let (point, tangent, zero_tangent) = (&space.point, &space.tangent, &space.zero);
    if !model.one_forms.is_empty() {
        let count = model.one_forms.len();
        let positions = bindings(false);
        let arms = model.one_forms.iter().enumerate().map(|(a, terms)| {
            let sum = accumulate(&quote!(__w), terms);
            quote!(#a => { #sum })
        });
        items.extend(quote! {
            const ONE_FORMS: usize = #count;

            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn one_form<__D: __dirac::Scalar>(
                &self,
                __q: &#point,
                __a: usize,
            ) -> #tangent {
                #positions
                let mut __w = #zero_tangent;
                match __a {
                    #(#arms)*
                    _ => {}
                }
                __w
            }
        });
        let names = &model.one_form_names;
        // (The Hamiltonian route's trait has no such methods.)
        if !model.hamiltonian {
            items.extend(quote! {
            fn one_form_name(&self, __a: usize) -> ::std::string::String {
                const __NAMES: [&str; #count] = [#(#names),*];
                match __NAMES.get(__a) {
                    ::core::option::Option::Some(__name) => ::std::format!("one-form `{}`", __name),
                    ::core::option::Option::None => ::std::format!("one-form {}", __a),
                }
            }
            });
        }
        let constant = &model.constant_one_forms;
        if !model.hamiltonian && constant.iter().any(|&c| c) {
            items.extend(quote! {
                fn one_form_is_constant(&self, __a: usize) -> bool {
                    const __CONSTANT: [bool; #count] = [#(#constant),*];
                    __a < #count && __CONSTANT[__a]
                }
            });
        }
    }
    if !model.holonomic.is_empty() {
        let count = model.holonomic.len();
        let positions = bindings(false);
        let arms = model
            .holonomic
            .iter()
            .enumerate()
            .map(|(b, g)| quote!(#b => #g,));
        items.extend(quote! {
            const HOLONOMIC: usize = #count;

            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn holonomic<__D: __dirac::Scalar>(
                &self,
                __q: &#point,
                __b: usize,
            ) -> __D {
                #positions
                match __b {
                    #(#arms)*
                    _ => #zero,
                }
            }
        });
    }
    if !model.forces.is_empty() {
        let state = bindings(true);
        let inputs = input_bindings(model);
        let sum = accumulate(&quote!(__f), &model.forces);
        let free = (model.forces_free_of_velocity && !model.hamiltonian).then(|| {
            quote!(
                const FORCES_FREE_OF_VELOCITY: bool = true;
            )
        });
        let affine = model.forces_affine.then(|| {
            quote!(
                const FORCES_AFFINE: bool = true;
            )
        });
        items.extend(quote! {
            const FORCES: bool = true;
            #free
            #affine

            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn force<__D: __dirac::Scalar>(
                &self,
                __q: &#point,
                __v: &#tangent,
                t: f64,
                __inputs: &[__D],
            ) -> #tangent {
                #state
                #inputs
                let mut __f = #zero_tangent;
                #sum
                __f
            }
        });
    }
    if !model.inputs.is_empty() {
        let count = model.inputs.len();
        let names = model.inputs.iter().map(|u| u.to_string());
        items.extend(quote! {
            const INPUTS: usize = #count;

            fn input_name(&self, __i: usize) -> ::std::string::String {
                let __names: [&str; #count] = [#(#names),*];
                __names.get(__i).map_or_else(|| ::std::format!("u{}", __i), |s| s.to_string())
            }
        });
    }
    if let Some(point) = &model.constraint_point {
        items.extend(quote! {
            fn constraint_point(&self) -> __dirac::ConstraintPoint {
                #point
            }
        });
    }
    items
}

/// After an error: an implementation with the right dimension, so that the user's code using
/// the system reports no second wave of errors. It is never run: compilation has failed.
fn stub(item: &syn::ItemStruct, coordinates: &[Coordinate], hamiltonian: bool) -> TokenStream {
    let space = Space::of(coordinates, hamiltonian);
    let header = header(item, &space);
    let (point, tangent) = (&space.point, &space.tangent);
    let function = match hamiltonian {
        true => quote!(hamiltonian),
        false => quote!(lagrangian),
    };
    quote! {
        #header {
            fn #function<__D: __dirac::Scalar>(
                &self,
                _: &#point,
                _: &#tangent,
            ) -> __D {
                ::core::unreachable!("#[dirac_system] reported a compile error")
            }
        }
    }
}
