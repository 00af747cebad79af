//! Kinematics of named frames and of the centre of mass, as expressions of
//! `q` (and `q̇`): what a controller reads (task-space placements,
//! Jacobians, velocities and acceleration biases), built from the world
//! frames of [`super::world_frames`]: Jacobians column by column from the
//! joints' motion subspaces carried to the world (as Pinocchio builds them,
//! not by differentiating placements, which costs several times more),
//! velocities as `J q̇`, and the biases `J̇ q̇` as the point's classical
//! acceleration at `q̈ = 0`, carried joint by joint from the root
//! (`path_motion`; Pinocchio's `getFrameClassicalAcceleration`), not by
//! differentiating `J q̇`'s expressions, which costs half as much again or
//! more.
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
use crate::expr::diff::AtRest;
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

/// The frame placed by `offset` in the described body `body`, whose world
/// frame is `world[body]`.
pub fn frame(
    g: &mut Graph,
    name: String,
    (described, world): (&[Described], &[Placement]),
    body: usize,
    offset: &Placement,
    n: usize,
) -> Frame {
    let placed = world[body].then(g, offset);
    let rotation = placed.rotation.map(|row| spatial::hold3(g, row));
    let position = spatial::hold3(g, placed.translation);
    let jacobian = point_jacobian(g, (described, world), body, position, n);
    let velocity = times_rates(g, &jacobian);
    // `J̇ q̇`: the point's classical acceleration at `q̈ = 0`,
    // `ö + ω̇ × r + ω × (ω × r)`, and `ω̇`.
    let motion = path_motion(g, (described, world), body, n);
    let r = spatial::sub(g, position, world[body].translation);
    let turned = spatial::cross(g, motion.alpha, r);
    let spun = spatial::cross(g, motion.omega, r);
    let spun = spatial::cross(g, motion.omega, spun);
    let linear = spatial::add(g, motion.acceleration, turned);
    let linear = spatial::add(g, linear, spun);
    let bias = linear.iter().chain(&motion.alpha).copied().collect();
    Frame {
        name,
        rotation,
        position,
        jacobian,
        velocity,
        bias,
    }
}

/// A body's angular velocity in world axes, `ω = J_ω q̇`, with its
/// Jacobian and its rate at `q̈ = 0`, `J̇_ω q̇`: what an orientation lock's
/// rows are made of (`crate::model::rotation`).
#[derive(Clone, Debug)]
pub struct AngularMotion {
    /// `J_ω`, 3 × n: each joint's angular column `R s_ω` on the body's path.
    pub jacobian: [Vec<Id>; 3],
    /// `ω = J_ω q̇`, held.
    pub velocity: V3,
    /// `J̇_ω q̇`, held.
    pub bias: V3,
}

/// [`AngularMotion`] of the described body `body`, whose world frames are
/// `world` ([`path_motion`]).
pub fn angular_motion(
    g: &mut Graph,
    (described, world): (&[Described], &[Placement]),
    body: usize,
    n: usize,
) -> AngularMotion {
    let m = path_motion(g, (described, world), body, n);
    AngularMotion {
        jacobian: m.jacobian,
        velocity: m.omega,
        bias: m.alpha,
    }
}

/// A body's motion at `q̈ = 0` in world axes, from [`path_motion`].
struct PathMotion {
    /// `J_ω`, 3 × n.
    jacobian: [Vec<Id>; 3],
    /// `ω`, held.
    omega: V3,
    /// `ω̇` at `q̈ = 0`, held.
    alpha: V3,
    /// The classical acceleration of the body's origin at `q̈ = 0`, held.
    acceleration: V3,
}

/// The motion of the described body `body` at `q̈ = 0`, joint by joint
/// from the root, in world axes. `ω` sums each joint's `R s_ω q̇`. A column
/// constant in its body (revolute, prismatic, helical, a mimic of one)
/// turns with the body but not about itself, so its rate is `ω_λ × R s_ω
/// q̇`, the parent's `ω_λ`. A quaternion's, `R_F k E q̇` ([`world_columns`]),
/// turns with its joint frame and scales with `k = 2/|q|²`:
/// `ω_λ × ω_J − k (qᵀq̇) ω_J` (`E(q̇) q̇ = 0`). Any other column's rate is
/// its derivative along the motion. Each origin, `d` from its parent's and
/// sliding at `u = R s_v q̇`, accelerates as
/// `ö = ö_λ + ω̇_λ × d + ω_λ × (ω_λ × d) + 2 ω_λ × u`: no partials of the
/// world frames.
fn path_motion(
    g: &mut Graph,
    (described, world): (&[Described], &[Placement]),
    body: usize,
    n: usize,
) -> PathMotion {
    let zero = g.int(0);
    let mut jacobian = [0, 1, 2].map(|_| vec![zero; n]);
    let (mut omega, mut alpha, mut acceleration) =
        (spatial::zero(g), spatial::zero(g), spatial::zero(g));
    let mut origin = spatial::zero(g);
    let mut at_rest = AtRest::default();
    let mut from_root: Vec<usize> = path(described, body).collect();
    from_root.reverse();
    for i in from_root {
        let here = world[i].translation;
        let d = spatial::sub(g, here, origin);
        let turned = spatial::cross(g, alpha, d);
        let spun = spatial::cross(g, omega, d);
        let spun = spatial::cross(g, omega, spun);
        let carried = spatial::add(g, acceleration, turned);
        acceleration = spatial::add(g, carried, spun);
        origin = here;
        if let Some(joint) = described[i].joint {
            let (mut own, mut slide) = (spatial::zero(g), spatial::zero(g));
            for (k, (linear, angular)) in world_columns(g, (described, world), i, joint) {
                accumulate(g, &mut jacobian, k, angular.iter());
                let rate = g.sym(Sym::Vel(k));
                let part = spatial::scale(g, rate, angular);
                own = spatial::add(g, own, part);
                let part = spatial::scale(g, rate, linear);
                slide = spatial::add(g, slide, part);
            }
            let own = spatial::hold3(g, own);
            let coriolis = spatial::cross(g, omega, slide);
            let two = g.int(2);
            let coriolis = spatial::scale(g, two, coriolis);
            acceleration = spatial::add(g, acceleration, coriolis);
            let js = JointState::new(g, joint);
            let turn = match js.quaternion {
                None => spatial::cross(g, omega, own),
                // `d/dt (k E q̇) = k̇ E q̇` (`E(q̇) q̇ = 0`), `k̇ = −k² qᵀq̇`.
                Some((q, _)) if joint.mimic.is_none() => {
                    let carried = spatial::cross(g, omega, own);
                    let rates = js_rates(g, joint.coordinate);
                    let scaled = super::free::subspace_rate(g, q, rates, own);
                    spatial::add(g, carried, scaled)
                }
                Some(_) => own.map(|e| at_rest.derivative(g, e)),
            };
            let sum = spatial::add(g, alpha, turn);
            alpha = spatial::hold3(g, sum);
            let sum = spatial::add(g, omega, own);
            omega = spatial::hold3(g, sum);
        }
        acceleration = spatial::hold3(g, acceleration);
    }
    PathMotion {
        jacobian,
        omega,
        alpha,
        acceleration,
    }
}

/// A quaternion's four rates from its first coordinate `c`.
fn js_rates(g: &mut Graph, c: usize) -> [Id; 4] {
    [0, 1, 2, 3].map(|m| g.sym(Sym::Vel(c + m)))
}

/// `J q̇` over `J`'s structural nonzeros, each entry held.
fn times_rates(g: &mut Graph, jacobian: &[Vec<Id>]) -> Vec<Id> {
    jacobian
        .iter()
        .map(|row| {
            let mut terms = Vec::with_capacity(row.len());
            for (k, &e) in row.iter().enumerate() {
                if !g.is_zero(e) {
                    let rate = g.sym(Sym::Vel(k));
                    terms.push(g.mul2(e, rate));
                }
            }
            let sum = g.add(&terms);
            spatial::hold(g, sum)
        })
        .collect()
}

/// `J` of the point `p` fixed in the described body `body`, by the motion
/// subspaces of the joints from it to the root (Pinocchio's
/// `computeJointJacobians`): each coordinate's column `S` carried to world
/// axes at its body's origin, `ω = R s_ω`, and moved to `p`,
/// `v = R s_v + ω × (p − o)`. Columns of coordinates off that path are
/// zero; a mimic's adds to the column of the joint it follows.
fn point_jacobian(
    g: &mut Graph,
    (described, world): (&[Described], &[Placement]),
    body: usize,
    p: V3,
    n: usize,
) -> Vec<Vec<Id>> {
    let zero = g.int(0);
    let mut jacobian = vec![vec![zero; n]; 6];
    for i in path(described, body) {
        let (Some(joint), frame) = (described[i].joint, &world[i]) else {
            continue;
        };
        let arm = spatial::sub(g, p, frame.translation);
        for (k, (linear, angular)) in world_columns(g, (described, world), i, joint) {
            let turn = spatial::cross(g, angular, arm);
            let linear = spatial::add(g, linear, turn);
            accumulate(g, &mut jacobian, k, linear.iter().chain(&angular));
        }
    }
    jacobian
}

/// The columns of body `i`'s joint `joint` in world axes at the body's
/// origin, `(R s_v, R s_ω)` by coordinate ([`world_column`]); a
/// quaternion's (no mimic) as `R_F k Eₘ` with `R_F` its joint frame's
/// axes ([`super::free::parent_columns`]), without the products of
/// `R(q/|q|)`.
fn world_columns(
    g: &mut Graph,
    (described, world): (&[Described], &[Placement]),
    i: usize,
    joint: super::Joint,
) -> Vec<(usize, (V3, V3))> {
    let js = JointState::new(g, joint);
    match js.quaternion {
        Some((q, _)) if joint.mimic.is_none() => {
            let placement = &described[i].placement;
            let frame = match described[i].parent {
                Some(p) => spatial::mat_mul(g, &world[p].rotation, &placement.rotation),
                None => placement.rotation,
            };
            let zero = spatial::zero(g);
            let own = super::free::parent_columns(g, q);
            (0..4)
                .map(|m| {
                    let angular = spatial::mat_vec(g, &frame, own[m]);
                    (joint.coordinate + m, (zero, angular))
                })
                .collect()
        }
        _ => js
            .columns(g)
            .into_iter()
            .map(|(k, s)| (k, world_column(g, &world[i], s)))
            .collect(),
    }
}

/// The described bodies from `body` to the root, `body` first (a tree: at
/// most one step per body).
fn path(described: &[Described], body: usize) -> impl Iterator<Item = usize> + '_ {
    std::iter::successors(Some(body), |&i| described[i].parent).take(described.len())
}

/// A motion subspace column `s` of a body's joint (in its axes, at its
/// origin) in world axes: `(R s_v, R s_ω)`.
pub(super) fn world_column(g: &mut Graph, frame: &Placement, s: Spatial) -> (V3, V3) {
    let linear = spatial::mat_vec(g, &frame.rotation, s.linear);
    let angular = spatial::mat_vec(g, &frame.rotation, s.angular);
    (linear, angular)
}

/// Adds `values` to column `k` of `rows`, row by row.
fn accumulate<'v>(
    g: &mut Graph,
    rows: &mut [Vec<Id>],
    k: usize,
    values: impl Iterator<Item = &'v Id>,
) {
    for (row, &e) in rows.iter_mut().zip(values) {
        row[k] = if g.is_zero(row[k]) {
            e
        } else {
            g.add2(row[k], e)
        };
    }
}

/// The bodies of the tree the described bodies merge into (fixed ones
/// into the movable body they hang from, those welded to the world left
/// out), their world frames, and each one's composite inertia (its own and
/// its descendants', about its origin in its axes) with its joint's motion
/// columns there.
struct Composites {
    tree: super::Tree,
    frames: Vec<Placement>,
    bodies: Vec<(Inertia, Vec<(usize, Spatial)>)>,
}

impl Composites {
    fn new(g: &mut Graph, described: &[Described], world: &[Placement]) -> Composites {
        let z = spatial::zero(g);
        let tree = super::Tree::new(g, described, z);
        // The composites are in each body's own axes, which a turn folded
        // into its joint's angle leaves as described.
        let tree = super::turn::folded_in_place(g, &tree).unwrap_or(tree);
        let frames = described
            .iter()
            .zip(world)
            .filter(|(d, _)| d.joint.is_some())
            .map(|(_, w)| *w)
            .collect();
        let bodies = super::recursion::composite_columns(g, &tree);
        Composites {
            tree,
            frames,
            bodies,
        }
    }
}

/// The centre of mass of the described bodies that move with some joint
/// (fixed ones included, those welded to the world not) in the world,
/// `Σ (mᵢ pᵢ + Rᵢ hᵢ) / Σ mᵢ` with `hᵢ = mᵢ cᵢ` in the body's axes, its
/// Jacobian `∂c/∂q`, its velocity and the centroidal momentum about it
/// ([`centroidal`]); `None` where that mass is the constant zero. The
/// bodies welded to the world are Pinocchio's universe, whose inertia its
/// `centerOfMass` leaves out: a fixed-base robot's base link is not part
/// of its centre of mass (a floating one's is, on its free joint). All of
/// it comes from the composite inertias, summed in each body's own frame
/// through its joint's sparse transform: `c` from the roots' composites
/// ([`composite_center`]), a column of `∂c/∂q` from its body's
/// ([`center_of_mass_jacobian`]); no body's first moment is carried to
/// the world.
pub fn center_of_mass(
    g: &mut Graph,
    described: &[Described],
    world: &[Placement],
    n: usize,
) -> Option<CenterOfMass> {
    let composites = Composites::new(g, described, world);
    let (position, total) = composite_center(g, &composites)?;
    let jacobian = center_of_mass_jacobian(g, &composites, total, n);
    let velocity = times_rates(g, &jacobian);
    let velocity = [velocity[0], velocity[1], velocity[2]];
    let (centroidal_map, centroidal_bias) = centroidal(g, &composites, &position, n);
    Some(CenterOfMass {
        position,
        jacobian,
        velocity,
        centroidal_map,
        centroidal_bias,
    })
}

/// `∂c/∂q` by subtrees (Pinocchio's `jacobianCenterOfMass`): a coordinate
/// of the joint of body `j` moves `j`'s subtree rigidly, so with `(m_j,
/// h_j)` the subtree's mass and first moment about `j`'s origin in `j`'s
/// axes (its composite inertia's) and `(v, ω)` the coordinate's motion
/// column there, its column is `R_j (m_j v + ω × h_j) / m`. A revolute
/// joint's `ω` is its axis, constant in the body's axes (a coordinate axis
/// turns the cross product into a permutation), and the rotation to the
/// world costs one column of `R_j` per nonzero of the local column.
fn center_of_mass_jacobian(
    g: &mut Graph,
    composites: &Composites,
    total: Id,
    n: usize,
) -> Vec<Vec<Id>> {
    let zero = g.int(0);
    let one = g.int(1);
    let inverse = g.div(one, total);
    let inverse = spatial::hold(g, inverse);
    let mut jacobian = vec![vec![zero; n]; 3];
    for ((inertia, columns), frame) in composites.bodies.iter().zip(&composites.frames) {
        if g.is_zero(inertia.mass) {
            continue;
        }
        // The subtree's share of the whole: `m_j / m` and `h_j / m`.
        let share = g.mul2(inertia.mass, inverse);
        let moment = spatial::scale(g, inverse, inertia.first_moment);
        for &(k, s) in columns {
            let carried = spatial::scale(g, share, s.linear);
            let turned = spatial::cross(g, s.angular, moment);
            let local = spatial::add(g, carried, turned);
            let column = spatial::mat_vec(g, &frame.rotation, local);
            accumulate(g, &mut jacobian, k, column.iter());
        }
    }
    jacobian
}

/// The centroidal map `A_G` and its bias `Ȧ_G q̇`, rows `[P; L_G]` in
/// world axes: the total linear momentum and the angular momentum about
/// the centre of mass `c`. With the bodies as the tree merges them (fixed
/// ones into the movable body they hang from), each body's composite
/// inertia `Iᶜ` (its own and its descendants') in its own frame, from the
/// composite-rigid-body pass through the joints' sparse transforms; the
/// column of a coordinate is the momentum `[n; f] = Iᶜ S` of its joint's
/// motion `S`, carried to world axes and about `c`: `[R f; R n + (o − c) ×
/// R f]` with `(R, o)` the body's world frame (Pinocchio's `ccrba` forms
/// `Iᶜ` in world axes instead: a dense rotation per body), `c` being the
/// centre of mass the same composites give ([`composite_center`]). The
/// bias is the rate of the momentum about the world's origin at `q̈ = 0`
/// without gravity, the force recursive Newton–Euler passes to the world
/// ([`super::recursion::momentum_rate`]), moved to `c` the same way
/// (`ċ × P = m ċ × ċ` vanishes).
fn centroidal(g: &mut Graph, composites: &Composites, c: &V3, n: usize) -> (Vec<Vec<Id>>, Vec<Id>) {
    let zero = g.int(0);
    let mut map = vec![vec![zero; n]; 6];
    for ((inertia, columns), frame) in composites.bodies.iter().zip(&composites.frames) {
        let lever = spatial::sub(g, frame.translation, *c);
        for &(k, s) in columns {
            // The subtree's momentum in the body's frame, then in world
            // axes with its moment taken about `c`.
            let momentum = inertia.apply(g, s);
            let linear = spatial::mat_vec(g, &frame.rotation, momentum.linear);
            let moment = spatial::mat_vec(g, &frame.rotation, momentum.angular);
            let shift = spatial::cross(g, lever, linear);
            let angular = spatial::add(g, moment, shift);
            accumulate(g, &mut map, k, linear.iter().chain(&angular));
        }
    }
    // The rate does not depend on the bodies' frames: turned and slid
    // where that saves products ([`super::slide::reframed`]), it costs
    // fewer operations.
    let slid = super::slide::reframed(g, &composites.tree);
    let rate = super::recursion::momentum_rate(g, slid.as_ref().unwrap_or(&composites.tree), n);
    (map, about_center(g, rate, c).to_vec())
}

/// The centre of mass from the composite inertias of the tree's roots
/// (every moving body is in one root's subtree): `Σ (mᵣ oᵣ + Rᵣ hᵣ) / Σ mᵣ`
/// over the roots `r` in their world frames `(Rᵣ, oᵣ)`, a few bodies'
/// products where the first moments of every body cost one each; and the
/// mass `Σ mᵣ`. `None` where that mass is the constant zero.
fn composite_center(g: &mut Graph, composites: &Composites) -> Option<(V3, Id)> {
    let Composites {
        tree,
        frames,
        bodies,
    } = composites;
    let roots: Vec<usize> = (0..tree.bodies.len())
        .filter(|&i| tree.bodies[i].parent.is_none())
        .collect();
    let masses: Vec<Id> = roots.iter().map(|&r| bodies[r].0.mass).collect();
    let total = g.add(&masses);
    if g.is_zero(total) {
        return None;
    }
    let moments: Vec<V3> = roots
        .iter()
        .map(|&r| {
            let (inertia, frame) = (&bodies[r].0, &frames[r]);
            let at_origin = spatial::scale(g, inertia.mass, frame.translation);
            let offset = spatial::mat_vec(g, &frame.rotation, inertia.first_moment);
            spatial::add(g, at_origin, offset)
        })
        .collect();
    let center = [0, 1, 2].map(|k| {
        let terms: Vec<Id> = moments.iter().map(|m| m[k]).collect();
        let sum = g.add(&terms);
        let c = g.div(sum, total);
        spatial::hold(g, c)
    });
    Some((center, total))
}

/// `[f; n − c × f]`: a force (or momentum) `[n; f]` about the world's
/// origin, as linear and angular parts about `c`.
fn about_center(g: &mut Graph, at_origin: Spatial, c: &V3) -> [Id; 6] {
    let f = at_origin.linear;
    let shift = spatial::cross(g, *c, f);
    let l = spatial::sub(g, at_origin.angular, shift);
    [f[0], f[1], f[2], l[0], l[1], l[2]]
}
