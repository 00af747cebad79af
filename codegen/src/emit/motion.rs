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

use super::body::{literal, Body};
use super::context::{Context, Inputs};
use super::ldlt::StructuredLdlt;
use crate::expr::Id;
use crate::model::Level;
use crate::motion::{MassInverse, Symbolic};
use crate::num::Num;
use proc_macro2::TokenStream;
use quote::quote;

/// Whether `acceleration` can fail: only when `M` is not known positive
/// definite at compile time.
pub(super) fn fallible(ctx: &Context) -> bool {
    match &ctx.eq.gauss {
        MassInverse::Symbolic(d) => !d.known_positive,
        MassInverse::Factored(_) | MassInverse::Auxiliary => true,
    }
}

/// The solver and the public methods.
pub(super) fn methods(ctx: &Context) -> TokenStream {
    let solver = match &ctx.eq.gauss {
        MassInverse::Symbolic(d) => symbolic_solver(ctx, d),
        MassInverse::Factored(f) => super::mass_inverse::factored::solver(ctx, f),
        MassInverse::Auxiliary => dense_solver(ctx),
    };
    let (params, args) = (ctx.params(Inputs::States), ctx.args(Inputs::States));
    let vector = ctx.vector(ctx.n);
    // The total methods of a system with a constant positive definite M
    // ask the solver for their value directly (the least-squares answer
    // where it fails: `TotalAcceleration`, `TotalForce`).
    // The fallible ones take their half of `Fallible`'s pair: the half not
    // taken is computed by nothing (straight-line arithmetic, removed).
    let gauss = |correction: TokenStream, force: bool| match (fallible(ctx), force) {
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
    let ret = if fallible(ctx) {
        ctx.result(vector.clone(), quote!(DynamicsError))
    } else {
        vector.clone()
    };
    let fallibility = if fallible(ctx) {
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
    let step = super::mass_inverse::step::method(ctx);
    let semidefinite = matches!(ctx.eq.gauss, MassInverse::Auxiliary).then(|| {
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

/// The two paths' own code before `gauss`'s value, where the rank check
/// comes before `λ` (a scalar `S`): `(suspect, fast)`.
pub(super) type PathCode = (TokenStream, TokenStream);

/// `gauss`'s value `(q̈, Aᵀλ)` as its `Finish` makes it, with the rank
/// decision of `ldlt` (the factorization of `S`) checked after the fact
/// (`constrained::rank`): where fewer rows than the generic rank were kept,
/// the runtime verifies the dropped ones and recomputes if they are
/// violated. `also` is a further condition for that check; `paths`, code
/// each path runs first.
pub(super) fn checked_motion(
    ctx: &Context,
    ldlt: &StructuredLdlt,
    acc: &TokenStream,
    force: &TokenStream,
    also: Option<TokenStream>,
    paths: Option<PathCode>,
) -> TokenStream {
    // The force as a closure that only the callers wanting it call, so
    // that `acceleration` never computes it.
    if ctx.k == 0 {
        return quote!(__F::stands(#acc, move || #force));
    }
    let suspect = ldlt.suspect(ctx.generic_rank);
    let suspect = match also {
        Some(also) => quote!((#suspect) | #also),
        None => suspect,
    };
    let (suspect_code, fast_code) = paths.unwrap_or_default();
    let checked = ctx.private(quote!(checked));
    // Two shapes, each the faster where it is used (measured against the
    // solve before `Finish`, alternating binaries of one run,
    // scripts/compare_acceleration.sh). k ≥ 2: q̈ bound once and the check
    // merging back into the fast path (the double pendulum, the chains,
    // the four-bars: within 1 %, the 32-link chain 0.91×). k = 1: the
    // suspect path complete in its own branch, with its own q̈ and return,
    // so that nothing of the fast path lives across the runtime call and
    // the fast path keeps no stack frame (the 1-link chain 0.89×, Appell's
    // particle 0.93×, the sleigh 0.94×, the two-link arm 0.96×; where that
    // path instead returned the runtime's answer through one generic call
    // taking the force as a closure, the k ≥ 2 models were up to 1.48×
    // slower, the closure's captures kept alive to the check).
    // The runtime's check of `__acc`, returning its recomputation.
    let recheck = quote! {
        if let ::core::option::Option::Some(__recomputed) =
            #checked(self, q, qd, t, correction, __acc)
        {
            return __F::settle(self, q, qd, t, correction, __recomputed);
        }
    };
    if ctx.k > 1 {
        return quote! {
            let __acc = #acc;
            if #suspect {
                #recheck
            }
            __F::stands(__acc, move || #force)
        };
    }
    quote! {
        if #suspect {
            #suspect_code
            let __acc = #acc;
            #recheck
            return __F::stands(__acc, move || #force);
        }
        #fast_code
        __F::stands(#acc, move || #force)
    }
}

/// `r + D db` where `gauss` was given a correction `db` (Baumgarte), over
/// the locals holding `r`; `scale` is the row scaling `D` of the system
/// solved (`crate::motion::Symbolic`), empty for none.
pub(super) fn corrected(residuals: &[syn::Ident], scale: &[Num]) -> TokenStream {
    let d: Vec<_> = (0..residuals.len())
        .map(|i| Context::local("db", i))
        .collect();
    let scaled = d.iter().enumerate().map(|(i, db)| match scale.get(i) {
        Some(&s) if !s.is_one() => {
            let (s, _) = literal(s);
            quote!(#s * #db)
        }
        _ => quote!(#db),
    });
    quote! {
        let (#(#residuals,)*) = match correction {
            ::core::option::Option::Some(__db) => {
                let [[#(#d),*]] = __db.data.0;
                (#(#residuals + #scaled,)*)
            }
            ::core::option::Option::None => (#(#residuals,)*),
        };
    }
}

/// The straight-line solve of Gauss's principle for a symbolic `M⁻¹`, up to
/// the multipliers: shared by `gauss` and the structured Jacobian
/// (`super::jacobian`), which both continue from `λ` in their own way.
pub(super) struct SymbolicGauss<'a> {
    /// The bodies' expressions: the Gauss pieces and the caller's roots.
    pub body: Body<'a>,
    /// The factorization of `S`, whose locals the code below defines.
    pub ldlt: StructuredLdlt<'a>,
    /// The code from the arguments to `λ` (`__lam{i}`) and the temporaries
    /// that need it: variables, entries of `S` and `r`, the run-time check
    /// of masses not known positive, the factorization and the solve.
    pub to_multipliers: TokenStream,
    /// `to_multipliers` in three parts, for `gauss` with a scalar `S`
    /// (`k = 1`): the code up to `S` and `r`, the guarded division, and
    /// the temporaries after `λ`.
    pub scalar: Option<ScalarSolve>,
}

/// The scalar (`k = 1`) solve of [`SymbolicGauss`] in parts.
pub(super) struct ScalarSolve {
    /// From the arguments to `S` and `r` (`__s0_0`, `__r0`).
    to_gram: TokenStream,
    /// `λ = r / S`, bare: the fast path, once the rank check passed.
    division: TokenStream,
    /// `λ = r / S` where `S > 0`, else 0: the suspect path.
    guarded: TokenStream,
    /// The temporaries that need `λ`.
    after: TokenStream,
}

impl<'a> SymbolicGauss<'a> {
    /// `extra` are further expressions the caller will ask `body` for;
    /// `gauss`: the code is the solver `gauss`'s (with the `b + db` of
    /// `acceleration_corrected`, errors through its `Finish`), else the
    /// Jacobian's (errors as `Err`).
    pub(super) fn new(ctx: &'a Context, d: &'a Symbolic, extra: &[Id], gauss: bool) -> Self {
        let k = ctx.k;
        let g = &ctx.eq.system.graph;
        let residuals: Vec<_> = (0..k).map(|i| Context::local("r", i)).collect();
        let ldlt = StructuredLdlt::gram(&d.structure);
        let mut named: Vec<(syn::Ident, Id)> = Vec::new();
        for (i, (r, &residual)) in residuals.iter().zip(&d.residual).enumerate() {
            for j in 0..=i {
                if !g.is_zero(d.gram[i][j]) {
                    named.push((ldlt.entry(i, j), d.gram[i][j]));
                }
            }
            named.push((r.clone(), residual));
        }
        // Each distinct mass that is not a positive constant is checked once.
        let mut unchecked: Vec<Id> = Vec::new();
        for &m in &d.masses {
            let constant_positive = g.as_num(m).is_some_and(|v| v.to_f64() > 0.0);
            if !constant_positive && !unchecked.contains(&m) {
                unchecked.push(m);
            }
        }
        let mut roots: Vec<Id> = named.iter().map(|(_, id)| *id).collect();
        roots.extend(&unchecked);
        roots.extend(&d.acceleration);
        roots.extend(&d.force);
        roots.extend(extra);
        let body = Body::new(ctx.eq, &roots);
        let preamble = body.preamble();
        let bindings = named.iter().map(|(name, id)| {
            let value = body.expr(*id);
            quote! { let #name = #value; }
        });
        let error = quote!(DynamicsError::MassNotPositiveDefinite);
        let exit = if gauss {
            ctx.gauss_error(error)
        } else {
            let error = ctx.path(error);
            quote!(return ::core::result::Result::Err(#error);)
        };
        let check = (!unchecked.is_empty()).then(|| {
            let positive = unchecked.iter().map(|&m| {
                let m = body.expr(m);
                quote! { #m > T::zero() }
            });
            quote! {
                if !(#(#positive)&&*) {
                    #exit
                }
            }
        });
        let corrected = (gauss && k > 0).then(|| corrected(&residuals, &d.scale));
        let multipliers: Vec<_> = (0..k).map(|i| Context::local("lam", i)).collect();
        let factor = ldlt.factor();
        let solve = ldlt.solve(&residuals, "y", &multipliers);
        let after = body.after_multipliers();
        let to_gram = quote! {
            #preamble
            #(#bindings)*
            #corrected
            #check
            #factor
        };
        let to_multipliers = quote! {
            #to_gram
            #solve
            #after
        };
        let scalar = match (&residuals[..], &multipliers[..]) {
            ([r], [lam]) => ldlt.scalar_division(r, lam).map(|division| ScalarSolve {
                to_gram,
                division,
                guarded: solve,
                after,
            }),
            _ => None,
        };
        SymbolicGauss {
            body,
            ldlt,
            to_multipliers,
            scalar,
        }
    }
}

/// `M⁻¹` known symbolically (`M` diagonal or a numeric constant): `a`, `S`,
/// `r`, `W` and `A` are straight-line expressions; `S λ = r` is solved by
/// `LDLᵀ` on the structural pattern of `S`.
fn symbolic_solver(ctx: &Context, d: &Symbolic) -> TokenStream {
    let SymbolicGauss {
        body,
        ldlt,
        to_multipliers,
        scalar,
    } = SymbolicGauss::new(ctx, d, &[], true);
    let acc = ctx.vector_value(d.acceleration.iter().map(|&e| body.expr(e)));
    let force = ctx.vector_value(d.force.iter().map(|&e| body.expr(e)));
    let also = overflowing_rows(ctx, d);
    // Fallible even where M is known positive definite: the rank check can
    // find the constraints unsatisfiable (the total methods then answer by
    // least squares, through their `Finish`).
    let signature = ctx.gauss_signature();
    // k = 1: the rank check is the division's own branch. The fast path
    // divides once, unguarded (S is in (safe minimum, largest] there); the
    // suspect path makes the guarded λ and what follows from it. The fast
    // path tests S once where it tested it twice (S > 0, then the check):
    // Appell's particle has as many instructions as eq. 32 by hand.
    let (to_multipliers, paths) = match scalar {
        Some(ScalarSolve {
            to_gram,
            division,
            guarded,
            after,
        }) => (
            to_gram,
            Some((quote!(#guarded #after), quote!(#division #after))),
        ),
        None => (to_multipliers, None),
    };
    let value = checked_motion(ctx, &ldlt, &acc, &force, also, paths);
    quote! {
        /// `(q̈, Aᵀλ)` of Gauss's principle, shared by `acceleration`,
        /// `constraint_force` and `acceleration_corrected` (`b + correction`),
        /// as `__F` makes it.
        #[inline(always)]
        #signature {
            #to_multipliers
            #value
        }
    }
}

/// Whether a row scaled down (`D`, d < 1) overflows in the model's own
/// units: it can be finite where the model's own `r` (and `b`) is not, and
/// then the runtime answers from A and b (`NonFinite`), so that an `Ok`
/// always satisfies the `A q̈ = b` it reports. One comparison per such row,
/// branch-free (`|`), over the locals `__r{i}`; `None` without such rows.
/// The Jacobian tests the same condition, so that it takes the runtime's
/// path (and its `Err`) exactly where `acceleration` does.
pub(super) fn overflowing_rows(ctx: &Context, d: &Symbolic) -> Option<TokenStream> {
    let overflows: Vec<TokenStream> = d
        .scale
        .iter()
        .enumerate()
        .filter(|(_, s)| s.to_f64() < 1.0)
        .map(|(i, s)| {
            let r = Context::local("r", i);
            let bound = ctx.private(quote!(unscaled_bound));
            let value = proc_macro2::Literal::f64_suffixed(s.to_f64());
            quote!((#r.abs() > #bound::<T>(#value)))
        })
        .collect();
    (!overflows.is_empty()).then(|| quote!(#(#overflows)|*))
}

/// A semi-definite `M`: the runtime's dense solve of the auxiliary system
/// (Cholesky of `M + s AᵀA`, pivoted `LDLᵀ` of `A M⁻¹ Aᵀ`).
fn dense_solver(ctx: &Context) -> TokenStream {
    let args = ctx.args(Inputs::States);
    let (signature, gauss_dense) = (ctx.gauss_signature(), ctx.private(quote!(gauss_dense)));
    quote! {
        /// `(q̈, Aᵀλ)` of Gauss's principle, shared by `acceleration`,
        /// `constraint_force` and `acceleration_corrected` (`b + correction`),
        /// as `__F` makes it.
        #[inline]
        #signature {
            let __motion = #gauss_dense(self, #args, correction);
            __F::settle(self, #args, correction, __motion)
        }
    }
}
