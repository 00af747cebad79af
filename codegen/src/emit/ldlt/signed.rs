//! The saddle-point matrix's signed pivots.

use super::StructuredLdlt;
use crate::emit::context::Context;
use proc_macro2::TokenStream;
use quote::quote;

impl StructuredLdlt<'_> {
    /// Pivot `j` of the saddle-point matrix and its reciprocal. A
    /// coordinate's must be positive. A multiplier's diagonal entry is zero,
    /// so `−dⱼ = Σ_c uⱼ꜀²·inv꜀`: the coordinate pivots' part `own` (each
    /// term positive), less what the earlier multipliers' (negative) pivots
    /// took back; it must stay above `tol·own` (`tol = 10⁻³`: the test of
    /// `S`'s pivots, `sin²θ`, for the rows eliminated so far, a thousand
    /// times stricter than the rank tolerance, since here a row that fails
    /// it is not dropped but handed to the dense solve with all the others).
    pub(super) fn signed_pivot(
        &self,
        j: usize,
        coordinates: usize,
        bail: &TokenStream,
    ) -> TokenStream {
        let (l, r) = (&self.structure.fill, &self.roles);
        let (dj, inv) = (Context::local(r.pivot, j), Context::local(r.inverse, j));
        // `u·l` (= u²·inv, formed already): one multiplication a term
        // fewer than `S`'s and `M`'s chain-friendly `(u·u)·inv`; a robot's
        // saddle-point matrix is wide, not a chain.
        let term = |c: usize| {
            let (ujc, ljc) = (
                Context::local2(r.update, j, c),
                Context::local2(r.lower, j, c),
            );
            quote!(#ujc * #ljc)
        };
        let is_coordinate = |p: usize| self.structure.order[p] < coordinates;
        if is_coordinate(j) {
            let xjj = self.at(j, j);
            let updates = (0..j).filter(|&c| l[j][c]).map(|c| {
                let t = term(c);
                quote!(- #t)
            });
            // Positive and at most the largest finite value: an infinite
            // pivot's reciprocal 0 would zero its column and leave a finite,
            // wrong answer (the entries are finite, their updates may not be).
            let largest = quote!(::constrained::__private::largest::<T>());
            return quote! {
                let #dj = #xjj #(#updates)*;
                if !(#dj > T::zero() && #dj <= #largest) {
                    #bail
                }
                let #inv = T::one() / #dj;
            };
        }
        let own: Vec<TokenStream> = (0..j)
            .filter(|&c| l[j][c] && is_coordinate(c))
            .map(term)
            .collect();
        let back = (0..j).filter(|&c| l[j][c] && !is_coordinate(c)).map(term);
        let own_name = Context::local("kown", j);
        let own = if own.is_empty() {
            quote!(T::zero())
        } else {
            quote!(#(#own)+*)
        };
        quote! {
            let #own_name = #own;
            let #dj = -#own_name #(- #back)*;
            if !(-#dj > __tol * #own_name) {
                #bail
            }
            let #inv = T::one() / #dj;
        }
    }
}
