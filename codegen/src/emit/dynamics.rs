//! The methods that evaluate the model rather than solve it: inverse
//! dynamics and the generalized gravity of a system with bodies, and the
//! energies of a system given by energies or bodies. Each is plain, or a
//! `Result` that is `Err(NonFinite)` where a value overflows, by the same
//! rule as `acceleration` (`super::motion::fallible`).

use super::body::Body;
use super::context::Context;
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::quote;

/// The arguments a method takes.
#[derive(Clone, Copy)]
enum Args {
    /// `(q, t)`.
    Positions,
    /// `(q, qd, t)`.
    States,
    /// `(q, qd, qdd, t)`.
    Accelerations,
}

fn params(ctx: &Context, args: Args) -> TokenStream {
    let v = ctx.vector(ctx.n);
    match args {
        Args::Positions => quote! { q: &#v, t: T },
        Args::States => quote! { q: &#v, qd: &#v, t: T },
        Args::Accelerations => quote! { q: &#v, qd: &#v, qdd: &#v, t: T },
    }
}

/// One method returning `entries` as a vector, or `entries[0]` as a
/// scalar when `scalar`.
fn method(
    ctx: &Context,
    name: TokenStream,
    doc: &str,
    args: Args,
    entries: &[Id],
    scalar: bool,
) -> TokenStream {
    let body = Body::new(ctx.eq, entries);
    let preamble = body.preamble();
    let (value, ok) = if scalar {
        (body.expr(entries[0]), quote!(T))
    } else {
        (
            ctx.vector_value(entries.iter().map(|&e| body.expr(e))),
            ctx.vector(entries.len()),
        )
    };
    let params = params(ctx, args);
    if ctx.eq.gauss.fallible() {
        let ret = ctx.result(ok, quote!(DynamicsError));
        let non_finite = ctx.path(quote!(DynamicsError::NonFinite));
        let finite = if scalar {
            quote!(__value.is_finite())
        } else {
            quote!(__value.iter().all(|__x| __x.is_finite()))
        };
        let doc = format!("{doc}\n\n`Err(NonFinite)` where a value is not finite (as `acceleration`, this system's methods return `Result`).");
        quote! {
            #[doc = #doc]
            #[inline]
            pub fn #name(&self, #params) -> #ret {
                #preamble
                let __value = #value;
                if #finite {
                    ::core::result::Result::Ok(__value)
                } else {
                    ::core::result::Result::Err(#non_finite)
                }
            }
        }
    } else {
        quote! {
            #[doc = #doc]
            #[inline]
            pub fn #name(&self, #params) -> #ok {
                #preamble
                #value
            }
        }
    }
}

/// The methods of this module that the system has.
pub(super) fn methods(ctx: &Context) -> TokenStream {
    let sys = &ctx.eq.system;
    let mut out = TokenStream::new();
    if let Some(b) = &sys.bodies {
        out.extend(method(
            ctx,
            quote!(inverse_dynamics),
            " Inverse dynamics by recursive Newton–Euler: the joint forces \
             `τ = M(q) q̈ + c(q, q̇)` that give the bodies the accelerations \
             `qdd`, `c` holding the Coriolis, centrifugal and gravity forces \
             (Pinocchio's `rnea`). The `forces` section is not included: with \
             `forces: [u1, ..]` as the joints' torques, `u = τ` gives `q̈ = qdd` \
             where no constraint acts.",
            Args::Accelerations,
            &b.inverse,
            false,
        ));
        out.extend(method(
            ctx,
            quote!(gravity_forces),
            " The generalized gravity `g(q)`: the joint forces that hold the \
             bodies still against gravity (Pinocchio's \
             `computeGeneralizedGravity`; `inverse_dynamics` at `q̇ = q̈ = 0`).",
            Args::Positions,
            &b.gravity,
            false,
        ));
    }
    let Some(e) = sys.energy else {
        return out;
    };
    let (kinetic, potential) = (e.kinetic, e.potential);
    out.extend(method(
        ctx,
        quote!(kinetic_energy),
        " The kinetic energy `T(q, q̇, t)`.",
        Args::States,
        &[kinetic],
        true,
    ));
    out.extend(method(
        ctx,
        quote!(potential_energy),
        " The potential energy `V(q, t)` (gravity's for bodies, and `potential_energy` as written; 0 where neither is given).",
        Args::Positions,
        &[potential],
        true,
    ));
    out.extend(method(
        ctx,
        quote!(energy),
        " The total energy `T + V`, conserved where no other force acts.",
        Args::States,
        &[e.total],
        true,
    ));
    out
}
