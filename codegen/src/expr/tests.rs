//! The canonical rules, one line a rule.

use super::*;

fn xyz(g: &mut Graph) -> (Id, Id, Id) {
    (
        g.sym(Sym::Coord(0)),
        g.sym(Sym::Coord(1)),
        g.sym(Sym::Coord(2)),
    )
}

/// One line a rule: the two sides must be the same node.
macro_rules! same {
    ($g:ident, $lhs:expr, $rhs:expr) => {{
        let (l, r) = ($lhs, $rhs);
        assert_eq!(l, r, "{:?} vs {:?}", $g.node(l), $g.node(r));
    }};
}

#[test]
fn canonical_rules() {
    let mut g = Graph::new();
    let (x, y, z) = xyz(&mut g);
    let zero = g.int(0);
    let one = g.int(1);
    let two = g.int(2);
    same!(g, g.add(&[x, zero]), x); // neutral element of +
    same!(g, g.mul(&[x, one]), x); // neutral element of ·
    same!(g, g.mul(&[x, zero]), zero); // absorbing element
    same!(g, g.add(&[x, y]), g.add(&[y, x])); // commutativity
    let xy = g.mul2(x, y);
    let yx = g.mul2(y, x);
    same!(g, xy, yx);
    let sum = g.add(&[x, y, z]);
    let left = g.add2(x, y);
    same!(g, g.add2(left, z), sum); // associativity
    let twox = g.scale(x, Num::int(2));
    same!(g, g.add(&[x, x]), twox); // collect like terms
    let sq = g.pown(x, Num::int(2));
    same!(g, g.mul(&[x, x]), sq); // collect powers
    same!(g, g.sub(x, x), zero);
    same!(g, g.div(x, x), one);
    let half = g.num(Num::ratio(1, 2));
    let hx = g.mul2(half, x);
    same!(g, g.add2(hx, hx), x); // exact rationals
    let three = g.int(3);
    same!(g, g.add2(one, two), three); // constant folding
    let sx = g.sqrt(x);
    same!(g, g.mul2(sx, sx), x);
    let s2 = g.sqrt(two);
    same!(g, g.mul2(s2, s2), two);
    let sxy = g.mul2(twox, y); // (2x)·y = 2·(x·y)
    same!(g, sxy, g.scale(xy, Num::int(2)));
    let sq2 = g.pown(twox, Num::int(2)); // (2x)² = 4x²
    same!(g, sq2, g.scale(sq, Num::int(4)));
    let nx = g.neg(x);
    let sin_x = g.func(Func::Sin, x);
    same!(g, g.func(Func::Sin, nx), g.neg(sin_x)); // odd
    same!(g, g.func(Func::Cos, nx), g.func(Func::Cos, x)); // even
    let ex = g.func(Func::Exp, x);
    same!(g, g.func(Func::Ln, ex), x);
    same!(g, g.func(Func::Cos, zero), one);
    same!(g, g.pow(x, two), sq);
}

#[test]
fn substitution_rebuilds_canonically() {
    let mut g = Graph::new();
    let (x, y, _) = xyz(&mut g);
    let e = g.sub(x, y);
    let zero = g.int(0);
    let replaced = g.substitute(e, &|s| (s == Sym::Coord(1)).then_some(x));
    assert_eq!(replaced, zero);
}

#[test]
fn evaluation() {
    let mut g = Graph::new();
    let (x, y, _) = xyz(&mut g);
    let s = g.func(Func::Sin, x);
    let p = g.pown(y, Num::ratio(3, 2));
    let e = g.add2(s, p);
    let v = g.eval(&[e], &|s| match s {
        Sym::Coord(0) => 0.5,
        _ => 4.0,
    });
    assert!((v[0] - (0.5f64.sin() + 8.0)).abs() < 1e-15);
}

/// `c·X·sin²u + c·X·cos²u = c·X`, inside larger sums too; different
/// coefficients or arguments stay.
#[test]
fn pythagorean_identity() {
    let mut g = Graph::new();
    let (x, y, z) = xyz(&mut g);
    let one = g.int(1);
    let square = |g: &mut Graph, f: Func, a: Id| {
        let v = g.func(f, a);
        g.pown(v, Num::int(2))
    };
    let (s2, c2) = (square(&mut g, Func::Sin, x), square(&mut g, Func::Cos, x));
    same!(g, g.add(&[s2, c2]), one);
    let y2 = g.pown(y, Num::int(2));
    let (a, b) = (g.mul(&[y2, s2]), g.mul(&[y2, c2]));
    let sum = g.linear_combination([(a, Num::int(3)), (b, Num::int(3)), (z, Num::ONE)]);
    let expected = g.linear_combination([(y2, Num::int(3)), (z, Num::ONE)]);
    same!(g, sum, expected);
    // Not an identity: other coefficients, other arguments.
    let uneven = g.linear_combination([(s2, Num::int(2)), (c2, Num::ONE)]);
    assert!(matches!(g.node(uneven), Node::Add(..)));
    let cy2 = square(&mut g, Func::Cos, y);
    let mixed = g.add(&[s2, cy2]);
    assert!(matches!(g.node(mixed), Node::Add(..)));
}
