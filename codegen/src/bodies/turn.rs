//! Each joint frame's constant turn about its own joint's axis folded into
//! the joint's angle.
//!
//! A joint frame placed in its parent by `(p, R_p)`, where `R_p` turns about
//! the joint's own axis `a` by `θ₀`, turns its child by `R_p R_a(q) =
//! R_a(θ₀ + q)`: the child's frame is the same with the joint frame's
//! rotation the identity and the joint's angle `θ₀ + q`. Every motion and
//! force vector, inertia and column of `M` that the recursions carry
//! through that joint frame is then turned once, by the joint, instead of
//! twice; the constant turn costs one addition before the joint's sine and
//! cosine. URDF files write such frames where a link's zero pose is tilted
//! about the axis it turns about (the Unitree G1's knees, by 0.1749 about
//! `y`, and its shoulder rolls, by ∓0.27925 about `x`).
//!
//! A joint frame turned about its *parent's* joint axis, its parent's only
//! child, is taken up ([`up`]): the parent's frame is turned by the same
//! angle about its own axis instead, so that the parent's angle carries
//! the turn, its inertia is taken in the turned axes and the child's joint
//! frame is placed at `R_pᵀ p` with no turn (the G1's hip rolls, turned
//! 0.1749 about `y` in the hip pitch links, which turn about `y`). The
//! child's translation may gain a component (at most four products more
//! in each cross product through it), where the turn cost six on every
//! 3-vector.
//!
//! Decided on the constants exactly: `a` is `±eₖ`, `R_p`'s row and column
//! `k` are `eₖ`, its other block is `[[c, −s], [s, c]]` of two numbers
//! neither of which is zero (a right angle's turn costs nothing: its
//! zeros and ones fold), and `θ₀` is an angle whose sine and cosine,
//! rounded as the placement's were (`crate::expr::rounded`), are `s` and
//! `c` to the last bit. The frames of the bodies as described, which
//! place frames, points and the centre of mass, fold the turns about
//! joints' own axes too ([`described_folded`]): they are the same frames,
//! and a function that needs both evaluates each joint's sine and cosine
//! once. Turns taken up and the slides ([`super::slide`]) change frames,
//! and stay in the dynamics' tree.

use super::joint::Joint;
use super::spatial;
use super::{Body, Described, Placement, Tree};
use crate::expr::num::Num;
use crate::expr::{Graph, Id};

/// `tree` with every joint frame's turn about its joint's own axis folded
/// into the joint's angle, and a single child's turn about its parent's
/// axis taken up into the parent's ([`up`]); `None` where no frame has
/// either.
pub fn folded(g: &mut Graph, tree: &Tree) -> Option<Tree> {
    fold(g, tree, true)
}

/// `tree` with every joint frame's turn about its joint's own axis folded
/// into the joint's angle and no frame turned: every body's frame is the
/// one described, so that world frames placed from the described bodies
/// still hold for it. `None` where no frame has such a turn.
pub fn folded_in_place(g: &mut Graph, tree: &Tree) -> Option<Tree> {
    fold(g, tree, false)
}

/// [`folded`], taking children's turns up only where `take_up`.
fn fold(g: &mut Graph, tree: &Tree, take_up: bool) -> Option<Tree> {
    let mut bodies = tree.bodies.clone();
    let mut any = false;
    for c in (0..bodies.len()).filter(|_| take_up) {
        any |= up(g, &mut bodies, c);
    }
    for body in &mut bodies {
        if let Some(angle) = turn(g, body) {
            body.joint.turn = Some(plus(g, body.joint.turn, angle));
            body.placement.rotation = spatial::identity(g);
            any = true;
        }
    }
    any.then_some(Tree {
        bodies,
        gravity: tree.gravity,
    })
}

/// Where body `c`'s joint frame is turned about its parent's joint axis
/// and is its parent's only child, the parent's frame turned by the same
/// angle about its axis instead (`P' = P R`): the parent's joint angle
/// gains it, its inertia is taken in the turned axes, and `c`'s joint
/// frame is placed at `Rᵀ p` without a turn. Whether the parent's
/// inertia and `c`'s translation are numbers, so that both are turned at
/// compile time.
fn up(g: &mut Graph, bodies: &mut [Body], c: usize) -> bool {
    let Some(p) = bodies[c].parent else {
        return false;
    };
    let only = bodies.iter().filter(|b| b.parent == Some(p)).count() == 1;
    let parent = &bodies[p];
    let inertia = &parent.inertia;
    let constant = std::iter::once(&inertia.mass)
        .chain(&inertia.first_moment)
        .chain(inertia.rotational.iter().flatten())
        .chain(&bodies[c].placement.translation)
        .all(|&x| g.as_num(x).is_some());
    if !only || !constant || !parent.joint.kind.turns_about_axis() || parent.joint.mimic.is_some() {
        return false;
    }
    let Some(angle) = about(g, parent.joint.axis, &bodies[c].placement.rotation) else {
        return false;
    };
    let r = bodies[c].placement.rotation;
    let back = spatial::transpose(&r);
    let zero = spatial::zero(g);
    let parent = &mut bodies[p];
    parent.joint.turn = Some(plus(g, parent.joint.turn, angle));
    parent.turned = Some(plus(g, parent.turned, angle));
    parent.inertia = parent.inertia.to_parent(g, &back, zero);
    let child = &mut bodies[c];
    child.placement.translation = spatial::mat_vec(g, &back, child.placement.translation);
    child.placement.rotation = spatial::identity(g);
    true
}

/// Described body `i`'s joint frame and joint with the frame's turn about
/// the joint's own axis folded into the joint's angle, as [`folded`] folds
/// the dynamics' tree: the body's frame is the same, and its angle's sine
/// and cosine are the dynamics' own, so that a function that places
/// frames or points (a contact's rows, the centre of mass) and runs the
/// recursions evaluates one pair per joint. Not on a body that hangs from
/// the world through fixed bodies only, which the tree does not fold.
pub fn described_folded(
    g: &mut Graph,
    described: &[Described],
    i: usize,
) -> (Placement, Option<Joint>) {
    let d = &described[i];
    let as_described = (d.placement, d.joint);
    let Some(joint) = d.joint.filter(|j| j.kind.turns_about_axis()) else {
        return as_described;
    };
    let mut ancestor = d.parent;
    while let Some(a) = ancestor.filter(|&a| described[a].joint.is_none()) {
        ancestor = described[a].parent;
    }
    if ancestor.is_none() {
        return as_described;
    }
    let Some(angle) = about(g, joint.axis, &d.placement.rotation) else {
        return as_described;
    };
    let turned = Joint {
        turn: Some(plus(g, joint.turn, angle)),
        ..joint
    };
    let placement = Placement {
        rotation: spatial::identity(g),
        translation: d.placement.translation,
    };
    (placement, Some(turned))
}

/// A turn of `angle` added to the turn `turn` already carried, if any.
fn plus(g: &mut Graph, turn: Option<Id>, angle: f64) -> Id {
    let angle = g.num(Num::Float(angle));
    match turn {
        Some(t) => g.add2(t, angle),
        None => angle,
    }
}

/// The angle `θ₀` of `body`'s joint frame's turn about its joint's axis,
/// where the frame has one and nothing else turns it.
fn turn(g: &Graph, body: &Body) -> Option<f64> {
    let joint = &body.joint;
    // On the world, nothing the recursions carry crosses the joint frame
    // but gravity, a constant: the turn costs nothing, its fold an addition.
    if !joint.kind.turns_about_axis() || body.parent.is_none() {
        return None;
    }
    about(g, joint.axis, &body.placement.rotation)
}

/// The angle by which `r` turns about `axis`, where `axis` is `±eₖ`, `r`'s
/// row and column `k` are `eₖ`, and its other block is `[[c, −s], [s, c]]`
/// of two numbers, neither zero, that an angle's rounded sine and cosine
/// give to the last bit.
fn about(g: &Graph, axis: spatial::V3, r: &spatial::M3) -> Option<f64> {
    let (k, sign) = spatial::unit(g, axis)?;
    let sign = g.as_num(sign)?.to_f64();
    let number = |id: Id| g.as_num(id);
    let exact = |id: Id, value: i64| number(id).is_some_and(|n| n == Num::int(value));
    let line_k = (0..3).all(|x| {
        let one = i64::from(x == k);
        exact(r[k][x], one) && exact(r[x][k], one)
    });
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let (c, s) = (number(r[i][i])?, number(r[j][i])?);
    let block = number(r[j][j]) == Some(c) && number(r[i][j]) == Some(-s);
    if !line_k || !block || c.is_zero() || s.is_zero() {
        return None;
    }
    angle(s.to_f64(), c.to_f64()).map(|phi| sign * phi)
}

/// An angle whose rounded sine and cosine are `s` and `c` exactly: the
/// arctangent, or one of the nearest doubles to it.
fn angle(s: f64, c: f64) -> Option<f64> {
    let guess = s.atan2(c);
    let mut candidates = vec![guess];
    let (mut down, mut up) = (guess, guess);
    for _ in 0..4 {
        down = down.next_down();
        up = up.next_up();
        candidates.extend([down, up]);
    }
    candidates.into_iter().find(|&theta| {
        crate::expr::rounded::sin_cos(Num::Float(theta))
            .is_some_and(|(ts, tc)| ts.to_bits() == s.to_bits() && tc.to_bits() == c.to_bits())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bodies::joint::{Joint, JointKind};
    use crate::bodies::spatial::Inertia;
    use crate::bodies::{Dynamics, Placement};
    use crate::expr::Sym;

    /// A chain of five revolute joints, lengths in thousandths and angles
    /// in millionths: about `z` on the world in a frame turned 0.5 about
    /// `z`, which costs nothing there; about `y` in a frame turned 1.570796
    /// about `y`, near a right angle but not one; about `−x` in a
    /// frame turned −0.4 about `x`; about `z` in a frame turned 0.2 about
    /// `x`, its parent's axis and not its own; about `z` in a frame turned
    /// 0.1 about `x`, neither its own axis nor its parent's.
    fn tree(g: &mut Graph) -> Tree {
        let n = |g: &mut Graph, x: i128| g.num(Num::ratio(x, 1000));
        let (zero, one, minus) = (g.int(0), g.int(1), g.int(-1));
        let specs: [([i128; 3], [Id; 3], [i128; 3]); 5] = [
            ([0, 0, 500_000], [zero, zero, one], [0, 0, 100]),
            ([0, 1_570_796, 0], [zero, one, zero], [100, 20, -300]),
            ([-400_000, 0, 0], [minus, zero, zero], [50, 0, -250]),
            ([200_000, 0, 0], [zero, zero, one], [30, -40, -120]),
            ([100_000, 0, 0], [zero, zero, one], [0, 60, -80]),
        ];
        let bodies = specs
            .iter()
            .enumerate()
            .map(|(i, &(rpy, axis, xyz))| {
                let k = i as i128;
                let angles = rpy.map(|x| g.num(Num::ratio(x, 1_000_000)));
                let mass = n(g, 1500 - 200 * k);
                let com = [n(g, 21 + k), n(g, -13), n(g, -90 + 7 * k)];
                let about = [[41, 2, -3], [2, 37, 5], [-3, 5, 12]].map(|r| r.map(|x| n(g, x)));
                Body {
                    name: format!("b{i}"),
                    parent: i.checked_sub(1),
                    placement: Placement {
                        rotation: spatial::rpy(g, angles),
                        translation: xyz.map(|x| n(g, x)),
                    },
                    joint: Joint::new(JointKind::Revolute, i, axis),
                    inertia: Inertia::from_com(g, mass, com, &about),
                    slid: None,
                    turned: None,
                }
            })
            .collect();
        let gravity = [n(g, 300), zero, n(g, -9810)];
        Tree { bodies, gravity }
    }

    /// Each joint's constant turn, where it has one.
    fn turns(g: &Graph, tree: &Tree) -> Vec<Option<f64>> {
        let value = |id: Option<Id>| id.and_then(|t| g.as_num(t)).map(Num::to_f64);
        tree.bodies.iter().map(|b| value(b.joint.turn)).collect()
    }

    /// Whether `x` is `want` to within 1e-15.
    fn near(x: Option<f64>, want: f64) -> bool {
        x.is_some_and(|x| (x - want).abs() < 1e-15)
    }

    /// `M`, the bias forces and `τ`, entry by entry.
    fn roots(d: &Dynamics) -> Vec<Id> {
        let all = d.mass.iter().flatten().chain(&d.bias).chain(&d.inverse);
        all.copied().collect()
    }

    /// The frames turned about their joints' axes are folded but on the
    /// world, the one turned about its parent's taken up, the other kept;
    /// `M`, the bias forces and `τ` are the same numbers at several
    /// states, and cost fewer operations.
    #[test]
    fn folding_turns_keeps_the_dynamics() {
        let mut g = Graph::new();
        let plain = tree(&mut g);
        let folded = folded(&mut g, &plain).expect("turns about the joints' axes");
        let turns = turns(&g, &folded);
        assert_eq!(turns[0], None);
        // 1.570796: near a right angle, not one.
        assert!(near(turns[1], 1_570_796.0 / 1e6), "{turns:?}");
        // About `−x`: its own frame's −0.4 about `x` is +0.4 about the
        // axis, and its child's 0.2 about `x` is −0.2.
        assert!(near(turns[2], 0.2), "{turns:?}");
        assert!(near(
            folded.bodies[2]
                .turned
                .and_then(|t| g.as_num(t))
                .map(Num::to_f64),
            -0.2
        ));
        assert_eq!(turns[3..], [None, None], "turns about other axes are kept");
        for (i, body) in folded.bodies.iter().enumerate() {
            let is_identity = (0..3).all(|a| {
                (0..3).all(|b| {
                    let e = body.placement.rotation[a][b];
                    g.as_num(e) == Some(Num::int(i64::from(a == b)))
                })
            });
            assert_eq!(is_identity, (1..4).contains(&i), "body {i}");
        }
        let a = crate::bodies::recursion::dynamics(&mut g, &plain, 5);
        let b = crate::bodies::recursion::dynamics(&mut g, &folded, 5);
        let (ra, rb) = (roots(&a), roots(&b));
        for k in 0..5 {
            let state = |s: Sym| match s {
                Sym::Coord(i) => 0.9 * k as f64 - 1.7 + 0.41 * i as f64,
                Sym::Vel(i) => 0.3 - 0.6 * i as f64 + 0.2 * k as f64,
                Sym::Accel(i) => 1.1 - 0.25 * (i + k) as f64,
                _ => 0.0,
            };
            let (want, got) = (g.eval(&ra, &state), g.eval(&rb, &state));
            for (w, x) in want.iter().zip(&got) {
                assert!((w - x).abs() <= 1e-13 * w.abs().max(1.0), "{w} {x}");
            }
        }
        let ops = |d: &Dynamics| crate::expr::squares::operations(&g, &roots(d));
        assert!(ops(&b) < ops(&a), "{} against {}", ops(&b), ops(&a));
    }

    /// Folded in place, the turns about the joints' own axes go into their
    /// angles and no frame is turned: the turn about the parent's axis
    /// stays, and each body's composite inertia and motion columns in its
    /// own axes (what the centre of mass and the centroidal map carry to
    /// the world) are the same numbers at several states.
    #[test]
    fn folding_in_place_keeps_every_frame() {
        let mut g = Graph::new();
        let plain = tree(&mut g);
        let folded = folded_in_place(&mut g, &plain).expect("turns about the joints' axes");
        let turns = turns(&g, &folded);
        assert!(near(turns[1], 1_570_796.0 / 1e6), "{turns:?}");
        assert!(near(turns[2], 0.4), "{turns:?}");
        assert_eq!([turns[0], turns[3], turns[4]], [None; 3]);
        assert!(folded.bodies.iter().all(|b| b.turned.is_none()));
        let flat = |g: &mut Graph, tree: &Tree| -> Vec<Id> {
            let columns = crate::bodies::recursion::composite_columns(g, tree);
            let mut all = Vec::new();
            for (inertia, motion) in &columns {
                all.push(inertia.mass);
                all.extend(inertia.first_moment);
                all.extend(inertia.rotational.iter().flatten());
                for (_, s) in motion {
                    all.extend(s.angular.iter().chain(&s.linear));
                }
            }
            all
        };
        let (ra, rb) = (flat(&mut g, &plain), flat(&mut g, &folded));
        assert_eq!(ra.len(), rb.len());
        for k in 0..5 {
            let state = |s: Sym| match s {
                Sym::Coord(i) => 0.7 * k as f64 - 1.3 + 0.37 * i as f64,
                _ => 0.0,
            };
            let (want, got) = (g.eval(&ra, &state), g.eval(&rb, &state));
            for (w, x) in want.iter().zip(&got) {
                assert!((w - x).abs() <= 1e-13 * w.abs().max(1.0), "{w} {x}");
            }
        }
    }

    /// Described bodies: a joint about `z` on the world in a frame turned
    /// 0.3 about `z`, a fixed body turned 0.2 about `x`, a joint about `y`
    /// in a frame turned 0.4 about `y`, a joint about `x` in a frame turned
    /// 0.5 about `z`. Only the third folds (the first hangs from the
    /// world, the fixed body has no joint, the last turns about another
    /// axis), and every world frame is the same numbers at several states.
    #[test]
    fn described_frames_fold_turns_about_their_own_axes() {
        let mut g = Graph::new();
        let n = |g: &mut Graph, x: i128| g.num(Num::ratio(x, 1000));
        let (zero, one) = (g.int(0), g.int(1));
        let specs: [([i128; 3], Option<[Id; 3]>); 4] = [
            ([0, 0, 300], Some([zero, zero, one])),
            ([200, 0, 0], None),
            ([0, 400, 0], Some([zero, one, zero])),
            ([0, 0, 500], Some([one, zero, zero])),
        ];
        let mut coordinate = 0;
        let described: Vec<Described> = specs
            .iter()
            .enumerate()
            .map(|(i, &(rpy, axis))| {
                let angles = rpy.map(|x| n(&mut g, x));
                let joint = axis.map(|axis| {
                    coordinate += 1;
                    Joint::new(JointKind::Revolute, coordinate - 1, axis)
                });
                let mass = n(&mut g, 1000);
                let com = [zero; 3];
                let about = [[10, 0, 0], [0, 10, 0], [0, 0, 10]].map(|r| r.map(|x| n(&mut g, x)));
                Described {
                    name: format!("d{i}"),
                    parent: i.checked_sub(1),
                    placement: Placement {
                        rotation: spatial::rpy(&mut g, angles),
                        translation: [n(&mut g, 100), n(&mut g, -20), n(&mut g, 50)],
                    },
                    joint,
                    inertia: Inertia::from_com(&mut g, mass, com, &about),
                }
            })
            .collect();
        let folded: Vec<bool> = (0..described.len())
            .map(|i| {
                described_folded(&mut g, &described, i)
                    .1
                    .is_some_and(|j| j.turn.is_some())
            })
            .collect();
        assert_eq!(folded, [false, false, true, false]);
        let (_, joint) = described_folded(&mut g, &described, 2);
        let turn = joint
            .and_then(|j| j.turn)
            .and_then(|t| g.as_num(t))
            .map(Num::to_f64);
        assert!(turn.is_some_and(|t| (t - 0.4).abs() < 1e-15), "{turn:?}");
        let world = crate::bodies::world_frames(&mut g, &described);
        let mut plain: Vec<Placement> = Vec::new();
        for d in &described {
            let parent = match d.parent {
                Some(p) => plain[p],
                None => Placement::identity(&mut g),
            };
            let motion = match d.joint {
                Some(j) => crate::bodies::joint::JointState::new(&mut g, j).placement(&mut g),
                None => Placement::identity(&mut g),
            };
            let joint_frame = parent.then(&mut g, &d.placement);
            plain.push(joint_frame.then(&mut g, &motion));
        }
        let flat = |p: &[Placement]| -> Vec<Id> {
            p.iter()
                .flat_map(|p| {
                    p.rotation
                        .iter()
                        .flatten()
                        .chain(&p.translation)
                        .copied()
                        .collect::<Vec<_>>()
                })
                .collect()
        };
        let (want, got) = (flat(&plain), flat(&world));
        for k in 0..5 {
            let state = |s: Sym| match s {
                Sym::Coord(i) => 0.8 * k as f64 - 1.9 + 0.53 * i as f64,
                _ => 0.0,
            };
            for (w, x) in g.eval(&want, &state).iter().zip(&g.eval(&got, &state)) {
                assert!((w - x).abs() <= 1e-14 * w.abs().max(1.0), "{w} {x}");
            }
        }
    }
}
