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
    if let Some(Ok(tokens)) = expanded_as_text(&input, options) {
        return tokens;
    }
    // With the compiler's tokens, errors point at the input's own.
    constrained_codegen::expand_with(input.into(), options)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// The expansion made with `proc-macro2`'s own tokens, handed to the
/// compiler as one string: `None` where the input cannot round-trip
/// through text, an `Err` where the input is rejected (the caller expands
/// it again with the compiler's tokens, whose spans the errors need).
///
/// Why: a robot's expansion is millions of tokens, and each token made or
/// read as the compiler's is a call across the proc-macro bridge (a third
/// of the standing G1's expansion time inside the compiler). With
/// `proc-macro2`'s own tokens the compiler parses the result once. The
/// generated items then carry the call site's span instead of the input's:
/// only errors point at the input's tokens, and they take the other path.
fn expanded_as_text(
    input: &TokenStream,
    options: constrained_codegen::Options,
) -> Option<syn::Result<TokenStream>> {
    // An invisible group (a `macro_rules!` fragment such as `$e:expr`)
    // prints without its delimiters, which would change how `a + b`
    // binds inside `$e * 2`: such input takes the compiler's tokens.
    if invisible_groups(input.clone()) {
        return None;
    }
    let text = input.to_string();
    let _fallback = Fallback::force();
    let tokens: proc_macro2::TokenStream = text.parse().ok()?;
    Some(constrained_codegen::expand_with(tokens, options).map(TokenStream::from))
}

/// Whether `stream` holds a group without delimiters, at any depth.
fn invisible_groups(stream: TokenStream) -> bool {
    stream.into_iter().any(|t| match t {
        proc_macro::TokenTree::Group(g) => {
            g.delimiter() == proc_macro::Delimiter::None || invisible_groups(g.stream())
        }
        _ => false,
    })
}

/// `proc-macro2`'s fallback tokens while this lives (the compiler's again
/// when it drops, on every path out).
struct Fallback;

impl Fallback {
    fn force() -> Fallback {
        proc_macro2::fallback::force();
        Fallback
    }
}

impl Drop for Fallback {
    fn drop(&mut self) {
        proc_macro2::fallback::unforce();
    }
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
