//! Code for the generalized-inverse equation of motion (eq. 24–26):
//! `acceleration`, `constraint_force`, `acceleration_corrected`,
//! `acceleration_moore_penrose`, and the impl of the runtime's hidden
//! `Generated` trait from which `ConstrainedSystem` follows.
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
use crate::equations::mass_inverse::MassInverse;
use crate::model::Level;
use proc_macro2::TokenStream;
use quote::quote;

/// The solver and the public methods.
pub(super) fn methods(ctx: &Context) -> TokenStream {
    let solver = mass_inverse::solver(ctx);
    let (params, args) = (ctx.params(Inputs::States), ctx.args(Inputs::States));
    let vector = ctx.vector(ctx.n);
    // The total methods of a system with a constant positive definite M
    // ask the solver for their value directly (the least-squares answer
    // where it fails: `TotalAcceleration`, `TotalForce`).
    // The fallible ones take their half of `Fallible`'s pair: the half not
    // taken is computed by nothing (straight-line arithmetic, removed).
    let gauss = |correction: TokenStream, force: bool| match (ctx.eq.mass_inverse.fallible(), force)
    {
        (true, force) => {
            let call = ctx.call_gauss("Fallible", correction);
            let part = if force { quote!(1) } else { quote!(0) };
            quote!(#call.map(|s| s.#part))
        }
        (false, true) => ctx.call_gauss("TotalForce", correction),
        (false, false) => ctx.call_gauss("TotalAcceleration", correction),
    };
    let none = quote!(::core::option::Option::None);
    let acc = gauss(none.clone(), false);
    let force = gauss(none, true);
    let corrected = gauss(quote!(::core::option::Option::Some(db)), false);
    let ret = if ctx.eq.mass_inverse.fallible() {
        ctx.result(vector.clone(), quote!(DynamicsError))
    } else {
        vector.clone()
    };
    let fallibility = if ctx.eq.mass_inverse.fallible() {
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
    };
    let acc_doc = format!(
        " The acceleration `q̈` by the generalized-inverse equation (Udwadia & \
         Kalaba eq. 24–26): `M q̈ = F + Aᵀ λ` with `(A M⁻¹ Aᵀ) λ = b − A a`, \
         solved with a rank-revealing {{1}}-inverse (see `constrained::inverse`) \
         whose rank decision is checked after the fact (`constrained::rank`). \
         Where `A` loses rank the result is the minimiser of Gauss's principle \
         over the constraints that remain independent (`q̈ = a` where `A = 0`); \
         never NaN for finite input. {fallibility}"
    );
    let force_doc = format!(
        " The constraint force `Fᶜ = M q̈ − F = Aᵀ λ` (the second term of eq. 26). \
         {fallibility}"
    );
    let k_vector = ctx.vector(ctx.k);
    let moore_penrose = ctx.private(quote!(moore_penrose));
    let mp_ret = ctx.result(vector, quote!(DynamicsError));
    quote! {
        #solver

        #[doc = #acc_doc]
        #[inline]
        pub fn acceleration(&self, #params) -> #ret { #acc }

        #[doc = #force_doc]
        #[inline]
        pub fn constraint_force(&self, #params) -> #ret { #force }

        /// The acceleration with `b` replaced by `b + db`: constraint
        /// stabilization (Baumgarte) asks `A q̈ = b − 2α φ̇ − β² φ` of
        /// position-level and `A q̈ = b − γ φ` of velocity-level constraints.
        #[inline]
        pub fn acceleration_corrected(&self, #params, db: &#k_vector) -> #ret {
            #corrected
        }

        /// The acceleration by the Moore–Penrose form of eq. 24 with
        /// `M = L Lᵀ`: `q̈ = a + L⁻ᵀ (A L⁻ᵀ)⁺ (b − A a)`, by SVD at run time
        /// (singular values below `√rank_tolerance` of the largest count as
        /// zero). Slower than [`acceleration`](Self::acceleration); the same
        /// result wherever the constraints are consistent. For comparison and
        /// for states where the least-squares reading of inconsistent
        /// constraints is wanted.
        pub fn acceleration_moore_penrose(&self, #params) -> #mp_ret {
            #moore_penrose(self, #args)
        }
    }
}

/// The impl of `constrained::__private::Generated`: the inherent methods,
/// forwarded, so that the runtime's blanket impl provides
/// `ConstrainedSystem` (the `State`-taking methods) once for every system.
pub(super) fn generated_impl(ctx: &Context) -> TokenStream {
    let name = &ctx.eq.system.name;
    let (n, k) = (Context::dim(ctx.n), Context::dim(ctx.k));
    let (states, positions) = (ctx.params(Inputs::States), ctx.params(Inputs::Positions));
    let args = ctx.args(Inputs::States);
    let (vector, k_vector) = (ctx.vector(ctx.n), ctx.vector(ctx.k));
    let (m, a) = (ctx.matrix(ctx.n, ctx.n), ctx.matrix(ctx.k, ctx.n));
    let motion = ctx.private(quote!(Motion<T, #n>));
    let gauss_ret = ctx.result(motion, quote!(DynamicsError));
    let gauss = ctx.call_gauss("Fallible", quote!(correction));
    let correction = ctx.correction_type();
    let generated = ctx.private(quote!(Generated<T, #n, #k>));
    let level = ctx.path(quote!(ConstraintLevel));
    let ga_system = ctx.result(quote!((#m, #vector)), quote!(GibbsAppellError));
    let ga_acceleration = ctx.result(vector.clone(), quote!(GibbsAppellError));
    let step = mass_inverse::step(ctx);
    let semidefinite = matches!(ctx.eq.mass_inverse, MassInverse::Auxiliary).then(|| {
        quote!(
            const SEMIDEFINITE_MASS: bool = true;
        )
    });
    let generic_rank = (ctx.generic_rank < ctx.k).then(|| {
        let r = Context::dim(ctx.generic_rank);
        quote!(
            const GENERIC_RANK: usize = #r;
        )
    });
    quote! {
        impl<T: ::constrained::nalgebra::RealField + Copy> #generated for #name<T> {
            const CONSTRAINT_LEVELS: [#level; #k] = Self::CONSTRAINT_LEVELS;
            #semidefinite
            #generic_rank
            #[inline]
            fn mass_matrix(&self, #positions) -> #m { Self::mass_matrix(self, q, t) }
            #[inline]
            fn forces(&self, #states) -> #vector { Self::forces(self, #args) }
            #[inline]
            fn constraint_residual(&self, #states) -> #k_vector {
                Self::constraint_residual(self, #args)
            }
            #[inline]
            fn constraint_velocity_residual(&self, #states) -> #k_vector {
                Self::constraint_velocity_residual(self, #args)
            }
            #[inline]
            fn constraint_matrices(&self, #states) -> (#a, #k_vector) {
                Self::constraint_matrices(self, #args)
            }
            #[inline]
            fn gauss(&self, #states, correction: #correction) -> #gauss_ret { #gauss }
            #[inline]
            fn gibbs_appell_matrices(&self, #states) -> #ga_system {
                Self::gibbs_appell_matrices(self, #args)
            }
            #[inline]
            fn acceleration_gibbs_appell(&self, #states) -> #ga_acceleration {
                Self::acceleration_gibbs_appell(self, #args)
            }
            #step
        }
    }
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
