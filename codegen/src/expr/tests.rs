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

/// A sum as a factor gives up its content where that is a small ratio,
/// and only its sign where it is not: coefficients that are products of
/// decimals (a URDF's inertias and lengths) have contents like 10⁻³⁰, which
/// would leave constants near 10²⁵ in the sum and 10⁻³⁰ outside it, both
/// at the edge of `f32`'s range.
#[test]
fn contents_leave_a_sum_only_when_small() {
    let mut g = Graph::new();
    let (x, y, z) = xyz(&mut g);
    // g·(2y − 2z) and g·(−2y + 2z) collect: the content ±2 leaves.
    let (two, minus_two) = (Num::int(2), Num::int(-2));
    let d = g.linear_combination([(y, two), (z, minus_two)]);
    let nd = g.linear_combination([(y, minus_two), (z, two)]);
    let (p, n) = (g.mul2(x, d), g.mul2(x, nd));
    let zero = g.int(0);
    same!(g, g.add2(p, n), zero);
    let diff = g.sub(y, z);
    let xd = g.mul2(x, diff);
    same!(g, p, g.scale(xd, two));
    // Products of decimals, as a URDF's inertias and lengths give, exact
    // (their content is 2·10⁻²¹).
    let a = Num::ratio(34_145_541_730_514_034, 1_000_000_000_000_000_000_000);
    let b = Num::ratio(151_120_519_943_795_600, 1_000_000_000_000_000_000_000);
    let decimals = g.linear_combination([(y, a), (z, b)]);
    let product = g.mul2(x, decimals);
    let Node::Mul(factors) = g.node(product).clone() else {
        panic!("x times a sum is a product: {:?}", g.node(product));
    };
    assert!(
        factors.iter().any(|&(f, _)| f == decimals),
        "the sum stays whole in the product: {:?}",
        g.node(product)
    );
    let constants: Vec<f64> = g.constants().map(Num::to_f64).collect();
    let extreme: Vec<f64> = constants
        .iter()
        .copied()
        .filter(|v| *v != 0.0 && !(1e-12..=1e12).contains(&v.abs()))
        .collect();
    assert!(extreme.is_empty(), "constants out of range: {extreme:?}");
    // Its negation collects with it all the same: only the sign leaves.
    let minus = g.neg(decimals);
    let negated = g.mul2(x, minus);
    same!(g, g.add2(product, negated), zero);
}

/// A content leaves a sum under a power only where its power stays near 1
/// (`2^±64`): at x = 0.2, `(x + 5/4)^625` is 1.4e100 and `x / (x + 5/4)^625`
/// is 2.8e-102, where `4^−625 · (4x + 5)^625` made `0 · ∞ = NaN`; the
/// same for a one-term sum, `(x/4)^625` at x = 3. A small power still
/// splits: `(x/2 + y/2)²` is `¼ (x + y)²`.
#[test]
fn contents_leave_a_power_only_when_its_power_is_moderate() {
    let mut g = Graph::new();
    let (x, y, _) = xyz(&mut g);
    let at = |s: Sym| match s {
        Sym::Coord(0) => 0.2,
        Sym::Coord(1) => 3.0,
        _ => f64::NAN,
    };
    let quarter = g.num(Num::ratio(5, 4));
    let base = g.add2(x, quarter);
    let power = g.pown(base, Num::int(625));
    let ratio = g.div(x, power);
    let one_term = g.scale(y, Num::ratio(1, 4));
    let small = g.pown(one_term, Num::int(625));
    let values = g.eval(&[power, ratio, small], &at);
    let truth = [
        1.45_f64.powi(625),
        0.2 / 1.45_f64.powi(625),
        0.75_f64.powi(625),
    ];
    for (v, t) in values.iter().zip(truth) {
        assert!((v - t).abs() <= 1e-12 * t, "{v:e} against {t:e}");
    }
    let half = Num::ratio(1, 2);
    let halves = g.linear_combination([(x, half), (y, half)]);
    let squared = g.pown(halves, Num::int(2));
    let whole = g.add2(x, y);
    let whole_squared = g.pown(whole, Num::int(2));
    same!(g, squared, g.scale(whole_squared, Num::ratio(1, 4)));
}
