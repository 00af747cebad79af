//! Code for the explicit Gibbs–Appell equation (eq. 18 and 37):
//! `gibbs_appell_matrices` and `acceleration_gibbs_appell`.
//!
//! The partition found at compile time (rank `r`, eliminated coordinates)
//! and whether `M` can couple the blocks (eq. 37) or not (eq. 18) become
//! constants of a call into `constrained::gibbs_appell`, which re-pivots at
//! run time where the preferred columns are poorly conditioned.

use super::context::{Context, Inputs};
use crate::equations::partition::Partition;
use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// The two generated methods.
pub(super) fn methods(ctx: &Context, partition: &Partition) -> TokenStream {
    let (eq, n) = (ctx.eq, ctx.n);
    let (nn, k) = (Context::dim(n), Context::dim(ctx.k));
    let (r, i) = (
        Context::dim(partition.rank),
        Context::dim(n - partition.rank),
    );
    let eliminated: Vec<Literal> = partition
        .eliminated
        .iter()
        .map(|&e| Literal::usize_unsuffixed(e))
        .collect();
    let coupled = !eq.mass_inverse.is_diagonal();
    let matrices_doc = matrices_doc(ctx, partition);
    let (params, args) = (ctx.params(Inputs::States), ctx.args(Inputs::States));
    let call = |function: TokenStream| {
        let function = ctx.path(quote!(gibbs_appell::#function));
        quote! {
            let (__a, __b) = self.constraint_matrices(#args);
            #function::<T, #nn, #k, #r, #i>(
                &__a,
                &__b,
                &self.mass_matrix(q, t),
                &self.forces(#args),
                &[#(#eliminated),*],
                #coupled,
            )
        }
    };
    let system = call(quote!(system));
    let acceleration = call(quote!(acceleration));
    let (m, vector) = (ctx.matrix(n, n), ctx.vector(n));
    let system_ret = ctx.result(quote!((#m, #vector)), quote!(GibbsAppellError));
    let acceleration_ret = ctx.result(vector, quote!(GibbsAppellError));
    quote! {
        #[doc = #matrices_doc]
        pub fn gibbs_appell_matrices(&self, #params) -> #system_ret {
            #system
        }

        /// `q̈` from the explicit Gibbs–Appell system (see
        /// [`gibbs_appell_matrices`](Self::gibbs_appell_matrices)); equal to
        /// [`acceleration`](Self::acceleration) wherever both are defined.
        pub fn acceleration_gibbs_appell(&self, #params) -> #acceleration_ret {
            #acceleration
        }
    }
}

/// The doc of `gibbs_appell_matrices`: the equation, its rows and the
/// eliminated coordinates chosen at compile time.
fn matrices_doc(ctx: &Context, partition: &Partition) -> String {
    let (eq, n) = (ctx.eq, ctx.n);
    let coupled = !eq.mass_inverse.is_diagonal();
    let names: Vec<String> = partition
        .eliminated
        .iter()
        .map(|&e| format!("`{}`", eq.system.coordinates[e]))
        .collect();
    let equation = if coupled { "eq. 37" } else { "eq. 18" };
    format!(
        " The explicit Gibbs–Appell system ({equation}) as `(S, s)` with `S q̈ = s`, \
         {n} × {n}, columns in the original coordinate order: {r} independent rows of \
         `A q̈ = b`, then the {} rows of eq. {}. The eliminated accelerations are those of \
         {} (chosen at compile time, rank {r}); where their columns of `A` are poorly \
         conditioned the partition is re-chosen at run time. `Err(RankDeficient)` where \
         `A` itself drops below rank {r}.",
        n - partition.rank,
        if coupled { "35" } else { "13" },
        if names.is_empty() {
            "no coordinate".to_string()
        } else {
            names.join(", ")
        },
        r = partition.rank,
    )
}
