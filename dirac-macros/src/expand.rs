//! Emits the struct unchanged and its `impl ::dirac::DiracSystem<N>`.

use proc_macro2::{Span, TokenStream};
use quote::{quote, quote_spanned};
use syn::spanned::Spanned;

use crate::ast::{Arguments, Coordinate, Lagrangian, Length, Model};
use crate::expression::bind_coordinate;
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
    match validate::model(arguments, item.clone()) {
        Outcome::Valid(model) => expand(&model),
        Outcome::Invalid {
            errors,
            coordinates,
        } => {
            let errors = errors.to_compile_errors();
            let stub = coordinates
                .filter(|c| !c.is_empty())
                .map(|c| stub(&item, &c));
            quote!(#errors #item #stub)
        }
    }
}

/// Number of coordinates as a const expression (a literal when every length is one).
fn dimension(coordinates: &[Coordinate]) -> TokenStream {
    let literal: Option<usize> = coordinates
        .iter()
        .map(|c| match &c.length {
            None => Some(1),
            Some(Length::Literal(n, _)) => Some(*n),
            Some(Length::Named(_)) => None,
        })
        .sum();
    match (literal, coordinates) {
        (Some(n), _) => quote!(#n),
        (None, [single]) => single
            .length
            .as_ref()
            .map(Length::tokens)
            .unwrap_or_default(),
        (None, _) => {
            let terms = coordinates
                .iter()
                .map(|c| c.length.as_ref().map_or(quote!(1usize), Length::tokens));
            quote!({ 0usize #(+ #terms)* })
        }
    }
}

/// Offsets of each coordinate into `q` (expressions).
fn offsets(coordinates: &[Coordinate]) -> Vec<TokenStream> {
    let mut offset = quote!(0usize);
    coordinates
        .iter()
        .map(|c| {
            let this = offset.clone();
            let length = c.length.as_ref().map_or(quote!(1usize), Length::tokens);
            offset = quote!(#offset + #length);
            this
        })
        .collect()
}

fn header(item: &syn::ItemStruct, n: &TokenStream) -> TokenStream {
    let name = &item.ident;
    let (impl_generics, ty_generics, where_clause) = item.generics.split_for_impl();
    quote!(impl #impl_generics ::dirac::DiracSystem<#n> for #name #ty_generics #where_clause)
}

fn expand(model: &Model) -> TokenStream {
    let item = &model.item;
    let n = dimension(&model.coordinates);
    let header = header(item, &n);
    let offsets = offsets(&model.coordinates);
    let body = match &model.lagrangian {
        Lagrangian::Function(path) => quote_spanned!(path.span()=> #path(self, __q, __v)),
        Lagrangian::Expression(expr) => {
            let parameters = model.parameters.iter().map(|p| {
                let name = &p.name;
                // Parameters stay f64: constant subexpressions cost no dual arithmetic.
                quote_spanned!(name.span()=> let #name = self.#name;)
            });
            let coordinates = model
                .coordinates
                .iter()
                .zip(&offsets)
                .map(|(c, o)| bind_coordinate(c, o));
            let result = quote_spanned!(expr.span()=> let __lagrangian: __D = #expr;);
            quote! {
                #(#parameters)*
                #(#coordinates)*
                #result
                __lagrangian
            }
        }
    };
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
    quote! {
        #item

        #[automatically_derived]
        #header {
            #[allow(unused_variables, non_snake_case, clippy::all)]
            fn lagrangian<__D: ::dirac::Scalar>(
                &self,
                __q: &::dirac::nalgebra::SVector<__D, #n>,
                __v: &::dirac::nalgebra::SVector<__D, #n>,
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

            fn quadrature(&self) -> ::dirac::Quadrature {
                #quadrature
            }
        }
    }
}

/// After an error: an implementation with the right dimension, so that the user's code using
/// the system reports no second wave of errors. It is never run: compilation has failed.
fn stub(item: &syn::ItemStruct, coordinates: &[Coordinate]) -> TokenStream {
    let n = dimension(coordinates);
    let header = header(item, &n);
    quote! {
        #header {
            fn lagrangian<__D: ::dirac::Scalar>(
                &self,
                _: &::dirac::nalgebra::SVector<__D, #n>,
                _: &::dirac::nalgebra::SVector<__D, #n>,
            ) -> __D {
                ::core::unreachable!("#[dirac_system] reported a compile error")
            }
        }
    }
}
