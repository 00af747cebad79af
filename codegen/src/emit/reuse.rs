//! Products that reuse an earlier temporary product: `t·λ/m` written as
//! `__t3/m` where `__t3 = t·λ` is bound before it. Each body keeps its
//! temporary products indexed by their first factor, so that a product's
//! candidates are found through its own factors rather than by scanning
//! every temporary product (a scan quadratic in a large body's
//! products).

use crate::expr::cse::Schedule;
use crate::expr::num::Num;
use crate::expr::{FastHash, Graph, Id, Node};
use std::collections::HashMap;

/// A body's temporaries that are products of two or more factors.
pub(super) struct TempProducts {
    /// Each product with its position in the schedule.
    products: Vec<(usize, Id)>,
    /// For each base, the indices in `products` of the products whose first
    /// factor it is, in position order.
    by_first: HashMap<Id, Vec<usize>, FastHash>,
}

impl TempProducts {
    /// The temporary products of `schedule`.
    pub(super) fn new(g: &Graph, schedule: &Schedule) -> TempProducts {
        let products: Vec<(usize, Id)> = schedule
            .temporaries
            .iter()
            .enumerate()
            .filter(|(_, &id)| matches!(g.node(id), Node::Mul(f) if f.len() > 1))
            .map(|(i, &id)| (i, id))
            .collect();
        let mut by_first: HashMap<Id, Vec<usize>, FastHash> = HashMap::default();
        for (k, &(_, id)) in products.iter().enumerate() {
            if let Node::Mul(factors) = g.node(id) {
                if let Some(&(first, _)) = factors.first() {
                    by_first.entry(first).or_default().push(k);
                }
            }
        }
        TempProducts { products, by_first }
    }

    /// The largest temporary product before position `limit` whose factors
    /// are a proper subset of `factors` (exponents equal, the `negated`
    /// one excluded), the earliest among equals, with the positions in
    /// `factors` it covers.
    pub(super) fn reusable(
        &self,
        g: &Graph,
        factors: &[(Id, Num)],
        (negated, limit): (Option<usize>, usize),
    ) -> Option<(Id, Vec<usize>)> {
        let at = |f: &(Id, Num)| {
            factors
                .iter()
                .position(|h| h == f)
                .filter(|&i| negated != Some(i))
        };
        // (number of factors, position, product) of the best so far.
        let mut best: Option<(usize, usize, Id)> = None;
        let candidates = factors
            .iter()
            .filter_map(|(b, _)| self.by_first.get(b))
            .flatten();
        for &k in candidates {
            let (position, p) = self.products[k];
            let Node::Mul(inner) = g.node(p) else {
                continue;
            };
            let better = best.is_none_or(|(size, first, _)| {
                inner.len() > size || (inner.len() == size && position < first)
            });
            if position >= limit || inner.len() >= factors.len() || !better {
                continue;
            }
            if inner.iter().all(|f| at(f).is_some()) {
                best = Some((inner.len(), position, p));
            }
        }
        let (_, _, p) = best?;
        let Node::Mul(inner) = g.node(p) else {
            return None;
        };
        Some((p, inner.iter().filter_map(at).collect()))
    }
}
