//! Stage 2: [`SystemInput`] → [`System`]: names resolved, expressions lowered
//! into the DAG, every rule of API.md checked.
//!
//! Errors do not stop the stage: each is recorded with the span of the
//! offending tokens and lowering goes on with a placeholder, so that one
//! compilation reports every mistake of the input at once (serde's `Ctxt`).

use crate::expr::{Func, Graph, Id, Sym};
use crate::num::Num;
use crate::parse::{ConstraintInput, List, MassInput, Section, SystemInput};
use crate::rng::SplitMix64;
use proc_macro2::Span;
use quote::ToTokens;
use std::collections::HashMap;
use std::fmt::Display;
use syn::{Attribute, Expr, Ident, Visibility};

/// Errors collected during a stage, reported together.
#[derive(Default)]
pub struct Errors(Vec<syn::Error>);

impl Errors {
    /// Records an error spanning `tokens`.
    pub fn spanned(&mut self, tokens: impl ToTokens, message: impl Display) {
        self.0.push(syn::Error::new_spanned(tokens, message));
    }

    /// Records an error at `span`.
    pub fn at(&mut self, span: Span, message: impl Display) {
        self.0.push(syn::Error::new(span, message));
    }

    /// How many errors have been recorded; checks that build on lowered
    /// expressions compare it before and after, to skip follow-on errors
    /// caused by a placeholder.
    pub fn count(&self) -> usize {
        self.0.len()
    }

    /// `Ok` when nothing was recorded, else all errors combined into one.
    pub fn finish(self) -> syn::Result<()> {
        let mut errors = self.0.into_iter();
        match errors.next() {
            None => Ok(()),
            Some(mut first) => {
                first.extend(errors);
                Err(first)
            }
        }
    }
}

/// Whether a constraint is differentiated twice or once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// No velocity in φ: holonomic, differentiated twice.
    Position,
    /// Some `dot(q)` in φ: differentiated once.
    Velocity,
}

/// One constraint `φ = 0`.
#[derive(Clone, Debug)]
pub struct Constraint {
    /// φ (`lhs − rhs`), definitions substituted.
    pub phi: Id,
    /// Position or velocity level.
    pub level: Level,
}

/// A checked system: every expression is a node of `graph`.
pub struct System {
    /// Attributes forwarded to the struct.
    pub attrs: Vec<Attribute>,
    /// Visibility of the struct.
    pub vis: Visibility,
    /// Name of the struct.
    pub name: Ident,
    /// Coordinates `q`, in order.
    pub coordinates: Vec<Ident>,
    /// Parameters, in order.
    pub parameters: Vec<Ident>,
    /// The expression arena.
    pub graph: Graph,
    /// `M(q, t)`, n × n, symmetric (entry (j, i) is the node of (i, j)).
    pub mass: Vec<Vec<Id>>,
    /// `F(q, q̇, t)`.
    pub forces: Vec<Id>,
    /// `φ(q, q̇, t) = 0`.
    pub constraints: Vec<Constraint>,
    /// Coordinates named in `eliminate: [...]`, by index, with the span of
    /// the list (its size is checked against the rank of `A` later).
    pub eliminate: Option<(Vec<usize>, Span)>,
}

impl System {
    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.coordinates.len()
    }
}

/// Functions callable in the DSL besides `dot`, with their argument counts
/// (the receiver of a method call counts as the first argument).
const FUNCTIONS: &[(&str, usize)] = &[
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("asin", 1),
    ("acos", 1),
    ("atan", 1),
    ("sinh", 1),
    ("cosh", 1),
    ("tanh", 1),
    ("exp", 1),
    ("ln", 1),
    ("sqrt", 1),
    ("powi", 2),
    ("powf", 2),
    ("atan2", 2),
];

/// Names the DSL or the generated code already uses.
const RESERVED: &[&str] = &["t", "dot", "q", "qd", "T", "Self"];

/// What a name in an expression refers to.
#[derive(Clone, Copy)]
enum Binding {
    Coordinate(usize),
    Parameter(usize),
    Definition(Id),
}

/// Lowers syn expressions into the graph, resolving names.
struct Lowerer<'a> {
    graph: &'a mut Graph,
    names: HashMap<String, Binding>,
    errors: &'a mut Errors,
}

/// The sections of one input, each at most once.
#[derive(Default)]
struct Sections<'a> {
    coordinates: Option<&'a List<Ident>>,
    parameters: Option<&'a List<Ident>>,
    mass: Option<(&'a Ident, &'a MassInput)>,
    forces: Option<&'a List<Expr>>,
    definitions: Option<&'a List<(Ident, Expr)>>,
    constraints: Option<&'a List<ConstraintInput>>,
    eliminate: Option<&'a List<Ident>>,
}

impl<'a> Sections<'a> {
    fn collect(input: &'a SystemInput, errors: &mut Errors) -> Self {
        let mut s = Sections::default();
        for section in &input.sections {
            let duplicate = match section {
                Section::Coordinates(_, l) => s.coordinates.replace(l).is_some(),
                Section::Parameters(_, l) => s.parameters.replace(l).is_some(),
                Section::Mass(k, m) => s.mass.replace((k, m)).is_some(),
                Section::Forces(_, l) => s.forces.replace(l).is_some(),
                Section::Definitions(_, l) => s.definitions.replace(l).is_some(),
                Section::Constraints(_, l) => s.constraints.replace(l).is_some(),
                Section::Eliminate(_, l) => s.eliminate.replace(l).is_some(),
            };
            if duplicate {
                let k = section.keyword();
                errors.spanned(k, format!("duplicate section `{k}`"));
            }
        }
        s
    }
}

/// Checks the input and lowers it into a [`System`].
pub fn check(input: &SystemInput) -> syn::Result<System> {
    let mut errors = Errors::default();
    let sections = Sections::collect(input, &mut errors);
    for (present, name) in [
        (sections.coordinates.is_some(), "coordinates"),
        (sections.mass.is_some(), "mass"),
    ] {
        if !present {
            errors.spanned(&input.name, format!("missing section `{name}`"));
        }
    }
    let empty = Vec::new();
    let coordinates = sections.coordinates.map_or(&empty, |l| &l.items);
    if let Some(list) = sections.coordinates.filter(|l| l.items.is_empty()) {
        errors.at(list.span, "`coordinates` must name at least one coordinate");
    }
    let parameters = sections.parameters.map_or(&empty, |l| &l.items);
    let n = coordinates.len();

    let mut graph = Graph::new();
    // Interning the variables first, in a fixed order, makes canonical term
    // order (by node id) read naturally: parameters before time before
    // coordinates before velocities, each in declaration order (`α·ż`, `x + y`).
    for i in 0..parameters.len() {
        graph.sym(Sym::Param(i));
    }
    graph.sym(Sym::Time);
    for i in 0..n {
        graph.sym(Sym::Coord(i));
    }
    for i in 0..n {
        graph.sym(Sym::Vel(i));
    }
    let mut lower = Lowerer {
        graph: &mut graph,
        names: HashMap::new(),
        errors: &mut errors,
    };
    for (i, c) in coordinates.iter().enumerate() {
        lower.declare(c, Binding::Coordinate(i), coordinates);
    }
    for (i, p) in parameters.iter().enumerate() {
        lower.declare(p, Binding::Parameter(i), coordinates);
    }
    for (name, value) in sections.definitions.map_or(&[][..], |l| &l.items) {
        let id = lower.lower(value);
        lower.declare(name, Binding::Definition(id), coordinates);
    }

    let mass = sections
        .mass
        .map(|(keyword, m)| lower.mass(keyword, m, n))
        .unwrap_or_default();
    let forces = match sections.forces {
        Some(list) => {
            lower.check_len(list.span, "`forces`", list.items.len(), n);
            let mut f: Vec<Id> = list.items.iter().map(|e| lower.lower(e)).collect();
            f.resize(n, lower.graph.int(0));
            f
        }
        None => vec![lower.graph.int(0); n],
    };
    let constraints = sections
        .constraints
        .map_or(&[][..], |l| &l.items)
        .iter()
        .map(|c| lower.constraint(c))
        .collect();
    let eliminate = sections
        .eliminate
        .map(|list| (lower.eliminate(list), list.span));

    errors.finish()?;
    Ok(System {
        attrs: input.attrs.clone(),
        vis: input.vis.clone(),
        name: input.name.clone(),
        coordinates: coordinates.clone(),
        parameters: parameters.clone(),
        graph,
        mass,
        forces,
        constraints,
        eliminate,
    })
}

impl Lowerer<'_> {
    fn declare(&mut self, name: &Ident, binding: Binding, coordinates: &[Ident]) {
        let text = name.to_string();
        if RESERVED.contains(&text.as_str()) || text.starts_with("__") {
            self.errors
                .spanned(name, format!("`{text}` is a reserved name"));
        } else if FUNCTIONS.iter().any(|(f, _)| *f == text) {
            self.errors.spanned(
                name,
                format!("`{text}` is a reserved name: it is a function of the DSL"),
            );
        } else if let Some(c) = coordinates
            .iter()
            .find(|c| text == crate::emit::velocity_name(&c.to_string()))
        {
            self.errors.spanned(
                name,
                format!(
                    "`{text}` is a reserved name: it names the velocity of `{c}` in generated code"
                ),
            );
        } else if self.names.insert(text.clone(), binding).is_some() {
            self.errors
                .spanned(name, format!("`{text}` is declared twice"));
        }
    }

    /// Requires `len == n`; with no coordinates declared (already an error)
    /// every length would be wrong, so nothing more is said.
    fn check_len(&mut self, span: Span, what: &str, len: usize, n: usize) {
        if len != n && n > 0 {
            self.errors.at(
                span,
                format!(
                    "{what} has {} but there {}",
                    entries(len),
                    coordinates_count(n)
                ),
            );
        }
    }

    fn mass(&mut self, keyword: &Ident, input: &MassInput, n: usize) -> Vec<Vec<Id>> {
        let before = self.errors.count();
        let zero = self.graph.int(0);
        let mut m = vec![vec![zero; n]; n];
        let mut sources: Vec<Vec<Option<&Expr>>> = vec![vec![None; n]; n];
        match input {
            MassInput::Diagonal(list) => {
                self.check_len(list.span, "`mass`", list.items.len(), n);
                for (i, e) in list.items.iter().enumerate().take(n) {
                    m[i][i] = self.lower(e);
                    sources[i][i] = Some(e);
                }
            }
            MassInput::Full(rows) => {
                self.check_len(rows.span, "`mass`", rows.items.len(), n);
                for (i, row) in rows.items.iter().enumerate().take(n) {
                    let what = format!("row {} of `mass`", i + 1);
                    self.check_len(row.span, &what, row.items.len(), n);
                    for (j, e) in row.items.iter().enumerate().take(n) {
                        m[i][j] = self.lower(e);
                        sources[i][j] = Some(e);
                    }
                }
            }
        }
        for (i, row) in sources.iter().enumerate() {
            for (j, source) in row.iter().enumerate() {
                let Some(source) = source else { continue };
                if self.graph.mentions(m[i][j], |s| matches!(s, Sym::Vel(_))) {
                    self.errors.spanned(
                        source,
                        "`mass` may depend on coordinates, `t` and parameters, not on velocities",
                    );
                }
            }
        }
        self.check_symmetric(&mut m, &sources);
        // Missing or unreadable entries were filled with zeros.
        if self.errors.count() == before {
            self.check_constant_positive_definite(keyword, &m);
        }
        m
    }

    /// Requires `M = Mᵀ` (compared as canonical forms, then numerically at
    /// random points for forms that differ but agree), then uses the upper
    /// triangle for both halves so generated code computes each entry once.
    fn check_symmetric(&mut self, m: &mut [Vec<Id>], sources: &[Vec<Option<&Expr>>]) {
        let n = m.len();
        for i in 0..n {
            for j in i + 1..n {
                let (upper, lower) = (m[i][j], m[j][i]);
                if upper != lower && !numerically_equal(self.graph, upper, lower) {
                    if let Some(source) = sources[j][i] {
                        self.errors.spanned(
                            source,
                            format!(
                                "`mass` is not symmetric: entry ({}, {}) differs from entry ({}, {})",
                                j + 1,
                                i + 1,
                                i + 1,
                                j + 1
                            ),
                        );
                    }
                }
                m[j][i] = upper;
            }
        }
    }

    /// A constant mass matrix can be checked for positive definiteness now.
    fn check_constant_positive_definite(&mut self, keyword: &Ident, m: &[Vec<Id>]) {
        let values: Option<Vec<Vec<f64>>> = m
            .iter()
            .map(|row| {
                row.iter()
                    .map(|&e| self.graph.as_num(e).map(Num::to_f64))
                    .collect()
            })
            .collect();
        if let Some(values) = values {
            if !crate::linalg::is_positive_definite(&values) {
                self.errors
                    .spanned(keyword, "constant `mass` matrix is not positive definite");
            }
        }
    }

    fn constraint(&mut self, c: &ConstraintInput) -> Constraint {
        let before = self.errors.count();
        let lhs = self.lower(&c.lhs);
        let phi = match &c.rhs {
            Some(rhs) => {
                let rhs = self.lower(rhs);
                self.graph.sub(lhs, rhs)
            }
            None => lhs,
        };
        let velocity = self.graph.mentions(phi, |s| matches!(s, Sym::Vel(_)));
        let coordinate = self.graph.mentions(phi, |s| matches!(s, Sym::Coord(_)));
        if !velocity && !coordinate && self.errors.count() == before {
            self.errors.spanned(
                &c.tokens,
                "constraint involves no coordinate or velocity (after simplification)",
            );
        }
        Constraint {
            phi,
            level: if velocity {
                Level::Velocity
            } else {
                Level::Position
            },
        }
    }

    fn eliminate(&mut self, list: &List<Ident>) -> Vec<usize> {
        let mut indices = Vec::new();
        for name in &list.items {
            match self.names.get(&name.to_string()) {
                Some(&Binding::Coordinate(i)) if indices.contains(&i) => {
                    self.errors
                        .spanned(name, format!("`{name}` is eliminated twice"));
                }
                Some(&Binding::Coordinate(i)) => indices.push(i),
                _ => self.errors.spanned(
                    name,
                    format!("`eliminate` takes coordinates; `{name}` is not one"),
                ),
            }
        }
        indices
    }

    /// Lowers one expression; on error records it and returns `0`.
    fn lower(&mut self, e: &Expr) -> Id {
        self.try_lower(e).unwrap_or_else(|err| {
            self.errors.0.push(err);
            self.graph.int(0)
        })
    }

    fn try_lower(&mut self, e: &Expr) -> syn::Result<Id> {
        use syn::{BinOp, UnOp};
        let err = |tokens: &dyn ToTokens, message: &str| -> syn::Result<Id> {
            Err(syn::Error::new_spanned(tokens.to_token_stream(), message))
        };
        match e {
            Expr::Lit(lit) => self.literal(&lit.lit),
            Expr::Paren(p) => self.try_lower(&p.expr),
            Expr::Group(g) => self.try_lower(&g.expr),
            Expr::Path(_) => {
                let name =
                    single_ident(e).ok_or_else(|| syn::Error::new_spanned(e, "expected a name"))?;
                self.name(name)
            }
            Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => {
                let a = self.try_lower(&u.expr)?;
                Ok(self.graph.neg(a))
            }
            Expr::Binary(b) => {
                let op = match b.op {
                    BinOp::Add(_) | BinOp::Sub(_) | BinOp::Mul(_) | BinOp::Div(_) => b.op,
                    BinOp::Eq(_) => {
                        return err(e, "`==` may only stand at the top of a constraint")
                    }
                    _ => return err(&b.op, "unsupported operator: expected `+`, `-`, `*` or `/`"),
                };
                // Lower both sides even if one fails, to report both.
                let (l, r) = (self.lower(&b.left), self.try_lower(&b.right)?);
                if matches!(op, BinOp::Div(_)) && self.graph.is_zero(r) {
                    return err(&b.right, "division by zero");
                }
                Ok(match op {
                    BinOp::Add(_) => self.graph.add2(l, r),
                    BinOp::Sub(_) => self.graph.sub(l, r),
                    BinOp::Mul(_) => self.graph.mul2(l, r),
                    _ => self.graph.div(l, r),
                })
            }
            Expr::MethodCall(call) => {
                let mut args: Vec<&Expr> = vec![&call.receiver];
                args.extend(call.args.iter());
                self.apply(&call.method, &args, e)
            }
            Expr::Call(call) => {
                let Some(name) = single_ident(&call.func) else {
                    return err(&call.func, "expected a function name");
                };
                let args: Vec<&Expr> = call.args.iter().collect();
                if name == "dot" {
                    return self.velocity(&args, e);
                }
                self.apply(name, &args, e)
            }
            _ => err(
                e,
                "unsupported expression: expected numbers, names, `dot(q)`, `+ - * /`, \
                 parentheses and the functions of the DSL",
            ),
        }
    }

    fn literal(&mut self, lit: &syn::Lit) -> syn::Result<Id> {
        let (digits, suffix) = match lit {
            syn::Lit::Int(i) => (i.base10_digits(), i.suffix()),
            syn::Lit::Float(f) => (f.base10_digits(), f.suffix()),
            _ => return Err(syn::Error::new_spanned(lit, "expected a number")),
        };
        if !matches!(suffix, "" | "f64" | "f32") {
            return Err(syn::Error::new_spanned(
                lit,
                format!("unsupported suffix `{suffix}`: write plain numbers"),
            ));
        }
        let n = Num::parse_decimal(digits)
            .ok_or_else(|| syn::Error::new_spanned(lit, "expected a number"))?;
        Ok(self.graph.num(n))
    }

    fn name(&mut self, name: &Ident) -> syn::Result<Id> {
        if name == "t" {
            return Ok(self.graph.sym(Sym::Time));
        }
        match self.names.get(&name.to_string()) {
            Some(&Binding::Coordinate(i)) => Ok(self.graph.sym(Sym::Coord(i))),
            Some(&Binding::Parameter(i)) => Ok(self.graph.sym(Sym::Param(i))),
            Some(&Binding::Definition(id)) => Ok(id),
            None => Err(syn::Error::new_spanned(
                name,
                format!("unknown name `{name}`: not a coordinate, parameter, definition or `t`"),
            )),
        }
    }

    fn velocity(&mut self, args: &[&Expr], call: &Expr) -> syn::Result<Id> {
        let [arg] = args else {
            return Err(syn::Error::new_spanned(call, "`dot` takes one coordinate"));
        };
        let Some(name) = single_ident(arg) else {
            return Err(syn::Error::new_spanned(
                arg,
                "`dot` takes a coordinate name",
            ));
        };
        let kind = match self.names.get(&name.to_string()) {
            Some(&Binding::Coordinate(i)) => return Ok(self.graph.sym(Sym::Vel(i))),
            Some(Binding::Parameter(_)) => "a parameter",
            Some(Binding::Definition(_)) => "a definition",
            None if name == "t" => "time",
            None => "not declared",
        };
        Err(syn::Error::new_spanned(
            arg,
            format!("`dot` takes a coordinate, and `{name}` is {kind}"),
        ))
    }

    fn apply(&mut self, name: &Ident, args: &[&Expr], call: &Expr) -> syn::Result<Id> {
        let text = name.to_string();
        let Some(&(_, arity)) = FUNCTIONS.iter().find(|(f, _)| *f == text) else {
            let known: Vec<&str> = FUNCTIONS.iter().map(|(f, _)| *f).collect();
            return Err(syn::Error::new_spanned(
                name,
                format!(
                    "unknown function `{text}`; expected `dot` or one of {}",
                    known.join(", ")
                ),
            ));
        };
        if args.len() != arity {
            return Err(syn::Error::new_spanned(
                call,
                format!(
                    "`{text}` takes {arity} argument{} (counting the receiver of a method call)",
                    if arity == 1 { "" } else { "s" }
                ),
            ));
        }
        if text == "powi" {
            let base = self.try_lower(args[0])?;
            let exponent = self.try_lower(args[1])?;
            return match self.graph.as_num(exponent).and_then(Num::as_integer) {
                Some(k) => Ok(self.graph.pown(base, Num::int(k))),
                None => Err(syn::Error::new_spanned(
                    args[1],
                    "`powi` takes an integer exponent; use `powf` for others",
                )),
            };
        }
        let lowered: Vec<Id> = args.iter().map(|a| self.lower(a)).collect();
        let g = &mut self.graph;
        Ok(match text.as_str() {
            "sqrt" => g.sqrt(lowered[0]),
            "powf" => g.pow(lowered[0], lowered[1]),
            "atan2" => g.atan2(lowered[0], lowered[1]),
            f => g.func(
                Func::from_name(f).expect("FUNCTIONS lists only known functions"),
                lowered[0],
            ),
        })
    }
}

fn entries(len: usize) -> String {
    match len {
        1 => "1 entry".to_string(),
        _ => format!("{len} entries"),
    }
}

fn coordinates_count(n: usize) -> String {
    match n {
        1 => "is 1 coordinate".to_string(),
        _ => format!("are {n} coordinates"),
    }
}

fn single_ident(e: &Expr) -> Option<&Ident> {
    match e {
        Expr::Path(p) if p.qself.is_none() => p.path.get_ident(),
        _ => None,
    }
}

/// Whether two expressions agree at a few deterministic pseudo-random points.
fn numerically_equal(g: &Graph, a: Id, b: Id) -> bool {
    let mut rng = SplitMix64::new(0x5eed_0fad);
    (0..4).all(|_| {
        let seed = rng.next_u64();
        let v = g.eval(&[a, b], &|s| SplitMix64::value_for(seed, s));
        let scale = v[0].abs().max(v[1].abs()).max(1.0);
        (v[0] - v[1]).abs() <= 1e-12 * scale
    })
}
