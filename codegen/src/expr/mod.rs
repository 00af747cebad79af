//! The expression DAG: an arena of hash-consed nodes in canonical form.
//!
//! Nodes live in a `Vec` and refer to their children by [`Id`]; a child is
//! always created before its parent, so arena order is a topological order.
//! Every node is built through a constructor (`build.rs`) that canonicalises
//! it and then looks it up in a hash map, so two structurally equal
//! expressions are the same `Id`. Common subexpressions are therefore shared
//! by construction, and equality of canonical forms is an `Id` comparison.
//!
//! Canonical form (the invariants the constructors maintain):
//! - sums are `Σ cᵢ·tᵢ + c₀` with terms sorted by `Id`, merged, no zero
//!   coefficient; a term is never a number or a sum; `1·x + 0` is `x`;
//! - products are `Π bᵢ^eᵢ` with rational exponents, bases sorted and merged,
//!   no zero exponent; a product of more than eight factors is not flattened
//!   into a product that multiplies it (it stays one base), which keeps
//!   derivatives of deep compositions linear in size; a numeric coefficient never sits inside a product but in
//!   the sum around it (`3·x·y` is `Add[(x·y, 3)]`); a number is a base only
//!   under a non-integer exponent (`√2`); `x^1` is `x`;
//! - `Pow` only for a non-constant exponent (`x.powf(y)`);
//! - elementary functions are [`Func`] nodes of the operator table
//!   (`func.rs`);
//! - constant arithmetic is folded exactly (see [`Num`]).
//!
//! Walkers see a node's operands through [`Node::children`] and rebuild one
//! with [`Node::map_children`] and [`Graph::rebuild`]; neither allocates, and
//! every walk here is iterative in arena order, so no input nests deep
//! enough to overflow the stack.

mod build;
pub mod common_factors;
pub(crate) mod cse;
pub mod diff;
pub(crate) mod finite;
pub(crate) mod func;
pub(crate) mod lagrange;
pub mod num;
pub mod print;
pub(crate) mod rounded;
pub(crate) mod squares;
pub mod tape;
#[cfg(test)]
mod tests;
pub(crate) mod trig;

pub use func::{Args, Emission, Func, Parity, Visibility, POWER_METHODS};

use crate::expr::num::Num;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

/// A multiply-rotate hasher (the Fx hash of rustc) for the graph's maps:
/// their keys are nodes and ids the macro builds itself, so SipHash's
/// protection against chosen keys buys nothing and costs a few percent of
/// an expansion.
#[derive(Default, Clone, Copy)]
pub struct FastHasher(u64);

impl FastHasher {
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl Hasher for FastHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
    }

    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }

    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }

    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }

    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }

    // The constants' `i128`s: two words, not `write`'s byte loop, which an
    // unoptimized proc macro (cargo's default release profile) runs slowly.
    fn write_u128(&mut self, i: u128) {
        self.add(i as u64);
        self.add((i >> 64) as u64);
    }

    fn write_i128(&mut self, i: i128) {
        self.write_u128(i as u128);
    }

    fn write_i64(&mut self, i: i64) {
        self.add(i as u64);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

/// Builds [`FastHasher`]s.
pub type FastHash = BuildHasherDefault<FastHasher>;

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
    /// Component `sᵢ` of the direction of a directional derivative
    /// (`crate::equations::tangent`): a column of the Jacobian at run time.
    Seed(usize),
    /// Acceleration `q̈ᵢ`: an argument of inverse dynamics only.
    Accel(usize),
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
    /// `[base, exponent]`: `base ^ exponent` with a non-constant exponent.
    Pow([Id; 2]),
    /// `f(args)`, a function of the operator table.
    Func(Func, Args),
}

/// The operands of a node, in order, without allocating.
pub enum Children<'a> {
    /// The terms of a sum or the bases of a product.
    Weighted(std::slice::Iter<'a, (Id, Num)>),
    /// Plain operands.
    Plain(std::slice::Iter<'a, Id>),
}

impl Iterator for Children<'_> {
    type Item = Id;

    fn next(&mut self) -> Option<Id> {
        match self {
            Children::Weighted(it) => it.next().map(|&(id, _)| id),
            Children::Plain(it) => it.next().copied(),
        }
    }
}

impl Node {
    /// The operands of this node (none for a leaf).
    pub fn children(&self) -> Children<'_> {
        match self {
            Node::Num(_) | Node::Sym(_) => Children::Plain([].iter()),
            Node::Add(items, _) | Node::Mul(items) => Children::Weighted(items.iter()),
            Node::Pow(pair) => Children::Plain(pair.iter()),
            Node::Func(_, args) => Children::Plain(args.as_slice().iter()),
        }
    }

    /// The same operator over operands mapped by `f` (not canonicalised:
    /// pass it to [`Graph::rebuild`]).
    pub fn map_children(&self, mut f: impl FnMut(Id) -> Id) -> Node {
        match self {
            Node::Num(_) | Node::Sym(_) => self.clone(),
            Node::Add(terms, c0) => Node::Add(terms.iter().map(|&(t, c)| (f(t), c)).collect(), *c0),
            Node::Mul(factors) => Node::Mul(factors.iter().map(|&(b, e)| (f(b), e)).collect()),
            Node::Pow([b, e]) => Node::Pow([f(*b), f(*e)]),
            Node::Func(func, args) => Node::Func(*func, args.map(f)),
        }
    }

    /// The value of this node in `f64`, given its operands' values.
    pub fn value(&self, operand: impl Fn(Id) -> f64, env: &dyn Fn(Sym) -> f64) -> f64 {
        match self {
            Node::Num(n) => n.to_f64(),
            Node::Sym(s) => env(*s),
            Node::Add(terms, c0) => terms
                .iter()
                .fold(c0.to_f64(), |acc, &(t, c)| acc + c.to_f64() * operand(t)),
            Node::Mul(factors) => factors
                .iter()
                .fold(1.0, |acc, &(b, e)| acc * power(operand(b), e)),
            Node::Pow([b, e]) => operand(*b).powf(operand(*e)),
            Node::Func(f, args) => {
                let mut values = [0.0; 2];
                for (v, &a) in values.iter_mut().zip(args.as_slice()) {
                    *v = operand(a);
                }
                f.eval(&values[..f.arity()])
            }
        }
    }
}

/// The arena of hash-consed nodes.
#[derive(Clone, Debug, Default)]
pub struct Graph {
    nodes: Vec<Node>,
    /// Each node's hash and id: a node is found by its hash and compared
    /// with the arena's, so it is stored once.
    index: hashbrown::HashTable<(u64, Id)>,
}

/// A node's hash in [`Graph`]'s index.
fn hash_of(node: &Node) -> u64 {
    let mut h = FastHasher::default();
    node.hash(&mut h);
    h.finish()
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

    /// Every numeric constant in the arena.
    pub fn constants(&self) -> impl Iterator<Item = Num> + '_ {
        // The coefficients of sums and the exponents of products are
        // constants too, written into the code like the `Num` nodes.
        self.nodes.iter().flat_map(|n| {
            let (own, weights): (Option<Num>, &[(Id, Num)]) = match n {
                Node::Num(c) => (Some(*c), &[]),
                Node::Add(terms, c0) => (Some(*c0), terms),
                Node::Mul(factors) => (None, factors),
                _ => (None, &[]),
            };
            own.into_iter().chain(weights.iter().map(|&(_, w)| w))
        })
    }

    /// Every node's `Id`, in arena (topological) order.
    pub fn ids(&self) -> impl Iterator<Item = Id> {
        (0..self.nodes.len()).map(|i| Id(i as u32))
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the graph has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Forgets every node made after the graph had `len` nodes, as if they
    /// had never been made: an alternative built only to be costed leaves
    /// no trace, so that what is built next is interned, and named, as it
    /// would have been without it. Ids of the forgotten nodes must not be
    /// used again.
    pub fn truncate(&mut self, len: usize) {
        while self.nodes.len() > len {
            let Some(node) = self.nodes.pop() else {
                break;
            };
            let id = Id(self.nodes.len() as u32);
            let hash = hash_of(&node);
            if let Ok(entry) = self.index.find_entry(hash, |&(h, i)| h == hash && i == id) {
                entry.remove();
            }
        }
    }

    /// The sum `−s` when the graph holds it, for a sum `s`: a square of
    /// `s` is the square of `−s`, which the derivation prints by the name
    /// `−s` may have (`dt(px)²` rather than its negated expansion).
    pub fn existing_negation(&self, s: Id) -> Option<Id> {
        let Node::Add(terms, c0) = self.node(s) else {
            return None;
        };
        let negated = Node::Add(terms.iter().map(|&(t, c)| (t, -c)).collect(), -*c0);
        self.find(&negated)
    }

    fn intern(&mut self, node: Node) -> Id {
        let hash = hash_of(&node);
        if let Some(id) = self.find_hashed(hash, &node) {
            return id;
        }
        let id = Id(u32::try_from(self.nodes.len()).expect("expression graph exceeds 2^32 nodes"));
        self.nodes.push(node);
        self.index.insert_unique(hash, (hash, id), |&(h, _)| h);
        id
    }

    /// The id of `node` if the arena holds it.
    fn find(&self, node: &Node) -> Option<Id> {
        self.find_hashed(hash_of(node), node)
    }

    /// [`Graph::find`] with the node's hash given.
    fn find_hashed(&self, hash: u64, node: &Node) -> Option<Id> {
        self.index
            .find(hash, |&(h, id)| {
                h == hash && self.nodes[id.index()] == *node
            })
            .map(|&(_, id)| id)
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

    /// The direct children of a node.
    pub fn children(&self, id: Id) -> Children<'_> {
        self.node(id).children()
    }

    /// Replaces variables by expressions (`map` returns `None` to keep one),
    /// rebuilding through the canonicalising constructors.
    pub fn substitute(&mut self, root: Id, map: &dyn Fn(Sym) -> Option<Id>) -> Id {
        self.substitute_all(&[root], map)[0]
    }

    /// [`Graph::substitute`] in each of `roots`, in one walk over what they
    /// reach (their shared nodes rebuilt once).
    pub fn substitute_all(&mut self, roots: &[Id], map: &dyn Fn(Sym) -> Option<Id>) -> Vec<Id> {
        let mut done: HashMap<Id, Id> = HashMap::new();
        for id in self.reachable(roots) {
            let node = self.node(id);
            let result = match node {
                Node::Num(_) => id,
                Node::Sym(s) => map(*s).unwrap_or(id),
                _ => {
                    let mapped = node.map_children(|c| done[&c]);
                    if mapped == *node {
                        id
                    } else {
                        self.rebuild(mapped)
                    }
                }
            };
            done.insert(id, result);
        }
        roots.iter().map(|r| done[r]).collect()
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
        let mut found = Vec::new();
        self.visit_reachable(roots, |id| found.push(id));
        // Arena order is topological; sorting what was found costs its own
        // size, not the graph's (many small walks of a robot's large graph).
        found.sort_unstable();
        found
    }

    /// Calls `visit` once for each node `roots` reach (themselves
    /// included), in no particular order: for a fold that needs none, such
    /// as a count, without [`Graph::reachable`]'s list and sort.
    pub fn visit_reachable(&self, roots: &[Id], visit: impl FnMut(Id)) {
        self.visit_unseen(roots, &mut vec![false; self.nodes.len()], visit);
    }

    /// Calls `visit` once for each node `roots` reach that `seen` does not
    /// mark, and marks it. `seen` is indexed by `Id` and grows to the
    /// graph's size: a node made after it was last used starts unmarked,
    /// as no older node reaches it.
    pub fn visit_unseen(&self, roots: &[Id], seen: &mut Vec<bool>, mut visit: impl FnMut(Id)) {
        if seen.len() < self.nodes.len() {
            seen.resize(self.nodes.len(), false);
        }
        let mut stack: Vec<Id> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if std::mem::replace(&mut seen[id.index()], true) {
                continue;
            }
            visit(id);
            stack.extend(self.children(id));
        }
    }

    /// Evaluates `roots` in `f64` with the variables given by `env` (once:
    /// for many points, compile them with [`Graph::tape`]).
    pub fn eval(&self, roots: &[Id], env: &dyn Fn(Sym) -> f64) -> Vec<f64> {
        self.tape(roots).eval(env)
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

/// `x^e` in `f64`, exact for integer and half-integer exponents. An
/// integer beyond `i32` goes to `powf`: `powi(k as i32)` wrapped `2³²` to
/// 0, and `x^(2³²)` was 1.
pub fn power(x: f64, e: Num) -> f64 {
    let integer = |x: f64, k: i64| match i32::try_from(k) {
        Ok(k) => x.powi(k),
        Err(_) => x.powf(k as f64),
    };
    match e.as_integer() {
        Some(k) => integer(x, k),
        None if matches!(e, Num::Rational(_, 2)) => {
            let k = (e * Num::int(2)).as_integer().unwrap_or(1);
            integer(x.sqrt(), k)
        }
        None => x.powf(e.to_f64()),
    }
}

/// `id` at one fixed generic point (each symbol a distinct value): the unit
/// tests' check that a rewrite kept an expression's value.
#[cfg(test)]
pub(crate) fn sample(g: &Graph, id: Id) -> f64 {
    g.eval(&[id], &|s| match s {
        Sym::Coord(i) => 0.3 + 0.7 * i as f64,
        Sym::Vel(i) => -0.4 + 0.9 * i as f64,
        Sym::Param(i) => 1.1 + 0.5 * i as f64,
        _ => 0.25,
    })[0]
}
