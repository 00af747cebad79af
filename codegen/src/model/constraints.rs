//! The constraints: each written one lowered (one row, or three for
//! points, or an orientation lock's), classified by level and recorded for
//! its rules (`check::constraint_rules`); the norms of the quaternion
//! joints; `eliminate`.

use super::check::WrittenConstraint;
use super::lower::{Binding, Lowerer};
use super::source::Source;
use super::{Constraint, InBase, Level};
use crate::expr::{Id, Sym};
use crate::parse::{ConstraintInput, List};
use syn::Ident;

impl Lowerer<'_> {
    /// The constraints written, then the norm of each quaternion joint's
    /// quaternion (`free`, `spherical`, a URDF's `floating`).
    pub(super) fn all_constraints(
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
                .map(|(phi, branch, rates)| Constraint {
                    branch: Some(branch),
                    rates,
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
                in_base: in_base.as_ref().map(|p| InBase {
                    w: p.w,
                    x: p.x,
                    point: p.point,
                    component,
                    body: p.body,
                    local: p.local,
                    path: p.path.clone(),
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
                rates: None,
            };
        }
        self.constraint_of(phi, &c.tokens)
    }

    /// φ classified by level, and recorded for the rules of a constraint.
    fn constraint_of(&mut self, phi: Id, tokens: &proc_macro2::TokenStream) -> Constraint {
        let velocity = self.graph.mentions(phi, |s| matches!(s, Sym::Vel(_)));
        let level = if velocity {
            Level::Velocity
        } else {
            Level::Position
        };
        self.written.constraints.push(WrittenConstraint {
            phi,
            level,
            tokens: tokens.clone(),
            slot: self.errors.slot(),
        });
        Constraint {
            phi,
            level,
            tokens: tokens.clone(),
            in_base: None,
            branch: None,
            rates: None,
        }
    }

    /// The coordinates named in `eliminate`, by index.
    pub(super) fn eliminate(&mut self, list: &List<Ident>) -> Vec<usize> {
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
