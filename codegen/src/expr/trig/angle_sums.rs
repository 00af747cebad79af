//! The addition theorems, `sin x·cos y ± cos x·sin y = sin(x ± y)` and
//! `cos x·cos y ∓ sin x·sin y = cos(x ± y)`, applied to a polynomial in
//! atoms (`super`): pairs of monomials joined until none is left.

use super::{accumulate, atom, multiply, times, Monomial, Poly, MAX_WORK};
use crate::expr::num::Num;
use crate::expr::{FastHash, Func, Graph, Id, Node};
use std::collections::HashMap;

/// `p` with each pair of monomials that is one side of an addition theorem
/// written as its other side, until no pair is left:
/// `c·R·(sin x·cos y ± cos x·sin y) = c·R·sin(x ± y)` and
/// `c·R·(cos x·cos y ∓ sin x·sin y) = c·R·cos(x ± y)`. A chain in joint
/// angles has `cos θ₁·cos(θ₁ + θ₂) + sin θ₁·sin(θ₁ + θ₂)` in its mass
/// matrix, the textbook's `cos θ₂`.
///
/// Each monomial is looked at once, and again only if a join creates it:
/// every join removes a monomial, so this ends. `None` past the work bound.
pub(super) fn angle_sums(g: &mut Graph, mut p: Poly, work: &mut usize) -> Option<Poly> {
    let mut trig = TrigAtoms::default();
    let mut pending: Vec<Monomial> = p.keys().cloned().collect();
    while let Some(m) = pending.pop() {
        let Some(&c) = p.get(&m) else {
            continue;
        };
        let Some((partner, replacement)) = join_pair(g, &mut trig, &p, &m, c, work)? else {
            continue;
        };
        p.remove(&m);
        p.remove(&partner);
        for (r, k) in replacement {
            pending.push(r.clone());
            accumulate(&mut p, r, k * c);
        }
    }
    Some(p)
}

/// The sines and cosines met so far: for each, its function, its argument
/// and the other function of the same argument (`cos x` for `sin x`).
#[derive(Default)]
struct TrigAtoms(HashMap<Id, Option<(Func, Id, Id)>, FastHash>);

impl TrigAtoms {
    fn get(&mut self, g: &mut Graph, atom: Id) -> Option<(Func, Id, Id)> {
        if let Some(&known) = self.0.get(&atom) {
            return known;
        }
        let found = match g.node(atom) {
            Node::Func(f @ (Func::Sin | Func::Cos), args) => {
                let (f, x) = (*f, args.as_slice()[0]);
                let other = if f == Func::Sin { Func::Cos } else { Func::Sin };
                Some((f, x, g.func(other, x)))
            }
            _ => None,
        };
        self.0.insert(atom, found);
        found
    }
}

/// The monomial of `p` that joins `c·m` by an addition theorem, and the
/// polynomial (per unit of `c`) that replaces the two; `Some(None)` when
/// there is none, `None` past the work bound.
#[allow(clippy::type_complexity)]
fn join_pair(
    g: &mut Graph,
    atoms: &mut TrigAtoms,
    p: &Poly,
    m: &Monomial,
    c: Num,
    work: &mut usize,
) -> Option<Option<(Monomial, Poly)>> {
    let mut trig: Vec<(Id, Func, Id, Id)> = Vec::new();
    for &(a, e) in m {
        if e >= 1 {
            if let Some((f, x, other)) = atoms.get(g, a) {
                trig.push((a, f, x, other));
            }
        }
    }
    for (i, &(a, fa, x, a2)) in trig.iter().enumerate() {
        for &(b, fb, y, b2) in &trig[i + 1..] {
            *work += 1;
            if *work > MAX_WORK {
                return None;
            }
            // sin·sin is met from its partner cos·cos.
            if x == y || (fa == Func::Sin && fb == Func::Sin) {
                continue;
            }
            let rest = times(m, &vec![(a, -1), (b, -1)]);
            let partner = times(&rest, &vec![(a2, 1), (b2, 1)]);
            let Some(&k) = p.get(&partner) else {
                continue;
            };
            let same = k == c;
            if !same && k != -c {
                continue;
            }
            // sin·cos with cos·sin: a sine; cos·cos with sin·sin: a cosine.
            let (f, plus) = if fa == Func::Cos && fb == Func::Cos {
                (Func::Cos, !same)
            } else {
                (Func::Sin, same)
            };
            // sin x·cos y − cos x·sin y = sin(x − y), x the sine's argument
            // in `m`.
            let (x, y) = if fa == Func::Cos && fb == Func::Sin {
                (y, x)
            } else {
                (x, y)
            };
            let argument = if plus { g.add2(x, y) } else { g.sub(x, y) };
            let value = g.func(f, argument);
            let replacement = multiply(&Poly::from([(rest, Num::ONE)]), &term(g, value), work)?;
            return Some(Some((partner, replacement)));
        }
    }
    Some(None)
}

/// The polynomial of a node built from atoms: a number, `k·atom` (the sign a
/// sine of a negated argument takes), or the node as an atom.
fn term(g: &Graph, id: Id) -> Poly {
    match g.node(id) {
        Node::Num(c) => Poly::from([(Vec::new(), *c)]),
        Node::Add(terms, c0) if terms.len() == 1 && c0.is_zero() => {
            let (t, k) = terms[0];
            Poly::from([(vec![(t, 1)], k)])
        }
        _ => atom(id),
    }
}

#[cfg(test)]
mod tests {
    use super::super::{join_angle_sums, simplify_all};
    use crate::expr::num::Num;
    use crate::expr::{Func, Graph, Id, Sym};

    /// One root alone: `simplify_all` of `[root]`.
    fn simplify(g: &mut Graph, root: Id) -> Id {
        simplify_all(g, &[root])[0]
    }

    /// One root alone, the addition theorems too: `join_angle_sums`.
    fn join(g: &mut Graph, root: Id) -> Id {
        join_angle_sums(g, &[root])[0]
    }

    /// Coordinates `x`, `y` and `sin x`, `cos x`, `sin y`, `cos y`.
    fn two_angles(g: &mut Graph) -> [Id; 6] {
        let (x, y) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let (sx, cx) = (g.func(Func::Sin, x), g.func(Func::Cos, x));
        let (sy, cy) = (g.func(Func::Sin, y), g.func(Func::Cos, y));
        [x, y, sx, cx, sy, cy]
    }

    /// The two-link arm in joint angles: `cos θ₁·cos(θ₁ + θ₂) + sin θ₁·sin(θ₁ + θ₂)`
    /// is `cos θ₂`, and `sin(θ₁ + θ₂)·cos θ₁ − cos(θ₁ + θ₂)·sin θ₁` is `sin θ₂`.
    #[test]
    fn a_chain_in_joint_angles_reads_its_relative_angle() {
        let mut g = Graph::new();
        let (t1, t2, l) = (
            g.sym(Sym::Coord(0)),
            g.sym(Sym::Coord(1)),
            g.sym(Sym::Param(0)),
        );
        let t12 = g.add2(t1, t2);
        let (s1, c1) = (g.func(Func::Sin, t1), g.func(Func::Cos, t1));
        let (s12, c12) = (g.func(Func::Sin, t12), g.func(Func::Cos, t12));
        let cc = g.mul(&[l, c1, c12]);
        let ss = g.mul(&[l, s1, s12]);
        let e = g.add2(cc, ss);
        let c2 = g.func(Func::Cos, t2);
        assert_eq!(join(&mut g, e), g.mul2(l, c2));
        let sc = g.mul2(s12, c1);
        let cs = g.mul2(c12, s1);
        let e = g.sub(sc, cs);
        assert_eq!(join(&mut g, e), g.func(Func::Sin, t2));
        // The other way round, the sine of the negated difference.
        let e = g.sub(cs, sc);
        let s2 = g.func(Func::Sin, t2);
        assert_eq!(join(&mut g, e), g.neg(s2));
    }

    /// `cos x·cos y − sin x·sin y` is `cos(x + y)`, `sin x·cos y + cos x·sin y`
    /// is `sin(x + y)`, and a pair whose coefficients differ is left alone.
    #[test]
    fn sums_of_angles_are_joined_and_unequal_pairs_left() {
        let mut g = Graph::new();
        let [x, y, sx, cx, sy, cy] = two_angles(&mut g);
        let xy = g.add2(x, y);
        let (cc, ss, sc, cs) = (
            g.mul2(cx, cy),
            g.mul2(sx, sy),
            g.mul2(sx, cy),
            g.mul2(cx, sy),
        );
        let e = g.sub(cc, ss);
        assert_eq!(join(&mut g, e), g.func(Func::Cos, xy));
        let e = g.add2(sc, cs);
        assert_eq!(join(&mut g, e), g.func(Func::Sin, xy));
        let twice = g.scale(cs, Num::int(2));
        let e = g.add2(sc, twice);
        assert_eq!(join(&mut g, e), e);
    }

    /// The Pythagorean pass alone (the forces' beside a written `M` or
    /// bodies) leaves a pair of the addition theorem as it is.
    #[test]
    fn the_pythagorean_pass_does_not_join_angles() {
        let mut g = Graph::new();
        let [x, y, sx, cx, sy, cy] = two_angles(&mut g);
        let (cc, ss) = (g.mul2(cx, cy), g.mul2(sx, sy));
        let e = g.add2(cc, ss);
        assert_eq!(simplify(&mut g, e), e);
        let difference = g.sub(x, y);
        assert_eq!(join(&mut g, e), g.func(Func::Cos, difference));
    }
}
