//! `gauss` through the saddle-point system
//! (`crate::equations::saddle_point`): `[M Aᵀ; A 0] [q̈; μ] = [F; b]`,
//! `λ = −μ`, factored once as `L D Lᵀ` in the compile-time order over its
//! pattern, then solved once. `M` and `F` are the auxiliary ones for a
//! semi-definite `M` (their added terms vanish where `A q̈ = b`, so `q̈`
//! and `λ` are the actual system's). Every row is kept, so no rank
//! decision is taken: a pivot that fails its test hands the solve to the
//! runtime's dense one, which takes it.
//!
//! The fallback is the runtime's dense solve, several times slower than
//! the fast path, rather than a generated range-space solve: generated
//! beside this one it would lengthen every build by almost a third, and in the
//! same function it would keep the inputs alive past the attempt and slow
//! the fast path. A leg stretched straight, where the pivot fails, is the
//! edge of the robot's workspace, not where it walks.

use super::auxiliary;
use super::{a_entry, forces_rhs, inputs};
use crate::emit::chunks::bounded;
use crate::emit::context::Context;
use crate::emit::ldlt::{Solves, StructuredLdlt};
use crate::emit::solve::{checked_motion, corrected};
use crate::emit::tokens::concat;
use crate::equations::mass_inverse::Factored;
use crate::equations::strategy::Strategy;
use crate::numeric::sparsity::Structure;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The function `gauss`.
pub(super) fn solver(ctx: &Context, f: &Factored, saddle: &Structure) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let dense = auxiliary::dense_answer(ctx);
    // `M`'s locals are named as for its own factorization (none runs).
    let mass = StructuredLdlt::mass(&f.mass, dense.clone(), Solves::Many);
    let bail = |error: TokenStream| ctx.gauss_error(error);
    let head = inputs(ctx, f, &mass, (true, &[]), (true, &bail));
    let b: Vec<Ident> = (0..k).map(|r| Context::local("b", r)).collect();
    let prelude = match &f.auxiliary {
        Some(_) => auxiliary::prelude(ctx, f, &mass, true, true),
        None => corrected(&b, &[]),
    };
    let ldlt = StructuredLdlt::saddle(saddle, n, dense);
    let entries = entries(ctx, saddle, &mass, &ldlt);
    let factor = ldlt.factor();
    let mut rhs = forces_rhs(ctx, f);
    rhs.extend(b.iter().map(|name| Some(quote!(#name))));
    let (solve, values) = solved(&ldlt, &rhs, (n, k));
    let acceleration: Vec<TokenStream> = values[..n].iter().map(or_zero).collect();
    let body = concat([head, prelude, entries, factor, solve]);
    function(
        ctx,
        (acceleration, &values[n..]),
        body,
        Strategy::Saddle.describe(),
    )
}

/// The function `gauss` from the code `body` that computes `q̈`'s entries
/// `acceleration` and each row's `μ` (`None` where structurally zero):
/// `Fᶜ = Aᵀλ = −Aᵀμ` with the model's `A`, `λ = −μ`, checked as every
/// solve's motion is; `how` ends its documentation.
pub(super) fn function(
    ctx: &Context,
    (acceleration, mu): (Vec<TokenStream>, &[Option<TokenStream>]),
    body: TokenStream,
    how: &str,
) -> TokenStream {
    let acc = ctx.vector_value(acceleration);
    let force = ctx.vector_value(constraint_force(ctx, mu));
    let lambda: Vec<TokenStream> = mu
        .iter()
        .map(|m| {
            let m = or_zero(m);
            quote!(-#m)
        })
        .collect();
    let value = checked_motion(ctx, None, (&acc, &force), &lambda, None, None, None);
    let body = bounded(body, &value);
    let signature = ctx.gauss_signature();
    let doc = format!(
        " `(q̈, Aᵀλ)` of Gauss's principle, shared by `acceleration`,\n \
         `constraint_force` and `acceleration_corrected` (`b + correction`),\n \
         as `__F` makes it; {how}"
    );
    quote! {
        #[doc = #doc]
        #[inline(always)]
        #signature {
            #body
            #value
        }
    }
}

/// The solve of the saddle-point system for `rhs` into `__kq{i}` (its
/// `n` coordinates) and `__mu{r}` (its `k` rows): the code, and each
/// unknown's local by position (`None` where structurally zero).
pub(super) fn solved(
    ldlt: &StructuredLdlt,
    rhs: &[Option<TokenStream>],
    (n, k): (usize, usize),
) -> (TokenStream, Vec<Option<TokenStream>>) {
    let out: Vec<Ident> = (0..n)
        .map(|i| Context::local("kq", i))
        .chain((0..k).map(|r| Context::local("mu", r)))
        .collect();
    let (solve, bound) = ldlt.solve_sparse(rhs, "ky", &out);
    let values = out
        .iter()
        .zip(bound)
        .map(|(name, bound)| bound.then(|| quote!(#name)))
        .collect();
    (solve, values)
}

/// A solved value, `T::zero()` where structurally zero.
pub(super) fn or_zero(value: &Option<TokenStream>) -> TokenStream {
    value.clone().unwrap_or_else(|| quote!(T::zero()))
}

/// `Fᶜ = Aᵀλ = −Aᵀμ` with the model's `A` (locals `__a{r}_{i}`), one
/// expression per coordinate, from each row's `μ`.
pub(super) fn constraint_force<'a>(
    ctx: &'a Context,
    mu: &'a [Option<TokenStream>],
) -> impl Iterator<Item = TokenStream> + 'a {
    let g = &ctx.eq.system.graph;
    (0..ctx.n).map(move |i| {
        let terms: Vec<TokenStream> = (0..ctx.k)
            .filter(|&r| !g.is_zero(ctx.eq.a[r][i]))
            .filter_map(|r| {
                let (a, m) = (a_entry(r, i), mu[r].as_ref()?);
                Some(quote!(#a * #m))
            })
            .collect();
        if terms.is_empty() {
            quote!(T::zero())
        } else {
            quote!(-(#(#terms)+*))
        }
    })
}

/// The saddle-point matrix's entries `__k{i}_{j}` (lower triangle, its
/// structural nonzeros): `M`'s locals, and `A`'s below them.
fn entries(
    ctx: &Context,
    saddle: &Structure,
    mass: &StructuredLdlt,
    ldlt: &StructuredLdlt,
) -> TokenStream {
    let n = ctx.n;
    let mut out = TokenStream::new();
    for i in 0..saddle.len() {
        for j in 0..=i {
            if !saddle.nonzero[i][j] {
                continue;
            }
            let value = if i < n {
                let m = mass.entry(i, j);
                quote!(#m)
            } else if j < n {
                a_entry(i - n, j)
            } else {
                continue;
            };
            let name = ldlt.entry(i, j);
            out.extend(quote! { let #name = #value; });
        }
    }
    out
}
