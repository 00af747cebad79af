//! The `constrained_system!` procedural macro. All logic lives in
//! `constrained-codegen` (`expand`); this crate only converts token types.
//! Use it through the `constrained` crate, which documents the DSL.

use proc_macro::TokenStream;

/// Derives the equations of motion of a constrained mechanical system at
/// compile time. See the `constrained` crate for the DSL and what it generates.
#[proc_macro]
pub fn constrained_system(input: TokenStream) -> TokenStream {
    constrained_codegen::expand(input.into())
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}
