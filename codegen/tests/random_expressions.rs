//! Property tests of the symbolic core on randomly generated expressions:
//! canonical simplification preserves the value, and every symbolic
//! derivative agrees with a finite difference. The reference is a plain tree
//! evaluator written here, independent of the DAG.

use constrained_codegen::expr::diff::Differentiator;
use constrained_codegen::expr::num::Num;
use constrained_codegen::expr::{Args, Func, Graph, Id, Sym};
use proptest::prelude::*;

#[derive(Clone, Debug)]
enum Tree {
    Var(usize),
    Const(i64, i64),
    Add(Box<Tree>, Box<Tree>),
    Sub(Box<Tree>, Box<Tree>),
    Mul(Box<Tree>, Box<Tree>),
    Div(Box<Tree>, Box<Tree>),
    Neg(Box<Tree>),
    Powi(Box<Tree>, i64),
    Sqrt(Box<Tree>),
    Powf(Box<Tree>, Box<Tree>),
    Func(Func, Box<Tree>),
    Binary(Func, Box<Tree>, Box<Tree>),
}

impl Tree {
    /// The value, or NaN when any intermediate value is not finite (the
    /// expression is then outside its domain, e.g. `x / 0`). Zero carries no
    /// sign (`+ 0.0` turns −0 into +0): the symbolic core's numbers are
    /// exact, and `atan2(−0, −1) = −π` is an artefact of IEEE arithmetic.
    fn eval(&self, x: &[f64; 3]) -> f64 {
        let v = self.eval_node(x) + 0.0;
        if v.is_finite() {
            v
        } else {
            f64::NAN
        }
    }

    fn eval_node(&self, x: &[f64; 3]) -> f64 {
        match self {
            Tree::Var(i) => x[*i],
            Tree::Const(p, q) => *p as f64 / *q as f64,
            Tree::Add(a, b) => a.eval(x) + b.eval(x),
            Tree::Sub(a, b) => a.eval(x) - b.eval(x),
            Tree::Mul(a, b) => a.eval(x) * b.eval(x),
            // Points on the boundary of a function's real domain (√0, 0^p,
            // asin(±1), poles, …) are left out: the derivative does not exist
            // there. So are points within MARGIN of it, where the tree's own
            // rounding is amplified without bound: y⁻¹·y = 1 − 1.1e-16 put
            // asin 1.5e-8 from the graph's exact asin(1) = π/2, and
            // (−1/3 + 5/3 − 4/3)⁻¹, exactly 1/0, came out as 6e15.
            Tree::Div(a, b) => a.eval(x) / interior(b.eval(x), |v| v.abs() > MARGIN),
            Tree::Neg(a) => -a.eval(x),
            Tree::Powi(a, k) if *k < 0 => interior(a.eval(x), |v| v.abs() > MARGIN).powi(*k as i32),
            Tree::Powi(a, k) => a.eval(x).powi(*k as i32),
            Tree::Sqrt(a) => interior(a.eval(x), |v| v > MARGIN).sqrt(),
            // Not `powf` on a NaN base alone: IEEE gives NaN⁰ = 1, which let
            // a base outside the domain through whenever the exponent was 0.
            Tree::Powf(a, b) => match (interior(a.eval(x), |v| v > MARGIN), b.eval(x)) {
                (base, exponent) if base.is_nan() || exponent.is_nan() => f64::NAN,
                (base, exponent) => base.powf(exponent),
            },
            Tree::Func(f, a) => {
                let v = match f {
                    Func::Ln => interior(a.eval(x), |v| v > MARGIN),
                    // The argument's own rounding, |v| ε, is an absolute error
                    // of the result: sin(0.2⁻¹²) differed by 1.6e-8 between
                    // the two evaluators. And tan has poles.
                    Func::Sin | Func::Cos => interior(a.eval(x), |v| v.abs() < LARGEST_ANGLE),
                    Func::Tan => interior(a.eval(x), |v| {
                        v.abs() < LARGEST_ANGLE && v.cos().abs() > MARGIN
                    }),
                    Func::Asin | Func::Acos => interior(a.eval(x), |v| v.abs() < 1.0 - MARGIN),
                    // Kinks and jumps: differences straddling one mislead.
                    Func::Abs | Func::Signum => interior(a.eval(x), |v| v.abs() > MARGIN),
                    _ => a.eval(x),
                };
                match f {
                    Func::Sin => v.sin(),
                    Func::Cos => v.cos(),
                    Func::Tan => v.tan(),
                    Func::Asin => v.asin(),
                    Func::Acos => v.acos(),
                    Func::Atan => v.atan(),
                    Func::Sinh => v.sinh(),
                    Func::Cosh => v.cosh(),
                    Func::Tanh => v.tanh(),
                    Func::Exp => v.exp(),
                    Func::Ln => v.ln(),
                    Func::Abs => v.abs(),
                    Func::Signum => v.signum(),
                    Func::Step | Func::Hold | Func::Atan2 | Func::Min | Func::Max => {
                        unreachable!("not a DSL function of one argument: {f:?}")
                    }
                }
            }
            Tree::Binary(Func::Atan2, a, b) => {
                let (y, x) = (a.eval(x), b.eval(x));
                // The origin, and the branch cut y = 0, x < 0, where the value
                // jumps from π to −π with the sign of a zero (which the graph
                // keeps and this evaluator drops: 0 · (−1.4) = −0).
                if (y == 0.0 && x == 0.0) || (y.abs() <= MARGIN && x < 0.0) {
                    f64::NAN
                } else {
                    y.atan2(x)
                }
            }
            Tree::Binary(f, a, b) => {
                let (a, b) = (a.eval(x), b.eval(x));
                // The kink where the arguments tie; NaN stays NaN (which
                // `f64::min` would drop).
                let gap = (a - b).abs();
                if gap.is_nan() || gap <= MARGIN {
                    f64::NAN
                } else if *f == Func::Min {
                    a.min(b)
                } else {
                    a.max(b)
                }
            }
        }
    }

    fn build(&self, g: &mut Graph) -> Id {
        match self {
            Tree::Var(i) => g.sym(Sym::Coord(*i)),
            Tree::Const(p, q) => g.num(Num::ratio((*p).into(), (*q).into())),
            Tree::Add(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.add2(a, b)
            }
            Tree::Sub(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.sub(a, b)
            }
            Tree::Mul(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.mul2(a, b)
            }
            Tree::Div(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.div(a, b)
            }
            Tree::Neg(a) => {
                let a = a.build(g);
                g.neg(a)
            }
            Tree::Powi(a, k) => {
                let a = a.build(g);
                g.pown(a, Num::int(*k))
            }
            Tree::Sqrt(a) => {
                let a = a.build(g);
                g.sqrt(a)
            }
            Tree::Powf(a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.pow(a, b)
            }
            Tree::Func(f, a) => {
                let a = a.build(g);
                g.func(*f, a)
            }
            Tree::Binary(f, a, b) => {
                let (a, b) = (a.build(g), b.build(g));
                g.apply(*f, Args::two(a, b))
            }
        }
    }
}

/// `v` when `inside(v)`, NaN otherwise.
/// How far inside its real domain an argument must be to be evaluated.
const MARGIN: f64 = 1e-6;

/// The largest argument of a trigonometric function evaluated: beyond it the
/// rounding of the argument alone exceeds the comparison's tolerance.
const LARGEST_ANGLE: f64 = 1e4;

fn interior(v: f64, inside: impl Fn(f64) -> bool) -> f64 {
    if inside(v) {
        v
    } else {
        f64::NAN
    }
}

fn tree() -> impl Strategy<Value = Tree> {
    let leaf = prop_oneof![
        3 => (0..3usize).prop_map(Tree::Var),
        1 => (-5..=5i64, 1..=4i64).prop_map(|(p, q)| Tree::Const(p, q)),
    ];
    leaf.prop_recursive(5, 40, 2, |inner| {
        let b = |t: Tree| Box::new(t);
        prop_oneof![
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::Add(b(x), b(y))),
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::Sub(b(x), b(y))),
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::Mul(b(x), b(y))),
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::Div(b(x), b(y))),
            inner.clone().prop_map(move |x| Tree::Neg(b(x))),
            (inner.clone(), -3..=4i64).prop_map(move |(x, k)| Tree::Powi(b(x), k)),
            inner.clone().prop_map(move |x| Tree::Sqrt(b(x))),
            (inner.clone(), inner.clone()).prop_map(move |(x, y)| Tree::Powf(b(x), b(y))),
            (inner.clone(), prop::sample::select(unary_functions()))
                .prop_map(move |(x, f)| Tree::Func(f, b(x))),
            (
                inner.clone(),
                inner,
                prop::sample::select(vec![Func::Atan2, Func::Min, Func::Max])
            )
                .prop_map(move |(x, y, f)| Tree::Binary(f, b(x), b(y))),
        ]
    })
}

/// The DSL's functions of one argument (those of two have `Tree::Binary`).
fn unary_functions() -> Vec<Func> {
    Func::ALL
        .iter()
        .copied()
        .filter(|f| f.arity() == 1 && f.in_dsl())
        .collect()
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(0.2..0.9f64)
}

fn env(x: [f64; 3]) -> impl Fn(Sym) -> f64 {
    move |s| match s {
        Sym::Coord(i) => x[i],
        _ => f64::NAN,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn simplification_preserves_value(t in tree(), x in point()) {
        let expected = t.eval(&x);
        prop_assume!(expected.is_finite() && expected.abs() < 1e8);
        let mut g = Graph::new();
        let id = t.build(&mut g);
        let actual = g.eval(&[id], &env(x))[0];
        prop_assert!(
            (actual - expected).abs() <= 1e-9 * expected.abs().max(1.0),
            "{t:?} at {x:?}: graph {actual} vs tree {expected}"
        );
    }

    #[test]
    fn derivatives_agree_with_finite_differences(t in tree(), x in point(), var in 0..3usize) {
        let f = |h: f64| {
            let mut y = x;
            y[var] += h;
            t.eval(&y)
        };
        let central = |h: f64| (f(h) - f(-h)) / (2.0 * h);
        let (coarse, fine) = (central(1e-4), central(5e-5));
        // Richardson extrapolation; skip points where f is not smooth at this
        // scale (near a pole or a branch point), where differences mislead.
        let fd = (4.0 * fine - coarse) / 3.0;
        // |f| must be moderate too: f(x ± h) of size 1e54 cancel to nothing.
        prop_assume!(fd.is_finite() && fd.abs() < 1e6 && f(0.0).abs() < 1e6);
        prop_assume!((fine - coarse).abs() < 1e-3 * fd.abs().max(1.0));
        let mut g = Graph::new();
        let id = t.build(&mut g);
        let d = Differentiator::new().partial(&mut g, id, Sym::Coord(var));
        let symbolic = g.eval(&[d], &env(x))[0];
        prop_assert!(
            (symbolic - fd).abs() <= 1e-5 * fd.abs().max(1.0),
            "d/dx{var} of {t:?} at {x:?}: symbolic {symbolic} vs finite difference {fd}"
        );
    }
}
