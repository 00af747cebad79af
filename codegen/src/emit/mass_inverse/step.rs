//! `constraint_step(q, qd, t, __rhs)`: the projections' Newton step
//! `W S⁺ r` (`W = M⁻¹ Aᵀ`, `S = A W`) through the same generated
//! factorizations as `acceleration`, and which rows the rank rule kept
//! (`constrained::stabilize::project` calls it through the hidden
//! `Generated` trait). Only `S` and `W` are built: no forces, no `b`.
//! `None` where the solve does not answer, as `acceleration` would consult
//! the runtime: `M` not positive there, or a suspect rank decision.

use crate::emit::body::literal;
use crate::emit::context::{Context, Inputs};
use crate::emit::ldlt::StructuredLdlt;
use crate::expr::num::Num;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The trait method around the strategy's `body`.
pub(super) fn method(ctx: &Context, body: &TokenStream) -> TokenStream {
    let (params, n, k) = (ctx.params(Inputs::States), ctx.n, ctx.k);
    let (vector, k_vector, k_l) = (ctx.vector(n), ctx.vector(k), Context::dim(k));
    quote! {
        #[inline]
        #[allow(unused_variables, non_snake_case, clippy::all, clippy::pedantic)]
        fn constraint_step(
            &self,
            #params,
            __rhs: &#k_vector,
        ) -> ::core::option::Option<(#vector, [bool; #k_l])> {
            #body
        }
    }
}

/// The solve of `S μ = r`, `W μ`, and the kept rows, once `S`'s factor
/// and `W`'s entries (`w(i, j)`, `None` where structurally zero; each
/// fit to be the left operand of `*`) are bound.
pub(super) fn finish(
    ctx: &Context,
    ldlt: &StructuredLdlt,
    scale: &[Num],
    w: impl Fn(usize, usize) -> Option<TokenStream>,
) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let rhs: Vec<Ident> = (0..k).map(|j| Context::local("pr", j)).collect();
    let mu: Vec<Ident> = (0..k).map(|j| Context::local("pmu", j)).collect();
    let solve = ldlt.solve(&rhs, "py", &mu);
    let suspect = ldlt.suspect(ctx.generic_rank);
    let step = ctx.vector_value((0..n).map(|i| {
        let terms: Vec<TokenStream> = (0..k)
            .filter_map(|j| {
                w(i, j).map(|wij| {
                    let m = &mu[j];
                    quote!(#wij * #m)
                })
            })
            .collect();
        if terms.is_empty() {
            quote!(T::zero())
        } else {
            quote!(#(#terms)+*)
        }
    }));
    let kept = (0..k).map(|j| ldlt.kept(j));
    // `W S⁻¹ r = W̃ S̃⁻¹ D r` for the scaled system (`crate::equations::mass_inverse::Symbolic`).
    let scaled = rhs
        .iter()
        .zip(scale)
        .filter(|(_, s)| !s.is_one())
        .map(|(r, &s)| {
            let (s, _) = literal(s);
            quote! { let #r = #s * #r; }
        });
    quote! {
        if #suspect {
            return ::core::option::Option::None;
        }
        let [[#(#rhs),*]] = __rhs.data.0;
        #(#scaled)*
        #solve
        ::core::option::Option::Some((#step, [#(#kept),*]))
    }
}
