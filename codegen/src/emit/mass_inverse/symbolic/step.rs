//! `constraint_step` for a symbolic `M⁻¹` (see `super::super::step`).

use crate::emit::body::Body;
use crate::emit::context::Context;
use crate::emit::ldlt::StructuredLdlt;
use crate::emit::mass_inverse::step::finish;
use crate::equations::mass_inverse::Symbolic;
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::quote;
use syn::Ident;

/// Constant or diagonal `M`: `S` and `W` as the symbolic expressions.
pub(in crate::emit) fn step(ctx: &Context, d: &Symbolic) -> TokenStream {
    let g = &ctx.eq.system.graph;
    let ldlt = StructuredLdlt::gram(&d.structure);
    let k = ctx.k;
    let mut named: Vec<(Ident, Id)> = Vec::new();
    for i in 0..k {
        for j in 0..=i {
            if d.structure.nonzero[i][j] {
                named.push((ldlt.entry(i, j), d.gram[i][j]));
            }
        }
    }
    let mut roots: Vec<Id> = named.iter().map(|(_, e)| *e).collect();
    roots.extend(d.weighted.iter().flatten().filter(|&&e| !g.is_zero(e)));
    // Each distinct mass that is not a positive constant, checked once.
    let mut masses: Vec<Id> = Vec::new();
    for &m in &d.masses {
        if !g.as_num(m).is_some_and(|v| v.to_f64() > 0.0) && !masses.contains(&m) {
            masses.push(m);
        }
    }
    roots.extend(&masses);
    let body = Body::new(ctx.eq, &roots);
    let preamble = body.preamble();
    let bindings = named.iter().map(|(name, e)| {
        let value = body.expr(*e);
        quote! { let #name = #value; }
    });
    let check = (!masses.is_empty()).then(|| {
        let positive = masses.iter().map(|&m| {
            let m = body.expr(m);
            quote!(#m > T::zero())
        });
        quote! {
            if !(#(#positive)&&*) {
                return ::core::option::Option::None;
            }
        }
    });
    let factor = ldlt.factor();
    let finish = finish(ctx, &ldlt, &d.scale, |i, j| {
        // An entry of W may be a sum (x₁ − x₂ over a mass): `factor`
        // parenthesises it.
        let e = d.weighted[i][j];
        (!g.is_zero(e)).then(|| body.factor(e))
    });
    quote! {
        #preamble
        #(#bindings)*
        #check
        #factor
        #finish
    }
}
