//! A positive semi-definite `M` solved through Udwadia & Schutte's
//! auxiliary system (`crate::equations::mass_inverse::Auxiliary`): the
//! factored solve of [`super`] with `M + s A_RᵀA_R` for `M` and
//! `F + s A_Rᵀb_R` for `F`, `A_R` the rows of `A` that complete `M`'s rank
//! (a quaternion's norm; the feet of a legged robot stay out of it). The
//! model's `M` and `F` are bound under their own names (`__mq{i}_{j}`,
//! `__fq{i}`) and checked finite, `A_RᵀA_R` as `__na{i}_{j}`; this module
//! forms the scale and the auxiliary entries under the names the
//! factorization reads (`__m{i}_{j}`, `__f{i}`).
//!
//! `s = tr M / ‖A_R‖²_F` (`‖A_R‖²_F = tr A_RᵀA_R`); where either is below
//! the safe minimum (underflow, or zero), or where a pivot of the
//! factorization is not positive, the runtime's dense solve (all rows)
//! answers instead ([`dense_answer`]). With `A q̈ = b`,
//! `M q̈ + s A_Rᵀ(A_R q̈ − b_R) = F + Aᵀλ` is the actual system's
//! `M q̈ = F + Aᵀλ`: the auxiliary multipliers are the actual ones, provided
//! `b` carries the correction of `acceleration_corrected` before it enters
//! `F + s A_Rᵀb_R` (else `Aᵀλ` would differ from `M q̈ − F` by
//! `s A_Rᵀ db_R`). So the correction is added to `b` here, not to the
//! residual.

use crate::emit::context::{Context, Inputs};
use crate::emit::ldlt::StructuredLdlt;
use crate::emit::solve::corrected;
use crate::equations::mass_inverse::{Auxiliary, Factored};
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The local holding entry `(i, j)` (i ≥ j) of the model's `M`.
fn model_mass(i: usize, j: usize) -> Ident {
    Context::local2("mq", i, j)
}

/// The local holding entry `(i, j)` (i ≥ j) of `AᵀA`.
fn normal(i: usize, j: usize) -> Ident {
    Context::local2("na", i, j)
}

/// The locals bound from the model's expressions: `M`'s lower nonzeros,
/// `F` (with `dynamics`), then `AᵀA`'s lower nonzeros; and how many are
/// `M` and `F` (the finiteness check reads them, as the runtime checks
/// `M` and `F`).
pub(super) fn named_mass_and_forces(
    ctx: &Context,
    aux: &Auxiliary,
    dynamics: bool,
) -> (Vec<(Ident, Id)>, usize) {
    let sys = &ctx.eq.system;
    let g = &sys.graph;
    let mut named = Vec::new();
    for i in 0..ctx.n {
        for j in 0..=i {
            if !g.is_zero(sys.mass[i][j]) {
                named.push((model_mass(i, j), sys.mass[i][j]));
            }
        }
    }
    if dynamics {
        for (i, &e) in sys.forces.iter().enumerate() {
            named.push((Context::local("fq", i), e));
        }
    }
    let mass_and_forces = named.len();
    for i in 0..ctx.n {
        for j in 0..=i {
            if !g.is_zero(aux.normal[i][j]) {
                named.push((normal(i, j), aux.normal[i][j]));
            }
        }
    }
    (named, mass_and_forces)
}

/// Which entries of `F + s A_Rᵀb_R` can be nonzero.
pub(super) fn forces_nonzero(ctx: &Context, aux: &Auxiliary) -> Vec<bool> {
    let g = &ctx.eq.system.graph;
    (0..ctx.n)
        .map(|i| {
            !g.is_zero(ctx.eq.system.forces[i])
                || aux.rows.iter().any(|&r| !g.is_zero(ctx.eq.a[r][i]))
        })
        .collect()
}

/// `Σ terms`, `T::zero()` for none.
fn sum(terms: Vec<TokenStream>) -> TokenStream {
    if terms.is_empty() {
        quote!(T::zero())
    } else {
        quote!(#(#terms)+*)
    }
}

/// The code between the finiteness check and `M`'s factorization: `b +
/// db` (with `correct`, `gauss`'s correction), the scale `__saux`, the
/// auxiliary mass's entries over the factored pattern and (with
/// `dynamics`) the auxiliary forces.
pub(super) fn prelude(
    ctx: &Context,
    f: &Factored,
    mass: &StructuredLdlt,
    dynamics: bool,
    correct: bool,
) -> TokenStream {
    // `b + db` rebinding the locals `__b{r}` where `gauss` is given a
    // correction.
    let correction = (correct && ctx.k > 0).then(|| {
        let b: Vec<Ident> = (0..ctx.k).map(|r| Context::local("b", r)).collect();
        corrected(&b, &[])
    });
    let (trace, norm) = traces(ctx, f);
    let entries = auxiliary_mass(ctx, f, mass);
    let forces = match (&f.auxiliary, dynamics) {
        (Some(aux), true) => Some(auxiliary_forces(ctx, aux)),
        _ => None,
    };
    let safe_minimum = ctx.private(quote!(safe_minimum));
    let dense = dense_answer(ctx);
    quote! {
        #correction
        let __trace = #trace;
        let __norm = #norm;
        // Underflowed (a state near zero: the fault matrix's tiny one, where
        // A and M are ~1e-310): no scale or pivot of the auxiliary system can
        // be trusted, and the runtime's dense solve, which checks its rank
        // decision after the fact, answers.
        let __safe = #safe_minimum::<T>();
        if !(__trace >= __safe && __norm >= __safe) {
            #dense
        }
        let __saux = __trace / __norm;
        #entries
        #forces
    }
}

/// Whether entry `(i, j)` of `A_RᵀA_R` can be nonzero.
fn normal_nonzero(ctx: &Context, f: &Factored, i: usize, j: usize) -> bool {
    let g = &ctx.eq.system.graph;
    f.auxiliary
        .as_ref()
        .is_some_and(|x| !g.is_zero(x.normal[i][j]))
}

/// `tr M` and `‖A_R‖²_F = tr A_RᵀA_R`, the scale's numerator and
/// denominator, over the diagonals' nonzeros.
fn traces(ctx: &Context, f: &Factored) -> (TokenStream, TokenStream) {
    let sys = &ctx.eq.system;
    let trace = sum((0..ctx.n)
        .filter(|&i| !sys.graph.is_zero(sys.mass[i][i]))
        .map(|i| {
            let m = model_mass(i, i);
            quote!(#m)
        })
        .collect());
    let norm = sum((0..ctx.n)
        .filter(|&i| normal_nonzero(ctx, f, i, i))
        .map(|i| {
            let x = normal(i, i);
            quote!(#x)
        })
        .collect());
    (trace, norm)
}

/// The auxiliary mass `M + s A_RᵀA_R` over the factored pattern, under the
/// names the factorization reads.
fn auxiliary_mass(ctx: &Context, f: &Factored, mass: &StructuredLdlt) -> TokenStream {
    let sys = &ctx.eq.system;
    let mut entries = TokenStream::new();
    for i in 0..ctx.n {
        for j in 0..=i {
            if !f.mass.nonzero[i][j] {
                continue;
            }
            let (m, x) = (model_mass(i, j), normal(i, j));
            let value = match (
                !sys.graph.is_zero(sys.mass[i][j]),
                normal_nonzero(ctx, f, i, j),
            ) {
                (true, true) => quote!(#m + __saux * #x),
                (true, false) => quote!(#m),
                (false, _) => quote!(__saux * #x),
            };
            let name = mass.entry(i, j);
            entries.extend(quote! { let #name = #value; });
        }
    }
    entries
}

/// The runtime's dense solve (with every row of `A`) as `gauss`'s answer:
/// where the auxiliary system underflowed, or where a pivot of its
/// generated factorization is not positive (`M + s A_RᵀA_R` not positive
/// definite at that state, which the runtime's rank-checked solve
/// handles, or reports).
pub(super) fn dense_answer(ctx: &Context) -> TokenStream {
    let gauss_dense = ctx.private(quote!(gauss_dense));
    let args = ctx.args(Inputs::States);
    quote! {
        let __motion = #gauss_dense(self, #args, correction);
        return __F::settle(self, #args, correction, __motion);
    }
}

/// `F + s Aᵀb` into the locals `__f{i}` (those that can be nonzero).
fn auxiliary_forces(ctx: &Context, aux: &Auxiliary) -> TokenStream {
    let sys = &ctx.eq.system;
    let g = &sys.graph;
    let mut code = TokenStream::new();
    for (i, nonzero) in forces_nonzero(ctx, aux).into_iter().enumerate() {
        if !nonzero {
            continue;
        }
        let products: Vec<TokenStream> = aux
            .rows
            .iter()
            .filter(|&&r| !g.is_zero(ctx.eq.a[r][i]))
            .map(|&r| {
                let (a, b) = (Context::local2("a", r, i), Context::local("b", r));
                quote!(#a * #b)
            })
            .collect();
        let own = (!g.is_zero(sys.forces[i])).then(|| Context::local("fq", i));
        let value = match (own, products.is_empty()) {
            (Some(fq), true) => quote!(#fq),
            (Some(fq), false) => quote!(#fq + __saux * (#(#products)+*)),
            (None, _) => quote!(__saux * (#(#products)+*)),
        };
        let name = Context::local("f", i);
        code.extend(quote! { let #name = #value; });
    }
    code
}
