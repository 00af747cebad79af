//! Straight-line code for a set of output expressions: variable bindings,
//! shared temporaries in topological order, and the outputs themselves.

mod arithmetic;

use super::context::Context;
pub(super) use super::literal::{literal, Prec};
use super::reuse::TempProducts;
use super::subproducts::{Factor, SubProducts};
use super::tokens::{let_statement, parenthesized};
use crate::equations::Equations;
use crate::expr::cse::{Paired, Schedule};
use crate::expr::num::Num;
use crate::expr::{Emission, FastHash, Func, Graph, Id, Node, Sym};
use crate::names::{acceleration_name, velocity_name};
use proc_macro2::{Span, TokenStream};
use quote::quote;
use std::collections::HashMap;
use syn::Ident;

/// The local name of each coordinate's velocity or acceleration.
fn local_names(eq: &Equations, name: fn(&str) -> String) -> Vec<Ident> {
    let c = &eq.system.coordinates;
    c.iter()
        .map(|c| Ident::new(&name(&c.to_string()), c.span()))
        .collect()
}

/// The body of one generated function: its variables, temporaries and outputs.
pub(super) struct Body<'a> {
    graph: &'a Graph,
    schedule: Schedule,
    coordinates: Vec<Ident>,
    velocities: Vec<Ident>,
    accelerations: Vec<Ident>,
    parameters: &'a [Ident],
    used: Vec<Sym>,
    temp_names: HashMap<Id, Ident, FastHash>,
    /// Nodes whose value needs the multipliers λ (computed mid-function) or
    /// the seeds `Sym::Seed` (set per column of a Jacobian).
    needs_multipliers: Vec<bool>,
    /// The temporaries that are products: a product written later reuses
    /// one whose factors it contains.
    temp_products: TempProducts,
    /// While the definition of temporary `i` is written, `i`: only those
    /// before it may be reused. `usize::MAX` elsewhere.
    defining: std::cell::Cell<usize>,
    /// Each constant's tokens, built once per body: a body writes the same
    /// few constants thousands of times.
    literals: std::cell::RefCell<HashMap<Num, TokenStream>>,
    /// Parameters that divide two or more products (a parametric mass in
    /// `q̈`, `S` and `W`): one reciprocal each, bound in the preamble, and
    /// a multiplication wherever one of them divides. Temporaries likewise
    /// (a quaternion's `|q|²`, 144 divisions of the quadruped's `q̈`), each
    /// reciprocal bound right after its temporary: LLVM keeps `x / d` a
    /// division, and the quadruped's `acceleration` ran in half the time
    /// without them.
    reciprocals: HashMap<Id, Ident, FastHash>,
    /// Products of variables and temporaries that several products share
    /// (`m·l`), each bound once right after its last factor
    /// (`super::subproducts`).
    subproducts: SubProducts,
    /// Outputs written into their places as soon as their values are
    /// known ([`Body::storing`]): the local that holds them, then each
    /// output's place and root by the position of the last temporary its
    /// expression reads (`None`: none).
    stores: Option<(TokenStream, StoresAt)>,
    /// Whether the body is large enough that its time follows the size of
    /// its code: there a sum writes each magnitude its terms share once
    /// (`c·(a − b)` for `c·a − c·b`; `arithmetic::LARGE_BODY` says why).
    shares_magnitudes: bool,
}

/// Each output's place and root, by the position of the last temporary
/// its expression reads (`None`: none).
type StoresAt = HashMap<Option<usize>, Vec<(TokenStream, Id)>>;

/// Outputs that a body writes into a local as soon as it knows each one
/// ([`Body::storing`]), rather than holding every one until the end.
pub(super) struct Stores {
    /// `let mut … = …;`: the local, with zeros where nothing is written.
    pub(super) local: TokenStream,
    /// Each output: where it is written (`__out0.data.0[c][r]`) and its
    /// expression, in the order the outputs are asked for.
    pub(super) places: Vec<(TokenStream, Id)>,
}

impl<'a> Body<'a> {
    pub(super) fn new(eq: &'a Equations, roots: &[Id]) -> Body<'a> {
        let schedule = Schedule::new(&eq.system.graph, roots);
        Body::scheduled(eq, roots, schedule)
    }

    /// A body whose outputs are written into `stores.local` as soon as
    /// each is known, its temporaries in the order the outputs ask for them
    /// ([`Schedule::in_demand_order`]): a value then leaves the registers
    /// soon after it is computed, where a value returned at the end holds
    /// one, or a slot of the stack, from its computation to the end. The
    /// order of `stores.places` is the order the outputs are asked for.
    pub(super) fn storing(eq: &'a Equations, stores: Stores) -> Body<'a> {
        let roots: Vec<Id> = stores.places.iter().map(|&(_, id)| id).collect();
        let schedule = Schedule::in_demand_order(&eq.system.graph, &roots);
        let mut body = Body::scheduled(eq, &roots, schedule);
        let position: HashMap<Id, usize, FastHash> = body
            .schedule
            .temporaries
            .iter()
            .enumerate()
            .map(|(i, &t)| (t, i))
            .collect();
        let mut at: StoresAt = HashMap::new();
        for (place, id) in stores.places {
            let ready = last_read(body.graph, &position, id);
            at.entry(ready).or_default().push((place, id));
        }
        body.stores = Some((stores.local, at));
        body
    }

    fn scheduled(eq: &'a Equations, roots: &[Id], schedule: Schedule) -> Body<'a> {
        let g = &eq.system.graph;
        let reachable = g.reachable(roots);
        let used = reachable
            .iter()
            .filter_map(|&id| match g.node(id) {
                Node::Sym(s) => Some(*s),
                _ => None,
            })
            .collect();
        let mut temp_names: HashMap<Id, Ident, FastHash> = schedule
            .temporaries
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, Context::local("t", i)))
            .collect();
        let shares_magnitudes = reachable.len() >= arithmetic::LARGE_BODY;
        let needs_multipliers = multiplier_nodes(g, &reachable);
        let temp_products = TempProducts::new(g, &schedule);
        let reciprocals = reciprocal_names(g, &reachable, &schedule.temporaries);
        let products: Vec<Id> = reachable
            .into_iter()
            .filter(|&id| matches!(g.node(id), Node::Mul(_)) && reciprocal_of(g, id).is_none())
            .collect();
        // Temporaries that are reciprocals are bound in the preamble under
        // another name, those that need λ later: neither joins a sub-product.
        let shareable = |id: Id| !needs_multipliers[id.index()] && reciprocal_of(g, id).is_none();
        let subproducts = SubProducts::plan(g, &products, &schedule.temporaries, &shareable);
        // A temporary that is itself `1/p` is the reciprocal.
        for id in &schedule.temporaries {
            if let Some(name) = reciprocal_of(g, *id).and_then(|b| reciprocals.get(&b)) {
                temp_names.insert(*id, name.clone());
            }
        }
        Body {
            reciprocals,
            subproducts,
            needs_multipliers,
            temp_products,
            literals: std::cell::RefCell::default(),
            defining: std::cell::Cell::new(usize::MAX),
            graph: g,
            schedule,
            coordinates: eq.system.coordinates.clone(),
            velocities: local_names(eq, velocity_name),
            accelerations: local_names(eq, acceleration_name),
            parameters: &eq.system.parameters,
            used,
            temp_names,
            stores: None,
            shares_magnitudes,
        }
    }

    /// The body with every term of a sum scaled by its own magnitude,
    /// however large the body (`arithmetic::LARGE_BODY`).
    pub(super) fn magnitudes_apart(mut self) -> Self {
        self.shares_magnitudes = false;
        self
    }

    /// The stores of the outputs that become known at `position` (`None`:
    /// before any temporary), each expression written with only the
    /// temporaries before it to reuse.
    fn stores_at(&self, position: Option<usize>) -> TokenStream {
        let Some((_, at)) = &self.stores else {
            return TokenStream::new();
        };
        let Some(places) = at.get(&position) else {
            return TokenStream::new();
        };
        self.defining.set(position.map_or(0, |p| p + 1));
        let stores = places.iter().map(|(place, id)| {
            let value = self.expr(*id);
            quote! { #place = #value; }
        });
        let out = quote! { #(#stores)* };
        self.defining.set(usize::MAX);
        out
    }

    /// Variable bindings, then the temporaries that do not need the
    /// multipliers λ.
    pub(super) fn preamble(&self) -> TokenStream {
        let params = self
            .parameters
            .iter()
            .enumerate()
            .filter(|(i, _)| self.used.contains(&Sym::Param(*i)))
            .map(|(_, p)| quote! { let #p = self.#p; });
        self.preamble_with(quote!(#(#params)*))
    }

    /// [`Body::preamble`] for a free function, which reads the parameters
    /// from its argument `__parameters: [T; P]` instead of `self`.
    pub(super) fn detached_preamble(&self) -> TokenStream {
        let params = self
            .used_pattern(self.parameters, Sym::Param)
            .map(|p| quote! { let #p = __parameters; });
        self.preamble_with(quote!(#params))
    }

    /// `[a, _, c]` binding the variables of `names` the body reads (`_`
    /// for the others), or `None` where it reads none.
    fn used_pattern(&self, names: &[Ident], sym: fn(usize) -> Sym) -> Option<TokenStream> {
        let any = (0..names.len()).any(|i| self.used.contains(&sym(i)));
        any.then(|| {
            let parts = names.iter().enumerate().map(|(i, name)| {
                if self.used.contains(&sym(i)) {
                    quote!(#name)
                } else {
                    quote!(_)
                }
            });
            quote! { [#(#parts),*] }
        })
    }

    fn preamble_with(&self, params: TokenStream) -> TokenStream {
        let pattern = |names: &[Ident], sym: fn(usize) -> Sym| {
            self.used_pattern(names, sym).map(|p| quote! { [#p] })
        };
        let coords = pattern(&self.coordinates, Sym::Coord).map(|p| quote! { let #p = q.data.0; });
        let vels = pattern(&self.velocities, Sym::Vel).map(|p| quote! { let #p = qd.data.0; });
        let accs =
            pattern(&self.accelerations, Sym::Accel).map(|p| quote! { let #p = qdd.data.0; });
        let mut reciprocals: Vec<(&Ident, Id)> = self
            .reciprocals
            .iter()
            .filter(|&(&b, _)| matches!(self.graph.node(b), Node::Sym(_)))
            .map(|(&b, name)| (name, b))
            .collect();
        reciprocals.sort_by_key(|&(_, b)| b);
        let reciprocals = reciprocals.into_iter().map(|(name, b)| {
            let p = self.expr(b);
            quote! { let #name = T::one() / #p; }
        });
        let mut out = quote! { #coords #vels #accs #params #(#reciprocals)* };
        out.extend(self.subproducts_after(None));
        if let Some((local, _)) = &self.stores {
            out.extend(local.clone());
            out.extend(self.stores_at(None));
        }
        out.extend(self.temporaries(false));
        out
    }

    /// The `let`s of the sub-products bound right after the temporary at
    /// `position` (`None`: those of variables only).
    fn subproducts_after(&self, position: Option<usize>) -> TokenStream {
        let lets = self
            .subproducts
            .pairs
            .iter()
            .enumerate()
            .filter(|&(i, _)| self.subproducts.after[i] == position)
            .map(|(i, &(a, b))| {
                let name = Context::local("sp", i);
                let (a, b) = (self.shared_factor(a), self.shared_factor(b));
                quote! { let #name = #a * #b; }
            });
        quote! { #(#lets)* }
    }

    /// `let __rt{i} = T::one() / t;` right after the temporary `t` where it
    /// divides two or more products.
    fn reciprocal_after(&self, id: Id) -> TokenStream {
        match (self.reciprocals.get(&id), self.temp_names.get(&id)) {
            (Some(r), Some(t)) => quote! { let #r = T::one() / #t; },
            _ => TokenStream::new(),
        }
    }

    /// A factor of a sub-product: a variable, or an earlier sub-product.
    fn shared_factor(&self, f: Factor) -> TokenStream {
        match f {
            Factor::Leaf(id) => self.expr(id),
            Factor::Shared(i) => {
                let name = Context::local("sp", i);
                quote!(#name)
            }
        }
    }

    /// Whether the body's expressions read the variable `s`.
    pub(super) fn uses(&self, s: Sym) -> bool {
        self.used.contains(&s)
    }

    /// The temporaries that need the multipliers λ or the seeds of a
    /// directional derivative, to emit once they are known.
    pub(super) fn after_multipliers(&self) -> TokenStream {
        self.temporaries(true)
    }

    /// The temporaries that need the multipliers (or not), each with what
    /// is bound right after it; in the pass without them, each output
    /// stored where the last temporary it reads is known (its roots need
    /// no multipliers: [`Body::storing`]'s are `M`'s).
    fn temporaries(&self, need_multipliers: bool) -> TokenStream {
        let mut out = TokenStream::new();
        for (position, &id) in self.schedule.temporaries.iter().enumerate() {
            let bound_in_preamble =
                reciprocal_of(self.graph, id).is_some_and(|b| self.reciprocals.contains_key(&b));
            if self.needs_multipliers[id.index()] == need_multipliers && !bound_in_preamble {
                out.extend(self.temporary(position, id));
            }
            if !need_multipliers {
                out.extend(self.stores_at(Some(position)));
            }
        }
        out
    }

    /// The `let` of the temporary `id` at `position`, and what is bound
    /// right after it.
    fn temporary(&self, position: usize, id: Id) -> TokenStream {
        let shared = self.subproducts_after(Some(position));
        // A sine and cosine of one argument: one `sin_cos`, the
        // runtime's (libm's `sincos` for `f64` and `f32`), and the
        // reciprocals of both where they divide.
        match self.schedule.paired.get(&id) {
            Some(&Paired::Later) => return shared,
            Some(&Paired::First { sin, cos, argument }) => {
                let (s, c) = (&self.temp_names[&sin], &self.temp_names[&cos]);
                let argument = self.operand(argument).0;
                let (rs, rc) = (self.reciprocal_after(sin), self.reciprocal_after(cos));
                return quote! {
                    let (#s, #c) = ::constrained::__private::sin_cos(#argument);
                    #rs
                    #rc
                    #shared
                };
            }
            None => {}
        }
        let mut shared = shared;
        shared.extend(self.reciprocal_after(id));
        let name = &self.temp_names[&id];
        self.defining.set(position);
        let value = self.node(id).0;
        self.defining.set(usize::MAX);
        // Moved into the statement, not interpolated (a copy).
        let mut statement = let_statement(name, value);
        statement.extend(shared);
        statement
    }

    /// The expression for `id` as the left operand of `*`: parenthesised
    /// only where it binds more loosely (a sum).
    pub(super) fn factor(&self, id: Id) -> TokenStream {
        self.wrapped(id, Prec::Product)
    }

    /// The expression for `id`: a temporary's name or the node inlined.
    pub(super) fn expr(&self, id: Id) -> TokenStream {
        self.operand(id).0
    }

    /// The constant `n` (an atom), from this body's cache.
    fn literal(&self, n: Num) -> TokenStream {
        self.literals
            .borrow_mut()
            .entry(n)
            .or_insert_with(|| literal(n).0)
            .clone()
    }

    fn operand(&self, id: Id) -> (TokenStream, Prec) {
        if let Some(name) = self.temp_names.get(&id) {
            return (quote!(#name), Prec::Atom);
        }
        self.node(id)
    }

    fn wrapped(&self, id: Id, at_least: Prec) -> TokenStream {
        let (tokens, prec) = self.operand(id);
        if prec < at_least {
            parenthesized(tokens)
        } else {
            tokens
        }
    }

    fn node(&self, id: Id) -> (TokenStream, Prec) {
        match self.graph.node(id) {
            Node::Num(n) => (self.literal(*n), Prec::Atom),
            Node::Sym(s) => (
                match *s {
                    Sym::Coord(i) => {
                        let c = &self.coordinates[i];
                        quote!(#c)
                    }
                    Sym::Vel(i) => {
                        let v = &self.velocities[i];
                        quote!(#v)
                    }
                    Sym::Param(i) => {
                        let p = &self.parameters[i];
                        quote!(#p)
                    }
                    Sym::Time => quote!(t),
                    Sym::Multiplier(i) => {
                        let l = Context::local("lam", i);
                        quote!(#l)
                    }
                    Sym::Seed(i) => {
                        let s = Context::local("seed", i);
                        quote!(#s)
                    }
                    Sym::Accel(i) => quote::ToTokens::to_token_stream(&self.accelerations[i]),
                },
                Prec::Atom,
            ),
            Node::Add(terms, c0) => self.sum(terms, *c0),
            Node::Mul(factors) => self.product(factors, None),
            Node::Pow([b, e]) => {
                let (b, e) = (self.wrapped(*b, Prec::Atom), self.expr(*e));
                (quote! { #b.powf(#e) }, Prec::Atom)
            }
            // `receiver.method(rest…)`: the table's name is the method of
            // `RealField` / `ComplexField`; or a runtime helper of that name.
            Node::Func(Func::Hold, args) => self.operand(args.as_slice()[0]),
            Node::Func(f, args) => {
                let method = Ident::new(f.name(), Span::call_site());
                if f.emission() == Emission::Helper {
                    let all = args.as_slice().iter().map(|&a| self.expr(a));
                    let helper = Context::helper(quote!(#method));
                    return (quote! { #helper(#(#all),*) }, Prec::Atom);
                }
                let (receiver, rest) = match args.as_slice() {
                    [first, rest @ ..] => (self.wrapped(*first, Prec::Atom), rest),
                    [] => (quote!(T::zero()), &[][..]),
                };
                let rest = rest.iter().map(|&a| self.expr(a));
                (quote! { #receiver.#method(#(#rest),*) }, Prec::Atom)
            }
        }
    }
}

/// The position among the temporaries (`position`) of the last one that
/// `id`'s expression reads: itself where it is one, else the latest its
/// inlined operands reach; `None` where it reads none.
fn last_read(g: &Graph, position: &HashMap<Id, usize, FastHash>, id: Id) -> Option<usize> {
    let mut latest = None;
    let mut stack = vec![id];
    let mut seen = std::collections::HashSet::new();
    while let Some(x) = stack.pop() {
        if !seen.insert(x) {
            continue;
        }
        match position.get(&x) {
            Some(&p) => latest = latest.max(Some(p)),
            None => stack.extend(g.children(x)),
        }
    }
    latest
}

/// Which nodes (by arena index) of `reachable` (topological) need the
/// multipliers λ or the seeds `Sym::Seed`, directly or through a child.
fn multiplier_nodes(g: &Graph, reachable: &[Id]) -> Vec<bool> {
    let mut needs_multipliers = vec![false; g.len()];
    for &id in reachable {
        needs_multipliers[id.index()] = match g.node(id) {
            Node::Sym(s) => matches!(s, Sym::Multiplier(_) | Sym::Seed(_)),
            _ => g.children(id).any(|c| needs_multipliers[c.index()]),
        };
    }
    needs_multipliers
}

/// The parameters and `temporaries` that divide two or more products of
/// `reachable`, each with the name of its reciprocal (`__rp{i}` after the
/// parameter, `__rt{i}` after the temporary's position): one reciprocal
/// each, since LLVM keeps every `x / d` a division, exactly.
fn reciprocal_names(
    g: &Graph,
    reachable: &[Id],
    temporaries: &[Id],
) -> HashMap<Id, Ident, FastHash> {
    let position: HashMap<Id, usize, FastHash> = temporaries
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect();
    let mut divides: HashMap<Id, usize> = HashMap::new();
    for &id in reachable {
        if let Node::Mul(factors) = g.node(id) {
            for &(b, e) in factors.iter() {
                let divisor =
                    matches!(g.node(b), Node::Sym(Sym::Param(_))) || position.contains_key(&b);
                if e.is_negative() && divisor {
                    *divides.entry(b).or_default() += 1;
                }
            }
        }
    }
    divides
        .into_iter()
        .filter(|&(_, count)| count >= 2)
        .filter_map(|(b, _)| match g.node(b) {
            Node::Sym(Sym::Param(i)) => Some((b, Context::local("rp", *i))),
            _ => Some((b, Context::local("rt", *position.get(&b)?))),
        })
        .collect()
}

/// `p` when `id` is the node `1/p`.
fn reciprocal_of(g: &Graph, id: Id) -> Option<Id> {
    match g.node(id) {
        Node::Mul(factors) => match factors.as_ref() {
            [(b, e)] if *e == Num::MINUS_ONE => Some(*b),
            _ => None,
        },
        _ => None,
    }
}
