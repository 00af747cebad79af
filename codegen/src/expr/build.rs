//! The canonicalising constructors of [`Graph`] (the invariants are listed
//! in the parent module's docs).

use super::{Args, Func, Graph, Id, Node, Parity};
use crate::expr::num::Num;

/// The longest product that a product it multiplies absorbs factor by
/// factor. Longer products stay one factor: flattening them makes the
/// derivative of a depth-n composition O(n²) in edges and text (issue 13).
/// Eight factors cover every product of the reference models, so their
/// canonical forms (and the snapshots) are unaffected.
const FLATTENED_FACTORS: usize = 8;

impl Graph {
    /// `Σ terms`.
    pub fn add(&mut self, terms: &[Id]) -> Id {
        self.linear_combination(terms.iter().map(|&t| (t, Num::ONE)))
    }

    /// `a + b`.
    pub fn add2(&mut self, a: Id, b: Id) -> Id {
        self.add(&[a, b])
    }

    /// `x` as one operand ([`Func::Hold`]) where it is a sum of two or more
    /// parts, else `x` itself: what keeps the bodies' recursions (and their
    /// derivatives) O(n), rather than copying a sum's terms into every
    /// product that scales it (`crate::bodies::spatial::hold`).
    pub fn hold(&mut self, x: Id) -> Id {
        let parts = match self.node(x) {
            Node::Add(terms, c0) => terms.len() + usize::from(!c0.is_zero()),
            _ => 0,
        };
        if parts >= 2 {
            self.func(Func::Hold, x)
        } else {
            x
        }
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
        if let Some((i, j, rest)) = self.pythagorean_pair(&merged) {
            let c = merged[i].1;
            let constant = self.num(constant);
            let items: Vec<(Id, Num)> = merged
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != i && k != j)
                .map(|(_, &item)| item)
                .chain([(rest, c), (constant, Num::ONE)])
                .collect();
            return self.linear_combination(items);
        }
        match (merged.as_slice(), constant.is_zero()) {
            ([], _) => self.num(constant),
            ([(t, c)], true) if c.is_one() => *t,
            _ => self.intern(Node::Add(merged.into_boxed_slice(), constant)),
        }
    }

    /// Two terms `c·X·sin²u` and `c·X·cos²u` of a sum, by index, and `X`:
    /// they add up to `c·X` (energies in angles produce them everywhere).
    fn pythagorean_pair(&mut self, terms: &[(Id, Num)]) -> Option<(usize, usize, Id)> {
        let two = Num::int(2);
        for (i, &(t, c)) in terms.iter().enumerate() {
            let Node::Mul(factors) = self.node(t) else {
                continue;
            };
            let factors = factors.to_vec();
            // Every sin² factor of the term (sin²φ·sin²θ pairs on either).
            for k in 0..factors.len() {
                let (base, exponent) = factors[k];
                let Node::Func(Func::Sin, args) = *self.node(base) else {
                    continue;
                };
                if exponent != two {
                    continue;
                }
                let cos = self.apply(Func::Cos, args);
                let mut partner = factors.clone();
                partner[k] = (cos, two);
                let partner = self.product(partner);
                if let Some(j) = terms.iter().position(|&(u, d)| u == partner && d == c) {
                    let mut rest = factors.clone();
                    rest.remove(k);
                    let rest = self.product(rest);
                    return Some((i, j, rest));
                }
            }
        }
        None
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
            None => self.intern(Node::Pow([base, exponent])),
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
                Node::Add(..) if integer_power => match self.sum_content(id, e) {
                    Some((v, rest)) => {
                        coefficient = coefficient * v;
                        pending.push((rest, e));
                    }
                    None => factors.push((id, e)),
                },
                // (Π bᵢ^eᵢ)^e = Π bᵢ^(eᵢ·e) for integer e, for a short
                // product; a long one stays a factor, so that the chain and
                // product rules on nested compositions (sin∘sin∘…) build
                // O(1) new edges per level instead of copying every factor.
                Node::Mul(inner) if integer_power && inner.len() <= FLATTENED_FACTORS => {
                    pending.extend(inner.iter().map(|&(b, k)| (b, k * e)));
                }
                _ => factors.push((id, e)),
            }
        }
        if coefficient.is_zero() {
            return self.num(Num::ZERO);
        }
        let kept = self.merged_factors(factors, &mut coefficient);
        let core = match kept.as_slice() {
            [] => return self.num(coefficient),
            [(b, e)] if e.is_one() => *b,
            _ => self.intern(Node::Mul(kept.into_boxed_slice())),
        };
        self.scale(core, coefficient)
    }

    /// For the sum `id` as a factor under the integer power `e`: the
    /// coefficient `c^e` that leaves the product's factor and the sum `t`
    /// that stays in its place, or `None` when the sum stays whole.
    ///
    /// A one-term sum `c·t` gives `(c·t)^e = c^e · t^e` (exactly, and only
    /// then). Any other sum is made primitive (coprime integer coefficients,
    /// the leading one positive) and its content joins the coefficient, so
    /// that g·(2y − 2z) and g·(−2y + 2z) become ±2·g·(y − z) and collect,
    /// while 4·a + b stays as it is. Exact rational content only, a small
    /// one ([`small_ratio`]) whose power is [`moderate`].
    fn sum_content(&mut self, id: Id, e: Num) -> Option<(Num, Id)> {
        let Node::Add(terms, c0) = self.node(id) else {
            return None;
        };
        if c0.is_zero() && terms.len() == 1 {
            let (t, c) = terms[0];
            return c.pow(e).filter(|&v| moderate(v)).map(|v| (v, t));
        }
        let content = crate::expr::num::content(terms.iter().map(|t| t.1).chain(Some(*c0)))
            .map(|c| if terms[0].1.is_negative() { -c } else { c });
        let content = match content {
            Some(c) if small_ratio(c) && c.pow(e).is_some_and(moderate) => c,
            // A large content stays in the sum; only its sign leaves, so
            // that a sum and its negation still collect.
            Some(c) if c.is_negative() => Num::MINUS_ONE,
            _ => return None,
        };
        if content.is_one() {
            return None;
        }
        let inv = content.recip();
        let mut items: Vec<(Id, Num)> = terms.iter().map(|&(t, c)| (t, c * inv)).collect();
        let constant = *c0 * inv;
        let k = self.num(constant);
        items.push((k, Num::ONE));
        let primitive = self.linear_combination(items);
        content.pow(e).map(|v| (v, primitive))
    }

    /// The gathered `factors` of a product sorted by base, with equal bases'
    /// exponents added and zero exponents dropped; numeric bases whose merged
    /// exponent became exact (√2·√2) fold into `coefficient`.
    fn merged_factors(&self, mut factors: Vec<(Id, Num)>, coefficient: &mut Num) -> Vec<(Id, Num)> {
        factors.sort_by_key(|&(b, _)| b);
        let mut merged: Vec<(Id, Num)> = Vec::with_capacity(factors.len());
        for (b, e) in factors {
            match merged.last_mut() {
                Some((last, k)) if *last == b => *k = *k + e,
                _ => merged.push((b, e)),
            }
        }
        let mut kept = Vec::with_capacity(merged.len());
        for (b, e) in merged {
            if e.is_zero() {
                continue;
            }
            match self.as_num(b).and_then(|n| n.pow(e)) {
                Some(v) => *coefficient = *coefficient * v,
                None => kept.push((b, e)),
            }
        }
        kept
    }

    /// `e` with every product that has a sum as a factor (to the first
    /// power) multiplied out, one level deep, in `e` itself or in the terms
    /// of a sum `e`: `m·(a − b) + m·b → m·a`. Lagrange's equations produce
    /// such sums whose terms cancel only once distributed.
    pub fn distribute(&mut self, e: Id) -> Id {
        match self.node(e).clone() {
            Node::Add(terms, c0) => {
                let constant = self.num(c0);
                let items: Vec<(Id, Num)> = terms
                    .iter()
                    .map(|&(t, c)| (self.distribute_product(t), c))
                    .chain([(constant, Num::ONE)])
                    .collect();
                self.linear_combination(items)
            }
            _ => self.distribute_product(e),
        }
    }

    /// `(a + b + c₀)·rest → a·rest + b·rest + c₀·rest` for the first sum
    /// factor of a product (the others stay).
    fn distribute_product(&mut self, e: Id) -> Id {
        let Node::Mul(factors) = self.node(e).clone() else {
            return e;
        };
        let Some(k) = factors
            .iter()
            .position(|&(b, p)| p.is_one() && matches!(self.node(b), Node::Add(..)))
        else {
            return e;
        };
        let Node::Add(terms, c0) = self.node(factors[k].0).clone() else {
            return e;
        };
        let others: Vec<(Id, Num)> = factors
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != k)
            .map(|(_, &f)| f)
            .collect();
        let rest = self.product(others);
        let mut items: Vec<(Id, Num)> = terms
            .iter()
            .map(|&(t, c)| (self.mul2(t, rest), c))
            .collect();
        items.push((rest, c0));
        self.linear_combination(items)
    }

    /// `f(a)` for a function of one argument.
    pub fn func(&mut self, f: Func, a: Id) -> Id {
        self.apply(f, Args::one(a))
    }

    /// `f(args)`, with the table's algebra: constants folded where the
    /// arguments are floats (exact rationals stay symbolic: `sin(1)`), the
    /// exact value at zero, odd/even symmetry, and `f(g(x)) = x` for an
    /// inverse pair (`ln∘exp`).
    pub fn apply(&mut self, f: Func, args: Args) -> Id {
        let ids = args.as_slice();
        let floats: Vec<f64> = ids
            .iter()
            .filter_map(|&a| match self.as_num(a) {
                Some(Num::Float(x)) => Some(x),
                _ => None,
            })
            .collect();
        if let [a] = *ids {
            if self.is_zero(a) {
                if let Some(v) = f.at_zero() {
                    return self.num(v);
                }
            }
        }
        if floats.len() == ids.len() {
            return self.num(Num::Float(f.eval(&floats)));
        }
        let exact: Vec<Num> = ids.iter().filter_map(|&a| self.as_num(a)).collect();
        if exact.len() == ids.len() {
            if let Some(value) = f.exact(&exact) {
                return self.num(value);
            }
        }
        if let [a] = *ids {
            if let Some(positive) = self.negated(a) {
                match f.parity() {
                    Parity::Odd => {
                        let inner = self.func(f, positive);
                        return self.neg(inner);
                    }
                    Parity::Even => return self.func(f, positive),
                    Parity::None => {}
                }
            }
            if let Node::Func(g, inner) = self.node(a) {
                if f.inverse_of() == Some(*g) {
                    return inner.as_slice()[0];
                }
            }
        }
        self.intern(Node::Func(f, args))
    }

    /// `Some(x)` when `a` is `−x` for a canonical `x` (a sum whose leading
    /// coefficient is negative), so that `f(−x)` can be written through `f(x)`.
    fn negated(&mut self, a: Id) -> Option<Id> {
        match self.node(a) {
            Node::Add(terms, _) if terms[0].1.is_negative() => Some(self.neg(a)),
            _ => None,
        }
    }

    /// The canonical node for `node`, whose operands are canonical: each
    /// operator through its constructor (used after
    /// [`Node::map_children`]).
    pub fn rebuild(&mut self, node: Node) -> Id {
        match node {
            Node::Num(n) => self.num(n),
            Node::Sym(s) => self.sym(s),
            Node::Add(terms, c0) => {
                let constant = self.num(c0);
                let items = terms.iter().copied().chain([(constant, Num::ONE)]);
                self.linear_combination(items)
            }
            Node::Mul(factors) => self.product(factors.iter().copied()),
            Node::Pow([b, e]) => self.pow(b, e),
            Node::Func(f, args) => self.apply(f, args),
        }
    }
}

/// Whether a coefficient split out of a power may leave it: within
/// `2^±64`, so that the factor left behind overflows or underflows only
/// where the whole power comes within `2^64` of doing so. Split whatever
/// its size, `(x + 5/4)^625` became `4^−625 · (4x + 5)^625`, `0 · ∞ = NaN`
/// at x = 0.2, where the power is 1.4e100.
fn moderate(v: Num) -> bool {
    const BOUND: f64 = (1u128 << 64) as f64;
    let x = v.to_f64().abs();
    (1.0 / BOUND..=BOUND).contains(&x)
}

/// Whether `c` is a ratio of integers below 2³² (2, ½, ¾, …): the content
/// a sum gives up to the surrounding product. The content of decimals
/// read from a file (a URDF's masses times its lengths) is rather 10⁻³⁰ or
/// so, with coefficients near 10²⁵ left in the sum: two constants at the
/// edge of `f32`'s range, and a multiplication more where the sum is read,
/// where the sum kept whole has neither.
fn small_ratio(c: Num) -> bool {
    const BOUND: u128 = 1 << 32;
    matches!(c, Num::Rational(p, q) if p.unsigned_abs() < BOUND && q.unsigned_abs() < BOUND)
}
