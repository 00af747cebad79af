//! Kinematics of named frames and of the centre of mass, as expressions of
//! `q` (and `q̇`): what a controller reads (task-space placements,
//! Jacobians, velocities and acceleration biases), built from the world
//! frames of [`super::world_frames`] and differentiated exactly by
//! `crate::expr::diff`.
//!
//! Conventions are Pinocchio's `LOCAL_WORLD_ALIGNED`: a frame's velocity is
//! `[v; ω]`, the velocity of its origin and its angular velocity, both in
//! world axes, and `J` maps `q̇` to it. Where a joint is a quaternion the
//! columns are by the quaternion's rates (`q̇`, as everywhere in this
//! library), the rotation being `R(q/|q|)`, so a rate along `q` itself moves
//! nothing.

use super::joint::JointState;
use super::spatial::{self, Inertia, Spatial, M3, V3};
use super::{Described, Placement};
use crate::expr::diff::{AtRest, Differentiator};
use crate::expr::{Graph, Id, Sym};

/// One named frame's expressions.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The frame's name as written.
    pub name: String,
    /// `R`: the frame's axes in the world, as columns.
    pub rotation: M3,
    /// `p`: its origin in the world.
    pub position: V3,
    /// `J`, 6 × n, rows `[v; ω]` in world axes (`LOCAL_WORLD_ALIGNED`).
    pub jacobian: Vec<Vec<Id>>,
    /// `J q̇ = [ṗ; ω]`.
    pub velocity: Vec<Id>,
    /// `J̇ q̇ = [p̈; ω̇]` at `q̈ = 0`: the classical acceleration's bias.
    pub bias: Vec<Id>,
}

/// The centre of mass of every body, its Jacobian and velocity, and the
/// centroidal momentum.
#[derive(Clone, Debug)]
pub struct CenterOfMass {
    /// `c = Σ mᵢ cᵢ / Σ mᵢ`, world coordinates.
    pub position: V3,
    /// `∂c/∂q`, 3 × n.
    pub jacobian: Vec<Vec<Id>>,
    /// `ċ = (∂c/∂q) q̇`.
    pub velocity: V3,
    /// `A_G = ∂h_G/∂q̇`, 6 × n: the centroidal momentum matrix, rows
    /// `[linear; angular about c]` in world axes.
    pub centroidal_map: Vec<Vec<Id>>,
    /// `Ȧ_G q̇`: the rate of `h_G = A_G q̇` at `q̈ = 0`.
    pub centroidal_bias: Vec<Id>,
}

/// What the `frames` section asks for: each named frame, and the centre of
/// mass that comes with the section.
#[derive(Clone, Debug)]
pub struct Kinematics {
    /// The named frames, in the order written.
    pub frames: Vec<Frame>,
    /// The centre of mass; `None` where the bodies have no mass at all.
    pub center_of_mass: Option<CenterOfMass>,
}

/// The frame placed by `offset` in a body whose world frame is `body`.
pub fn frame(g: &mut Graph, name: String, body: &Placement, offset: &Placement, n: usize) -> Frame {
    let placed = body.then(g, offset);
    let rotation = placed.rotation.map(|row| spatial::hold3(g, row));
    let position = spatial::hold3(g, placed.translation);
    let mut partials = Differentiator::new();
    let mut jacobian: Vec<Vec<Id>> = (0..6).map(|_| Vec::with_capacity(n)).collect();
    for k in 0..n {
        let linear = position.map(|p| partials.partial(g, p, Sym::Coord(k)));
        let turned = rotation.map(|row| row.map(|r| partials.partial(g, r, Sym::Coord(k))));
        let angular = spin(g, &turned, &rotation);
        for (row, &e) in jacobian.iter_mut().zip(linear.iter().chain(&angular)) {
            row.push(e);
        }
    }
    let mut rate = AtRest::default();
    let linear = position.map(|p| rate.derivative(g, p));
    let turned = rotation.map(|row| row.map(|r| rate.derivative(g, r)));
    let angular = spin(g, &turned, &rotation);
    let velocity: Vec<Id> = linear
        .iter()
        .chain(&angular)
        .map(|&v| spatial::hold(g, v))
        .collect();
    // `q̇` is held by `AtRest`: the derivative of `J(q) q̇` along the motion
    // at `q̈ = 0` is `J̇ q̇`.
    let bias = velocity.iter().map(|&v| rate.derivative(g, v)).collect();
    Frame {
        name,
        rotation,
        position,
        jacobian,
        velocity,
        bias,
    }
}

/// `vee(Ṙ Rᵀ)`, the angular velocity in world axes of a frame turned by
/// `R` at the rate `Ṙ`, as the axial vector of `½ (Ṙ Rᵀ − R Ṙᵀ)`: `R` is
/// orthogonal for every `q`, so `Ṙ Rᵀ` is skew and this is exact.
fn spin(g: &mut Graph, rate: &M3, rotation: &M3) -> V3 {
    let m = spatial::mat_mul(g, rate, &spatial::transpose(rotation));
    let two = g.int(2);
    let mut axial = |i: usize, j: usize| {
        let d = g.sub(m[i][j], m[j][i]);
        g.div(d, two)
    };
    [axial(2, 1), axial(0, 2), axial(1, 0)]
}

/// Whether body `i` is welded to the world: no joint moves it (each body
/// from it to the root fixed to its parent).
fn welded(described: &[Described], i: usize) -> bool {
    let mut at = Some(i);
    // A tree: at most one step per body.
    for _ in 0..=described.len() {
        match at {
            None => return true,
            Some(k) if described[k].joint.is_some() => return false,
            Some(k) => at = described[k].parent,
        }
    }
    false
}

/// The centre of mass of the described bodies that move with some joint
/// (fixed ones included, those welded to the world not) in the world,
/// `Σ (mᵢ pᵢ + Rᵢ hᵢ) / Σ mᵢ` with `hᵢ = mᵢ cᵢ` in the body's axes, its
/// Jacobian `∂c/∂q`, its velocity and the centroidal momentum about it
/// ([`centroidal`]); `None` where that mass is the constant zero. The
/// bodies welded to the world are Pinocchio's universe, whose inertia its
/// `centerOfMass` leaves out: a fixed-base robot's base link is not part
/// of its centre of mass (a floating one's is, on its free joint).
pub fn center_of_mass(
    g: &mut Graph,
    described: &[Described],
    world: &[Placement],
    n: usize,
) -> Option<CenterOfMass> {
    let mut masses = Vec::new();
    let mut moments: Vec<V3> = Vec::new();
    for (i, (d, frame)) in described.iter().zip(world).enumerate() {
        if g.is_zero(d.inertia.mass) || welded(described, i) {
            continue;
        }
        let at_origin = spatial::scale(g, d.inertia.mass, frame.translation);
        let offset = spatial::mat_vec(g, &frame.rotation, d.inertia.first_moment);
        moments.push(spatial::add(g, at_origin, offset));
        masses.push(d.inertia.mass);
    }
    let total = g.add(&masses);
    if g.is_zero(total) {
        return None;
    }
    let position = [0, 1, 2].map(|i| {
        let terms: Vec<Id> = moments.iter().map(|m| m[i]).collect();
        let sum = g.add(&terms);
        let c = g.div(sum, total);
        spatial::hold(g, c)
    });
    let mut partials = Differentiator::new();
    let jacobian = position
        .iter()
        .map(|&c| {
            (0..n)
                .map(|k| partials.partial(g, c, Sym::Coord(k)))
                .collect()
        })
        .collect();
    let mut rate = AtRest::default();
    let velocity = position.map(|c| {
        let v = rate.derivative(g, c);
        spatial::hold(g, v)
    });
    let (centroidal_map, centroidal_bias) = centroidal(g, described, world, &position, n);
    Some(CenterOfMass {
        position,
        jacobian,
        velocity,
        centroidal_map,
        centroidal_bias,
    })
}

/// The centroidal map `A_G` and its bias `Ȧ_G q̇`, rows `[P; L_G]` in
/// world axes: the total linear momentum and the angular momentum about
/// the centre of mass `c`. With the bodies as the tree merges them (fixed
/// ones into the movable body they hang from), each body's composite
/// inertia `Iᶜ` (its own and its descendants') about the world's origin in
/// world axes, from their world frames; the column of a coordinate is
/// `Iᶜ S` for its joint's motion `S` carried to the world (Pinocchio's
/// `ccrba`), `[f; n − c × f]`. The bias is the rate of the momentum about
/// the world's origin at `q̈ = 0` without gravity, the force recursive
/// Newton–Euler passes to the world ([`super::recursion::momentum_rate`]),
/// moved to `c` the same way (`ċ × P = m ċ × ċ` vanishes).
fn centroidal(
    g: &mut Graph,
    described: &[Described],
    world: &[Placement],
    c: &V3,
    n: usize,
) -> (Vec<Vec<Id>>, Vec<Id>) {
    let z = spatial::zero(g);
    let tree = super::Tree::new(g, described, z);
    let frames: Vec<Placement> = described
        .iter()
        .zip(world)
        .filter(|(d, _)| d.joint.is_some())
        .map(|(_, w)| *w)
        .collect();
    let mut composite: Vec<Inertia> = tree
        .bodies
        .iter()
        .zip(&frames)
        .map(|(b, f)| b.inertia.to_parent(g, &f.rotation, f.translation).held(g))
        .collect();
    for (i, body) in tree.bodies.iter().enumerate().rev() {
        if let Some(p) = body.parent {
            composite[p] = composite[p].add(g, &composite[i]).held(g);
        }
    }
    let zero = g.int(0);
    let mut map = vec![vec![zero; n]; 6];
    for ((body, frame), inertia) in tree.bodies.iter().zip(&frames).zip(&composite) {
        let js = JointState::new(g, body.joint);
        for (k, s) in js.columns(g) {
            let angular = spatial::mat_vec(g, &frame.rotation, s.angular);
            let linear = spatial::mat_vec(g, &frame.rotation, s.linear);
            let shift = spatial::cross(g, frame.translation, angular);
            let linear = spatial::add(g, linear, shift);
            let momentum = inertia.apply(g, Spatial { angular, linear });
            let column = about_center(g, momentum, c);
            for (row, e) in map.iter_mut().zip(column) {
                row[k] = if g.is_zero(row[k]) {
                    e
                } else {
                    g.add2(row[k], e)
                };
            }
        }
    }
    let rate = super::recursion::momentum_rate(g, &tree, n);
    (map, about_center(g, rate, c).to_vec())
}

/// `[f; n − c × f]`: a force (or momentum) `[n; f]` about the world's
/// origin, as linear and angular parts about `c`.
fn about_center(g: &mut Graph, at_origin: Spatial, c: &V3) -> [Id; 6] {
    let f = at_origin.linear;
    let shift = spatial::cross(g, *c, f);
    let l = spatial::sub(g, at_origin.angular, shift);
    [f[0], f[1], f[2], l[0], l[1], l[2]]
}
