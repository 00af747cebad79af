//! Sub-products shared by several products, computed once.
//!
//! Canonical products are flat (`m·l·cos θ`, `m·l²`, `m·l·θ̇²·sin θ`), so
//! the DAG cannot share `m·l` between them; the emitter does. Over every
//! product a body writes, the pair of qualifying factors that occurs in the
//! most products (two at least) becomes a local `__sp{i} = a * b`; the pair
//! is replaced by it wherever it occurs, and the search repeats, so a pair can grow into a longer sub-product
//! (`(m·l)·g`). Each product of `k` uses saves `k − 1` multiplications;
//! this is the greedy pair extraction of multiplier-block synthesis.
//!
//! Variables qualify (coordinates, velocities, parameters, time, to a small
//! positive integer power), and so do temporaries that do not wait for the
//! multipliers λ (`sin θ` bound once): a sub-product is bound right after
//! the last of its factors, which every product holding it comes after.

use crate::expr::cse::MAX_UNROLLED_POWER;
use crate::expr::num::Num;
use crate::expr::{Graph, Id, Node, Sym};
use std::collections::{BTreeMap, HashMap};

/// How many pairs are extracted at most per body (each round removes at
/// least two factors from the products, so real bodies stop far sooner).
const MAX_ROUNDS: usize = 64;

/// A factor of a product: a variable, or an earlier sub-product.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) enum Factor {
    /// A variable, or a temporary that qualifies (module docs).
    Leaf(Id),
    /// Sub-product `i`.
    Shared(usize),
}

/// A product's qualifying factors with their multiplicities.
pub(super) type Multiset = BTreeMap<Factor, u32>;

/// The sub-products of one body, in the order they were found (each made
/// of qualifying factors and earlier sub-products).
#[derive(Default)]
pub(super) struct SubProducts {
    pub(super) pairs: Vec<(Factor, Factor)>,
    /// Per sub-product, the position (in the body's schedule) of the
    /// temporary it is bound right after; `None` for one of variables
    /// only, bound in the preamble.
    pub(super) after: Vec<Option<usize>>,
    /// The temporaries that may be factors (by arena index).
    shareable: Vec<bool>,
}

impl SubProducts {
    /// The sub-products of a body that writes `products`, whose temporaries
    /// are `temporaries` (in schedule order), of which those where
    /// `shareable` holds may be factors; with where each is bound.
    pub(super) fn plan(
        g: &Graph,
        products: &[Id],
        temporaries: &[Id],
        shareable: &dyn Fn(Id) -> bool,
    ) -> SubProducts {
        let mut marked = vec![false; g.len()];
        let mut position: HashMap<Id, usize> = HashMap::new();
        for (i, &id) in temporaries.iter().enumerate() {
            marked[id.index()] = shareable(id);
            position.insert(id, i);
        }
        let mut plan = SubProducts::find(g, products, &|id| marked[id.index()]);
        for &(a, b) in &plan.pairs {
            let after = |f: Factor| match f {
                Factor::Leaf(id) => position.get(&id).copied(),
                Factor::Shared(j) => plan.after[j],
            };
            let at = after(a).max(after(b));
            plan.after.push(at);
        }
        plan.shareable = marked;
        plan
    }

    /// Whether `id` may be a factor of a sub-product besides a variable.
    pub(super) fn shareable(&self, id: Id) -> bool {
        self.shareable.get(id.index()).copied().unwrap_or(false)
    }

    /// The shared pairs among the products `products` (their nodes), whose
    /// factors qualify where they are variables or where `bound` holds.
    fn find(g: &Graph, products: &[Id], bound: &dyn Fn(Id) -> bool) -> SubProducts {
        let mut sets: Vec<Multiset> = products
            .iter()
            .map(|&p| match g.node(p) {
                Node::Mul(factors) => qualifying(g, factors.iter().copied(), bound),
                _ => Multiset::new(),
            })
            .filter(|set| set.values().sum::<u32>() >= 2)
            .collect();
        // Pair counts are kept up to date as sets change rather than
        // recounted every round: recounting is quadratic in the rounds, a
        // large share of a big model's expansion.
        let mut counts: HashMap<(Factor, Factor), usize> = HashMap::new();
        for set in &sets {
            count_pairs(set, &mut counts, true);
        }
        let mut found = SubProducts::default();
        for _ in 0..MAX_ROUNDS {
            // The most frequent pair; the first in key order among equals.
            let best = counts
                .iter()
                .filter(|&(_, &c)| c >= 2)
                .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0)))
                .map(|(&pair, _)| pair);
            let Some(pair) = best else {
                break;
            };
            let shared = Factor::Shared(found.pairs.len());
            found.pairs.push(pair);
            for set in &mut sets {
                if !set.contains_key(&pair.0) || !set.contains_key(&pair.1) {
                    continue;
                }
                count_pairs(set, &mut counts, false);
                replace(set, pair, shared);
                count_pairs(set, &mut counts, true);
            }
        }
        found
    }

    /// `set` with every sub-product substituted, in the order found (which
    /// reproduces the search's own substitutions).
    pub(super) fn apply(&self, mut set: Multiset) -> Multiset {
        for (i, &pair) in self.pairs.iter().enumerate() {
            // A pair takes two factors: fewer left, none can match.
            if set.values().sum::<u32>() < 2 {
                break;
            }
            if !set.contains_key(&pair.0) {
                continue;
            }
            replace(&mut set, pair, Factor::Shared(i));
        }
        set
    }
}

/// The factors of a product that qualify (module docs), as a multiset:
/// variables, and the bases for which `bound` holds.
pub(super) fn qualifying(
    g: &Graph,
    factors: impl Iterator<Item = (Id, Num)>,
    bound: &dyn Fn(Id) -> bool,
) -> Multiset {
    let mut set = Multiset::new();
    for (b, e) in factors {
        if let Some(k) = qualifies(g, b, e, bound) {
            *set.entry(Factor::Leaf(b)).or_default() += k;
        }
    }
    set
}

/// The multiplicity of the factor `b^e` in a sub-product, where it
/// qualifies: a variable or a base for which `bound` holds, to a small
/// positive integer power.
pub(super) fn qualifies(g: &Graph, b: Id, e: Num, bound: &dyn Fn(Id) -> bool) -> Option<u32> {
    let variable = bound(b)
        || matches!(
            g.node(b),
            Node::Sym(Sym::Coord(_) | Sym::Vel(_) | Sym::Param(_) | Sym::Time)
        );
    let k = e
        .as_integer()
        .filter(|k| (1..=MAX_UNROLLED_POWER).contains(k))?;
    variable.then_some(k as u32)
}

/// Adds (or removes) the pairs of factors of `set` to (from) `counts`: every
/// two distinct factors, and a factor with itself where its power is two or
/// more.
fn count_pairs(set: &Multiset, counts: &mut HashMap<(Factor, Factor), usize>, add: bool) {
    for (i, (&a, &ea)) in set.iter().enumerate() {
        let pairs = (ea >= 2)
            .then_some((a, a))
            .into_iter()
            .chain(set.keys().skip(i + 1).map(|&b| (a, b)));
        for pair in pairs {
            let count = counts.entry(pair).or_default();
            if add {
                *count += 1;
            } else {
                *count = count.saturating_sub(1);
            }
        }
    }
}

/// Replaces `pair` in `set` by `shared` as often as it occurs.
fn replace(set: &mut Multiset, (a, b): (Factor, Factor), shared: Factor) {
    let (ea, eb) = (
        set.get(&a).copied().unwrap_or(0),
        set.get(&b).copied().unwrap_or(0),
    );
    let times = if a == b { ea / 2 } else { ea.min(eb) };
    if times == 0 {
        return;
    }
    for (f, by) in [(a, times), (b, times)] {
        if let Some(e) = set.get_mut(&f) {
            *e -= by;
            if *e == 0 {
                set.remove(&f);
            }
        }
    }
    *set.entry(shared).or_default() += times;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::num::Num;

    #[test]
    fn a_pair_in_four_products_is_shared_and_grows() {
        // m·l·c, m·l², m·l·g·s, m·l·g·w: m·l in four, then (m·l)·g in two.
        let mut g = Graph::new();
        let (m, l, gr) = (
            g.sym(Sym::Param(0)),
            g.sym(Sym::Param(1)),
            g.sym(Sym::Param(2)),
        );
        let (c, s, w) = (
            g.sym(Sym::Coord(0)),
            g.sym(Sym::Coord(1)),
            g.sym(Sym::Vel(0)),
        );
        let l2 = g.pown(l, Num::int(2));
        let products = [
            g.mul(&[m, l, c]),
            g.mul(&[m, l2]),
            g.mul(&[m, l, gr, s]),
            g.mul(&[m, l, gr, w]),
        ];
        let found = SubProducts::find(&g, &products, &|_| false);
        assert_eq!(
            found.pairs,
            vec![
                (Factor::Leaf(m), Factor::Leaf(l)),
                (Factor::Leaf(gr), Factor::Shared(0)),
            ]
        );
        let Node::Mul(f) = g.node(products[1]).clone() else {
            panic!("a product");
        };
        let applied = found.apply(qualifying(&g, f.iter().copied(), &|_| false));
        assert_eq!(
            applied,
            Multiset::from([(Factor::Leaf(l), 1), (Factor::Shared(0), 1)])
        );
    }

    #[test]
    fn a_pair_in_one_product_is_not_shared() {
        let mut g = Graph::new();
        let (a, b, c) = (
            g.sym(Sym::Param(0)),
            g.sym(Sym::Param(1)),
            g.sym(Sym::Param(2)),
        );
        let products = [g.mul(&[a, b]), g.mul(&[b, c])];
        assert!(SubProducts::find(&g, &products, &|_| false)
            .pairs
            .is_empty());
    }
}
