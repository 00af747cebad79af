//! Where `M` and the velocity-dependent forces come from — written `mass`,
//! `kinetic_energy` by Lagrange, or a tree of `bodies` or a `urdf` file by
//! the recursions of `crate::bodies` — decided once ([`source`]) and
//! lowered once ([`Lowerer::dynamics`]), with the energies the generated
//! `kinetic_energy`, `potential_energy` and `energy` evaluate.

use super::check::{self, MassSource, WrittenMass};
use super::ctxt::Errors;
use super::lower::Lowerer;
use super::sections::Sections;
use super::{urdf, BodyTerms, Energies, EnergyTerms};
use crate::expr::{Graph, Id, Sym};
use crate::parse::{BodyInput, List, MassInput, SystemInput};
use proc_macro2::TokenStream;
use quote::ToTokens;
use syn::{Expr, Ident};

/// Where `M` and the velocity-dependent forces come from: the one
/// decision every later stage reads.
#[derive(Clone, Copy)]
pub(super) enum Source<'a> {
    /// `mass: ..`, written.
    Mass(&'a Ident, &'a MassInput),
    /// `kinetic_energy: T`, by Lagrange's equations.
    Kinetic(&'a Ident, &'a Expr),
    /// `bodies: [..]`, by the recursions of `crate::bodies`.
    Bodies(&'a Ident, &'a List<BodyInput>),
    /// `urdf: ".."`, the same recursions on the file's tree.
    Urdf(&'a Ident, &'a urdf::Robot),
    /// None given (an error has been recorded).
    Missing,
}

impl<'a> Source<'a> {
    pub(super) fn keyword(self) -> Option<&'a Ident> {
        match self {
            Source::Mass(k, _)
            | Source::Kinetic(k, _)
            | Source::Bodies(k, _)
            | Source::Urdf(k, _) => Some(k),
            Source::Missing => None,
        }
    }

    /// The section's name, for messages.
    pub(super) fn what(self) -> &'static str {
        match self {
            Source::Mass(..) => "`mass`",
            Source::Kinetic(..) => "`kinetic_energy`",
            Source::Bodies(..) => "`bodies`",
            Source::Urdf(..) => "`urdf`",
            Source::Missing => "",
        }
    }

    fn has_tree(self) -> bool {
        matches!(self, Source::Bodies(..) | Source::Urdf(..))
    }
}

/// Decides [`Source`]: exactly one of `mass`, `kinetic_energy`, `bodies`
/// and `urdf`, and `coordinates` exactly when there is no tree (a tree's
/// coordinates are its joints').
pub(super) fn source<'a>(
    input: &SystemInput,
    sections: &Sections<'a>,
    robot: Option<&'a urdf::Robot>,
    errors: &mut Errors,
) -> Source<'a> {
    let mut given: Vec<Source<'a>> = Vec::new();
    given.extend(sections.mass.map(|(k, m)| Source::Mass(k, m)));
    given.extend(sections.kinetic_energy.map(|(k, e)| Source::Kinetic(k, e)));
    given.extend(sections.bodies.map(|(k, b)| Source::Bodies(k, b)));
    if let (Some((k, _)), Some(r)) = (sections.urdf, robot) {
        given.push(Source::Urdf(k, r));
    }
    let chosen = match given.as_slice() {
        [] if sections.urdf.is_some() => Source::Missing, // the file's error is recorded
        [] => {
            errors.spanned(
                &input.name,
                "missing section `mass` (or `kinetic_energy`, to derive it, or `bodies` or `urdf`)",
            );
            Source::Missing
        }
        [one] => *one,
        several => {
            let names: Vec<&str> = several.iter().map(|s| s.what()).collect();
            for s in several {
                errors.spanned(
                    s.keyword(),
                    format!(
                        "{} are mutually exclusive: give M, or T to derive M = ∂²T/∂q̇∂q̇ᵀ from, \
                         or the bodies",
                        names.join(" and ")
                    ),
                );
            }
            *several.first().unwrap_or(&Source::Missing)
        }
    };
    let tree = chosen.has_tree() || sections.urdf.is_some();
    match (sections.coordinates, tree) {
        (None, false) => errors.spanned(&input.name, "missing section `coordinates`"),
        (Some(list), true) => errors.at(
            list.span,
            "with `bodies` or `urdf` the coordinates are the joints': remove `coordinates`",
        ),
        _ => {}
    }
    if let (Some((k, _)), None) = (sections.right_angles, sections.urdf) {
        errors.spanned(k, "`right_angles_within` applies to `urdf` only");
    }
    if !tree {
        for (what, given) in [
            ("`gravity`", sections.gravity.map(|l| l.span)),
            ("`locked`", sections.locked.map(|l| l.span)),
            ("`frames`", sections.frames.map(|l| l.span)),
            ("`derivatives`", sections.derivatives.map(|l| l.span)),
        ] {
            if let Some(span) = given {
                errors.at(span, format!("{what} applies to `bodies` or `urdf` only"));
            }
        }
    }
    chosen
}

/// `M`, `F` and what came with them, from the chosen [`Source`].
pub(super) struct Lowered {
    pub(super) mass: Vec<Vec<Id>>,
    pub(super) forces: Vec<Id>,
    /// The kinetic energy as written (energy form), for the input check.
    pub(super) kinetic: Option<Id>,
    pub(super) potential: Option<Id>,
    pub(super) energies: Option<Energies>,
    pub(super) bodies: Option<BodyTerms>,
    pub(super) energy: Option<EnergyTerms>,
}

impl Lowerer<'_> {
    /// The bodies of a tree source, lowered, and their frames in the world
    /// recorded for `position(..)` and `velocity(..)`, and the kinematics
    /// of a `frames` section, kept until the bodies' terms take them.
    pub(super) fn described(
        &mut self,
        source: Source,
        coordinates: &[Ident],
        frames: Option<&List<BodyInput>>,
    ) -> Vec<crate::bodies::Described> {
        let described = match source {
            Source::Bodies(_, list) => self.bodies(list, coordinates),
            Source::Urdf(_, robot) => robot.described(self.graph),
            _ => return Vec::new(),
        };
        let world = crate::bodies::world_frames(self.graph, &described);
        let parents = crate::bodies::parent_frames(self.graph, &described);
        self.chain = described.iter().map(|d| d.parent).zip(parents).collect();
        self.bases = (0..described.len())
            .map(|i| {
                let x = crate::bodies::free::free_base(self.graph, &described, i)?;
                Some((x + 3, x))
            })
            .collect();
        self.frames = described
            .iter()
            .map(|d| d.name.clone())
            .zip(world)
            .collect();
        self.kinematics = frames.map(|l| self.frames_section(l, &described));
        self.described.clone_from(&described);
        described
    }

    /// `M` and `F` from the [`Source`], in the usual order of the input so
    /// that errors come in source order.
    pub(super) fn dynamics(
        &mut self,
        source: Source,
        sections: &Sections,
        coordinates: &[Ident],
        described: Vec<crate::bodies::Described>,
    ) -> Lowered {
        let n = coordinates.len();
        // The keyword of a mass matrix derived from `T` without error: it is
        // checked once simplified with the forces.
        let mut derived_mass = None;
        let (mass, kinetic, tree) = match source {
            Source::Mass(keyword, m) => (self.mass(keyword, m, n), None, None),
            Source::Kinetic(keyword, e) => {
                let (m, t, clean) = self.kinetic(e, n);
                derived_mass = clean.then_some(keyword);
                (m, Some(t), None)
            }
            Source::Bodies(..) | Source::Urdf(..) => {
                let gravity = self.gravity(sections.gravity);
                let tree = crate::bodies::Tree::new(self.graph, &described, gravity);
                let (tree, d) = crate::bodies::slide::dynamics(self.graph, tree, n);
                (d.mass.clone(), None, Some((tree, d)))
            }
            Source::Missing => (Vec::new(), None, None),
        };
        let potential = sections.potential_energy.map(|(_, e)| self.potential(e));
        let applied = match sections.forces {
            Some(list) => self.vector(list, "`forces`", n),
            None => vec![self.graph.int(0); n],
        };
        if let Some(tree) = tree {
            let mut lowered = self.by_bodies(source, tree, mass, potential, &applied);
            let asked = sections.derivatives.map(|l| self.derivatives_section(l));
            if let Some(b) = lowered.bodies.as_mut() {
                b.inverse_derivatives = asked.unwrap_or(false);
            }
            return lowered;
        }
        if kinetic.is_some() || potential.is_some() {
            return self.by_lagrange(mass, (kinetic, potential), applied, derived_mass);
        }
        Lowered {
            mass,
            forces: applied,
            kinetic: None,
            potential: None,
            energies: None,
            bodies: None,
            energy: None,
        }
    }

    /// `F = Q − ∂V/∂q − c(q, q̇)` and the energies and terms of a tree of
    /// bodies, from its recursions.
    fn by_bodies(
        &mut self,
        source: Source,
        (tree, dynamics): (crate::bodies::Tree, crate::bodies::Dynamics),
        mass: Vec<Vec<Id>>,
        potential: Option<Id>,
        applied: &[Id],
    ) -> Lowered {
        let mut d = crate::expr::diff::Differentiator::new();
        // M q̈ = Q − ∂V/∂q − c(q, q̇).
        let applied_less_v =
            crate::expr::lagrange::forces(self.graph, &mut d, None, potential, applied);
        let applied_less_v = crate::expr::trig::simplify_all(self.graph, &applied_less_v);
        let forces = applied_less_v
            .iter()
            .zip(&dynamics.bias)
            .map(|(&f, &c)| self.graph.sub(f, c))
            .collect();
        let total_v = match potential {
            Some(v) => self.graph.add2(dynamics.potential, v),
            None => dynamics.potential,
        };
        let energy = self.energy_terms(dynamics.kinetic, total_v);
        let files = match source {
            Source::Urdf(_, robot) => vec![robot.path.clone()],
            _ => Vec::new(),
        };
        let bodies = BodyTerms {
            names: tree.bodies.iter().map(|b| b.name.clone()).collect(),
            inverse: dynamics.inverse,
            gravity: dynamics.gravity,
            bias: dynamics.bias,
            applied: applied_less_v,
            files,
            trace: dynamics.trace,
            gravity_vector: tree.gravity,
            tree: tree.bodies,
            velocity_mass: dynamics.velocity_mass,
            mass_in_world: (dynamics.mass_in_world, dynamics.velocity_mass_in_world),
            velocity_bias: dynamics.velocity_bias,
            kinematics: self.kinematics.take(),
            inverse_derivatives: false,
        };
        Lowered {
            mass,
            forces,
            kinetic: None,
            potential,
            energies: None,
            bodies: Some(bodies),
            energy: Some(energy),
        }
    }

    /// `F` from `T` (when given), `V` and `Q` by Lagrange's equations; `M`
    /// and `F` simplified (`M` with `F` when it comes from `T`), then a
    /// derived `M` recorded for its rules (`derived_mass`: its keyword).
    fn by_lagrange(
        &mut self,
        mass: Vec<Vec<Id>>,
        (kinetic, potential): (Option<Id>, Option<Id>),
        applied: Vec<Id>,
        derived_mass: Option<&Ident>,
    ) -> Lowered {
        let mut d = crate::expr::diff::Differentiator::new();
        let forces =
            crate::expr::lagrange::forces(self.graph, &mut d, kinetic, potential, &applied);
        // The identities where they make the set `q̈` is computed from
        // cheaper: `M` and `F` together when `M` comes from `T`.
        let (mass, forces) = match kinetic {
            Some(_) => joined(self.graph, mass, forces),
            None => (mass, crate::expr::trig::simplify_all(self.graph, &forces)),
        };
        if let Some(keyword) = derived_mass {
            self.written.mass = Some(WrittenMass {
                keyword: keyword.clone(),
                entries: None,
                clean: true,
                slot: self.errors.slot(),
            });
        }
        let t = kinetic.unwrap_or_else(|| self.quadratic_form(&mass));
        let v = potential.unwrap_or_else(|| self.graph.int(0));
        let energy = self.energy_terms(t, v);
        let energies = Energies {
            kinetic,
            potential,
            applied,
        };
        Lowered {
            mass,
            forces,
            kinetic,
            potential,
            energies: Some(energies),
            bodies: None,
            energy: Some(energy),
        }
    }

    fn energy_terms(&mut self, kinetic: Id, potential: Id) -> EnergyTerms {
        let total = self.graph.add2(kinetic, potential);
        EnergyTerms {
            kinetic,
            potential,
            total,
        }
    }

    /// `½ q̇ᵀ M q̇`.
    fn quadratic_form(&mut self, mass: &[Vec<Id>]) -> Id {
        let g = &mut *self.graph;
        let mut terms = Vec::new();
        for (i, row) in mass.iter().enumerate() {
            for (j, &m) in row.iter().enumerate() {
                let (vi, vj) = (g.sym(Sym::Vel(i)), g.sym(Sym::Vel(j)));
                terms.push(g.mul(&[m, vi, vj]));
            }
        }
        let sum = g.add(&terms);
        let half = g.num(crate::expr::num::Num::Rational(1, 2));
        g.mul2(half, sum)
    }
}

/// `M`'s upper triangle copied into its lower one: generated code then
/// computes each entry once (that the two agree is a rule,
/// [`check::mass_symmetric`]).
#[allow(clippy::needless_range_loop)] // (i, j) and (j, i): indices read best
fn upper_serves_both(m: &mut [Vec<Id>]) {
    let n = m.len();
    for i in 0..n {
        for j in i + 1..n {
            m[j][i] = m[i][j];
        }
    }
}

/// `M` (derived from `T`) and `F` with the addition theorems applied where
/// that makes the two together cheaper (`expr::trig::join_angle_sums`): a
/// chain in joint angles reads `cos θ₂` where its Cartesian definitions
/// gave `cos θ₁·cos(θ₁ + θ₂) + sin θ₁·sin(θ₁ + θ₂)`.
fn joined(g: &mut Graph, mut mass: Vec<Vec<Id>>, forces: Vec<Id>) -> (Vec<Vec<Id>>, Vec<Id>) {
    let n = forces.len();
    if mass.len() != n || mass.iter().any(|row| row.len() != n) {
        return (mass, forces);
    }
    let upper = (0..n).flat_map(|i| (i..n).map(move |j| (i, j)));
    let roots: Vec<Id> = upper
        .clone()
        .map(|(i, j)| mass[i][j])
        .chain(forces.iter().copied())
        .collect();
    let joined = crate::expr::trig::join_angle_sums(g, &roots);
    for ((i, j), &entry) in upper.zip(&joined) {
        mass[i][j] = entry;
        mass[j][i] = entry;
    }
    let forces = joined.into_iter().skip(n * (n + 1) / 2).collect();
    (mass, forces)
}

impl Lowerer<'_> {
    /// A written `M`, its upper triangle serving both halves (so that
    /// generated code computes each entry once); what the rules of `M`
    /// read is recorded ([`check::mass_rules`]).
    fn mass(&mut self, keyword: &Ident, input: &MassInput, n: usize) -> Vec<Vec<Id>> {
        let before = self.errors.count();
        let zero = self.graph.int(0);
        let mut m = vec![vec![zero; n]; n];
        let mut sources: Vec<Vec<Option<TokenStream>>> = vec![vec![None; n]; n];
        let mut entry = |lower: &mut Self, (i, j): (usize, usize), e: &Expr| {
            m[i][j] = lower.lower(e);
            sources[i][j] = Some(e.to_token_stream());
        };
        match input {
            MassInput::Diagonal(list) => {
                check::length(self.errors, list.span, "`mass`", list.items.len(), n);
                for (i, e) in list.items.iter().enumerate().take(n) {
                    entry(self, (i, i), e);
                }
            }
            MassInput::Full(rows) => {
                check::length(self.errors, rows.span, "`mass`", rows.items.len(), n);
                for (i, row) in rows.items.iter().enumerate().take(n) {
                    let what = format!("row {} of `mass`", i + 1);
                    check::length(self.errors, row.span, &what, row.items.len(), n);
                    for (j, e) in row.items.iter().enumerate().take(n) {
                        entry(self, (i, j), e);
                    }
                }
            }
        }
        let entries = m.clone();
        upper_serves_both(&mut m);
        self.written.mass = Some(WrittenMass {
            keyword: keyword.clone(),
            entries: Some((entries, MassSource(sources))),
            clean: self.errors.count() == before,
            slot: self.errors.slot(),
        });
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
    /// ([`check::mass_rules`]).
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
}
