//! The code generator behind `constrained_system!`.
//!
//! [`expand`] is the whole macro as a function from tokens to tokens, so that
//! tests, snapshots and benchmarks run it directly; the proc-macro crate
//! `constrained-macros` only converts token types and calls it.
//!
//! Stages, each a pure function of the previous one's output:
//! 1. [`parse`]: tokens → DSL syntax (`SystemInput`), after
//!    `parse::nesting` has bounded how deeply the tokens nest;
//! 2. [`model`]: names resolved, expressions lowered into the DAG of
//!    [`expr`], every rule checked, errors reported together;
//! 3. [`equations`]: constraints differentiated ([`expr::diff`]) into
//!    `A q̈ = b`, Gauss's principle set up ([`equations::mass_inverse`]),
//!    the derivatives behind the Jacobian of `q̈` taken
//!    (`equations::tangent`), and the Gibbs–Appell partition found at
//!    consistent states ([`equations::partition`]);
//! 4. [`emit`]: straight-line Rust with shared subexpressions
//!    (`expr::cse`) and the derivation text ([`emit::derivation`],
//!    `expr::print`).
//!
//! Below the stages: [`expr`] (the expression DAG, its exact rationals, its
//! operator table and its passes, Lagrange's equations among them),
//! [`numeric`] (dense linear algebra, sparsity patterns, the pseudo-random
//! points), `names`. [`tools`]
//! serves tests and benchmarks.

pub(crate) mod bodies;
pub mod emit;
pub mod equations;
pub mod expr;
pub mod model;
pub(crate) mod names;
pub mod numeric;
pub mod parse;
pub mod tools;

use proc_macro2::TokenStream;

/// What an expansion generates beyond the equations of motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// `acceleration_jacobian`, `linearize`, `linearize_reduced` and the
    /// `Tangent` impl they rest on: the exact derivatives of `q̈`, most of
    /// the expansion of a large model (three quarters of the Panda's
    /// lines). The `jacobians` feature of `constrained`, on by default.
    pub jacobians: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options { jacobians: true }
    }
}

/// Expands one `constrained_system! { ... }` invocation body.
pub fn expand(input: TokenStream) -> syn::Result<TokenStream> {
    expand_with(input, Options::default())
}

/// [`expand`] with [`Options`].
pub fn expand_with(input: TokenStream, options: Options) -> syn::Result<TokenStream> {
    let equations = analyse_with(input, options)?;
    overflow_free(&equations)?;
    Ok(emit::system(&equations))
}

/// A constant of the derivation that overflows `f64` (`x·1e155` in a
/// constraint makes `A M⁻¹ Aᵀ` hold `1e310`) would compute `∞` at run time
/// too and silently drop the constraint: a compile error instead. So is a
/// constant that is finite as written but not where generated code
/// evaluates it (`E.powi(710)`, `exp(1000)`, `ln(0)`; `expr::finite`): spanned
/// on the constraint or the mass matrix it occurs in, where it does.
fn overflow_free(eq: &equations::Equations) -> syn::Result<()> {
    let sys = &eq.system;
    let overflow = sys
        .graph
        .constants()
        .map(expr::num::Num::to_f64)
        .find(|v| !v.is_finite());
    if let Some(value) = overflow {
        return Err(syn::Error::new(
            sys.name.span(),
            format!(
                "deriving the equations produced a constant that overflows f64 ({value}); \
                 rescale the constraints or the units so that their coefficients and products stay below ~1e154"
            ),
        ));
    }
    let scale = match &eq.mass_inverse {
        equations::mass_inverse::MassInverse::Symbolic(d) => {
            d.scale.iter().map(|s| s.to_f64()).find(|v| !v.is_finite())
        }
        _ => None,
    };
    if let Some(value) = scale {
        return Err(syn::Error::new(
            sys.name.span(),
            format!("deriving the equations produced a row scale that overflows f64 ({value})"),
        ));
    }
    let found = expr::finite::non_finite(&sys.graph);
    if found.is_empty() {
        return Ok(());
    }
    Err(non_finite_error(sys, &found))
}

/// The error for the constants of `sys` that are not finite where generated
/// code evaluates them (`found`, in arena order, not empty): spanned on
/// the first constraint, else the mass matrix, that holds one, and on the
/// system's name where no input does.
fn non_finite_error(sys: &model::System, found: &[expr::finite::NonFinite]) -> syn::Error {
    let names = |v: &[syn::Ident]| v.iter().map(ToString::to_string).collect::<Vec<_>>();
    let (coordinates, parameters) = (names(&sys.coordinates), names(&sys.parameters));
    let printer = expr::print::Printer::new(
        &sys.graph,
        &coordinates,
        &parameters,
        expr::print::Style::Unicode,
    );
    let message = |bad: expr::finite::NonFinite| {
        let what = if bad.value.is_nan() {
            "is not a number (NaN)"
        } else {
            "overflows f64"
        };
        format!(
            "a constant in `{}` {what} where the generated code evaluates it \
             ({}); rescale the model's constants or units so that every constant, and every \
             power and product of them, stays within f64",
            printer.print(bad.node),
            bad.value
        )
    };
    let mut flagged = vec![false; sys.graph.len()];
    for bad in found {
        flagged[bad.node.index()] = true;
    }
    let within = |root: expr::Id| {
        sys.graph
            .reachable(&[root])
            .into_iter()
            .find(|id| flagged[id.index()])
            .and_then(|id| found.iter().copied().find(|bad| bad.node == id))
    };
    for c in &sys.constraints {
        if let Some(bad) = within(c.phi) {
            return syn::Error::new_spanned(&c.tokens, message(bad));
        }
    }
    if let Some(bad) = sys.mass.iter().flatten().find_map(|&m| within(m)) {
        return syn::Error::new(sys.mass_span, message(bad));
    }
    syn::Error::new(sys.name.span(), message(found[0]))
}

/// Stages 1–3: the checked system and its derived equations, the
/// Gibbs–Appell partition among them, before emission.
pub fn analyse(input: TokenStream) -> syn::Result<equations::Equations> {
    analyse_with(input, Options::default())
}

/// [`analyse`] with [`Options`].
pub fn analyse_with(input: TokenStream, options: Options) -> syn::Result<equations::Equations> {
    parse::nesting::check(&input)?;
    let input: parse::SystemInput = syn::parse2(input)?;
    let system = model::check(&input)?;
    equations::derive(system, options.jacobians)
}
