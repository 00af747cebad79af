//! Rigid-body trees: the kinematic tree of a `bodies` (or `urdf`) section
//! and the recursive algorithms that turn it into `M(q)` and the bias
//! forces, run once at compile time on expressions (Featherstone, *Rigid
//! Body Dynamics Algorithms*, ch. 5–6; Pinocchio's `rnea.hxx`, `crba.hxx`):
//! - [`spatial`]: 3-vectors, rotations, spatial vectors and inertias;
//! - [`recursion`]: recursive Newton–Euler (bias forces, inverse dynamics,
//!   gravity), the composite-rigid-body algorithm (`M`) and the energies;
//! - [`kinematics`]: named frames' placements, Jacobians, velocities and
//!   acceleration biases, and the centre of mass;
//! - [`derivatives`]: `∂τ/∂q` and `∂τ/∂q̇` of inverse dynamics by recursions
//!   in world axes;
//! - [`point_motion`]: by the same recursions, a point's acceleration under
//!   a free base and its partials by the joints between;
//! - [`slide`]: the dynamics' frames slid along their joints' axes where
//!   that empties translations;
//! - [`world_mass`]: `M` formed in world axes instead, kept where the
//!   bodies' frames are placed by dense rotations and that is the cheaper.
//!
//! Every quantity of a body is kept in the body's own frame, so a joint
//! contributes its own rotation only and the constant placements, whose
//! right angles and zeros are exact, fold away: the expressions grow O(n)
//! for the bias forces and O(n²) for `M`, against the n^3.5 of
//! differentiating the kinetic energy twice.

pub(crate) mod columns;
pub(crate) mod derivatives;
pub(crate) mod free;
pub(crate) mod joint;
pub(crate) mod kinematics;
pub(crate) mod point_motion;
pub(crate) mod recursion;
pub(crate) mod reference;
pub(crate) mod slide;
pub(crate) mod spatial;
pub(crate) mod turn;
pub(crate) mod world_mass;

use crate::expr::{Graph, Id};
pub use joint::{Joint, JointKind, Mimic};
use spatial::{Inertia, Spatial, M3, V3};

/// Where a frame sits in another: the columns of `rotation` are its axes,
/// `translation` its origin, both in the other frame's coordinates.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    /// `R`.
    pub rotation: M3,
    /// `p`.
    pub translation: V3,
}

impl Placement {
    /// The frame itself.
    pub fn identity(g: &mut Graph) -> Placement {
        Placement {
            rotation: spatial::identity(g),
            translation: spatial::zero(g),
        }
    }

    /// Whether this is the identity, decided on the constants.
    pub fn is_identity(&self, g: &Graph) -> bool {
        let one = |id| g.as_num(id).is_some_and(crate::expr::num::Num::is_one);
        self.translation.iter().all(|&t| g.is_zero(t))
            && (0..3).all(|r| {
                (0..3).all(|c| {
                    let e = self.rotation[r][c];
                    if r == c {
                        one(e)
                    } else {
                        g.is_zero(e)
                    }
                })
            })
    }

    /// `(R, p)⁻¹ = (Rᵀ, −Rᵀ p)`: the outer frame placed in this one.
    pub fn inverse(&self, g: &mut Graph) -> Placement {
        let rotation = spatial::transpose(&self.rotation);
        let back = spatial::mat_vec(g, &rotation, self.translation);
        Placement {
            rotation,
            translation: spatial::neg(g, back),
        }
    }

    /// Each entry [`spatial::hold`]: a frame the recursions read many times.
    pub fn held(self, g: &mut Graph) -> Placement {
        Placement {
            rotation: self.rotation.map(|row| spatial::hold3(g, row)),
            translation: spatial::hold3(g, self.translation),
        }
    }

    /// `self ∘ inner`: the placement in `self`'s outer frame of a frame
    /// placed by `inner` in `self`'s frame.
    pub fn then(&self, g: &mut Graph, inner: &Placement) -> Placement {
        let rotated = spatial::mat_vec(g, &self.rotation, inner.translation);
        Placement {
            rotation: spatial::mat_mul(g, &self.rotation, &inner.rotation),
            translation: spatial::add(g, self.translation, rotated),
        }
    }
}

/// One body as described, before fixed joints are merged away.
#[derive(Clone, Debug)]
pub struct Described {
    /// Name, for messages and the derivation.
    pub name: String,
    /// Index of the parent among the described bodies; `None`: the world.
    pub parent: Option<usize>,
    /// The joint frame in the parent's frame.
    pub placement: Placement,
    /// `None`: fixed to its parent.
    pub joint: Option<Joint>,
    /// Inertia about the body's origin, in its axes.
    pub inertia: Inertia,
}

/// A movable body of the tree.
#[derive(Clone, Debug)]
pub struct Body {
    /// Name, for the derivation.
    pub name: String,
    /// Index of the parent among the tree's bodies; `None`: the world.
    pub parent: Option<usize>,
    /// The joint frame in the parent's frame (fixed links in between composed in).
    pub placement: Placement,
    /// The joint.
    pub joint: Joint,
    /// Its inertia and that of every body fixed to it, about its origin.
    pub inertia: Inertia,
    /// How far its frame is slid along its joint's axis from the frame
    /// described ([`slide`]); `None`: not slid.
    pub slid: Option<Id>,
    /// How far its frame is turned about its joint's axis from the frame
    /// described, its child's joint frame's turn taken up
    /// ([`turn`]); `None`: not turned.
    pub turned: Option<Id>,
}

/// What `parent` stands for once the bodies fixed to the world at its own
/// frame are merged into it, as [`Tree::new`] merges them: `None` (the
/// world) for the world itself or a body on no joint placed at the
/// identity in a parent that is the world in this sense (a URDF's `world`
/// link, a `bodies` body on `fixed` between the world and a base), else
/// `parent`. Such a body's mass is the world's, which nothing moves. A
/// fixed body placed elsewhere is not the world: what hangs from it is
/// placed in another frame.
pub fn grounded(g: &Graph, described: &[Described], parent: Option<usize>) -> Option<usize> {
    let mut at = parent;
    // Each step moves to a parent, whose index is lower: at most
    // `described.len()` steps.
    for _ in 0..=described.len() {
        let d = described.get(at?)?;
        if d.joint.is_some() || !d.placement.is_identity(g) {
            return at;
        }
        at = d.parent;
    }
    at
}

/// A kinematic tree with only movable joints, parents before children.
#[derive(Clone, Debug)]
pub struct Tree {
    /// The bodies, in an order where each parent comes before its children.
    pub bodies: Vec<Body>,
    /// The acceleration of gravity in world coordinates.
    pub gravity: V3,
}

impl Tree {
    /// Merges every body on a fixed joint into the movable body (or the
    /// world) it hangs from: its inertia is added there and its children's
    /// placements are composed through it, as Pinocchio does with a URDF's
    /// fixed joints. `described` lists parents before children.
    pub fn new(g: &mut Graph, described: &[Described], gravity: V3) -> Tree {
        let mut bodies: Vec<Body> = Vec::new();
        // For each described body: the movable body it is rigidly attached
        // to (`None`: the world) and its frame's placement in that body's.
        let mut frames: Vec<(Option<usize>, Placement)> = Vec::with_capacity(described.len());
        for d in described {
            let (anchor, offset) = match d.parent {
                Some(p) => frames[p],
                None => (None, Placement::identity(g)),
            };
            let placement = offset.then(g, &d.placement);
            match d.joint {
                Some(joint) => {
                    bodies.push(Body {
                        name: d.name.clone(),
                        parent: anchor,
                        placement,
                        joint,
                        inertia: d.inertia,
                        slid: None,
                        turned: None,
                    });
                    frames.push((Some(bodies.len() - 1), Placement::identity(g)));
                }
                None => {
                    if let Some(a) = anchor {
                        let moved =
                            d.inertia
                                .to_parent(g, &placement.rotation, placement.translation);
                        bodies[a].inertia = bodies[a].inertia.add(g, &moved);
                    }
                    frames.push((anchor, placement));
                }
            }
        }
        Tree { bodies, gravity }
    }
}

/// The quantities the rest of the pipeline takes from a tree, as expressions.
#[derive(Clone, Debug)]
pub struct Dynamics {
    /// `M(q)` by the composite-rigid-body algorithm, n × n, symmetric.
    pub mass: Vec<Vec<Id>>,
    /// Whether `mass` was formed in world axes ([`world_mass`]), where
    /// that costs fewer operations than in the bodies' own.
    pub mass_in_world: bool,
    /// With quaternion joints, `Tᵀ M T`: `M` in the velocity coordinates of
    /// [`free`] (each quaternion's `w` row and column zero).
    pub velocity_mass: Option<Vec<Vec<Id>>>,
    /// Whether `velocity_mass` was formed in world axes.
    pub velocity_mass_in_world: bool,
    /// With quaternion joints, `Tᵀ c`: the bias forces in the same
    /// unknowns.
    pub velocity_bias: Option<Vec<Id>>,
    /// The bias forces `c(q, q̇) = C(q, q̇) q̇ + g(q)` by recursive Newton–Euler.
    pub bias: Vec<Id>,
    /// `τ = M(q) q̈ + c(q, q̇)` by recursive Newton–Euler with `q̈` as
    /// `Sym::Accel`.
    pub inverse: Vec<Id>,
    /// The generalized gravity `g(q)`: the torques that hold the tree still.
    pub gravity: Vec<Id>,
    /// The kinetic energy `T = Σ ½ vᵢᵀ Iᵢ vᵢ`.
    pub kinetic: Id,
    /// The potential energy of gravity `V = −Σ mᵢ gᵀ cᵢ`.
    pub potential: Id,
    /// Each body's named quantities, for the derivation.
    pub trace: Vec<Trace>,
}

/// A body's intermediates of the recursions that give `M` and the bias
/// forces, each in the body's frame (Featherstone's notation): what the
/// derivation names and prints per body.
#[derive(Clone, Copy, Debug)]
pub struct Trace {
    /// `vᵢ = ⁱX_λ v_λ + Sᵢ q̇ᵢ`.
    pub velocity: Spatial,
    /// `aᵢ = ⁱX_λ a_λ + vᵢ × Sᵢ q̇ᵢ` at `q̈ = 0`, gravity as `a₀ = −g`.
    pub acceleration: Spatial,
    /// `fᵢ = Iᵢ aᵢ + vᵢ ×* Iᵢ vᵢ + Σⱼ ʲXᵢᵀ fⱼ` over the children `j`.
    pub force: Spatial,
    /// The body's motion at its centre of mass, where its own force was
    /// taken there ([`spatial::Inertia::force`]).
    pub center: Option<spatial::Center>,
    /// The composite inertia `Iᶜᵢ = Iᵢ + Σⱼ ʲXᵢᵀ Iᶜⱼ ʲXᵢ`.
    pub composite: Inertia,
}

/// Every described body's frame in the world, as expressions of `q`: `R`
/// and the origin `p`, each entry held ([`spatial::hold`]). For points of
/// bodies in `forces` and `constraints` (`position(body, [x, y, z])`).
pub fn world_frames(g: &mut Graph, described: &[Described]) -> Vec<Placement> {
    let mut frames: Vec<Placement> = Vec::with_capacity(described.len());
    for (i, d) in described.iter().enumerate() {
        let parent = match d.parent {
            Some(p) => frames[p],
            None => Placement::identity(g),
        };
        let (placement, joint) = turn::described_folded(g, described, i);
        let joint_frame = parent.then(g, &placement);
        let motion = joint_motion(g, joint);
        let world = joint_frame.then(g, &motion);
        frames.push(world.held(g));
    }
    frames
}

/// Every described body's frame in its parent's (the world's for a root):
/// its placement, then its joint's motion, each entry held. A point's
/// position built from these inside out, `p₀ + R₀ (p₁ + R₁ (… + Rₖ x))`,
/// differentiates into matrix–vector products along the chain, where the
/// world frames' matrix products differentiate into matrix products.
pub fn parent_frames(g: &mut Graph, described: &[Described]) -> Vec<Placement> {
    (0..described.len())
        .map(|i| {
            let (placement, joint) = turn::described_folded(g, described, i);
            let motion = joint_motion(g, joint);
            placement.then(g, &motion).held(g)
        })
        .collect()
}

/// The motion of a joint: its rotation and translation by `q`.
fn joint_motion(g: &mut Graph, joint: Option<Joint>) -> Placement {
    match joint {
        Some(j) => joint::JointState::new(g, j).placement(g),
        None => Placement::identity(g),
    }
}
