//! `M(q)` by the composite-rigid-body algorithm in world axes, as
//! Pinocchio's `crba` forms it: each body's frame in the world `(Rᵢ, oᵢ)`,
//! its inertia there, the composites `Iᶜᵢʷ` summed in world axes about
//! the world's origin (no transform from child to parent), each joint's
//! motion columns in world axes `Sᵢʷ = [Rᵢ s_ω; Rᵢ s_v + oᵢ × Rᵢ s_ω]`,
//! and `Mⱼᵢ = Sⱼʷᵀ Iᶜᵢʷ Sᵢʷ` for `j` an ancestor of `i` or `i` itself:
//! six products a pair of joints.
//!
//! The recursion in the bodies' own axes (`super::recursion`) carries
//! `Iᶜᵢ Sᵢ` through every joint between `i` and `j` instead, which costs
//! a few products a step where frames are placed along coordinate axes,
//! and three dense rotations' worth where they are not (a URDF whose
//! `rpy` are `1.5708` rather than π/2, whose axes carry `6e-17`
//! leftovers): there the world's dense frames, paid once a body, are the
//! cheaper. [`cheaper`] keeps whichever form of `M` has fewer operations,
//! counted exactly on the expressions of both; the two are the same
//! function of `q`.

use super::joint::JointState;
use super::spatial::{self, Inertia, Spatial};
use super::{Placement, Tree};
use crate::expr::{Graph, Id};

/// Each body's frame in the world: its parent's, then its placement, then
/// its joint's motion, each entry held. The placement is composed first:
/// a constant, often sparse rotation, then the joint's about one axis.
fn frames(g: &mut Graph, tree: &Tree, states: &[JointState]) -> Vec<Placement> {
    let mut frames: Vec<Placement> = Vec::with_capacity(tree.bodies.len());
    for (body, js) in tree.bodies.iter().zip(states) {
        let joint_frame = match body.parent {
            Some(p) => frames[p].then(g, &body.placement).held(g),
            None => body.placement,
        };
        let motion = js.placement(g);
        frames.push(joint_frame.then(g, &motion).held(g));
    }
    frames
}

/// A motion vector `s` of a body's frame `(R, o)` in world axes, about
/// the world's origin: `[R s_ω; R s_v + o × R s_ω]`, held.
fn to_world(g: &mut Graph, frame: &Placement, s: Spatial) -> Spatial {
    let angular = spatial::mat_vec(g, &frame.rotation, s.angular);
    let turned = spatial::mat_vec(g, &frame.rotation, s.linear);
    let moment = spatial::cross(g, frame.translation, angular);
    let linear = spatial::add(g, turned, moment);
    Spatial { angular, linear }.held(g)
}

/// `M` (n × n) in world axes from each body's joint columns `columns` (in
/// the body's axes, the same ones [`super::recursion`]'s `M` reads).
pub(super) fn mass(
    g: &mut Graph,
    tree: &Tree,
    states: &[JointState],
    columns: &[Vec<(usize, Spatial)>],
    n: usize,
) -> Vec<Vec<Id>> {
    let frames = frames(g, tree, states);
    let mut composite: Vec<Inertia> = tree
        .bodies
        .iter()
        .zip(&frames)
        .map(|(b, f)| b.inertia.moved(g, &f.rotation, f.translation).held(g))
        .collect();
    for (i, body) in tree.bodies.iter().enumerate().rev() {
        if let Some(p) = body.parent {
            composite[p] = composite[p].add(g, &composite[i]).held(g);
        }
    }
    let world: Vec<Vec<(usize, Spatial)>> = columns
        .iter()
        .zip(&frames)
        .map(|(own, f)| own.iter().map(|&(c, s)| (c, to_world(g, f, s))).collect())
        .collect();
    let zero = g.int(0);
    let mut m = vec![vec![zero; n]; n];
    for (i, own) in world.iter().enumerate() {
        for &(ci, s) in own {
            let force = composite[i].apply(g, s).held(g);
            for &(ck, sk) in own {
                let mik = sk.dot(g, force);
                spatial::accumulate(g, &mut m[ci][ck], mik);
            }
            let mut j = i;
            while let Some(p) = tree.bodies[j].parent {
                j = p;
                for &(cj, sj) in &world[j] {
                    let mij = sj.dot(g, force);
                    spatial::accumulate(g, &mut m[ci][cj], mij);
                    spatial::accumulate(g, &mut m[cj][ci], mij);
                }
            }
        }
    }
    m
}

/// The operations of `M`'s lower triangle, each node once.
fn operations(g: &Graph, m: &[Vec<Id>]) -> usize {
    let roots: Vec<Id> = (0..m.len())
        .flat_map(|r| (0..=r).map(move |c| (r, c)))
        .map(|(r, c)| m[r][c])
        .collect();
    crate::expr::squares::operations(g, &roots)
}

/// `M` in world axes where it has fewer operations than `local`, the
/// same matrix in the bodies' own axes ([`super::recursion`]); `None`
/// otherwise (on a tie too), and then the graph is left as it was, so
/// that the code emitted for `local` does not depend on the alternative
/// having been costed.
pub(super) fn cheaper(
    g: &mut Graph,
    tree: &Tree,
    states: &[JointState],
    columns: &[Vec<(usize, Spatial)>],
    local: &[Vec<Id>],
) -> Option<Vec<Vec<Id>>> {
    let before = g.len();
    let world = mass(g, tree, states, columns, local.len());
    if operations(g, &world) < operations(g, local) {
        Some(world)
    } else {
        g.truncate(before);
        None
    }
}

#[cfg(test)]
#[path = "world_mass_tests.rs"]
mod tests;
