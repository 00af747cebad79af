//! Common-subexpression scheduling for straight-line code.
//!
//! The DAG already shares every repeated subexpression (hash-consing); what is
//! left is to decide which shared nodes get a `let` and in which order. A node
//! becomes a temporary when it is used more than once among the outputs'
//! subgraph (or by a power emitted as repeated multiplication); everything
//! else is inlined into its single user. Temporaries come in arena order,
//! which is topological, so the output is deterministic and every temporary
//! is defined before its first use.
//!
//! A sine and a cosine of the same argument are both temporaries and are
//! written as one `sin_cos()` ([`Schedule::sin_cos`]): one argument
//! reduction instead of two (libm's `sincos` in `no_std`; with `std`,
//! LLVM joins the two calls into the C library's `sincos` either way).

use crate::expr::{Func, Graph, Id, Node};
use std::collections::HashMap;

/// Powers up to this integer exponent are emitted as repeated multiplication
/// (`x * x * x`), which is faster than `powi` and exact.
pub const MAX_UNROLLED_POWER: i64 = 4;

/// Which nodes of an output set are bound to temporaries, in emission order.
pub struct Schedule {
    /// Nodes that get a `let`, in topological order.
    pub temporaries: Vec<Id>,
    /// The temporaries that are a sine and a cosine of one argument, to be
    /// bound together by one `a.sin_cos()` where the first of the two is
    /// scheduled.
    pub paired: HashMap<Id, Paired>,
}

/// A temporary's part in a `(sin a, cos a)` pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Paired {
    /// Scheduled first: both are bound here.
    First { sin: Id, cos: Id, argument: Id },
    /// Scheduled second: already bound.
    Later,
}

impl Schedule {
    /// Schedules the nodes reachable from `roots`.
    pub fn new(g: &Graph, roots: &[Id]) -> Schedule {
        let reachable = g.reachable(roots);
        let mut uses = vec![0usize; g.len()];
        for &r in roots {
            uses[r.index()] += 1;
        }
        for &id in &reachable {
            if let Node::Mul(factors) = g.node(id) {
                for (base, e) in factors.iter() {
                    let copies = e
                        .as_integer()
                        .map(i64::unsigned_abs)
                        .filter(|&k| k <= MAX_UNROLLED_POWER as u64)
                        .unwrap_or(1);
                    uses[base.index()] += copies as usize;
                }
            } else {
                for c in g.children(id) {
                    uses[c.index()] += 1;
                }
            }
        }
        let sin_cos = sine_cosine_pairs(g, &reachable);
        for &(s, c) in &sin_cos {
            uses[s.index()] = uses[s.index()].max(2);
            uses[c.index()] = uses[c.index()].max(2);
        }
        let temporaries: Vec<Id> = reachable
            .into_iter()
            .filter(|&id| {
                let leaf = matches!(g.node(id), Node::Num(_) | Node::Sym(_));
                !leaf && uses[id.index()] > 1
            })
            .collect();
        let paired = pair_positions(g, &temporaries, &sin_cos);
        Schedule {
            temporaries,
            paired,
        }
    }

    /// The same temporaries in the order the outputs `roots` ask for them,
    /// in the order given: each root's temporaries depth-first, operands
    /// in arena order, so that a value is computed just before the first
    /// output that needs it. Where each output is written out as soon as
    /// it is known (`emit::body`'s stores), a value's registers are then
    /// free soon after it is computed.
    pub fn in_demand_order(g: &Graph, roots: &[Id]) -> Schedule {
        let arena = Schedule::new(g, roots);
        let mut is_temporary = vec![false; g.len()];
        for &t in &arena.temporaries {
            is_temporary[t.index()] = true;
        }
        let mut seen = vec![false; g.len()];
        let mut temporaries = Vec::with_capacity(arena.temporaries.len());
        // Post-order without recursion (a chain's graph is deep): each
        // node is pushed once to expand, once more to emit.
        let mut stack: Vec<(Id, bool)> = Vec::new();
        for &root in roots {
            stack.push((root, false));
            while let Some((id, expanded)) = stack.pop() {
                if expanded {
                    if is_temporary[id.index()] {
                        temporaries.push(id);
                    }
                    continue;
                }
                if std::mem::replace(&mut seen[id.index()], true) {
                    continue;
                }
                stack.push((id, true));
                let mut children: Vec<Id> = g.children(id).collect();
                children.sort_unstable();
                // Reversed onto the stack: the first operand is expanded first.
                stack.extend(children.into_iter().rev().map(|c| (c, false)));
            }
        }
        // The arena order's pairs, placed again in this order.
        let sin_cos: Vec<(Id, Id)> = arena
            .paired
            .values()
            .filter_map(|p| match *p {
                Paired::First { sin, cos, .. } => Some((sin, cos)),
                Paired::Later => None,
            })
            .collect();
        let paired = pair_positions(g, &temporaries, &sin_cos);
        Schedule {
            temporaries,
            paired,
        }
    }
}

/// Each pair's first temporary (in `temporaries`' order) and its second.
fn pair_positions(g: &Graph, temporaries: &[Id], pairs: &[(Id, Id)]) -> HashMap<Id, Paired> {
    let position: HashMap<Id, usize> = temporaries
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect();
    let mut out = HashMap::new();
    for &(sin, cos) in pairs {
        let (Node::Func(_, args), Some(ps), Some(pc)) =
            (g.node(sin), position.get(&sin), position.get(&cos))
        else {
            continue;
        };
        let argument = args.as_slice()[0];
        let (first, later) = if ps < pc { (sin, cos) } else { (cos, sin) };
        out.insert(first, Paired::First { sin, cos, argument });
        out.insert(later, Paired::Later);
    }
    out
}

/// The `(sin a, cos a)` pairs among `nodes`, in the order of their sines.
fn sine_cosine_pairs(g: &Graph, nodes: &[Id]) -> Vec<(Id, Id)> {
    let mut cosines: HashMap<Id, Id> = HashMap::new();
    for &id in nodes {
        if let Node::Func(Func::Cos, args) = g.node(id) {
            cosines.insert(args.as_slice()[0], id);
        }
    }
    nodes
        .iter()
        .filter_map(|&id| match g.node(id) {
            Node::Func(Func::Sin, args) => cosines.get(&args.as_slice()[0]).map(|&c| (id, c)),
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::Schedule;
    use crate::expr::{Graph, Id, Sym};

    /// Two outputs whose temporaries were built in the other order: in
    /// demand order each output's come right before it, the first
    /// output's first; the set is the arena order's, and every temporary
    /// still follows its operands.
    #[test]
    fn demand_order_puts_each_outputs_temporaries_before_the_next_outputs() {
        let mut g = Graph::new();
        let (x, y) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        // Built first, read by the second output only.
        let late = g.add2(y, x);
        let late_sq = g.mul2(late, late);
        // Built second, read by the first output only.
        let s = g.sub(x, y);
        let s_sq = g.mul2(s, s);
        let first = g.mul2(s_sq, s);
        let second = g.mul2(late_sq, late);
        let roots = [first, second];
        let arena = Schedule::new(&g, &roots);
        let demand = Schedule::in_demand_order(&g, &roots);
        let sorted = |mut v: Vec<Id>| {
            v.sort_unstable();
            v
        };
        assert_eq!(
            sorted(arena.temporaries.clone()),
            sorted(demand.temporaries.clone())
        );
        assert_eq!(arena.temporaries, vec![late, s]);
        assert_eq!(demand.temporaries, vec![s, late]);
        for (i, &t) in demand.temporaries.iter().enumerate() {
            for c in g.children(t) {
                if let Some(j) = demand.temporaries.iter().position(|&u| u == c) {
                    assert!(j < i, "{c:?} after {t:?}");
                }
            }
        }
    }
}
