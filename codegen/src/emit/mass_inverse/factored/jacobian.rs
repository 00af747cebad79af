//! `acceleration_jacobian` for a configuration-dependent `M`: the tangent
//! systems solved column by column through `gauss`'s factorizations.

use super::FactoredSolve;
use crate::emit::chunks::bounded;
use crate::emit::context::Context;
use crate::emit::mass_inverse::adopt_dense;
use crate::equations::mass_inverse::Factored;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The body of `acceleration_jacobian` for a configuration-dependent `M`;
/// `dense` (the runtime's solve) answers where the rank decision is suspect.
pub(in crate::emit) fn jacobian(ctx: &Context, f: &Factored, dense: &TokenStream) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let g = &ctx.eq.system.graph;
    let a = &ctx.eq.a;
    let gauss = FactoredSolve::new(ctx, f, false);
    let qdd = ctx.vector_value(gauss.acceleration.iter().cloned());
    let lam = ctx.vector_value((0..k).map(|j| {
        let l = Context::local("lam", j);
        quote!(#l)
    }));
    // F̃ and b̃ into one column block each, by the `tangent_rhs` the
    // runtime's dense solve calls too (one copy of that code).
    // Per column: u = M⁻¹ F̃, μ = S⁺ (b̃ − A u), q̈ᵥ = u + W μ.
    let fv: Vec<Ident> = (0..n).map(|i| Context::local("jf", i)).collect();
    let u: Vec<Ident> = (0..n).map(|i| Context::local("ju", i)).collect();
    let rv: Vec<Ident> = (0..k).map(|j| Context::local("jb", j)).collect();
    let r: Vec<Ident> = (0..k).map(|j| Context::local("jr", j)).collect();
    let mu: Vec<Ident> = (0..k).map(|j| Context::local("jmu", j)).collect();
    let solve_u = gauss.mass.solve(&fv, "jy", &u);
    let residuals = (0..k).map(|j| {
        let products = (0..n).filter(|&i| !g.is_zero(a[j][i])).map(|i| {
            let (aji, ui) = (Context::local2("a", j, i), &u[i]);
            quote!(#aji * #ui)
        });
        let b = &rv[j];
        quote!(#b #(- #products)*)
    });
    let solve_mu = gauss.gram.solve(&r, "jz", &mu);
    let column = (0..n).map(|i| {
        let products: Vec<TokenStream> = (0..k)
            .filter(|&j| f.weighted[i][j])
            .map(|j| {
                let (w, m) = (Context::local2("w", i, j), &mu[j]);
                quote!(#w * #m)
            })
            .collect();
        let ui = &u[i];
        quote!(#ui #(+ #products)*)
    });
    let (n_l, k_l) = (Context::dim(n), Context::dim(k));
    let (jacobians_zero, d_l) = ctx.jacobians_zero();
    let tangent = ctx.private(quote!(Tangent<T, #n_l, #k_l, #d_l>));
    let finite = ctx.finite_or_error(quote!(__jac));
    debug_assert!(
        ctx.eq.mass_inverse.fallible(),
        "a configuration-dependent M is not known positive definite"
    );
    let unpack_b = (k > 0).then(|| quote!(let [#(#rv),*] = *__r;));
    let (suspect, adopt) = if k > 0 {
        let suspect = gauss.gram.suspect(ctx.generic_rank);
        let adopt = adopt_dense(dense);
        (suspect, adopt)
    } else {
        (quote!(false), TokenStream::new())
    };
    let solve_columns = quote! {
        let mut __fs = ::constrained::nalgebra::SMatrix::<T, #n_l, #d_l>::zeros();
        let mut __rs = ::constrained::nalgebra::SMatrix::<T, #k_l, #d_l>::zeros();
        <Self as #tangent>::tangent_rhs(self, q, qd, t, &#qdd, &#lam, &mut __fs, &mut __rs);
        let __outs = __jac.dq.data.0.iter_mut()
            .chain(__jac.dqd.data.0.iter_mut())
            .chain(__jac.du.data.0.iter_mut());
        for ((__f, __r), __out) in __fs.data.0.iter().zip(__rs.data.0.iter()).zip(__outs) {
            let [#(#fv),*] = *__f;
            #unpack_b
            #solve_u
            #(let #r = #residuals;)*
            #solve_mu
            *__out = [#(#column),*];
        }
    };
    let solve = if k > 0 {
        quote! {
            if #suspect {
                #adopt
            } else {
                #solve_columns
            }
        }
    } else {
        let _ = (suspect, adopt);
        solve_columns
    };
    let tail = quote! {
        let mut __jac = #jacobians_zero;
        #solve
        #finite
    };
    // Nested no deeper than a block (`crate::emit::chunks`).
    let to_multipliers = bounded(gauss.to_multipliers.clone(), &tail);
    quote! {
        #to_multipliers
        #tail
    }
}
