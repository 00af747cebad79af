//! Code for the linearization: `acceleration_jacobian`, `linearize`, their
//! `Result`-valued `try_` forms, `linearize_reduced`, and the impl of the runtime's hidden `Tangent`
//! trait (`tangent_rhs`, `velocity_constraint_jacobian`) they rest on.
//!
//! `tangent_rhs` evaluates, for every column variable `v` (coordinates,
//! velocities, inputs), the right-hand sides `F̃ᵥ` and `b̃ᵥ` of the tangent
//! system (see [`crate::equations::tangent`]) as straight-line code over the exact
//! derivatives, contracted with `q̈` and `λ`.
//!
//! Where `M⁻¹` is symbolic (constant or diagonal `M`), the tangent systems
//! are solved in generated code: the same straight-line Gauss solve as
//! `acceleration` gives `q̈`, `λ` and the structured factorization of
//! `S = A M⁻¹ Aᵀ`, and each column is one sparse solve through it
//! (`q̈ᵥ = M⁻¹F̃ᵥ + W S⁺(b̃ᵥ − A M⁻¹F̃ᵥ)`, `W = M⁻¹Aᵀ`, only structural
//! nonzeros touched). For a full `M(q)` the columns run through `gauss`'s
//! generated factors of `M` and `S`; where `gauss` solves the quaternions'
//! velocity form, through that form's factors, `∂λ` with them
//! (`mass_inverse::factored::velocity_jacobian`). Where a rank decision or
//! a pivot is suspect, and for a semi-definite `M` otherwise, the runtime
//! (`constrained::linearize`) factors `M` and `S` densely once and solves
//! for every column.

use super::context::{Context, Inputs};
use super::mass_inverse::{self, JacobianBody};
use super::tangent;
use crate::equations::partition::Partition;
use proc_macro2::TokenStream;
use quote::quote;

/// The methods and the impl of the runtime's hidden `Tangent` trait.
pub(super) fn methods(ctx: &Context, partition: &Partition) -> TokenStream {
    let (n, nu) = (ctx.n, ctx.eq.system.inputs);
    let columns = 2 * n + nu;
    let (params, args) = (ctx.params(Inputs::States), ctx.args(Inputs::States));
    let (n_lit, nu_lit, n2_lit, d_lit) = (
        Context::dim(n),
        Context::dim(nu),
        Context::dim(2 * n),
        Context::dim(columns),
    );
    let jacobians = ctx.path(quote!(Jacobians<T, #n_lit, #nu_lit>));
    let (a_type, b_type) = (ctx.matrix(2 * n, 2 * n), ctx.matrix(2 * n, nu));
    let jacobian = ctx.path(quote!(linearize::try_acceleration_jacobian));
    let linearization = ctx.path(quote!(linearize::linearization));
    let none = quote!(::core::option::Option::None);
    let fallible = ctx.eq.mass_inverse.fallible();
    let motion = if fallible {
        let solve = ctx.call_gauss("Fallible", none);
        quote!(#solve?)
    } else {
        ctx.call_gauss("Total", none)
    };
    let k_lit = Context::dim(ctx.k);
    let finite = ctx.finite_or_error(quote!(__j), quote!(__j));
    // The one body, a `Result`: `acceleration_jacobian`'s where
    // `acceleration` can fail, else `try_acceleration_jacobian`'s, which
    // the total `acceleration_jacobian` turns into NaN entries.
    let body = mass_inverse::jacobian(
        ctx,
        &quote! {
            let __motion = #motion;
            let __j = #jacobian::<T, Self, #n_lit, #k_lit, #nu_lit, #d_lit>(
                self, #args, __motion,
            )?;
            #finite
        },
    );
    let (body, in_place) = in_place(ctx, body, &jacobians, &params, &args);
    let parts = Public {
        params,
        args,
        body,
        jac_result: ctx.result(jacobians.clone(), quote!(DynamicsError)),
        lin_result: ctx.result(quote!((#a_type, #b_type)), quote!(DynamicsError)),
        linearization: quote!(#linearization::<T, #n_lit, #nu_lit, #n2_lit>),
        not_a_number: ctx.path(quote!(Jacobians::<T, #n_lit, #nu_lit>::not_a_number())),
        jacobians,
        linear: quote!((#a_type, #b_type)),
    };
    let reduced = reduced(ctx, partition);
    let (jacobian_methods, linearize_methods) = parts.methods(&Docs::new(fallible), fallible);
    let multipliers = multiplier_jacobian(ctx, &parts, &motion);
    quote! {
        #reduced
        #jacobian_methods
        #in_place
        #linearize_methods
        #multipliers
    }
}

/// The body of the Jacobian methods (a `Result<Jacobians, _>`), and
/// `acceleration_jacobian_to` with the private method it calls: where the
/// strategy writes in place (`JacobianBody::InPlace`), its body is that
/// method, which the others call with the caller's `out` or a local of
/// zeros; else `_to` stores the value. A `Result` returned by value is a
/// copy of its `Jacobians` (rustc builds it from the local, then moves
/// it): `_to` does not copy where the strategy writes in place.
fn in_place(
    ctx: &Context,
    body: JacobianBody,
    jacobians: &TokenStream,
    params: &TokenStream,
    args: &TokenStream,
) -> (TokenStream, TokenStream) {
    let result = ctx.result(quote!(()), quote!(DynamicsError));
    let doc = " [`try_acceleration_jacobian`](Self::try_acceleration_jacobian) \
               written into `out`, every entry, for a caller that keeps the \
               Jacobians from call to call (as Pinocchio keeps its `Data`): \
               where the solve writes in place, nothing is copied out of a \
               `Result`. `Err` as that method; `out` then holds no \
               Jacobian of this call (its entries may be an earlier \
               call's).";
    match body {
        JacobianBody::Value(body) => {
            let to = quote! {
                #[doc = #doc]
                #[inline]
                pub fn acceleration_jacobian_to(&self, #params, out: &mut #jacobians) -> #result {
                    *out = self.try_acceleration_jacobian(#args)?;
                    ::core::result::Result::Ok(())
                }
            };
            (body, to)
        }
        JacobianBody::InPlace(body) => {
            let zeros = ctx.jacobians_zero().0;
            let value = quote! {
                let mut __jac = #zeros;
                self.__acceleration_jacobian_into(#args, &mut __jac)?;
                ::core::result::Result::Ok(__jac)
            };
            // The body writes every entry, zeros included: `out` is not
            // cleared first, which would store the whole Jacobian twice.
            let to = quote! {
                #[doc = #doc]
                #[inline]
                pub fn acceleration_jacobian_to(&self, #params, out: &mut #jacobians) -> #result {
                    self.__acceleration_jacobian_into(#args, out)
                }

                /// The Jacobian methods' body: the Jacobians written into
                /// `__jac`, every entry.
                #[doc(hidden)]
                #[inline]
                fn __acceleration_jacobian_into(&self, #params, __jac: &mut #jacobians) -> #result {
                    #body
                }
            };
            (value, to)
        }
    }
}

/// `multiplier_jacobian` and `acceleration_and_multiplier_jacobians`, for
/// a system with constraint rows: `∂λ/∂q`, `∂λ/∂q̇`, `∂λ/∂u` (with those of
/// `q̈`) from the same tangent systems, solved through the velocity form's
/// factors where `gauss` solves that form, else by the runtime
/// (`linearize::try_acceleration_and_multiplier_jacobians`) after
/// `gauss`'s motion.
fn multiplier_jacobian(ctx: &Context, parts: &Public, motion: &TokenStream) -> TokenStream {
    if ctx.k == 0 {
        return TokenStream::new();
    }
    let (n, nu) = (ctx.n, ctx.eq.system.inputs);
    let (n_lit, k_lit, nu_lit) = (Context::dim(n), Context::dim(ctx.k), Context::dim(nu));
    let multipliers = ctx.path(quote!(linearize::MultiplierJacobians<T, #n_lit, #k_lit, #nu_lit>));
    let accelerations = ctx.path(quote!(Jacobians<T, #n_lit, #nu_lit>));
    let error = ctx.path(quote!(DynamicsError));
    let params = &parts.params;
    let (private, only_body, both_body, to_body) = multiplier_bodies(ctx, &parts.args, motion);
    let how = if private.is_empty() {
        "solved densely"
    } else {
        "solved through the velocity form's factors"
    };
    let only_doc = [
        " The Jacobians of the constraint multipliers `λ(q, q̇, u)` that".to_string(),
        " `constraint_multipliers` returns: `∂λ/∂q`, `∂λ/∂q̇`, `∂λ/∂u`".into(),
        " (`K` rows each), exact, from the same tangent systems as".into(),
        format!(" `acceleration_jacobian` (their multipliers), {how}."),
        " `Err(NotDifferentiable)` where the rows are not independent".into(),
        " (`λ` is then not unique); `Err` where `acceleration` is, or an".into(),
        " entry is not finite.".into(),
    ];
    let to_doc = [
        " [`acceleration_and_multiplier_jacobians`](Self::acceleration_and_multiplier_jacobians)"
            .to_string(),
        " written into `out` and `lambdas`, every entry, for a caller that".into(),
        " keeps them from call to call (as Pinocchio keeps its `Data`): where".into(),
        " the velocity form solves the tangent systems, nothing is copied out".into(),
        " of a `Result`. `Err` as that method; `out` and `lambdas` then hold".into(),
        " no Jacobian of this call (their entries may be an earlier call's).".into(),
    ];
    let both_doc = [
        " The Jacobians of `q̈` and of the multipliers `λ` from one".to_string(),
        format!(" evaluation of the tangent systems, {how}: what"),
        " `acceleration_jacobian` and `multiplier_jacobian` return, for".into(),
        " about the cost of the second alone. `Err` as".into(),
        " `multiplier_jacobian`.".into(),
    ];
    quote! {
        #private

        #(#[doc = #only_doc])*
        #[inline]
        pub fn multiplier_jacobian(
            &self,
            #params
        ) -> ::core::result::Result<#multipliers, #error> {
            #only_body
        }
        #(#[doc = #both_doc])*
        #[inline]
        pub fn acceleration_and_multiplier_jacobians(
            &self,
            #params
        ) -> ::core::result::Result<(#accelerations, #multipliers), #error> {
            #both_body
        }
        #(#[doc = #to_doc])*
        #[inline]
        pub fn acceleration_and_multiplier_jacobians_to(
            &self,
            #params,
            out: &mut #accelerations,
            lambdas: &mut #multipliers,
        ) -> ::core::result::Result<(), #error> {
            #to_body
        }
    }
}

/// The private methods the entry points call (none for the runtime's
/// solve) and their three bodies (`multiplier_jacobian`,
/// `acceleration_and_multiplier_jacobians` and its `_to` form): the
/// velocity form solves the tangent systems through its own factors, in
/// place; elsewhere the runtime solves them densely after `motion`.
fn multiplier_bodies(
    ctx: &Context,
    args: &TokenStream,
    motion: &TokenStream,
) -> (TokenStream, TokenStream, TokenStream, TokenStream) {
    if let Some((private, name, into)) = mass_inverse::multiplier_jacobians(ctx) {
        return (
            private,
            quote! {
                let (_, __l) = self.#name(#args)?;
                ::core::result::Result::Ok(__l)
            },
            quote!(self.#name(#args)),
            quote!(self.#into(#args, true, out, lambdas)),
        );
    }
    let (n, nu) = (ctx.n, ctx.eq.system.inputs);
    let (n_lit, k_lit, nu_lit, d_lit) = (
        Context::dim(n),
        Context::dim(ctx.k),
        Context::dim(nu),
        Context::dim(2 * n + nu),
    );
    let only = ctx.path(quote!(linearize::try_multiplier_jacobian));
    let both = ctx.path(quote!(linearize::try_acceleration_and_multiplier_jacobians));
    (
        TokenStream::new(),
        quote! {
            let __motion = #motion;
            #only::<T, Self, #n_lit, #k_lit, #nu_lit, #d_lit>(self, #args, __motion)
        },
        quote! {
            let __motion = #motion;
            #both::<T, Self, #n_lit, #k_lit, #nu_lit, #d_lit>(self, #args, __motion)
        },
        quote! {
            (*out, *lambdas) = self.acceleration_and_multiplier_jacobians(#args)?;
            ::core::result::Result::Ok(())
        },
    )
}

/// The public entry points' parts: the one body and what the two forms
/// (total, `Result`) wrap it in.
struct Public {
    params: TokenStream,
    args: TokenStream,
    body: TokenStream,
    jac_result: TokenStream,
    lin_result: TokenStream,
    linearization: TokenStream,
    not_a_number: TokenStream,
    jacobians: TokenStream,
    linear: TokenStream,
}

impl Public {
    /// `acceleration_jacobian`, `try_acceleration_jacobian`, `linearize`
    /// and `try_linearize`: the `Result` forms are the body where
    /// `acceleration` can fail; else the total forms wrap the `try_` ones.
    fn methods(&self, docs: &Docs, fallible: bool) -> (TokenStream, TokenStream) {
        (
            self.jacobian_methods(docs, fallible),
            self.linearize_methods(docs, fallible),
        )
    }

    /// `acceleration_jacobian` and `try_acceleration_jacobian`: where
    /// `acceleration` can fail the plain name holds the body and the `try_`
    /// name repeats it; else the `try_` name holds it and the plain name
    /// answers NaN for its `Err`.
    fn jacobian_methods(&self, docs: &Docs, fallible: bool) -> TokenStream {
        let Public {
            params,
            args,
            body,
            jac_result,
            not_a_number,
            jacobians,
            ..
        } = self;
        let (doc, try_doc) = (&docs.jacobian, &docs.try_jacobian);
        if fallible {
            quote! {
                #[doc = #doc]
                #[inline]
                pub fn acceleration_jacobian(&self, #params) -> #jac_result {
                    #body
                }

                #[doc = #try_doc]
                #[inline]
                pub fn try_acceleration_jacobian(&self, #params) -> #jac_result {
                    self.acceleration_jacobian(#args)
                }
            }
        } else {
            quote! {
                #[doc = #try_doc]
                #[inline]
                pub fn try_acceleration_jacobian(&self, #params) -> #jac_result {
                    #body
                }

                #[doc = #doc]
                #[inline]
                pub fn acceleration_jacobian(&self, #params) -> #jacobians {
                    self.try_acceleration_jacobian(#args).unwrap_or_else(|_| #not_a_number)
                }
            }
        }
    }

    /// `linearize` and `try_linearize`, from the Jacobian methods: both the
    /// `Result` where `acceleration` can fail; else `linearize` is total.
    fn linearize_methods(&self, docs: &Docs, fallible: bool) -> TokenStream {
        let Public {
            params,
            args,
            lin_result,
            linearization,
            linear,
            ..
        } = self;
        let (doc, try_doc) = (&docs.linearize, &docs.try_linearize);
        if fallible {
            quote! {
                #[doc = #doc]
                #[inline]
                pub fn linearize(&self, #params) -> #lin_result {
                    self.acceleration_jacobian(#args) .map(|j| #linearization(&j))
                }

                #[doc = #try_doc]
                #[inline]
                pub fn try_linearize(&self, #params) -> #lin_result {
                    self.linearize(#args)
                }
            }
        } else {
            quote! {
                #[doc = #doc]
                #[inline]
                pub fn linearize(&self, #params) -> #linear {
                    #linearization(&self.acceleration_jacobian(#args))
                }

                #[doc = #try_doc]
                #[inline]
                pub fn try_linearize(&self, #params) -> #lin_result {
                    self.try_acceleration_jacobian(#args) .map(|j| #linearization(&j))
                }
            }
        }
    }
}

/// The docs of the four methods, by whether `acceleration` can fail.
struct Docs {
    jacobian: String,
    linearize: String,
    try_jacobian: String,
    try_linearize: String,
}

impl Docs {
    fn new(fallible: bool) -> Self {
        let errors = "`Err(NotDifferentiable)` where `q̈` has no derivative \
             that `T` resolves (where `A` loses rank, e.g. a velocity-level \
             constraint at rest, or so nearly that the rank decision \
             `acceleration` checks makes it jump by more than `√ε`: see \
             `constrained::linearize`), and `Err(NonFinite)` where a \
             derivative overflows or `M` or a row of `A` has lost its digits \
             to underflow";
        let fallibility = if fallible {
            format!("`Err` exactly where [`acceleration`](Self::acceleration) fails; {errors}.")
        } else {
            "Total, as [`acceleration`](Self::acceleration) is: where the \
             derivative does not exist, cannot be trusted or overflows, every \
             entry is NaN; [`try_acceleration_jacobian`](Self::try_acceleration_jacobian) \
             says which as an `Err`."
                .to_owned()
        };
        let jacobian = format!(
            " The exact Jacobians of `q̈(q, q̇, u)` at this state: `dq = ∂q̈/∂q`, \
             `dqd = ∂q̈/∂q̇`, `du = ∂q̈/∂u` (columns in the order of `coordinates` \
             and `inputs`). Differentiated at compile time and solved through one \
             factorization: `M q̈ᵥ = F̃ᵥ + Aᵀλᵥ`, `A q̈ᵥ = b̃ᵥ` for each variable `v` \
             (see `constrained::linearize`). Where the rank decision dropped rows \
             of `A`, the Jacobian of the `q̈` actually returned. {fallibility}"
        );
        let linearize = format!(
            " The linearization `δẋ = A δx + B δu` of `ẋ = (q̇, q̈(q, q̇, u))` for \
             `x = (q, q̇)`: `A = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]`, `B = [[0], [∂q̈/∂u]]`. \
             In all `2n` coordinates: on a constrained system it carries the \
             constraint directions (see `constrained::linearize::reduced` for the \
             linearization on the constraint manifold). {}",
            if fallible {
                "`Err` exactly where [`acceleration_jacobian`](Self::acceleration_jacobian) is."
            } else {
                "Total: every entry of `∂q̈` NaN where \
                 [`acceleration_jacobian`](Self::acceleration_jacobian)'s are \
                 ([`try_linearize`](Self::try_linearize) says why)."
            }
        );
        let (try_jacobian, try_linearize) = Docs::try_forms(fallible, errors);
        Docs {
            jacobian,
            linearize,
            try_jacobian,
            try_linearize,
        }
    }

    /// The docs of `try_acceleration_jacobian` and `try_linearize`: the
    /// same methods under the `Result`-valued names where `acceleration`
    /// can fail, else the total methods' failures as values (`errors`).
    fn try_forms(fallible: bool, errors: &str) -> (String, String) {
        if fallible {
            (
                " [`acceleration_jacobian`](Self::acceleration_jacobian), under the \
                 name every system has for the `Result`-valued Jacobian."
                    .to_owned(),
                " [`linearize`](Self::linearize), under the name every system has \
                 for the `Result`-valued linearization."
                    .to_owned(),
            )
        } else {
            (
                format!(
                    " [`acceleration_jacobian`](Self::acceleration_jacobian) with its \
                     failures as values: never a non-finite entry in an `Ok`; {errors}."
                ),
                " [`linearize`](Self::linearize) with its failures as values, those of \
                 [`try_acceleration_jacobian`](Self::try_acceleration_jacobian)."
                    .to_owned(),
            )
        }
    }
}

/// `linearize_reduced`: the linearization on the constraint manifold.
fn reduced(ctx: &Context, partition: &Partition) -> TokenStream {
    let n = ctx.n;
    let nu = ctx.eq.system.inputs;
    let (r, rh) = (partition.rank, partition.position_rank);
    let (nq, nv) = (n - rh, n - r);
    let dims = |v: usize| Context::dim(v);
    let (n_l, k_l, nu_l, d_l) = (
        dims(n),
        dims(ctx.k),
        dims(nu),
        dims(ctx.eq.tangent.columns.len()),
    );
    let (nq_l, nv_l, nx_l, r_l, rh_l) = (dims(nq), dims(nv), dims(nq + nv), dims(r), dims(rh));
    let args = ctx.args(Inputs::States);
    let params = ctx.params(Inputs::States);
    let reduced_type = ctx.path(quote!(linearize::Reduced<T, #nx_l, #nu_l, #nq_l, #nv_l>));
    let ret = ctx.result(reduced_type, quote!(DynamicsError));
    let function = ctx.path(quote!(linearize::reduced));
    let jacobian = quote!(self.try_acceleration_jacobian(#args)?);
    let doc = format!(
        " The linearization on the constraint manifold \
         (`constrained::linearize::Reduced`): `{nq}` coordinates and `{nv}` \
         speeds, the dependent ones chosen at this state where they are best \
         conditioned. The constraint directions are eliminated, so its \
         eigenvalues are the physical ones. `Err(SingularPartition)` where \
         the constraints lose rank at this state; otherwise as \
         [`try_acceleration_jacobian`](Self::try_acceleration_jacobian)."
    );
    quote! {
        #[doc = #doc]
        #[inline]
        pub fn linearize_reduced(&self, #params) -> #ret {
            let __j = #jacobian;
            #function::<T, Self, #n_l, #k_l, #nu_l, #d_l, #nq_l, #nv_l, #nx_l, #r_l, #rh_l>(
                self, #args, &__j,
            )
        }
    }
}

/// The impl of the runtime's hidden `Tangent` trait, with the bodies.
pub(super) fn tangent_impl(ctx: &Context) -> TokenStream {
    let name = &ctx.eq.system.name;
    let (n, k) = (Context::dim(ctx.n), Context::dim(ctx.k));
    let d = Context::dim(ctx.eq.tangent.columns.len());
    let trait_path = ctx.private(quote!(Tangent<T, #n, #k, #d>));
    let rhs = tangent::tangent_rhs(ctx);
    let psi_q = tangent::velocity_constraint_jacobian(ctx);
    quote! {
        #[allow(unused_variables, non_snake_case, clippy::all, clippy::pedantic)]
        impl<T: ::constrained::nalgebra::RealField + Copy> #trait_path for #name<T> {
            #rhs
            #psi_q
        }
    }
}
