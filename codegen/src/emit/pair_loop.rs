//! `inverse_dynamics_jacobian`'s entries between a joint and the joints
//! beyond it, formed in a loop over a constant table of the pairs
//! (`crate::bodies::derivatives::PairProducts`): each column's and each
//! column beyond's 21 values are bound by the method's straight-line code
//! into two arrays, and the loop adds each pair's four dot products to the
//! matrices. A robot with many pairs spends most of `∂τ`'s straight-line
//! code on them (the G1's 117 pairs, 9,921 of 23,391 operations); in the
//! loop they cost 56 operations each and a loop body's bytes.

use super::body::Body;
use crate::bodies::derivatives::{
    PairProducts, BEYOND_BS, BEYOND_FQ, BEYOND_FR, BEYOND_IS, COLUMN_DA, COLUMN_DR, COLUMN_DV,
    COLUMN_S, PAIR_WIDTH,
};
use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// `Σ a[a0 + j] · b[b0 + j]` for `j < len`, `a` and `b` the arrays'
/// names.
fn dot(a: &TokenStream, a0: usize, b: &TokenStream, b0: usize, len: usize) -> TokenStream {
    let terms = (0..len).map(|j| {
        let (i, k) = (Literal::usize_unsuffixed(a0 + j), Literal::usize_unsuffixed(b0 + j));
        quote!(#a[#i] * #b[#k])
    });
    quote!(#(#terms)+*)
}

/// An array literal of `vectors`, each written by `body`.
fn vectors(body: &Body, vectors: &[[crate::expr::Id; PAIR_WIDTH]]) -> TokenStream {
    let rows = vectors.iter().map(|v| {
        let entries = v.iter().map(|&e| body.expr(e));
        quote!([#(#entries),*])
    });
    quote!([#(#rows),*])
}

/// `value` (the pair of matrices with the joints' own entries) with the
/// pairs' entries added, as one block expression. The table's indices are
/// read with `get`, so nothing in the loop can panic.
pub(super) fn added(body: &Body, pairs: &PairProducts, value: TokenStream) -> TokenStream {
    let (c, w) = (quote!(__c), quote!(__w));
    let by_q_beyond = {
        let a = dot(&w, BEYOND_IS, &c, COLUMN_DA, 6);
        let b = dot(&w, BEYOND_BS, &c, COLUMN_DV, 3);
        quote!(#a + #b)
    };
    let by_rate_beyond = {
        let a = dot(&w, BEYOND_IS, &c, COLUMN_DR, 6);
        let b = dot(&w, BEYOND_BS, &c, COLUMN_S, 3);
        quote!(#a + #b)
    };
    let by_q_joint = dot(&c, COLUMN_S, &w, BEYOND_FQ, 6);
    let by_rate_joint = dot(&c, COLUMN_S, &w, BEYOND_FR, 6);
    let (columns, beyond) = (
        vectors(body, &pairs.columns),
        vectors(body, &pairs.beyond),
    );
    let (nc, nb, np) = (
        Literal::usize_unsuffixed(pairs.columns.len()),
        Literal::usize_unsuffixed(pairs.beyond.len()),
        Literal::usize_unsuffixed(pairs.pairs.len()),
    );
    let width = Literal::usize_unsuffixed(PAIR_WIDTH);
    // Indices as `u16` where they fit (the table's bytes), else `u32`.
    let wide = pairs.pairs.iter().flatten().any(|&x| x > usize::from(u16::MAX));
    let (index, to_usize) = if wide {
        (quote!(u32), quote!(|__x| __x as usize))
    } else {
        (quote!(u16), quote!(usize::from))
    };
    let table = pairs.pairs.iter().map(|p| {
        let p = p.map(Literal::usize_unsuffixed);
        quote!([#(#p),*])
    });
    quote! {{
        let mut __value = #value;
        let __columns: [[T; #width]; #nc] = #columns;
        let __beyond: [[T; #width]; #nb] = #beyond;
        const __PAIRS: [[#index; 4]; #np] = [#(#table),*];
        for __p in __PAIRS {
            let [__ic, __ib, __i, __k] = __p.map(#to_usize);
            let (::core::option::Option::Some(#c), ::core::option::Option::Some(#w)) =
                (__columns.get(__ic), __beyond.get(__ib))
            else {
                continue;
            };
            if let ::core::option::Option::Some(__x) = __value.0.get_mut((__k, __i)) {
                *__x += #by_q_beyond;
            }
            if let ::core::option::Option::Some(__x) = __value.1.get_mut((__k, __i)) {
                *__x += #by_rate_beyond;
            }
            if let ::core::option::Option::Some(__x) = __value.0.get_mut((__i, __k)) {
                *__x += #by_q_joint;
            }
            if let ::core::option::Option::Some(__x) = __value.1.get_mut((__i, __k)) {
                *__x += #by_rate_joint;
            }
        }
        __value
    }}
}
