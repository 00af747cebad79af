//! The sections of one input, each read once (a second one is an error),
//! for the lowering to take in the order it needs them.

use super::ctxt::Errors;
use crate::parse::{BodyInput, ConstraintInput, List, MassInput, Section, SystemInput};
use syn::{Expr, Ident};

/// The sections of one input, each at most once.
#[derive(Default)]
pub(super) struct Sections<'a> {
    pub(super) coordinates: Option<&'a List<Ident>>,
    pub(super) parameters: Option<&'a List<Ident>>,
    pub(super) inputs: Option<&'a List<Ident>>,
    pub(super) mass: Option<(&'a Ident, &'a MassInput)>,
    pub(super) forces: Option<&'a List<Expr>>,
    pub(super) definitions: Option<&'a List<(Ident, Expr)>>,
    pub(super) constraints: Option<&'a List<ConstraintInput>>,
    pub(super) eliminate: Option<&'a List<Ident>>,
    pub(super) kinetic_energy: Option<(&'a Ident, &'a Expr)>,
    pub(super) potential_energy: Option<(&'a Ident, &'a Expr)>,
    pub(super) bodies: Option<(&'a Ident, &'a List<BodyInput>)>,
    pub(super) gravity: Option<&'a List<Expr>>,
    pub(super) urdf: Option<(&'a Ident, &'a syn::LitStr)>,
    pub(super) right_angles: Option<(&'a Ident, &'a syn::LitFloat)>,
    pub(super) locked: Option<&'a List<Ident>>,
    pub(super) unilateral: Option<&'a List<Expr>>,
    pub(super) friction: Option<&'a List<Expr>>,
    pub(super) frames: Option<&'a List<BodyInput>>,
    pub(super) derivatives: Option<&'a List<Ident>>,
    pub(super) dispatch: Option<&'a List<Ident>>,
}

impl<'a> Sections<'a> {
    /// Each section of `input`, the first where one is repeated.
    pub(super) fn collect(input: &'a SystemInput, errors: &mut Errors) -> Self {
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
                Section::RightAnglesWithin(k, l) => s.right_angles.replace((k, l)).is_some(),
                Section::Locked(_, l) => s.locked.replace(l).is_some(),
                Section::Unilateral(_, l) => s.unilateral.replace(l).is_some(),
                Section::Friction(_, l) => s.friction.replace(l).is_some(),
                Section::Frames(_, l) => s.frames.replace(l).is_some(),
                Section::Derivatives(_, l) => s.derivatives.replace(l).is_some(),
                Section::Dispatch(_, l) => s.dispatch.replace(l).is_some(),
            };
            if duplicate {
                let k = section.keyword();
                errors.spanned(k, format!("duplicate section `{k}`"));
            }
        }
        s
    }
}
