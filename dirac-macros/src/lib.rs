use proc_macro::TokenStream;
#[proc_macro_attribute]
pub fn dirac_system(_a: TokenStream, item: TokenStream) -> TokenStream { item }
