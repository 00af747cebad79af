//! The code generator behind `constrained_system!`.
//!
//! [`expand`] is the whole macro as a function from tokens to tokens, so that
//! tests, snapshots and benchmarks run it directly; the proc-macro crate
//! `constrained-macros` only converts token types and calls it.
//!
//! Stages, each a pure function of the previous one's output:
//! 1. [`parse`]: tokens → DSL syntax (`SystemInput`);
//! 2. [`model`]: names resolved, expressions lowered into the DAG of
//!    [`expr`], every rule checked, errors reported together;
//! 3. [`derive`](mod@derive): constraints differentiated ([`diff`]) into `A q̈ = b`;
//! 4. [`emit`]: straight-line Rust with shared subexpressions ([`cse`]) and
//!    the derivation text ([`derivation`], [`print`](mod@print)).

pub mod cse;
pub mod derivation;
pub mod derive;
pub mod diff;
pub mod emit;
pub mod expr;
pub mod fixtures;
pub mod linalg;
pub mod model;
pub mod motion;
pub mod num;
pub mod parse;
pub mod print;
pub mod rng;

use proc_macro2::TokenStream;

/// Expands one `constrained_system! { ... }` invocation body.
pub fn expand(input: TokenStream) -> syn::Result<TokenStream> {
    Ok(emit::system(&analyse(input)?))
}

/// Stages 1–3: the checked system and its derived equations, before emission.
pub fn analyse(input: TokenStream) -> syn::Result<derive::Equations> {
    let input: parse::SystemInput = syn::parse2(input)?;
    let system = model::check(&input)?;
    Ok(derive::constraint_equations(system))
}
