//! Whether the fast solve's rank decision of `S` must be verified at run
//! time (`constrained::rank`): the expression the generated code tests.

use super::StructuredLdlt;
use crate::emit::context::Context;
use proc_macro2::TokenStream;
use quote::quote;

impl StructuredLdlt<'_> {
    /// Whether the fast solve's rank decision must be verified, as a `bool`
    /// expression: fewer than `rank` rows kept, counting a row as dropped
    /// where its pivot was (`inv = 0`, which NaN and ∞ in `S` also give)
    /// or where its diagonal entry of `S` is so small that underflow may
    /// have spoilt it (`safe_minimum`). For k = 1 the solve divides by any
    /// positive `S`, so an infinite `S` (above `largest`) counts as dropped
    /// too.
    pub(in crate::emit) fn suspect(&self, rank: usize) -> TokenStream {
        let safe = quote!(::constrained::__private::safe_minimum::<T>());
        let k = self.k();
        if k == 1 {
            let s = self.at(0, 0);
            // `s ≤ largest` rather than `is_finite`: one floating-point
            // comparison, no move to an integer register.
            let largest = quote!(::constrained::__private::largest::<T>());
            return quote!(!(#s > #safe && #s <= #largest));
        }
        let dropped = |j: usize| {
            let (inv, sjj) = (Context::local(self.roles.inverse, j), self.at(j, j));
            quote!(((#inv == T::zero()) | (#sjj < #safe)))
        };
        if rank == k {
            // Any drop at all: a branch-free OR (`|`, not `||`: one branch,
            // not one per pivot), cheaper than a count.
            let any = (0..k).map(dropped);
            return quote!(#(#any)|*);
        }
        let r = Context::dim(rank);
        let kept = (0..k).map(|j| {
            let dropped = dropped(j);
            quote!(usize::from(!#dropped))
        });
        // A redundant set keeping a nearly dependent row is verified too
        // (`constrained::rank::conditioning_tolerance`): `inv ≠ 0` and
        // `dⱼ < tol·Sⱼⱼ`. A pivot nothing updated is its diagonal entry,
        // `sin²θ = 1`, and never weak.
        let fill = &self.structure.fill;
        let weak: Vec<TokenStream> = (0..k)
            .filter(|&j| (0..j).any(|c| fill[j][c]))
            .map(|j| {
                let (dj, inv, sjj) = (
                    Context::local(self.roles.pivot, j),
                    Context::local(self.roles.inverse, j),
                    self.at(j, j),
                );
                quote!(((#dj < __conditioned * #sjj) & (#inv != T::zero())))
            })
            .collect();
        if weak.is_empty() {
            return quote!((#(#kept)+*) < #r);
        }
        let tolerance = quote!(::constrained::__private::conditioning_tolerance::<T>());
        quote!({
            let __conditioned: T = #tolerance;
            ((#(#kept)+*) < #r) #(| #weak)*
        })
    }
}
