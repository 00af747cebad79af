//! A floating base standing on legs, each leg's joints eliminated through
//! its own foot's rows in closed form (the null-space method, leg by leg).
//!
//! In the velocity form ([`super::velocity`]) a foot's three rows in its
//! base's axes are `E u + J θ̈ = b` over the base's six unknowns `u = (z, β)`
//! and its leg's three joints `θ` ([`crate::equations::in_base`]). Where
//! every joint but the base's belongs to exactly one such leg (three joints,
//! three rows, no other row on them; legs do not share inertia: a tree),
//! `J` is square and, away from the leg's singular poses, invertible:
//!
//! ```text
//! θ̈ = c − N u,          c = J⁻¹ b,   N = J⁻¹ E,
//! S u = r,              S = M_bb − Σ (M_lbᵀ N + Nᵀ M_lb − Nᵀ M_ll N),
//!                       r = f_b − Σ (M_lbᵀ c + Nᵀ (f_l − M_ll c)),
//! μ = J⁻ᵀ (f_l − M_lb u − M_ll θ̈),
//! ```
//!
//! `S` the base's inertia with its feet held (6 × 6, positive definite
//! where the saddle-point system is regular) and `μ` each foot's
//! multipliers. It is the saddle-point elimination of [`super::saddle`] with
//! each leg's rows as its joints' pivots: exact, and `J⁻¹ E` keeps the
//! structure of `E = [I, −r̃]` that the signed pivots spread through the
//! base's block. The symmetric part is formed as `Nᵀ Y + Yᵀ N` with
//! `Y = M_lb − ½ M_ll N`. A leg whose `|det J|` is below `10⁻³` times the
//! product of its rows' lengths (the saddle's own pivot tolerance) or a
//! pivot of `S` that is not positive hands the solve to the runtime's
//! dense one.
//!
//! Where the legs have one structural pattern (a quadruped's four), their
//! factor code is written once, as a function the solve calls per leg
//! ([`shared`]): the same arithmetic on each leg's own entries, from one
//! copy of the code instead of one per leg.

use super::super::super::context::Context;
use super::super::super::ldlt::StructuredLdlt;
use crate::emit::literal::literal;
use crate::emit::tokens::{join_product, signed_sum};
use crate::equations::legs::Legs;
use crate::expr::num::Num;
use crate::numeric::sparsity::Structure;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

mod shared;

use shared::Shared;

/// Names of one leg's locals.
fn name(role: &str, t: usize, e: usize) -> Ident {
    Context::local2(role, t, e)
}

/// `a + b + …`, `None` for no terms.
fn sum(terms: Vec<TokenStream>) -> Option<TokenStream> {
    signed_sum(terms.into_iter().map(|t| (false, t)))
}

/// `Σ aᵢ bᵢ` over the pairs whose factors are both structurally nonzero.
fn dot<A: quote::ToTokens, B: quote::ToTokens>(
    pairs: impl IntoIterator<Item = (Option<A>, Option<B>)>,
) -> Option<TokenStream> {
    sum(pairs
        .into_iter()
        .filter_map(|(a, b)| {
            let (a, b) = (a?, b?);
            Some(quote!(#a * #b))
        })
        .collect())
}

/// `let name = value;` for a structurally nonzero value; the name, if so.
fn bind(code: &mut TokenStream, name: Ident, value: Option<TokenStream>) -> Option<Ident> {
    let value = value?;
    code.extend(quote! { let #name = #value; });
    Some(name)
}

/// `a − b` of optional terms (`None`: both structurally zero).
fn minus(a: Option<TokenStream>, b: Option<TokenStream>) -> Option<TokenStream> {
    match (a, b) {
        (a, None) => a,
        (Some(a), Some(b)) => Some(quote!(#a - (#b))),
        (None, Some(b)) => Some(quote!(-(#b))),
    }
}

/// One leg's matrices as locals: `J⁻¹`, `M_ll`, `M_lb`, `E`.
struct Leg<'a> {
    t: usize,
    inverse: [[Ident; 3]; 3],
    at: &'a dyn Fn(usize, usize) -> Option<TokenStream>,
    joints: [usize; 3],
    rows: [usize; 3],
    base: [usize; 6],
    nr: usize,
}

impl Leg<'_> {
    fn mll(&self, i: usize, k: usize) -> Option<TokenStream> {
        (self.at)(self.joints[i], self.joints[k])
    }

    fn mlb(&self, i: usize, m: usize) -> Option<TokenStream> {
        (self.at)(self.joints[i], self.base[m])
    }

    fn e(&self, k: usize, m: usize) -> Option<TokenStream> {
        (self.at)(self.nr + self.rows[k], self.base[m])
    }

    fn a(&self, i: usize, k: usize) -> Option<&Ident> {
        Some(&self.inverse[i][k])
    }

    fn name(&self, role: &str, e: usize) -> Ident {
        name(role, self.t, e)
    }
}

/// The solve: each leg's `J⁻¹` and its share of `S` and `r`, then
/// `S u = r` by `L D Lᵀ`, each leg's `θ̈` and `μ`. `entry(i, j)` is the
/// saddle-point matrix's bound local at (i, j) where structurally nonzero,
/// `rhs[i]` its right-hand side. Returns the code and the solved values by
/// position (coordinates, then rows). Without `factor`, only the code that
/// reads `rhs`: another right-hand side through the factors an earlier
/// call with `factor` bound in an enclosing scope (the tangent systems'
/// columns, `super::velocity_jacobian`).
pub(super) fn solve(
    legs: &Legs,
    (nr, kr): (usize, usize),
    entry: &dyn Fn(usize, usize) -> Option<Ident>,
    (rhs, factor): (&[Option<TokenStream>], bool),
    dense: &TokenStream,
) -> (TokenStream, Vec<Option<TokenStream>>) {
    let zero = || quote!(T::zero());
    let at = |i: usize, j: usize| entry(i.max(j), i.min(j)).map(|e| quote!(#e));
    let mut code = TokenStream::new();
    let (tolerance, _) = literal(Num::Rational(1, 1000));
    let half = factor.then(|| literal(Num::Rational(1, 2)).0);
    // S's entries and r: the base's own less each leg's share.
    let mut s_terms: Vec<Vec<Vec<TokenStream>>> = vec![vec![Vec::new(); 6]; 6];
    let mut r_terms: Vec<Vec<TokenStream>> = vec![Vec::new(); 6];
    let mut shares = Vec::new();
    // Legs of one structural pattern share one copy of their factor code.
    let shared = factor.then(|| Shared::new(legs, nr, &at, rhs)).flatten();
    if let Some(shared) = &shared {
        code.extend(shared.function());
    }
    for (t, &(joints, rows)) in legs.legs.iter().enumerate() {
        let j = |i: usize, k: usize| at(nr + rows[i], joints[k]);
        let leg = Leg {
            t,
            inverse: [0, 1, 2].map(|i| [0, 1, 2].map(|k| name("lja", t, 3 * i + k))),
            at: &at,
            joints,
            rows,
            base: legs.base,
            nr,
        };
        if let Some(shared) = &shared {
            let c = shared.call(&leg, dense, &mut code, (&mut s_terms, &mut r_terms));
            shares.push((leg, c));
            continue;
        }
        if factor {
            code.extend(inverse(t, &j, dense, &tolerance));
        }
        let c = share(
            &leg,
            rhs,
            &mut code,
            (&mut s_terms, &mut r_terms),
            half.as_ref(),
        );
        shares.push((leg, c));
    }
    let structure = Structure::with_order(vec![vec![true; 6]; 6], (0..6).collect());
    let ldlt = StructuredLdlt::reduced(&structure, dense.clone());
    if factor {
        for (m, row) in s_terms.iter().enumerate() {
            for (o, terms) in row.iter().enumerate().take(m + 1) {
                let own = at(legs.base[m], legs.base[o]);
                let entry = ldlt.entry(m, o);
                let value = minus(own, sum(terms.clone())).unwrap_or_else(zero);
                code.extend(quote! { let #entry = #value; });
            }
        }
        code.extend(ldlt.factor());
    }
    let r: Vec<Ident> = (0..6).map(|m| Context::local("bsr", m)).collect();
    for (m, name) in r.iter().enumerate() {
        let value = minus(rhs[legs.base[m]].clone(), sum(r_terms[m].clone()));
        let value = value.unwrap_or_else(zero);
        code.extend(quote! { let #name = #value; });
    }
    let u: Vec<Ident> = (0..6).map(|m| Context::local("bsz", m)).collect();
    code.extend(ldlt.solve(&r, "bsy", &u));
    let mut values: Vec<Option<TokenStream>> = vec![None; nr + kr];
    for (m, &p) in legs.base.iter().enumerate() {
        let um = &u[m];
        values[p] = Some(quote!(#um));
    }
    for (leg, c) in &shares {
        let (q, mu) = answers(leg, c, &u, rhs, &mut code);
        for i in 0..3 {
            values[leg.joints[i]] = q[i].as_ref().map(|q| quote!(#q));
            values[nr + leg.rows[i]] = mu[i].as_ref().map(|m| quote!(#m));
        }
    }
    (code, values)
}

/// Leg `leg`'s share: `c = J⁻¹ b` (returned), and into `S` and `r`:
/// `S −= Eᵀ W + Wᵀ E` with `W = J⁻ᵀ Y`, `Y = M_lb − ½ M_ll J⁻¹ E` (so that
/// `Eᵀ W = Nᵀ Y`; where it factors, `½` written as `half`), and
/// `r −= M_lbᵀ c + Eᵀ J⁻ᵀ (f_l − M_ll c)`.
fn share(
    leg: &Leg,
    rhs: &[Option<TokenStream>],
    code: &mut TokenStream,
    (s_terms, r_terms): (&mut [Vec<Vec<TokenStream>>], &mut [Vec<TokenStream>]),
    half: Option<&TokenStream>,
) -> [Option<Ident>; 3] {
    let b = |k: usize| rhs[leg.nr + leg.rows[k]].clone();
    let c = [0, 1, 2].map(|i| {
        let value = dot((0..3).map(|k| (leg.a(i, k), b(k))));
        bind(code, leg.name("ljc", i), value)
    });
    if let Some(half) = half {
        gram_share(leg, code, s_terms, half);
    }
    residual_share(leg, rhs, &c, code, r_terms);
    c
}

/// The leg's terms of `S`, `Eᵀ W + Wᵀ E` (pushed into `s_terms`, lower
/// triangle), with `W = J⁻ᵀ Y`, `Y = M_lb − ½ M_ll J⁻¹ E`, `½` written as
/// `half`.
fn gram_share(
    leg: &Leg,
    code: &mut TokenStream,
    s_terms: &mut [Vec<Vec<TokenStream>>],
    half: &TokenStream,
) {
    // G = M_ll J⁻¹, then Y = M_lb − ½ G E.
    let g = [0, 1, 2].map(|i| {
        [0, 1, 2].map(|k| {
            let value = dot((0..3).map(|j| (leg.mll(i, j), leg.a(j, k))));
            bind(code, leg.name("ljg", 3 * i + k), value)
        })
    });
    let y: Vec<Vec<Option<Ident>>> = (0..3)
        .map(|i| {
            (0..6)
                .map(|m| {
                    let p = dot((0..3).map(|k| (g[i][k].clone(), leg.e(k, m))));
                    let p = p.map(|p| quote!((#p) * #half));
                    bind(code, leg.name("ljy", 6 * i + m), minus(leg.mlb(i, m), p))
                })
                .collect()
        })
        .collect();
    // W = J⁻ᵀ Y, V = Eᵀ W.
    let w: Vec<Vec<Option<Ident>>> = (0..3)
        .map(|k| {
            (0..6)
                .map(|o| {
                    let value = dot((0..3).map(|i| (leg.a(i, k), y[i][o].clone())));
                    bind(code, leg.name("ljh", 6 * k + o), value)
                })
                .collect()
        })
        .collect();
    let v: Vec<Vec<Option<Ident>>> = (0..6)
        .map(|m| {
            (0..6)
                .map(|o| {
                    let value = dot((0..3).map(|k| (leg.e(k, m), w[k][o].clone())));
                    bind(code, leg.name("ljs", 6 * m + o), value)
                })
                .collect()
        })
        .collect();
    for m in 0..6 {
        for o in 0..=m {
            for x in [&v[m][o], &v[o][m]].into_iter().flatten() {
                s_terms[m][o].push(quote!(#x));
            }
        }
    }
}

/// The leg's terms of `r`, `M_lbᵀ c + Eᵀ J⁻ᵀ (f_l − M_ll c)` (pushed into
/// `r_terms`), given `c = J⁻¹ b`.
fn residual_share(
    leg: &Leg,
    rhs: &[Option<TokenStream>],
    c: &[Option<Ident>; 3],
    code: &mut TokenStream,
    r_terms: &mut [Vec<TokenStream>],
) {
    // w = f_l − M_ll c, x = J⁻ᵀ w.
    let f = |i: usize| rhs[leg.joints[i]].clone();
    let wl = [0, 1, 2].map(|i| {
        let value = minus(f(i), dot((0..3).map(|k| (leg.mll(i, k), c[k].clone()))));
        bind(code, leg.name("ljw", i), value)
    });
    let x = [0, 1, 2].map(|k| {
        let value = dot((0..3).map(|i| (leg.a(i, k), wl[i].clone())));
        bind(code, leg.name("ljx", k), value)
    });
    for (m, r) in r_terms.iter_mut().enumerate() {
        let own = (0..3).map(|i| (leg.mlb(i, m), c[i].as_ref().map(|c| quote!(#c))));
        let turned = (0..3).map(|k| (leg.e(k, m), x[k].as_ref().map(|x| quote!(#x))));
        if let Some(value) = bind(code, leg.name("ljr", m), dot(own.chain(turned))) {
            r.push(quote!(#value));
        }
    }
}

/// The leg's `θ̈ = c − J⁻¹ (E u)` (locals `__ljq{t}_{i}`) and
/// `μ = J⁻ᵀ (f_l − M_lb u − M_ll θ̈)` (locals `__ljm{t}_{i}`).
fn answers(
    leg: &Leg,
    c: &[Option<Ident>; 3],
    u: &[Ident],
    rhs: &[Option<TokenStream>],
    code: &mut TokenStream,
) -> ([Option<Ident>; 3], [Option<Ident>; 3]) {
    let eu = [0, 1, 2].map(|k| {
        let value = dot((0..6).map(|m| (leg.e(k, m), Some(&u[m]))));
        bind(code, leg.name("lje", k), value)
    });
    let q = [0, 1, 2].map(|i| {
        let n = dot((0..3).map(|k| (leg.a(i, k), eu[k].clone())));
        let value = minus(c[i].as_ref().map(|c| quote!(#c)), n);
        bind(code, leg.name("ljq", i), value)
    });
    let f = |i: usize| rhs[leg.joints[i]].clone();
    let v = [0, 1, 2].map(|i| {
        let base = (0..6).map(|m| {
            let um = &u[m];
            (leg.mlb(i, m), Some(quote!(#um)))
        });
        let own = (0..3).map(|k| (leg.mll(i, k), q[k].as_ref().map(|q| quote!(#q))));
        let value = minus(f(i), dot(base.chain(own)));
        bind(code, leg.name("ljz", i), value)
    });
    let mu = [0, 1, 2].map(|k| {
        let value = dot((0..3).map(|i| (leg.a(i, k), v[i].clone())));
        bind(code, leg.name("ljm", k), value)
    });
    (q, mu)
}

/// `Σ ± aᵢ bᵢ` over the pairs whose factors are both structurally nonzero
/// (`T::zero()` for none).
fn signed_products(pairs: &[(Option<TokenStream>, Option<TokenStream>, bool)]) -> TokenStream {
    let mut terms: Vec<(bool, TokenStream)> = pairs
        .iter()
        .filter_map(|(a, b, negative)| {
            let (a, b) = (a.as_ref()?, b.as_ref()?);
            Some((*negative, quote!(#a * #b)))
        })
        .collect();
    // A leading subtracted product is `-(a * b)`.
    if let Some((true, first)) = terms.first_mut() {
        *first = quote!((#first));
    }
    signed_sum(terms).unwrap_or_else(|| quote!(T::zero()))
}

/// `J⁻¹` of leg `t` by its cofactors (locals `__lja{t}_{3i+k}`), after the
/// test `det² > tol² Π |Jᵢ|²` (else `dense`).
fn inverse(
    t: usize,
    j: &dyn Fn(usize, usize) -> Option<TokenStream>,
    dense: &TokenStream,
    tolerance: &TokenStream,
) -> TokenStream {
    // cofactor(i, k) = J[i+1][k+1] J[i+2][k+2] − J[i+1][k+2] J[i+2][k+1].
    let mut code = TokenStream::new();
    for i in 0..3 {
        for k in 0..3 {
            let (i1, i2, k1, k2) = ((i + 1) % 3, (i + 2) % 3, (k + 1) % 3, (k + 2) % 3);
            let value =
                signed_products(&[(j(i1, k1), j(i2, k2), false), (j(i1, k2), j(i2, k1), true)]);
            let name = name("ljf", t, 3 * i + k);
            code.extend(quote! { let #name = #value; });
        }
    }
    let cofactor = |k: usize| {
        let f = name("ljf", t, k);
        Some(quote!(#f))
    };
    let det_value = signed_products(&[0, 1, 2].map(|k| (j(0, k), cofactor(k), false)));
    let norms = (0..3).map(|i| {
        let row = signed_products(&[0, 1, 2].map(|k| (j(i, k), j(i, k), false)));
        quote!((#row))
    });
    let (det, inverse_det) = (Context::local("ljd", t), Context::local("lji", t));
    let norms = join_product(norms.collect()).unwrap_or_default();
    code.extend(quote! {
        let #det = #det_value;
        if !(#det * #det > (#tolerance * #tolerance) * #norms) {
            #dense
        }
        let #inverse_det = T::one() / #det;
    });
    // (J⁻¹)[i][k] = cofactor(k, i) / det.
    for i in 0..3 {
        for k in 0..3 {
            let (a, f) = (name("lja", t, 3 * i + k), name("ljf", t, 3 * k + i));
            code.extend(quote! { let #a = #f * #inverse_det; });
        }
    }
    code
}
