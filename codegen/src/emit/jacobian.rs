//! Code for the linearization: `acceleration_jacobian`, `linearize`,
//! `linearize_reduced`, and the impl of the runtime's hidden `Tangent`
//! trait (`tangent_rhs`, `velocity_constraint_jacobian`) they rest on.
//!
//! `tangent_rhs` evaluates, for every column variable `v` (coordinates,
//! velocities, inputs), the right-hand sides `F̃ᵥ` and `b̃ᵥ` of the tangent
//! system (see [`crate::tangent`]) as straight-line code over the exact
//! derivatives, contracted with `q̈` and `λ`. The runtime
//! (`constrained::linearize`) factors `M` and `S = A M⁻¹ Aᵀ` once and solves
//! for every column.

use super::body::Body;
use super::context::{Context, Inputs};
use super::motion::fallible;
use crate::expr::Id;
use crate::partition::Partition;
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
    let jacobian = ctx.path(quote!(linearize::acceleration_jacobian));
    let linearization = ctx.path(quote!(linearize::linearization));
    let least_squares = ctx.private(quote!(least_squares));
    let k_lit = Context::dim(ctx.k);
    let value =
        quote!(#jacobian::<T, Self, #n_lit, #k_lit, #nu_lit, #d_lit>(self, #args, __motion));
    let non_finite = ctx.path(quote!(DynamicsError::NonFinite));
    let (jac_ret, lin_ret, jac_body, lin_body) = if fallible(ctx) {
        (
            ctx.result(jacobians.clone(), quote!(DynamicsError)),
            ctx.result(quote!((#a_type, #b_type)), quote!(DynamicsError)),
            quote! {
                let __motion = self.gauss(#args, ::core::option::Option::None)?;
                let __j = #value;
                if __j.is_finite() {
                    ::core::result::Result::Ok(__j)
                } else {
                    ::core::result::Result::Err(#non_finite)
                }
            },
            quote! {
                self.acceleration_jacobian(#args)
                    .map(|j| #linearization::<T, #n_lit, #nu_lit, #n2_lit>(&j))
            },
        )
    } else {
        (
            jacobians.clone(),
            quote!((#a_type, #b_type)),
            quote! {
                let __motion = match self.gauss(#args, ::core::option::Option::None) {
                    ::core::result::Result::Ok(m) => m,
                    ::core::result::Result::Err(_) => {
                        #least_squares(self, #args, ::core::option::Option::None)
                    }
                };
                #value
            },
            quote! {
                #linearization::<T, #n_lit, #nu_lit, #n2_lit>(&self.acceleration_jacobian(#args))
            },
        )
    };
    let fallibility = if fallible(ctx) {
        "`Err` exactly where [`acceleration`](Self::acceleration) fails, \
         and `Err(NonFinite)` where a derivative overflows."
    } else {
        "Total, as [`acceleration`](Self::acceleration) is (where a derivative \
         overflows, the entries are not finite)."
    };
    let jac_doc = format!(
        " The exact Jacobians of `q̈(q, q̇, u)` at this state: `dq = ∂q̈/∂q`, \
         `dqd = ∂q̈/∂q̇`, `du = ∂q̈/∂u` (columns in the order of `coordinates` \
         and `inputs`). Differentiated at compile time and solved through one \
         factorization: `M q̈ᵥ = F̃ᵥ + Aᵀλᵥ`, `A q̈ᵥ = b̃ᵥ` for each variable `v` \
         (see `constrained::linearize`). Where the rank decision dropped rows \
         of `A`, the Jacobian of the `q̈` actually returned. {fallibility}"
    );
    let lin_doc = format!(
        " The linearization `δẋ = A δx + B δu` of `ẋ = (q̇, q̈(q, q̇, u))` for \
         `x = (q, q̇)`: `A = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]`, `B = [[0], [∂q̈/∂u]]`. \
         In all `2n` coordinates: on a constrained system it carries the \
         constraint directions (see `constrained::linearize::reduced` for the \
         linearization on the constraint manifold). {fallibility}"
    );
    let reduced = reduced(ctx, partition);
    quote! {
        #reduced

        #[doc = #jac_doc]
        #[inline]
        pub fn acceleration_jacobian(&self, #params) -> #jac_ret {
            #jac_body
        }

        #[doc = #lin_doc]
        #[inline]
        pub fn linearize(&self, #params) -> #lin_ret {
            #lin_body
        }
    }
}

/// `tangent_rhs(q, qd, t, qdd, lam) -> (F̃, b̃)`, one column per variable.
fn tangent_rhs(ctx: &Context) -> TokenStream {
    let eq = ctx.eq;
    let tan = &eq.tangent;
    let (n, k, columns) = (ctx.n, ctx.k, tan.columns.len());
    let g = &eq.system.graph;
    let mut roots: Vec<Id> = Vec::new();
    for c in 0..columns {
        roots.extend(tan.forces[c].iter().filter(|&&e| !g.is_zero(e)));
        roots.extend(tan.mass[c].iter().map(|&(_, _, e)| e));
        roots.extend(tan.a[c].iter().map(|&(_, _, e)| e));
        roots.extend(tan.b[c].iter().filter(|&&e| !g.is_zero(e)));
    }
    let body = Body::new(eq, &roots);
    let preamble = body.preamble();
    let qdd: Vec<_> = (0..n).map(|i| Context::local("qdd", i)).collect();
    let lam: Vec<_> = (0..k).map(|r| Context::local("lam", r)).collect();
    // A term is `(negative, tokens)`; a derivative that is ±1 multiplies
    // by nothing.
    let times = |e: Id, x: &syn::Ident, negative: bool| -> (bool, TokenStream) {
        match g.as_num(e) {
            Some(c) if c.is_one() => (negative, quote!(#x)),
            Some(c) if (-c).is_one() => (!negative, quote!(#x)),
            _ => {
                let e = body.expr(e);
                (negative, quote!((#e) * #x))
            }
        }
    };
    let sum = |terms: Vec<(bool, TokenStream)>| {
        let mut out = TokenStream::new();
        for (i, (negative, term)) in terms.into_iter().enumerate() {
            out.extend(match (i, negative) {
                (0, false) => term,
                (0, true) => quote!(-#term),
                (_, false) => quote!(+ #term),
                (_, true) => quote!(- #term),
            });
        }
        if out.is_empty() {
            quote!(T::zero())
        } else {
            out
        }
    };
    let mut f_columns = Vec::with_capacity(columns);
    let mut b_columns = Vec::with_capacity(columns);
    for c in 0..columns {
        let mut f: Vec<Vec<(bool, TokenStream)>> = vec![Vec::new(); n];
        for (i, &e) in tan.forces[c].iter().enumerate() {
            if !g.is_zero(e) {
                f[i].push((false, body.expr(e)));
            }
        }
        for &(i, j, e) in &tan.mass[c] {
            f[i].push(times(e, &qdd[j], true));
        }
        let mut b: Vec<Vec<(bool, TokenStream)>> = vec![Vec::new(); k];
        for (r, &e) in tan.b[c].iter().enumerate() {
            if !g.is_zero(e) {
                b[r].push((false, body.expr(e)));
            }
        }
        for &(r, i, e) in &tan.a[c] {
            f[i].push(times(e, &lam[r], false));
            b[r].push(times(e, &qdd[i], true));
        }
        f_columns.push(f.into_iter().map(sum).collect());
        b_columns.push(b.into_iter().map(sum).collect());
    }
    let f_value = ctx.matrix_value(n, f_columns);
    let b_value = ctx.matrix_value(k, b_columns);
    let (f_type, b_type) = (ctx.matrix(n, columns), ctx.matrix(k, columns));
    let (vector, k_vector) = (ctx.vector(n), ctx.vector(k));
    let params = ctx.params(Inputs::States);
    let unpack_qdd = (n > 0).then(|| quote!(let [[#(#qdd),*]] = qdd.data.0;));
    let unpack_lam = (k > 0).then(|| quote!(let [[#(#lam),*]] = lam.data.0;));
    quote! {
        /// The right-hand sides `(F̃, b̃)` of the tangent systems, one column
        /// per variable (`q`, `q̇`, inputs): `F̃ᵥ = ∂F/∂v − (∂M/∂v) q̈ +
        /// (∂A/∂v)ᵀ λ`, `b̃ᵥ = ∂b/∂v − (∂A/∂v) q̈`.
        #[inline]
        fn tangent_rhs(
            &self,
            #params,
            qdd: &#vector,
            lam: &#k_vector,
        ) -> (#f_type, #b_type) {
            #unpack_qdd
            #unpack_lam
            #preamble
            (#f_value, #b_value)
        }
    }
}

/// `∂ψ/∂q` of the velocity-level constraints, `k × n`.
fn velocity_constraint_jacobian(ctx: &Context) -> TokenStream {
    let rows = &ctx.eq.tangent.velocity_constraints;
    let roots: Vec<Id> = rows.iter().flatten().copied().collect();
    let body = Body::new(ctx.eq, &roots);
    let preamble = body.preamble();
    let columns: Vec<Vec<TokenStream>> = (0..ctx.n)
        .map(|j| rows.iter().map(|row| body.expr(row[j])).collect())
        .collect();
    let value = ctx.matrix_value(ctx.k, columns);
    let (params, ret) = (ctx.params(Inputs::States), ctx.matrix(ctx.k, ctx.n));
    quote! {
        /// `∂ψ/∂q` of the velocity-level constraints `ψ` (`φ̇` or `φ`).
        #[inline]
        fn velocity_constraint_jacobian(&self, #params) -> #ret {
            #preamble
            #value
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
    let jacobian = if fallible(ctx) {
        quote!(self.acceleration_jacobian(#args)?)
    } else {
        quote!(self.acceleration_jacobian(#args))
    };
    let doc = format!(
        " The linearization on the constraint manifold \
         (`constrained::linearize::Reduced`): `{nq}` coordinates and `{nv}` \
         speeds, the dependent ones chosen at this state where they are best \
         conditioned. The constraint directions are eliminated, so its \
         eigenvalues are the physical ones. `Err(SingularPartition)` where \
         the constraints lose rank at this state; otherwise as \
         [`acceleration_jacobian`](Self::acceleration_jacobian)."
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
    let rhs = tangent_rhs(ctx);
    let psi_q = velocity_constraint_jacobian(ctx);
    quote! {
        #[allow(unused_variables, non_snake_case, clippy::all, clippy::pedantic)]
        impl<T: ::constrained::nalgebra::RealField + Copy> #trait_path for #name<T> {
            #rhs
            #psi_q
        }
    }
}
