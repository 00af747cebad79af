//! The frame the derivative recursions (`super::derivatives`) run in: for
//! each subtree on the world, the axes of one of its bodies, or the
//! world's.

use super::joint::JointState;
use super::{Body, Placement, Tree};
use crate::expr::Graph;

/// Every body's frame, and for each body on the world the world's frame,
/// in the axes of its subtree's reference body about its origin (the
/// world's for a subtree without one), each entry held. The recursions'
/// quantities are vectors and pairings of them, so any one frame serves a
/// subtree, fixed or not, and the one whose coordinates move the fewest
/// bodies' frames costs least: in a free base's own axes no body's frame
/// depends on the base's position or attitude, where in the world's every
/// one does. The subtrees hanging from the world never meet (the world
/// has no coordinate), so each may take its own. From each reference up
/// to the world, bodies are placed by walking up (each parent by its
/// child's inverse placement), the others down from their parents. A
/// second reference in a subtree that has one is ignored.
pub(super) fn reference_frames(
    g: &mut Graph,
    tree: &Tree,
    states: &[JointState],
    references: &[usize],
) -> (Vec<Placement>, Vec<Placement>) {
    let own = |g: &mut Graph, i: usize| {
        let joint = states[i].placement(g);
        tree.bodies[i].placement.then(g, &joint)
    };
    let count = tree.bodies.len();
    let mut frames: Vec<Option<Placement>> = vec![None; count];
    let mut worlds: Vec<Option<Placement>> = vec![None; count];
    for &r in references {
        let root = root_of(&tree.bodies, r);
        if worlds[root].is_some() {
            continue;
        }
        let mut here = Placement::identity(g);
        let mut at = r;
        frames[r] = Some(here);
        // Up the path to the world, at most one step per body.
        for _ in 0..count {
            let back = own(g, at).inverse(g);
            here = here.then(g, &back).held(g);
            match tree.bodies[at].parent {
                Some(p) => {
                    frames[p] = Some(here);
                    at = p;
                }
                None => {
                    worlds[at] = Some(here);
                    break;
                }
            }
        }
    }
    let identity = Placement::identity(g);
    let worlds: Vec<Placement> = worlds.into_iter().map(|w| w.unwrap_or(identity)).collect();
    let mut out = Vec::with_capacity(count);
    for (i, known) in frames.iter().enumerate() {
        let frame = match *known {
            Some(f) => f,
            None => {
                let parent = match tree.bodies[i].parent {
                    Some(p) => out[p],
                    None => worlds[i],
                };
                let step = own(g, i);
                parent.then(g, &step).held(g)
            }
        };
        out.push(frame);
    }
    (out, worlds)
}

/// The body on the world whose subtree holds body `i`.
pub fn root_of(bodies: &[Body], i: usize) -> usize {
    let mut at = i;
    for _ in 0..bodies.len() {
        match bodies[at].parent {
            Some(p) => at = p,
            None => break,
        }
    }
    at
}
