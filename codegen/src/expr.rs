//! The expression DAG: an arena of hash-consed nodes in canonical form.
//!
//! Nodes live in a `Vec` and refer to their children by [`Id`]; a child is
//! always created before its parent, so arena order is a topological order.
//! Every node is built through a constructor that canonicalises it and then
//! looks it up in a hash map, so two structurally equal expressions are the
//! same `Id`. Common subexpressions are therefore shared by construction, and
//! equality of canonical forms is an `Id` comparison.
//!
//! Canonical form (the invariants the constructors maintain):
//! - sums are `Σ cᵢ·tᵢ + c₀` with terms sorted by `Id`, merged, no zero
//!   coefficient; a term is never a number or a sum; `1·x + 0` is `x`;
//! - products are `Π bᵢ^eᵢ` with rational exponents, bases sorted and merged,
//!   no zero exponent; a numeric coefficient never sits inside a product but in
//!   the sum around it (`3·x·y` is `Add[(x·y, 3)]`); a number is a base only
//!   under a non-integer exponent (`√2`); `x^1` is `x`;
//! - `Pow` only for a non-constant exponent (`x.powf(y)`);
//! - constant arithmetic is folded exactly (see [`Num`]).

use crate::num::Num;
use std::collections::HashMap;

/// Index of a node in a [`Graph`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Id(u32);

impl Id {
    /// Position in the arena (children always have smaller indices).
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A leaf variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sym {
    /// Coordinate `qᵢ`.
    Coord(usize),
    /// Velocity `q̇ᵢ`.
    Vel(usize),
    /// Time `t`.
    Time,
    /// Parameter `pᵢ` (a struct field).
    Param(usize),
    /// Lagrange multiplier `λᵢ` of Gauss's principle: computed at run time
    /// by a factorization, then a variable of the expressions for `q̈`.
    Multiplier(usize),
}

/// Elementary functions of one argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func {
    /// sine
    Sin,
    /// cosine
    Cos,
    /// tangent
    Tan,
    /// arcsine
    Asin,
    /// arccosine
    Acos,
    /// arctangent
    Atan,
    /// hyperbolic sine
    Sinh,
    /// hyperbolic cosine
    Cosh,
    /// hyperbolic tangent
    Tanh,
    /// exponential
    Exp,
    /// natural logarithm
    Ln,
}

impl Func {
    /// All functions, for tables and tests.
    pub const ALL: [Func; 11] = [
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Asin,
        Func::Acos,
        Func::Atan,
        Func::Sinh,
        Func::Cosh,
        Func::Tanh,
        Func::Exp,
        Func::Ln,
    ];

    /// The DSL / Rust method name (`sin`, `ln`, …).
    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
            Func::Exp => "exp",
            Func::Ln => "ln",
        }
    }

    /// The function with this DSL name.
    pub fn from_name(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }

    /// `f(-x) = -f(x)`.
    fn is_odd(self) -> bool {
        matches!(
            self,
            Func::Sin | Func::Tan | Func::Asin | Func::Atan | Func::Sinh | Func::Tanh
        )
    }

    /// `f(-x) = f(x)`.
    fn is_even(self) -> bool {
        matches!(self, Func::Cos | Func::Cosh)
    }

    /// `f(0)` when it is an exact rational.
    fn at_zero(self) -> Option<Num> {
        match self {
            Func::Sin | Func::Tan | Func::Asin | Func::Atan | Func::Sinh | Func::Tanh => {
                Some(Num::ZERO)
            }
            Func::Cos | Func::Cosh | Func::Exp => Some(Num::ONE),
            Func::Acos | Func::Ln => None,
        }
    }

    /// Evaluates the function in `f64`.
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
            Func::Atan => x.atan(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Tanh => x.tanh(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
        }
    }
}

/// A node of the DAG, in canonical form (see the module docs).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant.
    Num(Num),
    /// A variable.
    Sym(Sym),
    /// `Σ cᵢ·tᵢ + c₀`.
    Add(Box<[(Id, Num)]>, Num),
    /// `Π bᵢ^eᵢ`.
    Mul(Box<[(Id, Num)]>),
    /// `base ^ exponent` with a non-constant exponent.
    Pow(Id, Id),
    /// `f(x)`.
    Func(Func, Id),
    /// `atan2(y, x)`.
    Atan2(Id, Id),
}

/// The arena of hash-consed nodes.
#[derive(Clone, Debug, Default)]
pub struct Graph {
    nodes: Vec<Node>,
    index: HashMap<Node, Id>,
}

impl Graph {
    /// An empty graph.
    pub fn new() -> Graph {
        Graph::default()
    }

    /// The node behind `id`.
    pub fn node(&self, id: Id) -> &Node {
        &self.nodes[id.index()]
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the graph has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    fn intern(&mut self, node: Node) -> Id {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        let id = Id(u32::try_from(self.nodes.len()).expect("expression graph exceeds 2^32 nodes"));
        self.nodes.push(node.clone());
        self.index.insert(node, id);
        id
    }

    /// The constant `n`.
    pub fn num(&mut self, n: Num) -> Id {
        self.intern(Node::Num(n))
    }

    /// The integer constant `n`.
    pub fn int(&mut self, n: i64) -> Id {
        self.num(Num::int(n))
    }

    /// The variable `s`.
    pub fn sym(&mut self, s: Sym) -> Id {
        self.intern(Node::Sym(s))
    }

    /// The constant value of `id`, if it is a number.
    pub fn as_num(&self, id: Id) -> Option<Num> {
        match self.node(id) {
            Node::Num(n) => Some(*n),
            _ => None,
        }
    }

    /// Whether `id` is the constant zero.
    pub fn is_zero(&self, id: Id) -> bool {
        self.as_num(id).is_some_and(Num::is_zero)
    }

    /// `Σ terms`.
    pub fn add(&mut self, terms: &[Id]) -> Id {
        self.linear_combination(terms.iter().map(|&t| (t, Num::ONE)))
    }

    /// `a + b`.
    pub fn add2(&mut self, a: Id, b: Id) -> Id {
        self.add(&[a, b])
    }

    /// `a − b`.
    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        self.linear_combination([(a, Num::ONE), (b, Num::MINUS_ONE)])
    }

    /// `−a`.
    pub fn neg(&mut self, a: Id) -> Id {
        self.scale(a, Num::MINUS_ONE)
    }

    /// `c·a`.
    pub fn scale(&mut self, a: Id, c: Num) -> Id {
        self.linear_combination([(a, c)])
    }

    /// `Σ cᵢ·xᵢ`, canonicalised: nested sums flattened, like terms collected.
    pub fn linear_combination(&mut self, items: impl IntoIterator<Item = (Id, Num)>) -> Id {
        let mut constant = Num::ZERO;
        let mut terms: Vec<(Id, Num)> = Vec::new();
        for (id, c) in items {
            if c.is_zero() {
                continue;
            }
            match self.node(id) {
                Node::Num(n) => constant = constant + *n * c,
                Node::Add(inner, c0) => {
                    constant = constant + *c0 * c;
                    terms.extend(inner.iter().map(|&(t, k)| (t, k * c)));
                }
                _ => terms.push((id, c)),
            }
        }
        terms.sort_by_key(|&(t, _)| t);
        let mut merged: Vec<(Id, Num)> = Vec::with_capacity(terms.len());
        for (t, c) in terms {
            match merged.last_mut() {
                Some((last, k)) if *last == t => *k = *k + c,
                _ => merged.push((t, c)),
            }
        }
        merged.retain(|(_, c)| !c.is_zero());
        match (merged.as_slice(), constant.is_zero()) {
            ([], _) => self.num(constant),
            ([(t, c)], true) if c.is_one() => *t,
            _ => self.intern(Node::Add(merged.into_boxed_slice(), constant)),
        }
    }

    /// `Π factors`.
    pub fn mul(&mut self, factors: &[Id]) -> Id {
        self.product(factors.iter().map(|&f| (f, Num::ONE)))
    }

    /// `a·b`.
    pub fn mul2(&mut self, a: Id, b: Id) -> Id {
        self.mul(&[a, b])
    }

    /// `a / b`.
    pub fn div(&mut self, a: Id, b: Id) -> Id {
        self.product([(a, Num::ONE), (b, Num::MINUS_ONE)])
    }

    /// `base ^ e` for a constant exponent.
    pub fn pown(&mut self, base: Id, e: Num) -> Id {
        self.product([(base, e)])
    }

    /// `base ^ exponent`; a constant exponent stays in the product form.
    pub fn pow(&mut self, base: Id, exponent: Id) -> Id {
        match self.as_num(exponent) {
            Some(e) => self.pown(base, e),
            None if self.is_zero(base) => base,
            None if self.as_num(base).is_some_and(Num::is_one) => base,
            None => self.intern(Node::Pow(base, exponent)),
        }
    }

    /// `√a`.
    pub fn sqrt(&mut self, a: Id) -> Id {
        self.pown(a, Num::ratio(1, 2))
    }

    /// `Π bᵢ^eᵢ`, canonicalised: nested products flattened, coefficients
    /// pulled out into a surrounding sum, equal bases merged, constants folded.
    pub fn product(&mut self, items: impl IntoIterator<Item = (Id, Num)>) -> Id {
        let mut coefficient = Num::ONE;
        let mut factors: Vec<(Id, Num)> = Vec::new();
        let mut pending: Vec<(Id, Num)> = items.into_iter().collect();
        while let Some((id, e)) = pending.pop() {
            if e.is_zero() {
                continue;
            }
            let integer_power = e.as_integer().is_some();
            match self.node(id) {
                Node::Num(n) => match n.pow(e) {
                    Some(v) => coefficient = coefficient * v,
                    None => factors.push((id, e)),
                },
                // (c·t)^e = c^e · t^e for integer e (exactly, and only then).
                Node::Add(terms, c0) if integer_power && c0.is_zero() && terms.len() == 1 => {
                    let (t, c) = terms[0];
                    match c.pow(e) {
                        Some(v) => {
                            coefficient = coefficient * v;
                            pending.push((t, e));
                        }
                        None => factors.push((id, e)),
                    }
                }
                // A sum as a factor is made primitive (leading coefficient 1)
                // and its content joins the coefficient, so that g·(2y − 2z)
                // and g·(−2y + 2z) become ±2·g·(y − z) and collect. Exact
                // rational content under an integer power only.
                Node::Add(terms, c0) if integer_power => {
                    let content = terms[0].1;
                    if content.is_one() || !matches!(content, Num::Rational(..)) {
                        factors.push((id, e));
                    } else {
                        let inv = content.recip();
                        let scaled: Vec<(Id, Num)> =
                            terms.iter().map(|&(t, c)| (t, c * inv)).collect();
                        let constant = *c0 * inv;
                        let mut items = scaled;
                        let k = self.num(constant);
                        items.push((k, Num::ONE));
                        let primitive = self.linear_combination(items);
                        match content.pow(e) {
                            Some(v) => {
                                coefficient = coefficient * v;
                                pending.push((primitive, e));
                            }
                            None => factors.push((id, e)),
                        }
                    }
                }
                // (Π bᵢ^eᵢ)^e = Π bᵢ^(eᵢ·e) for integer e.
                Node::Mul(inner) if integer_power => {
                    pending.extend(inner.iter().map(|&(b, k)| (b, k * e)));
                }
                _ => factors.push((id, e)),
            }
        }
        if coefficient.is_zero() {
            return self.num(Num::ZERO);
        }
        factors.sort_by_key(|&(b, _)| b);
        let mut merged: Vec<(Id, Num)> = Vec::with_capacity(factors.len());
        for (b, e) in factors {
            match merged.last_mut() {
                Some((last, k)) if *last == b => *k = *k + e,
                _ => merged.push((b, e)),
            }
        }
        // Numeric bases whose merged exponent became exact (√2·√2) fold.
        let mut kept = Vec::with_capacity(merged.len());
        for (b, e) in merged {
            if e.is_zero() {
                continue;
            }
            match self.as_num(b).and_then(|n| n.pow(e)) {
                Some(v) => coefficient = coefficient * v,
                None => kept.push((b, e)),
            }
        }
        let core = match kept.as_slice() {
            [] => return self.num(coefficient),
            [(b, e)] if e.is_one() => *b,
            _ => self.intern(Node::Mul(kept.into_boxed_slice())),
        };
        self.scale(core, coefficient)
    }

    /// `f(a)`, with exact values at zero, odd/even symmetry and `ln∘exp`.
    pub fn func(&mut self, f: Func, a: Id) -> Id {
        if let Some(n) = self.as_num(a) {
            if n.is_zero() {
                if let Some(v) = f.at_zero() {
                    return self.num(v);
                }
            }
            if let Num::Float(x) = n {
                return self.num(Num::Float(f.apply(x)));
            }
        }
        if let Some(positive) = self.negated(a) {
            if f.is_odd() {
                let inner = self.func(f, positive);
                return self.neg(inner);
            }
            if f.is_even() {
                return self.func(f, positive);
            }
        }
        match (f, self.node(a)) {
            (Func::Ln, &Node::Func(Func::Exp, x)) => x,
            (Func::Exp, &Node::Func(Func::Ln, x)) => x,
            _ => self.intern(Node::Func(f, a)),
        }
    }

    /// `atan2(y, x)`.
    pub fn atan2(&mut self, y: Id, x: Id) -> Id {
        if let (Some(Num::Float(a)), Some(Num::Float(b))) = (self.as_num(y), self.as_num(x)) {
            return self.num(Num::Float(a.atan2(b)));
        }
        self.intern(Node::Atan2(y, x))
    }

    /// `Some(x)` when `a` is `−x` for a canonical `x` (a sum whose leading
    /// coefficient is negative), so that `f(−x)` can be written through `f(x)`.
    fn negated(&mut self, a: Id) -> Option<Id> {
        match self.node(a) {
            Node::Add(terms, _) if terms[0].1.is_negative() => Some(self.neg(a)),
            _ => None,
        }
    }

    /// Replaces variables by expressions (`map` returns `None` to keep one),
    /// rebuilding through the canonicalising constructors.
    pub fn substitute(&mut self, root: Id, map: &dyn Fn(Sym) -> Option<Id>) -> Id {
        let mut memo: HashMap<Id, Id> = HashMap::new();
        self.substitute_memo(root, map, &mut memo)
    }

    fn substitute_memo(
        &mut self,
        id: Id,
        map: &dyn Fn(Sym) -> Option<Id>,
        memo: &mut HashMap<Id, Id>,
    ) -> Id {
        if let Some(&done) = memo.get(&id) {
            return done;
        }
        let result = match self.node(id).clone() {
            Node::Num(_) => id,
            Node::Sym(s) => map(s).unwrap_or(id),
            Node::Add(terms, c0) => {
                let mut items: Vec<(Id, Num)> = terms
                    .iter()
                    .map(|&(t, c)| (self.substitute_memo(t, map, memo), c))
                    .collect();
                let constant = self.num(c0);
                items.push((constant, Num::ONE));
                self.linear_combination(items)
            }
            Node::Mul(factors) => {
                let items: Vec<(Id, Num)> = factors
                    .iter()
                    .map(|&(b, e)| (self.substitute_memo(b, map, memo), e))
                    .collect();
                self.product(items)
            }
            Node::Pow(b, e) => {
                let (b, e) = (
                    self.substitute_memo(b, map, memo),
                    self.substitute_memo(e, map, memo),
                );
                self.pow(b, e)
            }
            Node::Func(f, a) => {
                let a = self.substitute_memo(a, map, memo);
                self.func(f, a)
            }
            Node::Atan2(y, x) => {
                let (y, x) = (
                    self.substitute_memo(y, map, memo),
                    self.substitute_memo(x, map, memo),
                );
                self.atan2(y, x)
            }
        };
        memo.insert(id, result);
        result
    }

    /// Whether any variable for which `pred` holds occurs in `root`.
    pub fn mentions(&self, root: Id, pred: impl Fn(Sym) -> bool) -> bool {
        self.reachable(&[root])
            .into_iter()
            .any(|id| match self.node(id) {
                Node::Sym(s) => pred(*s),
                _ => false,
            })
    }

    /// The nodes reachable from `roots`, in arena (topological) order.
    pub fn reachable(&self, roots: &[Id]) -> Vec<Id> {
        let mut seen = vec![false; self.nodes.len()];
        let mut stack: Vec<Id> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if std::mem::replace(&mut seen[id.index()], true) {
                continue;
            }
            stack.extend(self.children(id));
        }
        (0..self.nodes.len())
            .filter(|&i| seen[i])
            .map(|i| Id(i as u32))
            .collect()
    }

    /// The direct children of a node.
    pub fn children(&self, id: Id) -> Vec<Id> {
        match self.node(id) {
            Node::Num(_) | Node::Sym(_) => Vec::new(),
            Node::Add(terms, _) => terms.iter().map(|&(t, _)| t).collect(),
            Node::Mul(factors) => factors.iter().map(|&(b, _)| b).collect(),
            Node::Pow(a, b) | Node::Atan2(a, b) => vec![*a, *b],
            Node::Func(_, a) => vec![*a],
        }
    }

    /// Evaluates `roots` in `f64` with the variables given by `env`.
    pub fn eval(&self, roots: &[Id], env: &dyn Fn(Sym) -> f64) -> Vec<f64> {
        let order = self.reachable(roots);
        let mut value: HashMap<Id, f64> = HashMap::with_capacity(order.len());
        for id in order {
            let v = match self.node(id) {
                Node::Num(n) => n.to_f64(),
                Node::Sym(s) => env(*s),
                Node::Add(terms, c0) => terms
                    .iter()
                    .fold(c0.to_f64(), |acc, (t, c)| acc + c.to_f64() * value[t]),
                Node::Mul(factors) => factors
                    .iter()
                    .fold(1.0, |acc, (b, e)| acc * power(value[b], *e)),
                Node::Pow(b, e) => value[b].powf(value[e]),
                Node::Func(f, a) => f.apply(value[a]),
                Node::Atan2(y, x) => value[y].atan2(value[x]),
            };
            value.insert(id, v);
        }
        roots.iter().map(|r| value[r]).collect()
    }
}

/// The parts of a sum `Σ cᵢ·tᵢ + c₀` as printers write them: each term
/// (`None` for the constant, last) with the magnitude of its coefficient and
/// whether it is subtracted.
pub fn signed_parts(terms: &[(Id, Num)], c0: Num) -> Vec<(Option<Id>, Num, bool)> {
    let constant = (!c0.is_zero()).then_some((None, c0));
    terms
        .iter()
        .map(|&(t, c)| (Some(t), c))
        .chain(constant)
        .map(|(t, c)| (t, if c.is_negative() { -c } else { c }, c.is_negative()))
        .collect()
}

/// `x^e` in `f64`, exact for integer and half-integer exponents.
pub fn power(x: f64, e: Num) -> f64 {
    match e.as_integer() {
        Some(k) => x.powi(k as i32),
        None if matches!(e, Num::Rational(_, 2)) => {
            let k = (e * Num::int(2)).as_integer().unwrap_or(1);
            x.sqrt().powi(k as i32)
        }
        None => x.powf(e.to_f64()),
    }
}

#[cfg(test)]
mod tests {
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
}
