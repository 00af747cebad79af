//! `acceleration_jacobian` for a configuration-dependent `M`: the tangent
//! systems solved column by column through `gauss`'s factorizations.
//!
//! Per column `v`: `u = M⁻¹ F̃ᵥ`, `μ = S⁻¹ (b̃ᵥ − A u)`, `q̈ᵥ = u + W μ`.
//! A small system with one set of derivatives per column
//! (`Form::Columns`) binds the derivatives in the same body as `M`, `F`,
//! `A` and `b`, so that they share its temporaries (its sines and cosines
//! are computed once, not again by `tangent_rhs`), and solves its columns
//! straight-line over their structural nonzeros (a column that is
//! identically zero costs nothing). A larger one, or the directional form, runs one loop
//! over the columns of `tangent_rhs` (the code the runtime's dense solve
//! calls too), which grows with `n + k` rather than with the columns; in
//! the per-column form each column's solve there reads its right-hand
//! side's structural nonzeros only (a fixed base's leg touches its own
//! block of `M`, an arm's joint leaves the other arm's rows zero), and a
//! structurally zero column is solved for nothing, only written as zeros.
//! Without constraints, where inputs
//! enter `F` with constant factors (torques), `M⁻¹` is formed once when
//! that is cheaper than solving for their columns ([`unit_columns`]):
//! those columns are read from it, and the loop's columns are products
//! with it.

use super::groups::{dispatch, Dispatch, Pattern};
use super::{accelerations, residual_code, FactoredSolve};
use crate::emit::chunks::bounded;
use crate::emit::context::Context;
use crate::emit::literal::literal;
use crate::emit::mass_inverse::adopt_dense;
use crate::emit::tangent::{column_patterns, constant_columns, index, NamedTerms};
use crate::equations::mass_inverse::Factored;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The straight-line columns are kept while their estimated operations
/// (`(n + k)²` a nonzero column) stay under this; above, the loop.
const STRAIGHT_LINE_BUDGET: usize = 4096;

/// The body of `acceleration_jacobian` for a configuration-dependent `M`,
/// written into `__jac: &mut Jacobians`, every entry (the caller's own
/// may hold anything); `dense` (the runtime's solve) answers where the
/// rank decision is suspect.
pub(in crate::emit) fn jacobian(ctx: &Context, f: &Factored, dense: &TokenStream) -> TokenStream {
    let named = NamedTerms::new(ctx).filter(|t| straight_line_cost(ctx, t) <= STRAIGHT_LINE_BUDGET);
    let extra = named.as_ref().map_or(&[][..], |t| &t.named[..]);
    let gauss = FactoredSolve::with_extra(ctx, f, extra);
    let qdd = (0..ctx.n).map(|i| {
        let (name, value) = (Context::local("qdd", i), &gauss.acceleration[i]);
        quote!(let #name = #value;)
    });
    let qdd: TokenStream = qdd.collect();
    let columns = match &named {
        Some(terms) => straight_line(ctx, f, &gauss, terms),
        None => looped(ctx, f, &gauss),
    };
    debug_assert!(
        ctx.eq.mass_inverse.fallible(),
        "a configuration-dependent M is not known positive definite"
    );
    let solve = if ctx.k > 0 {
        let suspect = gauss.gram.suspect(ctx.generic_rank);
        let adopt = adopt_dense(dense, quote!(*__jac));
        quote! {
            if #suspect {
                #adopt
            } else {
                #qdd
                #columns
            }
        }
    } else {
        quote! { #qdd #columns }
    };
    let finite = ctx.finite_or_error(quote!(__jac), quote!(()));
    let tail = quote! {
        #solve
        #finite
    };
    // Nested no deeper than a block (`crate::emit::chunks`).
    let to_multipliers = bounded(gauss.to_multipliers.clone(), &tail);
    quote! {
        #to_multipliers
        #tail
    }
}

/// The locals `__{name}{i}` as an `SVector`.
fn vector(ctx: &Context, name: &str, len: usize) -> TokenStream {
    ctx.vector_value((0..len).map(|i| {
        let l = Context::local(name, i);
        quote!(#l)
    }))
}

/// Whether column `c` of the terms has a structural nonzero.
fn nonzero_column(terms: &NamedTerms, c: usize) -> bool {
    terms.forces[c]
        .iter()
        .chain(&terms.rhs[c])
        .any(Option::is_some)
}

/// The estimated operations of the straight-line columns.
fn straight_line_cost(ctx: &Context, terms: &NamedTerms) -> usize {
    let columns = (0..terms.forces.len())
        .filter(|&c| nonzero_column(terms, c))
        .count();
    columns * (ctx.n + ctx.k).pow(2)
}

/// Where column `c` of the Jacobian is written: `dq`, `dqd` or `du`, and
/// the column within it.
fn destination(ctx: &Context, c: usize) -> (TokenStream, proc_macro2::Literal) {
    let n = ctx.n;
    if c < n {
        (quote!(dq), index(c))
    } else if c < 2 * n {
        (quote!(dqd), index(c - n))
    } else {
        (quote!(du), index(c - 2 * n))
    }
}

/// Every column with a structural nonzero solved straight-line over its
/// nonzeros, and every column of `__jac` written (zeros where the column
/// is structurally zero).
fn straight_line(
    ctx: &Context,
    f: &Factored,
    gauss: &FactoredSolve,
    terms: &NamedTerms,
) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let n_l = Context::dim(n);
    let mut out = TokenStream::new();
    for c in 0..terms.forces.len() {
        let (matrix, column) = destination(ctx, c);
        if !nonzero_column(terms, c) {
            out.extend(quote!(__jac.#matrix.data.0[#column] = [T::zero(); #n_l];));
            continue;
        }
        let u: Vec<Ident> = (0..n).map(|i| Context::local2("ju", c, i)).collect();
        let (solve_u, u_bound) = gauss
            .mass
            .solve_sparse(&terms.forces[c], &format!("jy{c}x"), &u);
        let r: Vec<Ident> = (0..k).map(|j| Context::local2("jr", c, j)).collect();
        let (residuals, r_bound) = residual_code(ctx, &r, &terms.rhs[c], (&u_bound, &u));
        let r: Vec<Option<TokenStream>> = r
            .iter()
            .zip(&r_bound)
            .map(|(name, &bound)| bound.then(|| quote!(#name)))
            .collect();
        let mu: Vec<Ident> = (0..k).map(|j| Context::local2("jmu", c, j)).collect();
        let (solve_mu, mu_bound) = gauss.gram.solve_sparse(&r, &format!("jz{c}x"), &mu);
        out.extend([solve_u, residuals, solve_mu]);
        let values = accelerations(f, (&u_bound, &u), (&mu_bound, &mu))
            .into_iter()
            .map(|v| v.unwrap_or_else(|| quote!(T::zero())));
        out.extend(quote!(__jac.#matrix.data.0[#column] = [#(#values),*];));
    }
    out
}

/// The columns solved in one loop over the right-hand sides `tangent_rhs`
/// writes (the code the runtime's dense solve calls too), into `__jac`.
/// Where columns are sparse (a fixed base's branches, a leg's joint) or
/// structurally zero, each column's solve reads its `F̃`'s nonzeros only
/// ([`patterns`]), columns of one pattern sharing one copy of it
/// ([`super::groups`]), chosen by a constant table of the columns.
fn looped(ctx: &Context, f: &Factored, gauss: &FactoredSolve) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let (n_l, k_l) = (Context::dim(n), Context::dim(k));
    let d_l = ctx.jacobians_zero().1;
    let tangent = ctx.private(quote!(Tangent<T, #n_l, #k_l, #d_l>));
    let (qdd_vector, lam) = (vector(ctx, "qdd", n), vector(ctx, "lam", k));
    let (unit, inverse) = unit_columns(ctx, gauss);
    // With `M⁻¹` formed, every column is a product with it: independent
    // sums, where the solves are chains of dependent steps.
    let solve = |rows: &[bool]| match &inverse {
        Some(inverse) => column_product(&inverse.x, rows),
        None => column_solve(ctx, f, gauss, rows),
    };
    let pairs = quote!(__fs.data.0.iter().zip(__rs.data.0.iter()).zip(__outs));
    let (inverse_code, writes) = inverse
        .as_ref()
        .map(|i| (i.code.clone(), i.writes.clone()))
        .unwrap_or_default();
    // `__jac` is the caller's (`acceleration_jacobian_to`): every column
    // is written, a structurally zero one (or one `writes` fills after the
    // loop) with zeros.
    let zero_column = quote!(*__out = [T::zero(); #n_l];);
    let each = match patterns(ctx, &unit) {
        None => {
            let unpack = unpack(ctx, None);
            let solve = solve(&vec![true; n]);
            quote! {
                for ((__f, __r), __out) in #pairs {
                    #unpack
                    #solve
                }
            }
        }
        Some(patterns) => {
            let Dispatch {
                table,
                arms,
                patterns,
            } = dispatch(&patterns, &|p: &Pattern| solve(&p.0), &zero_column);
            let unpack = unpack(ctx, Some(&patterns));
            quote! {
                #table
                for (((__f, __r), __out), __g) in #pairs.zip(__GROUPS) {
                    #unpack
                    #arms
                }
            }
        }
    };
    quote! {
        let mut __fs = ::constrained::nalgebra::SMatrix::<T, #n_l, #d_l>::zeros();
        let mut __rs = ::constrained::nalgebra::SMatrix::<T, #k_l, #d_l>::zeros();
        <Self as #tangent>::tangent_rhs(self, q, qd, t, &#qdd_vector, &#lam, &mut __fs, &mut __rs);
        #inverse_code
        let __outs = __jac.dq.data.0.iter_mut()
            .chain(__jac.dqd.data.0.iter_mut())
            .chain(__jac.du.data.0.iter_mut());
        #each
        #writes
    }
}

/// The loop body's first lines: a column's `F̃` into `__jf{i}` (`_` for a
/// row no group reads) and its `b̃` into `__jb{r}`.
fn unpack(ctx: &Context, groups: Option<&[Pattern]>) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let fv = (0..n).map(|i| {
        let read = groups.is_none_or(|groups| groups.iter().any(|p| p.0[i]));
        let name = Context::local("jf", i);
        if read {
            quote!(#name)
        } else {
            quote!(_)
        }
    });
    let rv: Vec<Ident> = (0..k).map(|j| Context::local("jb", j)).collect();
    let unpack_b = (k > 0).then(|| quote!(let [#(#rv),*] = *__r;));
    quote! {
        let [#(#fv),*] = *__f;
        #unpack_b
    }
}

/// `M⁻¹` formed for the Jacobian's columns ([`unit_columns`]).
struct Inverse {
    /// Its code (before the loop).
    code: TokenStream,
    /// Its entries' locals, natural order (`None`: structurally zero).
    x: Vec<Vec<Option<Ident>>>,
    /// The columns read from it (after the loop).
    writes: TokenStream,
}

/// With `M⁻¹` formed (`k = 0`, [`Inverse`]): the column `M⁻¹ F̃`, `F̃` in
/// the locals `__jf{i}` nonzero where `rows` says, written to `*__out`.
fn column_product(x: &[Vec<Option<Ident>>], rows: &[bool]) -> TokenStream {
    let column = x.iter().map(|row| {
        let terms: Vec<TokenStream> = row
            .iter()
            .enumerate()
            .filter(|&(j, _)| rows[j])
            .filter_map(|(j, entry)| {
                let (entry, fj) = (entry.as_ref()?, Context::local("jf", j));
                Some(quote!(#entry * #fj))
            })
            .collect();
        if terms.is_empty() {
            quote!(T::zero())
        } else {
            quote!(#(#terms)+*)
        }
    });
    quote!(*__out = [#(#column),*];)
}

/// The columns whose `F̃` is a number in one row and zero elsewhere (a
/// motor torque's `∂q̈/∂u`), where `k = 0`: `q̈ᵥ = β M⁻¹ eᵣ`, read from
/// `M⁻¹` formed once by Takahashi's recurrence
/// ([`inverse`](crate::emit::ldlt::StructuredLdlt::inverse)) where that
/// takes fewer multiplications than their solves. Returns which columns
/// that writes (the loop skips them) and the inverse, whose writes run
/// after the loop (whose iterator holds `__jac` until then).
fn unit_columns(ctx: &Context, gauss: &FactoredSolve) -> (Vec<bool>, Option<Inverse>) {
    let columns = constant_columns(ctx).unwrap_or_default();
    let none = (vec![false; columns.len()], None);
    let rows: Vec<usize> = columns.iter().flatten().map(|&(r, _)| r).collect();
    if ctx.k > 0 || rows.is_empty() {
        return none;
    }
    let (inverse, solves) = gauss.mass.inverse_and_unit_solve_costs(&rows);
    if inverse >= solves {
        return none;
    }
    let (code, x) = gauss.mass.inverse("mx");
    let mut writes = TokenStream::new();
    for (c, column) in columns.iter().enumerate() {
        let Some((r, beta)) = column else { continue };
        let (matrix, col) = destination(ctx, c);
        for (i, entry) in x.iter().enumerate() {
            let Some(entry) = &entry[*r] else { continue };
            let value = if beta.is_one() {
                quote!(#entry)
            } else if (-*beta).is_one() {
                quote!(-#entry)
            } else {
                let b = literal(*beta).0;
                quote!(#b * #entry)
            };
            let row = index(i);
            writes.extend(quote!(__jac.#matrix.data.0[#col][#row] = #value;));
        }
    }
    let unit = columns.iter().map(Option::is_some).collect();
    (unit, Some(Inverse { code, x, writes }))
}

/// One column's solve, `F̃` in the locals `__jf{i}` nonzero where `rows`
/// says, `b̃` in `__jb{r}`: `u = M⁻¹ F̃` over the entries it can reach,
/// `μ = S⁻¹ (b̃ − A u)`, `q̈ᵥ = u + W μ` written to `*__out`.
fn column_solve(ctx: &Context, f: &Factored, gauss: &FactoredSolve, rows: &[bool]) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let u: Vec<Ident> = (0..n).map(|i| Context::local("ju", i)).collect();
    let r: Vec<Ident> = (0..k).map(|j| Context::local("jr", j)).collect();
    let mu: Vec<Ident> = (0..k).map(|j| Context::local("jmu", j)).collect();
    let rhs: Vec<Option<TokenStream>> = rows
        .iter()
        .enumerate()
        .map(|(i, &on)| {
            let name = Context::local("jf", i);
            on.then(|| quote!(#name))
        })
        .collect();
    let (solve_u, u_bound) = gauss.mass.solve_sparse(&rhs, "jy", &u);
    let b: Vec<Option<TokenStream>> = (0..k)
        .map(|j| {
            let name = Context::local("jb", j);
            Some(quote!(#name))
        })
        .collect();
    let (residuals, r_bound) = residual_code(ctx, &r, &b, (&u_bound, &u));
    let r: Vec<Option<TokenStream>> = r
        .iter()
        .zip(&r_bound)
        .map(|(name, &bound)| bound.then(|| quote!(#name)))
        .collect();
    let (solve_mu, mu_bound) = gauss.gram.solve_sparse(&r, "jz", &mu);
    let column = accelerations(f, (&u_bound, &u), (&mu_bound, &mu))
        .into_iter()
        .map(|e| e.unwrap_or_else(|| quote!(T::zero())));
    quote! {
        #solve_u
        #residuals
        #solve_mu
        *__out = [#(#column),*];
    }
}

/// Each column's pattern for the dispatch: the rows of `F̃` its solve
/// reads (its structural nonzeros: an arm's joint leaves the other arm's
/// rows zero, though `M⁻¹` couples both arms through the waist) and
/// whether it has a `b̃`, every row of which the solve reads; all-false
/// for a structurally zero column or one [`unit_columns`] writes. `None`
/// where every column reads every row or the form is directional (a
/// column's rows unknown).
fn patterns(ctx: &Context, skip: &[bool]) -> Option<Vec<Pattern>> {
    let n = ctx.n;
    let patterns: Vec<Pattern> = (column_patterns(ctx)?.into_iter().enumerate())
        .map(|(c, (f, b))| {
            if skip.get(c).copied().unwrap_or(false) {
                (vec![false; n], vec![false])
            } else {
                (f, vec![b.contains(&true)])
            }
        })
        .collect();
    let every = patterns.iter().all(|p| p.0.iter().all(|&r| r));
    (!every).then_some(patterns)
}
