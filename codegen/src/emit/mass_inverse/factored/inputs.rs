//! The code before a factored solve: `M`, `F`, `A` and `b` bound to
//! locals by one CSE'd body, their finiteness checked, and `M`'s
//! factorization, for a large branched `M` interleaved with the entries it
//! reads.

use super::auxiliary;
use crate::emit::body::Body;
use crate::emit::context::Context;
use crate::emit::demand::interleaved;
use crate::emit::detached;
use crate::emit::ldlt::{Solves, StructuredLdlt};
use crate::emit::tokens::{concat, let_statement};
use crate::equations::mass_inverse::Factored;
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// The code before the solve proper: the inputs (`M`, `F`, `A`, `b`),
/// their check and `M`'s factorization.
pub(super) enum Head {
    /// All of it before the solve.
    Before(TokenStream),
    /// Each input computed where the factorization first reads it
    /// ([`interleaved`]), the rest (`F`, `A`, `b`) after it. (Moving `F`
    /// into the solve too made the G1's `acceleration` larger.)
    Interleaved {
        inputs: TokenStream,
        factor: TokenStream,
    },
}

impl Head {
    /// The head, then `solve`.
    pub(super) fn then(self, solve: TokenStream) -> TokenStream {
        match self {
            Head::Before(before) => concat([before, solve]),
            Head::Interleaved { inputs, factor } => concat([interleaved(inputs, factor), solve]),
        }
    }
}

/// `M`'s factorization and the code before the solve: the inputs, their
/// check, for a semi-definite `M` the auxiliary mass and forces, and the
/// factorization, where [`interleaves`] says so with each input computed
/// where the factorization first reads it.
pub(super) fn head<'a>(
    ctx: &Context,
    f: &'a Factored,
    (dynamics, correction, extra): (bool, bool, &[(Ident, Id)]),
    (solves, mass_bail): (Solves, TokenStream),
    bail: &dyn Fn(TokenStream) -> TokenStream,
) -> (StructuredLdlt<'a>, Head) {
    if f.auxiliary.is_some() || !interleaves(ctx, f) {
        let mass = StructuredLdlt::mass(&f.mass, mass_bail, solves);
        let inputs = inputs(ctx, f, &mass, (dynamics, extra), (true, bail));
        let auxiliary = f
            .auxiliary
            .is_some()
            .then(|| auxiliary::prelude(ctx, f, &mass, dynamics, correction));
        let before = concat([inputs, auxiliary.unwrap_or_default(), mass.factor()]);
        return (mass, Head::Before(before));
    }
    let errors = (mass_bail, bail(quote!(DynamicsError::NonFinite)));
    let mass = StructuredLdlt::mass_checked(&f.mass, errors, solves);
    let inputs = inputs(ctx, f, &mass, (dynamics, extra), (false, bail));
    let factor = mass.factor();
    (mass, Head::Interleaved { inputs, factor })
}

/// Whether `M`'s entries are computed as its factorization reads them
/// ([`interleaved`]), the pivots checking what the inputs' check did. A
/// branched tree's `M` (structural zeros) is factored one branch after
/// another, each column reading its own branch's entries; a large one
/// ([`detached::large`]) would otherwise hold every entry, in a register
/// or a slot of the stack, until the last is known. A chain's dense `M`
/// gains nothing (every column reads every earlier one), and a small `M`
/// fits the registers; both keep the one check of every entry, which
/// vectorizes, where the pivots' checks would branch once each.
fn interleaves(ctx: &Context, f: &Factored) -> bool {
    let branched = f.mass.nonzero.iter().flatten().any(|&nz| !nz);
    let entries: Vec<Id> = (0..ctx.n)
        .flat_map(|i| (0..=i).map(move |j| (i, j)))
        .filter(|&(i, j)| f.mass.nonzero[i][j])
        .map(|(i, j)| ctx.eq.system.mass[i][j])
        .collect();
    branched && detached::large(ctx, &entries)
}

/// The model's expressions bound to locals ([`named_inputs`]) and checked:
/// `M` and `F` finite (an overflowed one would be solved as a limit,
/// 1/∞ = 0).
pub(super) fn inputs(
    ctx: &Context,
    f: &Factored,
    mass: &StructuredLdlt,
    (dynamics, extra): (bool, &[(Ident, Id)]),
    (check_mass, bail): (bool, &dyn Fn(TokenStream) -> TokenStream),
) -> TokenStream {
    let (mut named, mass_and_forces) = named_inputs(ctx, f, mass, dynamics);
    named.extend(extra.iter().cloned());
    let first = if check_mass {
        0
    } else {
        (0..ctx.n)
            .map(|i| (0..=i).filter(|&j| f.mass.nonzero[i][j]).count())
            .sum()
    };
    bind(ctx, &named, first..mass_and_forces, bail)
}

/// `named`'s expressions bound to their locals by one CSE'd body (shared
/// between the functions that bind the same list), those at `checked`
/// checked finite.
pub(super) fn bind(
    ctx: &Context,
    named: &[(Ident, Id)],
    checked: std::ops::Range<usize>,
    bail: &dyn Fn(TokenStream) -> TokenStream,
) -> TokenStream {
    let cached = ctx.bodies.borrow().get(named).cloned();
    let mut out = cached.unwrap_or_else(|| {
        let roots: Vec<Id> = named.iter().map(|(_, e)| *e).collect();
        let body = Body::new(ctx.eq, &roots);
        let mut out = body.preamble();
        out.extend(named.iter().map(|(name, id)| {
            let value = body.expr(*id);
            let_statement(name, value)
        }));
        ctx.bodies.borrow_mut().insert(named.to_vec(), out.clone());
        out
    });
    if checked.is_empty() {
        return out;
    }
    let finite = named[checked]
        .iter()
        .map(|(name, _)| quote!(#name.is_finite()));
    let non_finite = bail(quote!(DynamicsError::NonFinite));
    out.extend(quote! {
        if !(#(#finite)&*) {
            #non_finite
        }
    });
    out
}

/// The locals bound from the model's expressions: `M`'s lower pattern,
/// `F` (with `dynamics`), `A`'s nonzeros, `b` (with `dynamics`); and how
/// many of them are `M` and `F`, which come first (the finiteness check
/// reads them). For a semi-definite `M`, `M` and `F` under their own
/// names and `AᵀA` ([`auxiliary::named_mass_and_forces`]).
fn named_inputs(
    ctx: &Context,
    f: &Factored,
    mass: &StructuredLdlt,
    dynamics: bool,
) -> (Vec<(Ident, Id)>, usize) {
    let sys = &ctx.eq.system;
    let (mut named, mass_and_forces) = match &f.auxiliary {
        Some(aux) => auxiliary::named_mass_and_forces(ctx, aux, dynamics),
        None => {
            let mut named: Vec<(Ident, Id)> = Vec::new();
            for i in 0..ctx.n {
                for j in 0..=i {
                    if f.mass.nonzero[i][j] {
                        named.push((mass.entry(i, j), sys.mass[i][j]));
                    }
                }
            }
            if dynamics {
                for (i, &e) in sys.forces.iter().enumerate() {
                    named.push((Context::local("f", i), e));
                }
            }
            let count = named.len();
            (named, count)
        }
    };
    for (r, row) in ctx.eq.a.iter().enumerate() {
        for (i, &e) in row.iter().enumerate() {
            if !sys.graph.is_zero(e) {
                named.push((Context::local2("a", r, i), e));
            }
        }
    }
    if dynamics {
        for (r, &e) in ctx.eq.b.iter().enumerate() {
            named.push((Context::local("b", r), e));
        }
    }
    (named, mass_and_forces)
}

#[cfg(test)]
mod tests {
    use crate::tools::fixtures::{panda, two_arms};

    /// The generated `gauss` of `source`, as text without spaces.
    fn gauss(source: &str) -> String {
        let expanded = crate::expand(source.parse().expect("tokens")).expect("expands");
        let file: syn::File = syn::parse2(expanded).expect("Rust");
        let body = file
            .items
            .iter()
            .filter_map(|i| match i {
                syn::Item::Impl(i) => Some(i),
                _ => None,
            })
            .flat_map(|i| &i.items)
            .find_map(|i| match i {
                syn::ImplItem::Fn(f) if f.sig.ident == "gauss" => Some(f),
                _ => None,
            })
            .expect("gauss");
        quote::ToTokens::to_token_stream(&body.block)
            .to_string()
            .replace(' ', "")
    }

    /// Where `let` of `name` is, `None` where there is none.
    fn bound(text: &str, name: &str) -> Option<usize> {
        text.find(&format!("let{name}="))
    }

    /// Two arms of five links on a torso (a branched `M` past
    /// `DETACH_FROM` operations; three links each stay below): the first pivot is
    /// factored before the last entry of `M` is computed, each pivot is
    /// checked finite, and no entry of `M` is checked before. A chain's
    /// dense `M` (the Panda's six links) keeps the check of every entry
    /// before its factorization.
    #[test]
    fn a_branched_mass_is_factored_as_its_entries_come() {
        let branched = gauss(&two_arms("TwoArms", 5));
        let first_pivot = bound(&branched, "__md0").expect("pivot");
        let entries: Vec<usize> = (0..11)
            .flat_map(|i| (0..=i).map(move |j| (i, j)))
            .filter_map(|(i, j)| bound(&branched, &format!("__m{i}_{j}")))
            .collect();
        assert!(entries.len() > 11, "{} entries", entries.len());
        let last_entry = entries.iter().max().expect("entries");
        assert!(first_pivot < *last_entry, "{first_pivot} ≥ {last_entry}");
        for p in 0..11 {
            let check = format!("if!(__md{p}>T::zero()&&__md{p}.is_finite())");
            assert!(branched.contains(&check), "pivot {p} unchecked");
        }
        assert!(!branched.contains("__m0_0.is_finite()"));

        let chain = gauss(&panda("Arm", 6));
        let check = chain.find("__m0_0.is_finite()").expect("entries checked");
        assert!(check < bound(&chain, "__md0").expect("pivot"));
        assert!(!chain.contains("__md0.is_finite()"));
    }
}
