//! Code for the generalized-inverse equation of motion (eq. 24–26):
//! `acceleration`, `constraint_force`, `acceleration_moore_penrose` and the
//! `ConstrainedSystem` impl.
//!
//! Both generated methods share one private solver, `gauss`, returning
//! `(q̈, Aᵀλ)`; with `#[inline]` the unused half is optimised away. The
//! constraint force is emitted as `Aᵀ λ` rather than `M q̈ − F`, which is the
//! same quantity without the cancellation.

use super::body::Body;
use super::dim;
use crate::derive::Equations;
use crate::expr::Id;
use crate::motion::{MassInverse, Symbolic};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use syn::Ident;

/// Whether `acceleration` can fail: only when `M` is not known positive
/// definite at compile time.
pub(super) fn fallible(eq: &Equations) -> bool {
    match &eq.gauss {
        MassInverse::Symbolic(d) => !d.known_positive,
        MassInverse::Cholesky => true,
    }
}

/// The solver, the public methods and the trait impl's body items.
pub(super) fn methods(eq: &Equations) -> TokenStream {
    let n = dim(eq.system.dof());
    let solver = match &eq.gauss {
        MassInverse::Symbolic(d) => symbolic_solver(eq, d),
        MassInverse::Cholesky => cholesky_solver(eq),
    };
    let moore_penrose = moore_penrose(eq);
    let vector = quote!(::constrained::nalgebra::SVector<T, #n>);
    let args = quote! {
        q: &::constrained::nalgebra::SVector<T, #n>,
        qd: &::constrained::nalgebra::SVector<T, #n>,
        t: T
    };
    let (ret, acc, force, corrected) = if fallible(eq) {
        (
            quote!(::core::result::Result<#vector, ::constrained::DynamicsError>),
            quote!(self
                .gauss(q, qd, t, ::core::option::Option::None)
                .map(|s| s.0)),
            quote!(self
                .gauss(q, qd, t, ::core::option::Option::None)
                .map(|s| s.1)),
            quote!(self
                .gauss(q, qd, t, ::core::option::Option::Some(db))
                .map(|s| s.0)),
        )
    } else {
        (
            vector.clone(),
            quote!(self.gauss(q, qd, t, ::core::option::Option::None).0),
            quote!(self.gauss(q, qd, t, ::core::option::Option::None).1),
            quote!(self.gauss(q, qd, t, ::core::option::Option::Some(db)).0),
        )
    };
    let k = dim(eq.a.len());
    let fallibility = if fallible(eq) {
        "`Err` when `M` is not positive definite at this state (it is not \
         known to be at compile time)."
    } else {
        "Total: `M` is constant and positive definite."
    };
    let acc_doc = format!(
        " The acceleration `q̈` by the generalized-inverse equation (Udwadia & \
         Kalaba eq. 24–26): `M q̈ = F + Aᵀ λ` with `(A M⁻¹ Aᵀ) λ = b − A a`, \
         solved with a rank-revealing {{1}}-inverse (see `constrained::inverse`). \
         Where `A` loses rank the result is the minimiser of Gauss's principle \
         over the constraints that remain independent (`q̈ = a` where `A = 0`); \
         never NaN for finite input. {fallibility}"
    );
    let force_doc = format!(
        " The constraint force `Fᶜ = M q̈ − F = Aᵀ λ` (the second term of eq. 26). \
         {fallibility}"
    );
    quote! {
        #solver

        #[doc = #acc_doc]
        #[inline]
        pub fn acceleration(&self, #args) -> #ret { #acc }

        #[doc = #force_doc]
        #[inline]
        pub fn constraint_force(&self, #args) -> #ret { #force }

        /// The acceleration with `b` replaced by `b + db`: constraint
        /// stabilization (Baumgarte) asks `A q̈ = b − 2α φ̇ − β² φ` of
        /// position-level and `A q̈ = b − γ φ` of velocity-level constraints.
        #[inline]
        pub fn acceleration_corrected(
            &self,
            #args,
            db: &::constrained::nalgebra::SVector<T, #k>,
        ) -> #ret {
            #corrected
        }

        #moore_penrose
    }
}

/// The type of the optional correction of `b` taken by `gauss`.
fn correction_type(eq: &Equations) -> TokenStream {
    let k = dim(eq.a.len());
    quote!(::core::option::Option<&::constrained::nalgebra::SVector<T, #k>>)
}

/// The `ConstrainedSystem` impl.
pub(super) fn trait_impl(eq: &Equations) -> TokenStream {
    let name = &eq.system.name;
    let (n, k) = (dim(eq.system.dof()), dim(eq.a.len()));
    let state = quote!(&::constrained::State<T, #n>);
    let vector = quote!(::constrained::nalgebra::SVector<T, #n>);
    let result = quote!(::core::result::Result<#vector, ::constrained::DynamicsError>);
    let (acc, force, corrected) = if fallible(eq) {
        (
            quote!(self.acceleration(&s.q, &s.qd, s.t)),
            quote!(self.constraint_force(&s.q, &s.qd, s.t)),
            quote!(self.acceleration_corrected(&s.q, &s.qd, s.t, db)),
        )
    } else {
        (
            quote!(Ok(self.acceleration(&s.q, &s.qd, s.t))),
            quote!(Ok(self.constraint_force(&s.q, &s.qd, s.t))),
            quote!(Ok(self.acceleration_corrected(&s.q, &s.qd, s.t, db))),
        )
    };
    quote! {
        impl<T: ::constrained::nalgebra::RealField + Copy>
            ::constrained::ConstrainedSystem<T, #n, #k> for #name<T>
        {
            const CONSTRAINT_LEVELS: [::constrained::ConstraintLevel; #k] = Self::CONSTRAINT_LEVELS;
            fn mass_matrix(&self, s: #state) -> ::constrained::nalgebra::SMatrix<T, #n, #n> {
                self.mass_matrix(&s.q, s.t)
            }
            fn forces(&self, s: #state) -> #vector {
                self.forces(&s.q, &s.qd, s.t)
            }
            fn constraint_residual(&self, s: #state) -> ::constrained::nalgebra::SVector<T, #k> {
                self.constraint_residual(&s.q, &s.qd, s.t)
            }
            fn constraint_velocity_residual(&self, s: #state) -> ::constrained::nalgebra::SVector<T, #k> {
                self.constraint_velocity_residual(&s.q, &s.qd, s.t)
            }
            fn constraint_matrices(&self, s: #state) -> (
                ::constrained::nalgebra::SMatrix<T, #k, #n>,
                ::constrained::nalgebra::SVector<T, #k>,
            ) {
                self.constraint_matrices(&s.q, &s.qd, s.t)
            }
            fn acceleration(&self, s: #state) -> #result { #acc }
            fn constraint_force(&self, s: #state) -> #result { #force }
            fn acceleration_corrected(
                &self,
                s: #state,
                db: &::constrained::nalgebra::SVector<T, #k>,
            ) -> #result {
                #corrected
            }
            fn acceleration_moore_penrose(&self, s: #state) -> #result {
                self.acceleration_moore_penrose(&s.q, &s.qd, s.t)
            }
            fn gibbs_appell_matrices(&self, s: #state) -> ::core::result::Result<
                (::constrained::nalgebra::SMatrix<T, #n, #n>, #vector),
                ::constrained::GibbsAppellError,
            > {
                self.gibbs_appell_matrices(&s.q, &s.qd, s.t)
            }
            fn acceleration_gibbs_appell(&self, s: #state)
                -> ::core::result::Result<#vector, ::constrained::GibbsAppellError>
            {
                self.acceleration_gibbs_appell(&s.q, &s.qd, s.t)
            }
        }
    }
}

fn ident(prefix: &str, i: usize) -> Ident {
    format_ident!("__{}{}", prefix, i)
}

fn ident2(prefix: &str, i: usize, j: usize) -> Ident {
    format_ident!("__{}{}_{}", prefix, i, j)
}

/// `M` diagonal: `a`, `S`, `r`, `W` and `A` are straight-line expressions;
/// `S λ = r` is solved by `LDLᵀ` on the structural pattern of `S`.
fn symbolic_solver(eq: &Equations, d: &Symbolic) -> TokenStream {
    let (n, k) = (eq.system.dof(), eq.a.len());
    let g = &eq.system.graph;
    let mut named: Vec<(Ident, Id)> = Vec::new();
    for i in 0..k {
        for j in 0..=i {
            if !g.is_zero(d.gram[i][j]) {
                named.push((ident2("s", i, j), d.gram[i][j]));
            }
        }
        named.push((ident("r", i), d.residual[i]));
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
    let body = Body::new(eq, &roots);
    let preamble = body.preamble();
    let bindings = named.iter().map(|(name, id)| {
        let value = body.expr(*id);
        quote! { let #name = #value; }
    });
    let check = (!unchecked.is_empty()).then(|| {
        let positive = unchecked.iter().map(|&m| {
            let m = body.expr(m);
            quote! { #m > T::zero() }
        });
        quote! {
            if !(#(#positive)&&*) {
                return ::core::result::Result::Err(::constrained::DynamicsError::MassNotPositiveDefinite);
            }
        }
    });
    let solve = structured_ldlt(eq, d);
    let after = body.after_multipliers();
    let acc: Vec<TokenStream> = d.acceleration.iter().map(|&e| body.expr(e)).collect();
    let force: Vec<TokenStream> = d.force.iter().map(|&e| body.expr(e)).collect();
    let nn = dim(n);
    let vector = quote!(::constrained::nalgebra::SVector<T, #nn>);
    let new_vector = quote!(::constrained::nalgebra::SVector::<T, #nn>::from_array_storage);
    let result = quote! {
        (
            #new_vector(::constrained::nalgebra::ArrayStorage([[#(#acc),*]])),
            #new_vector(::constrained::nalgebra::ArrayStorage([[#(#force),*]])),
        )
    };
    let (ret, value) = if d.known_positive {
        (quote!((#vector, #vector)), result)
    } else {
        (
            quote!(::core::result::Result<(#vector, #vector), ::constrained::DynamicsError>),
            quote!(::core::result::Result::Ok(#result)),
        )
    };
    let correction = correction_type(eq);
    let corrected = (k > 0).then(|| {
        let r: Vec<_> = (0..k).map(|i| ident("r", i)).collect();
        let d: Vec<_> = (0..k).map(|i| ident("db", i)).collect();
        quote! {
            let (#(#r,)*) = match correction {
                ::core::option::Option::Some(__db) => {
                    let [[#(#d),*]] = __db.data.0;
                    (#(#r + #d,)*)
                }
                ::core::option::Option::None => (#(#r,)*),
            };
        }
    });
    quote! {
        /// `(q̈, Aᵀλ)` of Gauss's principle, shared by `acceleration`,
        /// `constraint_force` and `acceleration_corrected` (`b + correction`).
        #[inline]
        fn gauss(&self, q: &#vector, qd: &#vector, t: T, correction: #correction) -> #ret {
            #preamble
            #(#bindings)*
            #corrected
            #check
            #solve
            #after
            #value
        }
    }
}

/// `S λ = r` by `P S Pᵀ = L D Lᵀ` in the compile-time elimination order over
/// the compile-time pattern (fill included): only structural nonzeros are touched, so a chain's
/// tridiagonal `S` costs O(k). A pivot whose `sin²θ = dⱼ / Sⱼⱼ` is below
/// `rank_tolerance` is dropped (`D⁺`), which removes its constraint; for
/// k = 1 this is the scalar closed form `λ = r / S` with `λ = 0` where `S = 0`.
fn structured_ldlt(eq: &Equations, d: &Symbolic) -> TokenStream {
    let k = eq.a.len();
    let g = &eq.system.graph;
    if k == 0 {
        return TokenStream::new();
    }
    if k == 1 {
        return quote! {
            let __lam0 = if __s0_0 > T::zero() { __r0 / __s0_0 } else { T::zero() };
        };
    }
    // Everything below is indexed by position in the elimination order;
    // `o[p]` is the constraint at position p (its S, r and λ names).
    let l = &d.fill;
    let o = &d.order;
    let s = |p: usize, q: usize| -> TokenStream {
        let (i, j) = (o[p], o[q]);
        if g.is_zero(d.gram[i][j]) {
            quote!(T::zero())
        } else {
            let name = ident2("s", i.max(j), i.min(j));
            quote!(#name)
        }
    };
    // With u the Schur-updated (unscaled) entries and l = u·inv:
    //   dⱼ = Sⱼⱼ − Σ_c (u_jc·u_jc)·inv_c,  u_ij = S_ij − Σ_c u_ic·l_jc,  l_ij = u_ij·inv_j.
    // (u·u)·inv equals l·l·d (inv·d = 1 for a kept pivot, both 0 for a dropped
    // one) but leaves one multiplication, not three, between a pivot's
    // reciprocal and the next division: the recurrence is the critical path
    // of a chain, so this is what its cost per link is made of.
    let mut out = quote! { let __tol: T = ::constrained::inverse::rank_tolerance::<T>(); };
    let u = |i: usize, j: usize| -> TokenStream {
        let name = ident2("u", i, j);
        quote!(#name)
    };
    for j in 0..k {
        let (dj, inv, sjj) = (ident("d", j), ident("inv", j), s(j, j));
        let updates = (0..j).filter(|&c| l[j][c]).map(|c| {
            let (ujc, invc) = (u(j, c), ident("inv", c));
            quote!(- (#ujc * #ujc) * #invc)
        });
        out.extend(quote! {
            let #dj = #sjj #(#updates)*;
            let #inv = if #dj > __tol * #sjj { T::one() / #dj } else { T::zero() };
        });
        for i in j + 1..k {
            if !l[i][j] {
                continue;
            }
            let (lij, uij, sij) = (ident2("l", i, j), u(i, j), s(i, j));
            let updates = (0..j).filter(|&c| l[i][c] && l[j][c]).map(|c| {
                let (uic, ljc) = (u(i, c), ident2("l", j, c));
                quote!(- #uic * #ljc)
            });
            out.extend(quote! {
                let #uij = #sij #(#updates)*;
                let #lij = #uij * #inv;
            });
        }
    }
    for i in 0..k {
        let (y, r) = (ident("y", i), ident("r", o[i]));
        let updates = (0..i).filter(|&c| l[i][c]).map(|c| {
            let (lic, yc) = (ident2("l", i, c), ident("y", c));
            quote!(- #lic * #yc)
        });
        out.extend(quote! { let #y = #r #(#updates)*; });
    }
    for i in (0..k).rev() {
        let (lam, y, inv) = (ident("lam", o[i]), ident("y", i), ident("inv", i));
        let updates = (i + 1..k).filter(|&c| l[c][i]).map(|c| {
            let (lci, lamc) = (ident2("l", c, i), ident("lam", o[c]));
            quote!(- #lci * #lamc)
        });
        out.extend(quote! { let #lam = #y * #inv #(#updates)*; });
    }
    out
}

/// `M = L Lᵀ` at run time (`__chol`) and `a = M⁻¹ F` (`__acc`); a mass
/// matrix that is not positive definite returns the error.
fn cholesky_prelude() -> TokenStream {
    quote! {
        let ::core::option::Option::Some(__chol) =
            ::constrained::nalgebra::linalg::Cholesky::new(self.mass_matrix(q, t))
        else {
            return ::core::result::Result::Err(::constrained::DynamicsError::MassNotPositiveDefinite);
        };
        let __acc = __chol.solve(&self.forces(q, qd, t));
    }
}

/// A full `M(q, t)`: Cholesky at run time, then `S = A M⁻¹ Aᵀ` and the
/// pivoted `LDLᵀ` {1}-inverse of the runtime.
fn cholesky_solver(eq: &Equations) -> TokenStream {
    let prelude = cholesky_prelude();
    let (n, k) = (dim(eq.system.dof()), dim(eq.a.len()));
    let vector = quote!(::constrained::nalgebra::SVector<T, #n>);
    let solve = if eq.a.is_empty() {
        quote! { let __qdd = __acc; let __fc = ::constrained::nalgebra::SVector::<T, #n>::zeros(); }
    } else {
        quote! {
            let (__a, __b) = self.constraint_matrices(q, qd, t);
            let __b = match correction {
                ::core::option::Option::Some(__db) => __b + __db,
                ::core::option::Option::None => __b,
            };
            let __w = __chol.solve(&__a.transpose());
            let __s: ::constrained::nalgebra::SMatrix<T, #k, #k> = __a * __w;
            let __lam = ::constrained::inverse::solve_psd(&__s, &(__b - __a * __acc));
            let __qdd = __acc + __w * __lam;
            let __fc = __a.transpose() * __lam;
        }
    };
    let correction = correction_type(eq);
    quote! {
        /// `(q̈, Aᵀλ)` of Gauss's principle, shared by `acceleration`,
        /// `constraint_force` and `acceleration_corrected` (`b + correction`).
        #[inline]
        fn gauss(&self, q: &#vector, qd: &#vector, t: T, correction: #correction)
            -> ::core::result::Result<(#vector, #vector), ::constrained::DynamicsError>
        {
            #prelude
            #solve
            ::core::result::Result::Ok((__qdd, __fc))
        }
    }
}

/// `q̈ = a + L⁻ᵀ (A L⁻ᵀ)⁺ (b − A a)` with `M = L Lᵀ` and the Moore–Penrose
/// inverse by SVD: the reference form, selectable, not specialised.
fn moore_penrose(eq: &Equations) -> TokenStream {
    let prelude = cholesky_prelude();
    let (n, k) = (dim(eq.system.dof()), dim(eq.a.len()));
    let vector = quote!(::constrained::nalgebra::SVector<T, #n>);
    let constrained = (!eq.a.is_empty()).then(|| {
        quote! {
            let (__a, __b) = self.constraint_matrices(q, qd, t);
            let __l = __chol.l();
            // X = A L⁻ᵀ, computed as Xᵀ = L⁻¹ Aᵀ.
            let ::core::option::Option::Some(__xt) = __l.solve_lower_triangular(&__a.transpose()) else {
                return ::core::result::Result::Err(::constrained::DynamicsError::MassNotPositiveDefinite);
            };
            let __x: ::constrained::nalgebra::SMatrix<T, #k, #n> = __xt.transpose();
            // Singular values below √(rank tolerance) of the largest are zero:
            // the same sin θ threshold as the default {1}-inverse.
            let ::core::option::Option::Some(__sv) = ::constrained::svd::singular_values(&__xt) else {
                return ::core::result::Result::Err(::constrained::DynamicsError::NonFinite);
            };
            let __cut = ::constrained::inverse::rank_tolerance::<T>().sqrt() * __sv.max();
            let ::core::option::Option::Some(__y) =
                ::constrained::svd::pseudo_inverse_solve(&__x, &(__b - __a * __acc), __cut)
            else {
                return ::core::result::Result::Err(::constrained::DynamicsError::NonFinite);
            };
            let ::core::option::Option::Some(__z) = __l.transpose().solve_upper_triangular(&__y) else {
                return ::core::result::Result::Err(::constrained::DynamicsError::MassNotPositiveDefinite);
            };
            let __acc = __acc + __z;
        }
    });
    quote! {
        /// The acceleration by the Moore–Penrose form of eq. 24 with
        /// `M = L Lᵀ`: `q̈ = a + L⁻ᵀ (A L⁻ᵀ)⁺ (b − A a)`, by SVD at run time
        /// (singular values below `√rank_tolerance` of the largest count as
        /// zero). Slower than [`acceleration`](Self::acceleration); the same
        /// result wherever the constraints are consistent. For comparison and
        /// for states where the least-squares reading of inconsistent
        /// constraints is wanted.
        pub fn acceleration_moore_penrose(&self, q: &#vector, qd: &#vector, t: T)
            -> ::core::result::Result<#vector, ::constrained::DynamicsError>
        {
            #prelude
            #constrained
            ::core::result::Result::Ok(__acc)
        }
    }
}
