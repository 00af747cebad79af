//! Expressions as text: Unicode mathematics for `DERIVATION`, sympy syntax
//! for `SYMBOLIC`. One precedence-aware printer serves both styles.

use crate::expr::num::Num;
use crate::expr::{signed_parts, Func, Graph, Id, Node, Sym};
use std::collections::HashMap;

/// How to write an expression.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// `ẋ² − α·sin(t)`: for people.
    Unicode,
    /// `dot(x)**2 - alpha*sin(t)`: for `sympy.sympify`.
    Sympy,
}

/// Binding strength of the outermost operator of a printed expression.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Prec {
    Sum,
    Product,
    Power,
    Atom,
}

/// Prints expressions of one graph with the names of one system.
pub struct Printer<'a> {
    graph: &'a Graph,
    coordinates: &'a [String],
    parameters: &'a [String],
    style: Style,
    /// Nodes printed by name (definitions), not expanded.
    names: Option<&'a HashMap<Id, String>>,
}

impl<'a> Printer<'a> {
    /// A printer for `graph` naming variables after `coordinates` and `parameters`.
    pub fn new(
        graph: &'a Graph,
        coordinates: &'a [String],
        parameters: &'a [String],
        style: Style,
    ) -> Self {
        Printer {
            graph,
            coordinates,
            parameters,
            style,
            names: None,
        }
    }

    /// The same printer writing the nodes of `names` by their name: a
    /// definition stays named wherever it occurs, so the text grows with
    /// the input, not with the expansion.
    pub fn with_names(mut self, names: &'a HashMap<Id, String>) -> Self {
        self.names = Some(names);
        self
    }

    /// `id` written out one level even when it has a name (the right-hand
    /// side of its definition); names inside still apply.
    pub fn print_expanded(&self, id: Id) -> String {
        self.render_node(id).0
    }

    /// `id` as text.
    pub fn print(&self, id: Id) -> String {
        self.render(id).0
    }

    fn times(&self) -> &'static str {
        match self.style {
            Style::Unicode => "·",
            Style::Sympy => "*",
        }
    }

    fn minus(&self) -> &'static str {
        match self.style {
            Style::Unicode => "−",
            Style::Sympy => "-",
        }
    }

    /// The name of a velocity. For people, one convention for every name:
    /// the dot over the name's first letter (`ẋ`, `ẋ1`, `ṫh1`, `θ̇`), so that
    /// a velocity is always one token and reads as its coordinate's; for
    /// sympy, `dot(name)`.
    fn velocity(&self, i: usize) -> String {
        let name = &self.coordinates[i];
        match self.style {
            Style::Unicode => {
                let split = name.chars().next().map_or(0, char::len_utf8);
                let (first, rest) = name.split_at(split);
                format!("{}{rest}", dotted(first))
            }
            Style::Sympy => format!("dot({name})"),
        }
    }

    fn wrap(&self, (text, prec): (String, Prec), at_least: Prec) -> String {
        if prec < at_least {
            format!("({text})")
        } else {
            text
        }
    }

    fn number(&self, n: Num) -> (String, Prec) {
        match n {
            Num::Rational(_, 1) | Num::Float(_) if !n.is_negative() => (n.to_string(), Prec::Atom),
            Num::Rational(_, 1) | Num::Float(_) => (format!("{}{}", self.minus(), -n), Prec::Sum),
            Num::Rational(p, q) => {
                let sign = if p < 0 { self.minus() } else { "" };
                (
                    format!("{sign}{}/{q}", p.unsigned_abs()),
                    if p < 0 { Prec::Sum } else { Prec::Product },
                )
            }
            // A rational past i128, written out in full (`p/q` or `p`).
            Num::Big(_) if n.is_negative() => (format!("{}{}", self.minus(), -n), Prec::Sum),
            Num::Big(_) => (n.to_string(), Prec::Product),
        }
    }

    fn render(&self, id: Id) -> (String, Prec) {
        match self.names.and_then(|names| names.get(&id)) {
            Some(name) => (name.clone(), Prec::Atom),
            None => self.render_node(id),
        }
    }

    /// A variable's name in this style.
    fn symbol(&self, s: Sym) -> String {
        match s {
            Sym::Coord(i) => self.coordinates[i].clone(),
            Sym::Vel(i) => self.velocity(i),
            Sym::Param(i) => self.parameters[i].clone(),
            Sym::Time => "t".to_string(),
            Sym::Multiplier(i) => match self.style {
                Style::Unicode => format!("λ{}", subscript(i + 1)),
                Style::Sympy => format!("lambda_{}", i + 1),
            },
            Sym::Seed(i) => match self.style {
                Style::Unicode => format!("s{}", subscript(i + 1)),
                Style::Sympy => format!("s_{}", i + 1),
            },
            Sym::Accel(i) => match self.style {
                Style::Unicode => format!("{}̈", self.coordinates[i]),
                Style::Sympy => format!("ddot({})", self.coordinates[i]),
            },
        }
    }

    fn render_node(&self, id: Id) -> (String, Prec) {
        match self.graph.node(id) {
            Node::Num(n) => self.number(*n),
            Node::Sym(s) => (self.symbol(*s), Prec::Atom),
            Node::Add(terms, c0) => self.sum(terms, *c0),
            Node::Mul(factors) => self.product(factors),
            Node::Pow([b, e]) => {
                let base = self.wrap(self.render(*b), Prec::Atom);
                let exponent = self.wrap(self.render(*e), Prec::Atom);
                let op = if self.style == Style::Sympy {
                    "**"
                } else {
                    "^"
                };
                (format!("{base}{op}{exponent}"), Prec::Power)
            }
            Node::Func(f, args) => {
                let args: Vec<String> = args.as_slice().iter().map(|&a| self.print(a)).collect();
                let args = args.join(", ");
                let call = match self.style {
                    Style::Unicode if *f == Func::Hold => format!("({args})"),
                    Style::Unicode => format!("{}({args})", f.name()),
                    Style::Sympy => f.sympy_call(&args),
                };
                (call, Prec::Atom)
            }
        }
    }

    /// `Σ cᵢ·tᵢ + c₀` written with signs between the terms (`a − 2·b + 1`);
    /// a single positive term binds as a product.
    fn sum(&self, terms: &[(Id, Num)], c0: Num) -> (String, Prec) {
        let mut out = String::new();
        for (i, (term, magnitude, negative)) in signed_parts(terms, c0).into_iter().enumerate() {
            let text = match term {
                Some(t) => self.scaled(t, magnitude),
                None => magnitude.to_string(),
            };
            match (i, negative) {
                (0, false) => out.push_str(&text),
                (0, true) => out.push_str(&format!("{}{text}", self.minus())),
                (_, false) => out.push_str(&format!(" + {text}")),
                (_, true) => out.push_str(&format!(" {} {text}", self.minus())),
            }
        }
        let single_positive = terms.len() == 1 && c0.is_zero() && !terms[0].1.is_negative();
        (
            out,
            if single_positive {
                Prec::Product
            } else {
                Prec::Sum
            },
        )
    }

    /// `Π bᵢ^eᵢ` as a fraction: the factors of positive exponent over those
    /// of negative exponent (`a·b/(c·d)`), `1` for an empty numerator.
    fn product(&self, factors: &[(Id, Num)]) -> (String, Prec) {
        let (mut num, mut den) = (Vec::new(), Vec::new());
        for &(b, e) in factors {
            if e.is_negative() {
                den.push(self.power(b, -e));
            } else {
                num.push(self.power(b, e));
            }
        }
        let num_text = if num.is_empty() {
            "1".to_string()
        } else {
            num.join(self.times())
        };
        if den.is_empty() {
            return (
                num_text,
                if num.len() == 1 {
                    Prec::Power
                } else {
                    Prec::Product
                },
            );
        }
        let den_text = if den.len() == 1 {
            den.remove(0)
        } else {
            format!("({})", den.join(self.times()))
        };
        (format!("{num_text}/{den_text}"), Prec::Product)
    }

    /// `c·t` for a positive coefficient `c`: `t`, `3·t`, `t/2`, `3·t/4`.
    fn scaled(&self, t: Id, c: Num) -> String {
        let term = self.wrap(self.render(t), Prec::Product);
        match c {
            Num::Rational(1, 1) => term,
            Num::Rational(1, q) => format!("{term}/{q}"),
            Num::Rational(p, 1) => format!("{p}{}{term}", self.times()),
            Num::Rational(p, q) => format!("{p}{}{term}/{q}", self.times()),
            Num::Float(x) => format!("{x:?}{}{term}", self.times()),
            Num::Big(_) => format!("{c}{}{term}", self.times()),
        }
    }

    /// `b^e` for a positive exponent.
    fn power(&self, b: Id, e: Num) -> String {
        if e.is_one() {
            return self.wrap(self.render(b), Prec::Power);
        }
        // An even power of a sum whose negation is named is that name's
        // power: `dt(px)²`, not the negated expansion of `dt(px)`.
        let named = |id: Id| self.names.is_some_and(|names| names.contains_key(&id));
        let even = e.as_integer().is_some_and(|k| k % 2 == 0);
        let b = match self.graph.existing_negation(b) {
            Some(negated) if even && !named(b) && named(negated) => negated,
            _ => b,
        };
        let half = Num::ratio(1, 2);
        match self.style {
            Style::Unicode if e == half => format!("√{}", self.wrap(self.render(b), Prec::Atom)),
            Style::Sympy if e == half => format!("sqrt({})", self.print(b)),
            Style::Unicode if e.as_integer().is_some() => {
                format!(
                    "{}{}",
                    self.wrap(self.render(b), Prec::Atom),
                    superscript(&e.to_string())
                )
            }
            Style::Unicode => format!("{}^({e})", self.wrap(self.render(b), Prec::Atom)),
            Style::Sympy if e.as_integer().is_some() => {
                format!("{}**{e}", self.wrap(self.render(b), Prec::Atom))
            }
            Style::Sympy => format!("{}**({e})", self.wrap(self.render(b), Prec::Atom)),
        }
    }
}

/// A one-letter name with a dot above, precomposed where Unicode has the
/// letter (NFC, so that `ẋ` in the text equals the `ẋ` a user types).
fn dotted(letter: &str) -> String {
    const PRECOMPOSED: &[(char, char)] = &[
        ('a', 'ȧ'),
        ('b', 'ḃ'),
        ('c', 'ċ'),
        ('d', 'ḋ'),
        ('e', 'ė'),
        ('f', 'ḟ'),
        ('g', 'ġ'),
        ('h', 'ḣ'),
        ('m', 'ṁ'),
        ('n', 'ṅ'),
        ('o', 'ȯ'),
        ('p', 'ṗ'),
        ('r', 'ṙ'),
        ('s', 'ṡ'),
        ('t', 'ṫ'),
        ('w', 'ẇ'),
        ('x', 'ẋ'),
        ('y', 'ẏ'),
        ('z', 'ż'),
    ];
    let c = letter.chars().next().unwrap_or(' ');
    match PRECOMPOSED.iter().find(|(plain, _)| *plain == c) {
        Some((_, dotted)) => dotted.to_string(),
        None => format!("{letter}\u{307}"),
    }
}

/// `12` → `¹²`.
pub fn superscript(digits: &str) -> String {
    digits
        .chars()
        .map(|c| match c {
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            '9' => '⁹',
            '-' => '⁻',
            other => other,
        })
        .collect()
}

/// `12` → `₁₂`.
pub fn subscript(n: usize) -> String {
    n.to_string()
        .chars()
        .map(|c| char::from_u32(0x2080 + c.to_digit(10).unwrap_or(0)).unwrap_or(c))
        .collect()
}

/// Written out, a subexpression shorter than this many characters (about)
/// is repeated where it occurs; a longer one that occurs more than once is
/// named once.
const SHARED_LENGTH: usize = 40;

/// A text whose expressions written out in full stay below this many
/// characters (about) names nothing: a small derivation reads best as the
/// paper writes it.
const WRITTEN_OUT_BUDGET: usize = 16_000;

/// Names for the subexpressions of `roots` that occur more than once and
/// are longer than `SHARED_LENGTH` (40) characters written out, in
/// topological order (each may use earlier names): with them a text grows
/// linearly with the DAG, not with the expression tree, which for
/// Lagrange's equations or a long chain is exponentially larger. Nodes in
/// `taken` (definitions) keep their names; nodes that depend on the
/// multipliers `λ` are never named (they are printed after `λ`).
pub fn shared_subexpressions(
    g: &Graph,
    roots: &[Id],
    taken: &HashMap<Id, String>,
    name: impl Fn(usize) -> String,
) -> Vec<(Id, String)> {
    let order = g.reachable(roots);
    let (uses, multiplier) = uses_and_multipliers(g, &order);
    if written_out_length(g, &order, roots) < WRITTEN_OUT_BUDGET {
        return Vec::new();
    }
    let mut length: HashMap<Id, usize> = HashMap::new();
    let mut names = Vec::new();
    for &id in &order {
        let own = own_length(g, id);
        let inner: usize = g
            .children(id)
            .map(|c| length.get(&c).copied().unwrap_or(3))
            .sum();
        let total = own + inner;
        let shareable = !matches!(g.node(id), Node::Num(_) | Node::Sym(_))
            && !multiplier.get(&id).copied().unwrap_or(false);
        let written = if let Some(n) = taken.get(&id) {
            n.len()
        } else if shareable && uses.get(&id).copied().unwrap_or(0) > 1 && total > SHARED_LENGTH {
            let n = name(names.len() + 1);
            let len = n.chars().count();
            names.push((id, n));
            len
        } else {
            total
        };
        length.insert(id, written);
    }
    names
}

/// For the nodes of `order` (topological): how many distinct nodes use each
/// inside them, and whether each depends on a multiplier `λ`. Only uses
/// inside other expressions count: a whole printed expression that is only
/// repeated as a whole (`b₂` and `(b − A a)₂`) reads better written out
/// twice than named.
fn uses_and_multipliers(g: &Graph, order: &[Id]) -> (HashMap<Id, usize>, HashMap<Id, bool>) {
    let mut uses: HashMap<Id, usize> = HashMap::new();
    let mut multiplier: HashMap<Id, bool> = HashMap::new();
    for &id in order {
        let mut children: Vec<Id> = g.children(id).collect();
        children.sort();
        children.dedup();
        for &c in &children {
            *uses.entry(c).or_default() += 1;
        }
        let own = matches!(g.node(id), Node::Sym(Sym::Multiplier(_)));
        let inherited = children
            .iter()
            .any(|c| multiplier.get(c).copied().unwrap_or(false));
        multiplier.insert(id, own || inherited);
    }
    (uses, multiplier)
}

/// The estimated written length of `id` itself, its children not counted.
fn own_length(g: &Graph, id: Id) -> usize {
    match g.node(id) {
        Node::Num(_) | Node::Sym(_) => 3,
        Node::Add(terms, _) => 4 * terms.len() + 2,
        Node::Mul(factors) => 3 * factors.len(),
        Node::Pow(_) => 3,
        Node::Func(f, _) => f.name().len() + 2,
    }
}

/// The estimated length of `roots` with everything written out, nothing
/// named (saturating: trees can be exponentially larger than the DAG).
fn written_out_length(g: &Graph, order: &[Id], roots: &[Id]) -> usize {
    let mut full: HashMap<Id, usize> = HashMap::new();
    for &id in order {
        let inner = g.children(id).fold(0usize, |sum, c| {
            sum.saturating_add(full.get(&c).copied().unwrap_or(3))
        });
        full.insert(id, own_length(g, id).saturating_add(inner));
    }
    roots.iter().fold(0usize, |sum, r| {
        sum.saturating_add(full.get(r).copied().unwrap_or(0))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> (Vec<String>, Vec<String>) {
        (vec!["x".into(), "theta".into()], vec!["alpha".into()])
    }

    #[test]
    fn both_styles() {
        let mut g = Graph::new();
        let (x, th) = (g.sym(Sym::Coord(0)), g.sym(Sym::Coord(1)));
        let (xd, thd) = (g.sym(Sym::Vel(0)), g.sym(Sym::Vel(1)));
        let alpha = g.sym(Sym::Param(0));
        let sx = g.func(crate::expr::Func::Sin, x);
        let xd2 = g.pown(xd, Num::int(2));
        let half_xd2 = g.scale(xd2, Num::ratio(1, 2));
        let a_sin = g.mul2(alpha, sx);
        let root = g.sqrt(th);
        let q = g.div(thd, root);
        let e = g.add(&[half_xd2, q]);
        let e = g.sub(e, a_sin);
        let (c, p) = names();
        let uni = Printer::new(&g, &c, &p, Style::Unicode).print(e);
        let sym = Printer::new(&g, &c, &p, Style::Sympy).print(e);
        // Terms in canonical (creation) order.
        assert_eq!(uni, "\u{1e8b}²/2 − alpha·sin(x) + \u{1e6b}heta/√theta");
        assert_eq!(sym, "dot(x)**2/2 - alpha*sin(x) + dot(theta)/sqrt(theta)");
    }

    #[test]
    fn scripts() {
        assert_eq!(superscript("-12"), "⁻¹²");
        assert_eq!(subscript(10), "₁₀");
    }
}
