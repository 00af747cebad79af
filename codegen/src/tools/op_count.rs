//! The arithmetic a generated `acceleration` performs, counted on the
//! expanded code itself: the table of BENCHMARKS.md compares it with
//! sympy's `cse` + `count_ops` on the same `q̈` (tests/sympy).
//!
//! The count follows sympy's `count_ops` rules: every `+`, `-`, `*`, `/`
//! and unary minus is one operation, every elementary function (`sin`,
//! `sqrt`, `powi`, …) one, a fused `mul_add` two; literals, loads, tuple
//! and vector construction, comparisons and the finiteness checks count
//! nothing. Only what `q̈` depends on is counted: the `let` bindings of the
//! private solver `gauss` are sliced backwards from the acceleration it
//! returns (`Aᵀ λ`, the constraint force, is left out), and of a
//! `match correction` only the `None` arm, the plain `acceleration`. A
//! function the body defines (the legs' shared code) counts what its
//! value needs at each call whose result is read, as the code it replaces
//! would. A solver that calls into the runtime for its answer (a dense
//! `M(q)`) is not straight-line and has no count.

use crate::expr::{Func, POWER_METHODS};
use syn::{Expr, Pat, Stmt};

/// Operations by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    /// Additions.
    pub add: usize,
    /// Subtractions.
    pub sub: usize,
    /// Multiplications.
    pub mul: usize,
    /// Divisions.
    pub div: usize,
    /// Negations.
    pub neg: usize,
    /// Elementary-function calls (`sin`, `cos`, `sqrt`, `powi`, …).
    pub functions: usize,
}

impl OpCount {
    /// All operations.
    pub fn total(&self) -> usize {
        self.add + self.sub + self.mul + self.div + self.neg + self.functions
    }

    fn plus(&mut self, other: &OpCount) {
        self.add += other.add;
        self.sub += other.sub;
        self.mul += other.mul;
        self.div += other.div;
        self.neg += other.neg;
        self.functions += other.functions;
    }
}

/// Whether a method or function call of generated code is one elementary
/// function: an entry of the operator table (`crate::expr::Func`, by the
/// name generated code calls), or a power as `crate::emit` writes it.
fn is_function(name: &str) -> bool {
    Func::ALL.iter().any(|f| f.name() == name) || POWER_METHODS.contains(&name)
}

/// Method and function calls that compute nothing (conversions, checks,
/// constructors of the returned vectors).
const FREE: &[&str] = &[
    "is_finite",
    "zero",
    "zeros",
    "one",
    "lit",
    "safe_minimum",
    "rank_tolerance",
    "conditioning_tolerance",
    "from_array_storage",
    "ArrayStorage",
    "clone",
    "Some",
    "unstride",
];

/// The operations of the `acceleration` of one expanded system: `None` when
/// the expansion has no straight-line solver `gauss` (or uses something the
/// counter does not know, which it refuses rather than under-counts).
pub fn acceleration(expanded: &syn::File) -> Option<OpCount> {
    solved(expanded, false)
}

/// The operations of `acceleration_and_multipliers`: `q̈` and the
/// multipliers `λ` the solve returns beside it (the last argument of the
/// fast path's `__F::stands_with`), what both need counted once. `None`
/// as for [`acceleration`], and where the solve gives no `λ` of its own.
pub fn acceleration_and_multipliers(expanded: &syn::File) -> Option<OpCount> {
    solved(expanded, true)
}

/// The operations of the fast path's `q̈`, and with `multipliers` of its `λ`.
fn solved(expanded: &syn::File, multipliers: bool) -> Option<OpCount> {
    let gauss = find_method(expanded, "gauss")?;
    let mut bindings = Vec::new();
    let mut result = None;
    collect(&gauss.stmts, &mut bindings, &mut result, &mut Vec::new())?;
    let (call, at) = result?;
    let mut ops = OpCount::default();
    let mut uses = Vec::new();
    walk(call.args.first()?, &mut ops, &mut uses)?;
    if multipliers {
        let is_with = call.args.len() == 3;
        let Some(Expr::Closure(lambda)) = call.args.last().filter(|_| is_with) else {
            return None;
        };
        walk(&lambda.body, &mut ops, &mut uses)?;
    }
    needed(&bindings, uses, at, &mut ops);
    Some(ops)
}

/// The operations of a straight-line generated method that is not a solver
/// (`inverse_dynamics`, `mass_matrix`, …): its value is its tail expression,
/// or the `__value` it checks for finiteness; for one whose body writes
/// into its caller's value (`__{name}_into`), that body's.
pub fn method(expanded: &syn::File, name: &str) -> Option<OpCount> {
    let f =
        find_method(expanded, &format!("__{name}_into")).or_else(|| find_method(expanded, name))?;
    let mut bindings = Vec::new();
    let mut result = None;
    collect(&f.stmts, &mut bindings, &mut result, &mut Vec::new())?;
    let mut ops = OpCount::default();
    let uses = match f.stmts.last()? {
        _ if bindings
            .iter()
            .any(|b| b.names.iter().any(|n| n == "__value")) =>
        {
            vec!["__value".to_string()]
        }
        Stmt::Expr(tail, None) => {
            let mut uses = Vec::new();
            walk(tail, &mut ops, &mut uses)?;
            uses
        }
        _ => return None,
    };
    needed(&bindings, uses, bindings.len(), &mut ops);
    Some(ops)
}

/// Adds the operations of every binding the names `uses` (read after
/// binding `at`) need, transitively.
fn needed(bindings: &[Binding], uses: Vec<String>, at: usize, ops: &mut OpCount) {
    let mut needed = vec![false; bindings.len()];
    let mut pending: Vec<(String, usize)> = uses.into_iter().map(|u| (u, at)).collect();
    while let Some((name, before)) = pending.pop() {
        // The latest binding of `name` before the use (shadowing resolves
        // as Rust does); names with no binding are inputs.
        let found = bindings[..before]
            .iter()
            .rposition(|b: &Binding| b.names.contains(&name));
        if let Some(i) = found {
            if !needed[i] {
                needed[i] = true;
                ops.plus(&bindings[i].ops);
                pending.extend(bindings[i].uses.iter().map(|u| (u.clone(), i)));
            }
        }
    }
}

/// One `let`: the names it binds, the operations of its initializer and
/// the names that initializer reads.
struct Binding {
    names: Vec<String>,
    ops: OpCount,
    uses: Vec<String>,
}

/// The inherent method `name` (for `gauss`, the solver's body: the
/// trait's `gauss` only forwards to it).
/// The body of the method `name`: the function in the system's module
/// of detached values (`crate::emit::detached`) that the method forwards
/// to, where there is one, else the method's own.
fn find_method<'a>(file: &'a syn::File, name: &str) -> Option<&'a syn::Block> {
    let detached = detached_functions(file)
        .find(|f| f.sig.ident == name)
        .map(|f| &*f.block);
    detached.or_else(|| {
        file.items
            .iter()
            .filter_map(|item| match item {
                syn::Item::Impl(i) if i.trait_.is_none() => Some(i),
                _ => None,
            })
            .flat_map(|i| i.items.iter())
            .find_map(|item| match item {
                syn::ImplItem::Fn(f) if f.sig.ident == name => Some(&f.block),
                _ => None,
            })
    })
}

/// The functions of an expansion's module of detached values
/// (`crate::emit::detached`), which a large model's `M`, `F`, `φ`, `φ̇` and
/// `(A, b)` methods forward to.
pub fn detached_functions(file: &syn::File) -> impl Iterator<Item = &syn::ItemFn> {
    file.items
        .iter()
        .filter_map(|item| match item {
            syn::Item::Mod(m) if m.ident.to_string().starts_with("__constrained_") => {
                m.content.as_ref()
            }
            _ => None,
        })
        .flat_map(|(_, items)| items.iter())
        .filter_map(|item| match item {
            syn::Item::Fn(f) => Some(f),
            _ => None,
        })
}

/// Collects the bindings of `stmts` in order (blocks are entered, early
/// returns and checks skipped, and with them the suspect path) and the
/// acceleration: the first argument of the fast path's `__F::stands`,
/// with the number of bindings before it.
fn collect<'a>(
    stmts: &'a [Stmt],
    bindings: &mut Vec<Binding>,
    result: &mut Option<(&'a syn::ExprCall, usize)>,
    functions: &mut Vec<(String, OpCount)>,
) -> Option<()> {
    for stmt in stmts {
        match stmt {
            // A block of a long body (`crate::emit::chunks`): its bindings
            // are the ones the names it exports resolve to.
            Stmt::Local(local) if exported_block(local).is_some() => {
                collect(exported_block(local)?, bindings, result, functions)?;
            }
            Stmt::Local(local) => {
                let mut names = Vec::new();
                pattern_names(&local.pat, &mut names)?;
                let mut ops = OpCount::default();
                let mut uses = Vec::new();
                if let Some(init) = &local.init {
                    // A call of a function the body defines costs that
                    // function's operations, at every call.
                    match nested_call(&init.expr, functions) {
                        Some((cost, args)) => {
                            ops.plus(&cost);
                            walk_all(args, &mut ops, &mut uses)?;
                        }
                        None => walk(&init.expr, &mut ops, &mut uses)?,
                    }
                }
                bindings.push(Binding { names, ops, uses });
            }
            Stmt::Item(syn::Item::Fn(f)) => functions.push(nested_function(f)?),
            Stmt::Expr(Expr::Block(block), _) => {
                collect(&block.block.stmts, bindings, result, functions)?;
            }
            // A value stored into its place of an output local
            // (`crate::emit::body`'s stores): a new binding of the local
            // that reads the old one, so that reading the local at the end
            // counts every store.
            Stmt::Expr(Expr::Assign(store), _) => {
                let local = stored_local(&store.left)?;
                let mut ops = OpCount::default();
                let mut uses = vec![local.clone()];
                walk(&store.right, &mut ops, &mut uses)?;
                bindings.push(Binding {
                    names: vec![local],
                    ops,
                    uses,
                });
            }
            Stmt::Expr(expr, _) => {
                if let Some(call) = returned(expr) {
                    *result = Some((call, bindings.len()));
                }
            }
            Stmt::Item(_) | Stmt::Macro(_) => return None,
        }
    }
    Some(())
}

/// The name and the operations of a function defined inside a generated
/// body (`crate::emit::mass_inverse::factored`'s legs' shared code): what
/// its value needs, as [`method`] counts a method.
fn nested_function(f: &syn::ItemFn) -> Option<(String, OpCount)> {
    let mut bindings = Vec::new();
    collect(&f.block.stmts, &mut bindings, &mut None, &mut Vec::new())?;
    let Stmt::Expr(value, None) = f.block.stmts.last()? else {
        return None;
    };
    let mut ops = OpCount::default();
    let mut uses = Vec::new();
    walk(value, &mut ops, &mut uses)?;
    needed(&bindings, uses, bindings.len(), &mut ops);
    Some((f.sig.ident.to_string(), ops))
}

/// The arguments of a call.
type Arguments = syn::punctuated::Punctuated<Expr, syn::Token![,]>;

/// A call of one of `functions`: its operations and its arguments.
fn nested_call<'a>(
    expr: &'a Expr,
    functions: &[(String, OpCount)],
) -> Option<(OpCount, &'a Arguments)> {
    let Expr::Call(c) = expr else { return None };
    let Expr::Path(path) = &*c.func else {
        return None;
    };
    let name = path.path.segments.last()?.ident.to_string();
    let (_, cost) = functions.iter().find(|(f, _)| *f == name)?;
    Some((*cost, &c.args))
}

/// The local whose part `place` is (`__out.data.0[3][1]` → `__out`).
fn stored_local(place: &Expr) -> Option<String> {
    match place {
        Expr::Path(p) => p.path.get_ident().map(ToString::to_string),
        Expr::Field(f) => stored_local(&f.base),
        Expr::Index(i) => stored_local(&i.expr),
        Expr::Paren(p) => stored_local(&p.expr),
        _ => None,
    }
}

/// The statements of `let (a, b, …) = { …; (a, b, …) };`, a block of a
/// long body exporting the names it binds (`crate::emit::chunks`).
fn exported_block(local: &syn::Local) -> Option<&[Stmt]> {
    let Pat::Tuple(pattern) = &local.pat else {
        return None;
    };
    let Expr::Block(block) = &*local.init.as_ref()?.expr else {
        return None;
    };
    let Some(Stmt::Expr(Expr::Tuple(value), None)) = block.block.stmts.last() else {
        return None;
    };
    let names = |elems: Vec<Option<String>>| elems.into_iter().collect::<Option<Vec<String>>>();
    let bound = names(
        pattern
            .elems
            .iter()
            .map(|p| match p {
                Pat::Ident(p) => Some(p.ident.to_string()),
                _ => None,
            })
            .collect(),
    )?;
    let read = names(
        value
            .elems
            .iter()
            .map(|e| match e {
                Expr::Path(p) => p.path.get_ident().map(ToString::to_string),
                _ => None,
            })
            .collect(),
    )?;
    (bound == read).then_some(&block.block.stmts[..block.block.stmts.len() - 1])
}

/// The fast path's value `__F::stands(q̈, move || Fᶜ)` (or
/// `__F::stands_with(q̈, move || Fᶜ, move || λ)`).
fn returned(expr: &Expr) -> Option<&syn::ExprCall> {
    let Expr::Call(call) = expr else { return None };
    let Expr::Path(path) = &*call.func else {
        return None;
    };
    let last = &path.path.segments.last()?.ident;
    (last == "stands" || last == "stands_with").then_some(call)
}

fn pattern_names(pat: &Pat, names: &mut Vec<String>) -> Option<()> {
    match pat {
        Pat::Ident(p) => names.push(p.ident.to_string()),
        Pat::Tuple(t) => {
            for p in &t.elems {
                pattern_names(p, names)?;
            }
        }
        Pat::Slice(s) => {
            for p in &s.elems {
                pattern_names(p, names)?;
            }
        }
        // `let Some(x) = … else { … }`.
        Pat::TupleStruct(t) => {
            for p in &t.elems {
                pattern_names(p, names)?;
            }
        }
        Pat::Wild(_) => {}
        Pat::Type(t) => pattern_names(&t.pat, names)?,
        _ => return None,
    }
    Some(())
}

/// How many elementary functions a call named `name` evaluates: two for
/// `sin_cos` (a method, or the runtime's function), one for the others.
fn functions(name: &str) -> usize {
    if name == "sin_cos" {
        2
    } else {
        usize::from(is_function(name))
    }
}

/// Adds the operations of `expr` to `ops` and the names it reads to `uses`.
fn walk(expr: &Expr, ops: &mut OpCount, uses: &mut Vec<String>) -> Option<()> {
    match expr {
        Expr::Binary(b) => {
            count_binary(&b.op, ops);
            walk(&b.left, ops, uses)?;
            walk(&b.right, ops, uses)?;
        }
        Expr::Unary(u) => {
            if matches!(u.op, syn::UnOp::Neg(_)) {
                ops.neg += 1;
            }
            walk(&u.expr, ops, uses)?;
        }
        Expr::MethodCall(m) => method_call(m, ops, uses)?,
        Expr::Call(c) => call(c, ops, uses)?,
        Expr::Path(p) => {
            if let Some(ident) = p.path.get_ident() {
                uses.push(ident.to_string());
            }
        }
        Expr::Match(m) => {
            let correction = matches!(&*m.expr, Expr::Path(p) if p.path.is_ident("correction"));
            for arm in &m.arms {
                if correction && !pattern_is_none(&arm.pat) {
                    continue;
                }
                walk(&arm.body, ops, uses)?;
            }
        }
        Expr::If(i) => {
            walk(&i.cond, ops, uses)?;
            block(&i.then_branch.stmts, ops, uses)?;
            if let Some((_, e)) = &i.else_branch {
                walk(e, ops, uses)?;
            }
        }
        Expr::Block(b) => block(&b.block.stmts, ops, uses)?,
        Expr::Paren(p) => walk(&p.expr, ops, uses)?,
        Expr::Group(g) => walk(&g.expr, ops, uses)?,
        Expr::Tuple(t) => walk_all(&t.elems, ops, uses)?,
        Expr::Array(a) => walk_all(&a.elems, ops, uses)?,
        Expr::Lit(_) => {}
        Expr::Field(f) => walk(&f.base, ops, uses)?,
        Expr::Reference(r) => walk(&r.expr, ops, uses)?,
        _ => return None,
    }
    Some(())
}

/// Counts the arithmetic operation of a binary operator (compound
/// assignments included); comparisons and the logic of checks compute no
/// value of q̈ and count nothing.
fn count_binary(op: &syn::BinOp, ops: &mut OpCount) {
    use syn::BinOp;
    match op {
        BinOp::Add(_) | BinOp::AddAssign(_) => ops.add += 1,
        BinOp::Sub(_) | BinOp::SubAssign(_) => ops.sub += 1,
        BinOp::Mul(_) | BinOp::MulAssign(_) => ops.mul += 1,
        BinOp::Div(_) | BinOp::DivAssign(_) => ops.div += 1,
        _ => {}
    }
}

/// [`walk`] over each of `exprs` in turn.
fn walk_all<'a>(
    exprs: impl IntoIterator<Item = &'a Expr>,
    ops: &mut OpCount,
    uses: &mut Vec<String>,
) -> Option<()> {
    for e in exprs {
        walk(e, ops, uses)?;
    }
    Some(())
}

/// A method call: `mul_add` is a multiply and an add, the elementary
/// functions count as such, the free methods (conversions) count nothing, and
/// any other method leaves straight-line code (`None`).
fn method_call(m: &syn::ExprMethodCall, ops: &mut OpCount, uses: &mut Vec<String>) -> Option<()> {
    let name = m.method.to_string();
    if name == "mul_add" {
        ops.mul += 1;
        ops.add += 1;
    } else if let count @ 1.. = functions(&name) {
        ops.functions += count;
    } else if !FREE.contains(&name.as_str()) {
        return None;
    }
    walk(&m.receiver, ops, uses)?;
    walk_all(&m.args, ops, uses)
}

/// A call of a path: the runtime's scalar helpers (`sin_cos`, `signum`,
/// `step`) count as elementary functions, the free ones count nothing, and a
/// call into the rest of the runtime is not straight-line (`None`).
fn call(c: &syn::ExprCall, ops: &mut OpCount, uses: &mut Vec<String>) -> Option<()> {
    let Expr::Path(path) = &*c.func else {
        return None;
    };
    let name = path.path.segments.last()?.ident.to_string();
    if let count @ 1.. = functions(&name) {
        ops.functions += count;
    } else if !FREE.contains(&name.as_str()) {
        return None;
    }
    // `lit(2.5)` is a constant: its literal is not read.
    if name != "lit" {
        walk_all(&c.args, ops, uses)?;
    }
    Some(())
}

/// The expression statements of a block inside an initializer.
fn block(stmts: &[Stmt], ops: &mut OpCount, uses: &mut Vec<String>) -> Option<()> {
    for stmt in stmts {
        match stmt {
            Stmt::Expr(e, _) => walk(e, ops, uses)?,
            _ => return None,
        }
    }
    Some(())
}

fn pattern_is_none(pat: &Pat) -> bool {
    match pat {
        Pat::Path(p) => p.path.segments.last().is_some_and(|s| s.ident == "None"),
        Pat::Ident(p) => p.ident == "None",
        _ => false,
    }
}

#[cfg(test)]
#[path = "op_count_tests.rs"]
mod tests;
