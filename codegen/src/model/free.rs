//! Free (floating) joints of the `bodies` section:
//! `joint: free(x, y, z, qw, qx, qy, qz)` names seven coordinates, the
//! position of the body's origin in its parent's joint frame and the unit
//! quaternion of its attitude. The body is lowered as three massless
//! bodies on prismatic joints along the frame's axes and the body itself
//! on a quaternion joint (`crate::bodies::free`), and the quaternion's
//! norm `qw² + qx² + qy² + qz² = 1` becomes a constraint, after the ones
//! written.

use super::lower::Lowerer;
use super::Constraint;
use crate::bodies::spatial::{self, Inertia};
use crate::bodies::{Described, Joint, JointKind, Placement};
use crate::parse::{BodyInput, List};
use quote::ToTokens;
use syn::{Expr, ExprCall, Ident};

/// The names of a free joint's coordinates, for messages.
const USAGE: &str = "expected `free(x, y, z, qw, qx, qy, qz)`: the position of the body's \
                     origin, then its attitude as a unit quaternion";

/// The `free(..)` call of a body's joint, if it is one.
pub fn free_call(body: &BodyInput) -> Option<&ExprCall> {
    let (_, e) = body.fields.iter().find(|(k, _)| k == "joint")?;
    match e {
        Expr::Call(call) if is_ident(&call.func, "free") => Some(call),
        _ => None,
    }
}

fn is_ident(e: &Expr, name: &str) -> bool {
    matches!(e, Expr::Path(p) if p.qself.is_none() && p.path.is_ident(name))
}

/// The coordinates a `free(..)` call names, in order (those that are names).
pub fn names(call: &ExprCall) -> Vec<Ident> {
    call.args
        .iter()
        .filter_map(|a| match a {
            Expr::Path(p) if p.qself.is_none() => p.path.get_ident().cloned(),
            _ => None,
        })
        .collect()
}

impl Lowerer<'_> {
    /// A free joint's four described bodies: the three slides and the body
    /// itself, the first placed by `placement` in `parent`. `first` is
    /// the index the first will have among the described bodies.
    pub(super) fn free_bodies(
        &mut self,
        call: &ExprCall,
        coordinates: &[Ident],
        name: &str,
        (parent, placement, first): (Option<usize>, Placement, usize),
        inertia: Inertia,
    ) -> Vec<Described> {
        let named = names(call);
        if named.len() != 7 || call.args.len() != 7 {
            self.errors.spanned(call, USAGE);
            return Vec::new();
        }
        let Some(index) = named
            .iter()
            .map(|q| coordinates.iter().position(|c| c == q))
            .collect::<Option<Vec<usize>>>()
        else {
            return Vec::new();
        };
        if index.windows(2).any(|w| w[1] != w[0] + 1) {
            self.errors.spanned(call, USAGE);
            return Vec::new();
        }
        let zero = self.graph.int(0);
        let one = self.graph.int(1);
        let mut out = Vec::with_capacity(4);
        for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
            let mut unit = [zero; 3];
            unit[k] = one;
            let identity = Placement::identity(self.graph);
            out.push(Described {
                name: format!("{name}/{axis}"),
                parent: if k == 0 { parent } else { Some(first + k - 1) },
                placement: if k == 0 { placement } else { identity },
                joint: Some(Joint {
                    kind: JointKind::Prismatic,
                    coordinate: index[k],
                    axis: unit,
                }),
                inertia: Inertia::zero(self.graph),
            });
        }
        out.push(Described {
            name: name.to_string(),
            parent: Some(first + 2),
            placement: Placement::identity(self.graph),
            joint: Some(Joint {
                kind: JointKind::Quaternion,
                coordinate: index[3],
                axis: spatial::zero(self.graph),
            }),
            inertia,
        });
        out
    }

    /// The norm of each free joint's quaternion, a constraint each.
    pub(super) fn free_norms(
        &mut self,
        list: &List<BodyInput>,
        coordinates: &[Ident],
    ) -> Vec<Constraint> {
        let mut rows = Vec::new();
        for call in list.items.iter().filter_map(free_call) {
            let named = names(call);
            let Some(first) = named
                .get(3)
                .and_then(|w| coordinates.iter().position(|c| c == w))
            else {
                continue;
            };
            if named.len() != 7 || first + 4 > coordinates.len() {
                continue;
            }
            let q = crate::bodies::free::coordinates(self.graph, first);
            let phi = crate::bodies::free::norm(self.graph, q);
            rows.push(Constraint {
                phi,
                level: super::Level::Position,
                tokens: call.to_token_stream(),
            });
        }
        rows
    }
}
