//! The Jacobians of `q̈` and of `λ` in the quaternions' velocity
//! coordinates: the tangent systems solved through the factors `gauss`
//! builds ([`super::velocity`]), instead of the runtime's dense solve of
//! the auxiliary mass.
//!
//! Each tangent system `M q̈ᵥ = F̃ᵥ + Aᵀλᵥ`, `A q̈ᵥ = b̃ᵥ`
//! (`crate::equations::tangent`) has `gauss`'s matrix, so it is the same
//! velocity-form system with another right-hand side: `q̈ᵥ = T zᵥ`,
//!
//! ```text
//! [ TᵀMT  TᵀAᵀ ] [ zᵥ ]   [ TᵀF̃ᵥ ]
//! [ A T    0   ] [ μᵥ ] = [  b̃ᵥ  ],      λᵥ = −μᵥ,
//! ```
//!
//! with a point's rows under a free base premultiplied by `R̂ᵀ` on both
//! sides (its `λ = R̂ μ'`). `Tᵀ` is read off `T` itself: a leg's joint's
//! entry as it is, a free base position's `R̂ᵀ F̃`, a quaternion's
//! `½ qᵀ F̃` (its `α`) and `½ G F̃` (its `β`). One body evaluates the form
//! and factors it as `gauss` does (the same checks, each handing the
//! answer to the runtime's dense solve), solves `gauss`'s own right-hand
//! side for the `q̈` and `λ` that `tangent_rhs` contracts with, then one
//! loop runs every column through those factors: the legs' `J⁻¹` and the
//! base's `L D Lᵀ` with the feet held, or the saddle-point `L D Lᵀ`.
//! A body held at three or more points (its points' `λ` not unique) keeps
//! the runtime's solve.

use super::legs;
use super::saddle::{or_zero, solved};
use super::velocity::{self, accelerations, free_rotation, in_world, multipliers, row_times};
use crate::bodies::free::G_PATTERN;
use crate::emit::context::{Context, Inputs};
use crate::emit::literal::literal;
use crate::equations::legs::Legs;
use crate::equations::velocity::Velocity;
use crate::expr::num::Num;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The name of the private method [`method`] emits.
pub(in crate::emit) fn name() -> Ident {
    Ident::new("__velocity_jacobians", proc_macro2::Span::call_site())
}

/// Whether [`method`] applies: no body held at three or more points.
pub(super) fn applies(v: &Velocity) -> bool {
    v.system.held.is_empty()
}

/// The private methods `__velocity_jacobians(q, qd, t, multipliers)`,
/// returning `(∂q̈, ∂λ)` (`∂λ` zeros unless `multipliers`), and its
/// fallback `__velocity_jacobians_dense`, the runtime's solve after
/// `gauss`'s motion.
pub(super) fn method(ctx: &Context, v: &Velocity, legs: Option<&Legs>) -> TokenStream {
    let (n, k, nu) = (ctx.n, ctx.k, ctx.eq.system.inputs);
    let (n_l, k_l, nu_l) = (Context::dim(n), Context::dim(k), Context::dim(nu));
    let d_l = Context::dim(2 * n + nu);
    let jacobians = ctx.path(quote!(Jacobians<T, #n_l, #nu_l>));
    let lambdas = ctx.path(quote!(linearize::MultiplierJacobians<T, #n_l, #k_l, #nu_l>));
    let literal = ctx.path(quote!(linearize::MultiplierJacobians::<T, #n_l, #k_l, #nu_l>));
    let error = ctx.path(quote!(DynamicsError));
    let result = quote!(::core::result::Result<(#jacobians, #lambdas), #error>);
    let (params, args) = (ctx.params(Inputs::States), ctx.args(Inputs::States));
    let name = name();
    let dense_name = Ident::new("__velocity_jacobians_dense", proc_macro2::Span::call_site());
    let dense = quote! { return self.#dense_name(#args, multipliers); };
    let bail = |_: TokenStream| dense.clone();
    let solved = velocity::solve(ctx, v, legs, &dense, &bail);
    let qdd: Vec<Ident> = (0..n).map(|i| Context::local("qdd", i)).collect();
    let lam: Vec<Ident> = (0..k).map(|r| Context::local("lam", r)).collect();
    let (acc, mu) = (&solved.acceleration, &solved.mu);
    let lam_values = mu.iter().map(|m| {
        let m = or_zero(m);
        quote!(-(#m))
    });
    let columns = columns(ctx, v, legs, &solved.ldlt, &dense);
    let tangent = ctx.private(quote!(Tangent<T, #n_l, #k_l, #d_l>));
    let zeros = |rows: usize, cols: usize| {
        let m = ctx.matrix(rows, cols);
        quote!(<#m>::zeros())
    };
    let (fs, rs) = (zeros(n, 2 * n + nu), zeros(k, 2 * n + nu));
    let (ldq, ldu) = (zeros(k, n), zeros(k, nu));
    let jacobians_zero = ctx.jacobians_zero().0;
    let correction = ctx.correction_type();
    let body = solved.code;
    let (qdd_vector, lam_vector) = (
        ctx.vector_value(qdd.iter().map(|x| quote!(#x))),
        ctx.vector_value(lam.iter().map(|x| quote!(#x))),
    );
    let dense_method = dense_method(ctx, &dense_name, &params, &result, &literal);
    quote! {
        /// `(∂q̈, ∂λ)` through the velocity form's factors (`∂λ` zeros
        /// unless `multipliers`); the runtime's dense solve where a check
        /// of the factorization fails.
        #[allow(clippy::too_many_lines, clippy::many_single_char_names)]
        fn #name(&self, #params, multipliers: bool) -> #result {
            let correction: #correction = ::core::option::Option::None;
            #body
            #( let #qdd = #acc; )*
            #( let #lam = #lam_values; )*
            let mut __fs = #fs;
            let mut __rs = #rs;
            <Self as #tangent>::tangent_rhs(
                self,
                #args,
                &#qdd_vector,
                &#lam_vector,
                &mut __fs,
                &mut __rs,
            );
            let mut __jac = #jacobians_zero;
            let mut __lj = #literal { dq: #ldq, dqd: #ldq, du: #ldu };
            {
                let __outs = __jac.dq.data.0.iter_mut()
                    .chain(__jac.dqd.data.0.iter_mut())
                    .chain(__jac.du.data.0.iter_mut());
                let __louts = __lj.dq.data.0.iter_mut()
                    .chain(__lj.dqd.data.0.iter_mut())
                    .chain(__lj.du.data.0.iter_mut());
                let __pairs = __fs.data.0.iter().zip(__rs.data.0.iter()).zip(__outs).zip(__louts);
                for (((__f, __r), __out), __lout) in __pairs {
                    #columns
                }
            }
            if __jac.is_finite() && __lj.is_finite() {
                ::core::result::Result::Ok((__jac, __lj))
            } else {
                ::core::result::Result::Err(#error::NonFinite)
            }
        }

        #dense_method
    }
}

/// `__velocity_jacobians_dense` (`lambdas` the path of `∂λ`'s struct): `gauss`'s motion, then the runtime's
/// dense solve of the tangent systems (its rank rule decides where the
/// velocity form's checks failed).
fn dense_method(
    ctx: &Context,
    name: &Ident,
    params: &TokenStream,
    result: &TokenStream,
    lambdas: &TokenStream,
) -> TokenStream {
    let (n, k, nu) = (ctx.n, ctx.k, ctx.eq.system.inputs);
    let (n_l, k_l, nu_l) = (Context::dim(n), Context::dim(k), Context::dim(nu));
    let d_l = Context::dim(2 * n + nu);
    let args = ctx.args(Inputs::States);
    let motion = ctx.call_gauss("Fallible", quote!(::core::option::Option::None));
    let both = ctx.path(quote!(linearize::try_acceleration_and_multiplier_jacobians));
    let alone = ctx.path(quote!(linearize::try_acceleration_jacobian));
    let zeros = |rows: usize, cols: usize| {
        let m = ctx.matrix(rows, cols);
        quote!(<#m>::zeros())
    };
    let (ldq, ldu) = (zeros(k, n), zeros(k, nu));
    quote! {
        /// The runtime's dense solve of the tangent systems after
        /// `gauss`'s motion: where a check of the velocity form fails.
        #[inline(never)]
        fn #name(&self, #params, multipliers: bool) -> #result {
            let __motion = #motion?;
            if multipliers {
                #both::<T, Self, #n_l, #k_l, #nu_l, #d_l>(self, #args, __motion)
            } else {
                let __j = #alone::<T, Self, #n_l, #k_l, #nu_l, #d_l>(self, #args, __motion)?;
                ::core::result::Result::Ok((__j, #lambdas { dq: #ldq, dqd: #ldq, du: #ldu }))
            }
        }
    }
}

/// The loop's body: column `__f` (`F̃`), `__r` (`b̃`) into the velocity
/// form, solved through the factors, `q̈ᵥ = T zᵥ` into `*__out` and, where
/// `multipliers`, `λᵥ = −μᵥ` into `*__lout`.
fn columns(
    ctx: &Context,
    v: &Velocity,
    legs: Option<&Legs>,
    ldlt: &crate::emit::ldlt::StructuredLdlt,
    dense: &TokenStream,
) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let jf: Vec<Ident> = (0..n).map(|i| Context::local("jf", i)).collect();
    let jb: Vec<Ident> = (0..k).map(|r| Context::local("jb", r)).collect();
    let (forces_code, forces) = turned_forces(v, n);
    let (rows_code, rows) = turned_rows(ctx, v);
    let (nr, kr) = (v.coordinates.len(), v.rows.len());
    let mut rhs: Vec<Option<TokenStream>> = v
        .coordinates
        .iter()
        .map(|&i| {
            let f = &forces[i];
            Some(quote!(#f))
        })
        .collect();
    rhs.extend(rows.iter().map(|b| Some(quote!(#b))));
    let (solve, values) = match legs {
        Some(legs) => {
            let entry = |i: usize, j: usize| v.structure.nonzero[i][j].then(|| ldlt.entry(i, j));
            legs::solve(legs, (nr, kr), &entry, (&rhs, false), dense)
        }
        None => solved(ldlt, &rhs, (nr, kr)),
    };
    let (recover, acceleration) = accelerations(ctx, v, &values);
    let alpha_forces: Vec<Option<TokenStream>> = forces.iter().map(|f| Some(quote!(#f))).collect();
    let (norms, mut mu) = multipliers(ctx, v, &values, &alpha_forces);
    let world = in_world(v, &mut mu);
    let lambda = mu.iter().map(|m| {
        let m = or_zero(m);
        quote!(-(#m))
    });
    let unpack_b = (k > 0).then(|| quote!(let [#(#jb),*] = *__r;));
    quote! {
        let [#(#jf),*] = *__f;
        #unpack_b
        #forces_code
        #rows_code
        #solve
        #recover
        *__out = [#(#acceleration),*];
        if multipliers {
            #norms
            #world
            *__lout = [#(#lambda),*];
        }
    }
}

/// `TᵀF̃` of a column (`F̃` in `__jf{i}`) into `__jt{i}` by the model's
/// coordinate: a free base position's `R̂ᵀ F̃`, a quaternion's `½ qᵀ F̃` at
/// its `w` coordinate (its `α`) and `½ G F̃` at its three others (its `β`),
/// every other coordinate's `F̃` as it is.
fn turned_forces(v: &Velocity, n: usize) -> (TokenStream, Vec<Ident>) {
    let jf: Vec<Ident> = (0..n).map(|i| Context::local("jf", i)).collect();
    let mut value: Vec<TokenStream> = jf.iter().map(|f| quote!(#f)).collect();
    for (t, &(x, _)) in v.system.free.iter().enumerate() {
        for j in 0..3 {
            let r = [0, 1, 2].map(|i| free_rotation(t, i, j));
            let turned = row_times(r, [&jf[x], &jf[x + 1], &jf[x + 2]]);
            value[x + j] = turned;
        }
    }
    let (half, _) = literal(Num::Rational(1, 2));
    for &(c, _) in &v.system.quaternions {
        let q: Vec<Ident> = (0..4).map(|m| Context::local("qv", c + m)).collect();
        let f = &jf[c..c + 4];
        value[c] = quote!((#(#q * #f)+*) * #half);
        for (j, row) in G_PATTERN.iter().enumerate() {
            let terms = row.iter().enumerate().map(|(kk, &(plus, m))| {
                let (q, f) = (&q[m], &f[kk]);
                if plus {
                    quote!(+ #q * #f)
                } else {
                    quote!(- #q * #f)
                }
            });
            value[c + 1 + j] = quote!((T::zero() #(#terms)*) * #half);
        }
    }
    let names: Vec<Ident> = (0..n).map(|i| Context::local("jt", i)).collect();
    let code = quote! { #( let #names = #value; )* };
    (code, names)
}

/// `b̃` of a column (`__jb{r}`) into the kept rows' right-hand sides
/// `__jv{rr}`: a point's rows under a free base turned by `R̂ᵀ`, each
/// quaternion's `α = b̃_norm / (A T)_{norm,α}` (locals `__alpha{c}`,
/// which `q̈ᵥ = T zᵥ` reads), then `b̃ − Σ (A T)_{rα} α`.
fn turned_rows(ctx: &Context, v: &Velocity) -> (TokenStream, Vec<Ident>) {
    let g = &ctx.eq.system.graph;
    let jb: Vec<Ident> = (0..ctx.k).map(|r| Context::local("jb", r)).collect();
    let mut b: Vec<TokenStream> = jb.iter().map(|x| quote!(#x)).collect();
    for rows in &v.system.in_base {
        let [b0, b1, b2] = rows.rows.map(|r| &jb[r]);
        for (i, &r) in rows.rows.iter().enumerate() {
            let turned = row_times(
                [0, 1, 2].map(|j| velocity::rotation_local(v, rows, j, i)),
                [b0, b1, b2],
            );
            b[r] = quote!((#turned));
        }
    }
    let mut code = TokenStream::new();
    for &(c, norm) in &v.system.quaternions {
        let (alpha, an, bn) = (
            Context::local("alpha", c),
            Context::local2("aa", norm, c),
            &b[norm],
        );
        code.extend(quote! { let #alpha = #bn / #an; });
    }
    let mut names = Vec::with_capacity(v.rows.len());
    for (rr, &r) in v.rows.iter().enumerate() {
        let terms: Vec<TokenStream> = (v.system.quaternions.iter())
            .filter(|&&(c, _)| !g.is_zero(v.system.a[r][c]))
            .map(|&(c, _)| {
                let (a, alpha) = (Context::local2("aa", r, c), Context::local("alpha", c));
                quote!(#a * #alpha)
            })
            .collect();
        let own = &b[r];
        let value = if terms.is_empty() {
            quote!(#own)
        } else {
            quote!(#own - (#(#terms)+*))
        };
        let name = Context::local("jv", rr);
        code.extend(quote! { let #name = #value; });
        names.push(name);
    }
    (code, names)
}
