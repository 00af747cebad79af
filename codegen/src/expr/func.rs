//! The operator table: every elementary function of the DSL, declared once.
//!
//! An entry gives the function's DSL name (also the name of the Rust method
//! that generated code calls on `T: RealField`, receiver first), its sympy
//! name, its arity, its value in `f64`, its partial derivatives as
//! expressions, and the algebraic facts the canonicalising constructor uses
//! (parity, exact value at zero, the function it inverts). Every walker —
//! lowering, substitution, evaluation, differentiation, printing, emission —
//! reads the table, so adding a function is one entry here (egg's
//! `define_language!`).

use super::{Graph, Id};
use crate::expr::num::Num;

/// The arguments of a function node: up to two, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Args {
    ids: [Id; 2],
    len: u8,
}

impl Args {
    /// One argument.
    pub fn one(a: Id) -> Args {
        Args {
            ids: [a, a],
            len: 1,
        }
    }

    /// Two arguments.
    pub fn two(a: Id, b: Id) -> Args {
        Args {
            ids: [a, b],
            len: 2,
        }
    }

    /// Arguments from a slice of one or two.
    pub fn from_slice(ids: &[Id]) -> Option<Args> {
        match *ids {
            [a] => Some(Args::one(a)),
            [a, b] => Some(Args::two(a, b)),
            _ => None,
        }
    }

    /// The arguments in order.
    pub fn as_slice(&self) -> &[Id] {
        &self.ids[..usize::from(self.len)]
    }

    /// The arguments with `f` applied to each.
    pub fn map(&self, mut f: impl FnMut(Id) -> Id) -> Args {
        let mut out = *self;
        for id in out.ids.iter_mut().take(usize::from(self.len)) {
            *id = f(*id);
        }
        out
    }
}

/// How a function of one argument treats `−x`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parity {
    /// `f(−x) = −f(x)`.
    Odd,
    /// `f(−x) = f(x)`.
    Even,
    /// Neither (or more than one argument).
    None,
}

/// Whether a function of the table can be written in the DSL.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// Users write it.
    Dsl,
    /// Only derivatives produce it.
    Internal,
}

/// How generated code calls a function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Emission {
    /// `receiver.name(rest…)`, a method of `RealField` / `ComplexField`.
    Method,
    /// `::constrained::__private::name(args…)`, where the method's
    /// convention differs from the table's (`f64::signum(0.0)` is 1).
    Helper,
}

macro_rules! functions {
    ($(
        $(#[doc = $doc:literal])*
        $variant:ident: $name:literal / $sympy:literal, $arity:literal, $dsl:ident, $emit:ident {
            eval: |$x:ident| $eval:expr,
            exact: |$n:ident| $exact:expr,
            partials: |$g:ident, $a:ident, $fa:ident| $partials:expr,
            parity: $parity:ident,
            at_zero: $zero:expr,
            inverse: $inverse:expr,
            differentiable: $differentiable:expr $(,)?
        }
    )*) => {
        /// An elementary function of the DSL (one entry of the table).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Func {
            $( $(#[doc = $doc])* $variant, )*
        }

        impl Func {
            /// Every function, in table order.
            pub const ALL: &'static [Func] = &[$(Func::$variant),*];

            /// Whether users may call the function in the DSL (the others
            /// appear only in derivatives, e.g. `step` in `max′`).
            pub fn in_dsl(self) -> bool {
                match self { $(Func::$variant => Visibility::$dsl == Visibility::Dsl,)* }
            }

            /// How generated code calls the function.
            pub fn emission(self) -> Emission {
                match self { $(Func::$variant => Emission::$emit,)* }
            }

            /// The exact value at rational arguments, when it is rational
            /// (`abs(−2) = 2`, `max(1/2, 1/3) = 1/2`).
            pub fn exact(self, args: &[Num]) -> Option<Num> {
                match self { $(Func::$variant => { let $n = args; $exact })* }
            }

            /// The DSL name, which is also the Rust method generated code
            /// calls (`x.sin()`, `y.atan2(x)`).
            pub fn name(self) -> &'static str {
                match self { $(Func::$variant => $name,)* }
            }

            /// The name sympy knows the function by, or a template in
            /// which `{}` stands for the arguments.
            fn sympy_template(self) -> &'static str {
                match self { $(Func::$variant => $sympy,)* }
            }

            /// The call in sympy syntax, given the printed arguments.
            pub fn sympy_call(self, args: &str) -> String {
                let template = self.sympy_template();
                if template.contains("{}") {
                    template.replace("{}", args)
                } else {
                    format!("{template}({args})")
                }
            }

            /// The number of arguments (a method's receiver is the first).
            pub fn arity(self) -> usize {
                match self { $(Func::$variant => $arity,)* }
            }

            /// The value at `args` (of length [`arity`](Self::arity)) in `f64`.
            pub fn eval(self, args: &[f64]) -> f64 {
                match self { $(Func::$variant => { let $x = args; $eval })* }
            }

            /// `∂f/∂argᵢ` for each argument, as expressions; `fa` is the
            /// node `f(args)` itself (so that `exp′ = exp` reuses it).
            pub fn partials(self, g: &mut Graph, args: &[Id], fa: Id) -> Args {
                match self { $(Func::$variant => { let ($g, $a, $fa) = (&mut *g, args, fa); $partials })* }
            }

            /// `f(−x)` through `f(x)`, for functions of one argument.
            pub fn parity(self) -> Parity {
                match self { $(Func::$variant => Parity::$parity,)* }
            }

            /// `f(0)` when it is an exact rational.
            pub fn at_zero(self) -> Option<Num> {
                match self { $(Func::$variant => $zero,)* }
            }

            /// `g` such that `f(g(x)) = x` wherever `f(g(x))` is defined.
            pub fn inverse_of(self) -> Option<Func> {
                match self { $(Func::$variant => $inverse,)* }
            }

            /// The function with this DSL name (functions users can call only).
            pub fn from_name(name: &str) -> Option<Func> {
                Func::ALL.iter().copied().find(|f| f.in_dsl() && f.name() == name)
            }

            /// How many times the function can be differentiated along a
            /// trajectory where its arguments vary: `abs`, `min`, `max` have
            /// a kink (one derivative, one-sided there), `signum` and `step`
            /// jump (none); `None` for functions smooth where defined.
            pub fn differentiable_times(self) -> Option<usize> {
                match self { $(Func::$variant => $differentiable,)* }
            }
        }
    };
}

functions! {
    /// sine
    Sin: "sin" / "sin", 1, Dsl, Method {
        eval: |x| x[0].sin(),
        exact: |_n| None,
        partials: |g, a, _fa| Args::one(g.func(Func::Cos, a[0])),
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None, differentiable: None,
    }
    /// cosine
    Cos: "cos" / "cos", 1, Dsl, Method {
        eval: |x| x[0].cos(),
        exact: |_n| None,
        partials: |g, a, _fa| {
            let s = g.func(Func::Sin, a[0]);
            Args::one(g.neg(s))
        },
        parity: Even, at_zero: Some(Num::ONE), inverse: None, differentiable: None,
    }
    /// tangent: `tan′ = 1 + tan²`
    Tan: "tan" / "tan", 1, Dsl, Method {
        eval: |x| x[0].tan(),
        exact: |_n| None,
        partials: |g, _a, fa| {
            let (one, t2) = (g.int(1), g.pown(fa, Num::int(2)));
            Args::one(g.add2(one, t2))
        },
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None, differentiable: None,
    }
    /// arcsine: `1/√(1 − x²)`
    Asin: "asin" / "asin", 1, Dsl, Method {
        eval: |x| x[0].asin(),
        exact: |_n| None,
        partials: |g, a, _fa| Args::one(inverse_root_of_one_minus_square(g, a[0])),
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None, differentiable: None,
    }
    /// arccosine: `−1/√(1 − x²)`
    Acos: "acos" / "acos", 1, Dsl, Method {
        eval: |x| x[0].acos(),
        exact: |_n| None,
        partials: |g, a, _fa| {
            let d = inverse_root_of_one_minus_square(g, a[0]);
            Args::one(g.neg(d))
        },
        parity: None, at_zero: None, inverse: None, differentiable: None,
    }
    /// arctangent: `1/(1 + x²)`
    Atan: "atan" / "atan", 1, Dsl, Method {
        eval: |x| x[0].atan(),
        exact: |_n| None,
        partials: |g, a, _fa| {
            let (one, a2) = (g.int(1), g.pown(a[0], Num::int(2)));
            let d = g.add2(one, a2);
            Args::one(g.pown(d, Num::MINUS_ONE))
        },
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None, differentiable: None,
    }
    /// hyperbolic sine
    Sinh: "sinh" / "sinh", 1, Dsl, Method {
        eval: |x| x[0].sinh(),
        exact: |_n| None,
        partials: |g, a, _fa| Args::one(g.func(Func::Cosh, a[0])),
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None, differentiable: None,
    }
    /// hyperbolic cosine
    Cosh: "cosh" / "cosh", 1, Dsl, Method {
        eval: |x| x[0].cosh(),
        exact: |_n| None,
        partials: |g, a, _fa| Args::one(g.func(Func::Sinh, a[0])),
        parity: Even, at_zero: Some(Num::ONE), inverse: None, differentiable: None,
    }
    /// hyperbolic tangent: `tanh′ = 1 − tanh²`
    Tanh: "tanh" / "tanh", 1, Dsl, Method {
        eval: |x| x[0].tanh(),
        exact: |_n| None,
        partials: |g, _a, fa| {
            let (one, t2) = (g.int(1), g.pown(fa, Num::int(2)));
            Args::one(g.sub(one, t2))
        },
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None, differentiable: None,
    }
    /// exponential: `exp′ = exp`
    Exp: "exp" / "exp", 1, Dsl, Method {
        eval: |x| x[0].exp(),
        exact: |_n| None,
        partials: |_g, _a, fa| Args::one(fa),
        parity: None, at_zero: Some(Num::ONE), inverse: Some(Func::Ln), differentiable: None,
    }
    /// natural logarithm: `1/x`
    Ln: "ln" / "log", 1, Dsl, Method {
        eval: |x| x[0].ln(),
        exact: |_n| None,
        partials: |g, a, _fa| Args::one(g.pown(a[0], Num::MINUS_ONE)),
        parity: None, at_zero: None, inverse: Some(Func::Exp), differentiable: None,
    }
    /// two-argument arctangent `atan2(y, x)`: `∂/∂y = x/(x² + y²)`,
    /// `∂/∂x = −y/(x² + y²)`
    Atan2: "atan2" / "atan2", 2, Dsl, Method {
        eval: |x| x[0].atan2(x[1]),
        exact: |_n| None,
        partials: |g, a, _fa| {
            let (y, x) = (a[0], a[1]);
            let (x2, y2) = (g.pown(x, Num::int(2)), g.pown(y, Num::int(2)));
            let r2 = g.add2(x2, y2);
            let by_y = g.div(x, r2);
            let q = g.div(y, r2);
            Args::two(by_y, g.neg(q))
        },
        parity: None, at_zero: None, inverse: None, differentiable: None,
    }
    /// absolute value; `abs′(x) = 1` for `x ≥ 0` and `−1` below (at the
    /// kink, the derivative of the branch `abs` takes there)
    Abs: "abs" / "Abs", 1, Dsl, Method {
        eval: |x| x[0].abs(),
        exact: |n| Some(if n[0].is_negative() { -n[0] } else { n[0] }),
        partials: |g, a, _fa| {
            let h = g.func(Func::Step, a[0]);
            let two_h = g.scale(h, Num::int(2));
            let one = g.int(1);
            Args::one(g.sub(two_h, one))
        },
        parity: Even, at_zero: Some(Num::ZERO), inverse: None, differentiable: Some(1),
    }
    /// sign: `1`, `−1`, and `0` at `0` (sympy's `sign`, not `f64::signum`);
    /// derivative `0`
    Signum: "signum" / "sign", 1, Dsl, Helper {
        eval: |x| if x[0] > 0.0 { 1.0 } else if x[0] < 0.0 { -1.0 } else { x[0] * 0.0 },
        exact: |n| Some(if n[0].is_negative() { Num::MINUS_ONE } else if n[0].is_zero() { Num::ZERO } else { Num::ONE }),
        partials: |g, _a, _fa| Args::one(g.int(0)),
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None, differentiable: Some(0),
    }
    /// `min(a, b)`, which is `a` when `a ≤ b`: `∂/∂a = step(b − a)`,
    /// `∂/∂b = 1 − step(b − a)`
    Min: "min" / "Min", 2, Dsl, Method {
        eval: |x| if x[0] <= x[1] { x[0] } else if x[1] < x[0] { x[1] } else { f64::NAN },
        exact: |n| Some(if n[0] <= n[1] { n[0] } else { n[1] }),
        partials: |g, a, _fa| {
            let d = g.sub(a[1], a[0]);
            first_argument_branch(g, d)
        },
        parity: None, at_zero: None, inverse: None, differentiable: Some(1),
    }
    /// `max(a, b)`, which is `a` when `a ≥ b`: `∂/∂a = step(a − b)`,
    /// `∂/∂b = 1 − step(a − b)`
    Max: "max" / "Max", 2, Dsl, Method {
        eval: |x| if x[0] >= x[1] { x[0] } else if x[1] > x[0] { x[1] } else { f64::NAN },
        exact: |n| Some(if n[0] >= n[1] { n[0] } else { n[1] }),
        partials: |g, a, _fa| {
            let d = g.sub(a[0], a[1]);
            first_argument_branch(g, d)
        },
        parity: None, at_zero: None, inverse: None, differentiable: Some(1),
    }
    /// unit step, `1` for `x ≥ 0` and `0` below (sympy's `Heaviside(x, 1)`);
    /// only derivatives produce it
    Step: "step" / "Heaviside({}, 1)", 1, Internal, Helper {
        eval: |x| if x[0] >= 0.0 { 1.0 } else if x[0] < 0.0 { 0.0 } else { f64::NAN },
        exact: |n| Some(if n[0].is_negative() { Num::ZERO } else { Num::ONE }),
        partials: |g, _a, _fa| Args::one(g.int(0)),
        parity: None, at_zero: Some(Num::ONE), inverse: None, differentiable: Some(0),
    }
    /// the identity, kept as a node: a sum under it is one operand that
    /// constant factors do not distribute into (the rigid-body recursions
    /// hold each body's spatial quantities, so that `c·(a + b)` costs one
    /// product rather than one per term, and the expressions stay O(n));
    /// emitted and printed as its argument
    Hold: "hold" / "({})", 1, Internal, Helper {
        eval: |x| x[0],
        exact: |n| Some(n[0]),
        partials: |g, _a, _fa| Args::one(g.int(1)),
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None, differentiable: None,
    }
}

/// `(step(d), 1 − step(d))`: the partials of `min`/`max`, whose value is
/// their first argument exactly where `d ≥ 0`.
fn first_argument_branch(g: &mut Graph, d: Id) -> Args {
    let h = g.func(Func::Step, d);
    let one = g.int(1);
    let rest = g.sub(one, h);
    Args::two(h, rest)
}

/// `(1 − a²)^(−1/2)`, shared by `asin′` and `acos′`.
fn inverse_root_of_one_minus_square(g: &mut Graph, a: Id) -> Id {
    let (one, a2) = (g.int(1), g.pown(a, Num::int(2)));
    let d = g.sub(one, a2);
    g.pown(d, Num::ratio(-1, 2))
}

/// The methods generated code calls for a power `b^e` (`crate::emit`'s
/// bodies): `sqrt` for `e = 1/2`, `powi` for an integer, `powf` otherwise.
/// With the operator table's names, every function a generated body calls.
pub const POWER_METHODS: &[&str] = &["sqrt", "powi", "powf"];

#[cfg(test)]
mod tests {
    use super::Func;
    use crate::model::lower::ALGEBRAIC;
    use std::collections::BTreeSet;

    /// The names in the first column of the function table of
    /// `docs/dsl.md` (`sin cos …`, `atan2(y, x)`, `sqrt(x)`, `powi(x, k)`).
    fn documented() -> BTreeSet<String> {
        let dsl = include_str!("../../../docs/dsl.md");
        let table = dsl
            .split("| function | meaning |")
            .nth(1)
            .and_then(|rest| rest.split("\n\n").next())
            .unwrap_or_default();
        let mut names = BTreeSet::new();
        for row in table.lines().skip(2) {
            let first = row.split('|').nth(1).unwrap_or_default();
            for code in first.split('`').skip(1).step_by(2) {
                let head = code.split('(').next().unwrap_or_default();
                names.extend(head.split_whitespace().map(str::to_string));
            }
        }
        names
    }

    /// The docs' table lists exactly the DSL's functions: the operator
    /// table's user-facing entries and the algebraic ones of the lowering.
    #[test]
    fn docs_table_lists_every_function() {
        let table: BTreeSet<String> = Func::ALL
            .iter()
            .filter(|f| f.in_dsl())
            .map(|f| f.name().to_string())
            .chain(ALGEBRAIC.iter().map(|f| f.name.to_string()))
            .collect();
        let documented = documented();
        assert!(documented.len() > 20, "table not found: {documented:?}");
        assert_eq!(documented, table);
    }
}
