//! The methods that evaluate the model rather than solve it: inverse
//! dynamics and the generalized gravity of a system with bodies, and the
//! energies of a system given by energies or bodies. Each is plain, or a
//! `Result` that is `Err(NonFinite)` where a value overflows, by the same
//! rule as `acceleration` (`MassInverse::fallible`). Every one is a row of
//! [`EVALUATIONS`].

use super::body::Body;
use super::context::Context;
use crate::equations::Equations;
use crate::expr::Id;
use proc_macro2::TokenStream;
use quote::quote;

/// The arguments a method takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Args {
    /// `(q, t)`.
    Positions,
    /// `(q, qd, t)`.
    States,
    /// `(q, qd, qdd, t)`.
    Accelerations,
}

fn params(ctx: &Context, args: Args) -> TokenStream {
    let v = ctx.vector(ctx.n);
    match args {
        Args::Positions => quote! { q: &#v, t: T },
        Args::States => quote! { q: &#v, qd: &#v, t: T },
        Args::Accelerations => quote! { q: &#v, qd: &#v, qdd: &#v, t: T },
    }
}

/// The names of the arguments a method takes, as they are passed on.
fn args(args: Args) -> TokenStream {
    match args {
        Args::Positions => quote! { q, t },
        Args::States => quote! { q, qd, t },
        Args::Accelerations => quote! { q, qd, qdd, t },
    }
}

/// The method of the row `e`, returning `value`: a vector, a scalar, or a
/// pair of n × n matrices.
fn method(ctx: &Context, e: &Evaluation, value: &Value) -> TokenStream {
    let flat = match value {
        Value::Vector(entries) => Flat::Vector(entries),
        Value::Scalar(e) => Flat::Scalar(*e),
        Value::Matrices(pair) => return matrices_method(ctx, e, pair),
    };
    let name = syn::Ident::new(e.name, proc_macro2::Span::call_site());
    let doc = e.doc;
    let entries: Vec<Id> = match flat {
        Flat::Vector(entries) => entries.to_vec(),
        Flat::Scalar(e) => vec![e],
    };
    let body = Body::new(ctx.eq, &entries);
    let preamble = body.preamble();
    let apart = e.strided && super::detached::large(ctx, &entries);
    let (value, ok) = tokens(ctx, &body, flat, apart);
    let params = params(ctx, e.args);
    if ctx.eq.mass_inverse.fallible() {
        let ret = ctx.result(ok, quote!(DynamicsError));
        let non_finite = ctx.path(quote!(DynamicsError::NonFinite));
        let all = ctx.private(quote!(all_finite));
        let finite = match flat {
            Flat::Scalar(_) => quote!(__value.is_finite()),
            Flat::Vector(_) => quote!(#all(__value.as_slice())),
        };
        let doc = format!("{doc}\n\n`Err(NonFinite)` where a value is not finite (as `acceleration`, this system's methods return `Result`).");
        quote! {
            #[doc = #doc]
            #[inline]
            pub fn #name(&self, #params) -> #ret {
                #preamble
                let __value = #value;
                if #finite {
                    ::core::result::Result::Ok(__value)
                } else {
                    ::core::result::Result::Err(#non_finite)
                }
            }
        }
    } else {
        quote! {
            #[doc = #doc]
            #[inline]
            pub fn #name(&self, #params) -> #ok {
                #preamble
                #value
            }
        }
    }
}

/// From this many coordinates a pair of n × n matrices is written in
/// place ([`matrices_method`]); below, it is one literal. Measured on the
/// benchmarks' robots: in place, the G1's (29) `∂τ` and the fixed-trunk
/// Go1's (12) run faster, the Panda's (7) slower in both orders of the
/// stores tried. Why is not established; a candidate is the finiteness
/// check's vector loads right behind the scalar stores of a short body,
/// which the stores cannot serve.
const IN_PLACE_FROM: usize = 12;

/// The method of a pair of n × n matrices (`inverse_dynamics_jacobian`)
/// and its `_to` form, which writes the pair into the caller's `out`.
///
/// A `Result` built from a local is a copy of it (rustc places a returned
/// local in the caller's slot only when it is the whole value), and the
/// pair is 2n² entries, most of them structural zeros. From
/// [`IN_PLACE_FROM`] coordinates the body is a method of its own,
/// `__{name}_into`, that writes the structural nonzeros into a pair that
/// holds zeros and says whether every entry is finite: the `_to` form
/// zeroes `out` (a `memset` a matrix) and passes it, so that nothing is
/// copied; the method passes a local, returned as its value. The body is
/// also the function the dispatch copies (`super::dispatch`), so that its
/// copy writes where the caller reads. Below, the body is the method's, its
/// value one literal, and the `_to` form stores that value.
fn matrices_method(ctx: &Context, e: &Evaluation, pair: &[Vec<Vec<Id>>; 2]) -> TokenStream {
    let name = syn::Ident::new(e.name, proc_macro2::Span::call_site());
    let to = quote::format_ident!("{}_to", e.name);
    let matrix = ctx.matrix(pair[0].len(), pair[0].len());
    let pair_type = quote!((#matrix, #matrix));
    let params = params(ctx, e.args);
    let fallible = ctx.eq.mass_inverse.fallible();
    let (ret, to_ret, doc) = if fallible {
        (
            ctx.result(pair_type.clone(), quote!(DynamicsError)),
            ctx.result(quote!(()), quote!(DynamicsError)),
            format!("{}\n\n`Err(NonFinite)` where a value is not finite (as `acceleration`, this system's methods return `Result`).", e.doc),
        )
    } else {
        (pair_type.clone(), quote!(()), e.doc.to_string())
    };
    let to_doc = format!(
        " [`{0}`](Self::{0}) written into `out`, every entry, for a caller \
         that keeps the pair from call to call (as Pinocchio keeps its \
         `Data`): nothing is returned by value, so nothing is copied.{1}",
        e.name,
        if fallible {
            " `Err` as the method; `out` then holds what was computed."
        } else {
            ""
        }
    );
    let Bodies {
        method,
        to: to_body,
        into,
    } = if pair[0].len() < IN_PLACE_FROM {
        literal(ctx, pair, fallible)
    } else {
        in_place(ctx, e, pair, &pair_type, fallible)
    };
    quote! {
        #[doc = #doc]
        #[inline]
        pub fn #name(&self, #params) -> #ret {
            #method
        }
        #[doc = #to_doc]
        #[inline]
        pub fn #to(&self, #params, out: &mut #pair_type) -> #to_ret {
            #to_body
        }
        #into
    }
}

/// The bodies of a pair's method and of its `_to` form, and the method
/// they share, if any.
struct Bodies {
    method: TokenStream,
    to: TokenStream,
    into: TokenStream,
}

/// The pair as one literal (below [`IN_PLACE_FROM`] coordinates), in the
/// method and again in `_to`, which stores it into `out`: a call of the
/// method would copy its `Result`'s pair into `out` (`memcpy`), whose
/// speed depends on where the two fall in their pages.
fn literal(ctx: &Context, pair: &[Vec<Vec<Id>>; 2], fallible: bool) -> Bodies {
    let n = pair[0].len();
    let entries: Vec<Id> = pair.iter().flatten().flatten().copied().collect();
    let body = Body::new(ctx.eq, &entries);
    let preamble = body.preamble();
    let [a, b] = pair.each_ref().map(|rows| {
        let columns = (0..n)
            .map(|c| rows.iter().map(|row| body.expr(row[c])).collect())
            .collect();
        ctx.matrix_value(n, columns)
    });
    if !fallible {
        return Bodies {
            method: quote! { #preamble (#a, #b) },
            to: quote! { #preamble *out = (#a, #b); },
            into: TokenStream::new(),
        };
    }
    let all = ctx.private(quote!(all_finite));
    let non_finite = ctx.path(quote!(DynamicsError::NonFinite));
    // Over the structural nonzeros only: a literal zero is known finite,
    // and each entry checked costs a subtraction and an addition.
    let nonzeros = places(ctx, pair).into_iter().map(|(place, _)| place);
    let finite = quote!(#all(&[#(#nonzeros),*]));
    Bodies {
        method: quote! {
            #preamble
            let __value = (#a, #b);
            if #finite {
                ::core::result::Result::Ok(__value)
            } else {
                ::core::result::Result::Err(#non_finite)
            }
        },
        to: quote! {
            #preamble
            let __value = (#a, #b);
            let __finite = #finite;
            *out = __value;
            if __finite {
                ::core::result::Result::Ok(())
            } else {
                ::core::result::Result::Err(#non_finite)
            }
        },
        into: TokenStream::new(),
    }
}

/// The pair written in place (from [`IN_PLACE_FROM`] coordinates): the
/// body is `__{name}_into`, which both forms call, `_to` with `out`
/// zeroed, the method with a local of zeros.
fn in_place(
    ctx: &Context,
    e: &Evaluation,
    pair: &[Vec<Vec<Id>>; 2],
    pair_type: &TokenStream,
    fallible: bool,
) -> Bodies {
    let (params, args) = (params(ctx, e.args), args(e.args));
    let into = quote::format_ident!("__{}_into", e.name);
    let zeros = ctx.matrix_zeros(pair[0].len(), pair[0].len());
    let stores = stores(ctx, pair);
    let all = ctx.private(quote!(all_finite));
    let non_finite = ctx.path(quote!(DynamicsError::NonFinite));
    let (check, returns) = if fallible {
        (
            quote!(#all(__value.0.as_slice()) & #all(__value.1.as_slice())),
            quote!(-> bool),
        )
    } else {
        (TokenStream::new(), TokenStream::new())
    };
    let call = |target: TokenStream, value: TokenStream| {
        if fallible {
            quote! {
                if self.#into(#args, #target) {
                    ::core::result::Result::Ok(#value)
                } else {
                    ::core::result::Result::Err(#non_finite)
                }
            }
        } else {
            quote! {
                self.#into(#args, #target);
                #value
            }
        }
    };
    let (method_call, to_call) = (
        call(quote!(&mut __value), quote!(__value)),
        call(quote!(out), quote!(())),
    );
    Bodies {
        method: quote! {
            let mut __value = (#zeros, #zeros);
            #method_call
        },
        // Entry by entry over each storage, which compiles to a `memset`
        // each (nalgebra's `fill`, or one loop over both chained, to a
        // loop of scalar stores).
        to: quote! {
            for __x in out.0.as_mut_slice() {
                *__x = T::zero();
            }
            for __x in out.1.as_mut_slice() {
                *__x = T::zero();
            }
            #to_call
        },
        into: quote! {
            /// The body of the method without `_into`: the structural
            /// nonzeros written into `__value`, which holds zeros.
            #[doc(hidden)]
            #[inline]
            fn #into(&self, #params, __value: &mut #pair_type) #returns {
                #stores
                #check
            }
        },
    }
}

/// The structural nonzeros of `pair` stored into `__value` after the
/// body that computes them: the values held until the end, as a literal
/// holds them (stored as soon as each is known instead, the G1's `∂τ`
/// ran slower). Each term keeps its own magnitude
/// ([`Body::magnitudes_apart`]): the entries are sums of products
/// `c·a·b − c·d·e` that LLVM's SLP vectorizer multiplies by `c` as one
/// packed pair: written `c·(a·b − d·e)`, the G1's `∂τ` ran slower with
/// fewer operations.
fn stores(ctx: &Context, pair: &[Vec<Vec<Id>>; 2]) -> TokenStream {
    let places = places(ctx, pair);
    let roots: Vec<Id> = places.iter().map(|&(_, id)| id).collect();
    let body = Body::new(ctx.eq, &roots).magnitudes_apart();
    let preamble = body.preamble();
    let stores = places.iter().map(|(place, id)| {
        let value = body.expr(*id);
        quote!(#place = #value;)
    });
    quote! { #preamble #(#stores)* }
}

/// The structural nonzeros of `pair`, each with its place in `__value`.
fn places(ctx: &Context, pair: &[Vec<Vec<Id>>; 2]) -> Vec<(TokenStream, Id)> {
    let g = &ctx.eq.system.graph;
    let mut places = Vec::new();
    for (m, rows) in pair.iter().enumerate() {
        let m = syn::Index::from(m);
        for c in 0..rows.len() {
            for (r, row) in rows.iter().enumerate() {
                if !g.is_zero(row[c]) {
                    let (rl, cl) = (Context::dim(r), Context::dim(c));
                    places.push((quote!(__value.#m.data.0[#cl][#rl]), row[c]));
                }
            }
        }
    }
    places
}

/// A large vector's value, its entries written two slots apart and read
/// back by the runtime's `unstride`, so that LLVM's SLP vectorizer does
/// not pair the expressions of adjacent entries: in recursive
/// Newton–Euler those are different bodies' forces, alike in shape only,
/// and the pairing cost shuffles at their leaves (1,464 of them in the
/// G1's `inverse_dynamics`, built for plain x86-64; `unstride` says why).
pub(super) fn strided(ctx: &Context, body: &Body, entries: &[Id]) -> TokenStream {
    let values = entries.iter().map(|&e| body.expr(e));
    let unstride = ctx.private(quote!(unstride));
    quote!(#unstride([#([#values, T::zero()]),*]))
}

/// A value of one vector or one scalar: what [`tokens`] writes.
#[derive(Clone, Copy)]
enum Flat<'v> {
    /// `SVector<T, len>`.
    Vector(&'v [Id]),
    /// `T`.
    Scalar(Id),
}

/// The value's expression and its type; a vector's entries returned
/// `apart` ([`strided`]) or as one literal.
fn tokens(ctx: &Context, body: &Body, value: Flat, apart: bool) -> (TokenStream, TokenStream) {
    match value {
        Flat::Scalar(e) => (body.expr(e), quote!(T)),
        Flat::Vector(entries) if apart => (strided(ctx, body, entries), ctx.vector(entries.len())),
        Flat::Vector(entries) => (
            ctx.vector_value(entries.iter().map(|&e| body.expr(e))),
            ctx.vector(entries.len()),
        ),
    }
}

/// One generated method that evaluates the model: a row of
/// [`EVALUATIONS`].
pub struct Evaluation {
    /// The method's name.
    pub name: &'static str,
    /// Its arguments after `&self`.
    pub args: Args,
    /// Whether `ConstrainedSystem` has it too (taking a `State`; its row
    /// of `forwarded_methods!` in `runtime/src/methods.rs`), as
    /// `Option<Result<..>>`: the generated impl forwards it
    /// (`emit/forwards.rs`).
    pub forwarded: bool,
    /// Its documentation (the inherent method's; `docs/generated.md` has a
    /// row for it, checked by a test).
    doc: &'static str,
    /// Its value, where the system has the method: the entries of a
    /// vector, or the one entry of a scalar.
    value: fn(&Equations) -> Option<Value>,
    /// Whether a large vector value is returned through `unstride`
    /// ([`strided`]): recursive Newton–Euler's joint forces, whose
    /// adjacent entries are unrelated bodies' (measured; the others'
    /// adjacent entries may be alike, as `M q̇`'s rows).
    strided: bool,
}

/// What an [`Evaluation`] returns.
enum Value {
    /// `SVector<T, len>`.
    Vector(Vec<Id>),
    /// `T`.
    Scalar(Id),
    /// `(SMatrix<T, n, n>, SMatrix<T, n, n>)`, each row by row.
    Matrices([Vec<Vec<Id>>; 2]),
}

/// The generated methods that evaluate the model rather than solve it,
/// in the order they are emitted: a new one is a row here (and a row of
/// the table in `docs/generated.md`; with `forwarded`, a row of the
/// runtime's `forwarded_methods!`).
pub const EVALUATIONS: &[Evaluation] = &[
    Evaluation {
        name: "inverse_dynamics",
        args: Args::Accelerations,
        forwarded: false,
        doc: " Inverse dynamics by recursive Newton–Euler: the joint forces \
              `τ = M(q) q̈ + c(q, q̇)` that give the bodies the accelerations \
              `qdd`, `c` holding the Coriolis, centrifugal and gravity forces \
              (Pinocchio's `rnea`). The `forces` section is not included: with \
              `forces: [u1, ..]` as the joints' torques, `u = τ` gives `q̈ = qdd` \
              where no constraint acts.",
        value: |eq| Some(Value::Vector(eq.system.bodies.as_ref()?.inverse.clone())),
        strided: true,
    },
    Evaluation {
        name: "inverse_dynamics_jacobian",
        args: Args::Accelerations,
        forwarded: false,
        doc: " The derivatives of inverse dynamics, `(∂τ/∂q, ∂τ/∂q̇)`, n × n each, \
              exact (built at compile time by the recursions of Pinocchio's \
              `computeRNEADerivatives`; `∂τ/∂q̈` is `mass_matrix`). Columns of a quaternion joint are by \
              its four coordinates and their rates, the rotation being \
              `R(q/|q|)`. Generated where `derivatives: [inverse_dynamics]` \
              asks for it.",
        value: |eq| Some(Value::Matrices(eq.inverse_jacobian.clone()?)),
        strided: false,
    },
    Evaluation {
        name: "gravity_forces",
        args: Args::Positions,
        forwarded: true,
        doc: " The generalized gravity `g(q)`: the joint forces that hold the \
              bodies still against gravity (Pinocchio's \
              `computeGeneralizedGravity`; `inverse_dynamics` at `q̇ = q̈ = 0`).",
        value: |eq| Some(Value::Vector(eq.system.bodies.as_ref()?.gravity.clone())),
        strided: true,
    },
    Evaluation {
        name: "kinetic_energy",
        args: Args::States,
        forwarded: true,
        doc: " The kinetic energy `T(q, q̇, t)`.",
        value: |eq| Some(Value::Scalar(eq.system.energy?.kinetic)),
        strided: false,
    },
    Evaluation {
        name: "potential_energy",
        args: Args::Positions,
        forwarded: true,
        doc: " The potential energy `V(q, t)` (gravity's for bodies, and `potential_energy` as written; 0 where neither is given).",
        value: |eq| Some(Value::Scalar(eq.system.energy?.potential)),
        strided: false,
    },
    Evaluation {
        name: "energy",
        args: Args::States,
        forwarded: true,
        doc: " The total energy `T + V`, conserved where no other force acts.",
        value: |eq| Some(Value::Scalar(eq.system.energy?.total)),
        strided: false,
    },
    Evaluation {
        name: "generalized_momentum",
        args: Args::States,
        forwarded: false,
        doc: " The generalized momentum `p = M(q, t) q̇` (`∂T/∂q̇` for a \
              kinetic energy quadratic in `q̇`), without forming `M`.",
        value: |eq| Some(Value::Vector(eq.momentum.clone())),
        strided: false,
    },
];

/// The type the method of [`EVALUATIONS`] named `name` returns (its
/// `Ok` type where it returns a `Result`), where the system has it.
pub(super) fn value_type(ctx: &Context, name: &str) -> Option<TokenStream> {
    let row = EVALUATIONS.iter().find(|e| e.name == name)?;
    match (row.value)(ctx.eq)? {
        Value::Vector(entries) => Some(ctx.vector(entries.len())),
        Value::Scalar(_) => Some(quote!(T)),
        Value::Matrices(pair) => {
            let [a, b] = pair.each_ref().map(|m| ctx.matrix(m.len(), m.len()));
            Some(quote!((#a, #b)))
        }
    }
}

/// The methods of [`EVALUATIONS`] that the system has.
pub(super) fn methods(ctx: &Context) -> TokenStream {
    let mut out = TokenStream::new();
    for e in EVALUATIONS {
        if let Some(value) = (e.value)(ctx.eq) {
            out.extend(method(ctx, e, &value));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{Args, EVALUATIONS};
    use crate::tools::fixtures::{joint_angle_pendulum, panda, two_arms};
    use crate::{expand_with, Options};

    /// The text of the generated method `name` (up to the next method),
    /// in an expansion written without spaces; `name<T` for the detached
    /// function in the system's module.
    fn method_text<'a>(expansion: &'a str, name: &str) -> &'a str {
        let open = if name.ends_with("<T") { "" } else { "(" };
        let start = expansion
            .find(&format!("pubfn{name}{open}"))
            .unwrap_or_else(|| panic!("no method {name}"));
        let rest = &expansion[start + 1..];
        &rest[..rest.find("pubfn").unwrap_or(rest.len())]
    }

    /// Recursive Newton–Euler's joint forces of a large model leave
    /// through `unstride` (`τ`, `g(q)`, and bodies' `F`, detached into the
    /// system's module), and nothing else does: not the momentum `M q̇`
    /// (whose adjacent rows are alike, so that pairing them pays), not the
    /// `F` of a model without bodies, and not a small model's forces,
    /// which its registers hold anyway.
    #[test]
    fn newton_eulers_forces_alone_are_returned_apart() {
        let expand = |source: String| {
            let tokens = source.parse().expect("the fixture is tokens");
            let expanded = expand_with(tokens, Options { jacobians: false }).expect("it expands");
            expanded.to_string().replace(' ', "")
        };
        let large = expand(two_arms("Arms", 7));
        for name in ["inverse_dynamics", "gravity_forces"] {
            assert!(method_text(&large, name).contains("unstride(["), "{name}");
        }
        assert!(method_text(&large, "forces<T").contains("unstride(["));
        assert!(!method_text(&large, "generalized_momentum").contains("unstride"));
        let energies = expand(joint_angle_pendulum("Pendulum", 8));
        assert!(method_text(&energies, "forces<T").contains("from_array_storage"));
        assert!(
            !energies.contains("unstride"),
            "no bodies: F is one literal"
        );
        let small = expand(panda("Shoulder", 2));
        assert!(
            !small.contains("unstride"),
            "a two-joint arm's are one literal"
        );
    }

    /// Every evaluation method has a row of the table of generated items
    /// in `docs/generated.md`, with its arguments as generated.
    #[test]
    fn docs_table_lists_every_evaluation() {
        let docs = include_str!("../../../docs/generated.md");
        let rows: Vec<&str> = docs.lines().filter(|l| l.starts_with("| `")).collect();
        assert!(rows.len() > 20, "table not found");
        for e in EVALUATIONS {
            let args = match e.args {
                Args::Positions => "q, t",
                Args::States => "q, qd, t",
                Args::Accelerations => "q, qd, qdd, t",
            };
            let item = format!("`{}({args})`", e.name);
            assert!(
                rows.iter().any(|r| r.contains(&item)),
                "docs/generated.md has no row for {item}"
            );
        }
    }
}
