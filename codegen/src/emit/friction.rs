//! The methods of a system with friction (`friction: [..]`): `FRICTION`,
//! `friction_velocities`, `friction_normals`, `friction_coefficients`, the
//! modes, and the runtime's `friction::Friction` trait, which the
//! `StickSlip` driver switches through (`docs/math.md`, "Stick–slip").
//! Nothing is generated for a system without friction.

use super::body::Body;
use super::context::{Context, Inputs};
use crate::expr::Id;
use crate::model::friction_mode;
use proc_macro2::TokenStream;
use quote::quote;

/// The inherent friction methods, or nothing without `friction`.
pub(super) fn methods(ctx: &Context) -> TokenStream {
    let entries = &ctx.eq.system.friction;
    if entries.is_empty() {
        return TokenStream::new();
    }
    let f_lit = Context::dim(entries.len());
    let state = ctx.params(Inputs::States);
    let vector = ctx.vector(entries.len());
    let velocities = vector_function(ctx, &entries.iter().map(|e| e.velocity).collect::<Vec<_>>());
    let normals = vector_function(ctx, &entries.iter().map(|e| e.normal).collect::<Vec<_>>());
    let coefficients = coefficients(ctx);
    let written: Vec<String> = entries.iter().map(|e| e.tokens.to_string()).collect();
    let doc = format!(
        " The sliding velocities `v`, in the order written: `{}`.",
        written.join("`, `")
    );
    let modes = mode_methods(ctx);
    quote! {
        /// Number of friction entries (`friction: [..]`).
        pub const FRICTION: usize = #f_lit;

        #[doc = #doc]
        #[inline]
        pub fn friction_velocities(&self, #state) -> #vector {
            #velocities
        }

        /// The normal forces `N`, one per friction entry.
        #[inline]
        pub fn friction_normals(&self, #state) -> #vector {
            #normals
        }

        /// The coefficients `(μs, μk)`, one pair per friction entry.
        #[inline]
        pub fn friction_coefficients(&self) -> [(T, T); #f_lit] {
            #coefficients
        }

        #modes
    }
}

/// The body of a method returning the vector of `ids`' values.
fn vector_function(ctx: &Context, ids: &[Id]) -> TokenStream {
    let body = Body::new(ctx.eq, ids);
    let (preamble, value) = (
        body.preamble(),
        ctx.vector_value(ids.iter().map(|&e| body.expr(e))),
    );
    quote! { #preamble #value }
}

/// The body of `friction_coefficients`: the array of each entry's pair
/// `(μs, μk)`.
fn coefficients(ctx: &Context) -> TokenStream {
    let entries = &ctx.eq.system.friction;
    let mus: Vec<Id> = entries
        .iter()
        .flat_map(|e| [e.mu_static, e.mu_kinetic])
        .collect();
    let body = Body::new(ctx.eq, &mus);
    let preamble = body.preamble();
    let pairs = entries.iter().map(|e| {
        let (s, k) = (body.expr(e.mu_static), body.expr(e.mu_kinetic));
        quote!((#s, #k))
    });
    quote! {
        #preamble
        [#(#pairs),*]
    }
}

/// `friction_modes` and `with_friction_modes`, over the system's mode
/// fields.
fn mode_methods(ctx: &Context) -> TokenStream {
    let f = ctx.eq.system.friction.len();
    let f_lit = Context::dim(f);
    let mode = ctx.path(quote!(friction::Mode));
    let fields: Vec<_> = (0..f).map(friction_mode).collect();
    quote! {
        /// The friction entries' modes (`Stick` after `new`).
        #[inline]
        pub fn friction_modes(&self) -> [#mode; #f_lit] {
            [#(#mode::slip(self.#fields)),*]
        }

        /// The same system with the friction entries in `modes`.
        #[inline]
        #[must_use]
        pub fn with_friction_modes(mut self, modes: [#mode; #f_lit]) -> Self {
            let [#(#fields),*] = modes;
            #(self.#fields = #fields.sign::<T>();)*
            self
        }
    }
}

/// `impl Friction for Name<T>`, forwarding to the inherent methods.
pub(super) fn trait_impl(ctx: &Context) -> TokenStream {
    let sys = &ctx.eq.system;
    if sys.friction.is_empty() {
        return TokenStream::new();
    }
    let name = &sys.name;
    let f = sys.friction.len();
    let (n_lit, k_lit, f_lit) = (Context::dim(ctx.n), Context::dim(ctx.k), Context::dim(f));
    let first_row = Context::dim(ctx.k - f);
    let friction = ctx.path(quote!(friction::Friction));
    let mode = ctx.path(quote!(friction::Mode));
    let state_type = ctx.path(quote!(State<T, #n_lit>));
    let multipliers = ctx.path(quote!(multipliers::Multipliers));
    let result = ctx.result(ctx.vector(f), quote!(DynamicsError));
    let state = ctx.params(Inputs::States);
    let vector = ctx.vector(f);
    quote! {
        impl<T: ::constrained::nalgebra::RealField + Copy> #friction<T, #n_lit, #k_lit, #f_lit>
            for #name<T>
        {
            fn friction_modes(&self) -> [#mode; #f_lit] {
                #name::friction_modes(self)
            }
            fn set_friction_modes(&mut self, modes: [#mode; #f_lit]) {
                *self = #name::with_friction_modes(*self, modes);
            }
            fn friction_velocities(&self, #state) -> #vector {
                #name::friction_velocities(self, q, qd, t)
            }
            fn friction_normals(&self, #state) -> #vector {
                #name::friction_normals(self, q, qd, t)
            }
            fn friction_coefficients(&self) -> [(T, T); #f_lit] {
                #name::friction_coefficients(self)
            }
            fn stick_forces(&self, state: &#state_type) -> #result {
                // The stick rows are the last of the constraints.
                let lambda = #multipliers::<T, #n_lit, #k_lit>::constraint_multipliers(self, state)?;
                ::core::result::Result::Ok(lambda.fixed_rows::<#f_lit>(#first_row).into_owned())
            }
        }
    }
}
