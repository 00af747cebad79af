//! Quadratic forms in the velocities written as sums of squares, where that
//! is shorter: the two-link arm's
//! `b = θ̇₁·(θ̇₁·(l₁·sin θ₁ + l₂·sin θ₁₂) + l₂·θ̇₂·sin θ₁₂) + l₂·θ̇₂·sin θ₁₂·(θ̇₁ + θ̇₂)`
//! becomes `l₁·θ̇₁²·sin θ₁ + l₂·(θ̇₁ + θ̇₂)²·sin θ₁₂`, the textbook form and
//! six operations fewer.
//!
//! `b = −(d/dt A)·q̇` of a position constraint is such a form: Σ cᵢⱼ·q̇ᵢ·q̇ⱼ
//! with coefficients in `q` and `t`. The expression is expanded as a
//! polynomial of degree two in the velocities, its velocity-free
//! coefficients kept whole; the terms of the coefficients group the
//! monomials (every monomial whose coefficient holds `l₂·sin θ₁₂` goes to
//! that term's group); each group's numeric matrix `Q` is reduced by
//! Lagrange's method (`Q = Σ dₖ·lₖ·lₖᵀ`, exact rationals) into
//! `Σ dₖ·(lₖ·q̇)²`, and a group is rewritten when that takes fewer squares
//! than it had monomials. The rewritten sum, factored like every other
//! (`crate::expr::common_factors`), replaces the original only when it costs at least
//! three operations fewer ([`operations`], `MIN_SAVING`): values are
//! unchanged, only the order of operations (and with it the rounding)
//! moves.

use crate::expr::common_factors::Factorer;
use crate::expr::num::Num;
use crate::expr::{Graph, Id, Node, Sym};
use std::collections::{BTreeMap, HashMap};

/// Expansions with more monomial contributions than this are abandoned:
/// the forms this is for have a handful, and expanding a large expression
/// would only be thrown away.
const MAX_CONTRIBUTIONS: usize = 64;

/// The fewest operations a rewrite must save. The count over `b` and its
/// context predicts the solve's only roughly (`r = b − A a` is factored
/// again, rows are scaled), and a saving of one there is a loss of six
/// in the redundant double pendulum's `q̈` (a square that re-expanded
/// `x₁² + y₁² − l₁² + 1`, which `A` shares).
const MIN_SAVING: usize = 3;

/// A monomial in the velocities of degree at most two: the sorted indices of
/// its velocities.
type Monomial = Vec<usize>;

/// A polynomial in the velocities: per monomial, the velocity-free
/// contributions to its coefficient (summed when the form is rebuilt).
type Poly = BTreeMap<Monomial, Vec<(Id, Num)>>;

/// `root` as a sum of squares where that costs at least `MIN_SAVING` (3)
/// fewer operations after factoring, counted together with `context` (the
/// other pieces the code computes, whose subexpressions `root` may share);
/// `root` factored otherwise (module docs).
pub fn complete(g: &mut Graph, factorer: &mut Factorer, root: Id, context: &[Id]) -> Id {
    let factored = factorer.factor(g, root);
    let Some(candidate) = squares(g, factorer, root) else {
        return factored;
    };
    let candidate = factorer.factor(g, candidate);
    let cost = |g: &Graph, id: Id| {
        let roots: Vec<Id> = context.iter().copied().chain([id]).collect();
        operations(g, &roots)
    };
    if cost(g, candidate) + MIN_SAVING <= cost(g, factored) {
        candidate
    } else {
        factored
    }
}

/// The form with its groups reduced to squares; `None` when `root` is not a
/// polynomial of degree two in the velocities or no group got shorter.
fn squares(g: &mut Graph, factorer: &Factorer, root: Id) -> Option<Id> {
    let poly = expand(g, factorer, root)?;
    // The velocity-free terms of every quadratic coefficient, grouped: per
    // term, the monomials it multiplies and with which rational.
    let mut groups: BTreeMap<Id, Vec<(usize, usize, Num)>> = BTreeMap::new();
    let mut rest: Vec<(Id, Num)> = Vec::new();
    for (monomial, contributions) in poly {
        let coefficient = g.linear_combination(contributions);
        let [i, j] = monomial[..] else {
            // Constant and linear parts stay as they are.
            let velocities: Vec<(Id, Num)> = monomial
                .iter()
                .map(|&i| (g.sym(Sym::Vel(i)), Num::ONE))
                .collect();
            let term = g.product(velocities.into_iter().chain([(coefficient, Num::ONE)]));
            rest.push((term, Num::ONE));
            continue;
        };
        let coefficient = g.distribute(coefficient);
        let one = g.num(Num::ONE);
        let terms: Vec<(Id, Num)> = match g.node(coefficient) {
            Node::Add(terms, c0) => terms
                .iter()
                .copied()
                .chain((!c0.is_zero()).then_some((one, *c0)))
                .collect(),
            Node::Num(c) => vec![(one, *c)],
            _ => vec![(coefficient, Num::ONE)],
        };
        for (term, c) in terms {
            groups.entry(term).or_default().push((i, j, c));
        }
    }
    let mut shorter = false;
    for (term, entries) in groups {
        let form = match lagrange_reduction(&entries) {
            Some(squares) if squares.len() < entries.len() => {
                shorter = true;
                sum_of_squares(g, squares)
            }
            _ => quadratic_form(g, entries),
        };
        rest.push((g.mul2(term, form), Num::ONE));
    }
    shorter.then(|| g.linear_combination(rest))
}

/// `Σ dₖ·(Σ lₖⱼ·q̇ⱼ)²` in the graph.
fn sum_of_squares(g: &mut Graph, squares: Vec<Square>) -> Id {
    let items: Vec<(Id, Num)> = squares
        .into_iter()
        .map(|(d, l)| {
            let items: Vec<(Id, Num)> = l
                .into_iter()
                .map(|(v, c)| (g.sym(Sym::Vel(v)), c))
                .collect();
            let linear = g.linear_combination(items);
            (g.pown(linear, Num::int(2)), d)
        })
        .collect();
    g.linear_combination(items)
}

/// `Σ c·q̇ᵢ·q̇ⱼ` in the graph, unreduced: the form where no reduction is shorter.
fn quadratic_form(g: &mut Graph, entries: Vec<(usize, usize, Num)>) -> Id {
    let items: Vec<(Id, Num)> = entries
        .into_iter()
        .map(|(i, j, c)| {
            let (vi, vj) = (g.sym(Sym::Vel(i)), g.sym(Sym::Vel(j)));
            (g.mul2(vi, vj), c)
        })
        .collect();
    g.linear_combination(items)
}

/// `root` as a polynomial of degree at most two in the velocities, or
/// `None` (a velocity under a function or in a named definition, which the
/// derivation shows by its name; a higher degree; too many terms).
fn expand(g: &mut Graph, factorer: &Factorer, root: Id) -> Option<Poly> {
    let order = g.reachable(&[root]);
    let mut expansion = Expansion {
        memo: HashMap::new(),
        moving: moving_nodes(g, &order),
    };
    for &id in &order {
        if !expansion.moving[id.index()] {
            continue;
        }
        if factorer.keeps(id) {
            return None;
        }
        let poly = match g.node(id).clone() {
            Node::Sym(Sym::Vel(i)) => {
                let one = g.num(Num::ONE);
                Poly::from([(vec![i], vec![(one, Num::ONE)])])
            }
            Node::Add(terms, c0) => expansion.sum(g, &terms, c0)?,
            Node::Mul(factors) => expansion.product(g, &factors)?,
            _ => return None,
        };
        let size: usize = poly.values().map(Vec::len).sum();
        if size > MAX_CONTRIBUTIONS {
            return None;
        }
        expansion.memo.insert(id, poly);
    }
    expansion.part(root)
}

/// Which nodes of `order` (topological, indexed by arena position) hold a
/// velocity: only those are expanded, the others are coefficients.
fn moving_nodes(g: &Graph, order: &[Id]) -> Vec<bool> {
    let mut moving = vec![false; g.len()];
    for &id in order {
        moving[id.index()] = match g.node(id) {
            Node::Sym(Sym::Vel(_)) => true,
            node => node.children().any(|c| moving[c.index()]),
        };
    }
    moving
}

/// The polynomials of the velocity-holding nodes expanded so far, which
/// the nodes after them are built from.
struct Expansion {
    /// The polynomial of each expanded node.
    memo: HashMap<Id, Poly>,
    /// Whether each node (by arena index) holds a velocity.
    moving: Vec<bool>,
}

impl Expansion {
    /// The polynomial of `id`: expanded if it holds a velocity, a constant
    /// coefficient otherwise.
    fn part(&self, id: Id) -> Option<Poly> {
        if self.moving[id.index()] {
            return self.memo.get(&id).cloned();
        }
        Some(constant(id))
    }

    /// The polynomial of `Σ cᵢ·tᵢ + c₀`: the parts' contributions scaled by
    /// their coefficients, monomial by monomial.
    fn sum(&self, g: &mut Graph, terms: &[(Id, Num)], c0: Num) -> Option<Poly> {
        let mut sum = Poly::new();
        if !c0.is_zero() {
            let one = g.num(Num::ONE);
            sum.entry(Vec::new()).or_default().push((one, c0));
        }
        for &(t, c) in terms {
            let part = self.part(t)?;
            for (m, contributions) in part {
                let slot = sum.entry(m).or_default();
                slot.extend(contributions.into_iter().map(|(x, k)| (x, k * c)));
            }
        }
        Some(sum)
    }

    /// The polynomial of `Π bᵢ^eᵢ`, or `None` past degree two.
    fn product(&self, g: &mut Graph, factors: &[(Id, Num)]) -> Option<Poly> {
        let mut product = constant(g.num(Num::ONE));
        for &(base, e) in factors {
            if !self.moving[base.index()] {
                // A velocity-free factor, at any power, is one coefficient.
                let factor = constant(g.pown(base, e));
                product = multiply(g, &product, &factor)?;
                continue;
            }
            // A velocity to a power other than 1 or 2 exceeds the degree
            // (or is no polynomial).
            let power = match e.as_integer() {
                Some(p @ 1..=2) => p,
                _ => return None,
            };
            let factor = self.part(base)?;
            for _ in 0..power {
                product = multiply(g, &product, &factor)?;
            }
        }
        Some(product)
    }
}

/// The polynomial that is the velocity-free coefficient `c` alone.
fn constant(c: Id) -> Poly {
    Poly::from([(Vec::new(), vec![(c, Num::ONE)])])
}

/// The product of two polynomials, `None` above degree two.
fn multiply(g: &mut Graph, a: &Poly, b: &Poly) -> Option<Poly> {
    let mut product = Poly::new();
    for (ma, ca) in a {
        for (mb, cb) in b {
            let mut m: Monomial = ma.iter().chain(mb).copied().collect();
            if m.len() > 2 {
                return None;
            }
            m.sort_unstable();
            let slot = product.entry(m).or_default();
            for &(x, k) in ca {
                for &(y, l) in cb {
                    slot.push((g.mul2(x, y), k * l));
                }
            }
        }
    }
    Some(product)
}

/// `dₖ·(Σ lₖⱼ·q̇ⱼ)²` as `(dₖ, [(j, lₖⱼ)])`.
type Square = (Num, Vec<(usize, Num)>);

/// Lagrange's reduction of the quadratic form `Σ c·q̇ᵢ·q̇ⱼ` over exact
/// rationals: `Σ dₖ·(Σ lₖⱼ·q̇ⱼ)²`. `None` where a pivot would be an
/// off-diagonal entry (a form such as `q̇₁·q̇₂` alone) or a number is not an
/// exact rational.
fn lagrange_reduction(entries: &[(usize, usize, Num)]) -> Option<Vec<Square>> {
    let mut q: BTreeMap<(usize, usize), Num> = BTreeMap::new();
    let half = Num::ratio(1, 2);
    for &(i, j, c) in entries {
        if !matches!(c, Num::Rational(..)) {
            return None;
        }
        let (value, pairs) = if i == j {
            (c, vec![(i, i)])
        } else {
            (c * half, vec![(i, j), (j, i)])
        };
        for key in pairs {
            let slot = q.entry(key).or_insert(Num::ZERO);
            *slot = *slot + value;
        }
    }
    let mut squares = Vec::new();
    // Each round removes a row and a column, so there are at most as many
    // rounds as velocities.
    while q.values().any(|c| !c.is_zero()) {
        let pivot = q
            .iter()
            .find(|&(&(i, j), c)| i == j && !c.is_zero())
            .map(|(&(i, _), &c)| (i, c));
        let (p, d) = pivot?;
        let row: Vec<(usize, Num)> = q
            .iter()
            .filter(|&(&(i, _), c)| i == p && !c.is_zero())
            .map(|(&(_, j), &c)| (j, c / d))
            .collect();
        for &(i, li) in &row {
            for &(j, lj) in &row {
                let slot = q.entry((i, j)).or_insert(Num::ZERO);
                *slot = *slot + -(d * li * lj);
                if !matches!(*slot, Num::Rational(..)) {
                    return None;
                }
            }
        }
        q.retain(|_, c| !c.is_zero());
        squares.push((d, row));
    }
    Some(squares)
}

/// The arithmetic operations of `roots`, counting each node they reach once
/// (as the emitted code computes it once): a sum of `k` parts `k − 1`, a
/// coefficient other than ±1 one, a product of `k` factors `k − 1`, an
/// integer power `n` `|n| − 1` (and a division when negative), a function
/// one.
pub fn operations(g: &Graph, roots: &[Id]) -> usize {
    let mut total = 0;
    g.visit_reachable(roots, |id| total += node_operations(g, id));
    total
}

/// Operations counted as roots join what the code computes, each node
/// once, as [`operations`] counts them: what one more root adds is the
/// operations of the nodes it reaches that nothing counted reaches. So
/// comparing candidates against a large context (a robot's `M`, `F` and
/// `A`) walks the candidates, not the context again for each.
pub struct Counted {
    seen: Vec<bool>,
}

impl Counted {
    /// The nodes `roots` reach, counted.
    pub fn new(g: &Graph, roots: &[Id]) -> Counted {
        let mut counted = Counted {
            seen: vec![false; g.len()],
        };
        counted.mark(g, roots);
        counted
    }

    /// The operations `root` would add to what is counted:
    /// `operations(context + [root]) − operations(context)`.
    pub fn extra(&mut self, g: &Graph, root: Id) -> usize {
        let marked = self.mark(g, &[root]);
        let total = marked.iter().map(|&id| node_operations(g, id)).sum();
        for id in marked {
            self.seen[id.index()] = false;
        }
        total
    }

    /// `root` counted from now on.
    pub fn add(&mut self, g: &Graph, root: Id) {
        self.mark(g, &[root]);
    }

    /// Marks the nodes `roots` reach that were not marked, and lists them.
    fn mark(&mut self, g: &Graph, roots: &[Id]) -> Vec<Id> {
        let mut marked = Vec::new();
        g.visit_unseen(roots, &mut self.seen, |id| marked.push(id));
        marked
    }
}

/// The arithmetic operations of node `id` alone, its operands computed
/// (see [`operations`]).
pub fn node_operations(g: &Graph, id: Id) -> usize {
    match g.node(id) {
        Node::Num(_) | Node::Sym(_) => 0,
        Node::Add(terms, c0) => {
            let scaled = terms
                .iter()
                .filter(|(_, c)| !c.is_one() && !(-*c).is_one())
                .count();
            terms.len() - 1 + usize::from(!c0.is_zero()) + scaled
        }
        Node::Mul(factors) => {
            let powers: usize = factors
                .iter()
                .map(|(_, e)| match e.as_integer() {
                    Some(n) => n.unsigned_abs().saturating_sub(1) as usize,
                    None => 1,
                })
                .sum();
            // One division for the negative powers, whatever their count.
            let division = usize::from(factors.iter().any(|(_, e)| e.is_negative()));
            factors.len() - 1 + powers + division
        }
        Node::Pow(_) | Node::Func(..) => 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::sample as value;
    use crate::expr::Func;

    #[test]
    fn the_two_link_arms_b_becomes_two_squares() {
        // θ̇₁·(θ̇₁·(l₁·s₁ + l₂·s₁₂) + l₂·θ̇₂·s₁₂) + l₂·θ̇₂·s₁₂·(θ̇₁ + θ̇₂)
        let mut g = Graph::new();
        let (th1, th2) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let (w1, w2) = (g.sym(Sym::Vel(0)), g.sym(Sym::Vel(1)));
        let (l1, l2) = (g.sym(Sym::Param(0)), g.sym(Sym::Param(1)));
        let s1 = g.func(Func::Sin, th1);
        let th12 = g.add2(th1, th2);
        let s12 = g.func(Func::Sin, th12);
        let (a, b) = (g.mul2(l1, s1), g.mul2(l2, s12));
        let ab = g.add2(a, b);
        let inner1 = g.mul2(w1, ab);
        let inner2 = g.mul(&[l2, w2, s12]);
        let inner = g.add2(inner1, inner2);
        let first = g.mul2(w1, inner);
        let w12 = g.add2(w1, w2);
        let second = g.mul(&[l2, w2, s12, w12]);
        let form = g.add2(first, second);

        let result = complete(&mut g, &mut Factorer::new(), form, &[]);

        let square = g.pown(w12, Num::int(2));
        let w1sq = g.pown(w1, Num::int(2));
        let expected_a = g.mul(&[l1, s1, w1sq]);
        let expected_b = g.mul(&[l2, s12, square]);
        let expected = g.add2(expected_a, expected_b);
        assert_eq!(result, expected, "{:?}", g.node(result));
        assert!((value(&g, result) - value(&g, form)).abs() < 1e-14);
        assert!(operations(&g, &[result]) + 5 <= operations(&g, &[form]));
    }

    /// What a root adds to the counted context is the difference of the
    /// counts with and without it, whether it shares nodes with the
    /// context, with nodes made after the context was counted, or not;
    /// asking leaves the count as it was, adding it changes it.
    #[test]
    fn a_roots_extra_operations_are_the_difference_of_the_counts() {
        let mut g = Graph::new();
        let (x, y, z) = (
            g.sym(Sym::Coord(0)),
            g.sym(Sym::Coord(1)),
            g.sym(Sym::Vel(0)),
        );
        let s = g.func(Func::Sin, x);
        let xy = g.mul(&[x, y, s]);
        let context = [g.add2(xy, z)];
        let mut counted = Counted::new(&g, &context);
        let shared = g.mul(&[xy, z, z]);
        let shared = g.scale(shared, Num::int(3));
        let c = g.func(Func::Cos, y);
        let apart = g.add(&[c, y, z]);
        for root in [shared, apart, xy] {
            let with: Vec<Id> = context.iter().copied().chain([root]).collect();
            let difference = operations(&g, &with) - operations(&g, &context);
            assert_eq!(counted.extra(&g, root), difference);
            assert_eq!(counted.extra(&g, root), difference, "asked twice");
        }
        assert!(counted.extra(&g, shared) > 0);
        assert_eq!(counted.extra(&g, xy), 0);
        counted.add(&g, shared);
        let both = g.add2(shared, apart);
        let all = [context[0], shared, both];
        let difference = operations(&g, &all) - operations(&g, &[context[0], shared]);
        assert_eq!(counted.extra(&g, both), difference);
    }

    #[test]
    fn a_form_without_a_diagonal_pivot_is_left_factored() {
        // 2·ẋ·ẏ·sin x has no square to complete.
        let mut g = Graph::new();
        let (x, xd, yd) = (g.sym(Sym::Coord(0)), g.sym(Sym::Vel(0)), g.sym(Sym::Vel(1)));
        let s = g.func(Func::Sin, x);
        let p = g.mul(&[xd, yd, s]);
        let form = g.scale(p, Num::int(2));
        assert_eq!(complete(&mut g, &mut Factorer::new(), form, &[]), form);
    }

    #[test]
    fn velocities_under_functions_are_not_expanded() {
        let mut g = Graph::new();
        let xd = g.sym(Sym::Vel(0));
        let s = g.func(Func::Sin, xd);
        let form = g.add2(s, xd);
        assert!(squares(&mut g, &Factorer::new(), form).is_none());
    }

    #[test]
    fn the_reduction_is_exact() {
        // x² + 2xy + 2y² = (x + y)² + y²
        let reduced =
            lagrange_reduction(&[(0, 0, Num::ONE), (0, 1, Num::int(2)), (1, 1, Num::int(2))])
                .expect("a diagonal pivot");
        assert_eq!(
            reduced,
            vec![
                (Num::ONE, vec![(0, Num::ONE), (1, Num::ONE)]),
                (Num::ONE, vec![(1, Num::ONE)]),
            ]
        );
    }
}
