//! Stage 2: [`SystemInput`] → [`System`]: names resolved, expressions lowered
//! into the DAG, every rule of the DSL checked (serde_derive's `internals/`):
//! - [`ctxt`]: the error collector, so that every mistake is reported at once;
//! - [`lower`]: name resolution and lowering;
//! - [`check`](mod@check): the rules on lowered expressions, one function each.

pub mod check;
pub mod ctxt;
pub mod lower;

use crate::expr::{Graph, Id, Sym};
use crate::parse::{ConstraintInput, List, MassInput, Section, SystemInput};
use check::MassSource;
use ctxt::Errors;
use lower::{Binding, Lowerer};
use proc_macro2::Span;
use std::collections::HashMap;
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
    if sections.coordinates.is_none() {
        errors.spanned(&input.name, "missing section `coordinates`");
    }
    match (sections.mass, sections.kinetic_energy) {
        (None, None) => errors.spanned(
            &input.name,
            "missing section `mass` (or `kinetic_energy`, to derive it)",
        ),
        (Some((mass, _)), Some((kinetic, _))) => {
            for keyword in [mass, kinetic] {
                errors.spanned(
                    keyword,
                    "`mass` and `kinetic_energy` are mutually exclusive: \
                     give M, or T to derive M = ∂²T/∂q̇∂q̇ᵀ from",
                );
            }
        }
        _ => {}
    }
    let empty = Vec::new();
    let coordinates = sections.coordinates.map_or(&empty, |l| &l.items);
    if let Some(list) = sections.coordinates.filter(|l| l.items.is_empty()) {
        errors.at(list.span, "`coordinates` must name at least one coordinate");
    }
    // Inputs are parameters to every stage but the checks below and the
    // Jacobian: fields after the parameters, `Sym::Param` after theirs.
    let inputs = sections.inputs.map_or(&empty, |l| &l.items);
    let parameters: Vec<Ident> = sections
        .parameters
        .map_or(&empty, |l| &l.items)
        .iter()
        .chain(inputs)
        .cloned()
        .collect();
    let first_input = parameters.len() - inputs.len();
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
        n,
        named: Vec::new(),
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
        lower.name_node(name.to_string(), id);
    }

    // In the usual order of the input, so that errors come in source order.
    let (mass, kinetic) = match (sections.mass, sections.kinetic_energy) {
        (Some((keyword, m)), _) => (lower.mass(keyword, m, n), None),
        (None, Some((keyword, e))) => lower.kinetic(keyword, e, n),
        (None, None) => (Vec::new(), None),
    };
    let potential = sections.potential_energy.map(|(_, e)| lower.potential(e));
    let applied = match sections.forces {
        Some(list) => lower.vector(list, "`forces`", n),
        None => vec![lower.graph.int(0); n],
    };
    let (forces, energies) = if kinetic.is_some() || potential.is_some() {
        let mut d = crate::diff::Differentiator::new();
        let forces = crate::lagrange::forces(lower.graph, &mut d, kinetic, potential, &applied);
        let energies = Energies {
            kinetic,
            potential,
            applied,
        };
        (forces, Some(energies))
    } else {
        (applied, None)
    };
    let constraints: Vec<Constraint> = sections
        .constraints
        .map_or(&[][..], |l| &l.items)
        .iter()
        .map(|c| lower.constraint(c))
        .collect();
    let eliminate = sections
        .eliminate
        .map(|list| (lower.eliminate(list), list.span));

    if !inputs.is_empty() {
        let is_input = |s: Sym| matches!(s, Sym::Param(i) if i >= first_input);
        let g = &*lower.graph;
        let mentions = |id: Id| g.mentions(id, is_input);
        let where_mass = match (sections.mass, sections.kinetic_energy) {
            (Some((keyword, _)), _) => Some(("`mass`", keyword)),
            (None, Some((keyword, _))) => Some(("`kinetic_energy`", keyword)),
            (None, None) => None,
        };
        let mass_has_input =
            mass.iter().flatten().any(|&m| mentions(m)) || kinetic.is_some_and(&mentions);
        if let (true, Some((what, keyword))) = (mass_has_input, where_mass) {
            check::input_outside_forces(lower.errors, keyword, what);
        }
        if let (Some(v), Some((keyword, _))) = (potential, sections.potential_energy) {
            if mentions(v) {
                check::input_outside_forces(lower.errors, keyword, "`potential_energy`");
            }
        }
        for c in &constraints {
            if mentions(c.phi) {
                check::input_outside_forces(lower.errors, &c.tokens, "a constraint");
            }
        }
    }
    let named = std::mem::take(&mut lower.named);
    let mass_span = match (sections.mass, sections.kinetic_energy) {
        (Some((keyword, _)), _) | (None, Some((keyword, _))) => keyword.span(),
        (None, None) => input.name.span(),
    };
    errors.finish()?;
    Ok(System {
        attrs: input.attrs.clone(),
        vis: input.vis.clone(),
        name: input.name.clone(),
        coordinates: coordinates.clone(),
        parameters,
        inputs: inputs.len(),
        graph,
        mass,
        forces,
        constraints,
        eliminate,
        mass_span,
        named,
        energies,
    })
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
        let source = MassSource::Entries(sources);
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

    /// `M = ∂²T/∂q̇∂q̇ᵀ` from `T`, checked like a written mass matrix, and
    /// `T` itself.
    fn kinetic(&mut self, keyword: &Ident, e: &Expr, n: usize) -> (Vec<Vec<Id>>, Option<Id>) {
        let before = self.errors.count();
        let t = self.lower(e);
        let mut d = crate::diff::Differentiator::new();
        let m = match crate::lagrange::mass_from_kinetic_energy(self.graph, &mut d, t, n) {
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
                return (vec![vec![zero; n]; n], Some(t));
            }
        };
        if self.errors.count() == before {
            check::constant_mass_positive_semidefinite(self.errors, self.graph, &m, keyword);
        }
        (m, Some(t))
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
        if self.errors.count() == before {
            check::constraint_involves_state(self.errors, self.graph, phi, &c.tokens);
        }
        let velocity = self.graph.mentions(phi, |s| matches!(s, Sym::Vel(_)));
        let level = if velocity {
            Level::Velocity
        } else {
            Level::Position
        };
        if self.errors.count() == before {
            check::constraint_differentiable(self.errors, self.graph, phi, level, &c.tokens);
        }
        Constraint {
            phi,
            level,
            tokens: c.tokens.clone(),
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
