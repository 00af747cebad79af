//! Name resolution and lowering: DSL expressions (syn) into the DAG, each
//! name resolved to what it refers to. An expression that cannot be lowered
//! is recorded as an error and replaced by `0`, so lowering goes on.

use super::check;
use super::ctxt::Errors;
use crate::expr::diff::Differentiator;
use crate::expr::num::Num;
use crate::expr::{Args, Func, Graph, Id, Sym};
use crate::names::{acceleration_name, velocity_name, CONSTANTS, GENERATED_PREFIX, RESERVED};
use quote::ToTokens;
use std::collections::HashMap;
use syn::{Expr, Ident};

/// A DSL function lowered to sums, products and powers rather than to a
/// function node: a row of [`ALGEBRAIC`].
pub struct Algebraic {
    /// The DSL name.
    pub name: &'static str,
    /// The argument count (a method's receiver counts).
    pub arity: usize,
    /// The expression, from the lowered arguments (`arity` of them).
    lower: fn(&mut Graph, &[Id]) -> Id,
}

/// The DSL's algebraic functions, the complement of the operator table
/// (`crate::expr::Func`): every other function name of the DSL comes from
/// the table. `powi` is checked (an integer exponent that fits `i32`)
/// before it is lowered.
pub const ALGEBRAIC: &[Algebraic] = &[
    Algebraic {
        name: "sqrt",
        arity: 1,
        lower: |g, x| g.sqrt(x[0]),
    },
    Algebraic {
        name: "powi",
        arity: 2,
        lower: |g, x| g.pow(x[0], x[1]),
    },
    Algebraic {
        name: "powf",
        arity: 2,
        lower: |g, x| g.pow(x[0], x[1]),
    },
    // √(x² + y²): exact symbolically, and sympy has no `hypot`.
    Algebraic {
        name: "hypot",
        arity: 2,
        lower: |g, x| {
            let (x2, y2) = (g.pown(x[0], Num::int(2)), g.pown(x[1], Num::int(2)));
            let r2 = g.add2(x2, y2);
            g.sqrt(r2)
        },
    },
    // min(max(x, lo), hi): never panics when lo > hi (Rust's `clamp`
    // does), and its derivatives follow from max and min.
    Algebraic {
        name: "clamp",
        arity: 3,
        lower: |g, x| {
            let low = g.apply(Func::Max, Args::two(x[0], x[1]));
            g.apply(Func::Min, Args::two(low, x[2]))
        },
    },
];

/// Every function name the DSL accepts besides `dot`, for messages.
pub fn function_names() -> Vec<&'static str> {
    Func::ALL
        .iter()
        .filter(|f| f.in_dsl())
        .map(|f| f.name())
        .chain(ALGEBRAIC.iter().map(|f| f.name))
        .chain(["dt"])
        .collect()
}

/// What a name in an expression refers to.
#[derive(Clone, Copy)]
pub enum Binding {
    /// Coordinate `qᵢ`.
    Coordinate(usize),
    /// Parameter `pᵢ`.
    Parameter(usize),
    /// A definition, already lowered.
    Definition(Id),
}

/// Lowers syn expressions into the graph, resolving names.
pub struct Lowerer<'a> {
    /// The arena being built.
    pub graph: &'a mut Graph,
    /// The names declared so far.
    pub names: HashMap<String, Binding>,
    /// Where errors go.
    pub errors: &'a mut Errors,
    /// The number of coordinates (for `dt`).
    pub n: usize,
    /// Named expressions for the derivation's text, in order: definitions,
    /// and `dt(name)` of a definition.
    pub named: Vec<(String, Id)>,
    /// Each body's frame in the world, by name (systems with bodies).
    pub frames: Vec<(String, crate::bodies::Placement)>,
    /// Each body's parent (by index in `frames`) and frame in the parent's
    /// (`crate::bodies::parent_frames`), for points' positions.
    pub chain: Vec<(Option<usize>, crate::bodies::Placement)>,
    /// By the same index, `(w, x)`: the quaternion's and the position's
    /// first coordinates of a free base on the world
    /// (`crate::bodies::free::free_base`).
    pub bases: Vec<Option<(usize, usize)>>,
    /// What the rules read beside the lowered system (`check::check`).
    pub written: check::Written,
    /// The kinematics of a `frames` section, until the bodies' terms take
    /// them (`crate::bodies::kinematics`).
    pub kinematics: Option<crate::bodies::kinematics::Kinematics>,
    /// The described bodies, by the index of `frames`, for the angular
    /// velocities of orientation locks (`super::rotation`).
    pub described: Vec<crate::bodies::Described>,
}

impl<'a> Lowerer<'a> {
    /// A lowerer of `n` coordinates with nothing declared.
    pub fn new(graph: &'a mut Graph, errors: &'a mut Errors, n: usize) -> Self {
        Lowerer {
            graph,
            names: HashMap::new(),
            errors,
            n,
            named: Vec::new(),
            frames: Vec::new(),
            chain: Vec::new(),
            bases: Vec::new(),
            written: check::Written::default(),
            kinematics: None,
            described: Vec::new(),
        }
    }

    /// Declares `name`, or records why it cannot be one: reserved by the
    /// DSL or by generated code, a function of the DSL, or declared twice.
    pub fn declare(&mut self, name: &Ident, binding: Binding, coordinates: &[Ident]) {
        let text = name.to_string();
        if text.starts_with("r#") {
            self.errors.spanned(
                name,
                format!("raw identifier `{text}` is not supported: choose another name"),
            );
        } else if RESERVED.contains(&text.as_str()) || text.starts_with(GENERATED_PREFIX) {
            self.errors
                .spanned(name, format!("`{text}` is a reserved name"));
        } else if CONSTANTS.iter().any(|(c, _)| *c == text) {
            self.errors.spanned(
                name,
                format!("`{text}` is a reserved name: it is a constant of the DSL"),
            );
        } else if function_names().contains(&text.as_str()) {
            self.errors.spanned(
                name,
                format!("`{text}` is a reserved name: it is a function of the DSL"),
            );
        } else if let Some((c, what)) = coordinates.iter().find_map(|c| {
            let c = c.to_string();
            let what = if text == velocity_name(&c) {
                "velocity"
            } else if text == acceleration_name(&c) {
                "acceleration"
            } else {
                return None;
            };
            Some((c, what))
        }) {
            self.errors.spanned(
                name,
                format!(
                    "`{text}` is a reserved name: it names the {what} of `{c}` in generated code"
                ),
            );
        } else if self.names.insert(text.clone(), binding).is_some() {
            self.errors
                .spanned(name, format!("`{text}` is declared twice"));
        }
    }

    /// Lowers a vector of `n` entries (missing ones are zero).
    pub fn vector(&mut self, list: &crate::parse::List<Expr>, what: &str, n: usize) -> Vec<Id> {
        check::length(self.errors, list.span, what, list.items.len(), n);
        let mut v: Vec<Id> = list.items.iter().map(|e| self.lower(e)).collect();
        v.resize(n, self.graph.int(0));
        v
    }

    /// Lowers one expression; on error records it and returns `0`.
    pub fn lower(&mut self, e: &Expr) -> Id {
        self.try_lower(e).unwrap_or_else(|err| {
            self.errors.push(err);
            self.graph.int(0)
        })
    }

    /// Lowers one expression; a constant that is not finite in `f64`
    /// (`1e309`, `1e308 * 1e308`, `exp(1000)`) is an error here, where it
    /// can be pointed at, rather than a non-finite literal in the output.
    fn try_lower(&mut self, e: &Expr) -> syn::Result<Id> {
        let id = self.try_lower_node(e)?;
        match self.graph.as_num(id) {
            Some(n) if !n.to_f64().is_finite() => Err(syn::Error::new_spanned(
                e,
                format!("this constant is not finite in f64 ({})", n.to_f64()),
            )),
            _ => Ok(id),
        }
    }

    fn try_lower_node(&mut self, e: &Expr) -> syn::Result<Id> {
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
                    BinOp::BitXor(_) => return power_hint(b),
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
            Expr::Field(field) => self.point_component(field),
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
            Expr::Assign(a) => err(
                &a.eq_token,
                "`=` assigns: did you mean `==`? (a constraint is written `lhs == rhs`)",
            ),
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
        if let Some(&(_, value)) = CONSTANTS.iter().find(|(c, _)| name == c) {
            return Ok(self.graph.num(Num::Float(value)));
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

    /// `dt(e)`: the total time derivative `Σ ∂e/∂qᵢ q̇ᵢ + ∂e/∂t` of an
    /// expression without velocities (with them, it would need `q̈`).
    fn total_derivative(&mut self, args: &[&Expr], call: &Expr) -> syn::Result<Id> {
        let [arg] = args else {
            return Err(syn::Error::new_spanned(call, "`dt` takes one expression"));
        };
        let e = self.try_lower(arg)?;
        let of_definition = single_ident(arg)
            .filter(|name| {
                matches!(
                    self.names.get(&name.to_string()),
                    Some(Binding::Definition(_))
                )
            })
            .map(|name| format!("dt({name})"));
        if self.graph.mentions(e, |s| matches!(s, Sym::Vel(_))) {
            return Err(syn::Error::new_spanned(
                arg,
                "`dt` of an expression with velocities would need accelerations: \
                 write positions (and `t`) inside `dt(..)`",
            ));
        }
        let (_, rest) = Differentiator::new().time_derivative(self.graph, e, self.n);
        if let Some(name) = of_definition {
            self.name_node(name, rest);
        }
        Ok(rest)
    }

    /// Records `name` for `id` in the derivation's text, unless `id` is a
    /// single variable or number (naming `z` `h` everywhere would obscure
    /// it) or already has a name.
    pub fn name_node(&mut self, name: String, id: Id) {
        // A variable, a number or a function of one (`sin(th)`) reads
        // better as itself.
        let simple = |g: &Graph, id: Id| {
            matches!(
                g.node(id),
                crate::expr::Node::Sym(_) | crate::expr::Node::Num(_)
            )
        };
        let leaf = simple(self.graph, id)
            || matches!(self.graph.node(id), crate::expr::Node::Func(_, args)
                if args.as_slice().iter().all(|&a| simple(self.graph, a)));
        if !leaf && self.named.iter().all(|(_, other)| *other != id) {
            self.named.push((name, id));
        }
    }

    fn apply(&mut self, name: &Ident, args: &[&Expr], call: &Expr) -> syn::Result<Id> {
        let text = name.to_string();
        if text == "dt" {
            return self.total_derivative(args, call);
        }
        let func = Func::from_name(&text);
        let algebraic = ALGEBRAIC.iter().find(|f| f.name == text);
        let arity = match (func, algebraic) {
            (Some(f), _) => f.arity(),
            (None, Some(f)) => f.arity,
            (None, None) => {
                return Err(syn::Error::new_spanned(
                    name,
                    format!(
                        "unknown function `{text}`; expected `dot` or one of {}",
                        function_names().join(", ")
                    ),
                ))
            }
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
                // Generated code calls `powi(k: i32)`.
                Some(k) if i32::try_from(k).is_err() => Err(syn::Error::new_spanned(
                    args[1],
                    format!(
                        "`powi` exponent {k} is out of range (at most {} in magnitude)",
                        i32::MAX
                    ),
                )),
                Some(k) => Ok(self.graph.pown(base, Num::int(k))),
                None => Err(syn::Error::new_spanned(
                    args[1],
                    "`powi` takes an integer exponent; use `powf` for others",
                )),
            };
        }
        let lowered: Vec<Id> = args.iter().map(|a| self.lower(a)).collect();
        let g = &mut self.graph;
        Ok(match (func, algebraic) {
            (Some(f), _) => match Args::from_slice(&lowered) {
                Some(args) => g.apply(f, args),
                None => g.int(0), // arity checked above
            },
            (None, Some(f)) => (f.lower)(g, &lowered),
            (None, None) => g.int(0), // an unknown name returned above
        })
    }
}

fn single_ident(e: &Expr) -> Option<&Ident> {
    match e {
        Expr::Path(p) if p.qself.is_none() => p.path.get_ident(),
        _ => None,
    }
}

/// `x^2`: in Rust `^` is the bitwise xor (and binds more loosely than `*`,
/// so `m * x^2` is `(m * x) ^ 2`), not a power. The error spans `^` and
/// the exponent, and names the method to use instead.
fn power_hint(b: &syn::ExprBinary) -> syn::Result<Id> {
    let exponent = match &*b.right {
        Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(k),
            ..
        }) => Some(k.base10_digits().to_string()),
        _ => None,
    };
    let message = match exponent {
        Some(k) => format!("`^` is not a power in Rust: use `.powi({k})`, as in `x.powi({k})`"),
        None => "`^` is not a power in Rust: use `.powi(n)` for an integer exponent, \
                 `.powf(y)` otherwise"
            .to_string(),
    };
    let op = &b.op;
    let right = &b.right;
    Err(syn::Error::new_spanned(quote::quote!(#op #right), message))
}
