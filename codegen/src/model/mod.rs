//! Stage 2: [`SystemInput`] → [`System`]: names resolved, expressions lowered
//! into the DAG, every rule of the DSL checked (serde_derive's `internals/`):
//! - `ctxt`: the error collector, so that every mistake is reported at once;
//! - [`lower`]: name resolution and lowering;
//! - `check`: the rules on lowered expressions, one function each.

pub(crate) mod bodies;
pub(crate) mod check;
pub(crate) mod ctxt;
pub(crate) mod frames;
pub(crate) mod free;
pub(crate) mod friction;
pub mod lower;
mod rotation;
mod source;
pub(crate) mod unilateral;
pub(crate) mod urdf;

use crate::expr::{Graph, Id, Sym};
use crate::parse::{BodyInput, ConstraintInput, List, MassInput, Section, SystemInput};
use check::MassSource;
use ctxt::Errors;
use lower::{Binding, Lowerer};
use proc_macro2::Span;
use source::{inputs_in_forces_only, source, Source};
use std::ops::Range;
use syn::{Attribute, Expr, Ident, Visibility};

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
}

/// A row `φᵢ = (p + R̂ r)ᵢ − cᵢ` of a point of a body under a free base
/// (position `p`, quaternion `q`, `R̂ = R(q/|q|)`), `r` the point in the
/// base's axes, a function of the joints between: the velocity form
/// (`crate::equations::velocity`) solves the three rows premultiplied by
/// `R̂ᵀ`, free of the base's attitude.
#[derive(Clone, Copy, Debug)]
pub struct InBase {
    /// The quaternion's `w` coordinate.
    pub w: usize,
    /// The base's `x` coordinate.
    pub x: usize,
    /// `r`, in the base's axes.
    pub point: crate::bodies::spatial::V3,
    /// Which of the three rows, `i`.
    pub component: usize,
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
    /// Files the model was read from (a URDF), so that the build is redone
    /// when they change.
    pub files: Vec<String>,
    /// The tree's movable bodies (fixed links merged in), for the
    /// derivation's part per body.
    pub tree: Vec<crate::bodies::Body>,
    /// Each body's intermediates of the recursions, named in the derivation.
    pub trace: Vec<crate::bodies::Trace>,
    /// With quaternion joints, `M` in their velocity coordinates
    /// (`crate::bodies::Dynamics::velocity_mass`).
    pub velocity_mass: Option<Vec<Vec<Id>>>,
    /// With quaternion joints, the bias forces in the same unknowns
    /// (`crate::bodies::Dynamics::velocity_bias`).
    pub velocity_bias: Option<Vec<Id>>,
    /// With quaternion joints, `TᵀF`: `Tᵀ` of `F`'s applied part (`F + c`)
    /// less the velocity bias; set by `crate::equations`.
    pub velocity_forces: Option<Vec<Id>>,
    /// The named frames and the centre of mass, with a `frames` section.
    pub kinematics: Option<crate::bodies::kinematics::Kinematics>,
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

/// The sections of one input, each at most once.
#[derive(Default)]
struct Sections<'a> {
    coordinates: Option<&'a List<Ident>>,
    parameters: Option<&'a List<Ident>>,
    inputs: Option<&'a List<Ident>>,
    mass: Option<(&'a Ident, &'a MassInput)>,
    forces: Option<&'a List<Expr>>,
    definitions: Option<&'a List<(Ident, Expr)>>,
    constraints: Option<&'a List<ConstraintInput>>,
    eliminate: Option<&'a List<Ident>>,
    kinetic_energy: Option<(&'a Ident, &'a Expr)>,
    potential_energy: Option<(&'a Ident, &'a Expr)>,
    bodies: Option<(&'a Ident, &'a List<BodyInput>)>,
    gravity: Option<&'a List<Expr>>,
    urdf: Option<(&'a Ident, &'a syn::LitStr)>,
    locked: Option<&'a List<Ident>>,
    unilateral: Option<&'a List<Expr>>,
    friction: Option<&'a List<Expr>>,
    frames: Option<&'a List<BodyInput>>,
}

impl<'a> Sections<'a> {
    fn collect(input: &'a SystemInput, errors: &mut Errors) -> Self {
        let mut s = Sections::default();
        for section in &input.sections {
            let duplicate = match section {
                Section::Coordinates(_, l) => s.coordinates.replace(l).is_some(),
                Section::Parameters(_, l) => s.parameters.replace(l).is_some(),
                Section::Inputs(_, l) => s.inputs.replace(l).is_some(),
                Section::Mass(k, m) => s.mass.replace((k, m)).is_some(),
                Section::Forces(_, l) => s.forces.replace(l).is_some(),
                Section::Definitions(_, l) => s.definitions.replace(l).is_some(),
                Section::Constraints(_, l) => s.constraints.replace(l).is_some(),
                Section::Eliminate(_, l) => s.eliminate.replace(l).is_some(),
                Section::KineticEnergy(k, e) => s.kinetic_energy.replace((k, e)).is_some(),
                Section::PotentialEnergy(k, e) => s.potential_energy.replace((k, e)).is_some(),
                Section::Bodies(k, l) => s.bodies.replace((k, l)).is_some(),
                Section::Gravity(_, l) => s.gravity.replace(l).is_some(),
                Section::Urdf(k, l) => s.urdf.replace((k, l)).is_some(),
                Section::Locked(_, l) => s.locked.replace(l).is_some(),
                Section::Unilateral(_, l) => s.unilateral.replace(l).is_some(),
                Section::Friction(_, l) => s.friction.replace(l).is_some(),
                Section::Frames(_, l) => s.frames.replace(l).is_some(),
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
    let mut errors = Errors::new();
    let sections = Sections::collect(input, &mut errors);
    check::struct_name(&mut errors, &input.name);
    check::forwarded_attributes(&mut errors, &input.attrs);
    let robot = sections.urdf.and_then(|(_, path)| {
        urdf::Robot::read(path, sections.locked)
            .map_err(|e| errors.push(e))
            .ok()
    });
    let source = source(input, &sections, robot.as_ref(), &mut errors);
    let coordinates: Vec<Ident> = match source {
        Source::Bodies(_, list) => bodies::joint_coordinates(list),
        Source::Urdf(_, robot) => robot.coordinates(),
        _ => sections
            .coordinates
            .map_or_else(Vec::new, |l| l.items.clone()),
    };
    let coordinate_names = match source {
        Source::Urdf(_, robot) => robot.coordinate_names(),
        _ => coordinates.iter().map(ToString::to_string).collect(),
    };
    if let Some(list) = sections.coordinates.filter(|l| l.items.is_empty()) {
        errors.at(list.span, "`coordinates` must name at least one coordinate");
    }
    let inputs: &[Ident] = sections.inputs.map_or(&[][..], |l| &l.items);
    let (parameters, modes) = all_parameters(&sections, inputs);
    let first_input = modes.end;
    let n = coordinates.len();
    let mut graph = new_graph(parameters.len(), n);
    let mut lower = Lowerer::new(&mut graph, &mut errors, n);
    for (i, c) in coordinates.iter().enumerate() {
        lower.declare(c, Binding::Coordinate(i), &coordinates);
    }
    for (i, p) in parameters
        .iter()
        .enumerate()
        .filter(|(i, _)| !modes.contains(i))
    {
        lower.declare(p, Binding::Parameter(i), &coordinates);
    }
    // The bodies come before the definitions, so that every expression
    // may name their points (`position(body, [x, y, z]).z`).
    let described = lower.described(source, &coordinates, sections.frames);
    for (name, value) in sections.definitions.map_or(&[][..], |l| &l.items) {
        let id = lower.lower(value);
        lower.declare(name, Binding::Definition(id), &coordinates);
        lower.name_node(name.to_string(), id);
    }
    let mut dynamics = lower.dynamics(source, &sections, &coordinates, described);
    let mut constraints = lower.all_constraints(sections.constraints, source, &coordinates);
    let unilateral = sections
        .unilateral
        .map_or_else(Vec::new, |l| lower.gaps(l, first_input));
    let (forces, rows) = (&mut dynamics.forces, &mut constraints);
    let friction = sections
        .friction
        .map_or_else(Vec::new, |l| lower.friction(l, &modes, forces, rows));
    let eliminate = sections
        .eliminate
        .map(|list| (lower.eliminate(list), list.span));
    if !inputs.is_empty() {
        let is_input = |s: Sym| matches!(s, Sym::Param(i) if i >= first_input);
        inputs_in_forces_only(
            &mut lower,
            &is_input,
            source,
            &sections,
            &dynamics,
            &constraints,
        );
    }
    let named = std::mem::take(&mut lower.named);
    let mass_span = source.keyword().map_or(input.name.span(), Ident::span);
    errors.finish()?;
    Ok(System {
        attrs: input.attrs.clone(),
        vis: input.vis.clone(),
        name: input.name.clone(),
        coordinates,
        coordinate_names,
        parameters,
        inputs: inputs.len(),
        graph,
        mass: dynamics.mass,
        forces: dynamics.forces,
        constraints,
        eliminate,
        mass_span,
        named,
        energies: dynamics.energies,
        bodies: dynamics.bodies,
        energy: dynamics.energy,
        unilateral,
        friction,
    })
}

/// The parameters, then the friction entries' modes (hidden fields), then
/// the inputs: inputs are parameters to every stage but the checks and the
/// Jacobian (fields after the parameters, `Sym::Param` after theirs). With
/// the indices of the modes.
fn all_parameters(sections: &Sections, inputs: &[Ident]) -> (Vec<Ident>, Range<usize>) {
    let written = sections.parameters.map_or(&[][..], |l| &l.items);
    let modes = sections.friction.map_or(0, |l| l.items.len());
    let hidden = (0..modes).map(friction_mode);
    let parameters = written
        .iter()
        .cloned()
        .chain(hidden)
        .chain(inputs.iter().cloned());
    (parameters.collect(), written.len()..written.len() + modes)
}

/// The hidden field holding friction entry `i`'s mode.
pub fn friction_mode(i: usize) -> Ident {
    Ident::new(
        &format!("{}friction{i}", crate::names::GENERATED_PREFIX),
        Span::call_site(),
    )
}

/// A graph with the variables interned first, in a fixed order, so that
/// canonical term order (by node id) reads naturally: parameters before
/// time before coordinates before velocities, each in declaration order
/// (`α·ż`, `x + y`).
fn new_graph(parameters: usize, n: usize) -> Graph {
    let mut graph = Graph::new();
    for i in 0..parameters {
        graph.sym(Sym::Param(i));
    }
    graph.sym(Sym::Time);
    for i in 0..n {
        graph.sym(Sym::Coord(i));
    }
    for i in 0..n {
        graph.sym(Sym::Vel(i));
    }
    graph
}

impl Lowerer<'_> {
    fn mass(&mut self, keyword: &Ident, input: &MassInput, n: usize) -> Vec<Vec<Id>> {
        let before = self.errors.count();
        let zero = self.graph.int(0);
        let mut m = vec![vec![zero; n]; n];
        let mut sources: Vec<Vec<Option<&Expr>>> = vec![vec![None; n]; n];
        match input {
            MassInput::Diagonal(list) => {
                check::length(self.errors, list.span, "`mass`", list.items.len(), n);
                for (i, e) in list.items.iter().enumerate().take(n) {
                    m[i][i] = self.lower(e);
                    sources[i][i] = Some(e);
                }
            }
            MassInput::Full(rows) => {
                check::length(self.errors, rows.span, "`mass`", rows.items.len(), n);
                for (i, row) in rows.items.iter().enumerate().take(n) {
                    let what = format!("row {} of `mass`", i + 1);
                    check::length(self.errors, row.span, &what, row.items.len(), n);
                    for (j, e) in row.items.iter().enumerate().take(n) {
                        m[i][j] = self.lower(e);
                        sources[i][j] = Some(e);
                    }
                }
            }
        }
        let source = MassSource(sources);
        check::mass_without_velocities(self.errors, self.graph, &m, &source);
        check::mass_symmetric(self.errors, self.graph, &mut m, &source);
        // Missing or unreadable entries were filled with zeros.
        if self.errors.count() == before {
            check::constant_mass_positive_semidefinite(self.errors, self.graph, &m, keyword);
        }
        m
    }

    /// `V(q, t)`: no velocities (`dt(..)` of a position brings them in).
    fn potential(&mut self, e: &Expr) -> Id {
        let v = self.lower(e);
        if self.graph.mentions(v, |s| matches!(s, Sym::Vel(_))) {
            self.errors.spanned(
                e,
                "`potential_energy` may depend on coordinates, `t` and parameters, not on \
                 velocities (`dot(..)`, or `dt(..)` of a position, brings them in)",
            );
        }
        v
    }

    /// `M = ∂²T/∂q̇∂q̇ᵀ` from `T`, as derived, `T` itself, and whether both
    /// came without error (when `T` is not a quadratic form an error is
    /// reported and `M` is zero). The caller simplifies `M` with the forces,
    /// then checks it like a written mass matrix
    /// ([`check::constant_mass_positive_semidefinite`]).
    fn kinetic(&mut self, e: &Expr, n: usize) -> (Vec<Vec<Id>>, Id, bool) {
        let before = self.errors.count();
        let t = self.lower(e);
        let mut d = crate::expr::diff::Differentiator::new();
        let m = match crate::expr::lagrange::mass_from_kinetic_energy(self.graph, &mut d, t, n) {
            Ok(m) => m,
            Err(why) => {
                self.errors.spanned(
                    e,
                    format!(
                        "`kinetic_energy` must be a polynomial of degree at most 2 in the velocities \
                         (`dot(..)`), with coefficients of the coordinates, `t` and parameters only: {why}"
                    ),
                );
                let zero = self.graph.int(0);
                return (vec![vec![zero; n]; n], t, false);
            }
        };
        (m, t, self.errors.count() == before)
    }

    /// The constraints written, then the norm of each quaternion joint's
    /// quaternion (`free`, `spherical`, a URDF's `floating`).
    fn all_constraints(
        &mut self,
        written: Option<&List<ConstraintInput>>,
        source: Source,
        coordinates: &[Ident],
    ) -> Vec<Constraint> {
        let mut constraints: Vec<Constraint> = written
            .map_or(&[][..], |l| &l.items)
            .iter()
            .flat_map(|c| self.constraints(c))
            .collect();
        match source {
            Source::Bodies(_, list) => {
                constraints.extend(self.quaternion_norms(list, coordinates));
            }
            Source::Urdf(keyword, robot) => {
                let tokens = quote::ToTokens::to_token_stream(keyword);
                for w in robot.quaternions() {
                    constraints.push(self.norm_row(w, tokens.clone()));
                }
            }
            _ => {}
        }
        constraints
    }

    /// One constraint, or three where both sides are points
    /// (`position(a, [..]) == position(b, [..])`, or `== [x, y, z]`).
    fn constraints(&mut self, c: &ConstraintInput) -> Vec<Constraint> {
        if let Some(rows) = self.orientation_rows(c) {
            return rows
                .into_iter()
                .map(|(phi, branch)| Constraint {
                    branch: Some(branch),
                    ..self.constraint_of(phi, &c.tokens)
                })
                .collect();
        }
        let Some((rows, in_base)) = self.point_rows(c) else {
            return vec![self.constraint(c)];
        };
        rows.into_iter()
            .enumerate()
            .map(|(component, phi)| Constraint {
                in_base: in_base.map(|(w, x, point)| InBase {
                    w,
                    x,
                    point,
                    component,
                }),
                ..self.constraint_of(phi, &c.tokens)
            })
            .collect()
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
        if self.errors.count() != before {
            return Constraint {
                phi,
                level: Level::Position,
                tokens: c.tokens.clone(),
                in_base: None,
                branch: None,
            };
        }
        self.constraint_of(phi, &c.tokens)
    }

    /// φ checked and classified by level.
    fn constraint_of(&mut self, phi: Id, tokens: &proc_macro2::TokenStream) -> Constraint {
        let before = self.errors.count();
        check::constraint_involves_state(self.errors, self.graph, phi, tokens);
        let velocity = self.graph.mentions(phi, |s| matches!(s, Sym::Vel(_)));
        let level = if velocity {
            Level::Velocity
        } else {
            Level::Position
        };
        if self.errors.count() == before {
            check::constraint_differentiable(self.errors, self.graph, phi, level, tokens);
        }
        Constraint {
            phi,
            level,
            tokens: tokens.clone(),
            in_base: None,
            branch: None,
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
}
