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
//! base's `L D Lᵀ` with the feet held, or the saddle-point `L D Lᵀ`. Each
//! column's solve is emitted for the rows its right-hand side can touch,
//! columns of one pattern sharing one copy ([`looped`]). A body held at
//! three or more points (its points' `λ` not unique) keeps the runtime's
//! solve.

use super::groups::{dispatch, Dispatch, Pattern};
use super::legs;
use super::saddle::{or_zero, solved};
use super::velocity::{self, accelerations, free_rotation, in_world, multipliers};
use crate::bodies::free::G_PATTERN;
use crate::emit::context::{Context, Inputs};
use crate::emit::ldlt::StructuredLdlt;
use crate::emit::literal::literal;
use crate::emit::tangent::column_patterns;
use crate::equations::legs::Legs;
use crate::equations::mass_inverse::Factored;
use crate::equations::strategy::Strategy;
use crate::equations::velocity::Velocity;
use crate::expr::num::Num;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The private methods that solve the tangent systems through the
/// velocity form's factors (the module docs), where `gauss` solves that
/// form and no body is held at three or more points; the name of the one
/// that answers `(∂q̈, ∂λ)`, and of the one that writes them into the
/// caller's outputs.
pub(in crate::emit) fn velocity_jacobians(
    ctx: &Context,
    f: &Factored,
) -> Option<(TokenStream, Ident, Ident)> {
    let strategy = ctx.eq.strategy();
    let v = f.velocity.as_ref().filter(|v| applies(v))?;
    let legs = match strategy {
        Strategy::Legs => f.legs.as_ref(),
        Strategy::VelocitySaddle => None,
        _ => return None,
    };
    Some((method(ctx, v, legs), name(), into_name()))
}

/// The name of the private method [`method`] emits.
fn name() -> Ident {
    Ident::new("__velocity_jacobians", proc_macro2::Span::call_site())
}

/// The name of the private method that writes [`name`]'s answer into the
/// caller's outputs.
fn into_name() -> Ident {
    Ident::new("__velocity_jacobians_into", proc_macro2::Span::call_site())
}

/// Whether [`method`] applies: no body held at three or more points.
fn applies(v: &Velocity) -> bool {
    v.system.held.is_empty()
}

/// The private methods `__velocity_jacobians(q, qd, t)`, returning
/// `(∂q̈, ∂λ)`, `__velocity_jacobians_into`, which writes them (`∂λ` only
/// where `multipliers`) into the caller's outputs, and their
/// fallback `__velocity_jacobians_dense`, the runtime's solve after
/// `gauss`'s motion.
fn method(ctx: &Context, v: &Velocity, legs: Option<&Legs>) -> TokenStream {
    let (n, k, nu) = (ctx.n, ctx.k, ctx.eq.system.inputs);
    let (n_l, k_l, nu_l) = (Context::dim(n), Context::dim(k), Context::dim(nu));
    let d_l = Context::dim(2 * n + nu);
    let jacobians = ctx.path(quote!(Jacobians<T, #n_l, #nu_l>));
    let lambdas = ctx.path(quote!(linearize::MultiplierJacobians<T, #n_l, #k_l, #nu_l>));
    let lambdas_zero = ctx.multiplier_jacobians_zero();
    let error = ctx.path(quote!(DynamicsError));
    let result = quote!(::core::result::Result<(#jacobians, #lambdas), #error>);
    let (params, args) = (ctx.params(Inputs::States), ctx.args(Inputs::States));
    let name = name();
    let into = into_name();
    let dense_name = Ident::new("__velocity_jacobians_dense", proc_macro2::Span::call_site());
    let dense = quote! {
        let (__dj, __dl) = self.#dense_name(#args, multipliers)?;
        (*__jac, *__lj) = (__dj, __dl);
        return ::core::result::Result::Ok(());
    };
    let bail = |_: TokenStream| dense.clone();
    let solved = velocity::solve(ctx, v, legs, &dense, &bail);
    let qdd: Vec<Ident> = (0..n).map(|i| Context::local("qdd", i)).collect();
    let lam: Vec<Ident> = (0..k).map(|r| Context::local("lam", r)).collect();
    let (acc, mu) = (&solved.acceleration, &solved.mu);
    let lam_values = mu.iter().map(|m| {
        let m = or_zero(m);
        quote!(-(#m))
    });
    let columns = looped(ctx, v, legs, &solved.ldlt, &dense);
    let jacobians_zero = ctx.jacobians_zero().0;
    let outputs = outputs(ctx, &columns);
    let tangent = ctx.private(quote!(Tangent<T, #n_l, #k_l, #d_l>));
    let (fs, rs) = (ctx.matrix(n, 2 * n + nu), ctx.matrix(k, 2 * n + nu));
    let correction = ctx.correction_type();
    let body = solved.code;
    let (qdd_vector, lam_vector) = (
        ctx.vector_value(qdd.iter().map(|x| quote!(#x))),
        ctx.vector_value(lam.iter().map(|x| quote!(#x))),
    );
    let dense_method = dense_method(ctx, &dense_name, &params, &result, &lambdas_zero);
    let into_result = quote!(::core::result::Result<(), #error>);
    quote! {
        /// `(∂q̈, ∂λ)` through the velocity form's factors; the runtime's
        /// dense solve where a check of the factorization fails.
        #[inline]
        fn #name(&self, #params) -> #result {
            let (mut __jac, mut __lj) = (#jacobians_zero, #lambdas_zero);
            self.#into(#args, true, &mut __jac, &mut __lj)?;
            ::core::result::Result::Ok((__jac, __lj))
        }

        /// The same `(∂q̈, ∂λ)` written into `__jac` and, where
        /// `multipliers`, `__lj`, every entry (the caller's own may hold
        /// anything).
        #[allow(clippy::too_many_lines, clippy::many_single_char_names)]
        fn #into(
            &self,
            #params,
            multipliers: bool,
            __jac: &mut #jacobians,
            __lj: &mut #lambdas,
        ) -> #into_result {
            let correction: #correction = ::core::option::Option::None;
            #body
            #( let #qdd = #acc; )*
            #( let #lam = #lam_values; )*
            let mut __fs = <#fs>::zeros();
            let mut __rs = <#rs>::zeros();
            <Self as #tangent>::tangent_rhs(
                self,
                #args,
                &#qdd_vector,
                &#lam_vector,
                &mut __fs,
                &mut __rs,
            );
            #outputs
        }

        #dense_method
    }
}

/// The outputs `__jac` and `__lj` (the caller's), each column written by
/// the loop `columns` over `__pairs`, then checked finite.
fn outputs(ctx: &Context, columns: &TokenStream) -> TokenStream {
    let error = ctx.path(quote!(DynamicsError));
    quote! {
        {
            let __outs = __jac.dq.data.0.iter_mut()
                .chain(__jac.dqd.data.0.iter_mut())
                .chain(__jac.du.data.0.iter_mut());
            let __louts = __lj.dq.data.0.iter_mut()
                .chain(__lj.dqd.data.0.iter_mut())
                .chain(__lj.du.data.0.iter_mut());
            let __pairs = __fs.data.0.iter().zip(__rs.data.0.iter()).zip(__outs).zip(__louts);
            #columns
        }
        if __jac.is_finite() && (!multipliers || __lj.is_finite()) {
            ::core::result::Result::Ok(())
        } else {
            ::core::result::Result::Err(#error::NonFinite)
        }
    }
}

/// `__velocity_jacobians_dense` (`lambdas_zero` the zeros of `∂λ`'s
/// struct): `gauss`'s motion, then the runtime's dense solve of the
/// tangent systems (its rank rule decides where the velocity form's checks
/// failed).
fn dense_method(
    ctx: &Context,
    name: &Ident,
    params: &TokenStream,
    result: &TokenStream,
    lambdas_zero: &TokenStream,
) -> TokenStream {
    let (n, k, nu) = (ctx.n, ctx.k, ctx.eq.system.inputs);
    let (n_l, k_l, nu_l) = (Context::dim(n), Context::dim(k), Context::dim(nu));
    let d_l = Context::dim(2 * n + nu);
    let args = ctx.args(Inputs::States);
    let motion = ctx.call_gauss("Fallible", quote!(::core::option::Option::None));
    let both = ctx.path(quote!(linearize::try_acceleration_and_multiplier_jacobians));
    let alone = ctx.path(quote!(linearize::try_acceleration_jacobian));
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
                ::core::result::Result::Ok((__j, #lambdas_zero))
            }
        }
    }
}

/// The loop over the columns of `tangent_rhs`: each column's solve
/// specialized to the rows its right-hand side can touch (a leg's joint
/// moves its own foot's rows and the base's forces only), the columns
/// grouped by those patterns ([`super::groups`]) and dispatched by a constant
/// table; a structurally zero column is written as zeros.
fn looped(
    ctx: &Context,
    v: &Velocity,
    legs: Option<&Legs>,
    ldlt: &StructuredLdlt,
    dense: &TokenStream,
) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let every = (vec![true; n], vec![true; k]);
    let each = |pattern: &Pattern| columns(ctx, v, legs, ldlt, dense, pattern);
    let Some(patterns) = column_patterns(ctx) else {
        let body = each(&every);
        return quote! {
            for (((__f, __r), __out), __lout) in __pairs {
                #body
            }
        };
    };
    // The outputs are the caller's: a structurally zero column is written
    // as zeros.
    let (n_l, k_l) = (Context::dim(n), Context::dim(k));
    let zero = quote! {
        *__out = [T::zero(); #n_l];
        if multipliers {
            *__lout = [T::zero(); #k_l];
        }
    };
    let Dispatch { table, arms, .. } = dispatch(&patterns, &each, &zero);
    quote! {
        #table
        for ((((__f, __r), __out), __lout), __g) in __pairs.zip(__GROUPS) {
            #arms
        }
    }
}

/// The loop's body for the columns of `pattern`: column `__f` (`F̃`),
/// `__r` (`b̃`) into the velocity form, solved through the factors,
/// `q̈ᵥ = T zᵥ` into `*__out` and, where `multipliers`, `λᵥ = −μᵥ` into
/// `*__lout`.
fn columns(
    ctx: &Context,
    v: &Velocity,
    legs: Option<&Legs>,
    ldlt: &StructuredLdlt,
    dense: &TokenStream,
    (fp, bp): &Pattern,
) -> TokenStream {
    let (n, k) = (ctx.n, ctx.k);
    let read = |on: bool, name: Ident| if on { quote!(#name) } else { quote!(_) };
    let jf = (0..n).map(|i| read(fp[i], Context::local("jf", i)));
    let jb = (0..k).map(|r| read(bp[r], Context::local("jb", r)));
    let (forces_code, forces) = turned_forces(v, fp);
    let (rows_code, rows) = turned_rows(ctx, v, bp);
    let (nr, kr) = (v.coordinates.len(), v.rows.len());
    let mut rhs: Vec<Option<TokenStream>> = v
        .coordinates
        .iter()
        .map(|&i| forces[i].as_ref().map(|f| quote!(#f)))
        .collect();
    rhs.extend(rows.iter().map(|b| b.as_ref().map(|b| quote!(#b))));
    let (solve, values) = match legs {
        Some(legs) => {
            let entry = |i: usize, j: usize| v.structure.nonzero[i][j].then(|| ldlt.entry(i, j));
            legs::solve(legs, (nr, kr), &entry, (&rhs, false), dense)
        }
        None => solved(ldlt, &rhs, (nr, kr)),
    };
    let (recover, acceleration) = accelerations(ctx, v, &values);
    let alpha_forces: Vec<Option<TokenStream>> = (forces.iter())
        .map(|f| f.as_ref().map(|f| quote!(#f)))
        .collect();
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

/// `TᵀF̃` of a column (`F̃` in `__jf{i}`, nonzero where `fp`) into
/// `__jt{i}` by the model's coordinate: a free base position's `R̂ᵀ F̃`, a
/// quaternion's `½ qᵀ F̃` at its `w` coordinate (its `α`) and `½ G F̃` at
/// its three others (its `β`), every other coordinate's `F̃` as it is;
/// `None` where structurally zero.
fn turned_forces(v: &Velocity, fp: &[bool]) -> (TokenStream, Vec<Option<Ident>>) {
    let n = fp.len();
    let jf = |i: usize| fp[i].then(|| Context::local("jf", i));
    let mut value: Vec<Option<TokenStream>> = (0..n).map(|i| jf(i).map(|f| quote!(#f))).collect();
    for (t, &(x, _)) in v.system.free.iter().enumerate() {
        for j in 0..3 {
            let terms = (0..3).filter_map(|i| {
                let (r, f) = (free_rotation(t, i, j), jf(x + i)?);
                Some((quote!(#r), quote!(#f)))
            });
            value[x + j] = sum_of_products(terms);
        }
    }
    let (half, _) = literal(Num::Rational(1, 2));
    for &(c, _) in &v.system.quaternions {
        let q = |m: usize| Context::local("qv", c + m);
        let alpha = (0..4).filter_map(|m| {
            let (q, f) = (q(m), jf(c + m)?);
            Some((quote!(#q), quote!(#f)))
        });
        value[c] = sum_of_products(alpha).map(|a| quote!((#a) * #half));
        for (j, row) in G_PATTERN.iter().enumerate() {
            let terms: Vec<TokenStream> = (row.iter().enumerate())
                .filter_map(|(kk, &(plus, m))| {
                    let (q, f) = (q(m), jf(c + kk)?);
                    Some(if plus {
                        quote!(+ #q * #f)
                    } else {
                        quote!(- #q * #f)
                    })
                })
                .collect();
            value[c + 1 + j] = (!terms.is_empty()).then(|| quote!((T::zero() #(#terms)*) * #half));
        }
    }
    let mut code = TokenStream::new();
    let names = (value.into_iter().enumerate())
        .map(|(i, value)| {
            let value = value?;
            let name = Context::local("jt", i);
            code.extend(quote! { let #name = #value; });
            Some(name)
        })
        .collect();
    (code, names)
}

/// `Σ aᵢ bᵢ`, `None` for no pairs.
fn sum_of_products(pairs: impl Iterator<Item = (TokenStream, TokenStream)>) -> Option<TokenStream> {
    let terms: Vec<TokenStream> = pairs.map(|(a, b)| quote!(#a * #b)).collect();
    (!terms.is_empty()).then(|| quote!(#(#terms)+*))
}

/// `b̃` of a column (`__jb{r}`, nonzero where `bp`) into the kept rows'
/// right-hand sides `__jv{rr}` (`None` where structurally zero): a
/// point's rows under a free base turned by `R̂ᵀ`, each quaternion's
/// `α = b̃_norm / (A T)_{norm,α}` (locals `__alpha{c}`, zero without a
/// `b̃_norm`, which `q̈ᵥ = T zᵥ` reads), then `b̃ − Σ (A T)_{rα} α`.
fn turned_rows(ctx: &Context, v: &Velocity, bp: &[bool]) -> (TokenStream, Vec<Option<Ident>>) {
    let g = &ctx.eq.system.graph;
    let jb = |r: usize| bp[r].then(|| Context::local("jb", r));
    let mut b: Vec<Option<TokenStream>> = (0..ctx.k).map(|r| jb(r).map(|x| quote!(#x))).collect();
    for rows in &v.system.in_base {
        for (i, &r) in rows.rows.iter().enumerate() {
            let terms = (0..3).filter_map(|j| {
                let (rot, x) = (velocity::rotation_local(v, rows, j, i), jb(rows.rows[j])?);
                Some((quote!(#rot), quote!(#x)))
            });
            b[r] = sum_of_products(terms).map(|t| quote!((#t)));
        }
    }
    let mut code = TokenStream::new();
    let mut alphas = Vec::new();
    for &(c, norm) in &v.system.quaternions {
        let alpha = Context::local("alpha", c);
        match &b[norm] {
            Some(bn) => {
                let an = Context::local2("aa", norm, c);
                code.extend(quote! { let #alpha = #bn / #an; });
                alphas.push(c);
            }
            None => code.extend(quote! { let #alpha = T::zero(); }),
        }
    }
    let mut names = Vec::with_capacity(v.rows.len());
    for (rr, &r) in v.rows.iter().enumerate() {
        let terms: Vec<TokenStream> = (v.system.quaternions.iter())
            .filter(|&&(c, _)| alphas.contains(&c) && !g.is_zero(v.system.a[r][c]))
            .map(|&(c, _)| {
                let (a, alpha) = (Context::local2("aa", r, c), Context::local("alpha", c));
                quote!(#a * #alpha)
            })
            .collect();
        let value = match (&b[r], terms.is_empty()) {
            (None, true) => None,
            (Some(own), true) => Some(quote!(#own)),
            (Some(own), false) => Some(quote!(#own - (#(#terms)+*))),
            (None, false) => Some(quote!(-(#(#terms)+*))),
        };
        let name = value.map(|value| {
            let name = Context::local("jv", rr);
            code.extend(quote! { let #name = #value; });
            name
        });
        names.push(name);
    }
    (code, names)
}
