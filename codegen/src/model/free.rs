//! Quaternion joints of the `bodies` section: `joint: free(x, y, z, qw,
//! qx, qy, qz)` names seven coordinates, the position of the body's origin
//! in its parent's joint frame and the unit quaternion of its attitude;
//! `joint: spherical(qw, qx, qy, qz)` names the quaternion alone (the
//! body's frame turns about the joint frame's origin). A free body is
//! lowered as three massless bodies on prismatic joints along the frame's
//! axes and the body itself on a quaternion joint (`crate::bodies::free`),
//! a spherical one as the last of these; each quaternion's norm
//! `qw² + qx² + qy² + qz² = 1` becomes a constraint, after the ones
//! written.

use super::lower::Lowerer;
use super::Constraint;
use crate::bodies::spatial::Inertia;
use crate::bodies::{Described, Placement};
use crate::parse::{BodyInput, List};
use quote::ToTokens;
use syn::{Expr, ExprCall, Ident};

/// The two quaternion joints, with the number of coordinates each names
/// and where its quaternion starts among them.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Quaternion {
    /// `free(x, y, z, qw, qx, qy, qz)`.
    Free,
    /// `spherical(qw, qx, qy, qz)`.
    Spherical,
}

impl Quaternion {
    fn arity(self) -> usize {
        match self {
            Quaternion::Free => 7,
            Quaternion::Spherical => 4,
        }
    }

    /// The index of `qw` among the call's arguments.
    fn w(self) -> usize {
        self.arity() - 4
    }

    fn usage(self) -> &'static str {
        match self {
            Quaternion::Free => {
                "expected `free(x, y, z, qw, qx, qy, qz)`: the position of the body's \
                 origin, then its attitude as a unit quaternion"
            }
            Quaternion::Spherical => {
                "expected `spherical(qw, qx, qy, qz)`: the body's attitude in its joint \
                 frame as a unit quaternion"
            }
        }
    }
}

/// The `free(..)` or `spherical(..)` call of a body's joint, if it is one.
pub fn quaternion_call(body: &BodyInput) -> Option<(&ExprCall, Quaternion)> {
    let (_, e) = body.fields.iter().find(|(k, _)| k == "joint")?;
    match e {
        Expr::Call(call) if is_ident(&call.func, "free") => Some((call, Quaternion::Free)),
        Expr::Call(call) if is_ident(&call.func, "spherical") => {
            Some((call, Quaternion::Spherical))
        }
        _ => None,
    }
}

fn is_ident(e: &Expr, name: &str) -> bool {
    matches!(e, Expr::Path(p) if p.qself.is_none() && p.path.is_ident(name))
}

/// The coordinates a quaternion joint's call names, in order (those that
/// are names).
pub fn names(call: &ExprCall) -> Vec<Ident> {
    call.args
        .iter()
        .filter_map(|a| match a {
            Expr::Path(p) if p.qself.is_none() => p.path.get_ident().cloned(),
            _ => None,
        })
        .collect()
}

/// The index in `q` of the first coordinate the call names, when it names
/// as many consecutive coordinates as its kind has.
fn first_coordinate(call: &ExprCall, kind: Quaternion, coordinates: &[Ident]) -> Option<usize> {
    let named = names(call);
    if named.len() != kind.arity() || call.args.len() != kind.arity() {
        return None;
    }
    let index = named
        .iter()
        .map(|q| coordinates.iter().position(|c| c == q))
        .collect::<Option<Vec<usize>>>()?;
    index
        .windows(2)
        .all(|w| w[1] == w[0] + 1)
        .then_some(index[0])
}

impl Lowerer<'_> {
    /// A quaternion joint's described bodies: for `free`, the three slides
    /// and the body itself, the first placed by `placement` in `parent`;
    /// for `spherical`, the body alone. `first` is the index the first
    /// will have among the described bodies.
    pub(super) fn quaternion_bodies(
        &mut self,
        (call, kind): (&ExprCall, Quaternion),
        coordinates: &[Ident],
        name: &str,
        (parent, placement, first): (Option<usize>, Placement, usize),
        inertia: Inertia,
    ) -> Vec<Described> {
        let Some(coordinate) = first_coordinate(call, kind, coordinates) else {
            self.errors.spanned(call, kind.usage());
            return Vec::new();
        };
        match kind {
            Quaternion::Free => crate::bodies::free::described(
                self.graph,
                name,
                (parent, placement, first),
                coordinate,
                inertia,
            ),
            Quaternion::Spherical => vec![crate::bodies::free::spherical(
                self.graph,
                name,
                (parent, placement),
                coordinate,
                inertia,
            )],
        }
    }

    /// The norm of each quaternion joint's quaternion, a constraint each.
    pub(super) fn quaternion_norms(
        &mut self,
        list: &List<BodyInput>,
        coordinates: &[Ident],
    ) -> Vec<Constraint> {
        let mut rows = Vec::new();
        for (call, kind) in list.items.iter().filter_map(quaternion_call) {
            let Some(first) = first_coordinate(call, kind, coordinates) else {
                continue;
            };
            rows.push(self.norm_row(first + kind.w(), call.to_token_stream()));
        }
        rows
    }

    /// `|q|² − 1 = 0` for the quaternion whose `w` is coordinate `w`.
    pub(super) fn norm_row(&mut self, w: usize, tokens: proc_macro2::TokenStream) -> Constraint {
        let q = crate::bodies::free::coordinates(self.graph, w);
        let phi = crate::bodies::free::norm(self.graph, q);
        Constraint {
            phi,
            level: super::Level::Position,
            tokens,
            in_base: None,
            branch: None,
            rates: None,
        }
    }
}
