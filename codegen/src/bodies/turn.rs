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
//! Decided on the constants exactly: `a` is `±eₖ`, `R_p`'s row and column
//! `k` are `eₖ`, its other block is `[[c, −s], [s, c]]` of two numbers
//! neither of which is zero (a right angle's turn costs nothing: its
//! zeros and ones fold), and `θ₀` is an angle whose sine and cosine,
//! rounded as the placement's were (`crate::expr::rounded`), are `s` and
//! `c` to the last bit. As the slides ([`super::slide`]), only the
//! dynamics' tree is folded: frames, points and the centre of mass are
//! placed from the bodies as described.

use super::spatial;
use super::{Body, Tree};
use crate::expr::num::Num;
use crate::expr::{Graph, Id};

/// `tree` with every joint frame's turn about its joint's own axis folded
/// into the joint's angle; `None` where no frame has one.
pub fn folded(g: &mut Graph, tree: &Tree) -> Option<Tree> {
    let mut bodies = tree.bodies.clone();
    let mut any = false;
    for body in &mut bodies {
        if let Some(angle) = turn(g, body) {
            body.joint.turn = Some(g.num(Num::Float(angle)));
            body.placement.rotation = spatial::identity(g);
            any = true;
        }
    }
    any.then(|| Tree {
        bodies,
        gravity: tree.gravity,
    })
}

/// The angle `θ₀` of `body`'s joint frame's turn about its joint's axis,
/// where the frame has one and nothing else turns it.
fn turn(g: &Graph, body: &Body) -> Option<f64> {
    let joint = &body.joint;
    if !joint.kind.turns_about_axis() || joint.turn.is_some() {
        return None;
    }
    let (k, sign) = super::slide::unit(g, joint.axis)?;
    let sign = g.as_num(sign)?.to_f64();
    let r = &body.placement.rotation;
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

    /// A chain of four revolute joints in thousandths: about `z` on the
    /// world; about `y` in a frame turned 0.3 about `y`; about `−x` in a
    /// frame turned −0.4 about `x`; about `z` in a frame turned 0.2 about
    /// `x`, which is not its axis.
    fn tree(g: &mut Graph) -> Tree {
        let n = |g: &mut Graph, x: i128| g.num(Num::ratio(x, 1000));
        let (zero, one, minus) = (g.int(0), g.int(1), g.int(-1));
        let specs: [([i128; 3], [Id; 3], [i128; 3]); 4] = [
            ([0, 0, 0], [zero, zero, one], [0, 0, 100]),
            ([0, 300, 0], [zero, one, zero], [100, 20, -300]),
            ([-400, 0, 0], [minus, zero, zero], [50, 0, -250]),
            ([200, 0, 0], [zero, zero, one], [30, -40, -120]),
        ];
        let bodies = specs
            .iter()
            .enumerate()
            .map(|(i, &(rpy, axis, xyz))| {
                let k = i as i128;
                let angles = rpy.map(|x| n(g, x));
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
                }
            })
            .collect();
        let gravity = [n(g, 300), zero, n(g, -9810)];
        Tree { bodies, gravity }
    }

    /// `M`, the bias forces and `τ`, entry by entry.
    fn roots(d: &Dynamics) -> Vec<Id> {
        let all = d.mass.iter().flatten().chain(&d.bias).chain(&d.inverse);
        all.copied().collect()
    }

    /// The frames turned about their joints' axes are folded, the other
    /// kept; `M`, the bias forces and `τ` are the same numbers at several
    /// states, and cost fewer operations.
    #[test]
    fn folding_turns_keeps_the_dynamics() {
        let mut g = Graph::new();
        let plain = tree(&mut g);
        let folded = folded(&mut g, &plain).expect("two turns about the joints' axes");
        let turns: Vec<Option<f64>> = folded
            .bodies
            .iter()
            .map(|b| b.joint.turn.and_then(|t| g.as_num(t)).map(Num::to_f64))
            .collect();
        assert_eq!(turns[0], None);
        assert!((turns[1].expect("folded") - 0.3).abs() < 1e-15, "{turns:?}");
        // About `−x` by −0.4 about `x`: +0.4 about the axis.
        assert!((turns[2].expect("folded") - 0.4).abs() < 1e-15, "{turns:?}");
        assert_eq!(turns[3], None, "a turn about another axis is kept");
        for (i, body) in folded.bodies.iter().enumerate() {
            let is_identity = (0..3).all(|a| {
                (0..3).all(|b| {
                    let e = body.placement.rotation[a][b];
                    g.as_num(e) == Some(Num::int(i64::from(a == b)))
                })
            });
            assert_eq!(is_identity, i != 3, "body {i}");
        }
        let a = crate::bodies::recursion::dynamics(&mut g, &plain, 4);
        let b = crate::bodies::recursion::dynamics(&mut g, &folded, 4);
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
}
