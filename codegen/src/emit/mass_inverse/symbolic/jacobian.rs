//! `acceleration_jacobian` for a symbolic `M⁻¹` (constant or diagonal
//! `M`), solved in generated code through the structure `acceleration`
//! uses.
//!
//! Each tangent system `M q̈ᵥ = F̃ᵥ + Aᵀμᵥ`, `A q̈ᵥ = b̃ᵥ` is solved as
//! `q̈ᵥ = aᵥ + W μᵥ`, `aᵥ = M⁻¹F̃ᵥ`, `S μᵥ = b̃ᵥ − A aᵥ`, `W = M⁻¹Aᵀ`, in
//! two parts:
//!
//! - straight-line, column by column: `aᵥ` and `b̃ᵥ − A aᵥ` over the
//!   structural nonzeros of `F̃ᵥ`, `b̃ᵥ`, `M⁻¹` and `A`. A column of a
//!   chain touches a few entries, so this costs what `tangent_rhs` costs,
//!   and no matrix of `F̃` is formed;
//! - one loop over the columns: `μᵥ` by the solve step of `acceleration`'s
//!   factorization of `S` (the same pivots, so the same rank decision),
//!   and `W μᵥ` over the nonzeros of `W`. Its code grows with `n + k`, not
//!   with the number of columns.
//!
//! Where the rank decision is suspect, the runtime's dense solve answers,
//! exactly where `acceleration` consults the runtime; so it does for the
//! directional form of the derivatives (`crate::equations::tangent`), which has no
//! column structure.

use super::{overflowing_rows, SymbolicSolve};
use crate::emit::body::literal;
use crate::emit::context::Context;
use crate::emit::mass_inverse::adopt_dense;
use crate::emit::tangent::{index, TangentTerms};
use crate::equations::mass_inverse::Symbolic;
use crate::equations::tangent::Form;
use crate::expr::num::Num;
use crate::expr::{Graph, Id};
use proc_macro2::TokenStream;
use quote::quote;

/// The body of `acceleration_jacobian` (`try_acceleration_jacobian` for a
/// total system), a `Result`; `dense` is the runtime's solve, as an
/// expression of the same type.
pub(in crate::emit) fn jacobian(ctx: &Context, d: &Symbolic, dense: &TokenStream) -> TokenStream {
    // Right-hand sides along a direction have no column structure to
    // exploit: the runtime's dense solve, looping over the columns.
    if matches!(ctx.eq.tangent.form, Form::Directional(_)) {
        return dense.clone();
    }
    let k = ctx.k;
    let gauss = SymbolicSolve::new(ctx, d, &column_constants(ctx, d), false);
    let (constants, qdd) = constants(ctx, d, &gauss);
    // The rows' scales fold into `b̃` and into `F̃`'s constant coefficients
    // of `λ̃` (`TangentTerms::scaled`) where `λ = D λ̃`; a common mass
    // would stand between them.
    let scales = d.common_mass.is_none().then_some(d.scale.as_slice());
    let (tangent_preamble, columns) = straight_line_columns(ctx, d, scales);
    let k_l = Context::dim(k);
    let (jacobians_zero, d_l) = ctx.jacobians_zero();
    // A `Result` whether or not `acceleration` can fail: the body is
    // `try_acceleration_jacobian`'s for a total system, and a derivative
    // that does not exist or overflows is an `Err` there too.
    let value = ctx.finite_or_error(quote!(__jac), quote!(__jac));
    let to_multipliers = &gauss.to_multipliers;
    let unscaled = unscaled_multipliers(d, &gauss);
    if k == 0 {
        return quote! {
            #to_multipliers
            let mut __jac = #jacobians_zero;
            #(#constants)*
            #(#qdd)*
            {
                #tangent_preamble
                #columns
            }
            #value
        };
    }
    let multipliers = multiplier_loop(ctx, d, &gauss);
    // One local holds the answer on every path, so that it is built where
    // the caller wants it (a returned local assigned on two paths, or a
    // second local, costs a copy of the whole Jacobian: 32 KiB at 32 links).
    let suspect = suspect(ctx, d, &gauss);
    let adopt = adopt_dense(dense, quote!(__jac));
    quote! {
        #to_multipliers
        let mut __jac = #jacobians_zero;
        if #suspect {
            #adopt
        } else {
            #(#constants)*
            #(#qdd)*
            #(#unscaled)*
            let mut __rs = [[T::zero(); #k_l]; #d_l];
            {
                #tangent_preamble
                #columns
            }
            #multipliers
        }
        #value
    }
}

/// The constant pieces of every column's solve, named once: the structural
/// nonzeros of `A`, `W = M⁻¹Aᵀ` and `M⁻¹`, and the common mass.
fn column_constants(ctx: &Context, d: &Symbolic) -> Vec<Id> {
    let g = &ctx.eq.system.graph;
    let mut extra: Vec<Id> = Vec::new();
    for entries in [&d.rows, &d.weighted, &d.inverse] {
        extra.extend(entries.iter().flatten().copied().filter(|&e| !g.is_zero(e)));
    }
    extra.extend(d.common_mass);
    extra
}

/// The tangent terms' preamble and the straight-line part of every column
/// ([`column`]), each in a scope of its own.
fn straight_line_columns(
    ctx: &Context,
    d: &Symbolic,
    scales: Option<&[Num]>,
) -> (TokenStream, TokenStream) {
    let terms = TangentTerms::scaled(ctx, scales);
    let preamble = terms.body.preamble();
    let mut columns = TokenStream::new();
    let scaled = scales.is_some();
    for (c, (f, b)) in terms.forces.iter().zip(&terms.rhs).enumerate() {
        columns.extend(column(ctx, d, c, (f, b), scaled));
    }
    (preamble, columns)
}

/// When the dense solve answers instead: the same condition as
/// `acceleration`'s check (`checked_motion`), the factorization's rank
/// decision suspect or a scaled row overflowing.
fn suspect(ctx: &Context, d: &Symbolic, gauss: &SymbolicSolve) -> TokenStream {
    let suspect = gauss.ldlt.suspect(ctx.generic_rank);
    match overflowing_rows(ctx, d) {
        Some(also) => quote!((#suspect) | #also),
        None => suspect,
    }
}

/// `μᵥ` and `W μᵥ` for every column, one loop over the columns: each
/// column's right-hand side `__rs[c]` solved by `acceleration`'s
/// factorization of `S`, and `W μᵥ` added into the column's outputs.
fn multiplier_loop(ctx: &Context, d: &Symbolic, gauss: &SymbolicSolve) -> TokenStream {
    let g = &ctx.eq.system.graph;
    let r: Vec<_> = (0..ctx.k).map(|j| Context::local("jr", j)).collect();
    let mu: Vec<_> = (0..ctx.k).map(|j| Context::local("jmu", j)).collect();
    let solve = gauss.ldlt.solve(&r, "jy", &mu);
    let (outputs, updates) = weighted_update(d, &mu, |e| !g.is_zero(e), ctx.n);
    quote! {
        let __outs = __jac.dq.data.0.iter_mut()
            .chain(__jac.dqd.data.0.iter_mut())
            .chain(__jac.du.data.0.iter_mut());
        for (__r, __out) in __rs.iter().zip(__outs) {
            let [#(#r),*] = *__r;
            #solve
            let [#(#outputs),*] = __out;
            #updates
        }
    }
}

/// The locals every column reads: `Â` (`__ja…`; the scaled rows of the
/// system `acceleration` solves, the right-hand sides being scaled by `D`
/// to match), `W` (`__jw…`), `M⁻¹` (`__jm…`) over their nonzeros, and
/// `q̈` (`__qdd…`).
fn constants(
    ctx: &Context,
    d: &Symbolic,
    gauss: &SymbolicSolve,
) -> ([TokenStream; 3], Vec<TokenStream>) {
    let g = &ctx.eq.system.graph;
    let body = &gauss.body;
    let bind = |role: &str, entries: &[Vec<Id>]| -> TokenStream {
        let mut out = TokenStream::new();
        for (i, row) in entries.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                if !g.is_zero(e) {
                    let (name, value) = (Context::local2(role, i, j), body.expr(e));
                    out.extend(quote! { let #name = #value; });
                }
            }
        }
        out
    };
    let constants = [
        bind("ja", &d.rows),
        bind("jw", &d.weighted),
        bind("jm", &d.inverse),
    ];
    let qdd = d
        .acceleration
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            let (name, value) = (Context::local("qdd", i), body.expr(e));
            quote! { let #name = #value; }
        })
        .collect();
    (constants, qdd)
}

/// The straight-line part of column `c`, in a scope of its own (its
/// locals end with it): `aᵥ = M⁻¹ F̃ᵥ` written into the Jacobian's column,
/// and `b̃ᵥ − A aᵥ` into `__rs[c]`, over the structural nonzeros of `F̃ᵥ`
/// (`f`), `b̃ᵥ` (`b`), `M⁻¹` and `Â`.
fn column(
    ctx: &Context,
    d: &Symbolic,
    c: usize,
    (f, b): (&[Option<TokenStream>], &[Option<TokenStream>]),
    scaled: bool,
) -> TokenStream {
    let n = ctx.n;
    let g = &ctx.eq.system.graph;
    let (part, cc) = match c {
        c if c < n => (quote!(dq), c),
        c if c < 2 * n => (quote!(dqd), c - n),
        c => (quote!(du), c - 2 * n),
    };
    let (cl, ccl) = (index(c), index(cc));
    let mut code = TokenStream::new();
    let mut f_nonzero = Vec::new();
    for (i, value) in f.iter().enumerate() {
        if let Some(value) = value {
            let name = Context::local("jf", i);
            code.extend(quote! { let #name = #value; });
            f_nonzero.push(i);
        }
    }
    let (free, a_nonzero) = free_acceleration(g, d, &f_nonzero, &quote!(__jac.#part.data.0[#ccl]));
    code.extend(free);
    code.extend(constraint_rhs(
        g,
        d,
        (&a_nonzero, b, scaled),
        &quote!(__rs[#cl]),
    ));
    quote! {{ #code }}
}

/// `aᵥ = M⁻¹ F̃ᵥ` over the nonzeros of `M⁻¹` and of `F̃ᵥ` (`f_nonzero`,
/// bound as `__jf…`), each entry bound as `__ju…` and written into the
/// Jacobian's column `out`; and the rows of `aᵥ` that are nonzero.
fn free_acceleration(
    g: &Graph,
    d: &Symbolic,
    f_nonzero: &[usize],
    out: &TokenStream,
) -> (TokenStream, Vec<usize>) {
    let mut code = TokenStream::new();
    let mut a_nonzero = Vec::new();
    for (i, row) in d.inverse.iter().enumerate() {
        let products: Vec<TokenStream> = f_nonzero
            .iter()
            .filter(|&&l| !g.is_zero(row[l]))
            .map(|&l| {
                let (m, f) = (Context::local2("jm", i, l), Context::local("jf", l));
                quote!(#m * #f)
            })
            .collect();
        if !products.is_empty() {
            let (u, il) = (Context::local("ju", i), index(i));
            code.extend(quote! {
                let #u = #(#products)+*;
                #out[#il] = #u;
            });
            a_nonzero.push(i);
        }
    }
    (code, a_nonzero)
}

/// `b̃ᵥ − A aᵥ`, the right-hand side of `S μᵥ`, written into `out`: `b̃ᵥ`
/// (`b`) scaled by `D` to match the scaled rows `Â` (unless `scaled`: the
/// terms were), over the nonzeros of `Â` and of `aᵥ` (`a_nonzero`).
fn constraint_rhs(
    g: &Graph,
    d: &Symbolic,
    (a_nonzero, b, scaled): (&[usize], &[Option<TokenStream>], bool),
    out: &TokenStream,
) -> TokenStream {
    let mut code = TokenStream::new();
    for (j, row) in d.rows.iter().enumerate() {
        let products: Vec<TokenStream> = a_nonzero
            .iter()
            .filter(|&&i| !g.is_zero(row[i]))
            .map(|&i| {
                let (a, u) = (Context::local2("ja", j, i), Context::local("ju", i));
                quote!(#a * #u)
            })
            .collect();
        let b = b[j].as_ref().map(|b| {
            if scaled || d.scale[j].is_one() {
                b.clone()
            } else {
                let (s, _) = literal(d.scale[j]);
                quote!(#s * (#b))
            }
        });
        let value = match (&b, products.is_empty()) {
            (Some(b), true) => quote!(#b),
            (Some(b), false) => quote!(#b - (#(#products)+*)),
            (None, false) => quote!(-(#(#products)+*)),
            (None, true) => continue,
        };
        let jl = index(j);
        code.extend(quote! { #out[#jl] = #value; });
    }
    code
}

/// The model's own multipliers `λ = μ D λ̃` that the tangent terms hold,
/// where `acceleration` solved the scaled system for `λ̃`
/// (`crate::equations::mass_inverse::Symbolic`).
fn unscaled_multipliers(d: &Symbolic, gauss: &SymbolicSolve) -> Vec<TokenStream> {
    let mass = d.common_mass.map(|m| gauss.body.factor(m));
    d.scale
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.is_one() || mass.is_some())
        .map(|(j, s)| {
            let lam = Context::local("lam", j);
            // The solve's own `λ̃`, which the scaled terms read.
            let solved = Context::local("lams", j);
            let keep = mass.is_none().then(|| quote! { let #solved = #lam; });
            let value = match (s.is_one(), &mass) {
                (true, Some(m)) => quote!(#m * #lam),
                (false, Some(m)) => {
                    let (s, _) = literal(*s);
                    quote!(#s * #m * #lam)
                }
                (_, None) => {
                    let (s, _) = literal(*s);
                    quote!(#s * #lam)
                }
            };
            quote! { #keep let #lam = #value; }
        })
        .collect()
}

/// `W μᵥ` added into the column's outputs over the nonzeros of `W`: the
/// pattern binding the outputs (`_` for a row of `W` without nonzeros) and
/// the updates.
fn weighted_update(
    d: &Symbolic,
    mu: &[syn::Ident],
    nonzero: impl Fn(Id) -> bool,
    n: usize,
) -> (Vec<TokenStream>, TokenStream) {
    let mut outputs = Vec::with_capacity(n);
    let mut updates = TokenStream::new();
    for (i, row) in d.weighted.iter().enumerate() {
        let products: Vec<TokenStream> = (0..mu.len())
            .filter(|&j| nonzero(row[j]))
            .map(|j| {
                let (w, m) = (Context::local2("jw", i, j), &mu[j]);
                quote!(#w * #m)
            })
            .collect();
        if products.is_empty() {
            outputs.push(quote!(_));
        } else {
            let o = Context::local("jo", i);
            updates.extend(quote! { *#o += #(#products)+*; });
            outputs.push(quote!(#o));
        }
    }
    (outputs, updates)
}
