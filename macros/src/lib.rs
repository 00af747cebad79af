//! The `constrained_system!` procedural macro. All logic lives in
//! `constrained-codegen` (`expand`); this crate only converts token types.
//! Use it through the `constrained` crate, which documents the DSL.

use proc_macro::TokenStream;

/// Derives the equations of motion of a constrained mechanical system at
/// compile time. See the `constrained` crate for the DSL and what it generates.
#[proc_macro]
pub fn constrained_system(input: TokenStream) -> TokenStream {
    let options = constrained_codegen::Options {
        jacobians: cfg!(feature = "jacobians"),
    };
    constrained_codegen::expand_with(input.into(), options)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// The DSL's functions as a Markdown list line for the `constrained` crate's
/// docs, generated from the operator table so that the docs cannot fall
/// behind it. Not public API.
#[doc(hidden)]
#[proc_macro]
pub fn __dsl_functions(_: TokenStream) -> TokenStream {
    let names: Vec<String> = constrained_codegen::model::lower::function_names()
        .iter()
        .map(|f| format!("`{f}`"))
        .collect();
    let line = format!(" Functions: {}.", names.join(", "));
    TokenStream::from(proc_macro::TokenTree::Literal(proc_macro::Literal::string(
        &line,
    )))
}
