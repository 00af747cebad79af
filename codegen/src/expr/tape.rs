//! Expressions compiled once for evaluation in `f64` at many points.
//!
//! Stage 3 evaluates the same expressions (the rows of `A`, `φ`, `φ̇`) at
//! hundreds of states while it projects sample states onto the constraints
//! and measures the rank. Walking the graph for every state found the same
//! nodes each time, converted the same rational constants to `f64`, and
//! looked each operand up in a hash map. A [`Tape`] does that once: the
//! nodes the roots reach, in arena (topological) order, each operand
//! replaced by its slot on the tape and each constant by its `f64`.
//! Evaluation is then one pass over a vector, with the same arithmetic in
//! the same order as [`Node::value`], so the values are the same bits.

use super::num::Num;
use super::{power, Func, Graph, Id, Node, Sym};
use std::ops::Range;

/// One node of a [`Tape`], its operands as slots of the tape.
#[derive(Clone, Debug)]
enum Step {
    Constant(f64),
    Variable(Sym),
    /// `c₀ + Σ cᵢ·xᵢ`, the terms at `terms[range]`.
    Sum(Range<usize>, f64),
    /// `Π xᵢ^eᵢ`, the factors at `factors[range]`.
    Product(Range<usize>),
    Power(usize, usize),
    Function(Func, [usize; 2]),
}

/// Roots compiled for repeated evaluation (module docs).
#[derive(Clone, Debug)]
pub struct Tape {
    steps: Vec<Step>,
    terms: Vec<(usize, f64)>,
    factors: Vec<(usize, Num)>,
    roots: Vec<usize>,
}

impl Graph {
    /// `roots` compiled into a [`Tape`].
    pub fn tape(&self, roots: &[Id]) -> Tape {
        let order = self.reachable(roots);
        // `order` is sorted by id, so an operand's slot is its rank there;
        // every operand of a reached node is reached, so the search finds it.
        let slot = |id: Id| match order.binary_search(&id) {
            Ok(i) | Err(i) => i,
        };
        let mut tape = Tape {
            steps: Vec::with_capacity(order.len()),
            terms: Vec::new(),
            factors: Vec::new(),
            roots: roots.iter().map(|&r| slot(r)).collect(),
        };
        for &id in &order {
            let step = match self.node(id) {
                Node::Num(n) => Step::Constant(n.to_f64()),
                Node::Sym(s) => Step::Variable(*s),
                Node::Add(terms, c0) => {
                    let start = tape.terms.len();
                    tape.terms
                        .extend(terms.iter().map(|&(t, c)| (slot(t), c.to_f64())));
                    Step::Sum(start..tape.terms.len(), c0.to_f64())
                }
                Node::Mul(factors) => {
                    let start = tape.factors.len();
                    tape.factors
                        .extend(factors.iter().map(|&(b, e)| (slot(b), e)));
                    Step::Product(start..tape.factors.len())
                }
                Node::Pow([b, e]) => Step::Power(slot(*b), slot(*e)),
                Node::Func(f, args) => {
                    let mut operands = [0; 2];
                    for (o, &a) in operands.iter_mut().zip(args.as_slice()) {
                        *o = slot(a);
                    }
                    Step::Function(*f, operands)
                }
            };
            tape.steps.push(step);
        }
        tape
    }
}

impl Tape {
    /// The roots' values with the variables given by `env`.
    pub fn eval(&self, env: &dyn Fn(Sym) -> f64) -> Vec<f64> {
        let mut value: Vec<f64> = Vec::with_capacity(self.steps.len());
        for step in &self.steps {
            let v = match step {
                Step::Constant(c) => *c,
                Step::Variable(s) => env(*s),
                Step::Sum(range, c0) => self.terms[range.clone()]
                    .iter()
                    .fold(*c0, |acc, &(t, c)| acc + c * value[t]),
                Step::Product(range) => self.factors[range.clone()]
                    .iter()
                    .fold(1.0, |acc, &(b, e)| acc * power(value[b], e)),
                Step::Power(b, e) => value[*b].powf(value[*e]),
                Step::Function(f, [a, b]) => {
                    let args = [value[*a], value[*b]];
                    f.eval(&args[..f.arity()])
                }
            };
            value.push(v);
        }
        self.roots.iter().map(|&r| value[r]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tools::fixtures::panda;
    use std::collections::HashMap;

    /// Each node by `Node::value`, its operands from a map: the evaluation
    /// a tape replaces.
    fn by_nodes(g: &Graph, roots: &[Id], env: &dyn Fn(Sym) -> f64) -> Vec<f64> {
        let mut value: HashMap<Id, f64> = HashMap::new();
        for id in g.reachable(roots) {
            let v = g.node(id).value(|c| value[&c], env);
            value.insert(id, v);
        }
        roots.iter().map(|r| value[r]).collect()
    }

    /// A tape gives the same bits as the node-by-node evaluation, for the
    /// Panda's `M`, `F` and a root repeated, at many points: stage 3's rank
    /// decisions must not depend on which of the two evaluated.
    #[test]
    fn a_tape_gives_the_node_by_node_values_bit_for_bit() {
        let eq = crate::analyse(panda("Panda", 7).parse().expect("tokens")).expect("expands");
        let g = &eq.system.graph;
        let mut roots: Vec<Id> = eq.system.mass.iter().flatten().copied().collect();
        roots.extend(&eq.system.forces);
        roots.push(roots[0]);
        let tape = g.tape(&roots);
        let mut checked = 0;
        for point in crate::numeric::rng::sample_points(3) {
            let env = |s: Sym| point(s);
            let (ours, theirs) = (tape.eval(&env), by_nodes(g, &roots, &env));
            assert_eq!(ours.len(), roots.len());
            for (a, b) in ours.iter().zip(&theirs) {
                assert_eq!(a.to_bits(), b.to_bits(), "{a} vs {b}");
                checked += usize::from(*a != 0.0);
            }
        }
        assert!(checked > 100, "{checked} nonzero values compared");
    }
}
