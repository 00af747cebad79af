//! The strategies of applying `M⁻¹` (`crate::equations::mass_inverse::MassInverse`), one
//! module each, every one providing the solver `gauss` (`acceleration` and
//! the trait's `gauss`), the body of `acceleration_jacobian` and the
//! projections' `constraint_step`:
//!
//! - `symbolic`: `M⁻¹` as expressions (`M` diagonal or a numeric
//!   constant);
//! - `factored`: a configuration-dependent `M`, factored in generated code
//!   on its compile-time pattern;
//! - `factored` again for a positive semi-definite `M`, through its
//!   auxiliary mass `M + s A_RᵀA_R` (the solver only: its step is the
//!   runtime's dense one, and so is its Jacobian, whose tangent systems are
//!   those of the actual `M`, but where `gauss` solves the quaternions'
//!   velocity form: its Jacobians, `∂q̈` and `∂λ`, run through that form's
//!   own factors).
//!
//! This module is the only `match` on how `M⁻¹` is applied in `emit`; which
//! solve `gauss` performs was decided in stage 3
//! (`crate::equations::strategy`) and is carried out in `factored`. `step` holds
//! what the strategies' steps share. Below: `super::solve` (the checked
//! value of `gauss`), the emission helpers.

mod factored;
mod step;
mod symbolic;

use super::context::Context;
use crate::equations::mass_inverse::MassInverse;
use proc_macro2::TokenStream;
use quote::quote;

/// The private solver `gauss` behind `acceleration`, `constraint_force`,
/// `acceleration_corrected` and the trait's `gauss`.
pub(super) fn solver(ctx: &Context) -> TokenStream {
    match &ctx.eq.mass_inverse {
        MassInverse::Symbolic(d) => symbolic::solver(ctx, d),
        MassInverse::Factored(f) => factored::solver(ctx, f),
        MassInverse::Auxiliary(f) => factored::solver(ctx, f),
    }
}

/// The body of the `Result`-valued Jacobian (`acceleration_jacobian`, or
/// `try_acceleration_jacobian` where `acceleration` is total); `dense` is
/// the runtime's solve, as an expression of the same type (the whole body
/// where the strategy has no Jacobian of its own).
pub(super) fn jacobian(ctx: &Context, dense: &TokenStream) -> JacobianBody {
    match &ctx.eq.mass_inverse {
        MassInverse::Symbolic(d) => {
            JacobianBody::Value(symbolic::jacobian::jacobian(ctx, d, dense))
        }
        MassInverse::Factored(f) => {
            JacobianBody::InPlace(factored::jacobian::jacobian(ctx, f, dense))
        }
        MassInverse::Auxiliary(f) => match factored::velocity_jacobians(ctx, f) {
            // The velocity form writes `∂q̈` into the caller's `__jac`; its
            // `∂λ`, not asked for, goes to a local.
            Some((_, _, into)) => {
                let args = ctx.args(super::context::Inputs::States);
                let lambdas = ctx.multiplier_jacobians_zero();
                JacobianBody::InPlace(quote! {
                    let mut __lj = #lambdas;
                    self.#into(#args, false, __jac, &mut __lj)
                })
            }
            None => JacobianBody::Value(dense.clone()),
        },
    }
}

/// The body of `acceleration_jacobian` a strategy emits.
pub(super) enum JacobianBody {
    /// A `Result<Jacobians, DynamicsError>`.
    Value(TokenStream),
    /// A `Result<(), DynamicsError>` that writes the Jacobians into
    /// `__jac: &mut Jacobians`, every entry: called with the caller's own,
    /// nothing is copied out of a `Result` and nothing is cleared first
    /// (`acceleration_jacobian_to`).
    InPlace(TokenStream),
}

/// The private methods behind `acceleration_and_multiplier_jacobians`
/// where the strategy solves the tangent systems itself (the velocity
/// form's), the name of the one to call with `(q, qd, t)`, which answers
/// both, and of the one that also takes whether `∂λ` is asked for and the
/// outputs to write into; `None`
/// where the runtime's dense solve does.
pub(super) fn multiplier_jacobians(ctx: &Context) -> Option<(TokenStream, syn::Ident, syn::Ident)> {
    match &ctx.eq.mass_inverse {
        MassInverse::Auxiliary(f) => factored::velocity_jacobians(ctx, f),
        MassInverse::Symbolic(_) | MassInverse::Factored(_) => None,
    }
}

/// The trait method `constraint_step`, or nothing (the trait's default,
/// `None`: the runtime's dense step) for a singular `M` or no constraints.
pub(super) fn step(ctx: &Context) -> TokenStream {
    if ctx.k == 0 {
        return TokenStream::new();
    }
    let body = match &ctx.eq.mass_inverse {
        MassInverse::Symbolic(d) => symbolic::step::step(ctx, d),
        MassInverse::Factored(f) => factored::step::step(ctx, f),
        MassInverse::Auxiliary(_) => return TokenStream::new(),
    };
    step::method(ctx, &body)
}

/// `target` (`__jac`, or `*__jac` where it is a `&mut`:
/// [`JacobianBody::InPlace`]) replaced by the runtime's dense solve
/// `dense` (a `Result`), its error returned: where a strategy's rank
/// decision is suspect.
fn adopt_dense(dense: &TokenStream, target: TokenStream) -> TokenStream {
    quote! {
        match { #dense } {
            ::core::result::Result::Ok(__dense) => #target = __dense,
            ::core::result::Result::Err(__e) => return ::core::result::Result::Err(__e),
        }
    }
}
