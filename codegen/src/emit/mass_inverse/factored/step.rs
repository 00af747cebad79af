//! `constraint_step` for a configuration-dependent `M` (see
//! `super::super::step`).

use super::FactoredSolve;
use crate::emit::context::Context;
use crate::emit::mass_inverse::step::finish;
use crate::equations::mass_inverse::Factored;
use proc_macro2::TokenStream;
use quote::quote;

/// `M(q)`: its generated factorization, then `W` and `S` on their patterns.
pub(in crate::emit) fn step(ctx: &Context, f: &Factored) -> TokenStream {
    let gauss = FactoredSolve::constraint_space(ctx, f);
    let to_gram = &gauss.to_multipliers; // stops at S's factor in this scope
    let finish = finish(ctx, &gauss.gram, &[], |i, j| {
        f.weighted[i][j].then(|| {
            let w = Context::local2("w", i, j);
            quote!(#w)
        })
    });
    quote! {
        #to_gram
        #finish
    }
}
