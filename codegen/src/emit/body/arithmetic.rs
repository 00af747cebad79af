//! How a [`Body`] writes sums and products: signs without multiplications
//! by ±1, a negated sum factor in place of a unary minus, reused temporary
//! products and shared sub-products, reciprocals and unrolled powers.

use super::{literal, Body, Prec};
use crate::emit::context::Context;
use crate::emit::subproducts::{qualifies, qualifying, Factor};
use crate::emit::tokens::{join_product, parenthesized, signed_sum};
use crate::expr::cse::MAX_UNROLLED_POWER;
use crate::expr::num::Num;
use crate::expr::{signed_parts, Id, Node};
use proc_macro2::{Literal, TokenStream};
use quote::quote;

impl Body<'_> {
    /// `Σ cᵢ·tᵢ + c₀` as `a + b - 2·c + …`: subtraction for negative
    /// coefficients, no multiplication by ±1.
    pub(super) fn sum(&self, terms: &[(Id, Num)], c0: Num) -> (TokenStream, Prec) {
        self.signed_sum(terms, c0, false)
    }

    /// The sum, or its negation, in as few operations as its form allows:
    /// a positive part first (no unary minus while one exists), and where
    /// every part is negative, one product's sum factor negated instead
    /// (`−ż·(g − α)` is `ż·(α − g)`). A shared rational content is not
    /// factored out (`2·(a − b·c)`), nor a shared magnitude (`c·(a − b)`
    /// for `c·a − c·b`): once the rows of `A` are scaled it saves few
    /// operations, and the longer dependency chain it makes costs the
    /// chains more time than the fewer operations save elsewhere
    /// (`scripts/compare_acceleration.sh` compares two revisions' code).
    fn signed_sum(&self, terms: &[(Id, Num)], c0: Num, negate: bool) -> (TokenStream, Prec) {
        let mut parts: Vec<(Option<Id>, Num, bool, Option<usize>)> = signed_parts(terms, c0)
            .into_iter()
            .map(|(t, m, negative)| (t, m, negative != negate, None))
            .collect();
        if parts.iter().all(|p| p.2) {
            let flip = parts
                .iter()
                .enumerate()
                .find_map(|(i, p)| Some((i, self.negatable_factor(p.0?)?)));
            if let Some((i, factor)) = flip {
                parts[i].2 = false;
                parts[i].3 = Some(factor);
            }
        }
        if let Some(first) = parts.iter().position(|p| !p.2) {
            let positive = parts.remove(first);
            parts.insert(0, positive);
        }
        let terms = parts.iter().map(|&(term, magnitude, negative, flipped)| {
            let value = match term {
                Some(t) => {
                    let (tokens, prec) = match (flipped, self.graph.node(t)) {
                        (Some(which), Node::Mul(factors)) => self.product(factors, Some(which)),
                        _ => self.operand(t),
                    };
                    let at_least = if magnitude.is_one() {
                        Prec::Product
                    } else {
                        Prec::Unary
                    };
                    let t = if prec < at_least {
                        parenthesized(tokens)
                    } else {
                        tokens
                    };
                    if magnitude.is_one() {
                        t
                    } else {
                        let mut lit = self.literal(magnitude);
                        lit.extend(quote!(*));
                        lit.extend(t);
                        lit
                    }
                }
                None => self.literal(magnitude),
            };
            (negative, value)
        });
        let out = signed_sum(terms).unwrap_or_default();
        let prec = match parts.as_slice() {
            [(Some(_), m, true, _)] if m.is_one() => Prec::Unary,
            [(Some(_), _, _, _)] => Prec::Product,
            _ => Prec::Sum,
        };
        (out, prec)
    }

    /// For a product inlined into a sum, the position of a factor that is
    /// itself an inlined sum with a negative part, so that negating the
    /// product costs nothing: that sum is written negated.
    fn negatable_factor(&self, t: Id) -> Option<usize> {
        if self.temp_names.contains_key(&t) {
            return None;
        }
        let Node::Mul(factors) = self.graph.node(t) else {
            return None;
        };
        factors.iter().position(|&(b, e)| {
            e.is_one()
                && !self.temp_names.contains_key(&b)
                && matches!(self.graph.node(b), Node::Add(terms, c0)
                    if terms.len() + usize::from(!c0.is_zero()) > 1
                        && (terms.iter().any(|t| t.1.is_negative()) || c0.is_negative()))
        })
    }

    /// `Π bᵢ^eᵢ` as `num / den`, small integer powers unrolled.
    pub(super) fn product(
        &self,
        factors: &[(Id, Num)],
        negated: Option<usize>,
    ) -> (TokenStream, Prec) {
        let (mut num, mut den) = (Vec::new(), Vec::new());
        // A temporary product whose factors are among these (`t·λ` inside
        // `t·λ/m`) is reused rather than recomputed.
        let reused =
            self.temp_products
                .reusable(self.graph, factors, (negated, self.defining.get()));
        if let Some((p, _)) = &reused {
            let name = &self.temp_names[p];
            num.push(quote!(#name));
        }
        let covered = |i: usize| {
            reused
                .as_ref()
                .is_some_and(|(_, covered)| covered.contains(&i))
        };
        // The variables left are written through the shared sub-products
        // (`m·l` once for `m·l·cos θ` and `m·l²`); what remains of each
        // variable's power is written below.
        let rest = factors
            .iter()
            .enumerate()
            .filter(|&(i, _)| !covered(i) && negated != Some(i))
            .map(|(_, &f)| f);
        let shareable = |id: Id| self.subproducts.shareable(id);
        let applied = self
            .subproducts
            .apply(qualifying(self.graph, rest, &shareable));
        for (&f, &k) in &applied {
            if let Factor::Shared(i) = f {
                let name = Context::local("sp", i);
                num.extend((0..k).map(|_| quote!(#name)));
            }
        }
        for (i, &(b, e)) in factors.iter().enumerate() {
            if covered(i) {
                continue;
            }
            // A variable: only the power no sub-product took.
            let e = if negated != Some(i) && qualifies(self.graph, b, e, &shareable).is_some() {
                let left = applied.get(&Factor::Leaf(b)).copied().unwrap_or(0);
                if left == 0 {
                    continue;
                }
                Num::int(i64::from(left))
            } else {
                e
            };
            if negated == Some(i) {
                // A sum factor of power 1 (`negatable_factor`), negated.
                if let Node::Add(terms, c0) = self.graph.node(b) {
                    let (tokens, _) = self.signed_sum(terms, *c0, true);
                    num.push(parenthesized(tokens));
                    continue;
                }
            }
            self.push_power(b, e, &mut num, &mut den);
        }
        fraction(num, den)
    }

    /// `b^e` as factors of the numerator, or for a negative exponent of the
    /// denominator; a small negative integer power of a base that has a
    /// reciprocal bound is that many multiplications by the reciprocal.
    fn push_power(&self, b: Id, e: Num, num: &mut Vec<TokenStream>, den: &mut Vec<TokenStream>) {
        if let (true, Some(name), Some(k)) = (
            e.is_negative(),
            self.reciprocals.get(&b),
            (-e).as_integer().filter(|&k| k <= MAX_UNROLLED_POWER),
        ) {
            num.extend((0..k).map(|_| quote!(#name)));
            return;
        }
        if e.is_negative() {
            den.extend(self.power(b, -e));
        } else {
            num.extend(self.power(b, e));
        }
    }

    /// `b^e` for `e > 0` as factors to multiply: `[b, b]` for `e = 2`,
    /// `[b.sqrt()]` for `e = 1/2`, `[b.powi(7)]`, `[b.powf(lit)]`.
    fn power(&self, b: Id, e: Num) -> Vec<TokenStream> {
        // Each arm renders the base once: rendering it twice and dropping
        // one copy doubles the work per nesting level (exponential time).
        let atom = || self.wrapped(b, Prec::Atom);
        match e.as_integer() {
            Some(k) if k <= MAX_UNROLLED_POWER => vec![self.wrapped(b, Prec::Unary); k as usize],
            // `powi` takes an `i32`; a larger integer goes to `powf` below.
            Some(k) if i32::try_from(k).is_ok() => {
                let (k, atom) = (Literal::i64_unsuffixed(k), atom());
                vec![quote! { #atom.powi(#k) }]
            }
            _ if e == Num::ratio(1, 2) => {
                let atom = atom();
                vec![quote! { #atom.sqrt() }]
            }
            _ => {
                let ((lit, _), atom) = (literal(e), atom());
                vec![quote! { #atom.powf(#lit) }]
            }
        }
    }
}

/// `num / den` joined into one product over another (`T::one()` for an
/// empty numerator, the denominator parenthesised where it has several
/// factors), with the precedence of the whole.
fn fraction(num: Vec<TokenStream>, den: Vec<TokenStream>) -> (TokenStream, Prec) {
    let single = num.len() == 1;
    let mut numerator = join_product(num).unwrap_or_else(|| quote!(T::one()));
    let denominators = den.len();
    let Some(d) = join_product(den) else {
        let prec = if single { Prec::Unary } else { Prec::Product };
        return (numerator, prec);
    };
    numerator.extend(quote!(/));
    numerator.extend(if denominators == 1 {
        d
    } else {
        parenthesized(d)
    });
    (numerator, Prec::Product)
}
