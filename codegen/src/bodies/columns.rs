//! A joint's columns for the derivative recursions (`super::derivatives`):
//! what each coordinate and rate does to the motion the joint passes on,
//! for a column constant in its body's axes and for a quaternion's, which
//! vary with its own coordinates.

use super::joint::JointState;
use super::kinematics::world_column;
use super::recursion::joint_motion;
use super::spatial::{self, Spatial};
use super::Placement;
use crate::expr::diff::Differentiator;
use crate::expr::{Graph, Sym};

/// One column of a joint, with what its coordinate and rate do to the
/// motion the joint passes on, in the reference frame's axes about its
/// origin (`super::reference`).
#[derive(Clone, Copy)]
pub(super) struct Column {
    /// The coordinate it moves.
    pub(super) coordinate: usize,
    /// `Sᵢ`.
    pub(super) column: Spatial,
    /// `δvᵢ`: `∂v/∂qᵢ` of every body beyond is `Sᵢ × v + δvᵢ`.
    pub(super) velocity_by_q: Spatial,
    /// `δaᵢ`: `∂a/∂qᵢ` of every body beyond is `Sᵢ × a + δaᵢ + δvᵢ × v`.
    pub(super) acceleration_by_q: Spatial,
    /// `δa′ᵢ`: `∂a/∂q̇ᵢ` of every body beyond is `δa′ᵢ + Sᵢ × v`.
    pub(super) acceleration_by_rate: Spatial,
}

/// `(v, a, column)` of a body on a joint of one column `S` constant in its
/// axes (revolute, prismatic, helical, a mimic of one), from its parent's
/// `(v_λ, a_λ)`: `δv = v_λ × S`, `δa = a_λ × S + v_λ × (v_λ × S)`,
/// `δa′ = 2 v_λ × S`.
pub(super) fn constant(
    g: &mut Graph,
    (vp, ap): (Spatial, Spatial),
    (coordinate, column): (usize, Spatial),
) -> (Spatial, Spatial, Column) {
    let rate = g.sym(Sym::Vel(coordinate));
    let accel = g.sym(Sym::Accel(coordinate));
    let sq = column.scale(g, rate);
    let v = vp.add(g, sq).held(g);
    let velocity_by_q = vp.cross_motion(g, column).held(g);
    // `vᵢ × Sᵢ q̇ᵢ = v_λ × Sᵢ q̇ᵢ` (`Sᵢ × Sᵢ = 0`).
    let coriolis = velocity_by_q.scale(g, rate);
    let sa = column.scale(g, accel);
    let a = ap.add(g, sa).add(g, coriolis).held(g);
    let turned = ap.cross_motion(g, column);
    let twice = vp.cross_motion(g, velocity_by_q);
    let acceleration_by_q = turned.add(g, twice).held(g);
    // `vᵢ × Sᵢ + v_λ × Sᵢ = 2 v_λ × Sᵢ`, likewise.
    let two = g.int(2);
    let acceleration_by_rate = velocity_by_q.scale(g, two).held(g);
    let col = Column {
        coordinate,
        column,
        velocity_by_q,
        acceleration_by_q,
        acceleration_by_rate,
    };
    (v, a, col)
}

/// `(v, a, columns, turning)` of a body on a joint whose columns vary with
/// its own coordinates (a quaternion's), from its parent's `(v_λ, a_λ)`.
/// With `X` the body's frame, the joint's own velocity `v_J = Σ S q̇` and
/// acceleration `a_J = Σ S q̈ + Σ Ṡ q̇` in its axes, `v = v_λ + X v_J` and
/// `a = a_λ + X a_J + v × X v_J`, so that per column
///
/// - `δv = v_λ × S + X ∂v_J/∂q`,
/// - `δa = a_λ × S + X ∂a_J/∂q + v_λ × δv + v × X ∂v_J/∂q`,
/// - `δa′ = X ∂a_J/∂q̇ + (v + v_λ) × S`,
///
/// which are [`constant`]'s where `v_J` and `a_J` do not depend on `q`;
/// the partials of `v_J`, `a_J` and `S` are taken of their expressions.
pub(super) fn varying(
    g: &mut Graph,
    js: &JointState,
    frame: &Placement,
    local: &[(usize, Spatial)],
    (vp, ap): (Spatial, Spatial),
) -> (Spatial, Spatial, Vec<Column>, Vec<Vec<Spatial>>) {
    let vj = joint_motion(g, local, Sym::Vel);
    let mut aj = joint_motion(g, local, Sym::Accel);
    if let Some(rate) = js.column_rate(g, vj.angular) {
        aj.angular = spatial::add(g, aj.angular, rate);
    }
    let vj_placed = in_frame(g, frame, vj);
    let v = vp.add(g, vj_placed).held(g);
    let aj_placed = in_frame(g, frame, aj);
    let transport = v.cross_motion(g, vj_placed);
    let a = ap.add(g, aj_placed).add(g, transport).held(g);
    let both = v.add(g, vp);
    let mut d = Differentiator::new();
    let mut partial = |g: &mut Graph, m: Spatial, by: Sym| {
        let local = Spatial {
            angular: m.angular.map(|e| d.partial(g, e, by)),
            linear: m.linear.map(|e| d.partial(g, e, by)),
        };
        in_frame(g, frame, local).held(g)
    };
    let mut columns = Vec::with_capacity(local.len());
    for &(coordinate, s) in local {
        let column = in_frame(g, frame, s).held(g);
        let dvj = partial(g, vj, Sym::Coord(coordinate));
        let daj = partial(g, aj, Sym::Coord(coordinate));
        let daj_rate = partial(g, aj, Sym::Vel(coordinate));
        let turned = vp.cross_motion(g, column);
        let velocity_by_q = turned.add(g, dvj).held(g);
        let parts = [
            ap.cross_motion(g, column),
            daj,
            vp.cross_motion(g, velocity_by_q),
            v.cross_motion(g, dvj),
        ];
        let acceleration_by_q = sum_of(g, parts).held(g);
        let carried = both.cross_motion(g, column);
        let acceleration_by_rate = daj_rate.add(g, carried).held(g);
        columns.push(Column {
            coordinate,
            column,
            velocity_by_q,
            acceleration_by_q,
            acceleration_by_rate,
        });
    }
    let turning = local
        .iter()
        .map(|&(_, s)| {
            local
                .iter()
                .map(|&(c, _)| partial(g, s, Sym::Coord(c)))
                .collect()
        })
        .collect();
    (v, a, columns, turning)
}

/// The sum of motion vectors.
fn sum_of<const K: usize>(g: &mut Graph, parts: [Spatial; K]) -> Spatial {
    let mut total = Spatial::zero(g);
    for p in parts {
        total = total.add(g, p);
    }
    total
}

/// A motion vector of a body's axes at its origin in the axes of the frame
/// its placement `frame` is in, about that frame's origin:
/// `ω = R s_ω`, `v = R s_v + p × ω`.
pub(super) fn in_frame(g: &mut Graph, frame: &Placement, s: Spatial) -> Spatial {
    let (linear, angular) = world_column(g, frame, s);
    let moved = spatial::cross(g, frame.translation, angular);
    Spatial {
        angular,
        linear: spatial::add(g, linear, moved),
    }
}
