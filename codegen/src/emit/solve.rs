//! What every strategy's solve `gauss` shares: the value it returns with
//! the rank decision checked after the fact (`checked_motion`) and the
//! Baumgarte correction of `b` (`corrected`). Below the strategies
//! (`super::mass_inverse`), above only the emission helpers.

use super::body::literal;
use super::context::Context;
use crate::expr::num::Num;
use proc_macro2::TokenStream;
use quote::quote;

/// The two paths' own code before `gauss`'s value, where the rank check
/// comes before `λ` (a scalar `S`): `(suspect, fast)`.
pub(in crate::emit) type PathCode = (TokenStream, TokenStream);

/// `gauss`'s value `(q̈, Aᵀλ)` as its `Finish` makes it, with the rank
/// decision `suspect` (of the factorization of `S`: `None` where the solve
/// took none) checked after the fact
/// (`constrained::rank`): where fewer rows than the generic rank were kept,
/// the runtime verifies the dropped ones and recomputes if they are
/// violated. `also` is a further condition for that check; `paths`, code
/// each path runs first; `minimum_norm`, a redundant set's minimum-norm
/// `λ` as an expression (`None`: the runtime solves for it).
pub(in crate::emit) fn checked_motion(
    ctx: &Context,
    suspect: Option<TokenStream>,
    (acc, force): (&TokenStream, &TokenStream),
    multipliers: &[TokenStream],
    also: Option<TokenStream>,
    paths: Option<PathCode>,
    minimum_norm: Option<TokenStream>,
) -> TokenStream {
    // The force as a closure that only the callers wanting it call, so
    // that `acceleration` never computes it.
    if ctx.k == 0 {
        return quote!(__F::stands(#acc, move || #force));
    }
    // λ where the fast path's rank decision stands, as a closure only
    // `Multiplied` calls: the unique λ where the model's rows are
    // independent (generic rank K); for a redundant set, whose λ are not
    // unique, the minimum norm from the solve's own factors where the
    // strategy writes it (`minimum_norm`), else the runtime's.
    let lambda = if ctx.generic_rank == ctx.k {
        Some(quote!([#(#multipliers),*]))
    } else {
        minimum_norm
    };
    let Some(suspect) = suspect else {
        // No rank decision was taken (every row kept, or the solve handed
        // to the runtime): λ stands as it is.
        let lambda = quote!([#(#multipliers),*]);
        return quote! {
            __F::stands_with(#acc, move || #force, move || ::core::option::Option::Some(#lambda))
        };
    };
    let suspect = match also {
        Some(also) => quote!((#suspect) | #also),
        None => suspect,
    };
    let checked = ctx.private(quote!(checked));
    // The runtime's check of `__acc`, returning its recomputation.
    let recheck = quote! {
        if let ::core::option::Option::Some(__recomputed) =
            #checked(self, q, qd, t, correction, __acc)
        {
            return __F::settle(self, q, qd, t, correction, __recomputed);
        }
    };
    let checked = Checked {
        acc,
        force,
        lambda,
        suspect,
        recheck,
    };
    // Two shapes, each the faster where it is used (compared by
    // scripts/compare_acceleration.sh). Neither returns the runtime's
    // answer through a generic call taking the force as a closure: the
    // closure's captures would stay alive to the check and slow the fast
    // path.
    if ctx.k > 1 {
        merged(checked)
    } else {
        apart(checked, paths.unwrap_or_default())
    }
}

/// The pieces of a value whose rank decision is checked after the fact.
struct Checked<'a> {
    /// `q̈`.
    acc: &'a TokenStream,
    /// `Aᵀλ`.
    force: &'a TokenStream,
    /// Every row's λ, where the fast path keeps them all.
    lambda: Option<TokenStream>,
    /// Whether the rank decision is suspect.
    suspect: TokenStream,
    /// The runtime's check of `__acc`, returning its recomputation.
    recheck: TokenStream,
}

/// k ≥ 2: `q̈` bound once and the check merging back into the fast path.
fn merged(c: Checked) -> TokenStream {
    let Checked {
        acc,
        force,
        lambda,
        suspect,
        recheck,
    } = c;
    // The closure decides again whether a row was dropped: only
    // `Multiplied` calls it, and the fast path stays as it was.
    let stands = match lambda {
        Some(lambda) => quote! {
            __F::stands_with(__acc, move || #force, move || {
                if #suspect {
                    ::core::option::Option::None
                } else {
                    ::core::option::Option::Some(#lambda)
                }
            })
        },
        None => quote!(__F::stands(__acc, move || #force)),
    };
    quote! {
        let __acc = #acc;
        if #suspect {
            #recheck
        }
        #stands
    }
}

/// k = 1: the suspect path complete in its own branch, with its own `q̈`
/// and return, so that nothing of the fast path lives across the runtime
/// call and the fast path keeps no stack frame; `paths`, the code each
/// path runs first.
fn apart(c: Checked, (suspect_code, fast_code): PathCode) -> TokenStream {
    let Checked {
        acc,
        force,
        lambda,
        suspect,
        recheck,
    } = c;
    let stands = match lambda {
        Some(lambda) => quote! {
            __F::stands_with(#acc, move || #force, move || ::core::option::Option::Some(#lambda))
        },
        None => quote!(__F::stands(#acc, move || #force)),
    };
    quote! {
        if #suspect {
            #suspect_code
            let __acc = #acc;
            #recheck
            return __F::stands(__acc, move || #force);
        }
        #fast_code
        #stands
    }
}

/// `r + D db` where `gauss` was given a correction `db` (Baumgarte), over
/// the locals holding `r`; `scale` is the row scaling `D` of the system
/// solved (`crate::equations::mass_inverse::Symbolic`), empty for none.
pub(in crate::emit) fn corrected(residuals: &[syn::Ident], scale: &[Num]) -> TokenStream {
    let terms: Vec<TokenStream> = correction_locals(residuals.len())
        .iter()
        .enumerate()
        .map(|(i, db)| match scale.get(i) {
            Some(&s) if !s.is_one() => {
                let (s, _) = literal(s);
                quote!(#s * #db)
            }
            _ => quote!(#db),
        })
        .collect();
    corrected_by(residuals, &terms)
}

/// The locals `__db{i}` of a correction's entries, as [`corrected_by`]
/// binds them.
pub(in crate::emit) fn correction_locals(k: usize) -> Vec<syn::Ident> {
    (0..k).map(|i| Context::local("db", i)).collect()
}

/// `r + term` where `gauss` was given a correction `db`, each `term`
/// written over the locals of [`correction_locals`].
pub(in crate::emit) fn corrected_by(
    residuals: &[syn::Ident],
    terms: &[TokenStream],
) -> TokenStream {
    let d = correction_locals(residuals.len());
    quote! {
        let (#(#residuals,)*) = match correction {
            ::core::option::Option::Some(__db) => {
                let [[#(#d),*]] = __db.data.0;
                (#(#residuals + #terms,)*)
            }
            ::core::option::Option::None => (#(#residuals,)*),
        };
    }
}
