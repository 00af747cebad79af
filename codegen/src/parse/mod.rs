//! Stage 1: tokens → [`SystemInput`], the syntax of the DSL (the
//! guide `docs/dsl.md`).
//!
//! Only the shape is checked here; names, lengths and meaning are checked by
//! [`crate::model`], which sees the whole input and reports every error at once.

pub(crate) mod nesting;

use proc_macro2::Span;
use syn::parse::{Lookahead1, Parse, ParseStream};
use syn::punctuated::Punctuated;
use syn::{braced, bracketed, Attribute, Expr, Ident, Token, Visibility};

/// Section keywords.
pub mod kw {
    syn::custom_keyword!(coordinates);
    syn::custom_keyword!(parameters);
    syn::custom_keyword!(inputs);
    syn::custom_keyword!(mass);
    syn::custom_keyword!(forces);
    syn::custom_keyword!(definitions);
    syn::custom_keyword!(constraints);
    syn::custom_keyword!(eliminate);
    syn::custom_keyword!(kinetic_energy);
    syn::custom_keyword!(potential_energy);
    syn::custom_keyword!(diag);
    syn::custom_keyword!(bodies);
    syn::custom_keyword!(gravity);
    syn::custom_keyword!(urdf);
    syn::custom_keyword!(right_angles_within);
    syn::custom_keyword!(locked);
    syn::custom_keyword!(inertia);
    syn::custom_keyword!(unilateral);
    syn::custom_keyword!(friction);
    syn::custom_keyword!(frames);
    syn::custom_keyword!(derivatives);
    syn::custom_keyword!(dispatch);
}

/// ```text
/// system := attribute* visibility `struct` Ident `{` section (`,` section)* `,`? `}`
/// ```
pub struct SystemInput {
    /// Doc comments and attributes, forwarded to the struct.
    pub attrs: Vec<Attribute>,
    /// Visibility of the struct.
    pub vis: Visibility,
    /// Name of the struct.
    pub name: Ident,
    /// The sections in source order (duplicates are rejected by `model`).
    pub sections: Vec<Section>,
}

/// A list in brackets, with the span of the brackets for length errors.
pub struct List<T> {
    /// The items.
    pub items: Vec<T>,
    /// Span of the whole `[...]`.
    pub span: Span,
}

/// ```text
/// section := `coordinates` `:` `[` Ident,* `]`
///          | `parameters`  `:` `[` Ident,* `]`
///          | `inputs`      `:` `[` Ident,* `]`
///          | `mass`        `:` (`diag` `[` expr,* `]` | `[` (`[` expr,* `]`),* `]`)
///          | `forces`      `:` `[` expr,* `]`
///          | `definitions` `:` `[` (Ident `=` expr),* `]`
///          | `constraints` `:` `[` (expr `==` expr | expr),* `]`
///          | `eliminate`   `:` `[` Ident,* `]`
///          | `kinetic_energy`   `:` expr
///          | `potential_energy` `:` expr
///          | `bodies`      `:` `[` body,* `]`
///          | `gravity`     `:` `[` expr `,` expr `,` expr `]`
///          | `urdf`        `:` LitStr
///          | `right_angles_within` `:` LitFloat
///          | `locked`      `:` `[` Ident,* `]`
///          | `unilateral`  `:` `[` (expr `>=` expr | expr `<=` expr),* `]`
///          | `friction`    `:` `[` (`coulomb` `(` expr `,` expr `,` expr (`,` expr)? `)`),* `]`
///          | `frames`      `:` `[` body,* `]`
///          | `derivatives` `:` `[` Ident,* `]`
///          | `dispatch`    `:` `[` Ident,* `]`
/// ```
pub enum Section {
    /// Generalised coordinates.
    Coordinates(Ident, List<Ident>),
    /// Parameters (become struct fields).
    Parameters(Ident, List<Ident>),
    /// Control inputs (struct fields after the parameters, in forces only).
    Inputs(Ident, List<Ident>),
    /// The mass matrix.
    Mass(Ident, MassInput),
    /// Impressed forces.
    Forces(Ident, List<Expr>),
    /// Named intermediate expressions.
    Definitions(Ident, List<(Ident, Expr)>),
    /// Constraints φ = 0.
    Constraints(Ident, List<ConstraintInput>),
    /// The Gibbs–Appell partition.
    Eliminate(Ident, List<Ident>),
    /// `T(q, q̇, t)`, in place of `mass`.
    KineticEnergy(Ident, Expr),
    /// `V(q, t)`.
    PotentialEnergy(Ident, Expr),
    /// A kinematic tree of rigid bodies (`crate::bodies`).
    Bodies(Ident, List<BodyInput>),
    /// The acceleration of gravity, in world coordinates.
    Gravity(Ident, List<Expr>),
    /// A URDF file, relative to the user's crate manifest.
    Urdf(Ident, syn::LitStr),
    /// The tolerance, in radians, within which a URDF angle is read as the
    /// multiple of π/2 it is near (`crate::model::urdf`).
    RightAnglesWithin(Ident, syn::LitFloat),
    /// URDF joints held fixed (their names as coordinates would be).
    Locked(Ident, List<Ident>),
    /// Gaps `g(q) ≥ 0` (unilateral constraints), checked by `crate::model`.
    Unilateral(Ident, List<Expr>),
    /// Coulomb friction entries `coulomb(v, N, μs, μk)`, checked by
    /// `crate::model`.
    Friction(Ident, List<Expr>),
    /// Named frames fixed in bodies, `name { body: b, xyz: [..], rpy: [..] }`
    /// (a body's syntax), checked by `crate::model`.
    Frames(Ident, List<BodyInput>),
    /// The methods whose derivatives are generated (`inverse_dynamics`),
    /// checked by `crate::model`.
    Derivatives(Ident, List<Ident>),
    /// The instruction-set extensions the large methods are also compiled
    /// for, chosen at run time (`avx`), checked by `crate::model`.
    Dispatch(Ident, List<Ident>),
}

impl Section {
    /// The section's keyword, for duplicate-section errors.
    pub fn keyword(&self) -> &Ident {
        match self {
            Section::Coordinates(k, _)
            | Section::Parameters(k, _)
            | Section::Inputs(k, _)
            | Section::Mass(k, _)
            | Section::Forces(k, _)
            | Section::Definitions(k, _)
            | Section::Constraints(k, _)
            | Section::Eliminate(k, _)
            | Section::KineticEnergy(k, _)
            | Section::PotentialEnergy(k, _)
            | Section::Bodies(k, _)
            | Section::Gravity(k, _)
            | Section::Urdf(k, _)
            | Section::RightAnglesWithin(k, _)
            | Section::Locked(k, _)
            | Section::Unilateral(k, _)
            | Section::Friction(k, _)
            | Section::Frames(k, _)
            | Section::Derivatives(k, _)
            | Section::Dispatch(k, _) => k,
        }
    }
}

/// The mass matrix as written.
pub enum MassInput {
    /// `diag[m₁, …, mₙ]`.
    Diagonal(List<Expr>),
    /// `[[m₁₁, …], …]`, row by row.
    Full(List<List<Expr>>),
}

/// One constraint as written: `lhs == rhs`, or `expr` meaning `expr = 0`.
pub struct ConstraintInput {
    /// Left-hand side.
    pub lhs: Expr,
    /// Right-hand side, when written with `==`.
    pub rhs: Option<Expr>,
    /// The whole constraint's tokens, to span errors over all of it.
    pub tokens: proc_macro2::TokenStream,
}

impl Parse for SystemInput {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let attrs = input.call(Attribute::parse_outer)?;
        let vis: Visibility = input.parse()?;
        input.parse::<Token![struct]>()?;
        let name: Ident = input.parse()?;
        let body;
        braced!(body in input);
        let sections = Punctuated::<Section, Token![,]>::parse_terminated(&body)?;
        Ok(SystemInput {
            attrs,
            vis,
            name,
            sections: sections.into_iter().collect(),
        })
    }
}

fn list<T>(input: ParseStream, item: fn(ParseStream) -> syn::Result<T>) -> syn::Result<List<T>> {
    let content;
    let bracket = bracketed!(content in input);
    let items = Punctuated::<T, Token![,]>::parse_terminated_with(&content, item)?;
    Ok(List {
        items: items.into_iter().collect(),
        span: bracket.span.join(),
    })
}

/// A section's keyword and its colon, as the keyword's identifier.
macro_rules! keyword {
    ($input:ident, $kw:ident) => {{
        let k: kw::$kw = $input.parse()?;
        $input.parse::<Token![:]>()?;
        Ident::new(stringify!($kw), k.span)
    }};
}

impl Parse for Section {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        // Peeked in the order the messages list the sections.
        let lookahead = input.lookahead1();
        if let Some(section) = equation_section(input, &lookahead)? {
            return Ok(section);
        }
        if let Some(section) = robot_section(input, &lookahead)? {
            return Ok(section);
        }
        if lookahead.peek(kw::unilateral) {
            let k = keyword!(input, unilateral);
            Ok(Section::Unilateral(k, list(input, Expr::parse)?))
        } else if lookahead.peek(kw::friction) {
            let k = keyword!(input, friction);
            Ok(Section::Friction(k, list(input, Expr::parse)?))
        } else if lookahead.peek(kw::frames) {
            let k = keyword!(input, frames);
            Ok(Section::Frames(k, list(input, BodyInput::parse)?))
        } else if lookahead.peek(kw::derivatives) {
            let k = keyword!(input, derivatives);
            Ok(Section::Derivatives(k, list(input, Ident::parse)?))
        } else if lookahead.peek(kw::dispatch) {
            let k = keyword!(input, dispatch);
            Ok(Section::Dispatch(k, list(input, Ident::parse)?))
        } else {
            Err(lookahead.error())
        }
    }
}

/// The sections of equations written out (`coordinates` to
/// `potential_energy`), or `None` where the next keyword is another's.
fn equation_section(input: ParseStream, lookahead: &Lookahead1) -> syn::Result<Option<Section>> {
    let section = if lookahead.peek(kw::coordinates) {
        let k = keyword!(input, coordinates);
        Section::Coordinates(k, list(input, Ident::parse)?)
    } else if lookahead.peek(kw::parameters) {
        let k = keyword!(input, parameters);
        Section::Parameters(k, list(input, Ident::parse)?)
    } else if lookahead.peek(kw::inputs) {
        let k = keyword!(input, inputs);
        Section::Inputs(k, list(input, Ident::parse)?)
    } else if lookahead.peek(kw::mass) {
        let k = keyword!(input, mass);
        Section::Mass(k, input.parse()?)
    } else if lookahead.peek(kw::forces) {
        let k = keyword!(input, forces);
        Section::Forces(k, list(input, Expr::parse)?)
    } else if lookahead.peek(kw::definitions) {
        let k = keyword!(input, definitions);
        Section::Definitions(k, list(input, parse_definition)?)
    } else if lookahead.peek(kw::constraints) {
        let k = keyword!(input, constraints);
        Section::Constraints(k, list(input, ConstraintInput::parse)?)
    } else if lookahead.peek(kw::eliminate) {
        let k = keyword!(input, eliminate);
        Section::Eliminate(k, list(input, Ident::parse)?)
    } else if lookahead.peek(kw::kinetic_energy) {
        let k = keyword!(input, kinetic_energy);
        Section::KineticEnergy(k, input.parse()?)
    } else if lookahead.peek(kw::potential_energy) {
        let k = keyword!(input, potential_energy);
        Section::PotentialEnergy(k, input.parse()?)
    } else {
        return Ok(None);
    };
    Ok(Some(section))
}

/// The sections of a tree of bodies (`bodies`, `gravity`, `urdf`,
/// `right_angles_within`, `locked`), or `None` where the next keyword is
/// another's.
fn robot_section(input: ParseStream, lookahead: &Lookahead1) -> syn::Result<Option<Section>> {
    let section = if lookahead.peek(kw::bodies) {
        let k = keyword!(input, bodies);
        Section::Bodies(k, list(input, BodyInput::parse)?)
    } else if lookahead.peek(kw::gravity) {
        let k = keyword!(input, gravity);
        Section::Gravity(k, list(input, Expr::parse)?)
    } else if lookahead.peek(kw::urdf) {
        let k = keyword!(input, urdf);
        Section::Urdf(k, input.parse()?)
    } else if lookahead.peek(kw::right_angles_within) {
        let k = keyword!(input, right_angles_within);
        Section::RightAnglesWithin(k, input.parse()?)
    } else if lookahead.peek(kw::locked) {
        let k = keyword!(input, locked);
        Section::Locked(k, list(input, Ident::parse)?)
    } else {
        return Ok(None);
    };
    Ok(Some(section))
}

impl Parse for MassInput {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let lookahead = input.lookahead1();
        if lookahead.peek(kw::diag) {
            input.parse::<kw::diag>()?;
            Ok(MassInput::Diagonal(list(input, Expr::parse)?))
        } else if lookahead.peek(syn::token::Bracket) {
            Ok(MassInput::Full(list(input, |row| list(row, Expr::parse))?))
        } else {
            Err(lookahead.error())
        }
    }
}

fn parse_definition(input: ParseStream) -> syn::Result<(Ident, Expr)> {
    let name: Ident = input.parse()?;
    input.parse::<Token![=]>()?;
    Ok((name, input.parse()?))
}

impl Parse for ConstraintInput {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let expr: Expr = input.parse()?;
        let tokens = quote::ToTokens::to_token_stream(&expr);
        Ok(match expr {
            Expr::Binary(b) if matches!(b.op, syn::BinOp::Eq(_)) => ConstraintInput {
                lhs: *b.left,
                rhs: Some(*b.right),
                tokens,
            },
            lhs => ConstraintInput {
                lhs,
                rhs: None,
                tokens,
            },
        })
    }
}

/// One rigid body of a `bodies` section:
/// ```text
/// body  := Ident `{` field,* `}`
/// field := `inertia` `:` (`diag` `[` expr,* `]` | `[` (`[` expr,* `]`),* `]`)
///        | Ident `:` expr
/// ```
/// The fields' names and values are checked by `crate::model::bodies`.
pub struct BodyInput {
    /// The body's name (its frame's, for `parent:` of other bodies).
    pub name: Ident,
    /// The fields other than `inertia`, in order.
    pub fields: Vec<(Ident, Expr)>,
    /// The inertia tensor about the centre of mass, in body axes.
    pub inertia: Option<(Ident, MassInput)>,
    /// Span of the braces, for missing-field errors.
    pub span: Span,
}

impl Parse for BodyInput {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let name: Ident = input.parse()?;
        let content;
        let brace = braced!(content in input);
        let mut fields = Vec::new();
        let mut inertia = None;
        while !content.is_empty() {
            if content.peek(kw::inertia) {
                let k: kw::inertia = content.parse()?;
                content.parse::<Token![:]>()?;
                let key = Ident::new("inertia", k.span);
                if inertia.is_some() {
                    return Err(syn::Error::new(k.span, "duplicate field `inertia`"));
                }
                inertia = Some((key, content.parse()?));
            } else {
                let key: Ident = content.parse()?;
                content.parse::<Token![:]>()?;
                fields.push((key, content.parse()?));
            }
            if content.is_empty() {
                break;
            }
            content.parse::<Token![,]>()?;
        }
        Ok(BodyInput {
            name,
            fields,
            inertia,
            span: brace.span.join(),
        })
    }
}
