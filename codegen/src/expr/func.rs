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
use crate::num::Num;

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

macro_rules! functions {
    ($(
        $(#[doc = $doc:literal])*
        $variant:ident: $name:literal / $sympy:literal, $arity:literal {
            eval: |$x:ident| $eval:expr,
            partials: |$g:ident, $a:ident, $fa:ident| $partials:expr,
            parity: $parity:ident,
            at_zero: $zero:expr,
            inverse: $inverse:expr $(,)?
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

            /// The DSL name, which is also the Rust method generated code
            /// calls (`x.sin()`, `y.atan2(x)`).
            pub fn name(self) -> &'static str {
                match self { $(Func::$variant => $name,)* }
            }

            /// The name sympy knows the function by.
            pub fn sympy_name(self) -> &'static str {
                match self { $(Func::$variant => $sympy,)* }
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

            /// The function with this DSL name.
            pub fn from_name(name: &str) -> Option<Func> {
                Func::ALL.iter().copied().find(|f| f.name() == name)
            }
        }
    };
}

functions! {
    /// sine
    Sin: "sin" / "sin", 1 {
        eval: |x| x[0].sin(),
        partials: |g, a, _fa| Args::one(g.func(Func::Cos, a[0])),
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None,
    }
    /// cosine
    Cos: "cos" / "cos", 1 {
        eval: |x| x[0].cos(),
        partials: |g, a, _fa| {
            let s = g.func(Func::Sin, a[0]);
            Args::one(g.neg(s))
        },
        parity: Even, at_zero: Some(Num::ONE), inverse: None,
    }
    /// tangent: `tan′ = 1 + tan²`
    Tan: "tan" / "tan", 1 {
        eval: |x| x[0].tan(),
        partials: |g, _a, fa| {
            let (one, t2) = (g.int(1), g.pown(fa, Num::int(2)));
            Args::one(g.add2(one, t2))
        },
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None,
    }
    /// arcsine: `1/√(1 − x²)`
    Asin: "asin" / "asin", 1 {
        eval: |x| x[0].asin(),
        partials: |g, a, _fa| Args::one(inverse_root_of_one_minus_square(g, a[0])),
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None,
    }
    /// arccosine: `−1/√(1 − x²)`
    Acos: "acos" / "acos", 1 {
        eval: |x| x[0].acos(),
        partials: |g, a, _fa| {
            let d = inverse_root_of_one_minus_square(g, a[0]);
            Args::one(g.neg(d))
        },
        parity: None, at_zero: None, inverse: None,
    }
    /// arctangent: `1/(1 + x²)`
    Atan: "atan" / "atan", 1 {
        eval: |x| x[0].atan(),
        partials: |g, a, _fa| {
            let (one, a2) = (g.int(1), g.pown(a[0], Num::int(2)));
            let d = g.add2(one, a2);
            Args::one(g.pown(d, Num::MINUS_ONE))
        },
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None,
    }
    /// hyperbolic sine
    Sinh: "sinh" / "sinh", 1 {
        eval: |x| x[0].sinh(),
        partials: |g, a, _fa| Args::one(g.func(Func::Cosh, a[0])),
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None,
    }
    /// hyperbolic cosine
    Cosh: "cosh" / "cosh", 1 {
        eval: |x| x[0].cosh(),
        partials: |g, a, _fa| Args::one(g.func(Func::Sinh, a[0])),
        parity: Even, at_zero: Some(Num::ONE), inverse: None,
    }
    /// hyperbolic tangent: `tanh′ = 1 − tanh²`
    Tanh: "tanh" / "tanh", 1 {
        eval: |x| x[0].tanh(),
        partials: |g, _a, fa| {
            let (one, t2) = (g.int(1), g.pown(fa, Num::int(2)));
            Args::one(g.sub(one, t2))
        },
        parity: Odd, at_zero: Some(Num::ZERO), inverse: None,
    }
    /// exponential: `exp′ = exp`
    Exp: "exp" / "exp", 1 {
        eval: |x| x[0].exp(),
        partials: |_g, _a, fa| Args::one(fa),
        parity: None, at_zero: Some(Num::ONE), inverse: Some(Func::Ln),
    }
    /// natural logarithm: `1/x`
    Ln: "ln" / "log", 1 {
        eval: |x| x[0].ln(),
        partials: |g, a, _fa| Args::one(g.pown(a[0], Num::MINUS_ONE)),
        parity: None, at_zero: None, inverse: Some(Func::Exp),
    }
    /// two-argument arctangent `atan2(y, x)`: `∂/∂y = x/(x² + y²)`,
    /// `∂/∂x = −y/(x² + y²)`
    Atan2: "atan2" / "atan2", 2 {
        eval: |x| x[0].atan2(x[1]),
        partials: |g, a, _fa| {
            let (y, x) = (a[0], a[1]);
            let (x2, y2) = (g.pown(x, Num::int(2)), g.pown(y, Num::int(2)));
            let r2 = g.add2(x2, y2);
            let by_y = g.div(x, r2);
            let q = g.div(y, r2);
            Args::two(by_y, g.neg(q))
        },
        parity: None, at_zero: None, inverse: None,
    }
}

/// `(1 − a²)^(−1/2)`, shared by `asin′` and `acos′`.
fn inverse_root_of_one_minus_square(g: &mut Graph, a: Id) -> Id {
    let (one, a2) = (g.int(1), g.pown(a, Num::int(2)));
    let d = g.sub(one, a2);
    g.pown(d, Num::ratio(-1, 2))
}
