//! Common factors pulled out of sums, for the reviewer and the CPU alike:
//! `α·y·ẋ + α·x·ẏ + α·cos t` becomes `α·(y·ẋ + x·ẏ + cos t)` (one
//! multiplication by α, not three), and
//! `−2·ẋ₁·(ẋ₁ − ẋ₂) + 2·ẋ₂·(ẋ₁ − ẋ₂)` becomes `−2·(ẋ₁ − ẋ₂)²`: once
//! `ẋ₁ − ẋ₂` is pulled out, the cofactor `−2·ẋ₁ + 2·ẋ₂` is the same sum
//! up to its content, and the product constructor, which keeps sums
//! primitive, merges the two into a square.
//!
//! The rule is greedy, Horner's rule in several variables: in a sum, the
//! base that occurs in the most terms (two at least; with the smaller
//! power where the powers differ) is pulled out of those terms, their
//! cofactors are factored in turn, and the sum is searched again. Every
//! round merges at least two terms into one, so a sum of T terms takes at
//! most T − 1 rounds. Values are unchanged; only the order of operations
//! (and with it the rounding) moves.
//!
//! Factoring runs once, on the pieces the later stages print and emit (M,
//! F, A, b, and the Gauss pieces built from them), and only near their
//! surface: the sums among the top four levels of sums and products of
//! each root. Deeper nodes are shared with other roots and with named
//! definitions, and rebuilding them would duplicate them (see
//! [`Factorer`]); the bounded depth also bounds the recursion.

use crate::expr::num::Num;
use crate::expr::{FastHash, Graph, Id, Node};
use std::collections::{HashMap, HashSet};

/// Sums with more terms than this are left as they are: the search is
/// quadratic in the terms, and sums that long come from expansions nobody
/// reads (the 32-link chain's longest sum of interest has 8 terms).
const MAX_TERMS: usize = 48;

/// How many levels of sums and products below a root are factored.
const SURFACE_DEPTH: usize = 4;

/// A memo of factored nodes over one graph: each is factored once per
/// depth, however many of the Gauss pieces reach it.
#[derive(Default)]
pub struct Factorer {
    /// Each node factored to a depth (a root's is [`SURFACE_DEPTH`]): the
    /// same node under many roots, or many times under one, is factored
    /// once per depth. Nodes are interned, so a second factoring would
    /// build the same node.
    done: HashMap<(Id, usize), Id, FastHash>,
    /// Nodes kept whole: the user's named definitions, which the derivation
    /// prints by name only while their node is unchanged.
    atoms: HashSet<Id>,
}

impl Factorer {
    /// A factorer with nothing factored yet.
    pub fn new() -> Self {
        Factorer::default()
    }

    /// A factorer that keeps `atoms` whole: neither factored inside nor
    /// split into their factors.
    pub fn keeping(atoms: impl IntoIterator<Item = Id>) -> Self {
        Factorer {
            done: HashMap::default(),
            atoms: atoms.into_iter().collect(),
        }
    }

    /// Whether `id` is kept whole (a named definition).
    pub fn keeps(&self, id: Id) -> bool {
        self.atoms.contains(&id)
    }

    /// `root` with the sums near its surface factored (module docs).
    pub fn factor(&mut self, g: &mut Graph, root: Id) -> Id {
        self.factor_within(g, root, SURFACE_DEPTH)
    }

    /// `id` with the sums in its top `levels` levels of sums and products
    /// factored. Deeper nodes (and everything under a function) keep their
    /// `Id`: rebuilding the whole DAG under every root would duplicate the
    /// parts that other roots and named definitions share, and the text
    /// and the code would grow instead of shrinking (factoring every sum
    /// makes a 1,040-definition model's derivation two thirds larger).
    fn factor_within(&mut self, g: &mut Graph, id: Id, levels: usize) -> Id {
        if levels == 0 || self.atoms.contains(&id) {
            return id;
        }
        if let Some(&done) = self.done.get(&(id, levels)) {
            return done;
        }
        let factored = match g.node(id).clone() {
            Node::Add(terms, c0) => {
                let terms: Vec<(Id, Num)> = terms
                    .iter()
                    .map(|&(t, c)| (self.factor_within(g, t, levels - 1), c))
                    .collect();
                if terms.len() >= 2 && terms.len() <= MAX_TERMS {
                    factor_sum(g, &self.atoms, terms, c0)
                } else {
                    let constant = g.num(c0);
                    g.linear_combination(terms.into_iter().chain([(constant, Num::ONE)]))
                }
            }
            Node::Mul(factors) => {
                let factors: Vec<(Id, Num)> = factors
                    .iter()
                    .map(|&(b, e)| (self.factor_within(g, b, levels - 1), e))
                    .collect();
                g.product(factors)
            }
            _ => id,
        };
        // Memoized with its depth: at another depth it may be factored
        // further.
        self.done.insert((id, levels), factored);
        factored
    }

    /// Every entry of `ids` factored.
    pub fn factor_all(&mut self, g: &mut Graph, ids: &[Id]) -> Vec<Id> {
        ids.iter().map(|&id| self.factor(g, id)).collect()
    }

    /// Every entry of a matrix factored.
    pub fn factor_rows(&mut self, g: &mut Graph, rows: &[Vec<Id>]) -> Vec<Vec<Id>> {
        rows.iter().map(|row| self.factor_all(g, row)).collect()
    }
}

/// The factors of a term as `(base, exponent)`: a product's own, anything
/// else (and an atom) is itself to the first power.
fn factors_of(g: &Graph, atoms: &HashSet<Id>, term: Id) -> Vec<(Id, Num)> {
    match g.node(term) {
        Node::Mul(factors) if !atoms.contains(&term) => factors.to_vec(),
        _ => vec![(term, Num::ONE)],
    }
}

/// The power of `base` common to the terms containing it with exponents of
/// one sign (the smaller magnitude), and which terms those are.
fn shared_power(per_term: &[Vec<(Id, Num)>], base: Id, positive: bool) -> (Num, Vec<usize>) {
    let mut power: Option<Num> = None;
    let mut members = Vec::new();
    for (i, factors) in per_term.iter().enumerate() {
        let Some(&(_, e)) = factors
            .iter()
            .find(|&&(b, e)| b == base && e.is_negative() != positive)
        else {
            continue;
        };
        if !matches!(e, Num::Rational(..)) {
            continue;
        }
        members.push(i);
        power = Some(match power {
            Some(p) if p.to_f64().abs() <= e.to_f64().abs() => p,
            _ => e,
        });
    }
    (power.unwrap_or(Num::ZERO), members)
}

/// `Σ cᵢ·tᵢ + c₀` with common factors pulled out greedily (module docs).
fn factor_sum(g: &mut Graph, atoms: &HashSet<Id>, terms: Vec<(Id, Num)>, c0: Num) -> Id {
    factor_sum_within(g, atoms, terms, c0, MAX_DEPTH)
}

/// How deeply cofactors are factored in their turn (a backstop: each level
/// removes a factor from every term, so real sums stop far earlier).
const MAX_DEPTH: usize = 16;

/// The exponent of `base` in the factors of a term (zero when absent).
fn exponent_of(factors: &[(Id, Num)], base: Id) -> Num {
    factors
        .iter()
        .find(|&&(b, _)| b == base)
        .map_or(Num::ZERO, |&(_, e)| e)
}

fn factor_sum_within(
    g: &mut Graph,
    atoms: &HashSet<Id>,
    mut terms: Vec<(Id, Num)>,
    c0: Num,
    depth: usize,
) -> Id {
    // Bases that could not be divided out exactly (a product of more than
    // eight factors stays one base of the quotient, see `expr::build`):
    // not tried again in this sum.
    let mut refused: HashSet<(Id, bool)> = HashSet::new();
    // At most `terms.len() − 1` merging rounds, plus one per refused base.
    let mut rounds = 2 * terms.len();
    while depth > 0 && terms.len() >= 2 && rounds > 0 {
        rounds -= 1;
        let per_term: Vec<Vec<(Id, Num)>> = terms
            .iter()
            .map(|&(t, _)| factors_of(g, atoms, t))
            .collect();
        let Some((base, positive)) = most_shared_base(g, &per_term, &refused) else {
            break;
        };
        let (power, members) = shared_power(&per_term, base, positive);
        // Σ over the members of cᵢ·tᵢ/base^power, factored in its turn.
        let cofactors: Vec<(Id, Num)> = members
            .iter()
            .map(|&i| {
                let (t, c) = terms[i];
                (g.product([(t, Num::ONE), (base, -power)]), c)
            })
            .collect();
        // The division must have taken `base^power` out of every member;
        // otherwise the cofactors still hold it and factoring them again
        // would not end.
        let exact = members.iter().zip(&cofactors).all(|(&i, &(q, _))| {
            let before = exponent_of(&per_term[i], base);
            exponent_of(&factors_of(g, atoms, q), base) == before + -power
        });
        if !exact {
            refused.insert((base, positive));
            continue;
        }
        let inner = factor_sum_within(g, atoms, cofactors, Num::ZERO, depth - 1);
        let grouped = g.product([(base, power), (inner, Num::ONE)]);
        terms = members_replaced(g, &terms, &members, grouped);
    }
    let constant = g.num(c0);
    terms.push((constant, Num::ONE));
    g.linear_combination(terms)
}

/// The base (with the sign of its exponent) among the factors of the most
/// terms, at least two, that has not been `refused`; ties go to the smaller
/// `Id` (the older, usually simpler, node). Only bases under a rational
/// exponent count, and no number.
fn most_shared_base(
    g: &Graph,
    per_term: &[Vec<(Id, Num)>],
    refused: &HashSet<(Id, bool)>,
) -> Option<(Id, bool)> {
    let mut counts: HashMap<(Id, bool), usize> = HashMap::new();
    for factors in per_term {
        for &(b, e) in factors {
            if matches!(e, Num::Rational(..)) && !matches!(g.node(b), Node::Num(_)) {
                *counts.entry((b, !e.is_negative())).or_default() += 1;
            }
        }
    }
    counts
        .into_iter()
        .filter(|&(key, c)| c >= 2 && !refused.contains(&key))
        .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)))
        .map(|(key, _)| key)
}

/// `terms` with the `members` (indices) replaced by the one term `grouped`,
/// which is their sum factored. `grouped` may come back as `c·product` (a
/// one-term sum): its coefficient stays in the term, as
/// `linear_combination` would keep it.
fn members_replaced(
    g: &Graph,
    terms: &[(Id, Num)],
    members: &[usize],
    grouped: Id,
) -> Vec<(Id, Num)> {
    let mut rest: Vec<(Id, Num)> = terms
        .iter()
        .enumerate()
        .filter(|(i, _)| !members.contains(i))
        .map(|(_, &item)| item)
        .collect();
    match g.node(grouped) {
        Node::Add(inner_terms, k) if k.is_zero() && inner_terms.len() == 1 => {
            rest.push(inner_terms[0]);
        }
        _ => rest.push((grouped, Num::ONE)),
    }
    rest
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::sample as value;
    use crate::expr::{Func, Sym};

    #[test]
    fn a_common_factor_is_pulled_out_once() {
        // α·y·ẋ + α·x·ẏ + α·cos t → α·(y·ẋ + x·ẏ + cos t)
        let mut g = Graph::new();
        let (x, y, xd, yd, t, alpha) = (
            g.sym(Sym::Coord(0)),
            g.sym(Sym::Coord(1)),
            g.sym(Sym::Vel(0)),
            g.sym(Sym::Vel(1)),
            g.sym(Sym::Time),
            g.sym(Sym::Param(0)),
        );
        let cos = g.func(Func::Cos, t);
        let terms = [
            g.mul(&[alpha, y, xd]),
            g.mul(&[alpha, x, yd]),
            g.mul2(alpha, cos),
        ];
        let b = g.add(&terms);
        let f = Factorer::new().factor(&mut g, b);
        let Node::Mul(factors) = g.node(f) else {
            panic!("not a product: {:?}", g.node(f));
        };
        assert_eq!(factors.len(), 2);
        assert!(factors.contains(&(alpha, Num::ONE)));
        assert!((value(&g, f) - value(&g, b)).abs() < 1e-15);
    }

    #[test]
    fn a_difference_times_its_negative_becomes_a_square() {
        // −2·ẋ₁·(ẋ₁ − ẋ₂) + 2·ẋ₂·(ẋ₁ − ẋ₂) → −2·(ẋ₁ − ẋ₂)²
        let mut g = Graph::new();
        let (v1, v2) = (g.sym(Sym::Vel(0)), g.sym(Sym::Vel(1)));
        let d = g.sub(v1, v2);
        let (p, q) = (g.mul2(v1, d), g.mul2(v2, d));
        let b = g.linear_combination([(p, Num::int(-2)), (q, Num::int(2))]);
        let f = Factorer::new().factor(&mut g, b);
        let square = g.pown(d, Num::int(2));
        assert_eq!(f, g.scale(square, Num::int(-2)));
        assert!((value(&g, f) - value(&g, b)).abs() < 1e-15);
    }

    #[test]
    fn sums_without_shared_factors_are_unchanged() {
        let mut g = Graph::new();
        let (x, y) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let (sx, cy) = (g.func(Func::Sin, x), g.func(Func::Cos, y));
        let s = g.add(&[sx, cy, x]);
        assert_eq!(Factorer::new().factor(&mut g, s), s);
    }
}
