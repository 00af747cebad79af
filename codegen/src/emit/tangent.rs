//! The right-hand sides of the tangent systems as code: for every column
//! variable `v` (coordinates, velocities, inputs),
//! `F̃ᵥ = ∂F/∂v − (∂M/∂v) q̈ + (∂A/∂v)ᵀ λ` and `b̃ᵥ = ∂b/∂v − (∂A/∂v) q̈`
//! (see [`crate::equations::tangent`]), contracted with the locals `__qdd{i}` and
//! `__lam{r}`, structural zeros left out. [`TangentTerms`] is read twice:
//! by the hidden `tangent_rhs` (the runtime's dense solve) and by the
//! generated structured solve (`super::mass_inverse::symbolic::jacobian`), which needs no
//! matrix of them. [`NamedTerms`] are the same terms over derivatives the
//! caller binds in its own body (`super::mass_inverse::factored::jacobian`,
//! sharing the sines and cosines of `M`, `F`, `A` and `b`).

use super::body::{literal, Body};
use super::chunks::bounded;
use super::context::{Context, Inputs};
use super::tokens::{braced, concat, signed_sum};
use crate::equations::tangent::{Derivatives, Form};
use crate::expr::num::Num;
use crate::expr::{Id, Sym};
use proc_macro2::TokenStream;
use quote::{quote, ToTokens};

/// The entries of `F̃` and `b̃` over one body: column by column, or along
/// the seeds (one "column" whose terms read `__seed{c}`).
pub(super) struct TangentTerms<'a> {
    /// The expressions' variables and temporaries.
    pub body: Body<'a>,
    /// `forces[c][i]`: `F̃` of column `c`, row `i`; `None` where it is a
    /// structural zero.
    pub forces: Vec<Vec<Option<TokenStream>>>,
    /// `rhs[c][r]`: `b̃` of column `c`, constraint `r`.
    pub rhs: Vec<Vec<Option<TokenStream>>>,
    /// Whether the one set of terms is along the seeds.
    pub directional: bool,
}

impl<'a> TangentTerms<'a> {
    pub(super) fn new(ctx: &'a Context) -> Self {
        Self::scaled(ctx, None)
    }

    /// [`TangentTerms::new`] for a solve of the rows scaled by `scales`
    /// (`Â = D A`, `λ = D λ̃`): each `b̃` row comes scaled by its `D`, and
    /// `F̃` reads `__lams{r}`, the solve's own `λ̃`, where `∂A/∂v` is a
    /// constant. A constant and its row's scale then multiply once, at
    /// compile time (`2 · ½`: a chain's rod rows, whose `A` is twice the
    /// rod, scaled by ½), not twice in every column's code.
    pub(super) fn scaled(ctx: &'a Context, scales: Option<&[Num]>) -> Self {
        let (sets, directional) = sets(ctx);
        let body = Body::new(ctx.eq, &roots(ctx, &sets));
        let (forces, rhs) = terms(ctx, &sets, &|e| body.expr(e), scales);
        TangentTerms {
            body,
            forces,
            rhs,
            directional,
        }
    }

    /// Code writing `F̃` and `b̃` of every column into the places `f`
    /// (`[[T; n]; columns]`) and `b` (`[[T; k]; columns]`), which hold zeros:
    /// straight-line over the columns' nonzeros, or a loop over the columns
    /// running the directional derivative with the column's unit seed. In a
    /// block of its own (its temporaries shadow the caller's). Reads the
    /// locals `__qdd{i}` and `__lam{r}`.
    pub(super) fn fill(&self, columns: usize, f: &TokenStream, b: &TokenStream) -> TokenStream {
        let preamble = self.body.preamble();
        let writes = |c: &TokenStream, set: usize| {
            let mut out = TokenStream::new();
            for (i, value) in self.forces[set].iter().enumerate() {
                if let Some(value) = value {
                    let il = index(i);
                    out.extend(quote! { #f[#c][#il] = #value; });
                }
            }
            for (r, value) in self.rhs[set].iter().enumerate() {
                if let Some(value) = value {
                    let rl = index(r);
                    out.extend(quote! { #b[#c][#rl] = #value; });
                }
            }
            out
        };
        if !self.directional {
            let all =
                concat((0..self.forces.len()).map(|c| writes(&index(c).to_token_stream(), c)));
            // Terms that read `λ` (the points' under a free base,
            // `crate::equations::point_tangent`): the caller has bound it.
            let preamble = concat([preamble, self.body.after_multipliers()]);
            // Nested no deeper than a block (`super::chunks`).
            let preamble = bounded(preamble, &all);
            return braced(concat([preamble, all]));
        }
        let seeds = (0..columns)
            .filter(|&c| self.body.uses(Sym::Seed(c)))
            .map(|c| {
                let (seed, cl) = (Context::local("seed", c), index(c));
                quote! { let #seed = if __c == #cl { T::one() } else { T::zero() }; }
            });
        let after = self.body.after_multipliers();
        let column = writes(&quote!(__c), 0);
        let columns = index(columns);
        let mut each = seeds.collect::<TokenStream>();
        each.extend(after);
        each.extend(column);
        let mut looped = quote! { for __c in 0..#columns };
        looped.extend(braced(each));
        let mut block = bounded(preamble, &looped);
        block.extend(looped);
        braced(block)
    }
}

/// A `usize` index as an unsuffixed literal.
pub(super) fn index(i: usize) -> proc_macro2::Literal {
    proc_macro2::Literal::usize_unsuffixed(i)
}

/// The sets of derivatives: one per column, or the one along the seeds
/// (then `true`).
fn sets<'a>(ctx: &Context<'a>) -> (Vec<&'a Derivatives>, bool) {
    match &ctx.eq.tangent.form {
        Form::Columns(columns) => (columns.iter().collect(), false),
        Form::Directional(along) => (vec![along], true),
    }
}

/// The expressions the terms read: every structurally nonzero derivative.
fn roots(ctx: &Context, sets: &[&Derivatives]) -> Vec<Id> {
    let g = &ctx.eq.system.graph;
    let mut roots: Vec<Id> = Vec::new();
    for d in sets {
        roots.extend(d.forces.iter().filter(|&&e| !g.is_zero(e)));
        roots.extend(d.mass.iter().map(|&(_, _, e)| e));
        roots.extend(d.mass_times.iter().filter(|&&e| !g.is_zero(e)));
        roots.extend(d.a.iter().map(|&(_, _, e)| e));
        roots.extend(d.b.iter().filter(|&&e| !g.is_zero(e)));
    }
    roots
}

/// `F̃` and `b̃` of each set, `[set][row]`, `None` where a structural zero.
type Terms = (Vec<Vec<Option<TokenStream>>>, Vec<Vec<Option<TokenStream>>>);

/// `F̃` and `b̃` of each set, contracted with `__qdd{i}` and `__lam{r}`,
/// each derivative written by `expr`; with `scales`, row `r`'s `b̃`
/// scaled by `scales[r]` and `F̃`'s constant coefficients of `λ` folded
/// with it onto `__lams{r}` ([`TangentTerms::scaled`]).
fn terms(
    ctx: &Context,
    sets: &[&Derivatives],
    expr: &dyn Fn(Id) -> TokenStream,
    scales: Option<&[Num]>,
) -> Terms {
    let (n, k) = (ctx.n, ctx.k);
    let g = &ctx.eq.system.graph;
    let qdd: Vec<_> = (0..n).map(|i| Context::local("qdd", i)).collect();
    let lam: Vec<_> = (0..k).map(|r| Context::local("lam", r)).collect();
    let solved: Vec<_> = (0..k).map(|r| Context::local("lams", r)).collect();
    let scale = |r: usize| scales.map_or(Num::int(1), |s| s[r]);
    let mut forces = Vec::with_capacity(sets.len());
    let mut rhs = Vec::with_capacity(sets.len());
    for d in sets {
        // Each entry's own derivative (`∂F/∂v`, `∂b/∂v`) as its first term.
        let mut f: Vec<Vec<(bool, TokenStream)>> = d
            .forces
            .iter()
            .map(|&e| own(g, e, expr).into_iter().collect())
            .collect();
        for &(i, j, e) in &d.mass {
            f[i].push(times(g, e, &qdd[j], true, expr));
        }
        for (i, &e) in d.mass_times.iter().enumerate() {
            if !g.is_zero(e) {
                // Subtracted whole: a written sum must not lose its sign
                // after its first term.
                let e = expr(e);
                f[i].push((true, quote!((#e))));
            }
        }
        // Row `r`'s terms of `b̃`: in a scaled row, those whose coefficient
        // is a number carry the scale in it, the others are summed under
        // it; an unscaled row's are in order.
        let mut constant: Vec<Vec<(bool, TokenStream)>> = vec![Vec::new(); k];
        // A sum of numeric multiples takes the scale into its coefficients.
        let mut other: Vec<Vec<(bool, TokenStream)>> = (d.b.iter().enumerate())
            .map(|(r, &e)| match distributed(g, e, scale(r), expr) {
                Some(terms) => {
                    constant[r] = terms;
                    Vec::new()
                }
                None => own(g, e, expr).into_iter().collect(),
            })
            .collect();
        for &(r, i, e) in &d.a {
            let s = scale(r);
            match (g.as_num(e), s.is_one()) {
                (Some(c), false) => {
                    f[i].push(times_number(c * s, &solved[r], false));
                    constant[r].push(times_number(c * s, &qdd[i], true));
                }
                _ => {
                    f[i].push(times(g, e, &lam[r], false, expr));
                    other[r].push(times(g, e, &qdd[i], true, expr));
                }
            }
        }
        forces.push(f.into_iter().map(signed_sum).collect());
        let b = other
            .into_iter()
            .zip(constant)
            .enumerate()
            .map(|(r, (other, constant))| {
                let s = scale(r);
                let scaled = signed_sum(other).map(|sum| match s.is_one() {
                    true => (false, sum),
                    false => {
                        let (s, _) = literal(s);
                        (false, quote!(#s * (#sum)))
                    }
                });
                signed_sum(scaled.into_iter().chain(constant))
            });
        rhs.push(b.collect());
    }
    (forces, rhs)
}

/// `∂F/∂v` or `∂b/∂v` as a first term, `None` where a structural zero.
fn own(
    g: &crate::expr::Graph,
    e: Id,
    expr: &dyn Fn(Id) -> TokenStream,
) -> Option<(bool, TokenStream)> {
    (!g.is_zero(e)).then(|| (false, expr(e)))
}

/// `e · x` as a signed term (`negative`: subtracted).
fn times(
    g: &crate::expr::Graph,
    e: Id,
    x: &syn::Ident,
    negative: bool,
    expr: &dyn Fn(Id) -> TokenStream,
) -> (bool, TokenStream) {
    match g.as_num(e) {
        Some(c) => times_number(c, x, negative),
        None => {
            let e = expr(e);
            (negative, quote!((#e) * #x))
        }
    }
}

/// `s · e` as signed terms where `s` is not 1 and `e` is a sum
/// `Σ cᵢ·tᵢ + c₀`: `Σ (s cᵢ)·tᵢ + s c₀`, each coefficient folded at
/// compile time. `None` otherwise.
fn distributed(
    g: &crate::expr::Graph,
    e: Id,
    s: Num,
    expr: &dyn Fn(Id) -> TokenStream,
) -> Option<Vec<(bool, TokenStream)>> {
    let crate::expr::Node::Add(terms, c0) = g.node(e) else {
        return None;
    };
    if s.is_one() {
        return None;
    }
    let mut out: Vec<(bool, TokenStream)> = terms
        .iter()
        .map(|&(t, c)| {
            // A term written as more than one token is bracketed, as a
            // factor and under a sign.
            let t = expr(t);
            let t = match t.clone().into_iter().nth(1) {
                Some(_) => quote!((#t)),
                None => t,
            };
            times_number(c * s, &t, false)
        })
        .collect();
    if !c0.is_zero() {
        let c = *c0 * s;
        let magnitude = literal(if c.is_negative() { -c } else { c }).0;
        out.push((c.is_negative(), magnitude));
    }
    Some(out)
}

/// `c · x` as a signed term: a coefficient of ±1 multiplies by nothing, a
/// negative one flips the sign.
fn times_number(c: Num, x: &impl ToTokens, negative: bool) -> (bool, TokenStream) {
    if c.is_one() {
        (negative, quote!(#x))
    } else if (-c).is_one() {
        (!negative, quote!(#x))
    } else {
        let magnitude = literal(if c.is_negative() { -c } else { c }).0;
        (negative != c.is_negative(), quote!(#magnitude * #x))
    }
}

/// Per column of the per-column form, which rows of `F̃` and which of `b̃`
/// can be nonzero; `None` for the directional form.
pub(super) fn column_patterns(ctx: &Context) -> Option<Vec<(Vec<bool>, Vec<bool>)>> {
    let (sets, directional) = sets(ctx);
    if directional {
        return None;
    }
    // Any tokens do: only which terms exist is read.
    let (forces, rhs) = terms(ctx, &sets, &|_| quote!(x), None);
    let rows = forces
        .iter()
        .zip(&rhs)
        .map(|(f, b)| {
            let f = f.iter().map(Option::is_some).collect();
            let b = b.iter().map(Option::is_some).collect();
            (f, b)
        })
        .collect();
    Some(rows)
}

/// Per column of the per-column form, the row and the number where its
/// `F̃` is that number in that row and zero elsewhere, with no `b̃`: a
/// column of `∂q̈/∂u` where an input enters `F` alone with a constant
/// factor (a motor torque), whose tangent solve is a column of `M⁻¹`
/// scaled. `None` for another column, and for the directional form.
pub(super) fn constant_columns(ctx: &Context) -> Option<Vec<Option<(usize, Num)>>> {
    let (sets, directional) = sets(ctx);
    if directional {
        return None;
    }
    let g = &ctx.eq.system.graph;
    let column = |d: &Derivatives| -> Option<(usize, Num)> {
        let coupled = d.mass.iter().any(|&(_, _, e)| !g.is_zero(e))
            || d.mass_times.iter().any(|&e| !g.is_zero(e))
            || d.a.iter().any(|&(_, _, e)| !g.is_zero(e))
            || d.b.iter().any(|&e| !g.is_zero(e));
        let mut rows = d.forces.iter().enumerate().filter(|(_, &e)| !g.is_zero(e));
        let (row, &e) = rows.next()?;
        if coupled || rows.next().is_some() {
            return None;
        }
        Some((row, g.as_num(e)?))
    };
    Some(sets.iter().map(|d| column(d)).collect())
}

/// The per-column terms written over locals bound elsewhere: the
/// derivatives each get a name (`__tg{i}`, constants inlined) for the
/// caller to bind in its own body, so that they share its temporaries (its
/// sines and cosines above all). `None` for the directional form.
pub(super) struct NamedTerms {
    /// The derivatives to bind, each under its name.
    pub named: Vec<(syn::Ident, Id)>,
    /// `forces[c][i]`: `F̃` of column `c`, row `i`.
    pub forces: Vec<Vec<Option<TokenStream>>>,
    /// `rhs[c][r]`: `b̃` of column `c`, constraint `r`.
    pub rhs: Vec<Vec<Option<TokenStream>>>,
}

impl NamedTerms {
    pub(super) fn new(ctx: &Context) -> Option<NamedTerms> {
        let (sets, directional) = sets(ctx);
        // The derivatives of `M q̈` read `q̈`, which the body these names are
        // bound in has not solved yet: those systems take `tangent_rhs`.
        if directional || sets.iter().any(|d| !d.mass_times.is_empty()) {
            return None;
        }
        let g = &ctx.eq.system.graph;
        let mut names: std::collections::HashMap<Id, syn::Ident> = Default::default();
        let mut named = Vec::new();
        for e in roots(ctx, &sets) {
            if g.as_num(e).is_none() && !names.contains_key(&e) {
                let name = Context::local("tg", named.len());
                names.insert(e, name.clone());
                named.push((name, e));
            }
        }
        let expr = |e: Id| match (g.as_num(e), names.get(&e)) {
            (Some(c), _) => literal(c).0,
            (None, Some(name)) => quote!(#name),
            (None, None) => unreachable!("every derivative the terms read is named"),
        };
        let (forces, rhs) = terms(ctx, &sets, &expr, None);
        Some(NamedTerms { named, forces, rhs })
    }
}

/// `tangent_rhs(q, qd, t, qdd, lam, f, b)`: writes `F̃` and `b̃`, one
/// column per variable, for the runtime's dense solve.
pub(super) fn tangent_rhs(ctx: &Context) -> TokenStream {
    let (n, k, columns) = (ctx.n, ctx.k, ctx.eq.tangent.columns.len());
    let terms = TangentTerms::new(ctx);
    let qdd: Vec<_> = (0..n).map(|i| Context::local("qdd", i)).collect();
    let lam: Vec<_> = (0..k).map(|r| Context::local("lam", r)).collect();
    // Only the structural nonzeros are written: the caller passes zeros.
    let writes = terms.fill(columns, &quote!(__f.data.0), &quote!(__b.data.0));
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
            #writes
        }
    }
}

/// `∂ψ/∂q` of the velocity-level constraints, `k × n`.
pub(super) fn velocity_constraint_jacobian(ctx: &Context) -> TokenStream {
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
