//! Issue 15 asked to measure an e-graph (the `egg` crate) against the
//! rule-based factoring of `constrained_codegen::expr::common_factors` before choosing.
//! This is that measurement, on every reference model: the raw `M`, `F`,
//! `A` and `b` (the DSL lowered, the constraints differentiated, nothing
//! factored) are
//!
//! - factored by `Factorer`, as `constrained_system!` does, and
//! - saturated by egg with commutativity, associativity, distribution and
//!   factoring both ways, then extracted by the same operation cost,
//!
//! and both are costed by one function on egg's `RecExpr` (operations of
//! the expression tree, as `count_ops` counts them). Printed: the total
//! cost of each model's roots raw, factored and extracted, and the time
//! each took.
//!
//! `bash scripts/egg_compare.sh` (or `cargo run --release` here).

use constrained_codegen::expr::diff::Differentiator;
use constrained_codegen::expr::{Graph, Id, Node, Sym};
use constrained_codegen::expr::common_factors::Factorer;
use constrained_codegen::model::{self, Level};
use constrained_codegen::expr::num::Num;
use constrained_codegen::parse::SystemInput;
use egg::{rewrite as rw, CostFunction, Extractor, Language, RecExpr, Rewrite, Runner, SymbolLang};
use std::collections::HashMap;
use std::path::Path;
use std::time::{Duration, Instant};

/// `count_ops`'s rule: every operator node is one operation, leaves none.
struct Operations;

impl CostFunction<SymbolLang> for Operations {
    type Cost = usize;
    fn cost<C: FnMut(egg::Id) -> usize>(&mut self, enode: &SymbolLang, mut costs: C) -> usize {
        let own = usize::from(!enode.is_leaf());
        enode.fold(own, |sum, id| sum + costs(id))
    }
}

fn rules() -> Vec<Rewrite<SymbolLang, ()>> {
    vec![
        rw!("add-comm"; "(+ ?a ?b)" => "(+ ?b ?a)"),
        rw!("mul-comm"; "(* ?a ?b)" => "(* ?b ?a)"),
        rw!("add-assoc"; "(+ ?a (+ ?b ?c))" => "(+ (+ ?a ?b) ?c)"),
        rw!("mul-assoc"; "(* ?a (* ?b ?c))" => "(* (* ?a ?b) ?c)"),
        rw!("sub-as-add"; "(- ?a ?b)" => "(+ ?a (neg ?b))"),
        rw!("add-as-sub"; "(+ ?a (neg ?b))" => "(- ?a ?b)"),
        rw!("neg-mul"; "(* ?a (neg ?b))" => "(neg (* ?a ?b))"),
        rw!("mul-neg"; "(neg (* ?a ?b))" => "(* ?a (neg ?b))"),
        rw!("neg-neg"; "(neg (neg ?a))" => "?a"),
        rw!("distribute"; "(* ?a (+ ?b ?c))" => "(+ (* ?a ?b) (* ?a ?c))"),
        rw!("factor"; "(+ (* ?a ?b) (* ?a ?c))" => "(* ?a (+ ?b ?c))"),
        rw!("square"; "(* ?a ?a)" => "(pow ?a 2)"),
        rw!("div-mul"; "(/ (* ?a ?b) ?c)" => "(* ?a (/ ?b ?c))"),
        rw!("mul-div"; "(* ?a (/ ?b ?c))" => "(/ (* ?a ?b) ?c)"),
    ]
}

/// Our DAG as an egg expression (shared nodes added once).
struct ToEgg<'a> {
    graph: &'a Graph,
    expr: RecExpr<SymbolLang>,
    done: HashMap<Id, egg::Id>,
}

impl ToEgg<'_> {
    fn leaf(&mut self, name: String) -> egg::Id {
        self.expr.add(SymbolLang::leaf(name))
    }

    fn op(&mut self, op: &str, children: Vec<egg::Id>) -> egg::Id {
        self.expr.add(SymbolLang::new(op, children))
    }

    fn number(&mut self, n: Num) -> egg::Id {
        self.leaf(format!("{}", n.to_f64()))
    }

    fn convert(&mut self, id: Id) -> egg::Id {
        if let Some(&done) = self.done.get(&id) {
            return done;
        }
        let out = match self.graph.node(id).clone() {
            Node::Num(n) => self.number(n),
            Node::Sym(s) => self.leaf(match s {
                Sym::Coord(i) => format!("q{i}"),
                Sym::Vel(i) => format!("qd{i}"),
                Sym::Time => "t".into(),
                Sym::Param(i) => format!("p{i}"),
                Sym::Multiplier(i) => format!("lam{i}"),
                Sym::Seed(i) => format!("s{i}"),
                Sym::Accel(i) => format!("qdd{i}"),
            }),
            Node::Add(terms, c0) => {
                let mut acc: Option<egg::Id> = None;
                for &(t, c) in terms.iter() {
                    let t = self.convert(t);
                    let magnitude = magnitude(c);
                    let term = if magnitude.is_one() {
                        t
                    } else {
                        let m = self.number(magnitude);
                        self.op("*", vec![m, t])
                    };
                    acc = Some(match (acc, c.is_negative()) {
                        (None, false) => term,
                        (None, true) => self.op("neg", vec![term]),
                        (Some(a), false) => self.op("+", vec![a, term]),
                        (Some(a), true) => self.op("-", vec![a, term]),
                    });
                }
                let acc = acc.expect("a sum has terms");
                if c0.is_zero() {
                    acc
                } else {
                    let k = self.number(c0);
                    self.op("+", vec![acc, k])
                }
            }
            Node::Mul(factors) => {
                let (mut num, mut den) = (Vec::new(), Vec::new());
                for &(b, e) in factors.iter() {
                    let b = self.convert(b);
                    let magnitude = magnitude(e);
                    let power = if magnitude.is_one() {
                        b
                    } else {
                        let e = self.number(magnitude);
                        self.op("pow", vec![b, e])
                    };
                    if e.is_negative() {
                        den.push(power);
                    } else {
                        num.push(power);
                    }
                }
                let product = |this: &mut Self, items: Vec<egg::Id>| {
                    items.into_iter().reduce(|a, b| this.op("*", vec![a, b]))
                };
                let num = product(self, num).unwrap_or_else(|| self.leaf("1".into()));
                match product(self, den) {
                    Some(d) => self.op("/", vec![num, d]),
                    None => num,
                }
            }
            Node::Pow([b, e]) => {
                let (b, e) = (self.convert(b), self.convert(e));
                self.op("pow", vec![b, e])
            }
            Node::Func(f, args) => {
                let args: Vec<egg::Id> = args.as_slice().iter().map(|&a| self.convert(a)).collect();
                self.op(f.name(), args)
            }
        };
        self.done.insert(id, out);
        out
    }
}

fn magnitude(n: Num) -> Num {
    if n.is_negative() {
        -n
    } else {
        n
    }
}

fn to_egg(graph: &Graph, root: Id) -> RecExpr<SymbolLang> {
    let mut t = ToEgg {
        graph,
        expr: RecExpr::default(),
        done: HashMap::new(),
    };
    t.convert(root);
    t.expr
}

fn cost(e: &RecExpr<SymbolLang>) -> usize {
    Operations.cost_rec(e)
}

/// Every `constrained_system!` invocation of `src/models`, by name.
fn models() -> Vec<(String, SystemInput)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../src/models");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).expect("src/models") {
        let source = std::fs::read_to_string(entry.expect("entry").path()).expect("source");
        for item in syn::parse_file(&source).expect("parses").items {
            if let syn::Item::Macro(m) = item {
                if m.mac.path.is_ident("constrained_system") {
                    let input: SystemInput = syn::parse2(m.mac.tokens).expect("model parses");
                    out.push((input.name.to_string(), input));
                }
            }
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn main() {
    println!("| model | roots | raw | factored (`Factorer`) | time | egg | egg time | egg e-nodes | stopped |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let (mut total_factored, mut total_egg, mut total_raw) = (0, 0, 0);
    let (mut time_factored, mut time_egg) = (Duration::ZERO, Duration::ZERO);
    for (name, input) in models() {
        let mut system = model::check(&input).expect("model checks");
        let n = system.dof();
        let named: Vec<Id> = system.named.iter().map(|(_, id)| *id).collect();
        // The raw roots: M, F, and A, b as differentiated, unfactored.
        let mut roots: Vec<Id> = system.mass.iter().flatten().copied().collect();
        roots.extend(&system.forces);
        let mut d = Differentiator::new();
        let g = &mut system.graph;
        for c in &system.constraints {
            let velocity_level = match c.level {
                Level::Velocity => c.phi,
                Level::Position => d.time_derivative(g, c.phi, n).1,
            };
            let (row, rest) = d.time_derivative(g, velocity_level, n);
            roots.extend(row);
            roots.push(g.neg(rest));
        }
        roots.retain(|&r| !g.is_zero(r));
        let raw: usize = roots.iter().map(|&r| cost(&to_egg(g, r))).sum();

        let start = Instant::now();
        let mut factorer = Factorer::keeping(named);
        let factored = factorer.factor_all(g, &roots);
        let factored_time = start.elapsed();
        let factored: usize = factored.iter().map(|&r| cost(&to_egg(g, r))).sum();

        let start = Instant::now();
        let exprs: Vec<RecExpr<SymbolLang>> = roots.iter().map(|&r| to_egg(g, r)).collect();
        let mut runner = Runner::default()
            .with_node_limit(50_000)
            .with_iter_limit(30)
            .with_time_limit(Duration::from_secs(5));
        for e in &exprs {
            runner = runner.with_expr(e);
        }
        let runner = runner.run(&rules());
        let extractor = Extractor::new(&runner.egraph, Operations);
        let extracted: usize = runner.roots.iter().map(|&r| extractor.find_best(r).0).sum();
        let egg_time = start.elapsed();
        let stopped = format!("{:?}", runner.stop_reason.as_ref().expect("stopped"));
        let stopped = stopped.split('(').next().unwrap_or("").to_string();

        println!(
            "| {name} | {} | {raw} | {factored} | {:.2} ms | {extracted} | {:.0} ms | {} | {stopped} |",
            roots.len(),
            factored_time.as_secs_f64() * 1e3,
            egg_time.as_secs_f64() * 1e3,
            runner.egraph.total_number_of_nodes(),
        );
        total_raw += raw;
        total_factored += factored;
        total_egg += extracted;
        time_factored += factored_time;
        time_egg += egg_time;
    }
    println!(
        "| all | | {total_raw} | {total_factored} | {:.1} ms | {total_egg} | {:.1} s | | |",
        time_factored.as_secs_f64() * 1e3,
        time_egg.as_secs_f64()
    );
}
