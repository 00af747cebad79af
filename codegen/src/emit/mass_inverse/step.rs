//! `constraint_step(q, qd, t, __rhs)`: the projections' Newton step
//! `W S⁺ r` (`W = M⁻¹ Aᵀ`, `S = A W`) through the same generated
//! factorizations as `acceleration`, and which rows the rank rule kept
//! (`constrained::stabilize::project` calls it through the hidden
//! `Generated` trait). Only `S` and `W` are built: no forces, no `b`.
//! `None` where the solve does not answer, as `acceleration` would consult
//! the runtime: `M` not positive there, or a suspect rank decision.

use super::factored::FactoredGauss;
use crate::emit::body::{literal, Body};
use crate::emit::context::{Context, Inputs};
use crate::emit::ldlt::StructuredLdlt;
use crate::expr::Id;
use crate::motion::{Factored, MassInverse, Symbolic};
use crate::num::Num;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The trait method for this system, or nothing (the trait's default,
/// `None`: the runtime's dense step) for a singular `M` or no constraints.
pub(in crate::emit) fn method(ctx: &Context) -> TokenStream {
    if ctx.k == 0 {
        return TokenStream::new();
    }
    let body = match &ctx.eq.gauss {
        MassInverse::Symbolic(d) => symbolic(ctx, d),
        MassInverse::Factored(f) => factored(ctx, f),
        MassInverse::Auxiliary => return TokenStream::new(),
    };
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
fn finish(
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
    // `W S⁻¹ r = W̃ S̃⁻¹ D r` for the scaled system (`crate::motion::Symbolic`).
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

/// Constant or diagonal `M`: `S` and `W` as the symbolic expressions.
fn symbolic(ctx: &Context, d: &Symbolic) -> TokenStream {
    let g = &ctx.eq.system.graph;
    let ldlt = StructuredLdlt::gram(&d.structure);
    let k = ctx.k;
    let mut named: Vec<(Ident, Id)> = Vec::new();
    for i in 0..k {
        for j in 0..=i {
            if d.structure.nonzero[i][j] {
                named.push((ldlt.entry(i, j), d.gram[i][j]));
            }
        }
    }
    let mut roots: Vec<Id> = named.iter().map(|(_, e)| *e).collect();
    roots.extend(d.weighted.iter().flatten().filter(|&&e| !g.is_zero(e)));
    // Each distinct mass that is not a positive constant, checked once.
    let mut masses: Vec<Id> = Vec::new();
    for &m in &d.masses {
        if !g.as_num(m).is_some_and(|v| v.to_f64() > 0.0) && !masses.contains(&m) {
            masses.push(m);
        }
    }
    roots.extend(&masses);
    let body = Body::new(ctx.eq, &roots);
    let preamble = body.preamble();
    let bindings = named.iter().map(|(name, e)| {
        let value = body.expr(*e);
        quote! { let #name = #value; }
    });
    let check = (!masses.is_empty()).then(|| {
        let positive = masses.iter().map(|&m| {
            let m = body.expr(m);
            quote!(#m > T::zero())
        });
        quote! {
            if !(#(#positive)&&*) {
                return ::core::option::Option::None;
            }
        }
    });
    let factor = ldlt.factor();
    let finish = finish(ctx, &ldlt, &d.scale, |i, j| {
        // An entry of W may be a sum (x₁ − x₂ over a mass): `factor`
        // parenthesises it.
        let e = d.weighted[i][j];
        (!g.is_zero(e)).then(|| body.factor(e))
    });
    quote! {
        #preamble
        #(#bindings)*
        #check
        #factor
        #finish
    }
}

/// `M(q)`: its generated factorization, then `W` and `S` on their patterns.
fn factored(ctx: &Context, f: &Factored) -> TokenStream {
    let gauss = FactoredGauss::constraint_space(ctx, f);
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
