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
