//! A redundant set's minimum-norm `λ` from the factors of `S`
//! ([`StructuredLdlt::minimum_norm`]; docs/math.md, "The multipliers of a
//! redundant set").

use super::{Pivots, Roles, Solves, StructuredLdlt};
use crate::emit::context::Context;
use crate::numeric::sparsity::Structure;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

impl StructuredLdlt<'_> {
    /// The minimum-norm solution of `S λ = r` from the solve's `lam` (`S`'s {1}-inverse,
    /// this factorization with its dropped pivots): `lam` less its part in
    /// the null space of `S`. Each dropped pivot `p` gives a null vector
    /// `nₚ = Pᵀ L⁻ᵀ eₚ` (`S nₚ = Pᵀ L D eₚ = 0`), and they span it; written
    /// for every pivot scaled by its flag `dropped`, so that which ones were
    /// dropped is read at run time, `λ = lam − N y` with
    /// `(NᵀN + diag(kept)) y = Nᵀ lam`, a positive definite system (a
    /// dropped `nₚ` is 1 at `p` and 0 beyond it, a kept one is zero). Where
    /// `S`'s rows are the constraints', `null(S) = null(Aᵀ)`, so this is the
    /// minimum-norm `λ` of `Aᵀλ = Fᶜ`, written to the locals `__nl{j}`
    /// where it reproduces the solve's force ([`reproduces_force`]).
    /// Where the rows were scaled (`λ` is
    /// `D lam`), the norm is `D`'s: `weight` holds `dᵢ²` by row (`None`,
    /// or past its end, 1), and `NᵀWN`, `NᵀW lam` replace `NᵀN`, `Nᵀ lam`.
    /// Returns the code and each row's value (natural order), for the
    /// caller to write; a pivot of that system that is not positive (only
    /// NaN can make one) returns `None` from the enclosing closure.
    pub(in crate::emit) fn minimum_norm(
        &self,
        lam: &[Ident],
        weight: &[Option<TokenStream>],
        rows: &Rows,
    ) -> (TokenStream, Vec<TokenStream>) {
        let k = self.k();
        if k <= 1 || self.scalar_gram() {
            // λ = r / S, or 0 where S = 0: already the least norm.
            return (TokenStream::new(), lam.iter().map(|l| quote!(#l)).collect());
        }
        let o = &self.structure.order;
        let mut code = TokenStream::new();
        // `wᵢ ·` at position `i`, where row `o[i]` is weighted.
        let weighted = |i: usize| weight.get(o[i]).cloned().flatten().map(|w| quote!(#w *));
        let (vectors, reach) = self.null_vectors();
        code.extend(vectors);
        let reach = &reach;
        let structure = Structure::new(overlaps(reach));
        let system = StructuredLdlt {
            structure: &structure,
            roles: Roles {
                entry: "ng",
                pivot: "ngd",
                inverse: "ngi",
                update: "ngu",
                lower: "ngl",
            },
            pivots: Pivots::Positive(quote!(return ::core::option::Option::None;)),
            solves: Solves::Once,
        };
        code.extend(normal_entries(&system, reach, &weighted));
        code.extend(system.factor());
        // `Nᵀ lam`, by position.
        let rhs: Vec<Ident> = (0..k).map(|p| Context::local("nh", p)).collect();
        for (p, h) in rhs.iter().enumerate() {
            let products = (0..k).filter(|&i| reach[p][i]).map(|i| {
                let (n, x, w) = (null(p, i), &lam[o[i]], weighted(i));
                quote!(#w #n * #x)
            });
            code.extend(quote! { let #h = #(#products)+*; });
        }
        let y: Vec<Ident> = (0..k).map(|p| Context::local("ny", p)).collect();
        code.extend(system.solve(&rhs, "nz", &y));
        let mut out: Vec<TokenStream> = vec![TokenStream::new(); k];
        for i in 0..k {
            let x = &lam[o[i]];
            let corrections = (0..k).filter(|&p| reach[p][i]).map(|p| {
                let (yp, n) = (&y[p], null(p, i));
                quote!(- #yp * #n)
            });
            let name = Context::local("nl", o[i]);
            code.extend(quote! { let #name = #x #(#corrections)*; });
            out[o[i]] = quote!(#name);
        }
        code.extend(reproduces_force(rows, lam));
        (code, out)
    }

    /// Every pivot's null vector `nₚ = dropped · L⁻ᵀ eₚ` (by position) into
    /// the locals `__nv{p}_{q}`, each pivot's flag into `__nk{p}` (1 where
    /// it was dropped, `inv = 0`); returns the code and where each can be
    /// nonzero (`reach[p][q]`, entry `q` of `nₚ`).
    fn null_vectors(&self) -> (TokenStream, Vec<Vec<bool>>) {
        let k = self.k();
        let l = &self.structure.fill;
        let mut code = TokenStream::new();
        let mut reach = vec![vec![false; k]; k];
        for (p, reach) in reach.iter_mut().enumerate() {
            let (inv, flag, npp) = (
                Context::local(self.roles.inverse, p),
                Context::local("nk", p),
                null(p, p),
            );
            code.extend(quote! {
                let #flag = if #inv == T::zero() { T::one() } else { T::zero() };
                let #npp = #flag;
            });
            reach[p] = true;
            // Lᵀ nₚ = eₚ, by back substitution from p.
            for q in (0..p).rev() {
                let terms: Vec<TokenStream> = (q + 1..=p)
                    .filter(|&c| l[c][q] && reach[c])
                    .map(|c| {
                        let (lcq, nc) = (Context::local2(self.roles.lower, c, q), null(p, c));
                        quote!(#lcq * #nc)
                    })
                    .collect();
                if terms.is_empty() {
                    continue;
                }
                reach[q] = true;
                let nq = null(p, q);
                code.extend(quote! { let #nq = -(#(#terms)+*); });
            }
        }
        (code, reach)
    }
}

/// Where the null vectors `p` and `q` can both be nonzero (`reach`): the
/// pattern of `NᵀN`.
fn overlaps(reach: &[Vec<bool>]) -> Vec<Vec<bool>> {
    let k = reach.len();
    (0..k)
        .map(|p| {
            (0..k)
                .map(|q| (0..k).any(|i| reach[p][i] && reach[q][i]))
                .collect()
        })
        .collect()
}

/// The entries of `NᵀWN + diag(kept)` (by position, `weighted(i)` the
/// factor `wᵢ ·` of position `i`, if any) as `system`'s locals.
fn normal_entries(
    system: &StructuredLdlt,
    reach: &[Vec<bool>],
    weighted: &dyn Fn(usize) -> Option<TokenStream>,
) -> TokenStream {
    let k = reach.len();
    let mut code = TokenStream::new();
    for p in 0..k {
        for q in (0..=p).filter(|&q| system.structure.nonzero[p][q]) {
            let products = (0..k).filter(|&i| reach[p][i] && reach[q][i]).map(|i| {
                let (a, b, w) = (null(p, i), null(q, i), weighted(i));
                quote!(#w #a * #b)
            });
            let kept = (p == q).then(|| {
                let flag = Context::local("nk", p);
                quote!(+ (T::one() - #flag))
            });
            let entry = system.entry(p, q);
            code.extend(quote! { let #entry = #(#products)+* #kept; });
        }
    }
    code
}

/// The local holding entry `q` (a position) of pivot `p`'s null vector.
fn null(p: usize, q: usize) -> Ident {
    Context::local2("nv", p, q)
}

/// The rows of `A` the solve's `λ` multiplies, for [`reproduces_force`].
pub(in crate::emit) struct Rows<'r> {
    /// `n`.
    pub coordinates: usize,
    /// Entry `(r, i)` of the rows the solve's `λ` multiplies (scaled, where
    /// it scaled them), `None` where structurally zero.
    pub entry: &'r dyn Fn(usize, usize) -> Option<TokenStream>,
}

/// `return None` unless the minimum-norm `λ` (`__nl{j}`) gives the solve's
/// force `Aᵀ lam` to `√ε` of its largest term: `maxᵢ |Σᵣ aᵣᵢ (λᵣ − lamᵣ)| ≤
/// √ε maxᵢ Σᵣ |aᵣᵢ lamᵣ|` (`half_precision`). A row the rank rule's loose
/// cutoff dropped while only nearly dependent has a unique `λ`, and a
/// direction that is not quite null changes the force by about the row's
/// angle: the runtime answers there.
fn reproduces_force(rows: &Rows, lam: &[Ident]) -> TokenStream {
    let k = lam.len();
    let mut code = TokenStream::new();
    let (mut change, mut size) = (Vec::new(), Vec::new());
    for i in 0..rows.coordinates {
        let entries: Vec<(usize, TokenStream)> = (0..k)
            .filter_map(|r| (rows.entry)(r, i).map(|a| (r, a)))
            .collect();
        if entries.is_empty() {
            continue;
        }
        let moved = entries.iter().map(|(r, a)| {
            let (after, before) = (Context::local("nl", *r), &lam[*r]);
            quote!((#a) * (#after - #before))
        });
        let terms = entries.iter().map(|(r, a)| {
            let before = &lam[*r];
            quote!(((#a) * #before).abs())
        });
        let (dc, ds) = (Context::local("ndf", i), Context::local("nds", i));
        code.extend(quote! {
            let #dc = (#(#moved)+*).abs();
            let #ds = #(#terms)+*;
        });
        change.push(dc);
        size.push(ds);
    }
    let (Some((first_change, changes)), Some((first_size, sizes))) =
        (change.split_first(), size.split_first())
    else {
        return code;
    };
    code.extend(quote! {
        let __nmoved = #first_change #(.max(#changes))*;
        let __nforce = #first_size #(.max(#sizes))*;
        if !(__nmoved <= ::constrained::__private::half_precision::<T>() * __nforce) {
            return ::core::option::Option::None;
        }
    });
    code
}
