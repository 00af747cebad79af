//! The functions of bodies that expressions call, declared once, as the
//! operator table (`crate::expr::func`) declares the elementary functions:
//! each row gives the name, how it is written (for messages), where it may
//! appear, and how it lowers. `position`, `velocity` and
//! `angular_velocity` are vectors in world axes, used whole in a
//! constraint between points or by component (`.x`, `.y`, `.z`) in any
//! expression ([`super::bodies`]); `orientation` is one side of an
//! orientation lock only ([`super::rotation`]).
//!
//! A new function of bodies is a row here and its lowering (a method of
//! the lowerer in `bodies.rs` or `rotation.rs`), plus its line in the
//! DSL guide.

use super::lower::Lowerer;
use crate::bodies::spatial::V3;
use syn::{Expr, ExprCall};

/// Where a function of bodies may appear.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// A vector in world axes: whole in a constraint, or by component.
    Vector,
    /// One side of a lock: `f(a) == f(b)` or `f(a) == [..]`.
    Lock,
}

/// One function of bodies.
pub struct BodyFunction {
    /// The DSL name.
    pub name: &'static str,
    /// How it is written, for messages.
    pub usage: &'static str,
    /// Where it may appear.
    pub role: Role,
    /// Its world-axes vector from the call and its arguments (a
    /// [`Role::Vector`] row).
    pub lower: fn(&mut Lowerer, &Expr, &[&Expr]) -> syn::Result<V3>,
}

/// Every function of bodies.
pub const BODY_FUNCTIONS: [BodyFunction; 4] = [
    BodyFunction {
        name: "position",
        usage: "`position(body, [x, y, z])`",
        role: Role::Vector,
        lower: |l, e, a| l.position(e, a),
    },
    BodyFunction {
        name: "velocity",
        usage: "`velocity(body, [x, y, z])` or `velocity(body, position(other, [x, y, z]))`",
        role: Role::Vector,
        lower: |l, e, a| l.point_velocity(e, a),
    },
    BodyFunction {
        name: "angular_velocity",
        usage: "`angular_velocity(body)`",
        role: Role::Vector,
        lower: |l, e, a| l.angular_velocity(e, a),
    },
    BodyFunction {
        name: "orientation",
        usage: "`orientation(a) == orientation(b)` or `orientation(a) == [roll, pitch, yaw]`",
        role: Role::Lock,
        lower: |l, e, a| l.lock_only(e, a),
    },
];

/// The row of the function `e` calls, with the call; `None` if `e` is not
/// a call of a function of bodies.
pub fn body_function(e: &Expr) -> Option<(&'static BodyFunction, &ExprCall)> {
    let Expr::Call(call) = e else { return None };
    let Expr::Path(p) = &*call.func else {
        return None;
    };
    let name = p.path.get_ident()?;
    BODY_FUNCTIONS
        .iter()
        .find(|f| name == f.name)
        .map(|f| (f, call))
}

/// What a vector of a body may be, for messages.
pub fn vector_usage() -> String {
    let rows: Vec<&str> = BODY_FUNCTIONS
        .iter()
        .filter(|f| f.role == Role::Vector)
        .map(|f| f.usage)
        .collect();
    format!("expected {}", rows.join(", "))
}
