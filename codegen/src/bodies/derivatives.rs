//! `∂τ/∂q` and `∂τ/∂q̇` of inverse dynamics by recursions over the tree
//! (Carpentier & Mansard, *Analytical Derivatives of Rigid Body Dynamics
//! Algorithms*, RSS 2018; Pinocchio's `computeRNEADerivatives`), instead of
//! differentiating `τ`'s expressions coordinate by coordinate: O(n) spatial
//! quantities per body, then one product of two of them per entry of the
//! matrices that can be nonzero (a joint and one of its ancestors).
//!
//! Every quantity is in the axes of one frame about its origin (the
//! world's, or a body's where that costs less: [`reference_frames`]), where a
//! coordinate `qᵢ` moves the bodies beyond its joint rigidly about the
//! joint's column `Sᵢ` (`∂X/∂qᵢ = Sᵢ × X` for each of their motion vectors,
//! `Sᵢ ×*` for forces). What does not move rigidly is the motion the
//! parent `λ` passes on, so that for every body beyond the joint
//! `∂v/∂qᵢ = Sᵢ × v + δvᵢ`, `∂a/∂qᵢ = Sᵢ × a + δaᵢ + δvᵢ × v` and
//! `∂a/∂q̇ᵢ = δa′ᵢ + Sᵢ × v`, with per column
//!
//! - `δvᵢ = v_λ × Sᵢ`, `δaᵢ = a_λ × Sᵢ + v_λ × (v_λ × Sᵢ)`,
//!   `δa′ᵢ = vᵢ × Sᵢ + v_λ × Sᵢ = 2 v_λ × Sᵢ` (gravity as `a₀ = −g`)
//!
//! for a column constant in its body's axes (revolute, prismatic,
//! helical, and mimics of them, whose columns carry the multiplier and add
//! to the coordinate they follow, `accumulate`). A quaternion's four
//! columns vary with its own coordinates: its `δv`, `δa`, `δa′` gain the
//! partials of the joint's own velocity and acceleration ([`varying`]),
//! and its rows the turn of its columns among themselves.
//!
//! Per body, the rate of its force along a change `δv` of velocity that
//! is the same for all bodies beyond is `Bᵢ δv = vᵢ ×* Iᵢ δv − Iᵢ (vᵢ × δv) +
//! δv ×* kᵢ` (`kᵢ = Iᵢ vᵢ`; Pinocchio's `doYcrb`). In the 3 × 3 blocks of
//! `[ω; v]`, `B = [Σ − k̃ₙ, 0; −2 k̃_f, 0]` with the symmetric
//! `Σ = ω̃ Ī − Ī ω̃ − (h vᵀ + v hᵀ − 2 (v·h) 1)` (`Ī`, `h` the inertia's
//! rotational part and first moment about the origin): it reads the
//! angular part of `δv` only. With the composites over each subtree (`Iᶜ`,
//! `Bᶜ`, `fᶜ`), for `k` beyond `i`:
//!
//! - `∂τₖ/∂qᵢ = (Iᶜₖ Sₖ)ᵀ δaᵢ + (Bᶜₖᵀ Sₖ)ᵀ δvᵢ`, and `∂τₖ/∂q̇ᵢ` the
//!   same with `δa′ᵢ` and `Sᵢ`;
//! - `∂τᵢ/∂qₖ = Sᵢᵀ (Bᶜₖ δvₖ + Iᶜₖ δaₖ + Sₖ ×* fᶜₖ)`, and
//!   `∂τᵢ/∂q̇ₖ = Sᵢᵀ (Bᶜₖ Sₖ + Iᶜₖ δa′ₖ)`; between two columns of one joint
//!   the same without the last term (the rigid turns of `Sᵢ` and of `fᶜ`
//!   cancel), plus `(∂Sᵢ/∂qₖ − Sₖ × Sᵢ)ᵀ fᶜ` where the columns vary.

use super::columns::{constant, in_frame, varying, Column};
use super::joint::JointState;
use super::reference::reference_frames;
use super::spatial::accumulate;
use super::spatial::{self, Inertia, Spatial, M3, V3};
use super::{Body, Placement, Tree};
use crate::expr::{Graph, Id};

/// A body's quantities from the outward pass, in its subtree's reference
/// frame's axes about that frame's origin.
struct Outward {
    /// Its joint's columns.
    columns: Vec<Column>,
    /// `[r][c]`: `∂Sᵣ/∂q_c − S_c × Sᵣ` between two columns of a joint whose
    /// columns vary with its own coordinates (a quaternion's); empty where
    /// they are constant in the body's axes.
    turning: Vec<Vec<Spatial>>,
    /// The body's own inertia, `Σᵢ`, momentum and force: its subtree's
    /// [`Composite`] before the children's are added.
    own: Composite,
}

/// A body's products from the inward pass for one of its columns, with
/// the composites of its subtree: what the entries of its ancestors read.
#[derive(Clone, Copy)]
struct Inward {
    /// The column's coordinate.
    coordinate: usize,
    /// `Iᶜₖ Sₖ`.
    inertia_column: Spatial,
    /// The angular part of `Bᶜₖᵀ Sₖ` (its linear part is zero).
    rate_column: V3,
    /// `Bᶜₖ δvₖ + Iᶜₖ δaₖ + Sₖ ×* fᶜₖ`.
    force_by_q: Spatial,
    /// `Bᶜₖ Sₖ + Iᶜₖ δa′ₖ`.
    force_by_rate: Spatial,
}

/// The composites of a subtree, summed inward.
#[derive(Clone, Copy)]
struct Composite {
    /// `Iᶜ`.
    inertia: Inertia,
    /// `Σᶜ`, the symmetric block of `Bᶜ`.
    symmetric: M3,
    /// `kᶜ`, the sum of `kᵢ = Iᵢ vᵢ`.
    momentum: Spatial,
    /// `fᶜ`, the sum of `fᵢ = Iᵢ aᵢ + vᵢ ×* kᵢ`.
    force: Spatial,
}

/// `(∂τ/∂q, ∂τ/∂q̇)` of the tree's inverse dynamics, n × n each, with `q̈`
/// as `Sym::Accel`, the recursions run in the axes of one reference body
/// per subtree on the world (the world's for a subtree without one;
/// [`reference_frames`]).
pub fn inverse_dynamics_jacobian(
    g: &mut Graph,
    tree: &Tree,
    n: usize,
    references: &[usize],
) -> [Vec<Vec<Id>>; 2] {
    let outward = outward(g, tree, references);
    let zero = g.int(0);
    let mut by_q = vec![vec![zero; n]; n];
    let mut by_rate = vec![vec![zero; n]; n];
    let mut composite: Vec<Composite> = outward.iter().map(|o| o.own).collect();
    let mut inward: Vec<Vec<Inward>> = vec![Vec::new(); tree.bodies.len()];
    for i in (0..tree.bodies.len()).rev() {
        let c = held(g, composite[i]);
        let o = &outward[i];
        let own: Vec<Inward> = o.columns.iter().map(|col| products(g, &c, col)).collect();
        own_entries(g, o, &own, c.force, [&mut by_q, &mut by_rate]);
        // The entries between this joint's columns and those beyond.
        for k in beyond(&tree.bodies, i) {
            for w in &inward[k] {
                for col in &o.columns {
                    let (s, ck, ci) = (col.column, w.coordinate, col.coordinate);
                    let entries = [
                        pair(g, w, col.acceleration_by_q, col.velocity_by_q.angular),
                        pair(g, w, col.acceleration_by_rate, s.angular),
                        s.dot(g, w.force_by_q),
                        s.dot(g, w.force_by_rate),
                    ];
                    accumulate(g, &mut by_q[ck][ci], entries[0]);
                    accumulate(g, &mut by_rate[ck][ci], entries[1]);
                    accumulate(g, &mut by_q[ci][ck], entries[2]);
                    accumulate(g, &mut by_rate[ci][ck], entries[3]);
                }
            }
        }
        // What the ancestors read also turns the subtree's force.
        inward[i] = own
            .into_iter()
            .zip(&o.columns)
            .map(|(w, col)| {
                let turned = col.column.cross_force(g, c.force);
                Inward {
                    force_by_q: w.force_by_q.add(g, turned).held(g),
                    ..w
                }
            })
            .collect();
        if let Some(p) = tree.bodies[i].parent {
            composite[p] = sum(g, &composite[p], &c);
        }
    }
    [by_q, by_rate]
}

/// The entries between a joint's own columns: `∂τᵣ/∂q_c = Sᵣᵀ (Bᶜ δv_c +
/// Iᶜ δa_c) + (∂Sᵣ/∂q_c − S_c × Sᵣ)ᵀ fᶜ` and `∂τᵣ/∂q̇_c = Sᵣᵀ (Bᶜ S_c +
/// Iᶜ δa′_c)` (the subtree's rigid turn `S_c ×* fᶜ` cancels that of `Sᵣ`).
fn own_entries(
    g: &mut Graph,
    o: &Outward,
    own: &[Inward],
    force: Spatial,
    [by_q, by_rate]: [&mut Vec<Vec<Id>>; 2],
) {
    for (r, row) in o.columns.iter().enumerate() {
        for (k, (col, w)) in o.columns.iter().zip(own).enumerate() {
            let (ri, ci) = (row.coordinate, col.coordinate);
            let mut by_coordinate = row.column.dot(g, w.force_by_q);
            if let Some(turn) = o.turning.get(r).and_then(|t| t.get(k)) {
                let turned = turn.dot(g, force);
                by_coordinate = g.add2(by_coordinate, turned);
            }
            accumulate(g, &mut by_q[ri][ci], by_coordinate);
            let by_velocity = row.column.dot(g, w.force_by_rate);
            accumulate(g, &mut by_rate[ri][ci], by_velocity);
        }
    }
}

/// A column's products with its body's subtree's composites `c`,
/// `force_by_q` without the turn `Sₖ ×* fᶜₖ` (which its own entries do
/// not read).
fn products(g: &mut Graph, c: &Composite, col: &Column) -> Inward {
    let s = col.column;
    let inertia_column = c.inertia.apply(g, s).held(g);
    let rate_column = transposed_rate(g, c, s);
    let rate_column = spatial::hold3(g, rate_column);
    let by_velocity = rate(g, c, col.velocity_by_q);
    let by_acceleration = c.inertia.apply(g, col.acceleration_by_q);
    let force_by_q = by_velocity.add(g, by_acceleration).held(g);
    let own = rate(g, c, s);
    let by_acceleration = c.inertia.apply(g, col.acceleration_by_rate);
    let force_by_rate = own.add(g, by_acceleration).held(g);
    Inward {
        coordinate: col.coordinate,
        inertia_column,
        rate_column,
        force_by_q,
        force_by_rate,
    }
}

/// Every body's [`Outward`] quantities, parents first, each in the axes
/// of its subtree's reference body ([`reference_frames`]).
fn outward(g: &mut Graph, tree: &Tree, references: &[usize]) -> Vec<Outward> {
    let states: Vec<JointState> = tree
        .bodies
        .iter()
        .map(|b| JointState::new(g, b.joint))
        .collect();
    let (frames, worlds) = reference_frames(g, tree, &states, references);
    let zero = spatial::zero(g);
    let down = spatial::neg(g, tree.gravity);
    let rest = Spatial::zero(g);
    let mut motion: Vec<(Spatial, Spatial)> = Vec::with_capacity(tree.bodies.len());
    let mut out = Vec::with_capacity(tree.bodies.len());
    for (i, body) in tree.bodies.iter().enumerate() {
        let parent = match body.parent {
            Some(p) => motion[p],
            None => {
                let gravity = Spatial {
                    angular: zero,
                    linear: spatial::mat_vec(g, &worlds[i].rotation, down),
                };
                (rest, gravity)
            }
        };
        let (js, frame) = (&states[i], &frames[i]);
        let local = js.columns(g);
        let (v, a, columns, turning) = match &local[..] {
            &[(coordinate, s)] if js.quaternion.is_none() => {
                let column = in_frame(g, frame, s).held(g);
                let (v, a, col) = constant(g, parent, (coordinate, column));
                (v, a, vec![col], Vec::new())
            }
            _ => varying(g, js, frame, &local, parent),
        };
        let inertia = inertia_in_frame(g, &body.inertia, frame);
        let momentum = inertia.apply(g, v).held(g);
        let ia = inertia.apply(g, a);
        let gyroscopic = v.cross_force(g, momentum);
        let force = ia.add(g, gyroscopic).held(g);
        let symmetric = symmetric_rate(g, &inertia, v);
        out.push(Outward {
            columns,
            turning,
            own: Composite {
                inertia,
                symmetric,
                momentum,
                force,
            },
        });
        motion.push((v, a));
    }
    out
}

/// A body's inertia in the axes of the frame its placement `frame` is in,
/// about that frame's origin ([`Inertia::moved`]), each parameter held.
fn inertia_in_frame(g: &mut Graph, inertia: &Inertia, frame: &Placement) -> Inertia {
    inertia.moved(g, &frame.rotation, frame.translation).held(g)
}

/// `Σ = ω̃ Ī − Ī ω̃ − (h vᵀ + v hᵀ − 2 (v·h) 1)` for the velocity `[ω; v]`:
/// `X + Xᵀ` with `X = ω̃ Ī`, less the symmetric `ṽ h̃ + h̃ ṽ`, each
/// symmetric entry once.
fn symmetric_rate(g: &mut Graph, inertia: &Inertia, velocity: Spatial) -> M3 {
    let (w, v, h) = (velocity.angular, velocity.linear, inertia.first_moment);
    let w = spatial::skew(g, w);
    let turned = spatial::mat_mul(g, &w, &inertia.rotational);
    let vh = spatial::dot(g, v, h);
    let two = g.int(2);
    let twice = g.mul2(two, vh);
    let mut out = [[g.int(0); 3]; 3];
    for r in 0..3 {
        for c in r..3 {
            let hv = g.mul2(h[r], v[c]);
            let vh = g.mul2(v[r], h[c]);
            let mut e = g.add(&[turned[r][c], turned[c][r]]);
            e = g.sub(e, hv);
            e = g.sub(e, vh);
            if r == c {
                e = g.add2(e, twice);
            }
            let e = spatial::hold(g, e);
            out[r][c] = e;
            out[c][r] = e;
        }
    }
    out
}

/// `Bᶜ m = [Σᶜ ω − kₙ × ω; −2 k_f × ω]` for `m = [ω; v]`.
fn rate(g: &mut Graph, c: &Composite, m: Spatial) -> Spatial {
    let w = m.angular;
    let sw = spatial::mat_vec(g, &c.symmetric, w);
    let kw = spatial::cross(g, c.momentum.angular, w);
    let fw = spatial::cross(g, c.momentum.linear, w);
    let minus_two = g.int(-2);
    Spatial {
        angular: spatial::sub(g, sw, kw),
        linear: spatial::scale(g, minus_two, fw),
    }
}

/// The angular part of `Bᶜᵀ s = [Σᶜ s_ω + kₙ × s_ω + 2 k_f × s_v; 0]`.
fn transposed_rate(g: &mut Graph, c: &Composite, s: Spatial) -> V3 {
    let sw = spatial::mat_vec(g, &c.symmetric, s.angular);
    let kw = spatial::cross(g, c.momentum.angular, s.angular);
    let fv = spatial::cross(g, c.momentum.linear, s.linear);
    let two = g.int(2);
    let fv = spatial::scale(g, two, fv);
    let sum = spatial::add(g, sw, kw);
    spatial::add(g, sum, fv)
}

/// `(Iᶜₖ Sₖ)ᵀ a + (Bᶜₖᵀ Sₖ)ᵀ [w; ·]`: an entry of a column beyond the
/// joint whose `δa` is `a` and whose `δv` has angular part `w`.
fn pair(g: &mut Graph, w: &Inward, a: Spatial, angular: V3) -> Id {
    let by_a = w.inertia_column.dot(g, a);
    let by_v = spatial::dot(g, w.rate_column, angular);
    g.add2(by_a, by_v)
}

/// The bodies strictly beyond body `i` (its descendants).
fn beyond(bodies: &[Body], i: usize) -> Vec<usize> {
    (i + 1..bodies.len())
        .filter(|&k| {
            std::iter::successors(bodies[k].parent, |&p| bodies[p].parent)
                .take(bodies.len())
                .any(|p| p == i)
        })
        .collect()
}

/// Each part of a composite held, as the recursions hold theirs.
fn held(g: &mut Graph, c: Composite) -> Composite {
    Composite {
        inertia: c.inertia.held(g),
        symmetric: c.symmetric.map(|row| spatial::hold3(g, row)),
        momentum: c.momentum.held(g),
        force: c.force.held(g),
    }
}

/// `a + b`, part by part.
fn sum(g: &mut Graph, a: &Composite, b: &Composite) -> Composite {
    Composite {
        inertia: a.inertia.add(g, &b.inertia),
        symmetric: spatial::mat_add(g, &a.symmetric, &b.symmetric),
        momentum: a.momentum.add(g, b.momentum),
        force: a.force.add(g, b.force),
    }
}

#[cfg(test)]
mod tests {
    use crate::bodies::Tree;
    use crate::expr::diff::Differentiator;
    use crate::expr::Sym;

    /// A branched tree: a turned revolute base, a prismatic and a helical
    /// joint on one branch, a revolute pair on turned axes on the other,
    /// full inertias off their origins, gravity off every axis.
    const BRANCHED: &str = "pub struct Branched {
        gravity: [0.3, -1.2, -9.7],
        bodies: [
            base {
                joint: revolute(q1, [0.0, 0.6, 0.8]),
                xyz: [0.1, -0.2, 0.3],
                rpy: [0.3, -0.2, 0.1],
                mass: 2.0,
                com: [0.05, 0.02, 0.2],
                inertia: [[0.05, 0.001, -0.002], [0.001, 0.06, 0.003], [-0.002, 0.003, 0.03]],
            },
            slide {
                parent: base,
                joint: prismatic(s, [1.0, 0.0, 0.0]),
                xyz: [0.0, 0.1, 0.4],
                mass: 0.7,
                com: [0.1, 0.0, -0.05],
                inertia: diag[0.004, 0.005, 0.006],
            },
            screw {
                parent: slide,
                joint: helical(h, [0.0, 0.0, 1.0], 0.02),
                xyz: [0.2, 0.0, 0.0],
                rpy: [0.0, 0.4, 0.0],
                mass: 0.4,
                com: [0.0, 0.03, 0.01],
                inertia: diag[0.001, 0.002, 0.0015],
            },
            upper {
                parent: base,
                joint: revolute(q2, [0.0, 1.0, 0.0]),
                xyz: [0.0, -0.1, 0.4],
                rpy: [-0.5, 0.0, 0.2],
                mass: 1.5,
                com: [0.25, 0.01, 0.0],
                inertia: diag[0.01, 0.04, 0.045],
            },
            fore {
                parent: upper,
                joint: revolute(q3, [0.36, 0.48, 0.8]),
                xyz: [0.5, 0.0, 0.0],
                mass: 1.0,
                com: [0.2, 0.0, 0.02],
                inertia: diag[0.005, 0.02, 0.021],
            },
        ],
    }";

    /// A free base (three slides and a quaternion) carrying a revolute
    /// arm whose second link hangs on a spherical joint (a quaternion
    /// whose parent moves), full inertias off their origins.
    const FLOATING: &str = "pub struct Floating {
        gravity: [0.3, -1.2, -9.7],
        bodies: [
            trunk {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: 6.0,
                com: [0.02, -0.01, 0.03],
                inertia: [[0.08, 0.002, -0.001], [0.002, 0.2, 0.003], [-0.001, 0.003, 0.22]],
            },
            upper {
                parent: trunk,
                joint: revolute(q1, [0.0, 0.6, 0.8]),
                xyz: [0.2, -0.1, 0.0],
                rpy: [0.3, -0.2, 0.1],
                mass: 1.5,
                com: [0.0, 0.01, -0.15],
                inertia: diag[0.01, 0.012, 0.004],
            },
            ball {
                parent: upper,
                joint: spherical(bw, bx, by, bz),
                xyz: [0.0, 0.05, -0.3],
                mass: 0.8,
                com: [0.01, 0.0, -0.12],
                inertia: [[0.006, 0.0004, 0.0], [0.0004, 0.005, -0.0002], [0.0, -0.0002, 0.002]],
            },
            foot {
                parent: ball,
                joint: prismatic(s, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, -0.25],
                mass: 0.3,
                com: [0.0, 0.02, -0.01],
                inertia: diag[0.0005, 0.0006, 0.0004],
            },
        ],
    }";

    /// Two arms on the world, each of two links: subtrees that may each
    /// take their own frame.
    const TWO_ARMS: &str = "pub struct TwoArms {
        gravity: [0.0, 0.4, -9.8],
        bodies: [
            left { joint: revolute(a1, [0.0, 0.0, 1.0]), xyz: [0.0, 0.2, 0.5], mass: 1.0,
                   com: [0.1, 0.0, 0.0], inertia: diag[0.01, 0.02, 0.02] },
            left_fore { parent: left, joint: revolute(a2, [0.0, 1.0, 0.0]), xyz: [0.3, 0.0, 0.0],
                        rpy: [0.2, 0.0, 0.0], mass: 0.5, com: [0.15, 0.0, 0.01],
                        inertia: diag[0.002, 0.006, 0.006] },
            right { joint: revolute(b1, [0.6, 0.0, 0.8]), xyz: [0.0, -0.2, 0.5], rpy: [0.0, 0.3, 0.0],
                    mass: 1.2, com: [0.0, 0.1, 0.0], inertia: diag[0.02, 0.01, 0.02] },
            right_fore { parent: right, joint: prismatic(b2, [0.0, 1.0, 0.0]), xyz: [0.0, 0.3, 0.0],
                         mass: 0.4, com: [0.0, 0.1, 0.02], inertia: diag[0.003, 0.001, 0.003] },
        ],
    }";

    /// A revolute arm and a finger on a prismatic joint that follows the
    /// elbow (a URDF `<mimic>` with a multiplier and an offset), and a
    /// second finger that follows it the other way.
    const MIMIC: &str = r#"<robot name="r">
      <link name="base"/>
      <link name="arm"><inertial><origin xyz="0.1 0 0.2"/><mass value="1.2"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.01"/></inertial></link>
      <link name="fore"><inertial><origin xyz="0.2 0.01 0"/><mass value="0.8"/><inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.02" iyz="0" izz="0.015"/></inertial></link>
      <link name="left"><inertial><origin xyz="0 0.02 0"/><mass value="0.1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
      <link name="right"><inertial><origin xyz="0 -0.02 0"/><mass value="0.1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="elbow" type="revolute"><parent link="arm"/><child link="fore"/><origin xyz="0 0 0.4" rpy="0.2 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="left_joint" type="prismatic"><parent link="fore"/><child link="left"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="elbow" multiplier="0.5" offset="0.01"/>
      </joint>
      <joint name="right_joint" type="prismatic"><parent link="fore"/><child link="right"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="elbow" multiplier="-0.5"/>
      </joint>
    </robot>"#;

    /// The recursions' `∂τ/∂q`, `∂τ/∂q̇`, in the world's axes and in each
    /// body's, against the exact partials of `τ`'s own expressions, at
    /// random points: the largest difference relative to the largest entry.
    fn against_partials(model: &str) -> f64 {
        let mut eq = crate::analyse(model.parse().expect("tokens")).expect("expands");
        let bodies = eq.system.bodies.clone().expect("bodies");
        let g = &mut eq.system.graph;
        let tau = &bodies.inverse;
        let n = tau.len();
        let tree = Tree {
            bodies: bodies.tree.clone(),
            gravity: bodies.gravity_vector,
        };
        let mut d = Differentiator::new();
        let mut worst: f64 = 0.0;
        // No reference, each body alone, and every subtree on the world at
        // once in its first and its second body's axes.
        let count = tree.bodies.len();
        let roots: Vec<usize> = (0..count)
            .filter(|&i| tree.bodies[i].parent.is_none())
            .collect();
        let children: Vec<usize> = roots
            .iter()
            .filter_map(|&r| (0..count).find(|&i| tree.bodies[i].parent == Some(r)))
            .collect();
        let references = std::iter::once(Vec::new())
            .chain((0..count).map(|i| vec![i]))
            .chain([roots, children]);
        for reference in references {
            let recursions = super::inverse_dynamics_jacobian(g, &tree, n, &reference);
            for (m, by) in recursions
                .iter()
                .zip([Sym::Coord as fn(usize) -> Sym, Sym::Vel])
            {
                let mut ours = Vec::new();
                let mut truth = Vec::new();
                for (i, row) in m.iter().enumerate() {
                    for (k, &e) in row.iter().enumerate() {
                        ours.push(e);
                        truth.push(d.partial(g, tau[i], by(k)));
                    }
                }
                for point in crate::numeric::rng::sample_points(7) {
                    let a = g.eval(&ours, &point);
                    let b = g.eval(&truth, &point);
                    let scale = b.iter().fold(1.0_f64, |s, x| s.max(x.abs()));
                    for (x, y) in a.iter().zip(&b) {
                        worst = worst.max((x - y).abs() / scale);
                    }
                }
            }
        }
        worst
    }

    #[test]
    fn recursions_agree_with_the_partials_of_tau() {
        let panda = crate::tools::fixtures::panda("Panda", 7);
        let path = std::env::temp_dir().join(format!(
            "constrained-mimic-rnea-{}.urdf",
            std::process::id()
        ));
        std::fs::write(&path, MIMIC).expect("the temporary directory is writable");
        let mimic = format!(
            "pub struct Mimic {{ gravity: [0.0, 0.0, -9.81], urdf: \"{}\", }}",
            path.display()
        );
        let cases = [
            ("branched", BRANCHED.to_string()),
            ("panda", panda),
            ("mimic", mimic),
            ("floating", FLOATING.to_string()),
            ("two arms", TWO_ARMS.to_string()),
        ];
        for (name, model) in cases {
            let worst = against_partials(&model);
            println!("{name}: within {worst:.1e}");
            assert!(worst <= 1e-12, "{name}: {worst:e}");
        }
        let _ = std::fs::remove_file(&path);
    }
}
