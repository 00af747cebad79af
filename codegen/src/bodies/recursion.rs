//! The recursive algorithms on a [`Tree`], built on expressions
//! (Featherstone ch. 5–6, spatial_v2's `ID.m` and `HandC.m`):
//! - outward, each body's velocity and acceleration from its parent's
//!   (`vᵢ = Xᵢ v_λ + Sᵢ q̇ᵢ`, `aᵢ = Xᵢ a_λ + Sᵢ q̈ᵢ + vᵢ × Sᵢ q̇ᵢ`, gravity as
//!   the base's acceleration `a₀ = −g`);
//! - inward, the forces (`fᵢ = Iᵢ aᵢ + vᵢ ×* Iᵢ vᵢ`, `τᵢ = Sᵢᵀ fᵢ`,
//!   `f_λ += Xᵢᵀ fᵢ`): recursive Newton–Euler;
//! - inward, the composite inertias (`I_λ += Xᵢᵀ Iᵢ Xᵢ`) and `Mᵢⱼ = Sⱼᵀ ⱼXᵢ* Iᵢ Sᵢ`:
//!   the composite-rigid-body algorithm.
//!
//! A transform `Xᵢ` is applied in two steps, the constant placement and
//! then the joint's own motion (a rotation about, or a translation along,
//! its axis, or a quaternion's rotation), so that only the second involves
//! `qᵢ`. A quaternion joint has four columns in `Sᵢ` ([`super::free`]).

use super::joint::{JointKind, JointState};
use super::spatial::accumulate;
use super::spatial::{self, Center, Inertia, Spatial};
use super::{Body, Dynamics, Trace, Tree};
use crate::expr::{Graph, Id, Sym};

pub(super) fn joint_state(g: &mut Graph, body: &Body) -> JointState {
    JointState::new(g, body.joint)
}

/// `Xᵢ m`: a motion vector of the parent's frame in the body's frame.
fn motion_to_child(g: &mut Graph, body: &Body, js: JointState, m: Spatial) -> Spatial {
    let p = &body.placement;
    // The joint frame: ω' = Rᵀ ω, v' = Rᵀ (v + ω × p). Through a rotation
    // that mixes components, the sums are held on either side (see
    // [`spatial::mixes`]).
    let mixes = spatial::mixes(g, &p.rotation);
    let w = spatial::mat_t_vec(g, &p.rotation, m.angular);
    let shifted = spatial::cross(g, m.angular, p.translation);
    let v = spatial::add(g, m.linear, shifted);
    let (w, v) = if mixes {
        let v = spatial::hold3(g, v);
        let v = spatial::mat_t_vec(g, &p.rotation, v);
        (spatial::hold3(g, w), spatial::hold3(g, v))
    } else {
        (w, spatial::mat_t_vec(g, &p.rotation, v))
    };
    // Then the joint's own: v'' = R_Jᵀ (v' + ω' × p_J).
    let v = match js.slide(g) {
        Some(offset) => {
            let shifted = spatial::cross(g, w, offset);
            spatial::add(g, v, shifted)
        }
        None => v,
    };
    js.to_child(g, w, v)
}

/// `Xᵢᵀ f`: a force vector of the body's frame in the parent's frame.
fn force_to_parent(g: &mut Graph, body: &Body, js: JointState, f: Spatial) -> Spatial {
    let (n, force) = js.to_parent(g, f.angular, f.linear);
    let n = match js.slide(g) {
        Some(offset) => {
            let moment = spatial::cross(g, offset, force);
            spatial::add(g, n, moment)
        }
        None => n,
    };
    let p = &body.placement;
    let (n, force) = if spatial::mixes(g, &p.rotation) {
        // Held on either side of the rotation (see [`spatial::mixes`]).
        let (n, force) = (spatial::hold3(g, n), spatial::hold3(g, force));
        let force = spatial::mat_vec(g, &p.rotation, force);
        let n = spatial::mat_vec(g, &p.rotation, n);
        (n, spatial::hold3(g, force))
    } else {
        let force = spatial::mat_vec(g, &p.rotation, force);
        (spatial::mat_vec(g, &p.rotation, n), force)
    };
    let moment = spatial::cross(g, p.translation, force);
    Spatial {
        angular: spatial::add(g, n, moment),
        linear: force,
    }
}

/// `Sᵢ`: the joint's motion subspace, one motion vector per coordinate.
fn subspace(g: &mut Graph, js: JointState) -> Vec<(usize, Spatial)> {
    js.columns(g)
}

/// `Σₖ Sₖ xₖ` for the joint's coordinates' velocities or accelerations.
pub(super) fn joint_motion(
    g: &mut Graph,
    columns: &[(usize, Spatial)],
    sym: fn(usize) -> Sym,
) -> Spatial {
    let mut sum = Spatial::zero(g);
    for &(c, s) in columns {
        let x = g.sym(sym(c));
        let sx = s.scale(g, x);
        sum = sum.add(g, sx);
    }
    sum
}

/// What the outward pass includes.
#[derive(Clone, Copy)]
struct Terms {
    velocities: bool,
    accelerations: bool,
    gravity: bool,
}

/// One pass of recursive Newton–Euler: the generalized force of each
/// coordinate (0 where no body moves it), and each body's velocity,
/// acceleration and force (the children's included).
struct Pass {
    tau: Vec<Id>,
    v: Vec<Spatial>,
    a: Vec<Spatial>,
    f: Vec<Spatial>,
    /// Each body's motion at its centre of mass, where its force was
    /// taken there.
    centers: Vec<Option<Center>>,
}

/// Recursive Newton–Euler.
fn newton_euler(g: &mut Graph, tree: &Tree, n: usize, terms: Terms) -> Pass {
    let states: Vec<JointState> = tree.bodies.iter().map(|b| joint_state(g, b)).collect();
    let base_acceleration = if terms.gravity {
        let z = spatial::zero(g);
        Spatial {
            angular: z,
            linear: spatial::neg(g, tree.gravity),
        }
    } else {
        Spatial::zero(g)
    };
    let base_velocity = Spatial::zero(g);
    let mut v: Vec<Spatial> = Vec::with_capacity(tree.bodies.len());
    let mut f: Vec<Spatial> = Vec::with_capacity(tree.bodies.len());
    let mut a: Vec<Spatial> = Vec::with_capacity(tree.bodies.len());
    let mut centers = Vec::with_capacity(tree.bodies.len());
    for (i, body) in tree.bodies.iter().enumerate() {
        let parent = match body.parent {
            Some(p) => (v[p], a[p]),
            None => (base_velocity, base_acceleration),
        };
        let (vi, ai) = body_motion(g, body, states[i], parent, terms);
        v.push(vi);
        a.push(ai);
        let (force, center) = body.inertia.force(g, vi, a[i]);
        f.push(force.held(g));
        centers.push(center);
    }
    let zero = g.int(0);
    let mut tau = vec![zero; n];
    for (i, body) in tree.bodies.iter().enumerate().rev() {
        for (c, s) in subspace(g, states[i]) {
            let part = s.dot(g, f[i]);
            accumulate(g, &mut tau[c], part);
        }
        if let Some(p) = body.parent {
            let up = force_to_parent(g, body, states[i], f[i]);
            f[p] = f[p].add(g, up).held(g);
        }
    }
    Pass {
        tau,
        v,
        a,
        f,
        centers,
    }
}

/// A body's velocity `vᵢ = ⁱX_λ v_λ + Sᵢ q̇ᵢ` and acceleration `aᵢ = ⁱX_λ
/// a_λ + vᵢ × Sᵢ q̇ᵢ (+ Ṡᵢ q̇ᵢ) + Sᵢ q̈ᵢ` from its parent's, each held, with
/// the terms `terms` asks for.
fn body_motion(
    g: &mut Graph,
    body: &Body,
    state: JointState,
    (vp, ap): (Spatial, Spatial),
    terms: Terms,
) -> (Spatial, Spatial) {
    let s = subspace(g, state);
    let vi = motion_to_child(g, body, state, vp);
    let (vi, ai) = if terms.velocities {
        let sq = joint_motion(g, &s, Sym::Vel);
        let vi = vi.add(g, sq).held(g);
        let coriolis = vi.cross_motion(g, sq);
        let coriolis = match state.column_rate(g, sq.angular) {
            // Sᵢ varies with q: Σ Ṡₖ q̇ₖ as well.
            Some(rate) => {
                let angular = spatial::add(g, coriolis.angular, rate);
                Spatial {
                    angular,
                    ..coriolis
                }
            }
            None => coriolis,
        };
        let ai = motion_to_child(g, body, state, ap);
        (vi, ai.add(g, coriolis))
    } else {
        (vi, motion_to_child(g, body, state, ap))
    };
    let mut ai = ai.held(g);
    if terms.accelerations {
        let sq = joint_motion(g, &s, Sym::Accel);
        ai = ai.add(g, sq).held(g);
    }
    (vi, ai)
}

/// `M(q) q̈` by recursive Newton–Euler without velocities or gravity, `q̈`
/// as `Sym::Accel`: O(n) expressions where `M`'s entries are O(n²), whose
/// derivatives the Jacobian of `q̈` contracts instead of `∂M`
/// (`crate::equations::tangent`).
pub fn mass_times(g: &mut Graph, bodies: &[Body], n: usize) -> Vec<Id> {
    let zero = spatial::zero(g);
    let tree = Tree {
        bodies: bodies.to_vec(),
        gravity: zero,
    };
    let terms = Terms {
        velocities: false,
        accelerations: true,
        gravity: false,
    };
    newton_euler(g, &tree, n, terms).tau
}

/// The rate of the bodies' total momentum about the world's origin, in
/// world axes (`[n; f]`), at `q̈ = 0` without gravity: the force each root
/// passes to the world in recursive Newton–Euler, summed. `Ȧ q̇` of the
/// momentum `A q̇` (`super::kinematics`).
pub fn momentum_rate(g: &mut Graph, tree: &Tree, n: usize) -> Spatial {
    let terms = Terms {
        velocities: true,
        accelerations: false,
        gravity: false,
    };
    let pass = newton_euler(g, tree, n, terms);
    let mut total = Spatial::zero(g);
    for (i, body) in tree.bodies.iter().enumerate() {
        if body.parent.is_none() {
            let js = joint_state(g, body);
            let out = force_to_parent(g, body, js, pass.f[i]);
            total = total.add(g, out);
        }
    }
    total.held(g)
}

/// The inertia of a body about its parent's origin, in its parent's axes.
fn inertia_to_parent(g: &mut Graph, body: &Body, js: JointState, inertia: &Inertia) -> Inertia {
    let turned = js.turn_inertia(g, inertia);
    let in_joint = match js.slide(g) {
        Some(offset) => {
            let identity = spatial::identity(g);
            turned.to_parent(g, &identity, offset)
        }
        None => turned,
    };
    let p = &body.placement;
    let in_joint = if spatial::mixes(g, &p.rotation) {
        // Held before the rotation (see [`spatial::mixes`]).
        in_joint.held(g)
    } else {
        in_joint
    };
    in_joint.to_parent(g, &p.rotation, p.translation)
}

/// Each body's composite inertia (its own and its descendants'), about
/// its origin in its axes: the backward pass of the composite-rigid-body
/// algorithm, through the joints' own transforms.
pub(super) fn composites(g: &mut Graph, tree: &Tree, states: &[JointState]) -> Vec<Inertia> {
    let mut composite: Vec<Inertia> = tree.bodies.iter().map(|b| b.inertia).collect();
    for (i, body) in tree.bodies.iter().enumerate().rev() {
        if let Some(p) = body.parent {
            let moved = inertia_to_parent(g, body, states[i], &composite[i]);
            composite[p] = composite[p].add(g, &moved).held(g);
        }
    }
    composite
}

/// Each body's composite inertia in its own frame, and its joint's motion
/// columns there: what the centroidal map (`super::kinematics`) carries to
/// the world.
pub fn composite_columns(g: &mut Graph, tree: &Tree) -> Vec<(Inertia, Vec<(usize, Spatial)>)> {
    let states: Vec<JointState> = tree.bodies.iter().map(|b| joint_state(g, b)).collect();
    let composite = composites(g, tree, &states);
    composite
        .into_iter()
        .zip(&states)
        .map(|(c, &js)| (c, subspace(g, js)))
        .collect()
}

/// The composite-rigid-body algorithm: `M(q)`, n × n, each body's
/// composite inertia, and whether `M` is the one formed in world axes
/// (`super::world_mass`, where that costs fewer operations). With
/// `velocity`, each quaternion joint's columns are those of
/// [`super::free::velocity_subspace`], and the matrix is `Tᵀ M T`
/// ([`super::free`]).
fn composite_rigid_body(
    g: &mut Graph,
    tree: &Tree,
    n: usize,
    velocity: bool,
) -> (Vec<Vec<Id>>, Vec<Inertia>, bool) {
    let states: Vec<JointState> = tree.bodies.iter().map(|b| joint_state(g, b)).collect();
    let composite = composites(g, tree, &states);
    let columns = mass_columns(g, tree, &states, velocity);
    let local = local_mass(g, tree, (&states, &composite), &columns, n);
    match super::world_mass::cheaper(g, tree, &states, &columns, &local) {
        Some(world) => (world, composite, true),
        None => (local, composite, false),
    }
}

/// Each body's joint columns in its own axes: its joint's, or with
/// `velocity` those of the velocity form ([`velocity_columns`]).
pub(super) fn mass_columns(
    g: &mut Graph,
    tree: &Tree,
    states: &[JointState],
    velocity: bool,
) -> Vec<Vec<(usize, Spatial)>> {
    if velocity {
        velocity_columns(g, tree, states)
    } else {
        states.iter().map(|&js| subspace(g, js)).collect()
    }
}

/// `M` in the bodies' own axes: `Mᵢᵢ = Sᵢᵀ Iᶜᵢ Sᵢ` and, carrying `Iᶜᵢ Sᵢ`
/// through each joint towards the root, `Mⱼᵢ = Sⱼᵀ ʲXᵢ* Iᶜᵢ Sᵢ` for each
/// ancestor `j`.
pub(super) fn local_mass(
    g: &mut Graph,
    tree: &Tree,
    (states, composite): (&[JointState], &[Inertia]),
    columns: &[Vec<(usize, Spatial)>],
    n: usize,
) -> Vec<Vec<Id>> {
    let zero = g.int(0);
    let mut m = vec![vec![zero; n]; n];
    for (i, own) in columns.iter().enumerate() {
        for &(ci, s) in own {
            let mut force = composite[i].apply(g, s).held(g);
            for &(ck, sk) in own {
                let mik = sk.dot(g, force);
                accumulate(g, &mut m[ci][ck], mik);
            }
            let mut j = i;
            while let Some(p) = tree.bodies[j].parent {
                force = force_to_parent(g, &tree.bodies[j], states[j], force).held(g);
                j = p;
                for &(cj, sj) in &columns[j] {
                    let mij = sj.dot(g, force);
                    // Two bodies: both Mᵢⱼ and Mⱼᵢ of the joints' matrix,
                    // the same entry when a mimic shares its coordinate.
                    accumulate(g, &mut m[ci][cj], mij);
                    accumulate(g, &mut m[cj][ci], mij);
                }
            }
        }
    }
    m
}

/// Each body's columns in the velocity form's unknowns
/// (`crate::equations::velocity`): a quaternion's `β` columns `eⱼ`
/// ([`super::free::velocity_subspace`]); a free base's position
/// accelerations in its own axes, `p̈ = R̂ z` (the columns `[0; eⱼ]` of the
/// base itself, at the slides' coordinates, which lose theirs); every
/// other joint's own.
fn velocity_columns(
    g: &mut Graph,
    tree: &Tree,
    states: &[JointState],
) -> Vec<Vec<(usize, Spatial)>> {
    let bases: Vec<Option<usize>> = (0..tree.bodies.len())
        .map(|i| super::free::free_base_in_tree(g, &tree.bodies, i))
        .collect();
    let slides: Vec<usize> = bases.iter().flatten().flat_map(|&x| x..x + 3).collect();
    tree.bodies
        .iter()
        .zip(states)
        .zip(&bases)
        .map(|((b, &js), base)| {
            let c = b.joint.coordinate;
            if b.joint.kind == JointKind::Prismatic && slides.contains(&c) {
                return Vec::new();
            }
            if js.quaternion.is_none() {
                return subspace(g, js);
            }
            let mut own: Vec<(usize, Spatial)> = Vec::new();
            if let Some(x) = *base {
                for (j, s) in super::free::velocity_subspace(g).into_iter().enumerate() {
                    let linear = Spatial {
                        angular: s.linear,
                        linear: s.angular,
                    };
                    own.push((x + j, linear));
                }
            }
            for (j, s) in super::free::velocity_subspace(g).into_iter().enumerate() {
                own.push((c + 1 + j, s));
            }
            own
        })
        .collect()
}

/// The bias forces in the velocity form's unknowns: `Sᵥᵀ fᵢ` for each
/// body's [`velocity_columns`] (0 for each quaternion's `α`, along which
/// nothing moves).
fn velocity_bias(g: &mut Graph, tree: &Tree, n: usize, forces: &[Spatial]) -> Vec<Id> {
    let states: Vec<JointState> = tree.bodies.iter().map(|b| joint_state(g, b)).collect();
    let columns = velocity_columns(g, tree, &states);
    let zero = g.int(0);
    let mut tau = vec![zero; n];
    for (own, f) in columns.iter().zip(forces) {
        for &(c, s) in own {
            let part = s.dot(g, *f);
            accumulate(g, &mut tau[c], part);
        }
    }
    tau
}

/// `T = Σ ½ vᵢᵀ Iᵢ vᵢ` and `V = −Σ gᵀ (mᵢ pᵢ + Rᵢ hᵢ)`, with each body's
/// `gᵀ pᵢ` and gravity in its axes carried outward.
fn energies(g: &mut Graph, tree: &Tree) -> (Id, Id) {
    let states: Vec<JointState> = tree.bodies.iter().map(|b| joint_state(g, b)).collect();
    let zero = spatial::zero(g);
    let mut v: Vec<Spatial> = Vec::new();
    // Gravity as a "motion" with no angular part: Xᵢ only rotates it.
    let mut gravity: Vec<Spatial> = Vec::new();
    let mut height: Vec<Id> = Vec::new();
    let (mut kinetic, mut potential) = (Vec::new(), Vec::new());
    for (i, body) in tree.bodies.iter().enumerate() {
        let (vp, gp, hp) = match body.parent {
            Some(p) => (v[p], gravity[p], height[p]),
            None => {
                let z = g.int(0);
                let world = Spatial {
                    angular: zero,
                    linear: tree.gravity,
                };
                (Spatial::zero(g), world, z)
            }
        };
        let s = subspace(g, states[i]);
        let sq = joint_motion(g, &s, Sym::Vel);
        let vi = motion_to_child(g, body, states[i], vp);
        let vi = vi.add(g, sq).held(g);
        // gᵀ pᵢ = gᵀ p_λ + g_λᵀ rᵢ, rᵢ the origin in the parent's frame.
        let origin = match states[i].slide(g) {
            Some(slide) => {
                let slide = spatial::mat_vec(g, &body.placement.rotation, slide);
                spatial::add(g, body.placement.translation, slide)
            }
            None => body.placement.translation,
        };
        let rise = spatial::dot(g, gp.linear, origin);
        let hi = g.add2(hp, rise);
        let hi = spatial::hold(g, hi);
        let gi = motion_to_child(g, body, states[i], gp).held(g);
        let momentum = body.inertia.apply(g, vi);
        kinetic.push(vi.dot(g, momentum));
        let mh = g.mul2(body.inertia.mass, hi);
        let gh = spatial::dot(g, gi.linear, body.inertia.first_moment);
        potential.push(g.add2(mh, gh));
        v.push(vi);
        gravity.push(gi);
        height.push(hi);
    }
    let t = g.add(&kinetic);
    let half = g.num(crate::expr::num::Num::Rational(1, 2));
    let t = g.mul2(half, t);
    let v_sum = g.add(&potential);
    (t, g.neg(v_sum))
}

/// Everything the pipeline takes from a tree.
pub fn dynamics(g: &mut Graph, tree: &Tree, n: usize) -> Dynamics {
    let all = Terms {
        velocities: true,
        accelerations: false,
        gravity: true,
    };
    let bias = newton_euler(g, tree, n, all);
    let (mass, composite, mass_in_world) = composite_rigid_body(g, tree, n, false);
    let has_quaternion = tree
        .bodies
        .iter()
        .any(|b| b.joint.kind == JointKind::Quaternion);
    let velocity = has_quaternion.then(|| composite_rigid_body(g, tree, n, true));
    let velocity_mass_in_world = velocity.as_ref().is_some_and(|v| v.2);
    let velocity_mass = velocity.map(|v| v.0);
    let velocity_bias = has_quaternion.then(|| velocity_bias(g, tree, n, &bias.f));
    let trace = (0..tree.bodies.len())
        .map(|i| Trace {
            velocity: bias.v[i],
            acceleration: bias.a[i],
            force: bias.f[i],
            center: bias.centers[i],
            composite: composite[i],
        })
        .collect();
    let inverse = newton_euler(
        g,
        tree,
        n,
        Terms {
            accelerations: true,
            ..all
        },
    )
    .tau;
    let gravity = newton_euler(
        g,
        tree,
        n,
        Terms {
            velocities: false,
            accelerations: false,
            gravity: true,
        },
    )
    .tau;
    let (kinetic, potential) = energies(g, tree);
    Dynamics {
        mass,
        mass_in_world,
        velocity_mass,
        velocity_mass_in_world,
        velocity_bias,
        bias: bias.tau,
        inverse,
        gravity,
        kinetic,
        potential,
        trace,
    }
}
