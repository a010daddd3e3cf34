//! The expansion of a model made of subsystems (read and checked by
//! [`check::subsystems`](crate::check::subsystems)): its `impl DiracSystem` through each
//! subsystem's `Slot`, and its place as a subsystem of a larger model.

use proc_macro2::TokenStream;
use quote::{format_ident, quote, quote_spanned};
use syn::spanned::Spanned;
use syn::{Ident, Type};

use crate::check::subsystems::{Composite, Subsystem};

/// The struct and its `impl DiracSystem`, in a block where `__dirac` names the runtime.
pub fn expand(model: &Composite) -> TokenStream {
    let item = &model.item;
    let name = &item.ident;
    let krate = &model.krate;
    let k = model.subsystems.len();
    // How each subsystem is read from `self` (`self.a`, `self.cells[2]`) and its name.
    let fields: Vec<TokenStream> = model.subsystems.iter().map(Subsystem::access).collect();
    let types: Vec<&Type> = model.subsystems.iter().map(|s| &s.ty).collect();
    let labels: Vec<String> = model.subsystems.iter().map(Subsystem::label).collect();
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
                #((#labels, #fields.quadrature()?)),*
            ])
        },
    };
    let lookups = labels.iter().zip(&types).zip(&slots).map(|((label, ty), slot)| {
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
        let span = model.subsystems[i].field.span();
        quote_spanned!(span=> if __i == #i { ::core::panic!(#message) })
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
            // The sum of the components' Lagrangians and forces: quadratic, and affine, where
            // every component's is.
            const QUADRATIC: bool = true #(&& #systems::QUADRATIC)*;
            const FORCES_AFFINE: bool = true #(&& (!#systems::FORCES || #systems::FORCES_AFFINE))*;

            fn lagrangian<__D: __dirac::Scalar>(&self, __q: &#dual, __v: &#dual) -> __D {
                let mut __l = #zero;
                #(__l = __l + #slots.lagrangian(&#fields, __q, __v);)*
                __l
            }

            fn lagrangian_gradient(
                &self,
                __q: &#real,
                __v: &#real,
            ) -> ::core::option::Option<__dirac::LagrangianGradient<{ __N }>> {
                let mut __g = __dirac::LagrangianGradient::zero();
                #(#slots.add_gradient(&#fields, __q, __v, &mut __g)?;)*
                ::core::option::Option::Some(__g)
            }

            fn lagrangian_hessian(
                &self,
                __q: &#real,
                __v: &#real,
            ) -> ::core::option::Option<__dirac::LagrangianHessian<{ __N }>> {
                let mut __h = __dirac::LagrangianHessian::zero();
                #(#slots.add_hessian(&#fields, __q, __v, &mut __h)?;)*
                ::core::option::Option::Some(__h)
            }

            fn one_form<__D: __dirac::Scalar>(&self, __q: &#dual, __a: usize) -> #dual {
                #(
                    if let ::core::option::Option::Some(__w) = #slots.one_form(&#fields, __q, __a) {
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
                    if let ::core::option::Option::Some(__name) = #slots.one_form_name(&#fields, #labels, __a) {
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
                    if let ::core::option::Option::Some(__c) = #slots.one_form_is_constant(&#fields, __a) {
                        return __c;
                    }
                )*
                true
            }

            fn holonomic<__D: __dirac::Scalar>(&self, __q: &#dual, __b: usize) -> __D {
                #(
                    if let ::core::option::Option::Some(__g) = #slots.holonomic(&#fields, __q, __b) {
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
                #(#slots.place_force(&#fields, __q, __v, __t, __u, &mut __f);)*
                __f
            }

            fn input_name(&self, __i: usize) -> ::std::string::String {
                #(
                    if let ::core::option::Option::Some(__name) = #slots.input_name(&#fields, #labels, __i) {
                        return __name;
                    }
                )*
                ::std::format!("u{}", __i)
            }

            fn coordinate_name(&self, __i: usize) -> ::std::string::String {
                #(
                    if let ::core::option::Option::Some(__name) = #slots.coordinate_name(&#fields, #labels, __i) {
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
                #(__dirac::slot::Slot::parameters(&#fields, #labels, &mut __p);)*
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
                [#(#slots.energy(&#fields, __q, __v)),*]
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

            fn component_name(&self, __c: usize) -> ::std::string::String {
                const __NAMES: [&str; #k] = [#(#labels),*];
                __NAMES.get(__c).map_or_else(
                    || ::std::format!("component {}", __c),
                    |__n| ::std::string::String::from(*__n),
                )
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
