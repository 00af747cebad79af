//! Exact symbolic differentiation on the DAG, and the total time derivative.

use crate::expr::num::Num;
use crate::expr::{FastHash, Func, Graph, Id, Node, Sym};
use std::collections::HashMap;

/// Memoised partial derivatives `∂e/∂v`; one per graph, reused across calls so
/// that shared subexpressions are differentiated once.
#[derive(Default)]
pub struct Differentiator {
    memo: HashMap<(Id, Sym), Id, FastHash>,
}

impl Differentiator {
    /// A differentiator with an empty memo.
    pub fn new() -> Differentiator {
        Differentiator::default()
    }

    /// `∂e/∂v`.
    pub fn partial(&mut self, g: &mut Graph, e: Id, v: Sym) -> Id {
        if let Some(&d) = self.memo.get(&(e, v)) {
            return d;
        }
        let d = self.partial_uncached(g, e, v);
        self.memo.insert((e, v), d);
        d
    }

    fn partial_uncached(&mut self, g: &mut Graph, e: Id, v: Sym) -> Id {
        derive(&mut PartialBy { d: self, v }, g, e)
    }

    /// The total time derivative of `e(q, q̇, t)` split as `D e = Σⱼ rowⱼ·q̈ⱼ + rest`:
    /// `rowⱼ = ∂e/∂q̇ⱼ` and `rest = Σⱼ ∂e/∂qⱼ·q̇ⱼ + ∂e/∂t`.
    /// `D e` is affine in `q̈` because `e` has no `q̈`.
    pub fn time_derivative(&mut self, g: &mut Graph, e: Id, n: usize) -> (Vec<Id>, Id) {
        let row: Vec<Id> = (0..n).map(|j| self.partial(g, e, Sym::Vel(j))).collect();
        let mut rest: Vec<Id> = Vec::with_capacity(n + 1);
        for j in 0..n {
            let dq = self.partial(g, e, Sym::Coord(j));
            let qd = g.sym(Sym::Vel(j));
            rest.push(g.mul2(dq, qd));
        }
        rest.push(self.partial(g, e, Sym::Time));
        (row, g.add(&rest))
    }
}

/// One rule of differentiation: how the derivative of a child is had, and
/// what the derivative of a variable is.
trait Rule {
    /// The derivative of `e`, memoised by the implementation.
    fn of(&mut self, g: &mut Graph, e: Id) -> Id;
    /// The derivative of the variable `s`.
    fn leaf(&self, g: &mut Graph, s: Sym) -> Id;
}

/// `∂/∂v`.
struct PartialBy<'a> {
    d: &'a mut Differentiator,
    v: Sym,
}

impl Rule for PartialBy<'_> {
    fn of(&mut self, g: &mut Graph, e: Id) -> Id {
        self.d.partial(g, e, self.v)
    }
    fn leaf(&self, g: &mut Graph, s: Sym) -> Id {
        g.int(i64::from(s == self.v))
    }
}

/// The derivative of `e` by the sum, product, power and chain rules, each
/// child's derivative from `d`.
fn derive(d: &mut impl Rule, g: &mut Graph, e: Id) -> Id {
    match g.node(e).clone() {
        Node::Num(_) => g.int(0),
        Node::Sym(s) => d.leaf(g, s),
        Node::Add(terms, _) => {
            let items: Vec<(Id, Num)> = terms.iter().map(|&(t, c)| (d.of(g, t), c)).collect();
            g.linear_combination(items)
        }
        // ∂(Π bᵢ^eᵢ) = Σᵢ eᵢ·∂bᵢ · bᵢ^(eᵢ−1) · Π_{j≠i} bⱼ^eⱼ
        Node::Mul(factors) => {
            let mut terms = Vec::with_capacity(factors.len());
            for (i, &(b, k)) in factors.iter().enumerate() {
                let db = d.of(g, b);
                if g.is_zero(db) {
                    continue;
                }
                let mut items: Vec<(Id, Num)> = factors.to_vec();
                items[i].1 = k + Num::MINUS_ONE;
                items.push((db, Num::ONE));
                let term = g.product(items);
                terms.push((term, k));
            }
            g.linear_combination(terms)
        }
        // ∂(b^p) = b^p · (∂p·ln b + p·∂b / b)
        Node::Pow([b, p]) => {
            let (db, dp) = (d.of(g, b), d.of(g, p));
            if g.is_zero(db) && g.is_zero(dp) {
                return g.int(0);
            }
            let ln_b = g.func(Func::Ln, b);
            let t1 = g.mul2(dp, ln_b);
            let t2 = g.product([(p, Num::ONE), (db, Num::ONE), (b, Num::MINUS_ONE)]);
            let inner = g.add2(t1, t2);
            g.mul2(e, inner)
        }
        // The chain rule over the table's partial derivatives:
        // ∂f(a₁, …) = Σᵢ ∂f/∂aᵢ · ∂aᵢ. Where every ∂aᵢ is zero the result
        // is zero even where f′ is singular (`asin(1)`), so the partials
        // are not even built.
        Node::Func(Func::Hold, args) => held(d, g, args.as_slice()[0]),
        Node::Func(f, args) => {
            let inner: Vec<Id> = args.as_slice().iter().map(|&a| d.of(g, a)).collect();
            if inner.iter().all(|&d| g.is_zero(d)) {
                return g.int(0);
            }
            let partials = f.partials(g, args.as_slice(), e);
            let mut terms: Vec<(Id, Num)> = Vec::with_capacity(inner.len());
            for (&outer, &d) in partials.as_slice().iter().zip(&inner) {
                if !g.is_zero(d) {
                    terms.push((g.mul2(outer, d), Num::ONE));
                }
            }
            g.linear_combination(terms)
        }
    }
}

/// The derivative of `hold(x)`. A held sum's derivative is held too where
/// it is a sum: what keeps the recursions' expressions O(n)
/// (`crate::bodies::spatial::hold`) keeps their derivatives so, rather than
/// copying the terms of each derivative into every product that scales it.
fn held(d: &mut impl Rule, g: &mut Graph, x: Id) -> Id {
    let inner = d.of(g, x);
    g.hold(inner)
}

/// Forward mode: the directional derivative `Σᵢ sᵢ·∂e/∂vᵢ` along the seeds
/// `Sym::Seed(i)` of the variables `vᵢ`. One derivative node per node of
/// `e`, however many variables: the Jacobian's columns are then the
/// directions `sᵢ = δᵢc` at run time, rather than one expression per column.
pub struct Directional {
    memo: HashMap<Id, Id, FastHash>,
    seeds: HashMap<Sym, usize>,
}

impl Directional {
    /// Derivatives along the seeds of `variables` (`Sym::Seed(i)` for
    /// `variables[i]`); other variables are constants.
    pub fn new(variables: &[Sym]) -> Directional {
        Directional {
            memo: HashMap::default(),
            seeds: variables.iter().enumerate().map(|(i, &v)| (v, i)).collect(),
        }
    }

    /// `Σᵢ sᵢ·∂e/∂vᵢ`.
    pub fn derivative(&mut self, g: &mut Graph, e: Id) -> Id {
        if let Some(&d) = self.memo.get(&e) {
            return d;
        }
        let d = derive(self, g, e);
        self.memo.insert(e, d);
        d
    }
}

impl Rule for Directional {
    fn of(&mut self, g: &mut Graph, e: Id) -> Id {
        self.derivative(g, e)
    }
    fn leaf(&self, g: &mut Graph, s: Sym) -> Id {
        match self.seeds.get(&s) {
            Some(&i) => g.sym(Sym::Seed(i)),
            None => g.int(0),
        }
    }
}

/// Forward mode along the motion with `q̈ = 0`: `D₀ e = Σⱼ ∂e/∂qⱼ·q̇ⱼ +
/// ∂e/∂t` for `e(q, t)`, and for `e(q, q̇, t)` the same with `q̇` held
/// (the part of `D e` without `q̈`). One derivative node per node of `e`,
/// by the product and chain rules over `e`'s own structure: the second
/// derivative of a point of a chain `p = R(q)·r(q)` stays
/// `R̈₀ r + 2 Ṙ ṙ + R r̈₀` rather than the `Σᵢⱼ ∂²p/∂qᵢ∂qⱼ·q̇ᵢq̇ⱼ` of
/// [`Differentiator::time_derivative`]'s partials.
#[derive(Default)]
pub struct AtRest {
    memo: HashMap<Id, Id, FastHash>,
}

impl AtRest {
    /// `D₀ e`.
    pub fn derivative(&mut self, g: &mut Graph, e: Id) -> Id {
        if let Some(&d) = self.memo.get(&e) {
            return d;
        }
        let d = derive(self, g, e);
        self.memo.insert(e, d);
        d
    }
}

impl Rule for AtRest {
    fn of(&mut self, g: &mut Graph, e: Id) -> Id {
        self.derivative(g, e)
    }
    fn leaf(&self, g: &mut Graph, s: Sym) -> Id {
        match s {
            Sym::Coord(j) => g.sym(Sym::Vel(j)),
            Sym::Time => g.int(1),
            _ => g.int(0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Table test: d/dx of each function of one argument at x = 0.3 against
    /// its known value, written out here independently of the table.
    #[test]
    fn derivative_table() {
        let x0: f64 = 0.3;
        let cases = [
            (Func::Sin, x0.cos()),
            (Func::Cos, -x0.sin()),
            (Func::Tan, 1.0 / x0.cos().powi(2)),
            (Func::Asin, 1.0 / (1.0 - x0 * x0).sqrt()),
            (Func::Acos, -1.0 / (1.0 - x0 * x0).sqrt()),
            (Func::Atan, 1.0 / (1.0 + x0 * x0)),
            (Func::Sinh, x0.cosh()),
            (Func::Cosh, x0.sinh()),
            (Func::Tanh, 1.0 - x0.tanh().powi(2)),
            (Func::Exp, x0.exp()),
            (Func::Ln, 1.0 / x0),
            (Func::Abs, 1.0),
            (Func::Signum, 0.0),
            (Func::Step, 0.0),
            (Func::Hold, 1.0),
        ];
        let unary = Func::ALL.iter().filter(|f| f.arity() == 1).count();
        assert_eq!(
            cases.len(),
            unary,
            "every function of one argument has a case"
        );
        for (f, expected) in cases {
            let mut g = Graph::new();
            let x = g.sym(Sym::Coord(0));
            let e = g.func(f, x);
            let d = Differentiator::new().partial(&mut g, e, Sym::Coord(0));
            let v = g.eval(&[d], &|_| x0)[0];
            assert!((v - expected).abs() < 1e-14, "{f:?}: {v} vs {expected}");
        }
    }

    /// At a kink the derivative is the one of the branch the value is
    /// taken from: `abs(x) = x` for `x ≥ 0`; `min(a, b) = a` for `a ≤ b`,
    /// `max(a, b) = a` for `a ≥ b`. Away from kinks, the ordinary ones.
    #[test]
    fn kinks_take_the_derivative_of_their_branch() {
        let mut g = Graph::new();
        let (x, y) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let abs = g.func(Func::Abs, x);
        let min = g.apply(Func::Min, crate::expr::Args::two(x, y));
        let max = g.apply(Func::Max, crate::expr::Args::two(x, y));
        let mut d = Differentiator::new();
        let mut partials = vec![d.partial(&mut g, abs, Sym::Coord(0))];
        for e in [min, max] {
            partials.push(d.partial(&mut g, e, Sym::Coord(0)));
            partials.push(d.partial(&mut g, e, Sym::Coord(1)));
        }
        // (x, y) → [abs′, ∂min/∂x, ∂min/∂y, ∂max/∂x, ∂max/∂y]
        let cases: [((f64, f64), [f64; 5]); 4] = [
            ((0.0, 0.0), [1.0, 1.0, 0.0, 1.0, 0.0]),
            ((-0.5, 0.2), [-1.0, 1.0, 0.0, 0.0, 1.0]),
            ((0.5, 0.2), [1.0, 0.0, 1.0, 1.0, 0.0]),
            ((0.2, 0.2), [1.0, 1.0, 0.0, 1.0, 0.0]),
        ];
        for ((x0, y0), expected) in cases {
            let v = g.eval(&partials, &|s| if s == Sym::Coord(0) { x0 } else { y0 });
            assert_eq!(v, expected, "at ({x0}, {y0})");
        }
    }

    /// The derivative of a held sum is the held sum of the derivatives,
    /// with the value of the sum's derivative; a derivative that is one
    /// term is not held.
    #[test]
    fn held_sums_differentiate_into_held_sums() {
        let mut g = Graph::new();
        let (x, y) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let (xx, xy) = (g.mul2(x, x), g.mul2(x, y));
        let sum = g.add(&[xx, xy]);
        let held = g.func(Func::Hold, sum);
        let mut d = Differentiator::new();
        let (dx, dy) = (
            d.partial(&mut g, held, Sym::Coord(0)),
            d.partial(&mut g, held, Sym::Coord(1)),
        );
        assert!(
            matches!(g.node(dx), Node::Func(Func::Hold, _)),
            "2x + y is held"
        );
        assert_eq!(dy, x, "∂(x² + xy)/∂y is x alone");
        let v = g.eval(&[dx], &|s| if s == Sym::Coord(0) { 0.7 } else { -1.3 });
        assert!((v[0] - (2.0 * 0.7 - 1.3)).abs() < 1e-15, "{v:?}");
    }

    #[test]
    fn atan2_and_pow() {
        let mut g = Graph::new();
        let (x, y) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let a = g.apply(Func::Atan2, crate::expr::Args::two(y, x));
        let p = g.pow(x, y);
        let mut d = Differentiator::new();
        let (dax, day) = (
            d.partial(&mut g, a, Sym::Coord(0)),
            d.partial(&mut g, a, Sym::Coord(1)),
        );
        let (dpx, dpy) = (
            d.partial(&mut g, p, Sym::Coord(0)),
            d.partial(&mut g, p, Sym::Coord(1)),
        );
        let (x0, y0): (f64, f64) = (1.3, 0.7);
        let v = g.eval(&[dax, day, dpx, dpy], &|s| {
            if s == Sym::Coord(0) {
                x0
            } else {
                y0
            }
        });
        let r2 = x0 * x0 + y0 * y0;
        let expected = [
            -y0 / r2,
            x0 / r2,
            y0 * x0.powf(y0 - 1.0),
            x0.powf(y0) * x0.ln(),
        ];
        for (a, b) in v.iter().zip(expected) {
            assert!((a - b).abs() < 1e-14, "{a} vs {b}");
        }
    }

    /// Appell's constraint: D[(ẋ² + ẏ² − ż²)/2] has row [ẋ, ẏ, −ż] and no rest.
    #[test]
    fn time_derivative_of_appell_constraint() {
        let mut g = Graph::new();
        let v: Vec<Id> = (0..3).map(|i| g.sym(Sym::Vel(i))).collect();
        let sq: Vec<Id> = v.iter().map(|&vi| g.pown(vi, Num::int(2))).collect();
        let half = Num::ratio(1, 2);
        let phi = g.linear_combination([(sq[0], half), (sq[1], half), (sq[2], -half)]);
        let (row, rest) = Differentiator::new().time_derivative(&mut g, phi, 3);
        let minus_zd = g.neg(v[2]);
        assert_eq!(row, vec![v[0], v[1], minus_zd]);
        assert!(g.is_zero(rest));
    }

    /// Forward mode at rest against the partials: a point of a two-link
    /// chain that also moves in time, `p = (l₁ cos q₀ + l₂ cos(q₀ + q₁)) ·
    /// (1 + t q₁)`: `D₀ p` equals the rest of `D p`, and `D₀ D₀ p` the rest
    /// of `D (D p)` (`b` of a position constraint), at several states; the
    /// forward form has fewer nodes than the partials'.
    #[test]
    fn at_rest_equals_the_partials_rest() {
        let mut g = Graph::new();
        let (q0, q1, t) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)), g.sym(Sym::Time));
        let (l1, l2) = (g.sym(Sym::Param(0)), g.sym(Sym::Param(1)));
        let c0 = g.func(Func::Cos, q0);
        let sum = g.add2(q0, q1);
        let c01 = g.func(Func::Cos, sum);
        let (a, b) = (g.mul2(l1, c0), g.mul2(l2, c01));
        let reach = g.add2(a, b);
        let tq = g.mul2(t, q1);
        let one = g.int(1);
        let grow = g.add2(one, tq);
        let p = g.mul2(reach, grow);
        let mut d = Differentiator::new();
        let (_, velocity) = d.time_derivative(&mut g, p, 2);
        let (_, bias) = d.time_derivative(&mut g, velocity, 2);
        let mut rest = AtRest::default();
        let forward_velocity = rest.derivative(&mut g, p);
        let forward_bias = rest.derivative(&mut g, forward_velocity);
        for k in 0..5 {
            let x = f64::from(k);
            let env = |s: Sym| match s {
                Sym::Coord(i) => 0.3 + 0.7 * x + f64::from(u32::try_from(i).unwrap_or(0)),
                Sym::Vel(i) => -0.4 + 0.2 * x - 0.9 * f64::from(u32::try_from(i).unwrap_or(0)),
                Sym::Time => 0.1 * x,
                Sym::Param(i) => 1.0 + f64::from(u32::try_from(i).unwrap_or(0)),
                _ => 0.0,
            };
            let v = g.eval(&[velocity, forward_velocity, bias, forward_bias], &env);
            assert!((v[0] - v[1]).abs() <= 1e-13 * (1.0 + v[0].abs()), "{v:?}");
            assert!((v[2] - v[3]).abs() <= 1e-12 * (1.0 + v[2].abs()), "{v:?}");
        }
        let size = |g: &Graph, e: Id| g.reachable(&[e]).len();
        assert!(size(&g, forward_bias) < size(&g, bias));
    }
}
