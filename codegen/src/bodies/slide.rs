//! Each joint's frame slid along its own axis where that zeroes a
//! translation the recursions multiply by.
//!
//! A body's frame may move by `t a` along its joint's axis `a` without
//! changing anything the joint coordinates see: the joint's rotation about
//! `a` (or translation or screw along it) commutes with that translation,
//! so the body's joint frame moves to `p + t R a` in its parent, its
//! inertia and its children's frames are taken about the new origin (`h −
//! m t a`, `pₖ − t a`), and `M`, the bias forces and `τ` are the same
//! functions of `q`, `q̇` and `q̈`. Denavit and Hartenberg choose their
//! frames on the common normals for the same reason. A translation that
//! points along a coordinate axis costs two products in every cross
//! product `p × f` that carries a column of `M` or a body's force through
//! it, one along two axes five and a dense one nine; sliding a frame can
//! empty a component of its own translation or of a child's. A slide that
//! empties one component by filling another further down the chain can
//! lower that count and still make slower code (more values live at once,
//! more of them spilled), so a frame slides only where it fills none.
//!
//! Only what is a function of the coordinates alone is computed on a slid
//! tree: the dynamics ([`dynamics`]) and the rate of the total momentum
//! (`super::kinematics`). Frames, points and the centre of mass are placed
//! from the bodies as described.

use super::spatial::{self, V3};
use super::{Body, Dynamics, Tree};
use crate::expr::{Graph, Id};

/// `M`, the bias forces and `τ` of `tree` with its frames [`reframed`],
/// and that tree. A slide only empties components of translations and
/// fills none, so no cross product it touches gains a product, and the
/// slid tree is taken without costing both trees' recursions, which would
/// run them twice.
pub fn dynamics(g: &mut Graph, tree: Tree, n: usize) -> (Tree, Dynamics) {
    let tree = reframed(g, &tree).unwrap_or(tree);
    let d = super::recursion::dynamics(g, &tree, n);
    (tree, d)
}

/// `tree` with its frames' turns about their joints' axes folded into the
/// joints' angles ([`super::turn`]), then its frames slid ([`slid`]);
/// `None` where neither changes a frame. Turns go first: a frame no longer
/// turned about its axis slides where its axis's image in the parent is
/// then a coordinate axis.
pub fn reframed(g: &mut Graph, tree: &Tree) -> Option<Tree> {
    let folded = super::turn::folded(g, tree);
    let base = folded.as_ref().unwrap_or(tree);
    slid(g, base).or(folded)
}

/// How a body's frame may slide: its joint's axis along coordinate axis
/// `axis` of its own frame (`sign` ±1) and along coordinate axis `image`
/// of its parent's, through its placement's rotation (`image_sign`).
#[derive(Clone, Copy, Debug)]
struct Along {
    axis: usize,
    sign: Id,
    image: usize,
    image_sign: Id,
}

/// Whether body `i` may slide: a joint of one axis that commutes with a
/// translation along it, that axis and its image in the parent along
/// coordinate axes, and its own and its children's translations and its
/// mass and first moment constants.
fn along(g: &mut Graph, bodies: &[Body], children: &[usize], i: usize) -> Option<Along> {
    let body = &bodies[i];
    if !body.joint.kind.commutes_along_axis() {
        return None;
    }
    let constant = |g: &Graph, v: &V3| v.iter().all(|&x| g.as_num(x).is_some());
    if !constant(g, &body.placement.translation)
        || !constant(g, &body.inertia.first_moment)
        || g.as_num(body.inertia.mass).is_none()
        || children
            .iter()
            .any(|&k| !constant(g, &bodies[k].placement.translation))
    {
        return None;
    }
    let (axis, sign) = spatial::unit(g, body.joint.axis)?;
    let image = spatial::mat_vec(g, &body.placement.rotation, body.joint.axis);
    let (image, image_sign) = spatial::unit(g, image)?;
    Some(Along {
        axis,
        sign,
        image,
        image_sign,
    })
}

/// Cross products with a translation of 0, 1, 2 or 3 nonzero components
/// cost 0, 2, 5 and 9 operations.
fn cross_cost(g: &Graph, p: V3) -> usize {
    [0, 2, 5, 9][p.iter().filter(|&&x| !g.is_zero(x)).count()]
}

/// The tree with frames slid where that makes the translations cheaper by
/// [`cross_cost`], weighted by how many columns of `M` cross each (a
/// body's subtree, and two for the bias forces; none for a body on the
/// world, whose placement nothing carries across), and makes no zero
/// component of a translation nonzero; `None` where no frame moves or
/// where sliding would change a free base.
pub fn slid(g: &mut Graph, tree: &Tree) -> Option<Tree> {
    let slider = Slider::new(g, &tree.bodies)?;
    let slide = slider.settle(g);
    if slide.iter().all(|&t| g.is_zero(t)) {
        return None;
    }
    let out = slider.apply(g, tree, &slide);
    let bases = |g: &Graph, t: &[Body]| -> Vec<Option<usize>> {
        (0..t.len())
            .map(|i| super::free::free_base_in_tree(g, t, i))
            .collect()
    };
    (bases(g, &out.bodies) == bases(g, &tree.bodies)).then_some(out)
}

/// What the choice of slides reads of a tree: each body's children, the
/// weight of its translation and how it may slide.
struct Slider<'t> {
    bodies: &'t [Body],
    children: Vec<Vec<usize>>,
    weight: Vec<usize>,
    along: Vec<Option<Along>>,
}

impl<'t> Slider<'t> {
    fn new(g: &mut Graph, bodies: &'t [Body]) -> Option<Slider<'t>> {
        let count = bodies.len();
        let mut children = vec![Vec::new(); count];
        for (i, b) in bodies.iter().enumerate() {
            if let Some(p) = b.parent {
                children.get_mut(p)?.push(i);
            }
        }
        // Parents come before their children: one pass from the leaves.
        let mut size = vec![1usize; count];
        for i in (0..count).rev() {
            if let Some(p) = bodies[i].parent {
                size[p] += size[i];
            }
        }
        let weight = (0..count)
            .map(|i| bodies[i].parent.map_or(0, |_| size[i] + 2))
            .collect();
        let along = (0..count)
            .map(|i| along(g, bodies, &children[i], i))
            .collect();
        Some(Slider {
            bodies,
            children,
            weight,
            along,
        })
    }

    /// Body `i` and its children: the translations its slide moves.
    fn family(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        std::iter::once(i).chain(self.children[i].iter().copied())
    }

    /// Body `k`'s translation with its parent's and its own slide.
    fn translation(&self, g: &mut Graph, slide: &[Id], k: usize) -> V3 {
        let mut p = self.bodies[k].placement.translation;
        let parent = self.bodies[k].parent;
        if let Some((j, a)) = parent.and_then(|j| self.along[j].map(|a| (j, a))) {
            let by = g.mul2(slide[j], a.sign);
            p[a.axis] = g.sub(p[a.axis], by);
        }
        if let Some(a) = self.along[k] {
            let by = g.mul2(slide[k], a.image_sign);
            p[a.image] = g.add2(p[a.image], by);
        }
        p
    }

    /// The weighted cost of the translations body `i`'s slide moves.
    fn cost(&self, g: &mut Graph, slide: &[Id], i: usize) -> usize {
        self.family(i)
            .map(|k| {
                let p = self.translation(g, slide, k);
                self.weight[k] * cross_cost(g, p)
            })
            .sum()
    }

    /// Whether sliding body `i` as `other` has it makes a component of
    /// its translation or a child's nonzero that is zero under `slide`.
    fn fills(&self, g: &mut Graph, slide: &[Id], other: &[Id], i: usize) -> bool {
        self.family(i).any(|k| {
            let before = self.translation(g, slide, k);
            let after = self.translation(g, other, k);
            (0..3).any(|c| g.is_zero(before[c]) && !g.is_zero(after[c]))
        })
    }

    /// Body `i`'s slides worth trying: none, and each that empties the
    /// component along its axis of its own translation or of a child's.
    fn candidates(&self, g: &mut Graph, slide: &[Id], i: usize, a: Along) -> Vec<Id> {
        let zero = g.int(0);
        let mut unslid = slide.to_vec();
        unslid[i] = zero;
        let own = self.translation(g, &unslid, i);
        let t = g.mul2(own[a.image], a.image_sign);
        let mut out = vec![zero, g.neg(t)];
        for &k in &self.children[i] {
            let p = self.translation(g, &unslid, k);
            out.push(g.mul2(p[a.axis], a.sign));
        }
        out
    }

    /// Each body's slide: sweeps that move a frame only where that lowers
    /// the cost and fills nothing. The cost is bounded below, and a few
    /// sweeps settle the chains that exist.
    fn settle(&self, g: &mut Graph) -> Vec<Id> {
        let zero = g.int(0);
        let mut slide = vec![zero; self.bodies.len()];
        for _ in 0..4 {
            let mut moved = false;
            for i in 0..slide.len() {
                let Some(a) = self.along[i] else { continue };
                let mut best = (self.cost(g, &slide, i), slide[i]);
                for t in self.candidates(g, &slide, i, a) {
                    let mut other = slide.clone();
                    other[i] = t;
                    let cost = self.cost(g, &other, i);
                    if cost < best.0 && !self.fills(g, &slide, &other, i) {
                        best = (cost, t);
                    }
                }
                if best.1 != slide[i] {
                    slide[i] = best.1;
                    moved = true;
                }
            }
            if !moved {
                break;
            }
        }
        slide
    }

    /// `tree` with `slide` applied: translations moved, and each slid
    /// body's inertia about its new origin.
    fn apply(&self, g: &mut Graph, tree: &Tree, slide: &[Id]) -> Tree {
        let mut out = tree.clone();
        for (k, body) in out.bodies.iter_mut().enumerate() {
            body.placement.translation = self.translation(g, slide, k);
            if let Some(a) = self.along[k].filter(|_| !g.is_zero(slide[k])) {
                // The old frame sits at `−t a` in the new one.
                let mut back = spatial::zero(g);
                let by = g.mul2(slide[k], a.sign);
                back[a.axis] = g.neg(by);
                let identity = spatial::identity(g);
                body.inertia = self.bodies[k].inertia.to_parent(g, &identity, back);
                body.slid = Some(slide[k]);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bodies::joint::{Joint, JointKind};
    use crate::bodies::spatial::Inertia;
    use crate::bodies::Placement;
    use crate::expr::num::Num;
    use crate::expr::Sym;

    /// The bodies of [`tree`].
    const SPECS: [Spec; 5] = [
        (
            None,
            JointKind::Revolute,
            2,
            M3Spec::Identity,
            [30, 40, 333],
        ),
        (
            Some(0),
            JointKind::Prismatic,
            1,
            M3Spec::QuarterX,
            [0, -316, 50],
        ),
        (
            Some(1),
            JointKind::Revolute,
            0,
            M3Spec::Identity,
            [82, 20, -10],
        ),
        (
            Some(1),
            JointKind::Revolute,
            1,
            M3Spec::Identity,
            [-40, 384, 25],
        ),
        (
            Some(2),
            JointKind::Revolute,
            1,
            M3Spec::Identity,
            [0, 50, 30],
        ),
    ];

    /// A branched tree of exact decimals: a revolute joint about z on the
    /// world, a prismatic one along y below it placed a right angle about
    /// x, then two revolute ones about x and y, each translation with a
    /// component along its joint's axis, and below the one about x another
    /// about y on a translation without an x component, which emptying the
    /// x of its parent's translation would fill.
    fn tree(g: &mut Graph) -> Tree {
        let n = |g: &mut Graph, x: i128| g.num(Num::ratio(x, 1000));
        let (zero, one) = (g.int(0), g.int(1));
        let minus = g.int(-1);
        let e = |k: usize| {
            let mut v = [zero; 3];
            v[k] = one;
            v
        };
        let quarter_x = [[one, zero, zero], [zero, zero, minus], [zero, one, zero]];
        let identity = spatial::identity(g);
        let bodies = SPECS
            .iter()
            .enumerate()
            .map(|(i, &(parent, kind, axis, rotation, xyz))| {
                let k = i as i128;
                let mass = n(g, 1200 + 100 * k);
                let com = [n(g, 13 + k), n(g, -27), n(g, 41 - 5 * k)];
                let about = [[310, 7, -3], [7, 388, 8], [-3, 8, 428]].map(|r| r.map(|x| n(g, x)));
                Body {
                    name: format!("b{i}"),
                    parent,
                    placement: Placement {
                        rotation: match rotation {
                            M3Spec::Identity => identity,
                            M3Spec::QuarterX => quarter_x,
                        },
                        translation: xyz.map(|x| n(g, x)),
                    },
                    joint: Joint::new(kind, i, e(axis)),
                    inertia: Inertia::from_com(g, mass, com, &about),
                    slid: None,
                    turned: None,
                }
            })
            .collect();
        let gravity = [zero, zero, n(g, -9810)];
        Tree { bodies, gravity }
    }

    /// A body: its parent, joint kind, axis, placement's rotation and
    /// translation in thousandths.
    type Spec = (Option<usize>, JointKind, usize, M3Spec, [i128; 3]);

    #[derive(Clone, Copy)]
    enum M3Spec {
        Identity,
        QuarterX,
    }

    /// `M`, the bias forces and `τ`, entry by entry.
    fn roots(d: &Dynamics) -> Vec<Id> {
        d.mass
            .iter()
            .flatten()
            .chain(&d.bias)
            .chain(&d.inverse)
            .copied()
            .collect()
    }

    /// The operations of `M`, the bias forces and `τ`.
    fn operations(g: &Graph, d: &Dynamics) -> usize {
        crate::expr::squares::operations(g, &roots(d))
    }

    /// Their values at one state.
    fn values(g: &Graph, d: &Dynamics) -> Vec<f64> {
        g.eval(&roots(d), &|s| match s {
            Sym::Coord(k) => 0.4 - 0.3 * k as f64,
            Sym::Vel(k) => 0.7 + 0.2 * k as f64,
            Sym::Accel(k) => -0.5 + 0.35 * k as f64,
            _ => 0.0,
        })
    }

    /// The slid tree empties translations, keeps every joint's motion and
    /// costs fewer operations, and `M`, the bias forces and `τ` are the
    /// same numbers.
    #[test]
    fn sliding_keeps_the_dynamics_and_empties_translations() {
        let mut g = Graph::new();
        let plain = tree(&mut g);
        let moved = slid(&mut g, &plain).expect("translations along the axes");
        let zeros = |t: &Tree| {
            t.bodies
                .iter()
                .flat_map(|b| b.placement.translation)
                .filter(|&x| g.is_zero(x))
                .count()
        };
        assert!(zeros(&moved) > zeros(&plain), "no translation emptied");
        for (before, after) in plain.bodies.iter().zip(&moved.bodies) {
            let (b, a) = (before.placement.translation, after.placement.translation);
            assert!(
                (0..3).all(|c| !g.is_zero(b[c]) || g.is_zero(a[c])),
                "`{}`: a zero component filled",
                before.name
            );
        }
        let (a, b) = (
            recursion_dynamics(&mut g, &plain),
            recursion_dynamics(&mut g, &moved),
        );
        let (want, got) = (values(&g, &a), values(&g, &b));
        for (w, x) in want.iter().zip(&got) {
            assert!(
                (w - x).abs() <= 1e-13 * w.abs().max(1.0),
                "{want:?} {got:?}"
            );
        }
        assert!(operations(&g, &b) < operations(&g, &a));
        let (kept, _) = dynamics(&mut g, plain, 5);
        assert!(kept.bodies.iter().any(|b| b.slid.is_some()));
    }

    fn recursion_dynamics(g: &mut Graph, t: &Tree) -> Dynamics {
        crate::bodies::recursion::dynamics(g, t, 5)
    }
}
