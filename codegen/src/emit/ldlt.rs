//! `S λ = r` by `P S Pᵀ = L D Lᵀ` in the compile-time elimination order over
//! the compile-time pattern (fill included), emitted as two steps: the
//! factorization of `S` (once), then a solve for a right-hand side (as often
//! as there are right-hand sides), each with its own names.
//!
//! Only structural nonzeros are touched, so a chain's tridiagonal `S` costs
//! O(k). A pivot whose `sin²θ = dⱼ / Sⱼⱼ` is below `rank_tolerance` is
//! dropped (`D⁺`), which removes its constraint; for k = 1 this is the scalar
//! closed form `λ = r / S` with `λ = 0` where `S = 0`. A drop the model's
//! redundancy does not explain is flagged ([`StructuredLdlt::suspect`]) and
//! verified at run time (`constrained::rank`).

use super::context::Context;
use crate::expr::Graph;
use crate::motion::Symbolic;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The factorization of `S = A M⁻¹ Aᵀ`, whose entries are the locals
/// `__s{i}_{j}` (i ≥ j, structural nonzeros only).
pub(super) struct StructuredLdlt<'a> {
    graph: &'a Graph,
    d: &'a Symbolic,
}

impl<'a> StructuredLdlt<'a> {
    pub(super) fn new(graph: &'a Graph, d: &'a Symbolic) -> Self {
        StructuredLdlt { graph, d }
    }

    /// The local holding `S[i][j]`.
    pub(super) fn entry(i: usize, j: usize) -> Ident {
        Context::local2("s", i.max(j), i.min(j))
    }

    fn k(&self) -> usize {
        self.d.gram.len()
    }

    /// `S` at positions `p`, `q` of the elimination order.
    fn s(&self, p: usize, q: usize) -> TokenStream {
        let (i, j) = (self.d.order[p], self.d.order[q]);
        if self.graph.is_zero(self.d.gram[i][j]) {
            quote!(T::zero())
        } else {
            let name = Self::entry(i, j);
            quote!(#name)
        }
    }

    /// The factor step: pivots `__d{j}`, their guarded reciprocals
    /// `__inv{j}`, the Schur-updated entries `__u{i}_{j}` and the unit lower
    /// factor `__l{i}_{j}`, all by position in the elimination order.
    ///
    /// With u the Schur-updated (unscaled) entries and l = u·inv:
    ///   dⱼ = Sⱼⱼ − Σ_c (u_jc·u_jc)·inv_c,  u_ij = S_ij − Σ_c u_ic·l_jc,  l_ij = u_ij·inv_j.
    /// (u·u)·inv equals l·l·d (inv·d = 1 for a kept pivot, both 0 for a
    /// dropped one) but leaves one multiplication, not three, between a
    /// pivot's reciprocal and the next division: the recurrence is the
    /// critical path of a chain, so this is what its cost per link is made of.
    pub(super) fn factor(&self) -> TokenStream {
        let k = self.k();
        if k < 2 {
            return TokenStream::new(); // k = 1 divides by S itself in `solve`
        }
        let l = &self.d.fill;
        let rank_tolerance = quote!(::constrained::inverse::rank_tolerance::<T>());
        let mut out = quote! { let __tol: T = #rank_tolerance; };
        for j in 0..k {
            let (dj, inv, sjj) = (
                Context::local("d", j),
                Context::local("inv", j),
                self.s(j, j),
            );
            let updates = (0..j).filter(|&c| l[j][c]).map(|c| {
                let (ujc, invc) = (Context::local2("u", j, c), Context::local("inv", c));
                quote!(- (#ujc * #ujc) * #invc)
            });
            out.extend(quote! {
                let #dj = #sjj #(#updates)*;
                let #inv = if #dj > __tol * #sjj { T::one() / #dj } else { T::zero() };
            });
            for i in j + 1..k {
                if !l[i][j] {
                    continue;
                }
                let (lij, uij, sij) = (
                    Context::local2("l", i, j),
                    Context::local2("u", i, j),
                    self.s(i, j),
                );
                let updates = (0..j).filter(|&c| l[i][c] && l[j][c]).map(|c| {
                    let (uic, ljc) = (Context::local2("u", i, c), Context::local2("l", j, c));
                    quote!(- #uic * #ljc)
                });
                out.extend(quote! {
                    let #uij = #sij #(#updates)*;
                    let #lij = #uij * #inv;
                });
            }
        }
        out
    }

    /// Whether the fast solve's rank decision must be verified, as a `bool`
    /// expression: fewer than `rank` rows kept, counting a row as dropped
    /// where its pivot was (`inv = 0`, which NaN and ∞ in `S` also give)
    /// or where its diagonal entry of `S` is so small that underflow may
    /// have spoilt it (`safe_minimum`). For k = 1 the solve divides by any
    /// positive `S`, so an infinite `S` counts as dropped too.
    pub(super) fn suspect(&self, rank: usize) -> TokenStream {
        let safe = quote!(::constrained::__private::safe_minimum::<T>());
        let k = self.k();
        if k == 1 {
            let s = self.s(0, 0);
            return quote!(!(#s > #safe && #s.is_finite()));
        }
        let dropped = |j: usize| {
            let (inv, sjj) = (Context::local("inv", j), self.s(j, j));
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
        quote!((#(#kept)+*) < #r)
    }

    /// The solve step for the right-hand side `rhs` (one local per
    /// constraint, in constraint order): forward substitution into
    /// `__{y}{i}`, then back substitution into `out` (one local per
    /// constraint). `y` names the intermediate locals, so that several
    /// solves can follow one factorization.
    pub(super) fn solve(&self, rhs: &[Ident], y: &str, out: &[Ident]) -> TokenStream {
        let k = self.k();
        if k == 0 {
            return TokenStream::new();
        }
        if k == 1 {
            // `S` may be structurally zero (a row of `A` that simplifies to
            // 0): then the literal zero, and λ = 0.
            let (lam, r, s) = (&out[0], &rhs[0], self.s(0, 0));
            return quote! {
                let #lam = if #s > T::zero() { #r / #s } else { T::zero() };
            };
        }
        let (l, o) = (&self.d.fill, &self.d.order);
        let mut code = TokenStream::new();
        for i in 0..k {
            let (yi, r) = (Context::local(y, i), &rhs[o[i]]);
            let updates = (0..i).filter(|&c| l[i][c]).map(|c| {
                let (lic, yc) = (Context::local2("l", i, c), Context::local(y, c));
                quote!(- #lic * #yc)
            });
            code.extend(quote! { let #yi = #r #(#updates)*; });
        }
        for i in (0..k).rev() {
            let (lam, yi, inv) = (&out[o[i]], Context::local(y, i), Context::local("inv", i));
            let updates = (i + 1..k).filter(|&c| l[c][i]).map(|c| {
                let (lci, lamc) = (Context::local2("l", c, i), &out[o[c]]);
                quote!(- #lci * #lamc)
            });
            code.extend(quote! { let #lam = #yi * #inv #(#updates)*; });
        }
        code
    }
}
