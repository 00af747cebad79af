//! Code for the explicit Gibbs–Appell equation (eq. 18 and 37):
//! `gibbs_appell_matrices` and `acceleration_gibbs_appell`.
//!
//! The partition found at compile time (rank `r`, eliminated coordinates)
//! and whether `M` can couple the blocks (eq. 37) or not (eq. 18) become
//! constants of a call into `constrained::gibbs_appell`, which re-pivots at
//! run time where the preferred columns are poorly conditioned.

use super::dim;
use crate::derive::Equations;
use crate::partition::Partition;
use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// The two generated methods.
pub(super) fn methods(eq: &Equations, partition: &Partition) -> TokenStream {
    let n = eq.system.dof();
    let (nn, k) = (dim(n), dim(eq.a.len()));
    let (r, i) = (dim(partition.rank), dim(n - partition.rank));
    let eliminated: Vec<Literal> = partition
        .eliminated
        .iter()
        .map(|&e| Literal::usize_unsuffixed(e))
        .collect();
    let coupled = !eq.gauss.is_diagonal();
    let names: Vec<String> = partition
        .eliminated
        .iter()
        .map(|&e| format!("`{}`", eq.system.coordinates[e]))
        .collect();
    let equation = if coupled { "eq. 37" } else { "eq. 18" };
    let matrices_doc = format!(
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
    );
    let args = quote! {
        q: &::constrained::nalgebra::SVector<T, #nn>,
        qd: &::constrained::nalgebra::SVector<T, #nn>,
        t: T
    };
    let call = |function: TokenStream| {
        quote! {
            let (__a, __b) = self.constraint_matrices(q, qd, t);
            ::constrained::gibbs_appell::#function::<T, #nn, #k, #r, #i>(
                &__a,
                &__b,
                &self.mass_matrix(q, t),
                &self.forces(q, qd, t),
                &[#(#eliminated),*],
                #coupled,
            )
        }
    };
    let system = call(quote!(system));
    let acceleration = call(quote!(acceleration));
    quote! {
        #[doc = #matrices_doc]
        pub fn gibbs_appell_matrices(&self, #args) -> ::core::result::Result<
            (
                ::constrained::nalgebra::SMatrix<T, #nn, #nn>,
                ::constrained::nalgebra::SVector<T, #nn>,
            ),
            ::constrained::GibbsAppellError,
        > {
            #system
        }

        /// `q̈` from the explicit Gibbs–Appell system (see
        /// [`gibbs_appell_matrices`](Self::gibbs_appell_matrices)); equal to
        /// [`acceleration`](Self::acceleration) wherever both are defined.
        pub fn acceleration_gibbs_appell(&self, #args) -> ::core::result::Result<
            ::constrained::nalgebra::SVector<T, #nn>,
            ::constrained::GibbsAppellError,
        > {
            #acceleration
        }
    }
}
