//! `M⁻¹` formed from the factors (Takahashi's recurrence), for the
//! Jacobian's columns where that is cheaper than solving for them.

use super::StructuredLdlt;
use crate::emit::context::Context;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

impl StructuredLdlt<'_> {
    /// The inverse `X = M⁻¹` by Takahashi's recurrence over the factors,
    /// from the last position to the first: `Lᵀ X = D⁻¹ L⁻¹`, whose right
    /// side is zero above the diagonal, gives for `m ≥ j`
    /// `Xⱼₘ = δⱼₘ / dⱼ − Σ_{c > j} L_cj X_cm` (`X` symmetric), each entry
    /// from entries already formed. Entries between rows of different
    /// blocks are zero and skipped. Returns the code (locals `__{name}{a}_{b}`
    /// by position) and, in natural order, each entry's local (`None`:
    /// structurally zero), the same for `(a, b)` and `(b, a)`.
    pub(in crate::emit) fn inverse(&self, name: &str) -> (TokenStream, Vec<Vec<Option<Ident>>>) {
        let k = self.k();
        let (l, o) = (&self.structure.fill, &self.structure.order);
        let blocks = self.blocks();
        let mut x: Vec<Vec<Option<Ident>>> = vec![vec![None; k]; k];
        let mut code = TokenStream::new();
        for j in (0..k).rev() {
            let below: Vec<usize> = (j + 1..k).filter(|&c| l[c][j]).collect();
            for m in (j..k).rev().filter(|&m| blocks[o[m]] == blocks[o[j]]) {
                let updates: Vec<TokenStream> = below
                    .iter()
                    .filter_map(|&c| {
                        let xcm = x[c.max(m)][c.min(m)].as_ref()?;
                        let lcj = Context::local2(self.roles.lower, c, j);
                        Some(quote!(#lcj * #xcm))
                    })
                    .collect();
                let value = if m == j {
                    let own = if self.reciprocal(j) {
                        let inv = Context::local(self.roles.inverse, j);
                        quote!(#inv)
                    } else {
                        let d = Context::local(self.roles.pivot, j);
                        quote!(T::one() / #d)
                    };
                    quote!(#own #(- #updates)*)
                } else if let Some((first, rest)) = updates.split_first() {
                    quote!(-(#first) #(- #rest)*)
                } else {
                    continue;
                };
                let local = Context::local2(name, m, j);
                code.extend(quote! { let #local = #value; });
                x[m][j] = Some(local);
            }
        }
        let mut natural: Vec<Vec<Option<Ident>>> = vec![vec![None; k]; k];
        for a in 0..k {
            for b in 0..=a {
                natural[o[a]][o[b]].clone_from(&x[a][b]);
                natural[o[b]][o[a]].clone_from(&x[a][b]);
            }
        }
        (code, natural)
    }

    /// The multiplications of [`inverse`](Self::inverse) and of a solve
    /// for a unit right-hand side in natural row `row`
    /// ([`solve_sparse`](Self::solve_sparse)), by the same rules: which
    /// is cheaper for a given set of unit columns.
    pub(in crate::emit) fn inverse_and_unit_solve_costs(&self, rows: &[usize]) -> (usize, usize) {
        let k = self.k();
        let (l, o) = (&self.structure.fill, &self.structure.order);
        let blocks = self.blocks();
        let mut inverse = 0;
        for j in 0..k {
            let below = (j + 1..k).filter(|&c| l[c][j]).count();
            let same = (j..k).filter(|&m| blocks[o[m]] == blocks[o[j]]).count();
            inverse += below * same + 1;
        }
        let mut solves = 0;
        for &row in rows {
            let start = o.iter().position(|&r| r == row).unwrap_or(0);
            let mut reached = vec![false; k];
            reached[start] = true;
            for i in start + 1..k {
                let updates = (start..i).filter(|&c| l[i][c] && reached[c]).count();
                reached[i] = updates > 0;
                solves += updates;
            }
            let bound = reached.iter().filter(|&&r| r).count();
            // Back substitution: every reached position, and every
            // position a reached one below it updates.
            let block = |i: usize| blocks[o[i]] == blocks[row];
            let updates: usize = (0..k)
                .filter(|&i| block(i))
                .map(|i| (i + 1..k).filter(|&c| l[c][i]).count())
                .sum();
            solves += bound + updates;
        }
        (inverse, solves)
    }
}
