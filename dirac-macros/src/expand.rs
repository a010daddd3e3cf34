//! Emits the struct unchanged and its `impl __dirac::DiracSystem<N>`.

use proc_macro2::{Span, TokenStream};
use quote::{quote, quote_spanned};
use syn::spanned::Spanned;

use crate::ast::{Arguments, Coordinate, Lagrangian, Model, dimension, offsets};
use crate::expression::{Context, bind_coordinate, part_ident};
use crate::validate::{self, Outcome};

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
    let arguments: Arguments = match syn::parse2(args) {
        Ok(arguments) => arguments,
        Err(error) => {
            let error = error.to_compile_error();
            return quote!(#error #item);
        }
    };
    match validate::model(arguments, item) {
        Outcome::Valid(model) => expand(&model),
        Outcome::Invalid {
            errors,
            coordinates,
            item,
            krate,
        } => {
            let errors = errors.to_compile_errors();
            let stub = coordinates
                .filter(|c| !c.is_empty())
                .map(|c| in_scope(&krate, stub(&item, &c)));
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

fn header(item: &syn::ItemStruct, n: &TokenStream) -> TokenStream {
    let name = &item.ident;
    let (impl_generics, ty_generics, where_clause) = item.generics.split_for_impl();
    quote!(impl #impl_generics __dirac::DiracSystem<#n> for #name #ty_generics #where_clause)
}

fn expand(model: &Model) -> TokenStream {
    let item = &model.item;
    let n = dimension(&model.coordinates);
    let header = header(item, &n);
    let offsets = offsets(&model.coordinates);
    let bindings = |velocities: bool| {
        // Parameters stay f64: constant subexpressions cost no dual arithmetic.
        let parameters = model.parameters.iter().map(|p| {
            let name = &p.name;
            quote_spanned!(name.span()=> let #name = self.#name;)
        });
        let coordinates = model
            .coordinates
            .iter()
            .zip(&offsets)
            .map(move |(c, o)| bind_coordinate(c, o, velocities));
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
    let dirac = dirac_items(model, &n, &bindings);
    let closed_form = closed_form(model, &n);
    let parts = parts(model, &n, &bindings);
    let names = model.coordinates.iter().zip(&offsets).map(|(c, offset)| {
        let name = c.name.to_string();
        match &c.length {
            None => quote!(if __i == #offset { return ::std::string::String::from(#name); }),
            Some(length) => {
                let length = length.tokens();
                quote! {
                    if __i >= #offset && __i < #offset + #length {
                        return ::std::format!("{}[{}]", #name, __i - (#offset));
                    }
                }
            }
        }
    });
    let parameters = model.parameters.iter().map(|p| {
        let name = &p.name;
        let label = name.to_string();
        if p.array {
            quote! {
                for (__k, __x) in self.#name.iter().enumerate() {
                    __p.push((::std::format!("{}[{}]", #label, __k), *__x));
                }
            }
        } else {
            quote!(__p.push((::std::string::String::from(#label), self.#name));)
        }
    });
    let quadrature = &model.quadrature;
    let implementation = quote! {
        #parts

        #[automatically_derived]
        #header {
            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn lagrangian<__D: __dirac::Scalar>(
                &self,
                __q: &__dirac::nalgebra::SVector<__D, #n>,
                __v: &__dirac::nalgebra::SVector<__D, #n>,
            ) -> __D {
                #body
            }

            #[allow(clippy::all)]
            fn coordinate_name(&self, __i: usize) -> ::std::string::String {
                #(#names)*
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
    };
    let implementation = in_scope(&model.krate, implementation);
    quote!(#item #implementation)
}

/// `lagrangian_gradient` and `lagrangian_hessian` where the Lagrangian has closed forms: the
/// parameters bound by name, then straight-line `f64` code.
fn closed_form(model: &Model, n: &TokenStream) -> TokenStream {
    let Some(closed) = &model.closed_form else {
        return TokenStream::new();
    };
    let parameters = model.parameters.iter().map(|p| {
        let name = &p.name;
        quote!(let #name = self.#name;)
    });
    let parameters = quote!(#(#parameters)*);
    let vector = quote!(&__dirac::nalgebra::SVector<f64, #n>);
    let gradient = &closed.gradient;
    let hessian = closed.hessian.as_ref().map(|hessian| {
        quote! {
            #[inline]
            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn lagrangian_hessian(
                &self,
                __q: #vector,
                __v: #vector,
            ) -> ::core::option::Option<__dirac::LagrangianHessian<#n>> {
                #parameters
                #hessian
            }
        }
    });
    quote! {
        #[inline]
        #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
        fn lagrangian_gradient(
            &self,
            __q: #vector,
            __v: #vector,
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
fn parts(model: &Model, n: &TokenStream, bindings: &dyn Fn(bool) -> TokenStream) -> TokenStream {
    if model.parts.is_empty() {
        return TokenStream::new();
    }
    let vector = quote!(&__dirac::nalgebra::SVector<__D, #n>);
    let methods = model.parts.iter().enumerate().map(|(k, part)| {
        let (parameters, prelude) = match part.context {
            Context::Lagrangian => (quote!(__q: #vector, __v: #vector,), bindings(true)),
            Context::Force => {
                let state = bindings(true);
                let inputs = input_bindings(model);
                (
                    quote!(__q: #vector, __v: #vector, t: f64, __inputs: &[__D],),
                    quote!(#state #inputs),
                )
            }
            Context::Positions => (quote!(__q: #vector,), bindings(false)),
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
fn accumulate(target: &TokenStream, terms: &[crate::ast::Term]) -> TokenStream {
    let terms = terms.iter().map(|t| {
        let (index, coefficient) = (&t.index, &t.coefficient);
        quote_spanned!(t.span=> #target[#index] += #coefficient;)
    });
    quote!(#(#terms)*)
}

/// The one-forms, holonomic constraints, forces and inputs: only those the model names.
fn dirac_items(
    model: &Model,
    n: &TokenStream,
    bindings: &dyn Fn(bool) -> TokenStream,
) -> TokenStream {
    let mut items = TokenStream::new();
    let zero = quote!(<__D as ::core::convert::From<f64>>::from(0.0));
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
                __q: &__dirac::nalgebra::SVector<__D, #n>,
                __a: usize,
            ) -> __dirac::nalgebra::SVector<__D, #n> {
                #positions
                let mut __w = __dirac::nalgebra::SVector::<__D, #n>::from_element(#zero);
                match __a {
                    #(#arms)*
                    _ => {}
                }
                __w
            }
        });
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
                __q: &__dirac::nalgebra::SVector<__D, #n>,
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
        items.extend(quote! {
            const FORCES: bool = true;

            #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
            fn force<__D: __dirac::Scalar>(
                &self,
                __q: &__dirac::nalgebra::SVector<__D, #n>,
                __v: &__dirac::nalgebra::SVector<__D, #n>,
                t: f64,
                __inputs: &[__D],
            ) -> __dirac::nalgebra::SVector<__D, #n> {
                #state
                #inputs
                let mut __f = __dirac::nalgebra::SVector::<__D, #n>::from_element(#zero);
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
fn stub(item: &syn::ItemStruct, coordinates: &[Coordinate]) -> TokenStream {
    let n = dimension(coordinates);
    let header = header(item, &n);
    quote! {
        #header {
            fn lagrangian<__D: __dirac::Scalar>(
                &self,
                _: &__dirac::nalgebra::SVector<__D, #n>,
                _: &__dirac::nalgebra::SVector<__D, #n>,
            ) -> __D {
                ::core::unreachable!("#[dirac_system] reported a compile error")
            }
        }
    }
}
