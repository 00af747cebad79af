//! `gauss` in the quaternions' velocity coordinates
//! (`crate::equations::velocity`): `TᵀMT`, `TᵀF`, `A T` and `b` bound by one
//! CSE'd body; each quaternion's `α = b_norm / (A T)_{norm,α}`; the other
//! rows' `b` less their `α` terms; the saddle-point `L D Lᵀ` of the rest in
//! its compile-time order (signed pivots; one that fails its test hands the
//! solve to the runtime's dense one, as in [`super::saddle`]), or, for a
//! floating base standing on legs, each leg through its foot's rows and the
//! base's 6 × 6 inertia with the feet held ([`super::legs`]); then
//! `q̈ = T z` and the norms' multipliers. A body held at three or more
//! points is solved through its own six rows, whose `b` (and correction)
//! come from its points' and whose `μ` give its points' least `λ`
//! (`crate::equations::held`). `Aᵀλ` is formed with the model's `A`, so
//! every output is in the model's coordinates.

use super::saddle::{function, or_zero, solved};
use super::{auxiliary, bind};
use crate::bodies::free::G_PATTERN;
use crate::emit::context::Context;
use crate::emit::demand::interleaved;
use crate::emit::ldlt::StructuredLdlt;
use crate::emit::literal::literal;
use crate::emit::solve::{corrected, correction_locals};
use crate::emit::tokens::concat;
use crate::equations::held::HeldRows;
use crate::equations::in_base::InBaseRows;
use crate::equations::legs::Legs;
use crate::equations::strategy::Strategy;
use crate::equations::velocity::Velocity;
use crate::expr::num::Num;
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The function `gauss`.
pub(super) fn solver(ctx: &Context, v: &Velocity, legs: Option<&Legs>) -> TokenStream {
    let dense = auxiliary::dense_answer(ctx);
    let bail = |error: TokenStream| ctx.gauss_error(error);
    let solved = solve(ctx, v, legs, &dense, &bail);
    function(
        ctx,
        (solved.acceleration, &solved.mu),
        solved.code,
        solved.how,
    )
}

/// The velocity form solved for `gauss`'s right-hand side: the code, and
/// what it leaves bound.
pub(super) struct Solved<'a> {
    /// From the expressions to `q̈` and `μ`.
    pub code: TokenStream,
    /// `q̈`'s entries, in the model's coordinates.
    pub acceleration: Vec<TokenStream>,
    /// Each row's `μ` (`λ = −μ`), `None` where structurally zero.
    pub mu: Vec<Option<TokenStream>>,
    /// The strategy's sentence.
    pub how: &'static str,
    /// The saddle-point `L D Lᵀ` it factored (the legs' own where `legs`).
    pub ldlt: StructuredLdlt<'a>,
}

/// The velocity form's solve, every check handing the answer to `dense`
/// (non-finite inputs to `bail`): `gauss`'s body, and the factors the
/// tangent systems' columns are solved through
/// (`super::velocity_jacobian`). Reads `correction`.
pub(super) fn solve<'a>(
    ctx: &Context,
    v: &'a Velocity,
    legs: Option<&Legs>,
    dense: &TokenStream,
    bail: &dyn Fn(TokenStream) -> TokenStream,
) -> Solved<'a> {
    let ldlt = StructuredLdlt::saddle(&v.structure, v.coordinates.len(), dense.clone());
    let (named, checked) = named(ctx, v, &ldlt);
    // Without legs, the saddle-point factorization reads every entry of
    // `TᵀMT` (and of `A T`) as it is computed (`interleaved`): its signed
    // pivots, which hand a failure to `dense` (and `gauss_dense` checks
    // `M` and `F`), check what the inputs' check did for `TᵀMT`, as
    // `StructuredLdlt::mass_checked`'s do for `M` (a non-finite entry makes
    // its row's pivot fail). `TᵀF` keeps its check.
    let mass_entries = if legs.is_none() {
        (0..v.coordinates.len())
            .map(|i| (0..=i).filter(|&j| v.structure.nonzero[i][j]).count())
            .sum()
    } else {
        0
    };
    let head = bind(ctx, &named, mass_entries..checked, bail);
    let b: Vec<Ident> = (0..ctx.k).map(|r| Context::local("b", r)).collect();
    let correction = if v.system.in_base.is_empty() {
        corrected(&b, &[])
    } else {
        turned_correction(ctx, v)
    };
    let alphas = alphas(ctx, v, dense);
    let (nr, kr) = (v.coordinates.len(), v.rows.len());
    let g = &ctx.eq.system.graph;
    let mut rhs: Vec<Option<TokenStream>> = v
        .coordinates
        .iter()
        .map(|&i| {
            (!g.is_zero(v.system.forces[i])).then(|| {
                let f = Context::local("f", i);
                quote!(#f)
            })
        })
        .collect();
    rhs.extend((0..kr).map(|rr| {
        let name = Context::local("bv", rr);
        Some(quote!(#name))
    }));
    let ((solve, values), how) = match legs {
        Some(legs) => {
            let entry = |i: usize, j: usize| v.structure.nonzero[i][j].then(|| ldlt.entry(i, j));
            let solved = super::legs::solve(legs, (nr, kr), &entry, (&rhs, true), dense);
            (solved, Strategy::Legs.describe())
        }
        None => {
            let (solve, values) = solved(&ldlt, &rhs, (nr, kr));
            (
                (concat([ldlt.factor(), solve]), values),
                Strategy::VelocitySaddle.describe(),
            )
        }
    };
    let (recover, acceleration) = accelerations(ctx, v, &values);
    let forces: Vec<Option<TokenStream>> = (0..ctx.n)
        .map(|i| {
            (!g.is_zero(v.system.forces[i])).then(|| {
                let f = Context::local("f", i);
                quote!(#f)
            })
        })
        .collect();
    let (norms, mut mu) = multipliers(ctx, v, &values, &forces);
    let norms = concat([norms, in_world(v, &mut mu), held_multipliers(v, &mut mu)]);
    Solved {
        code: if legs.is_none() {
            interleaved(head, concat([correction, alphas, solve, recover, norms]))
        } else {
            concat([head, correction, alphas, solve, recover, norms])
        },
        acceleration,
        mu,
        how,
        ldlt,
    }
}

/// The locals bound from the expressions: `TᵀMT`'s entries of the
/// structure, `TᵀF` (these checked finite, their count second), the
/// structure's entries of `A T`, `A T`'s `α` columns, the model's `A`
/// (for `Aᵀλ`), `b`, the quaternions' coordinates.
fn named(ctx: &Context, v: &Velocity, ldlt: &StructuredLdlt) -> (Vec<(Ident, Id)>, usize) {
    let mut named = mass_and_forces(ctx, v, ldlt);
    let checked = named.len();
    named.extend(constraint_inputs(ctx, v, ldlt));
    (named, checked)
}

/// `TᵀMT`'s entries of the structure and `TᵀF`'s nonzeros, the inputs
/// checked finite.
fn mass_and_forces(ctx: &Context, v: &Velocity, ldlt: &StructuredLdlt) -> Vec<(Ident, Id)> {
    let g = &ctx.eq.system.graph;
    let nr = v.coordinates.len();
    let mut named = Vec::new();
    for i in 0..nr {
        for j in 0..=i {
            if v.structure.nonzero[i][j] {
                let e = v.mass[v.coordinates[i]][v.coordinates[j]];
                named.push((ldlt.entry(i, j), e));
            }
        }
    }
    for (i, &e) in v.system.forces.iter().enumerate() {
        if !g.is_zero(e) {
            named.push((Context::local("f", i), e));
        }
    }
    named
}

/// The structure's entries of `A T`, `A T`'s `α` columns, the model's `A`
/// (for `Aᵀλ`), `b` (`R̂ᵀ b` for a point's rows under a free base), the
/// free bases' rotations and the quaternions' coordinates.
fn constraint_inputs(ctx: &Context, v: &Velocity, ldlt: &StructuredLdlt) -> Vec<(Ident, Id)> {
    let g = &ctx.eq.system.graph;
    let (n, k, nr) = (ctx.n, ctx.k, v.coordinates.len());
    let mut named = Vec::new();
    for (rr, &r) in v.rows.iter().enumerate() {
        for (jj, &j) in v.coordinates.iter().enumerate() {
            if !g.is_zero(v.system.a[r][j]) {
                named.push((ldlt.entry(nr + rr, jj), v.system.a[r][j]));
            }
        }
    }
    let solved = solved_rows(v);
    for &(c, _) in &v.system.quaternions {
        for &r in &solved {
            if !g.is_zero(v.system.a[r][c]) {
                named.push((Context::local2("aa", r, c), v.system.a[r][c]));
            }
        }
    }
    for r in 0..k {
        for i in 0..n {
            if !g.is_zero(ctx.eq.a[r][i]) {
                named.push((Context::local2("a", r, i), ctx.eq.a[r][i]));
            }
        }
    }
    for (r, &e) in ctx.eq.b.iter().enumerate() {
        // A row of a point under a free base: `R̂ᵀ b`; of a held body's
        // six, theirs.
        let e = v
            .system
            .in_base
            .iter()
            .find_map(|t| Some(t.b[t.rows.iter().position(|&x| x == r)?]))
            .unwrap_or(e);
        let e = held_b(v, r).unwrap_or(e);
        if solved.contains(&r) {
            named.push((Context::local("b", r), e));
        }
    }
    for (h, held) in v.system.held.iter().enumerate() {
        for i in 0..3 {
            for j in 0..3 {
                named.push((held_local("hr", h, i, j), held.rotation[i][j]));
                named.push((held_local("hb", h, i, j), held.relative[i][j]));
            }
        }
    }
    for (t, (_, rotation)) in v.system.free.iter().enumerate() {
        for (i, row) in rotation.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                named.push((free_rotation(t, i, j), e));
            }
        }
    }
    for (&(c, _), q) in v.system.quaternions.iter().zip(&v.system.q) {
        for (m, &e) in q.iter().enumerate() {
            named.push((Context::local("qv", c + m), e));
        }
    }
    named
}

/// Each quaternion's `α = b_norm / (A T)_{norm,α}` (the divisor `|q|²`
/// below the safe minimum hands the solve to the dense one), then the kept
/// rows' right-hand sides `__bv{rr} = b − Σ (A T)_{rα} α`.
fn alphas(ctx: &Context, v: &Velocity, dense: &TokenStream) -> TokenStream {
    let g = &ctx.eq.system.graph;
    let safe_minimum = ctx.private(quote!(safe_minimum));
    let mut out = TokenStream::new();
    for &(c, norm) in &v.system.quaternions {
        let (alpha, an, b) = (
            Context::local("alpha", c),
            Context::local2("aa", norm, c),
            Context::local("b", norm),
        );
        out.extend(quote! {
            if !(#an >= #safe_minimum::<T>()) {
                #dense
            }
            let #alpha = #b / #an;
        });
    }
    for (rr, &r) in v.rows.iter().enumerate() {
        let b = Context::local("b", r);
        let terms: Vec<TokenStream> = v
            .system
            .quaternions
            .iter()
            .filter(|&&(c, _)| !g.is_zero(v.system.a[r][c]))
            .map(|&(c, _)| {
                let (a, alpha) = (Context::local2("aa", r, c), Context::local("alpha", c));
                quote!(#a * #alpha)
            })
            .collect();
        let name = Context::local("bv", rr);
        let value = if terms.is_empty() {
            quote!(#b)
        } else {
            quote!(#b - (#(#terms)+*))
        };
        out.extend(quote! { let #name = #value; });
    }
    out
}

/// `q̈ = T z`: the kept coordinates as solved, each quaternion's four as
/// `½ (q α + Gᵀ β)` (locals `__qa{i}`); the code and each coordinate's
/// value.
pub(super) fn accelerations(
    ctx: &Context,
    v: &Velocity,
    solved: &[Option<TokenStream>],
) -> (TokenStream, Vec<TokenStream>) {
    let mut values: Vec<TokenStream> = (0..ctx.n).map(|_| quote!(T::zero())).collect();
    for (p, &i) in v.coordinates.iter().enumerate() {
        values[i] = or_zero(&solved[p]);
    }
    let mut code = TokenStream::new();
    for (t, &(x, _)) in v.system.free.iter().enumerate() {
        // p̈ = R̂ z.
        let z: Vec<TokenStream> = (0..3).map(|j| values[x + j].clone()).collect();
        for i in 0..3 {
            let value = row_times(
                [0, 1, 2].map(|j| free_rotation(t, i, j)),
                [&z[0], &z[1], &z[2]],
            );
            let name = Context::local("pa", x + i);
            code.extend(quote! { let #name = #value; });
        }
        for i in 0..3 {
            let name = Context::local("pa", x + i);
            values[x + i] = quote!(#name);
        }
    }
    let (half, _) = literal(Num::Rational(1, 2));
    for &(c, _) in &v.system.quaternions {
        let beta: Vec<TokenStream> = (0..3).map(|j| values[c + 1 + j].clone()).collect();
        let alpha = Context::local("alpha", c);
        for k in 0..4 {
            let own = Context::local("qv", c + k);
            let mut terms = vec![quote!(#own * #alpha)];
            for (j, row) in G_PATTERN.iter().enumerate() {
                let (plus, m) = row[k];
                let (q, b) = (Context::local("qv", c + m), &beta[j]);
                terms.push(if plus {
                    quote!(+ #q * #b)
                } else {
                    quote!(- #q * #b)
                });
            }
            let first = &terms[0];
            let rest = &terms[1..];
            let name = Context::local("qa", c + k);
            code.extend(quote! { let #name = (#first #(#rest)*) * #half; });
        }
        for k in 0..4 {
            let name = Context::local("qa", c + k);
            values[c + k] = quote!(#name);
        }
    }
    (code, values)
}

/// `μ` for every row (`None` where structurally zero): the kept rows' as
/// solved, each norm's
/// `((TᵀF)_α − Σ (A T)_{rα} μ_r) / (A T)_{norm,α}` (locals `__mun{r}`),
/// `(TᵀF)_α` from `forces` by coordinate.
pub(super) fn multipliers(
    ctx: &Context,
    v: &Velocity,
    solved: &[Option<TokenStream>],
    forces: &[Option<TokenStream>],
) -> (TokenStream, Vec<Option<TokenStream>>) {
    let g = &ctx.eq.system.graph;
    let nr = v.coordinates.len();
    let mut mu: Vec<Option<TokenStream>> = vec![None; ctx.k];
    for (rr, &r) in v.rows.iter().enumerate() {
        mu[r] = solved[nr + rr].clone();
    }
    let mut code = TokenStream::new();
    for &(c, norm) in &v.system.quaternions {
        let f = or_zero(&forces[c]);
        let terms: Vec<TokenStream> = v
            .rows
            .iter()
            .filter(|&&r| !g.is_zero(v.system.a[r][c]))
            .filter_map(|&r| {
                let (a, m) = (Context::local2("aa", r, c), mu[r].as_ref()?);
                Some(quote!(#a * #m))
            })
            .collect();
        let an = Context::local2("aa", norm, c);
        let name = Context::local("mun", norm);
        let value = if terms.is_empty() {
            quote!(#f / #an)
        } else {
            quote!((#f - (#(#terms)+*)) / #an)
        };
        code.extend(quote! { let #name = #value; });
        mu[norm] = Some(quote!(#name));
    }
    (code, mu)
}

/// The local of `R̂[i][j]` of the `t`-th free base.
pub(super) fn free_rotation(t: usize, i: usize, j: usize) -> Ident {
    Context::local2("rf", t, 3 * i + j)
}

/// The local of `R̂[i][j]` of the free base of a triple of rows in its
/// axes (`crate::equations::velocity::form` keeps only triples whose base
/// is among `free`).
pub(super) fn rotation_local(v: &Velocity, rows: &InBaseRows, i: usize, j: usize) -> Ident {
    let t = v
        .system
        .free
        .iter()
        .position(|&(x, _)| x == rows.base)
        .unwrap_or(0);
    free_rotation(t, i, j)
}

/// `b + δb` for `acceleration_corrected`, with the rows of a point under a
/// free base in the base's axes: `R̂ᵀ b + R̂ᵀ δb`; a held body's six from
/// its points' `δb` ([`held_correction`]).
fn turned_correction(ctx: &Context, v: &Velocity) -> TokenStream {
    let d = correction_locals(ctx.k);
    let mut terms: Vec<TokenStream> = d.iter().map(|d| quote!(#d)).collect();
    for rows in &v.system.in_base {
        let [d0, d1, d2] = rows.rows.map(|r| &d[r]);
        for (i, &r) in rows.rows.iter().enumerate() {
            let value = row_times(
                [0, 1, 2].map(|j| rotation_local(v, rows, j, i)),
                [d0, d1, d2],
            );
            terms[r] = quote!((#value));
        }
    }
    let mut code = TokenStream::new();
    for (h, held) in v.system.held.iter().enumerate() {
        let (local, six) = held_correction(h, held, &d);
        code.extend(local);
        for (i, r) in held.six().into_iter().enumerate() {
            terms[r] = six[i].clone();
        }
    }
    let solved = solved_rows(v);
    let b: Vec<Ident> = solved.iter().map(|&r| Context::local("b", r)).collect();
    let terms: Vec<&TokenStream> = solved.iter().map(|&r| &terms[r]).collect();
    quote! {
        let (#(#b,)*) = match correction {
            ::core::option::Option::Some(__db) => {
                let [[#(#d),*]] = __db.data.0;
                #code
                (#(#b + #terms,)*)
            }
            ::core::option::Option::None => (#(#b,)*),
        };
    }
}

/// The rows the saddle-point solve reads `b` of: its own and the norms'.
fn solved_rows(v: &Velocity) -> Vec<usize> {
    let mut rows = v.rows.clone();
    rows.extend(v.system.quaternions.iter().map(|&(_, norm)| norm));
    rows.sort_unstable();
    rows
}

/// The right-hand side of row `r` where it is one of a held body's six.
fn held_b(v: &Velocity, r: usize) -> Option<Id> {
    v.system.held.iter().find_map(|h| {
        let i = h.six().iter().position(|&x| x == r)?;
        Some(h.b[i])
    })
}

/// The local of entry `(i, j)` of a held body's `R` (`"hr"`) or `R_B`
/// (`"hb"`).
fn held_local(what: &str, h: usize, i: usize, j: usize) -> Ident {
    Context::local2(what, h, 3 * i + j)
}

/// `Σ wᵢ xᵢ` over the nonzero constant weights, parenthesised;
/// `T::zero()` for none.
fn weighted(weights: impl Iterator<Item = (Num, TokenStream)>) -> TokenStream {
    let pairs: Vec<(TokenStream, TokenStream)> = weights
        .filter(|(w, _)| !w.is_zero())
        .map(|(w, x)| (literal(w).0, x))
        .collect();
    if pairs.is_empty() {
        return quote!(T::zero());
    }
    let sum = super::dot(pairs);
    quote!((#sum))
}

/// `r₀ x₀ + r₁ x₁ + r₂ x₂`: a row of a rotation's locals times a vector.
fn row_times<A: quote::ToTokens, B: quote::ToTokens>(r: [A; 3], x: [B; 3]) -> TokenStream {
    let ([r0, r1, r2], [x0, x1, x2]) = (r, x);
    quote!(#r0 * #x0 + #r1 * #x1 + #r2 * #x2)
}

/// A held body's six right-hand sides' change from its points' `δb`
/// (world axes): each point's in the body's axes, `δᴸ = Rᵀ δb` (locals
/// `__hd{h}_{c}`), then `R_B (P G δᴸ)` and `R (G_ω δᴸ)`.
fn held_correction(h: usize, held: &HeldRows, d: &[Ident]) -> (TokenStream, Vec<TokenStream>) {
    let mut code = TokenStream::new();
    let mut local: Vec<TokenStream> = Vec::new();
    for (p, triple) in held.triples.iter().enumerate() {
        let [d0, d1, d2] = triple.map(|r| &d[r]);
        for i in 0..3 {
            let value = row_times([0, 1, 2].map(|j| held_local("hr", h, j, i)), [d0, d1, d2]);
            let name = Context::local2("hd", h, 3 * p + i);
            code.extend(quote! { let #name = #value; });
            local.push(quote!(#name));
        }
    }
    let six: Vec<TokenStream> = (0..6)
        .map(|i| {
            weighted(
                held.correction
                    .iter()
                    .map(|c| c[i])
                    .zip(local.iter().cloned()),
            )
        })
        .collect();
    let turn = |what: &str, part: &[TokenStream]| -> Vec<TokenStream> {
        (0..3)
            .map(|i| {
                let r = [0, 1, 2].map(|j| held_local(what, h, i, j));
                let value = row_times(r, [&part[0], &part[1], &part[2]]);
                quote!((#value))
            })
            .collect()
    };
    let mut out = turn("hb", &six[..3]);
    out.extend(turn("hr", &six[3..]));
    (code, out)
}

/// A held body's points' multipliers from its six rows' (`μ₁` in the
/// base's axes, `μ_ω` in the world's): `fᴸ = R_Bᵀ μ₁`, `τᴸ = Rᵀ μ_ω`
/// (locals `__hw{h}_{i}`), then each point's `R (H [fᴸ; τᴸ])ᵢ` in world
/// axes (locals `__hl{h}_{c}` in the body's, `__mub{r}` in the world's).
fn held_multipliers(v: &Velocity, mu: &mut [Option<TokenStream>]) -> TokenStream {
    let mut code = TokenStream::new();
    for (h, held) in v.system.held.iter().enumerate() {
        let six: Vec<TokenStream> = held.six().iter().map(|&r| or_zero(&mu[r])).collect();
        let mut wrench = Vec::new();
        for (what, part) in [("hb", &six[..3]), ("hr", &six[3..])] {
            for i in 0..3 {
                let r = [0, 1, 2].map(|j| held_local(what, h, j, i));
                let value = row_times(r, [&part[0], &part[1], &part[2]]);
                let name = Context::local2("hw", h, wrench.len());
                code.extend(quote! { let #name = #value; });
                wrench.push(quote!(#name));
            }
        }
        for (c, row) in held.multipliers.iter().enumerate() {
            let value = weighted(row.iter().copied().zip(wrench.iter().cloned()));
            let name = Context::local2("hl", h, c);
            code.extend(quote! { let #name = #value; });
        }
        for (p, triple) in held.triples.iter().enumerate() {
            for (i, &r) in triple.iter().enumerate() {
                let local = [0, 1, 2].map(|j| Context::local2("hl", h, 3 * p + j));
                let value = row_times([0, 1, 2].map(|j| held_local("hr", h, i, j)), local);
                let name = Context::local("mub", r);
                code.extend(quote! { let #name = #value; });
                mu[r] = Some(quote!(#name));
            }
        }
    }
    code
}

/// Each triple of rows solved in a base's axes gives `λ'`; the model's
/// rows' are `λ = R̂ λ'` (locals `__mub{r}`); a held body's points' come
/// from its six rows instead ([`held_multipliers`]).
pub(super) fn in_world(v: &Velocity, mu: &mut [Option<TokenStream>]) -> TokenStream {
    let mut code = TokenStream::new();
    let held: Vec<usize> = (v.system.held.iter())
        .flat_map(|h| h.triples.iter().flatten().copied())
        .collect();
    for rows in v
        .system
        .in_base
        .iter()
        .filter(|t| !held.contains(&t.rows[0]))
    {
        let own: Vec<TokenStream> = rows.rows.iter().map(|&r| or_zero(&mu[r])).collect();
        for (i, &r) in rows.rows.iter().enumerate() {
            let r3 = [0, 1, 2].map(|j| rotation_local(v, rows, i, j));
            let value = row_times(r3, [&own[0], &own[1], &own[2]]);
            let name = Context::local("mub", r);
            code.extend(quote! { let #name = #value; });
            mu[r] = Some(quote!(#name));
        }
    }
    code
}
