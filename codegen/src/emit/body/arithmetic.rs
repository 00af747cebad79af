//! How a [`Body`] writes sums and products: signs without multiplications
//! by ±1, a negated sum factor in place of a unary minus, in a large body
//! each magnitude that terms share written once, reused temporary
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
use std::collections::HashMap;

/// A part of a sum as it is written: whether it is subtracted, and its
/// tokens.
type Signed = (bool, TokenStream);

/// The size, in nodes of the graph it reads, from which a body's time
/// follows the size of its code rather than its longest chain of
/// operations: such a body's code outgrows the L1 instruction cache and
/// streams from L2 on every call (the G1's `q̈`, `∂τ` and `tangent_rhs`),
/// so that every instruction removed is time saved. Below it the code
/// stays in L1 and a sum's dependency chain decides: the 32-link chain's
/// `q̈` (about a thousand operations) ran slower with its magnitudes
/// shared.
pub(super) const LARGE_BODY: usize = 4096;

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
    /// factored out (`2·(a − b·c)`), nor, in a body below [`LARGE_BODY`],
    /// a shared magnitude (`c·(a − b)` for `c·a − c·b`): once the rows of
    /// `A` are scaled it saves few operations, and the longer dependency
    /// chain it makes costs the chains more time than the fewer operations
    /// save elsewhere (`scripts/compare_acceleration.sh` compares two
    /// revisions' code). In a larger body the magnitudes are shared
    /// ([`Body::shared_magnitudes`]).
    fn signed_sum(&self, terms: &[(Id, Num)], c0: Num, negate: bool) -> (TokenStream, Prec) {
        let (groups, terms) = self.shared_magnitudes(terms, negate);
        let mut parts: Vec<(Option<Id>, Num, bool, Option<usize>)> = signed_parts(&terms, c0)
            .into_iter()
            .map(|(t, m, negative)| (t, m, negative != negate, None))
            .collect();
        if parts.iter().all(|p| p.2) && groups.iter().all(|g| g.0) {
            let flip = parts
                .iter()
                .enumerate()
                .find_map(|(i, p)| Some((i, self.negatable_factor(p.0?)?)));
            if let Some((i, factor)) = flip {
                parts[i].2 = false;
                parts[i].3 = Some(factor);
            }
        }
        let prec = match (parts.as_slice(), groups.as_slice()) {
            ([(Some(_), m, true, _)], []) if m.is_one() => Prec::Unary,
            ([(Some(_), _, _, _)], []) => Prec::Product,
            ([], [(true, _)]) => Prec::Unary,
            ([], [(false, _)]) => Prec::Product,
            _ => Prec::Sum,
        };
        let mut items: Vec<Signed> = parts
            .iter()
            .map(|&(term, magnitude, negative, flipped)| {
                (negative, self.scaled_part(term, magnitude, flipped))
            })
            .collect();
        items.extend(groups);
        // A positive part first, so that no unary minus is written while
        // one exists.
        if let Some(first) = items.iter().position(|p| !p.0) {
            let positive = items.remove(first);
            items.insert(0, positive);
        }
        (signed_sum(items).unwrap_or_default(), prec)
    }

    /// One part of a sum, `c·t` (or `t` where `c` is one, or `c` alone),
    /// with the factor `flipped` of a product written negated.
    fn scaled_part(&self, term: Option<Id>, magnitude: Num, flipped: Option<usize>) -> TokenStream {
        let Some(t) = term else {
            return self.literal(magnitude);
        };
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

    /// In a body of [`LARGE_BODY`] nodes or more, the terms whose
    /// magnitude (other than one) two or more terms share, each such group
    /// written once as `c·(±a ± b …)` with its sign (negative where every
    /// term of it is), in the order the magnitudes first occur; and the
    /// terms left. Elsewhere, no group and every term.
    fn shared_magnitudes(
        &self,
        terms: &[(Id, Num)],
        negate: bool,
    ) -> (Vec<Signed>, Vec<(Id, Num)>) {
        if !self.shares_magnitudes || terms.len() < 2 {
            return (Vec::new(), terms.to_vec());
        }
        let magnitude = |c: Num| if c.is_negative() { -c } else { c };
        let mut count: HashMap<Num, usize> = HashMap::new();
        for &(_, c) in terms {
            *count.entry(magnitude(c)).or_default() += 1;
        }
        // Each shared magnitude's terms, with whether each is subtracted,
        // in the order the magnitudes first occur.
        let mut groups: Vec<(Num, Vec<(Id, bool)>)> = Vec::new();
        let mut group_of: HashMap<Num, usize> = HashMap::new();
        let mut rest = Vec::new();
        for &(t, c) in terms {
            let m = magnitude(c);
            if m.is_one() || count.get(&m).is_none_or(|&k| k < 2) {
                rest.push((t, c));
                continue;
            }
            let i = *group_of.entry(m).or_insert_with(|| {
                groups.push((m, Vec::new()));
                groups.len() - 1
            });
            if let Some((_, members)) = groups.get_mut(i) {
                members.push((t, c.is_negative() != negate));
            }
        }
        let groups = groups
            .iter()
            .map(|(m, members)| self.shared_group(*m, members))
            .collect();
        (groups, rest)
    }

    /// `c·(±a ± b …)` for the terms `members` (each with whether it is
    /// subtracted) of magnitude `c`: subtracted whole where every member
    /// is, so that its sum starts with an addition.
    fn shared_group(&self, magnitude: Num, members: &[(Id, bool)]) -> Signed {
        let negative = members.iter().all(|&(_, n)| n);
        let inner: Vec<(Id, Num)> = members
            .iter()
            .map(|&(t, n)| {
                (
                    t,
                    if n != negative {
                        Num::MINUS_ONE
                    } else {
                        Num::ONE
                    },
                )
            })
            .collect();
        let (sum, _) = self.signed_sum(&inner, Num::ZERO, false);
        let mut lit = self.literal(magnitude);
        lit.extend(quote!(*));
        lit.extend(parenthesized(sum));
        (negative, lit)
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

#[cfg(test)]
mod tests {
    use super::super::Body;
    use crate::expr::num::Num;
    use crate::expr::Sym;
    use crate::tools::fixtures::planar_chain;
    use crate::{analyse_with, Options};

    /// `2.5·x − 2.5·y + 3·x·y − 3·y² + 7·x²`: a large body writes each
    /// shared magnitude once and keeps the lone `7` where it is; a small
    /// one (or one kept apart) writes every term with its own, as before.
    /// A group whose terms are all negative is subtracted whole. This pins
    /// the form; the values of a body large enough to group (the
    /// quadruped's `tangent_rhs`) are checked against the runtime's dense
    /// solve and central differences in `tests/velocity_jacobians.rs`.
    #[test]
    fn a_large_body_writes_each_shared_magnitude_once() {
        let tokens = planar_chain("Chain", 2)
            .parse()
            .expect("the fixture is tokens");
        let mut eq = analyse_with(tokens, Options { jacobians: false }).expect("it analyses");
        let g = &mut eq.system.graph;
        let (x, y) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let (xy, yy, xx) = (g.mul2(x, y), g.mul2(y, y), g.mul2(x, x));
        let half = Num::ratio(5, 2);
        let sum = g.linear_combination([
            (x, half),
            (y, -half),
            (xy, Num::int(3)),
            (yy, Num::int(-3)),
            (xx, Num::int(7)),
        ]);
        let negative = g.linear_combination([(x, -half), (y, -half), (xx, Num::int(7))]);
        let text = |body: &Body| body.expr(sum).to_string().replace(' ', "");
        let apart = text(&Body::new(&eq, &[sum]));
        assert_eq!(
            apart,
            "2.5f64*x1-2.5f64*y1+7f64*(x1*x1)-3f64*(y1*y1)+3f64*(x1*y1)"
        );
        let mut large = Body::new(&eq, &[sum]);
        large.shares_magnitudes = true;
        assert_eq!(
            text(&large),
            "7f64*(x1*x1)+2.5f64*(x1-y1)+3f64*(x1*y1-y1*y1)"
        );
        let negative_text = large.expr(negative).to_string().replace(' ', "");
        assert_eq!(negative_text, "7f64*(x1*x1)-2.5f64*(x1+y1)");
        assert_eq!(text(&large.magnitudes_apart()), apart);
    }
}
