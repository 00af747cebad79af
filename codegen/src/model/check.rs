//! Every rule of the input that needs the lowered expressions, one named
//! function each, and the one [`check`] that applies them all to the
//! lowered [`System`] (serde_derive's `check.rs`). Lowering records in
//! [`Written`] what the rules read beside the system: where each part was
//! written, and the [`Slot`] its errors go in.

use super::ctxt::{Errors, Slot};
use super::{Level, System};
use crate::expr::num::Num;
use crate::expr::{Graph, Id, Sym};
use crate::numeric::rng::sample_points;
use proc_macro2::TokenStream;
use quote::ToTokens;
use syn::Ident;

/// Applies every rule to the lowered system, each reporting at the slot of
/// the part it checks (so that errors come in the order of the input):
///
/// - the struct: [`struct_name`], [`forwarded_attributes`];
/// - `M`: [`mass_without_velocities`], [`mass_symmetric`],
///   [`constant_mass_positive_semidefinite`] ([`mass_rules`]);
/// - each constraint written: [`constraint_involves_state`],
///   [`constraint_differentiable`] ([`constraint_rules`]);
/// - the control inputs: [`inputs_in_forces_only`].
///
/// [`length`] is the one rule applied while lowering, as each list is
/// read: lowering reads only the first `n` entries of a list.
pub fn check(errors: &mut Errors, system: &System, written: &Written) {
    errors.fill(written.header, |e| {
        struct_name(e, &system.name);
        forwarded_attributes(e, &system.attrs);
    });
    let g = &system.graph;
    if let Some(mass) = &written.mass {
        errors.fill(mass.slot, |e| mass_rules(e, g, &system.mass, mass));
    }
    for c in &written.constraints {
        errors.fill(c.slot, |e| constraint_rules(e, g, c));
    }
    if let Some(inputs) = &written.inputs {
        errors.fill(inputs.slot, |e| inputs_in_forces_only(e, system, inputs));
    }
}

/// What the rules read beside the lowered [`System`], recorded while it is
/// lowered. A part that lowered with an error holds a placeholder and is
/// not checked further, so that one mistake gives one error.
#[derive(Default)]
pub struct Written {
    /// Where the rules of the struct's name and attributes report: before
    /// anything is lowered.
    pub header: Slot,
    /// `M`, written or derived from `T` (without error).
    pub mass: Option<WrittenMass>,
    /// The constraints written (each row of one) that lowered without
    /// error, in order.
    pub constraints: Vec<WrittenConstraint>,
    /// Where the control inputs may not appear, when there are inputs.
    pub inputs: Option<WrittenInputs>,
}

/// `M` as the rules of [`mass_rules`] read it.
pub struct WrittenMass {
    /// Where to point at `M` as a whole (`mass` or `kinetic_energy`).
    pub keyword: Ident,
    /// For a written `M`, its entries as lowered (before the upper
    /// triangle serves both halves) and as written. A derived `M` needs no
    /// such check: Lagrange's equations make it symmetric and free of
    /// velocities.
    pub entries: Option<(Vec<Vec<Id>>, MassSource)>,
    /// Whether it lowered without error (missing or unreadable entries are
    /// zeros).
    pub clean: bool,
    /// Where its errors go.
    pub slot: Slot,
}

/// One constraint's `φ` as the rules of [`constraint_rules`] read it.
pub struct WrittenConstraint {
    /// `φ`.
    pub phi: Id,
    /// Its level, which says how often it is differentiated.
    pub level: Level,
    /// The constraint's tokens, to point at.
    pub tokens: TokenStream,
    /// Where its errors go.
    pub slot: Slot,
}

/// What [`inputs_in_forces_only`] reads beside the system.
pub struct WrittenInputs {
    /// The index of the first input among the parameters (`Sym::Param`).
    pub first: usize,
    /// The keyword of `M`'s source and the source's name for messages.
    pub source: Option<(Ident, &'static str)>,
    /// `T` as written.
    pub kinetic: Option<Id>,
    /// `V` as written, with its keyword.
    pub potential: Option<(Id, Ident)>,
    /// Where its errors go: after everything else.
    pub slot: Slot,
}

/// The entries of a mass matrix as written in `mass:` (`None` where an
/// entry is missing), to point errors at.
pub struct MassSource(pub Vec<Vec<Option<TokenStream>>>);

impl MassSource {
    fn at(&self, i: usize, j: usize) -> Option<TokenStream> {
        self.0.get(i)?.get(j)?.clone()
    }
}

/// The rules of `M`: a written one's entries free of velocities and
/// symmetric; a constant one positive semi-definite, where it lowered
/// without error and the rules before found none.
pub fn mass_rules(errors: &mut Errors, g: &Graph, m: &[Vec<Id>], written: &WrittenMass) {
    if let Some((entries, source)) = &written.entries {
        mass_without_velocities(errors, g, entries, source);
        mass_symmetric(errors, g, entries, source);
    }
    if written.clean && errors.count() == 0 {
        constant_mass_positive_semidefinite(errors, g, m, &written.keyword);
    }
}

/// The rules of a constraint: it involves the state, and where it does, it
/// is differentiable as often as its level asks.
pub fn constraint_rules(errors: &mut Errors, g: &Graph, c: &WrittenConstraint) {
    constraint_involves_state(errors, g, c.phi, &c.tokens);
    if errors.count() == 0 {
        constraint_differentiable(errors, g, c.phi, c.level, &c.tokens);
    }
}

/// Rule: the struct's name is an ordinary identifier that generated code
/// does not use itself (`T` is its scalar type parameter).
pub fn struct_name(errors: &mut Errors, name: &syn::Ident) {
    let text = name.to_string();
    if text.starts_with("r#") {
        errors.spanned(
            name,
            format!("raw identifier `{text}` is not supported: choose another name"),
        );
    } else if crate::names::RESERVED.contains(&text.as_str()) {
        errors.spanned(
            name,
            format!("`{text}` is a reserved name: generated code uses it (the scalar type is `T`)"),
        );
    }
}

/// Derives the generated code already provides, and `Default` (generated
/// for systems without parameters).
const GENERATED_DERIVES: &[&str] = &["Clone", "Copy", "Debug", "PartialEq", "Default"];

/// The attributes forwarded to the generated struct: the built-in ones that
/// compile on any struct.
const FORWARDED_ATTRIBUTES: [&str; 9] = [
    "doc",
    "allow",
    "warn",
    "deny",
    "forbid",
    "expect",
    "deprecated",
    "must_use",
    "derive",
];

/// The standard derives the generated struct does not already have and that
/// need nothing else (`Ord` would need `Eq` and `PartialOrd` as well).
const FORWARDED_DERIVES: [&str; 3] = ["Hash", "Eq", "PartialOrd"];

/// Whether a forwarded attribute has the form rustc accepts: a string
/// value for `doc`, `deprecated` and `must_use` (or none for the last two,
/// or a list for `doc`), a list of paths for the lint levels and `derive`.
fn well_formed(attr: &syn::Attribute) -> bool {
    let string = |meta: &syn::MetaNameValue| {
        matches!(
            &meta.value,
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(_),
                ..
            })
        )
    };
    let paths = |list: &syn::MetaList| {
        list.parse_args_with(
            syn::punctuated::Punctuated::<syn::Path, syn::Token![,]>::parse_terminated,
        )
        .is_ok_and(|p| !p.is_empty())
    };
    let name = attr
        .path()
        .get_ident()
        .map(ToString::to_string)
        .unwrap_or_default();
    match (&attr.meta, name.as_str()) {
        (syn::Meta::NameValue(m), "doc" | "deprecated" | "must_use") => string(m),
        (syn::Meta::Path(_), "deprecated" | "must_use") => true,
        (syn::Meta::List(l), "doc") => paths(l),
        (syn::Meta::List(l), "allow" | "warn" | "deny" | "forbid" | "expect" | "derive") => {
            paths(l)
        }
        _ => false,
    }
}

/// Rule: forwarded attributes are built-in ones that compile on any struct
/// (others, or unknown derives, would fail after the macro accepted the
/// input), do not repeat a generated derive (two impls of one trait would
/// not compile) and are not `#[cfg(..)]` (it would remove the struct but not
/// the impls generated for it).
pub fn forwarded_attributes(errors: &mut Errors, attrs: &[syn::Attribute]) {
    for attr in attrs {
        if attr.path().is_ident("cfg") {
            errors.spanned(
                attr,
                "`#[cfg(..)]` on the struct would not apply to the generated impls: \
                 put the `constrained_system!` invocation itself under `#[cfg(..)]` (e.g. in a module)",
            );
        } else if !FORWARDED_ATTRIBUTES.iter().any(|a| attr.path().is_ident(a)) {
            // An attribute the macro cannot know (a misspelling, a derive
            // helper without its derive) would fail to compile after the
            // macro accepted the input: refused here, with its span.
            errors.spanned(
                attr.path(),
                format!(
                    "this attribute cannot be forwarded to the generated struct; supported: {}",
                    FORWARDED_ATTRIBUTES.map(|a| format!("`#[{a}]`")).join(", ")
                ),
            );
        } else if !well_formed(attr) {
            errors.spanned(
                attr,
                "malformed attribute: `#[doc = \"..\"]`, `#[allow(lint, ..)]` (and the other lint \
                 levels), `#[deprecated]`, `#[deprecated = \"..\"]`, `#[must_use]`, \
                 `#[must_use = \"..\"]` or `#[derive(..)]`",
            );
        } else if attr.path().is_ident("derive") {
            let _ = attr.parse_nested_meta(|meta| {
                let name = meta.path.segments.last().map(|s| s.ident.to_string()).unwrap_or_default();
                let forwarded = meta.path.is_ident(&name) && FORWARDED_DERIVES.contains(&name.as_str());
                if !forwarded && !GENERATED_DERIVES.contains(&name.as_str()) {
                    errors.spanned(
                        &meta.path,
                        format!(
                            "only the standard derives {} can be added to the generated struct",
                            FORWARDED_DERIVES.map(|d| format!("`{d}`")).join(", ")
                        ),
                    );
                    return Ok(());
                }
                if GENERATED_DERIVES.contains(&name.as_str()) {
                    errors.spanned(
                        &meta.path,
                        format!(
                            "do not derive `{name}`: the generated struct derives Clone, Copy, Debug \
                             and PartialEq, and implements Default when it has no parameters"
                        ),
                    );
                }
                Ok(())
            });
        }
    }
}

/// Rule: the number of entries of a vector or a matrix row is the number of
/// coordinates. With no coordinates declared (already an error) every
/// length would be wrong, so nothing more is said.
pub fn length(errors: &mut Errors, span: proc_macro2::Span, what: &str, len: usize, n: usize) {
    if len != n && n > 0 {
        let entries = match len {
            1 => "1 entry".to_string(),
            _ => format!("{len} entries"),
        };
        let coordinates = match n {
            1 => "is 1 coordinate".to_string(),
            _ => format!("are {n} coordinates"),
        };
        errors.at(
            span,
            format!("{what} has {entries} but there {coordinates}"),
        );
    }
}

/// Rule: `M` depends on coordinates, `t` and parameters only.
pub fn mass_without_velocities(errors: &mut Errors, g: &Graph, m: &[Vec<Id>], source: &MassSource) {
    for (i, row) in m.iter().enumerate() {
        for (j, &entry) in row.iter().enumerate() {
            if g.mentions(entry, |s| matches!(s, Sym::Vel(_))) {
                if let Some(at) = source.at(i, j) {
                    errors.spanned(
                        at,
                        "`mass` may depend on coordinates, `t` and parameters, not on velocities",
                    );
                }
            }
        }
    }
}

/// Rule: `M = Mᵀ` (compared as canonical forms, then numerically at random
/// points for forms that differ but agree). The lowering then lets the
/// upper triangle serve both halves, so generated code computes each entry
/// once.
pub fn mass_symmetric(errors: &mut Errors, g: &Graph, m: &[Vec<Id>], source: &MassSource) {
    for (i, row) in m.iter().enumerate() {
        for (j, &upper) in row.iter().enumerate().skip(i + 1) {
            let lower = m.get(j).and_then(|r| r.get(i)).copied().unwrap_or(upper);
            if upper != lower && !numerically_equal(g, upper, lower) {
                if let Some(at) = source.at(j, i) {
                    errors.spanned(
                        at,
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
        }
    }
}

/// Rule: a constant `M` is positive semi-definite (checked now, at compile
/// time). A singular one is accepted here: the constraints may complete it
/// (`[M; A]` of full column rank), which the partition stage checks.
pub fn constant_mass_positive_semidefinite(
    errors: &mut Errors,
    g: &Graph,
    m: &[Vec<Id>],
    at: impl ToTokens,
) {
    let values: Option<Vec<Vec<f64>>> = m
        .iter()
        .map(|row| row.iter().map(|&e| g.as_num(e).map(Num::to_f64)).collect())
        .collect();
    if let Some(values) = values {
        if !crate::numeric::linalg::is_positive_semidefinite(&values) {
            errors.spanned(
                at,
                "constant `mass` matrix is not positive semi-definite (it has a negative eigenvalue)",
            );
        }
    }
}

/// Rule: a constraint involves some coordinate or velocity.
pub fn constraint_involves_state(errors: &mut Errors, g: &Graph, phi: Id, at: impl ToTokens) {
    let state = g.mentions(phi, |s| matches!(s, Sym::Vel(_) | Sym::Coord(_)));
    if !state {
        errors.spanned(
            at,
            "constraint involves no coordinate or velocity (after simplification)",
        );
    }
}

/// Rule: a constraint is differentiated (twice at position level, once at
/// velocity level) only through functions that have that many derivatives
/// where their arguments vary: `abs`, `min`, `max` and `clamp` have a kink
/// (their first derivative jumps, the second would be a Dirac impulse),
/// `signum` jumps itself.
pub fn constraint_differentiable(
    errors: &mut Errors,
    g: &Graph,
    phi: Id,
    level: Level,
    at: impl ToTokens,
) {
    let times = match level {
        Level::Position => 2,
        Level::Velocity => 1,
    };
    let state = |s: Sym| matches!(s, Sym::Vel(_) | Sym::Coord(_) | Sym::Time);
    for id in g.reachable(&[phi]) {
        let crate::expr::Node::Func(f, args) = g.node(id) else {
            continue;
        };
        let Some(allowed) = f.differentiable_times() else {
            continue;
        };
        if allowed < times && args.as_slice().iter().any(|&a| g.mentions(a, state)) {
            let (how, why) = match allowed {
                0 => ("jumps", "its derivative is an impulse"),
                _ => ("has a kink", "its second derivative is an impulse"),
            };
            let what = match level {
                Level::Position => "a position-level constraint, differentiated twice",
                Level::Velocity => "a velocity-level constraint, differentiated once",
            };
            errors.spanned(
                &at,
                format!(
                    "`{}` {how} and {why}, so it cannot appear in {what} \
                     (it may appear in `forces` and `mass`)",
                    f.name()
                ),
            );
            return;
        }
    }
}

/// Whether two expressions agree at a few deterministic pseudo-random points.
fn numerically_equal(g: &Graph, a: Id, b: Id) -> bool {
    sample_points(0x5eed_0fad).all(|point| {
        let v = g.eval(&[a, b], &point);
        let scale = v[0].abs().max(v[1].abs()).max(1.0);
        (v[0] - v[1]).abs() <= 1e-12 * scale
    })
}

/// A control input where only `forces` may have one: inputs enter the
/// dynamics as impressed forces (generalized forces `Q` with energies), so
/// that `∂q̈/∂u` is the constrained response to `∂F/∂u`.
pub fn input_outside_forces(errors: &mut Errors, at: impl ToTokens, what: &str) {
    errors.spanned(
        at,
        format!(
            "control inputs may appear in `forces` only, not in {what}; \
             make it a parameter if it is not an input"
        ),
    );
}

/// Rule: control inputs appear in `forces` only (not in `M`, `T`, `V` or a
/// constraint).
pub fn inputs_in_forces_only(errors: &mut Errors, system: &System, written: &WrittenInputs) {
    let g = &system.graph;
    let is_input = |s: Sym| matches!(s, Sym::Param(i) if i >= written.first);
    let mentions = |id: Id| g.mentions(id, is_input);
    let mass_has_input =
        system.mass.iter().flatten().any(|&m| mentions(m)) || written.kinetic.is_some_and(mentions);
    if let (true, Some((keyword, what))) = (mass_has_input, &written.source) {
        input_outside_forces(errors, keyword, what);
    }
    if let Some((v, keyword)) = &written.potential {
        if mentions(*v) {
            input_outside_forces(errors, keyword, "`potential_energy`");
        }
    }
    for c in &system.constraints {
        if mentions(c.phi) {
            input_outside_forces(errors, &c.tokens, "a constraint");
        }
    }
}
