//! A point's motion in the axes of the free base above it, and that
//! motion's partial derivatives by the coordinates and rates of the joints
//! between, by the recursions of [`super::derivatives`] (Carpentier &
//! Mansard; Pinocchio's `getFrameAccelerationDerivatives`) instead of
//! differentiating the point's expressions: what the tangents of the rows
//! `position(body, r) == c` under a free base read
//! (`crate::equations::point_tangent`).
//!
//! Everything is in the base's axes about its origin, the base turning
//! with `v₀ = [ω; 0]`, `a₀ = [ω̇; 0]` about its origin (its origin's own
//! acceleration is the rows' `p̈`, apart). Along the path's columns
//! `Sⱼ = [aⱼ; bⱼ]` (angular, linear), the body carrying the point moves
//! with `v = v₀ + Σ Sⱼ q̇ⱼ` and `a = a₀ + Σ (Sⱼ q̈ⱼ + v_λ(j) × Sⱼ q̇ⱼ)`,
//! and the point `r` with `ṙ = v_lin + v_ang × r` and classical
//! acceleration `r̈ = a_lin + a_ang × r + v_ang × ṙ`
//! (`ω̇ × r + J q̈ + J̇ q̇ + ω × (ω × r) + 2 ω × J q̇`). A coordinate `qᵢ`
//! of the path moves everything beyond its joint rigidly about `Sᵢ`:
//!
//! - `∂r/∂qᵢ = Jᵢ = bᵢ + aᵢ × r`, the point's column;
//! - `∂v/∂qᵢ = Sᵢ × v + δvᵢ`, `∂a/∂qᵢ = Sᵢ × a + δaᵢ + δvᵢ × v`,
//!   `∂v/∂q̇ᵢ = Sᵢ`, `∂a/∂q̇ᵢ = δa′ᵢ + Sᵢ × v` ([`super::columns::constant`]),
//!   so `∂ṙ/∂qᵢ = ∂v_lin + ∂v_ang × r + v_ang × Jᵢ` and
//!   `∂r̈/∂qᵢ = ∂a_lin + ∂a_ang × r + a_ang × Jᵢ + ∂v_ang × ṙ + v_ang × ∂ṙ`
//!   (by `q̇ᵢ`: `∂ṙ = Jᵢ`);
//! - between two columns, `∂Jⱼ/∂qᵢ = aᵢ × Jⱼ` where `i` is `j` or comes
//!   before it on the path (it turns `Sⱼ` and the point alike), and
//!   `aⱼ × Jᵢ` where it comes after (it moves the point only): the
//!   Hessian of `r`, one cross product an entry.

use super::columns::{constant, in_frame};
use super::joint::{Joint, JointState};
use super::spatial::{self, Spatial, V3};
use super::Placement;
use crate::expr::Graph;

/// A column of a joint on a point's path below a free base: its
/// coordinate and `S` in the base's axes about its origin.
#[derive(Clone, Copy, Debug)]
pub struct PathColumn {
    /// The coordinate it moves (a mimic's: the one it follows).
    pub coordinate: usize,
    /// `S = [a; b]`.
    pub column: Spatial,
}

/// The columns of the joints from a free base down to a body, given each
/// step's frame in its parent's (its placement, then its joint's motion)
/// and its joint, base first; `None` where a joint's column is not
/// constant in its body's axes (a quaternion's).
pub fn path_columns(
    g: &mut Graph,
    steps: &[(Placement, Option<Joint>)],
) -> Option<Vec<PathColumn>> {
    let mut frame = Placement::identity(g);
    let mut out = Vec::new();
    for (step, joint) in steps {
        frame = frame.then(g, step).held(g);
        let Some(joint) = joint else { continue };
        let state = JointState::new(g, *joint);
        if state.quaternion.is_some() {
            return None;
        }
        for (coordinate, s) in state.columns(g) {
            let column = in_frame(g, &frame, s).held(g);
            out.push(PathColumn { coordinate, column });
        }
    }
    Some(out)
}

/// What one column of the path does to the point.
#[derive(Clone, Copy, Debug)]
pub struct PointColumn {
    /// Its coordinate.
    pub coordinate: usize,
    /// `Jᵢ = ∂r/∂qᵢ`.
    pub jacobian: V3,
    /// `∂ṙ/∂qᵢ`.
    pub velocity_by_q: V3,
    /// `∂r̈/∂qᵢ`, with `q̈` as `Sym::Accel`.
    pub acceleration_by_q: V3,
    /// `∂r̈/∂q̇ᵢ`.
    pub acceleration_by_rate: V3,
}

/// The point's motion in the base's axes and its partials, column by
/// column along the path (base first).
#[derive(Clone, Debug)]
pub struct PointMotion {
    /// `ṙ`.
    pub velocity: V3,
    /// `r̈`, with `q̈` as `Sym::Accel`.
    pub acceleration: V3,
    /// Per column of the path.
    pub columns: Vec<PointColumn>,
}

/// The motion of the point `r` (in the base's axes) of the body at the end
/// of `path`, the base moving with `root` (`(v₀, a₀)`), and its partials
/// (the module docs).
pub fn point_motion(
    g: &mut Graph,
    path: &[PathColumn],
    r: V3,
    root: (Spatial, Spatial),
) -> PointMotion {
    let mut motion = root;
    let mut columns = Vec::with_capacity(path.len());
    for p in path {
        let (v, a, col) = constant(g, motion, (p.coordinate, p.column));
        motion = (v, a);
        columns.push(col);
    }
    let (v, a) = motion;
    let at_point = |g: &mut Graph, m: Spatial| {
        let turned = spatial::cross(g, m.angular, r);
        spatial::add(g, m.linear, turned)
    };
    let velocity = at_point(g, v);
    let velocity = spatial::hold3(g, velocity);
    let spin = spatial::cross(g, v.angular, velocity);
    let acceleration = at_point(g, a);
    let acceleration = spatial::add(g, acceleration, spin);
    let columns = columns
        .iter()
        .map(|col| {
            let s = col.column;
            let jacobian = at_point(g, s);
            let jacobian = spatial::hold3(g, jacobian);
            // By the coordinate: `∂v`, `∂a`, then the point's.
            let s_v = s.cross_motion(g, v);
            let dv = s_v.add(g, col.velocity_by_q).held(g);
            let turned = s.cross_motion(g, a);
            let carried = col.velocity_by_q.cross_motion(g, v);
            let da = turned.add(g, col.acceleration_by_q).add(g, carried);
            let moved = spatial::cross(g, v.angular, jacobian);
            let carried = at_point(g, dv);
            let velocity_by_q = spatial::add(g, carried, moved);
            let velocity_by_q = spatial::hold3(g, velocity_by_q);
            let terms = [
                at_point(g, da),
                spatial::cross(g, a.angular, jacobian),
                spatial::cross(g, dv.angular, velocity),
                spatial::cross(g, v.angular, velocity_by_q),
            ];
            let acceleration_by_q = spatial::sum(g, &terms);
            // By the rate: `∂v = S`, `∂a = δa′ + S × v`.
            let da = col.acceleration_by_rate.add(g, s_v);
            let terms = [
                at_point(g, da),
                spatial::cross(g, s.angular, velocity),
                spatial::cross(g, v.angular, jacobian),
            ];
            let acceleration_by_rate = spatial::sum(g, &terms);
            PointColumn {
                coordinate: col.coordinate,
                jacobian,
                velocity_by_q,
                acceleration_by_q,
                acceleration_by_rate,
            }
        })
        .collect();
    PointMotion {
        velocity,
        acceleration,
        columns,
    }
}
