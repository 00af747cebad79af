//! Code for the generalized-inverse equation of motion (eq. 24–26): the
//! methods that solve it, each a row of [`SOLVES`] (`acceleration`,
//! `constraint_force`, `acceleration_corrected`,
//! `acceleration_moore_penrose`), after the solver they share.
//!
//! The public methods share one private solver, `gauss`, generic over
//! what its caller wants back (`constrained::__private::Finish`: `q̈`
//! alone for the total `acceleration`, `Result<(q̈, Aᵀλ), DynamicsError>`
//! for the trait); it is `#[inline(always)]` and makes `Aᵀλ` only for the
//! callers that use it (a closure the others drop). Where the rank
//! decision is suspect, one out-of-line call into the runtime
//! (`constrained::rank::checked`) verifies or recomputes it. The
//! constraint force is emitted as `Aᵀ λ` rather than `M q̈ − F`, which is the
//! same quantity without the cancellation. What cannot be specialised (the
//! dense solve of a full `M(q)`, the Moore–Penrose form) is one call into
//! the runtime.

use super::context::{Context, Inputs};
use super::mass_inverse;
use crate::model::Level;
use proc_macro2::TokenStream;
use quote::quote;

/// One generated method that solves the equation of motion: a row of
/// [`SOLVES`].
pub struct Solve {
    /// The method's name.
    pub name: &'static str,
    /// Its arguments after `&self`, as `docs/generated.md` writes them.
    // Read only by the test that holds that table to this one.
    #[cfg_attr(not(test), allow(dead_code))]
    pub args: &'static str,
    /// Whether it is `#[inline]`: all but what calls into the runtime.
    inline: bool,
    /// Its documentation, one attribute per line.
    doc: fn(&Context) -> Vec<String>,
    /// Its signature after `(q, qd, t)` and its body.
    emit: fn(&Context) -> Emitted,
}

/// What a row of [`SOLVES`] emits besides its name and docs.
struct Emitted {
    /// Parameters after `(q, qd, t)`, each with its leading comma.
    extra: Option<TokenStream>,
    /// The return type.
    ret: TokenStream,
    /// The body.
    body: TokenStream,
}

/// The generated methods that solve the equation of motion, in the order
/// they are emitted after the solver `gauss`: a new one is a row here, its
/// emitter beside the others below, and a row of the table in
/// `docs/generated.md`.
pub const SOLVES: &[Solve] = &[
    Solve {
        name: "acceleration",
        args: "q, qd, t",
        inline: true,
        doc: |ctx| vec![acceleration_doc(ctx)],
        emit: |ctx| Emitted {
            extra: None,
            ret: solved_type(ctx),
            body: gauss(ctx, None, false),
        },
    },
    Solve {
        name: "constraint_force",
        args: "q, qd, t",
        inline: true,
        doc: |ctx| {
            vec![format!(
                " The constraint force `Fᶜ = M q̈ − F = Aᵀ λ` (the second term of eq. 26). \
                 {}",
                fallibility(ctx)
            )]
        },
        emit: |ctx| Emitted {
            extra: None,
            ret: solved_type(ctx),
            body: gauss(ctx, None, true),
        },
    },
    Solve {
        name: "acceleration_corrected",
        args: "q, qd, t, db",
        inline: true,
        doc: |_| {
            lines(&[
                " The acceleration with `b` replaced by `b + db`: constraint",
                " stabilization (Baumgarte) asks `A q̈ = b − 2α φ̇ − β² φ` of",
                " position-level and `A q̈ = b − γ φ` of velocity-level constraints.",
            ])
        },
        emit: |ctx| {
            let k_vector = ctx.vector(ctx.k);
            Emitted {
                extra: Some(quote!(, db: &#k_vector)),
                ret: solved_type(ctx),
                body: gauss(ctx, Some(quote!(::core::option::Option::Some(db))), false),
            }
        },
    },
    Solve {
        name: "acceleration_moore_penrose",
        args: "q, qd, t",
        inline: false,
        doc: |_| {
            lines(&[
                " The acceleration by the Moore–Penrose form of eq. 24 with",
                " `M = L Lᵀ`: `q̈ = a + L⁻ᵀ (A L⁻ᵀ)⁺ (b − A a)`, by SVD at run time",
                " (singular values below `√rank_tolerance` of the largest count as",
                " zero). Slower than [`acceleration`](Self::acceleration); the same",
                " result wherever the constraints are consistent. For comparison and",
                " for states where the least-squares reading of inconsistent",
                " constraints is wanted.",
            ])
        },
        emit: |ctx| {
            let moore_penrose = ctx.private(quote!(moore_penrose));
            let args = ctx.args(Inputs::States);
            Emitted {
                extra: None,
                ret: ctx.result(ctx.vector(ctx.n), quote!(DynamicsError)),
                body: quote!(#moore_penrose(self, #args)),
            }
        },
    },
];

/// The solver and the methods of [`SOLVES`].
pub(super) fn methods(ctx: &Context) -> TokenStream {
    let solver = mass_inverse::solver(ctx);
    let params = ctx.params(Inputs::States);
    let methods = SOLVES.iter().map(|row| {
        let name = syn::Ident::new(row.name, proc_macro2::Span::call_site());
        let docs = (row.doc)(ctx);
        let inline = row.inline.then(|| quote!(#[inline]));
        let Emitted { extra, ret, body } = (row.emit)(ctx);
        quote! {
            #(#[doc = #docs])*
            #inline
            pub fn #name(&self, #params #extra) -> #ret { #body }
        }
    });
    quote! {
        #solver

        #(#methods)*
    }
}

/// Doc lines as a row's `doc` returns them.
fn lines(lines: &[&str]) -> Vec<String> {
    lines.iter().map(ToString::to_string).collect()
}

/// What `acceleration` and `constraint_force` return: `q̈`-sized, in a
/// `Result` where the solve can fail.
fn solved_type(ctx: &Context) -> TokenStream {
    let vector = ctx.vector(ctx.n);
    if ctx.eq.mass_inverse.fallible() {
        ctx.result(vector, quote!(DynamicsError))
    } else {
        vector
    }
}

/// The call of `gauss` that gives the value wanted (the force where
/// `force`), with `correction` (`None` as tokens where there is none).
/// The total methods of a system with a constant positive definite `M` ask
/// the solver for their value directly (the least-squares answer where it
/// fails: `TotalAcceleration`, `TotalForce`). The fallible ones: `q̈` alone
/// by `FallibleAcceleration` (the force is never made, even where `gauss`
/// is not inlined), the force as the second half of `Fallible`'s pair.
fn gauss(ctx: &Context, correction: Option<TokenStream>, force: bool) -> TokenStream {
    let correction = correction.unwrap_or_else(|| quote!(::core::option::Option::None));
    match (ctx.eq.mass_inverse.fallible(), force) {
        (true, false) => ctx.call_gauss("FallibleAcceleration", correction),
        (true, true) => {
            let call = ctx.call_gauss("Fallible", correction);
            quote!(#call.map(|s| s.1))
        }
        (false, true) => ctx.call_gauss("TotalForce", correction),
        (false, false) => ctx.call_gauss("TotalAcceleration", correction),
    }
}

/// When the solve fails, for the docs of `acceleration` and
/// `constraint_force`.
fn fallibility(ctx: &Context) -> &'static str {
    if ctx.eq.mass_inverse.fallible() {
        "`Err` when `M` is not positive definite at this state (it is not \
         known to be at compile time), or when no acceleration satisfies \
         `A q̈ = b` to working precision (`Unsatisfiable`; see `constrained::rank`). \
         The `ConstrainedSystem` method also turns any non-finite value into \
         `Err(NonFinite)`."
    } else {
        "Total: `M` is constant and positive definite. Where no acceleration \
         satisfies `A q̈ = b` to working precision, the least-squares one (the \
         `ConstrainedSystem` method reports `Err(Unsatisfiable)` instead; see \
         `constrained::rank`)."
    }
}

/// The documentation of `acceleration`.
fn acceleration_doc(ctx: &Context) -> String {
    format!(
        " The acceleration `q̈` by the generalized-inverse equation (Udwadia & \
         Kalaba eq. 24–26): `M q̈ = F + Aᵀ λ` with `(A M⁻¹ Aᵀ) λ = b − A a`, \
         solved with a rank-revealing {{1}}-inverse (see `constrained::inverse`) \
         whose rank decision is checked after the fact (`constrained::rank`). \
         Where `A` loses rank the result is the minimiser of Gauss's principle \
         over the constraints that remain independent (`q̈ = a` where `A = 0`); \
         never NaN for finite input. {}",
        fallibility(ctx)
    )
}

/// The constraint levels as constants of the runtime's enum.
pub(super) fn levels(ctx: &Context) -> Vec<TokenStream> {
    ctx.eq
        .system
        .constraints
        .iter()
        .map(|c| match c.level {
            Level::Position => ctx.path(quote!(ConstraintLevel::Position)),
            Level::Velocity => ctx.path(quote!(ConstraintLevel::Velocity)),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::SOLVES;

    /// Every solve method has a row of the table of generated items in
    /// `docs/generated.md`, with its arguments as generated.
    #[test]
    fn docs_table_lists_every_solve() {
        let docs = include_str!("../../../docs/generated.md");
        let rows: Vec<&str> = docs.lines().filter(|l| l.starts_with("| `")).collect();
        assert!(rows.len() > 20, "table not found");
        for s in SOLVES {
            let item = format!("`{}({})`", s.name, s.args);
            assert!(
                rows.iter().any(|r| r.contains(&item)),
                "docs/generated.md has no row for {item}"
            );
        }
    }
}
