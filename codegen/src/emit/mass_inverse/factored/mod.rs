//! Gauss's principle for a configuration-dependent `M(q)`, solved in
//! generated code on compile-time patterns (`crate::equations::mass_inverse::Factored`):
//!
//! 1. `M`, `F`, `A` and `b` as one straight-line body, so that CSE shares
//!    their subexpressions, checked finite;
//! 2. `P M Pᵀ = L D Lᵀ` over `M`'s pattern (a pivot that is not positive
//!    returns `MassNotPositiveDefinite`, as a Cholesky factorization fails);
//!    for a large branched `M`, with each input computed where the
//!    factorization first reads it and the pivots, not `M`'s entries,
//!    checked finite ([`inputs::head`]);
//! 3. the solver `gauss`: `Y = L⁻¹ P Aᵀ` and `z = L⁻¹ P F` by sparse
//!    forward substitution, `S = Yᵀ D⁻¹ Y`, `r = b − Yᵀ D⁻¹ z`, `S`'s
//!    rank-revealing `LDLᵀ` exactly as for a constant `M`
//!    ([`crate::emit::ldlt`]) with the same after-the-fact rank check, and
//!    one back substitution `q̈ = Pᵀ L⁻ᵀ D⁻¹ (z + Y λ)` ([`GramForm`]);
//! 4. the Jacobian and the projections' step, which need `W = M⁻¹ Aᵀ`
//!    itself: `a = M⁻¹ F` and `W`'s columns by sparse substitution, each
//!    touching only what its right-hand side reaches, `S = A W`,
//!    `r = b − A a`.
//!
//! A semi-definite `M` is solved the same way through its auxiliary mass
//! `M + s A_RᵀA_R` and forces `F + s A_Rᵀb_R` ([`auxiliary`]), `A_R` the
//! rows that complete `M`'s rank.
//!
//! The Jacobian ([`jacobian`]) reuses both factorizations: `tangent_rhs`
//! fills the right-hand sides, one column each, and one loop solves every
//! column through `L D Lᵀ` of `M` and of `S`.

mod auxiliary;
mod gram_form;
mod groups;
mod inputs;
pub(in crate::emit) mod jacobian;
mod legs;
mod saddle;
pub(in crate::emit) mod step;
mod velocity;
mod velocity_jacobian;

pub(in crate::emit) use velocity_jacobian::velocity_jacobians;

use crate::emit::chunks::bounded;
use crate::emit::context::Context;
use crate::emit::ldlt::{Rows, Solves, StructuredLdlt};
use crate::emit::solve::{checked_motion, corrected};
use crate::emit::tokens::concat;
use crate::equations::mass_inverse::Factored;
use crate::equations::strategy::Strategy;
use crate::expr::Id;
use gram_form::gram_form;
use inputs::{bind, head, inputs, Head};
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The generated solve up to `λ`, shared by `gauss` and the Jacobian.
pub(super) struct FactoredSolve<'a> {
    /// `M`'s factorization (locals `__m{i}_{j}`, `__ml…`, `__mi…`).
    pub mass: StructuredLdlt<'a>,
    /// `S`'s factorization (locals `__s{i}_{j}`, `__l…`, `__inv…`).
    pub gram: StructuredLdlt<'a>,
    /// The code from the arguments to `λ` (`__lam{j}`): `M`, `F`, `A`, `b`,
    /// the finiteness check, both factorizations and solves.
    pub to_multipliers: TokenStream,
    /// `q̈ᵢ = aᵢ + Σⱼ Wᵢⱼ λⱼ`, one expression per coordinate.
    pub acceleration: Vec<TokenStream>,
    /// `Fᶜᵢ = Σⱼ Aⱼᵢ λⱼ`.
    pub force: Vec<TokenStream>,
}

/// `Σ x·y` over the given pairs, `T::zero()` for none.
fn dot(pairs: Vec<(TokenStream, TokenStream)>) -> TokenStream {
    if pairs.is_empty() {
        return quote!(T::zero());
    }
    let terms = pairs.into_iter().map(|(x, y)| quote!(#x * #y));
    quote!(#(#terms)+*)
}

/// How much of the solve is built.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Scope {
    /// All of it, to `λ`. `gauss`: the solver `gauss`'s code, with the
    /// `b + db` of `acceleration_corrected`, errors through its `Finish`;
    /// else the Jacobian's, errors as `Err(DynamicsError)`.
    Dynamics { gauss: bool },
    /// `M`'s factor, `W` and `S`'s factor only (the projections' step);
    /// an error is `None`.
    ConstraintSpace,
}

impl<'a> FactoredSolve<'a> {
    /// The solve to `λ`, for the solver `gauss` or (`gauss` false) the
    /// Jacobian.
    pub(super) fn new(ctx: &'a Context, f: &'a Factored, gauss: bool) -> Self {
        Self::build(ctx, f, Scope::Dynamics { gauss }, &[])
    }

    /// The Jacobian's solve to `λ`, with `extra` expressions bound under
    /// their names in the same body as `M`, `F`, `A` and `b` (the tangent
    /// terms, which share their sines and cosines).
    pub(super) fn with_extra(ctx: &'a Context, f: &'a Factored, extra: &[(Ident, Id)]) -> Self {
        Self::build(ctx, f, Scope::Dynamics { gauss: false }, extra)
    }

    /// `M`'s factor, `W = M⁻¹ Aᵀ` (locals `__w{i}_{j}`) and `S`'s factor,
    /// in a function returning `Option` (no forces, no `b`).
    pub(super) fn constraint_space(ctx: &'a Context, f: &'a Factored) -> Self {
        Self::build(ctx, f, Scope::ConstraintSpace, &[])
    }

    fn build(ctx: &'a Context, f: &'a Factored, scope: Scope, extra: &[(Ident, Id)]) -> Self {
        let k = ctx.k;
        let dynamics = matches!(scope, Scope::Dynamics { .. });
        let correction = matches!(scope, Scope::Dynamics { gauss: true });
        let bail = |error: TokenStream| match scope {
            Scope::Dynamics { gauss: true } => ctx.gauss_error(error),
            Scope::Dynamics { gauss: false } => {
                let error = ctx.path(error);
                quote!(return ::core::result::Result::Err(#error);)
            }
            Scope::ConstraintSpace => quote!(return ::core::option::Option::None;),
        };
        // `gauss` without constraints solves with M once (for `a`); with
        // them every pivot's reciprocal is read (`D⁻¹ Y`, the back
        // substitution), as by the Jacobian's solve per column.
        let once = correction && k == 0;
        let solves = if once { Solves::Once } else { Solves::Many };
        // The auxiliary mass of `gauss`: a pivot that is not positive hands
        // the solve to the runtime (`auxiliary::dense_answer`).
        let mass_bail = match (&f.auxiliary, scope) {
            (Some(_), Scope::Dynamics { gauss: true }) => auxiliary::dense_answer(ctx),
            _ => bail(quote!(DynamicsError::MassNotPositiveDefinite)),
        };
        let gram = StructuredLdlt::gram(&f.gram);
        let (mass, head) = head(
            ctx,
            f,
            (dynamics, correction, extra),
            (solves, mass_bail),
            &bail,
        );
        if scope == (Scope::Dynamics { gauss: true }) && k > 0 {
            return Self::solver(ctx, f, (mass, gram), head);
        }
        Self::column_solve(ctx, f, (mass, gram), head, scope)
    }

    /// Every solve but `gauss`'s with constraints, after `head` (the
    /// inputs, their check, the auxiliary mass and `M`'s factorization):
    /// `a = M⁻¹ F`, `W = M⁻¹ Aᵀ` column by column, `S = A W` and
    /// `r = b − A a`, and `S λ = r`; only `W` and `S`'s factor for
    /// [`Scope::ConstraintSpace`].
    fn column_solve(
        ctx: &'a Context,
        f: &'a Factored,
        (mass, gram): (StructuredLdlt<'a>, StructuredLdlt<'a>),
        head: Head,
        scope: Scope,
    ) -> Self {
        let k = ctx.k;
        let dynamics = matches!(scope, Scope::Dynamics { .. });
        let correction = matches!(scope, Scope::Dynamics { gauss: true });
        // a = M⁻¹ F.
        let unconstrained: Vec<Ident> = (0..ctx.n).map(|i| Context::local("ua", i)).collect();
        let (solve_a, a_bound) = mass.solve_sparse(&forces_rhs(ctx, f), "ay", &unconstrained);
        let solve_w = weighted_columns(ctx, f, &mass);
        let gram_entries = gram_entries(ctx, f, &gram);
        let residuals: Vec<Ident> = (0..k).map(|r| Context::local("r", r)).collect();
        let (residual_code, _) =
            residual_code(ctx, &residuals, &b_locals(ctx), (&a_bound, &unconstrained));
        // (The auxiliary prelude corrected `b` itself.)
        let corrected =
            (correction && k > 0 && f.auxiliary.is_none()).then(|| corrected(&residuals, &[]));
        let multipliers: Vec<Ident> = (0..k).map(|j| Context::local("lam", j)).collect();
        let factor_gram = gram.factor();
        let solve_gram = gram.solve(&residuals, "y", &multipliers);
        let (acceleration, force) = motion(ctx, f, &a_bound, &unconstrained, &multipliers);
        let to_multipliers = head.then(if dynamics {
            concat([
                solve_a,
                solve_w,
                gram_entries,
                residual_code,
                corrected.unwrap_or_default(),
                factor_gram,
                solve_gram,
            ])
        } else {
            concat([solve_w, gram_entries, factor_gram])
        });
        FactoredSolve {
            mass,
            gram,
            to_multipliers,
            acceleration,
            force,
        }
    }

    /// `gauss`'s solve with constraints, after `head` (the inputs, their
    /// check, the auxiliary mass and `M`'s factorization): [`GramForm`].
    fn solver(
        ctx: &'a Context,
        f: &'a Factored,
        (mass, gram): (StructuredLdlt<'a>, StructuredLdlt<'a>),
        head: Head,
    ) -> Self {
        let k = ctx.k;
        let lean = gram_form(ctx, f, &mass, &gram);
        // (The auxiliary prelude corrected `b` itself.)
        let corrected = f
            .auxiliary
            .is_none()
            .then(|| corrected(&lean.residuals, &[]));
        let multipliers: Vec<Ident> = (0..k).map(|j| Context::local("lam", j)).collect();
        let factor_gram = gram.factor();
        let solve_gram = gram.solve(&lean.residuals, "y", &multipliers);
        let (back, acceleration) = lean.back_substitution(ctx, &mass, &multipliers);
        let to_gram = lean.code;
        let force = constraint_force(ctx, &multipliers);
        FactoredSolve {
            to_multipliers: head.then(concat([
                to_gram,
                corrected.unwrap_or_default(),
                factor_gram,
                solve_gram,
                back,
            ])),
            mass,
            gram,
            acceleration,
            force,
        }
    }
}

/// The right-hand side of `a = M⁻¹ F`: the locals `__f{i}` that can be
/// nonzero (of `F`, or of the auxiliary `F + s Aᵀb`).
fn forces_rhs(ctx: &Context, f: &Factored) -> Vec<Option<TokenStream>> {
    let g = &ctx.eq.system.graph;
    let nonzero: Vec<bool> = if let Some(aux) = &f.auxiliary {
        auxiliary::forces_nonzero(ctx, aux)
    } else {
        ctx.eq
            .system
            .forces
            .iter()
            .map(|&e| !g.is_zero(e))
            .collect()
    };
    nonzero
        .iter()
        .enumerate()
        .map(|(i, &nz)| {
            nz.then(|| {
                let name = Context::local("f", i);
                quote!(#name)
            })
        })
        .collect()
}

/// Row `j` of `A` as a right-hand side (a column of `Aᵀ`): its locals,
/// `None` where structurally zero.
fn a_column(ctx: &Context, j: usize) -> Vec<Option<TokenStream>> {
    let g = &ctx.eq.system.graph;
    ctx.eq.a[j]
        .iter()
        .enumerate()
        .map(|(i, &e)| (!g.is_zero(e)).then(|| a_entry(j, i)))
        .collect()
}

/// The local `__a{r}_{i}` holding entry `(r, i)` of `A`.
fn a_entry(r: usize, i: usize) -> TokenStream {
    let name = Context::local2("a", r, i);
    quote!(#name)
}

/// The columns of `W = M⁻¹ Aᵀ` (locals `__w{i}_{j}`), by sparse solves
/// with `M`'s factor.
fn weighted_columns(ctx: &Context, f: &Factored, mass: &StructuredLdlt) -> TokenStream {
    let mut solve_w = TokenStream::new();
    for j in 0..ctx.k {
        let out: Vec<Ident> = (0..ctx.n).map(|i| Context::local2("w", i, j)).collect();
        let (code, bound) = mass.solve_sparse(&a_column(ctx, j), &format!("wy{j}x"), &out);
        debug_assert!((0..ctx.n).all(|i| bound[i] == f.weighted[i][j]));
        solve_w.extend(code);
    }
    solve_w
}

/// `S = A W` over its pattern.
fn gram_entries(ctx: &Context, f: &Factored, gram: &StructuredLdlt) -> TokenStream {
    let g = &ctx.eq.system.graph;
    let mut gram_entries = TokenStream::new();
    for (i, row) in ctx.eq.a.iter().enumerate() {
        for j in 0..=i {
            if f.gram.nonzero[i][j] {
                let pairs = (0..ctx.n)
                    .filter(|&l| !g.is_zero(row[l]) && f.weighted[l][j])
                    .map(|l| {
                        let w = Context::local2("w", l, j);
                        (a_entry(i, l), quote!(#w))
                    })
                    .collect();
                let (name, value) = (gram.entry(i, j), dot(pairs));
                gram_entries.extend(quote! { let #name = #value; });
            }
        }
    }
    gram_entries
}

/// `r = b − A a` into the locals `residuals`, over `a`'s nonzeros
/// (`a_bound`) and `b`'s (`None` a structural zero). Returns the code and
/// which residuals it binds (the others are zero).
fn residual_code(
    ctx: &Context,
    residuals: &[Ident],
    b: &[Option<TokenStream>],
    (a_bound, unconstrained): (&[bool], &[Ident]),
) -> (TokenStream, Vec<bool>) {
    let (g, a) = (&ctx.eq.system.graph, &ctx.eq.a);
    let mut residual_code = TokenStream::new();
    let mut bound = vec![false; residuals.len()];
    for (r, name) in residuals.iter().enumerate() {
        let pairs: Vec<_> = (0..ctx.n)
            .filter(|&l| !g.is_zero(a[r][l]) && a_bound[l])
            .map(|l| {
                let u = &unconstrained[l];
                (a_entry(r, l), quote!(#u))
            })
            .collect();
        let value = match (&b[r], pairs.is_empty()) {
            (None, true) => continue,
            (Some(b), true) => quote!(#b),
            (Some(b), false) => {
                let aa = dot(pairs);
                quote!(#b - (#aa))
            }
            (None, false) => {
                let aa = dot(pairs);
                quote!(-(#aa))
            }
        };
        bound[r] = true;
        residual_code.extend(quote! { let #name = #value; });
    }
    (residual_code, bound)
}

/// The locals `__b{r}` as right-hand sides, none structurally zero.
fn b_locals(ctx: &Context) -> Vec<Option<TokenStream>> {
    (0..ctx.k)
        .map(|r| {
            let b = Context::local("b", r);
            Some(quote!(#b))
        })
        .collect()
}

/// `q̈ᵢ = aᵢ + Σⱼ Wᵢⱼ λⱼ`, one expression per coordinate, over `a`'s
/// nonzeros (`a_bound`) and the multipliers' (`lambda_bound`); `None`
/// where no term is left.
fn accelerations(
    f: &Factored,
    (a_bound, unconstrained): (&[bool], &[Ident]),
    (lambda_bound, multipliers): (&[bool], &[Ident]),
) -> Vec<Option<TokenStream>> {
    (0..unconstrained.len())
        .map(|i| {
            let pairs: Vec<(TokenStream, TokenStream)> = (0..multipliers.len())
                .filter(|&j| f.weighted[i][j] && lambda_bound[j])
                .map(|j| {
                    let (w, lam) = (Context::local2("w", i, j), &multipliers[j]);
                    (quote!(#w), quote!(#lam))
                })
                .collect();
            let u = &unconstrained[i];
            match (a_bound[i], pairs.is_empty()) {
                (true, true) => Some(quote!(#u)),
                (true, false) => {
                    let wl = dot(pairs);
                    Some(quote!(#u + (#wl)))
                }
                (false, true) => None,
                (false, false) => Some(dot(pairs)),
            }
        })
        .collect()
}

/// `q̈ᵢ = aᵢ + Σⱼ Wᵢⱼ λⱼ` and `Fᶜᵢ = Σⱼ Aⱼᵢ λⱼ`, one expression per
/// coordinate each.
fn motion(
    ctx: &Context,
    f: &Factored,
    a_bound: &[bool],
    unconstrained: &[Ident],
    multipliers: &[Ident],
) -> (Vec<TokenStream>, Vec<TokenStream>) {
    let every = vec![true; ctx.k];
    let acceleration = accelerations(f, (a_bound, unconstrained), (&every, multipliers))
        .into_iter()
        .map(|e| e.unwrap_or_else(|| quote!(T::zero())))
        .collect();
    (acceleration, constraint_force(ctx, multipliers))
}

/// `Fᶜᵢ = Σⱼ Aⱼᵢ λⱼ`, one expression per coordinate.
fn constraint_force(ctx: &Context, multipliers: &[Ident]) -> Vec<TokenStream> {
    let (g, a) = (&ctx.eq.system.graph, &ctx.eq.a);
    (0..ctx.n)
        .map(|i| {
            dot((0..ctx.k)
                .filter(|&r| !g.is_zero(a[r][i]))
                .map(|r| {
                    let lam = &multipliers[r];
                    (a_entry(r, i), quote!(#lam))
                })
                .collect())
        })
        .collect()
}

/// `gauss` for a configuration-dependent `M`.
pub(in crate::emit) fn solver(ctx: &Context, f: &Factored) -> TokenStream {
    // The strategy was decided in stage 3; this carries it out.
    let strategy = ctx.eq.strategy();
    match (strategy, &f.velocity, &f.saddle) {
        (Strategy::Legs | Strategy::VelocitySaddle, Some(v), _) => {
            let legs = f.legs.as_ref().filter(|_| strategy == Strategy::Legs);
            return velocity::solver(ctx, v, legs);
        }
        (Strategy::Saddle, _, Some(structure)) => return saddle::solver(ctx, f, structure),
        _ => {}
    }
    let gauss = FactoredSolve::new(ctx, f, true);
    let acc = ctx.vector_value(gauss.acceleration.iter().cloned());
    let force = ctx.vector_value(gauss.force.iter().cloned());
    // The rank decision, checked after the fact, as for a constant M.
    let lambda: Vec<TokenStream> = (0..ctx.k)
        .map(|j| {
            let l = Context::local("lam", j);
            quote!(#l)
        })
        .collect();
    // A redundant set's λ: the least norm, from S's own factors.
    let minimum_norm = (ctx.generic_rank < ctx.k).then(|| {
        let lam: Vec<Ident> = (0..ctx.k).map(|j| Context::local("lam", j)).collect();
        let g = &ctx.eq.system.graph;
        let entry = |r: usize, i: usize| (!g.is_zero(ctx.eq.a[r][i])).then(|| a_entry(r, i));
        let a = Rows {
            coordinates: ctx.n,
            entry: &entry,
        };
        let (code, rows) = gauss.gram.minimum_norm(&lam, &[], &a);
        quote!({ #code [#(#rows),*] })
    });
    let value = checked_motion(
        ctx,
        Some(gauss.gram.suspect(ctx.generic_rank)),
        (&acc, &force),
        &lambda,
        None,
        None,
        minimum_norm,
    );
    // A robot's solve is thousands of `let`s: nested no deeper than a block.
    let to_multipliers = bounded(gauss.to_multipliers.clone(), &value);
    let signature = ctx.gauss_signature();
    let doc = format!(
        " `(q̈, Aᵀλ)` of Gauss's principle, shared by `acceleration`,\n \
         `constraint_force` and `acceleration_corrected` (`b + correction`),\n \
         as `__F` makes it; {}",
        strategy.describe()
    );
    quote! {
        #[doc = #doc]
        #[inline(always)]
        #signature {
            #to_multipliers
            #value
        }
    }
}
