//! Stage 2: `SystemInput` → [`System`]: names resolved, expressions lowered
//! into the DAG, every rule of the DSL checked (serde_derive's `internals/`).
//! This file is the data model, what the later stages read; the work is in
//! - `build`: the driver ([`check`]): the sections read, every part lowered
//!   in the input's order, then the rules;
//! - [`lower`]: name resolution and the lowering of expressions; `source`:
//!   where `M` comes from, and its lowering; `constraints`: the
//!   constraints' (and `bodies`, `free`, `rotation`, `friction`,
//!   `unilateral`, `urdf`, `dispatch` each their section's);
//! - `check`: the rules on lowered expressions, one function each, and the
//!   one `check` that applies them all;
//! - `ctxt`: the error collector, so that every mistake is reported at once.

pub(crate) mod bodies;
pub(crate) mod body_functions;
mod build;
pub(crate) mod check;
mod constraints;
pub(crate) mod ctxt;
mod derivatives;
pub(crate) mod dispatch;
pub(crate) mod frames;
pub(crate) mod free;
pub(crate) mod friction;
pub mod lower;
mod points;
mod rotation;
mod sections;
mod source;
pub(crate) mod unilateral;
pub(crate) mod urdf;

pub use build::check;

use crate::expr::{Graph, Id, Sym};
use proc_macro2::Span;
use std::ops::Range;
use syn::{Attribute, Ident, Visibility};

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
    /// The constraint's tokens, to span errors found after lowering.
    pub tokens: proc_macro2::TokenStream,
    /// For a row of `position(body, r) == c` (`c` constant) on a body
    /// under a free base: the point in the base's axes.
    pub in_base: Option<InBase>,
    /// For a row of an orientation lock, a residual that vanishes with the
    /// rows of the lock only on its branch (`Eᵢᵢ − 1`, `model::rotation`):
    /// the rows vanish at half turns too, where their rank drops, and the
    /// rank of `A` is measured on the branch.
    pub branch: Option<Id>,
    /// For a row of an orientation lock, its derivatives in closed form
    /// (`model::rotation`), which stage 3 takes instead of differentiating
    /// φ twice.
    pub rates: Option<Rates>,
}

/// A row's derivatives in closed form: the same values as `D φ` and its
/// parts, from the bodies' angular velocities instead of the partials of
/// their rotation matrices.
#[derive(Clone, Debug)]
pub struct Rates {
    /// `φ̇`.
    pub velocity: Id,
    /// `∂φ̇/∂q̇`, n entries: the row of `A`.
    pub row: Vec<Id>,
    /// `φ̈` at `q̈ = 0`: `−b`.
    pub bias: Id,
}

/// A row `φᵢ = (p + R̂ r)ᵢ − cᵢ` of a point of a body under a free base
/// (position `p`, quaternion `q`, `R̂ = R(q/|q|)`), `r` the point in the
/// base's axes, a function of the joints between: the velocity form
/// (`crate::equations::velocity`) solves the three rows premultiplied by
/// `R̂ᵀ`, free of the base's attitude.
#[derive(Clone, Debug)]
pub struct InBase {
    /// The quaternion's `w` coordinate.
    pub w: usize,
    /// The base's `x` coordinate.
    pub x: usize,
    /// `r`, in the base's axes.
    pub point: crate::bodies::spatial::V3,
    /// Which of the three rows, `i`.
    pub component: usize,
    /// The body, by its index among the described bodies.
    pub body: usize,
    /// The point in the body's frame, as written.
    pub local: crate::bodies::spatial::V3,
    /// The columns of the joints between the base and the body, base
    /// first; `None` where one is not constant in its body's axes.
    pub path: Option<Vec<crate::bodies::point_motion::PathColumn>>,
}

/// A body held at three or more of its points under a free base
/// (`position(body, r) == c`, each `r` numbers): its attitude and angular
/// motion, from which the velocity form replaces the points' rows by the
/// body's own six (`crate::equations::held`).
#[derive(Clone, Debug)]
pub struct HeldBody {
    /// The body, by its index among the described bodies.
    pub body: usize,
    /// Its attitude `R` (body axes → world).
    pub rotation: crate::bodies::spatial::M3,
    /// Its angular velocity, Jacobian and rate in world axes.
    pub angular: crate::bodies::kinematics::AngularMotion,
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
    /// Their names for users (`COORDINATES`): as written, the joints' own
    /// for a URDF (which need not be identifiers).
    pub coordinate_names: Vec<String>,
    /// Parameters, then the control inputs, in order: both are struct
    /// fields and `Sym::Param` in expressions.
    pub parameters: Vec<Ident>,
    /// How many of `parameters`, at the end, are control inputs
    /// (`inputs: [..]`): they appear in `forces` only, and
    /// `acceleration_jacobian` differentiates by them.
    pub inputs: usize,
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
    /// Where to point at the mass matrix (`mass:` or `kinetic_energy:`).
    pub mass_span: Span,
    /// Named expressions, in order (for the derivation's text): the
    /// definitions and `dt(..)` of definitions.
    pub named: Vec<(String, Id)>,
    /// The energies `M` and `F` were derived from, when given.
    pub energies: Option<Energies>,
    /// What the bodies' recursions produced, for systems with bodies.
    pub bodies: Option<BodyTerms>,
    /// `T`, `V` and `T + V`, for systems given by energies or bodies.
    pub energy: Option<EnergyTerms>,
    /// The gaps `g(q) ≥ 0` of `unilateral: [..]`, with their gradients.
    pub unilateral: Vec<unilateral::Gap>,
    /// The entries of `friction: [..]`; their modes are the parameters
    /// [`System::modes`] (hidden fields).
    pub friction: Vec<friction::Entry>,
    /// The bodies held at three or more points under a free base.
    pub held: Vec<HeldBody>,
    /// The extensions of `dispatch: [..]`: the large methods are also
    /// compiled for each, chosen at run time (`crate::emit`).
    pub dispatch: Vec<dispatch::Extension>,
}

/// The expressions of a system with bodies beyond `M` and `F`.
#[derive(Clone, Debug)]
pub struct BodyTerms {
    /// The bodies' names, in the tree's order (movable ones).
    pub names: Vec<String>,
    /// `τ = M q̈ + c(q, q̇)`, with `q̈` as `Sym::Accel`.
    pub inverse: Vec<Id>,
    /// The generalized gravity `g(q)`.
    pub gravity: Vec<Id>,
    /// The bias forces `c(q, q̇)`.
    pub bias: Vec<Id>,
    /// `F`'s other part, `Q − ∂V/∂q` (`F = Q − ∂V/∂q − c`): what the
    /// tangents differentiate beside inverse dynamics.
    pub applied: Vec<Id>,
    /// Files the model was read from (a URDF), so that the build is redone
    /// when they change.
    pub files: Vec<String>,
    /// The tree's movable bodies (fixed links merged in), for the
    /// derivation's part per body.
    pub tree: Vec<crate::bodies::Body>,
    /// The acceleration of gravity in world coordinates.
    pub gravity_vector: crate::bodies::spatial::V3,
    /// Each body's intermediates of the recursions, named in the derivation.
    pub trace: Vec<crate::bodies::Trace>,
    /// With quaternion joints, `M` in their velocity coordinates
    /// (`crate::bodies::Dynamics::velocity_mass`).
    pub velocity_mass: Option<Vec<Vec<Id>>>,
    /// Which of `M` and its velocity form were formed in world axes
    /// (`crate::bodies::world_mass`), for the derivation.
    pub mass_in_world: (bool, bool),
    /// With quaternion joints, the bias forces in the same unknowns
    /// (`crate::bodies::Dynamics::velocity_bias`).
    pub velocity_bias: Option<Vec<Id>>,
    /// The named frames and the centre of mass, with a `frames` section.
    pub kinematics: Option<crate::bodies::kinematics::Kinematics>,
    /// Whether `derivatives: [inverse_dynamics]` asks for
    /// `inverse_dynamics_jacobian`.
    pub inverse_derivatives: bool,
}

/// The energies of a system given by energies or bodies, for the
/// generated `kinetic_energy`, `potential_energy` and `energy`.
#[derive(Clone, Copy, Debug)]
pub struct EnergyTerms {
    /// `T(q, q̇, t)`: as written, the bodies' `Σ ½ vᵢᵀ Iᵢ vᵢ`, or `½ q̇ᵀ M q̇`.
    pub kinetic: Id,
    /// `V(q, t)`: as written plus gravity's for bodies; 0 if neither.
    pub potential: Id,
    /// `T + V`.
    pub total: Id,
}

/// The input of Lagrange's equations, kept for the derivation's text.
#[derive(Clone, Debug)]
pub struct Energies {
    /// `T(q, q̇, t)`, when `M` was derived from it.
    pub kinetic: Option<Id>,
    /// `V(q, t)`, when given.
    pub potential: Option<Id>,
    /// The generalized forces `Q` as written in `forces`.
    pub applied: Vec<Id>,
}

impl System {
    /// Number of coordinates.
    pub fn dof(&self) -> usize {
        self.coordinates.len()
    }

    /// The indices of the friction modes among `parameters`: between the
    /// parameters written and the inputs.
    pub fn modes(&self) -> Range<usize> {
        let end = self.parameters.len() - self.inputs;
        end - self.friction.len()..end
    }

    /// The symbol of input `j`.
    pub fn input(&self, j: usize) -> Sym {
        Sym::Param(self.parameters.len() - self.inputs + j)
    }
}

/// The hidden field holding friction entry `i`'s mode.
pub fn friction_mode(i: usize) -> Ident {
    Ident::new(
        &format!("{}friction{i}", crate::names::GENERATED_PREFIX),
        Span::call_site(),
    )
}
