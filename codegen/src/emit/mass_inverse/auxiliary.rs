//! A positive semi-definite `M`: the runtime solves the auxiliary system.

use crate::emit::context::{Context, Inputs};
use proc_macro2::TokenStream;
use quote::quote;

/// A semi-definite `M`: the runtime's dense solve of the auxiliary system
/// (Cholesky of `M + s AᵀA`, pivoted `LDLᵀ` of `A M⁻¹ Aᵀ`).
pub(in crate::emit) fn solver(ctx: &Context) -> TokenStream {
    let args = ctx.args(Inputs::States);
    let (signature, gauss_dense) = (ctx.gauss_signature(), ctx.private(quote!(gauss_dense)));
    quote! {
        /// `(q̈, Aᵀλ)` of Gauss's principle, shared by `acceleration`,
        /// `constraint_force` and `acceleration_corrected` (`b + correction`),
        /// as `__F` makes it.
        #[inline]
        #signature {
            let __motion = #gauss_dense(self, #args, correction);
            __F::settle(self, #args, correction, __motion)
        }
    }
}
