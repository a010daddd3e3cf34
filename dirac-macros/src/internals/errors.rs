//! The error collector every stage pushes into: each error keeps the span of the user's tokens,
//! and all are reported together.

use proc_macro2::{Punct, Spacing, Span, TokenStream, TokenTree};

/// Every error found, each with the span of the user's tokens; reported together. Validation,
/// the rewriter and the one-form splitter all push into one.
#[derive(Default)]
pub struct Errors(Vec<syn::Error>);

impl Errors {
    pub fn push(&mut self, span: Span, message: impl std::fmt::Display) {
        self.0.push(syn::Error::new(span, message));
    }

    /// An error underlining from the token at `start` to the one at `end`.
    pub fn push_range(&mut self, start: Span, end: Span, message: impl std::fmt::Display) {
        let ends: TokenStream = [start, end]
            .into_iter()
            .map(|span| {
                let mut end = Punct::new('.', Spacing::Alone);
                end.set_span(span);
                TokenTree::Punct(end)
            })
            .collect();
        self.0.push(syn::Error::new_spanned(ends, message));
    }

    pub fn add(&mut self, error: syn::Error) {
        self.0.push(error);
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn to_compile_errors(&self) -> TokenStream {
        self.0.iter().map(syn::Error::to_compile_error).collect()
    }
}
