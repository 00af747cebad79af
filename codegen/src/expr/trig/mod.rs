//! The Pythagorean identity `sin²x + cos²x = 1`, applied where a person
//! would: the Furuta pendulum written with Cartesian definitions derives
//! `M₁₁ = J + m·((r·sin θ + l·sin α·cos θ)² + (r·cos θ − l·sin α·sin θ)²)`,
//! which is `J + m·r² + m·l²·sin²α`; a pendulum whose `T` is written from
//! its bob's `x` and `y` has the constant `M = m·l²`, not
//! `m·l²·(sin²θ + cos²θ)` computed with a sine and a cosine.
//!
//! The expression is expanded into a polynomial whose variables are its
//! atoms (symbols, functions, non-integer powers; a subexpression whose
//! expansion would exceed `MAX_TERMS` stays an atom) with exact
//! coefficients. For each argument `x` with `sin x` or `cos x` in it, the
//! polynomial is reduced modulo `sin²x + cos²x − 1` in both directions
//! (`cos²x → 1 − sin²x`, then `sin²x → 1 − cos²x`), and the shorter of the
//! two, when shorter than before, is kept. A reduction that removed no
//! monomial leaves the expression as it was; one that did replaces it only
//! when the set of expressions it belongs to (a matrix's entries, the
//! forces) then costs no more operations, shared subexpressions counted
//! once ([`simplify_all`]). Values are unchanged up to
//! rounding: the identity is exact, only the order of operations moves.
//!
//! The addition theorems, `sin x·cos y ± cos x·sin y = sin(x ± y)` and
//! `cos x·cos y ∓ sin x·sin y = cos(x ± y)`, join pairs of monomials of the
//! reduced polynomial ([`join_angle_sums`]): a chain in joint angles reads
//! `M₁₂ = m₂·l₁·l₂·cos θ₂`, not `m₂·l₁·l₂·(cos θ₁·cos(θ₁ + θ₂) + sin θ₁·sin(θ₁ + θ₂))`.
//! Whether a join is kept is decided on the mass matrix and the forces
//! together, the set `q̈` is computed from.

mod angle_sums;

use crate::expr::num::Num;
use crate::expr::squares::node_operations;
use crate::expr::{FastHash, Func, Graph, Id, Node};
use std::collections::btree_map::Entry;
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// Expansions of more monomials than this keep the subexpression whole (an
/// atom): the forms the identity shortens are small, and the polynomial of a
/// large expression would cost time nobody gets back.
const MAX_TERMS: usize = 96;

/// The most monomial products one simplification may compute before it
/// gives up and leaves the expression as it was: a bound on the time the
/// macro spends here whatever the input. At 2,000 (counted per root on the
/// nodes it expands anew) every reference model, the Furuta pendulum,
/// every snapshot and the pendulums of 2 to 16 links derive the same code
/// as with a bound a hundred times higher, which spends a quarter of the
/// 16-link pendulum's expansion on its forces for no rewrite kept; the
/// 8-link pendulum's forces, which exceed it, give up after a few
/// milliseconds in all, about what the 35 entries it shortens take.
const MAX_WORK: usize = 2_000;

/// A product of atoms to integer powers, sorted by atom, no zero power.
type Monomial = Vec<(Id, i64)>;

/// A polynomial: its monomials with their exact coefficients.
type Poly = BTreeMap<Monomial, Num>;

/// The polynomials of the nodes expanded so far.
type Memo = HashMap<Id, Poly, FastHash>;

/// `roots` with `sin²x + cos²x = 1` applied to each where that removes
/// monomials and the whole set costs no more operations (module docs).
///
/// The cost is the set's, shared subexpressions counted once, not each
/// root's alone: a matrix's entries share most of their terms (the N-link
/// pendulum's `M`), and an entry rewritten as its own reduced polynomial
/// can cost less alone yet share nothing with its neighbours. Judged one
/// entry at a time, the 8-link pendulum's `q̈` grew from 4,673 to 5,441
/// operations and its expansion took 2.6 times as long.
pub fn simplify_all(g: &mut Graph, roots: &[Id]) -> Vec<Id> {
    decide(g, roots, Identities::Pythagorean)
}

/// `roots` (a mass matrix's entries and the forces together) with the
/// addition theorems applied as well as `sin²x + cos²x = 1`, where that
/// removes monomials and the whole set costs no more operations.
///
/// The set is the whole of what `q̈` is computed from, because a product
/// `sin x·sin y` the mass matrix no longer needs may still be needed by the
/// forces: joined in `M` alone, the 8-link pendulum's `q̈` would take 4,953
/// operations instead of 4,672, though `M` alone would shrink from 1,080 to 924.
pub fn join_angle_sums(g: &mut Graph, roots: &[Id]) -> Vec<Id> {
    decide(g, roots, Identities::AngleSums)
}

/// Which identities a simplification applies.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Identities {
    /// `sin²x + cos²x = 1` only.
    Pythagorean,
    /// That and the addition theorems, `sin(x ± y)` and `cos(x ± y)`.
    AngleSums,
}

/// Each root in whichever of its forms (as it is, reduced by `identities`)
/// makes the set cheapest (see [`simplify_all`]).
fn decide(g: &mut Graph, roots: &[Id], identities: Identities) -> Vec<Id> {
    // One expansion of each node for all the roots: a matrix's entries
    // share most of theirs.
    let mut memo = Memo::default();
    let candidates: Vec<Option<Id>> = roots
        .iter()
        .map(|&r| reduced(g, r, identities, &mut memo))
        .collect();
    if candidates.iter().all(Option::is_none) {
        return roots.to_vec();
    }
    let g: &Graph = g;
    let mut set = SetCost::new(g, roots);
    let apart = set.total;
    let mut out = roots.to_vec();
    // Together first: entries that share a definition only drop it when
    // all of them are rewritten (the Furuta pendulum's `M` loses the arm
    // angle only so).
    for (i, candidate) in candidates.iter().enumerate() {
        if let Some(candidate) = *candidate {
            set.replace(&mut out, i, candidate);
        }
    }
    if set.total > apart {
        for (i, &root) in roots.iter().enumerate() {
            set.replace(&mut out, i, root);
        }
    }
    // Then one entry at a time, each kept in whichever form costs the set
    // less (the rewritten one where equal).
    for (i, candidate) in candidates.iter().enumerate() {
        let Some(candidate) = *candidate else {
            continue;
        };
        let other = if out[i] == candidate {
            roots[i]
        } else {
            candidate
        };
        let (current, cost) = (out[i], set.total);
        set.replace(&mut out, i, other);
        let better = set.total < cost || (set.total == cost && other == candidate);
        if !better {
            set.replace(&mut out, i, current);
        }
    }
    out
}

/// The operations of a set of roots
/// ([`operations`](crate::expr::squares::operations)), kept as roots are
/// replaced one at a time: each node counts the roots and counted parents
/// that use it, and only the nodes whose count rises from or falls to zero
/// are visited. Deciding root by root over the whole of `M` and `F` by
/// walking the set each time would make the 16-link pendulum's expansion
/// half as long again.
struct SetCost<'a> {
    g: &'a Graph,
    uses: HashMap<Id, usize, FastHash>,
    total: usize,
}

impl<'a> SetCost<'a> {
    fn new(g: &'a Graph, roots: &[Id]) -> Self {
        let mut set = SetCost {
            g,
            uses: HashMap::default(),
            total: 0,
        };
        for &r in roots {
            set.add(r);
        }
        set
    }

    /// `out[i] = by`, the total updated.
    fn replace(&mut self, out: &mut [Id], i: usize, by: Id) {
        if out[i] != by {
            self.add(by);
            self.remove(out[i]);
            out[i] = by;
        }
    }

    fn add(&mut self, root: Id) {
        let mut stack = vec![root];
        while let Some(id) = stack.pop() {
            let uses = self.uses.entry(id).or_insert(0);
            *uses += 1;
            if *uses == 1 {
                self.total += node_operations(self.g, id);
                stack.extend(self.g.node(id).children());
            }
        }
    }

    fn remove(&mut self, root: Id) {
        let mut stack = vec![root];
        while let Some(id) = stack.pop() {
            let Some(uses) = self.uses.get_mut(&id) else {
                continue;
            };
            *uses -= 1;
            if *uses == 0 {
                self.uses.remove(&id);
                self.total -= node_operations(self.g, id);
                stack.extend(self.g.node(id).children());
            }
        }
    }
}

/// `root` reduced modulo `sin²x + cos²x − 1` for each of its arguments
/// `x`, rebuilt, when that removes monomials; `None` when it removes none
/// or the expansion or the work exceeds its bounds.
fn reduced(g: &mut Graph, root: Id, identities: Identities, memo: &mut Memo) -> Option<Id> {
    let arguments = trig_arguments(g, root);
    if arguments.is_empty() {
        return None;
    }
    let mut work = 0usize;
    let expanded = expand(g, root, memo, &mut work)?;
    let mut best = expanded.clone();
    for x in arguments {
        let (sin, cos) = (g.func(Func::Sin, x), g.func(Func::Cos, x));
        for (from, to) in [(cos, sin), (sin, cos)] {
            let reduced = reduce(&best, from, to, &mut work)?;
            if shorter(&reduced, &best) {
                best = reduced;
            }
        }
    }
    let best = match identities {
        Identities::Pythagorean => best,
        Identities::AngleSums => angle_sums::angle_sums(g, best, &mut work)?,
    };
    (best.len() < expanded.len()).then(|| rebuild(g, &best))
}

/// Whether `a` has fewer monomials than `b`, or as many of lower total
/// degree in its atoms.
fn shorter(a: &Poly, b: &Poly) -> bool {
    let degree = |p: &Poly| -> i64 { p.keys().flatten().map(|&(_, e)| e.abs()).sum() };
    (a.len(), degree(a)) < (b.len(), degree(b))
}

/// The arguments `x` for which `root` reaches both `sin x` and `cos x`, or
/// one of them under a power of two or more: the only places the identity
/// can apply.
fn trig_arguments(g: &Graph, root: Id) -> Vec<Id> {
    let mut sines = BTreeSet::new();
    let mut cosines = BTreeSet::new();
    let mut squared = BTreeSet::new();
    for id in g.reachable(&[root]) {
        match g.node(id) {
            Node::Func(Func::Sin, args) => {
                sines.insert(args.as_slice()[0]);
            }
            Node::Func(Func::Cos, args) => {
                cosines.insert(args.as_slice()[0]);
            }
            Node::Mul(factors) => {
                for &(base, e) in factors.iter() {
                    if let Node::Func(Func::Sin | Func::Cos, args) = g.node(base) {
                        if e.as_integer().is_some_and(|k| k >= 2) {
                            squared.insert(args.as_slice()[0]);
                        }
                    }
                }
            }
            _ => {}
        }
    }
    let both = sines.intersection(&cosines).copied();
    both.chain(squared)
        .collect::<BTreeSet<Id>>()
        .into_iter()
        .collect()
}

/// `root` as a polynomial in its atoms, or `None` when the work bound is
/// reached; `memo` holds the polynomials of the nodes already expanded (for
/// earlier roots too), and `work` counts only the products computed anew.
fn expand(g: &mut Graph, root: Id, memo: &mut Memo, work: &mut usize) -> Option<Poly> {
    for id in g.reachable(&[root]) {
        if memo.contains_key(&id) {
            continue;
        }
        let poly = match g.node(id).clone() {
            Node::Num(c) => Poly::from([(Vec::new(), c)]),
            Node::Add(terms, c0) => {
                let mut sum = Poly::new();
                if !c0.is_zero() {
                    sum.insert(Vec::new(), c0);
                }
                for (t, c) in terms.iter().copied() {
                    for (m, k) in &memo[&t] {
                        accumulate(&mut sum, m.clone(), *k * c);
                    }
                }
                sum
            }
            Node::Mul(factors) => product(g, memo, &factors, work)?,
            _ => atom(id),
        };
        let poly = if poly.len() > MAX_TERMS {
            atom(id)
        } else {
            poly
        };
        memo.insert(id, poly);
    }
    memo.get(&root).cloned()
}

/// The polynomial that is the atom `id` alone.
fn atom(id: Id) -> Poly {
    Poly::from([(vec![(id, 1)], Num::ONE)])
}

/// The polynomial of `Π bᵢ^eᵢ`: a factor to a positive integer power is
/// multiplied out (up to the fourth), a monomial factor to any integer power
/// raises its powers, and anything else (a sum in a denominator, a
/// fractional power) is an atom.
fn product(g: &mut Graph, memo: &Memo, factors: &[(Id, Num)], work: &mut usize) -> Option<Poly> {
    let mut result = Poly::from([(Vec::new(), Num::ONE)]);
    for &(base, e) in factors {
        let poly = &memo[&base];
        let factor = match e.as_integer() {
            Some(k) if poly.len() == 1 => {
                let (m, c) = poly.iter().next().map(|(m, c)| (m.clone(), *c))?;
                match c.pow(e) {
                    Some(c) => {
                        let m: Monomial = m.into_iter().map(|(a, p)| (a, p * k)).collect();
                        Poly::from([(m, c)])
                    }
                    None => atom(g.pown(base, e)),
                }
            }
            Some(k @ 1..=4) => {
                let mut power = poly.clone();
                for _ in 1..k {
                    power = multiply(&power, poly, work)?;
                }
                power
            }
            _ => atom(g.pown(base, e)),
        };
        result = multiply(&result, &factor, work)?;
    }
    Some(result)
}

/// Adds `c·m` to `p`, dropping the monomial when its coefficient cancels.
fn accumulate(p: &mut Poly, m: Monomial, c: Num) {
    match p.entry(m) {
        Entry::Occupied(mut slot) => {
            let sum = *slot.get() + c;
            if sum.is_zero() {
                slot.remove();
            } else {
                *slot.get_mut() = sum;
            }
        }
        Entry::Vacant(slot) => {
            if !c.is_zero() {
                slot.insert(c);
            }
        }
    }
}

/// The product of two polynomials, or `None` past the work bound.
fn multiply(a: &Poly, b: &Poly, work: &mut usize) -> Option<Poly> {
    *work += a.len() * b.len();
    if *work > MAX_WORK {
        return None;
    }
    let mut p = Poly::new();
    for (ma, ca) in a {
        for (mb, cb) in b {
            accumulate(&mut p, times(ma, mb), *ca * *cb);
        }
    }
    Some(p)
}

/// The product of two monomials; `b` need not be sorted (a pair of atoms
/// written by hand), `a` must be.
fn times(a: &Monomial, b: &Monomial) -> Monomial {
    if !b.is_sorted_by_key(|&(x, _)| x) {
        let mut sorted = b.clone();
        sorted.sort_unstable_by_key(|&(x, _)| x);
        return times(a, &sorted);
    }
    // Both sorted by atom: merged in one pass (the expansion's inner loop).
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let next = match (a.get(i), b.get(j)) {
            (Some(&(x, e)), Some(&(y, f))) if x == y => {
                (i, j) = (i + 1, j + 1);
                (x, e + f)
            }
            (Some(&(x, e)), Some(&(y, _))) if x < y => {
                i += 1;
                (x, e)
            }
            (_, Some(&(y, f))) => {
                j += 1;
                (y, f)
            }
            (Some(&(x, e)), None) => {
                i += 1;
                (x, e)
            }
            (None, None) => break,
        };
        if next.1 != 0 {
            out.push(next);
        }
    }
    out
}

/// `p` with every `from²` replaced by `1 − to²` until no monomial holds
/// `from` to a power of two or more (each round lowers that power by two, so
/// this ends); `None` past the work bound.
fn reduce(p: &Poly, from: Id, to: Id, work: &mut usize) -> Option<Poly> {
    let mut pending: Vec<(Monomial, Num)> = p.iter().map(|(m, c)| (m.clone(), *c)).collect();
    let mut done = Poly::new();
    while let Some((m, c)) = pending.pop() {
        *work += 1;
        if *work > MAX_WORK {
            return None;
        }
        let power = m.iter().find(|&&(x, _)| x == from).map_or(0, |&(_, e)| e);
        if power < 2 {
            accumulate(&mut done, m, c);
            continue;
        }
        let lowered = times(&m, &vec![(from, -2)]);
        pending.push((times(&lowered, &vec![(to, 2)]), -c));
        pending.push((lowered, c));
    }
    Some(done)
}

/// The expression of a polynomial.
fn rebuild(g: &mut Graph, p: &Poly) -> Id {
    let items: Vec<(Id, Num)> = p
        .iter()
        .map(|(m, c)| {
            let factors = m.iter().map(|&(x, e)| (x, Num::int(e)));
            (g.product(factors), *c)
        })
        .collect();
    g.linear_combination(items)
}

#[cfg(test)]
mod tests {
    /// One root alone: [`simplify_all`] of `[root]`.
    fn simplify(g: &mut Graph, root: Id) -> Id {
        simplify_all(g, &[root])[0]
    }

    use super::*;
    use crate::expr::{sample as value, Sym};

    /// `m·((l·cos θ)² + (l·sin θ)²)` is `m·l²`: no trigonometry left.
    #[test]
    fn a_pendulum_written_in_cartesian_terms_has_a_constant_mass() {
        let mut g = Graph::new();
        let (th, m, l) = (
            g.sym(Sym::Coord(0)),
            g.sym(Sym::Param(0)),
            g.sym(Sym::Param(1)),
        );
        let (s, c) = (g.func(Func::Sin, th), g.func(Func::Cos, th));
        let (x, y) = (g.mul2(l, c), g.mul2(l, s));
        let (x2, y2) = (g.pown(x, Num::int(2)), g.pown(y, Num::int(2)));
        let sum = g.add2(x2, y2);
        let entry = g.mul2(m, sum);
        let simplified = simplify(&mut g, entry);
        let l2 = g.pown(l, Num::int(2));
        assert_eq!(simplified, g.mul2(m, l2));
        assert!((value(&g, simplified) - value(&g, entry)).abs() < 1e-14);
    }

    /// The Furuta pendulum's `M₁₁` from its Cartesian bob:
    /// `(r·sin θ + l·sin α·cos θ)² + (r·cos θ − l·sin α·sin θ)² = r² + l²·sin²α`.
    #[test]
    fn the_furuta_arm_inertia_loses_its_theta() {
        let mut g = Graph::new();
        let (th, al) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let (r, l) = (g.sym(Sym::Param(0)), g.sym(Sym::Param(1)));
        let (st, ct) = (g.func(Func::Sin, th), g.func(Func::Cos, th));
        let sa = g.func(Func::Sin, al);
        let rs = g.mul2(r, st);
        let lsc = g.mul(&[l, sa, ct]);
        let first = g.add2(rs, lsc);
        let rc = g.mul2(r, ct);
        let lss = g.mul(&[l, sa, st]);
        let second = g.sub(rc, lss);
        let (a2, b2) = (g.pown(first, Num::int(2)), g.pown(second, Num::int(2)));
        let entry = g.add2(a2, b2);
        let simplified = simplify(&mut g, entry);
        assert!(!g.mentions(simplified, |s| s == Sym::Coord(0)));
        let r2 = g.pown(r, Num::int(2));
        let l2 = g.pown(l, Num::int(2));
        let sa2 = g.pown(sa, Num::int(2));
        let tail = g.mul2(l2, sa2);
        assert_eq!(simplified, g.add2(r2, tail));
        assert!((value(&g, simplified) - value(&g, entry)).abs() < 1e-13);
    }

    /// `1 − sin²α` is `cos²α`: the other direction of the identity.
    #[test]
    fn one_minus_a_squared_sine_is_a_squared_cosine() {
        let mut g = Graph::new();
        let al = g.sym(Sym::Coord(0));
        let s = g.func(Func::Sin, al);
        let s2 = g.pown(s, Num::int(2));
        let one = g.int(1);
        let e = g.sub(one, s2);
        let c = g.func(Func::Cos, al);
        assert_eq!(simplify(&mut g, e), g.pown(c, Num::int(2)));
    }

    /// Nothing to apply: `sin x·cos y` and `sin²x + y` are left alone.
    #[test]
    fn expressions_the_identity_does_not_shorten_are_unchanged() {
        let mut g = Graph::new();
        let (x, y) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let (sx, cy) = (g.func(Func::Sin, x), g.func(Func::Cos, y));
        let e = g.mul2(sx, cy);
        assert_eq!(simplify(&mut g, e), e);
        let s2 = g.pown(sx, Num::int(2));
        let e = g.add2(s2, y);
        assert_eq!(simplify(&mut g, e), e);
    }
}
