//! Stage 2's driver: the input's sections read once, every part lowered
//! in the order of the input (so that errors come in it), then every rule
//! applied to the lowered system (`check::check`), and all errors reported
//! together.

use super::check::{self, WrittenInputs};
use super::ctxt::Errors;
use super::friction::Entry;
use super::lower::{Binding, Lowerer};
use super::sections::Sections;
use super::source::{source, Lowered, Source};
use super::unilateral::Gap;
use super::{bodies, dispatch, friction_mode, urdf, Constraint, HeldBody, System};
use crate::expr::{Graph, Sym};
use crate::parse::{List, SystemInput};
use proc_macro2::Span;
use std::ops::Range;
use syn::{Expr, Ident};

/// Checks the input and lowers it into a [`System`], reporting every
/// mistake at once.
pub fn check(input: &SystemInput) -> syn::Result<System> {
    let mut errors = Errors::new();
    let sections = Sections::collect(input, &mut errors);
    let header = errors.slot();
    let robot = sections.urdf.and_then(|(_, path)| {
        let snap = sections.right_angles.map(|(_, tolerance)| tolerance);
        urdf::Robot::read(path, sections.locked, snap)
            .map_err(|e| errors.push(e))
            .ok()
    });
    let source = source(input, &sections, robot.as_ref(), &mut errors);
    let names = Names::new(&sections, source, &mut errors);
    let mut graph = new_graph(names.parameters.len(), names.coordinates.len());
    let mut lower = Lowerer::new(&mut graph, &mut errors, names.coordinates.len());
    let parts = lower.parts(&sections, source, &names);
    let named = std::mem::take(&mut lower.named);
    let mut written = std::mem::take(&mut lower.written);
    written.header = header;
    let dispatch =
        (sections.dispatch).map_or_else(Vec::new, |l| dispatch::extensions(l, &mut errors));
    let system = System {
        attrs: input.attrs.clone(),
        vis: input.vis.clone(),
        name: input.name.clone(),
        coordinates: names.coordinates,
        coordinate_names: names.coordinate_names,
        parameters: names.parameters,
        inputs: names.inputs,
        graph,
        mass: parts.dynamics.mass,
        forces: parts.dynamics.forces,
        constraints: parts.constraints,
        eliminate: parts.eliminate,
        mass_span: source.keyword().map_or(input.name.span(), Ident::span),
        named,
        energies: parts.dynamics.energies,
        bodies: parts.dynamics.bodies,
        energy: parts.dynamics.energy,
        unilateral: parts.unilateral,
        friction: parts.friction,
        held: parts.held,
        dispatch,
    };
    check::check(&mut errors, &system, &written);
    errors.finish()?;
    Ok(system)
}

/// The coordinates and the parameters, as the struct and the graph name
/// them.
struct Names {
    coordinates: Vec<Ident>,
    coordinate_names: Vec<String>,
    /// The parameters, the friction modes, the inputs.
    parameters: Vec<Ident>,
    /// The indices of the friction modes among `parameters`.
    modes: Range<usize>,
    /// How many inputs end `parameters`.
    inputs: usize,
}

impl Names {
    /// The coordinates (a tree's are its joints'), their names for users,
    /// and the parameters ([`all_parameters`]).
    fn new(sections: &Sections, source: Source, errors: &mut Errors) -> Names {
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
        let (parameters, modes) = all_parameters(sections, inputs);
        Names {
            coordinates,
            coordinate_names,
            parameters,
            modes,
            inputs: inputs.len(),
        }
    }
}

/// What lowering produced besides the graph.
struct Parts {
    dynamics: Lowered,
    constraints: Vec<Constraint>,
    held: Vec<HeldBody>,
    unilateral: Vec<Gap>,
    friction: Vec<Entry>,
    eliminate: Option<(Vec<usize>, Span)>,
}

impl Lowerer<'_> {
    /// Every part, in the order of the input: the names declared, the
    /// bodies (before the definitions, so that every expression may name
    /// their points: `position(body, [x, y, z]).z`), the definitions, `M`
    /// and `F`, the constraints, the gaps, friction (which adds a force
    /// term and a row), `eliminate`; last, where inputs may not appear.
    fn parts(&mut self, sections: &Sections, source: Source, names: &Names) -> Parts {
        let coordinates = &names.coordinates;
        self.declare_all(names);
        let described = self.described(source, coordinates, sections.frames);
        self.definitions(sections.definitions, coordinates);
        let mut dynamics = self.dynamics(source, sections, coordinates, described);
        let mut constraints = self.all_constraints(sections.constraints, source, coordinates);
        let held = self.held_bodies(&constraints);
        let first_input = names.modes.end;
        let unilateral = sections
            .unilateral
            .map_or_else(Vec::new, |l| self.gaps(l, first_input));
        let (forces, rows) = (&mut dynamics.forces, &mut constraints);
        let friction = sections
            .friction
            .map_or_else(Vec::new, |l| self.friction(l, &names.modes, forces, rows));
        let eliminate = sections
            .eliminate
            .map(|list| (self.eliminate(list), list.span));
        if names.inputs > 0 {
            let potential = sections.potential_energy.map(|(k, _)| k.clone());
            self.written.inputs = Some(WrittenInputs {
                first: first_input,
                source: source.keyword().map(|k| (k.clone(), source.what())),
                kinetic: dynamics.kinetic,
                potential: dynamics.potential.zip(potential),
                slot: self.errors.slot(),
            });
        }
        Parts {
            dynamics,
            constraints,
            held,
            unilateral,
            friction,
            eliminate,
        }
    }

    /// The coordinates and the parameters (not the friction modes, which
    /// no expression names).
    fn declare_all(&mut self, names: &Names) {
        let coordinates = &names.coordinates;
        for (i, c) in coordinates.iter().enumerate() {
            self.declare(c, Binding::Coordinate(i), coordinates);
        }
        let parameters = names.parameters.iter().enumerate();
        for (i, p) in parameters.filter(|(i, _)| !names.modes.contains(i)) {
            self.declare(p, Binding::Parameter(i), coordinates);
        }
    }

    /// Each definition, lowered, declared and named for the derivation.
    fn definitions(&mut self, list: Option<&List<(Ident, Expr)>>, coordinates: &[Ident]) {
        for (name, value) in list.map_or(&[][..], |l| &l.items) {
            let id = self.lower(value);
            self.declare(name, Binding::Definition(id), coordinates);
            self.name_node(name.to_string(), id);
        }
    }
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
