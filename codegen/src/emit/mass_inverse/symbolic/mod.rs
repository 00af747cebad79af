//! A symbolic `M⁻¹` (`M` diagonal or a numeric constant): the solve of
//! Gauss's principle as straight-line expressions, shared by the solver
//! `gauss`, the Jacobian (`jacobian`) and the projections' step (`step`).

pub(in crate::emit) mod jacobian;
pub(in crate::emit) mod step;

use crate::emit::body::Body;
use crate::emit::context::Context;
use crate::emit::ldlt::{Rows, StructuredLdlt};
use crate::emit::solve::{checked_motion, corrected};
use crate::equations::mass_inverse::Symbolic;
use crate::expr::{Graph, Id};
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The straight-line solve of Gauss's principle for a symbolic `M⁻¹`, up to
/// the multipliers: shared by `gauss` and the Jacobian
/// (`jacobian`), which both continue from `λ` in their own way.
pub(in crate::emit) struct SymbolicSolve<'a> {
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

/// The scalar (`k = 1`) solve of [`SymbolicSolve`] in parts.
pub(in crate::emit) struct ScalarSolve {
    /// From the arguments to `S` and `r` (`__s0_0`, `__r0`).
    to_gram: TokenStream,
    /// `λ = r / S`, bare: the fast path, once the rank check passed.
    division: TokenStream,
    /// `λ = r / S` where `S > 0`, else 0: the suspect path.
    guarded: TokenStream,
    /// The temporaries that need `λ`.
    after: TokenStream,
}

impl<'a> SymbolicSolve<'a> {
    /// `extra` are further expressions the caller will ask `body` for;
    /// `gauss`: the code is the solver `gauss`'s (with the `b + db` of
    /// `acceleration_corrected`, errors through its `Finish`), else the
    /// Jacobian's (errors as `Err`).
    pub(in crate::emit) fn new(
        ctx: &'a Context,
        d: &'a Symbolic,
        extra: &[Id],
        gauss: bool,
    ) -> Self {
        let k = ctx.k;
        let g = &ctx.eq.system.graph;
        let residuals: Vec<_> = (0..k).map(|i| Context::local("r", i)).collect();
        let ldlt = StructuredLdlt::gram(&d.structure);
        let named = gram_entries(g, d, &ldlt, &residuals);
        let unchecked = unchecked_masses(g, d);
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
        let check = mass_check(ctx, &body, &unchecked, gauss);
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
        SymbolicSolve {
            body,
            ldlt,
            to_multipliers,
            scalar,
        }
    }
}

/// The locals the factorization reads, with their expressions: the
/// structural nonzeros of each row of `S` up to the diagonal, then that
/// row's residual `r` (named `residuals`).
fn gram_entries(
    g: &Graph,
    d: &Symbolic,
    ldlt: &StructuredLdlt,
    residuals: &[syn::Ident],
) -> Vec<(syn::Ident, Id)> {
    let mut named: Vec<(syn::Ident, Id)> = Vec::new();
    for (i, (r, &residual)) in residuals.iter().zip(&d.residual).enumerate() {
        for j in 0..=i {
            if !g.is_zero(d.gram[i][j]) {
                named.push((ldlt.entry(i, j), d.gram[i][j]));
            }
        }
        named.push((r.clone(), residual));
    }
    named
}

/// The masses checked positive at run time: each distinct one that is not
/// a positive constant, once.
fn unchecked_masses(g: &Graph, d: &Symbolic) -> Vec<Id> {
    let mut unchecked: Vec<Id> = Vec::new();
    for &m in &d.masses {
        let constant_positive = g.as_num(m).is_some_and(|v| v.to_f64() > 0.0);
        if !constant_positive && !unchecked.contains(&m) {
            unchecked.push(m);
        }
    }
    unchecked
}

/// The run-time check that the `unchecked` masses are positive, leaving
/// with `MassNotPositiveDefinite` (through `gauss`'s `Finish`, or as an
/// `Err` for the Jacobian) where one is not; `None` without such masses.
fn mass_check(ctx: &Context, body: &Body, unchecked: &[Id], gauss: bool) -> Option<TokenStream> {
    let error = quote!(DynamicsError::MassNotPositiveDefinite);
    let exit = if gauss {
        ctx.gauss_error(error)
    } else {
        let error = ctx.path(error);
        quote!(return ::core::result::Result::Err(#error);)
    };
    (!unchecked.is_empty()).then(|| {
        let positive = unchecked.iter().map(|&m| {
            let m = body.expr(m);
            quote! { #m > T::zero() }
        });
        quote! {
            if !(#(#positive)&&*) {
                #exit
            }
        }
    })
}

/// `M⁻¹` known symbolically (`M` diagonal or a numeric constant): `a`, `S`,
/// `r`, `W` and `A` are straight-line expressions; `S λ = r` is solved by
/// `LDLᵀ` on the structural pattern of `S`.
pub(in crate::emit) fn solver(ctx: &Context, d: &Symbolic) -> TokenStream {
    let SymbolicSolve {
        body,
        ldlt,
        to_multipliers,
        scalar,
    } = SymbolicSolve::new(ctx, d, &[], true);
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
    let lambda = written_multipliers(ctx, d, &body);
    let minimum_norm = (ctx.generic_rank < ctx.k).then(|| minimum_norm(ctx, d, &body, &ldlt));
    let value = checked_motion(
        ctx,
        Some(ldlt.suspect(ctx.generic_rank)),
        (&acc, &force),
        &lambda,
        also,
        paths,
        minimum_norm,
    );
    let doc = format!(
        " `(q̈, Aᵀλ)` of Gauss's principle, shared by `acceleration`,\n \
         `constraint_force` and `acceleration_corrected` (`b + correction`),\n \
         as `__F` makes it; {}",
        ctx.eq.strategy().describe()
    );
    quote! {
        #[doc = #doc]
        #[inline(always)]
        #signature {
            #to_multipliers
            #value
        }
    }
}

/// A redundant set's minimum-norm `λ`, as an expression: the least
/// `‖μ D λ̂‖` among the scaled rows' solutions (`D`'s squares weight the
/// norm), from `S`'s factors (`StructuredLdlt::minimum_norm`), written as
/// the rows' own.
fn minimum_norm(ctx: &Context, d: &Symbolic, body: &Body, ldlt: &StructuredLdlt) -> TokenStream {
    let lam: Vec<Ident> = (0..ctx.k).map(|j| Context::local("lam", j)).collect();
    let weight: Vec<Option<TokenStream>> = (0..ctx.k)
        .map(|j| match d.scale.get(j) {
            Some(&s) if !s.is_one() => Some(crate::emit::body::literal(s * s).0),
            _ => None,
        })
        .collect();
    // The scaled rows `D A`, whose multipliers `lam` are.
    let g = &ctx.eq.system.graph;
    let entry = |r: usize, i: usize| {
        let a = ctx.eq.a[r][i];
        (!g.is_zero(a)).then(|| {
            let a = body.expr(a);
            match d.scale.get(r) {
                Some(&s) if !s.is_one() => {
                    let (s, _) = crate::emit::body::literal(s);
                    quote!(#s * (#a))
                }
                _ => a,
            }
        })
    };
    let a = Rows {
        coordinates: ctx.n,
        entry: &entry,
    };
    let (code, rows) = ldlt.minimum_norm(&lam, &weight, &a);
    let rows = written(d, body, &rows);
    quote!({ #code [#(#rows),*] })
}

/// `λ` of the rows as written: the solve's are those of the scaled rows
/// `Â = D A` with `M` divided by a common mass `μ` (the force is
/// `μ Âᵀ λ̂ = Aᵀ (μ D λ̂)`), so `λ = μ D λ̂`.
fn written_multipliers(ctx: &Context, d: &Symbolic, body: &Body) -> Vec<TokenStream> {
    let lam: Vec<TokenStream> = (0..ctx.k)
        .map(|j| {
            let l = Context::local("lam", j);
            quote!(#l)
        })
        .collect();
    written(d, body, &lam)
}

/// `μ D x` of the scaled rows' values `x` (see [`written_multipliers`]).
fn written(d: &Symbolic, body: &Body, values: &[TokenStream]) -> Vec<TokenStream> {
    let mass = d.common_mass.map(|m| body.expr(m));
    values
        .iter()
        .enumerate()
        .map(|(j, l)| {
            let scaled = match d.scale.get(j) {
                Some(&s) if !s.is_one() => {
                    let (s, _) = crate::emit::body::literal(s);
                    quote!(#s * #l)
                }
                _ => quote!(#l),
            };
            match &mass {
                Some(m) => quote!((#m) * (#scaled)),
                None => scaled,
            }
        })
        .collect()
}

/// Whether a row scaled down (`D`, d < 1) overflows in the model's own
/// units: it can be finite where the model's own `r` (and `b`) is not, and
/// then the runtime answers from A and b (`NonFinite`), so that an `Ok`
/// always satisfies the `A q̈ = b` it reports. One comparison per such row,
/// branch-free (`|`), over the locals `__r{i}`; `None` without such rows.
/// The Jacobian tests the same condition, so that it takes the runtime's
/// path (and its `Err`) exactly where `acceleration` does.
pub(in crate::emit) fn overflowing_rows(ctx: &Context, d: &Symbolic) -> Option<TokenStream> {
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
