//! Code for the linearization: `acceleration_jacobian`, `linearize`,
//! `linearize_reduced`, and the impl of the runtime's hidden `Tangent`
//! trait (`tangent_rhs`, `velocity_constraint_jacobian`) they rest on.
//!
//! `tangent_rhs` evaluates, for every column variable `v` (coordinates,
//! velocities, inputs), the right-hand sides `F̃ᵥ` and `b̃ᵥ` of the tangent
//! system (see [`crate::tangent`]) as straight-line code over the exact
//! derivatives, contracted with `q̈` and `λ`.
//!
//! Where `M⁻¹` is symbolic (constant or diagonal `M`), the tangent systems
//! are solved in generated code: the same straight-line Gauss solve as
//! `acceleration` gives `q̈`, `λ` and the structured factorization of
//! `S = A M⁻¹ Aᵀ`, and each column is one sparse solve through it
//! (`q̈ᵥ = M⁻¹F̃ᵥ + W S⁺(b̃ᵥ − A M⁻¹F̃ᵥ)`, `W = M⁻¹Aᵀ`, only structural
//! nonzeros touched). Where the rank decision is suspect, and for a full
//! `M(q)`, the runtime (`constrained::linearize`) factors `M` and `S`
//! densely once and solves for every column.

use super::body::Body;
use super::context::{Context, Inputs};
use super::motion::{fallible, SymbolicGauss};
use crate::expr::Id;
use crate::motion::{MassInverse, Symbolic};
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
    let jac_body = match &ctx.eq.gauss {
        MassInverse::Symbolic(d) => structured(ctx, d, &jac_body),
        MassInverse::Cholesky | MassInverse::Auxiliary => jac_body,
    };
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

/// The body of `acceleration_jacobian` for a symbolic `M⁻¹`: the Gauss
/// solve of `acceleration` up to `λ`, then `(F̃, b̃)` from `tangent_rhs`,
/// then one sparse solve per column through the same factorization.
/// `dense` (the runtime's solve) answers where the rank decision is
/// suspect, exactly where `acceleration` consults the runtime.
fn structured(ctx: &Context, d: &Symbolic, dense: &TokenStream) -> TokenStream {
    let (n, k, nu) = (ctx.n, ctx.k, ctx.eq.system.inputs);
    let g = &ctx.eq.system.graph;
    let nonzero = |e: Id| !g.is_zero(e);
    // The constant pieces of every column's solve: A, W = M⁻¹Aᵀ and M⁻¹,
    // structural nonzeros only.
    let mut extra: Vec<Id> = Vec::new();
    extra.extend(ctx.eq.a.iter().flatten().copied().filter(|&e| nonzero(e)));
    extra.extend(d.weighted.iter().flatten().copied().filter(|&e| nonzero(e)));
    extra.extend(d.inverse.iter().flatten().copied().filter(|&e| nonzero(e)));
    let gauss = SymbolicGauss::new(ctx, d, &extra, false);
    let body = &gauss.body;
    let bind = |role: &str, entries: &[Vec<Id>]| -> TokenStream {
        let mut out = TokenStream::new();
        for (i, row) in entries.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                if nonzero(e) {
                    let (name, value) = (Context::local2(role, i, j), body.expr(e));
                    out.extend(quote! { let #name = #value; });
                }
            }
        }
        out
    };
    let constants = [
        bind("ja", &ctx.eq.a),
        bind("jw", &d.weighted),
        bind("jm", &d.inverse),
    ];
    // Σ entry·x over the structural nonzeros of one row, `T::zero()` if none.
    let dot = |role: &str, i: usize, row: &[Id], x: &dyn Fn(usize) -> syn::Ident| {
        let terms: Vec<TokenStream> = row
            .iter()
            .enumerate()
            .filter(|&(_, &e)| nonzero(e))
            .map(|(j, _)| {
                let (entry, x) = (Context::local2(role, i, j), x(j));
                quote!(#entry * #x)
            })
            .collect();
        if terms.is_empty() {
            quote!(T::zero())
        } else {
            quote!(#(#terms)+*)
        }
    };
    let f: Vec<_> = (0..n).map(|i| Context::local("jf", i)).collect();
    let b: Vec<_> = (0..k).map(|j| Context::local("jb", j)).collect();
    let free: Vec<_> = (0..n).map(|i| Context::local("ju", i)).collect();
    let r: Vec<_> = (0..k).map(|j| Context::local("jr", j)).collect();
    let mu: Vec<_> = (0..k).map(|j| Context::local("jmu", j)).collect();
    let free_values = (0..n).map(|i| dot("jm", i, &d.inverse[i], &|l| f[l].clone()));
    let residual_values = (0..k).map(|j| {
        let a_free = dot("ja", j, &ctx.eq.a[j], &|i| free[i].clone());
        let bj = &b[j];
        quote!(#bj - (#a_free))
    });
    let solve = gauss.ldlt.solve(&r, "jy", &mu);
    let column = (0..n).map(|i| {
        let (u, w) = (&free[i], dot("jw", i, &d.weighted[i], &|j| mu[j].clone()));
        quote!(#u + (#w))
    });
    let unpack_b = (k > 0).then(|| quote!(let [#(#b),*] = *__b;));
    let columns = 2 * n + nu;
    let (n_l, nu_l, k_l, d_l) = (
        Context::dim(n),
        Context::dim(nu),
        Context::dim(k),
        Context::dim(columns),
    );
    let tangent = ctx.private(quote!(Tangent<T, #n_l, #k_l, #d_l>));
    let qdd = ctx.vector_value(d.acceleration.iter().map(|&e| body.expr(e)));
    let lam = ctx.vector_value((0..k).map(|j| {
        let l = Context::local("lam", j);
        quote!(#l)
    }));
    let jacobians_zero = ctx.path(quote!(Jacobians::<T, #n_l, #nu_l>::zeros()));
    let value = if fallible(ctx) {
        let non_finite = ctx.path(quote!(DynamicsError::NonFinite));
        quote! {
            if __jac.is_finite() {
                ::core::result::Result::Ok(__jac)
            } else {
                ::core::result::Result::Err(#non_finite)
            }
        }
    } else {
        quote!(__jac)
    };
    // One local holds the answer on every path, so that it is built where
    // the caller wants it (a returned local assigned on two paths, or a
    // second local, costs a copy of the whole Jacobian: 32 KiB at 32 links).
    let (suspect, adopt) = if k > 0 {
        let suspect = gauss.ldlt.suspect(ctx.generic_rank);
        let adopt = if fallible(ctx) {
            quote! {
                match { #dense } {
                    ::core::result::Result::Ok(__dense) => __jac = __dense,
                    ::core::result::Result::Err(__e) => return ::core::result::Result::Err(__e),
                }
            }
        } else {
            quote!(__jac = { #dense };)
        };
        (suspect, adopt)
    } else {
        (quote!(false), TokenStream::new())
    };
    let to_multipliers = &gauss.to_multipliers;
    quote! {
        #to_multipliers
        let mut __jac = #jacobians_zero;
        if #suspect {
            #adopt
        } else {
            let mut __ft = ::constrained::nalgebra::SMatrix::<T, #n_l, #d_l>::zeros();
            let mut __bt = ::constrained::nalgebra::SMatrix::<T, #k_l, #d_l>::zeros();
            <Self as #tangent>::tangent_rhs(self, q, qd, t, &#qdd, &#lam, &mut __ft, &mut __bt);
            #(#constants)*
            let __outs = __jac.dq.data.0.iter_mut()
                .chain(__jac.dqd.data.0.iter_mut())
                .chain(__jac.du.data.0.iter_mut());
            for ((__f, __b), __out) in __ft.data.0.iter().zip(__bt.data.0.iter()).zip(__outs) {
                let [#(#f),*] = *__f;
                #unpack_b
                #(let #free = #free_values;)*
                #(let #r = #residual_values;)*
                #solve
                *__out = [#(#column),*];
            }
        }
        #value
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
    // Only the structural nonzeros are written: the caller passes zeros.
    let mut writes = TokenStream::new();
    let column_index = |c: usize| proc_macro2::Literal::usize_unsuffixed(c);
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
        let cl = column_index(c);
        for (i, terms) in f.into_iter().enumerate() {
            if !terms.is_empty() {
                let (il, value) = (column_index(i), sum(terms));
                writes.extend(quote! { __f.data.0[#cl][#il] = #value; });
            }
        }
        for (r, terms) in b.into_iter().enumerate() {
            if !terms.is_empty() {
                let (rl, value) = (column_index(r), sum(terms));
                writes.extend(quote! { __b.data.0[#cl][#rl] = #value; });
            }
        }
    }
    let (f_type, b_type) = (ctx.matrix(n, columns), ctx.matrix(k, columns));
    let (vector, k_vector) = (ctx.vector(n), ctx.vector(k));
    let params = ctx.params(Inputs::States);
    let unpack_qdd = (n > 0).then(|| quote!(let [[#(#qdd),*]] = qdd.data.0;));
    let unpack_lam = (k > 0).then(|| quote!(let [[#(#lam),*]] = lam.data.0;));
    quote! {
        /// Writes the right-hand sides `(F̃, b̃)` of the tangent systems, one
        /// column per variable (`q`, `q̇`, inputs), into `__f` and `__b`
        /// (structural nonzeros only; the caller passes zeros):
        /// `F̃ᵥ = ∂F/∂v − (∂M/∂v) q̈ + (∂A/∂v)ᵀ λ`, `b̃ᵥ = ∂b/∂v − (∂A/∂v) q̈`.
        #[inline]
        fn tangent_rhs(
            &self,
            #params,
            qdd: &#vector,
            lam: &#k_vector,
            __f: &mut #f_type,
            __b: &mut #b_type,
        ) {
            #unpack_qdd
            #unpack_lam
            #preamble
            #writes
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
