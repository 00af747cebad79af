//! Tests of `super`: `M` in world axes against `M` in the bodies' own
//! axes, and which of the two is kept.

use super::*;
use crate::bodies::joint::{Joint, JointKind};
use crate::bodies::{recursion, Described};
use crate::expr::num::Num;
use crate::expr::Sym;

/// Described bodies, lengths in thousandths and angles in millionths:
/// with `free`, a free base (three slides and a quaternion) first;
/// then twelve revolute joints, on the world or the base, a chain of
/// eight with a branch of four from its third, their frames turned by
/// `1.5708` (near a right angle, not one) and general angles as an
/// exported URDF's are, every third axis not along a coordinate axis;
/// with `square`, every frame unturned.
fn described(g: &mut Graph, free: bool, square: bool) -> (Vec<Described>, usize) {
    let n = |g: &mut Graph, x: i128| g.num(Num::ratio(x, 1000));
    let (zero, one) = (g.int(0), g.int(1));
    let inertia = |g: &mut Graph, k: i128| {
        let mass = n(g, 1500 - 90 * k);
        let com = [n(g, 21 + k), n(g, -13), n(g, -90 + 7 * k)];
        let about = [[41, 2, -3], [2, 37, 5], [-3, 5, 12]].map(|r| r.map(|x| n(g, x)));
        Inertia::from_com(g, mass, com, &about)
    };
    let mut out = Vec::new();
    let mut coordinate = 0;
    if free {
        let base = inertia(g, 13);
        let identity = Placement::identity(g);
        out = crate::bodies::free::described(g, "base", (None, identity, 0), 0, base);
        coordinate = 7;
    }
    let (three, four) = (n(g, 600), n(g, 800));
    let axes = [
        [zero, zero, one],
        [zero, one, zero],
        [three, four, zero],
        [one, zero, zero],
    ];
    let first = out.len();
    let root = out.len().checked_sub(1);
    for k in 0..12_usize {
        let parent = match k {
            0 => None,
            8 => Some(2),
            _ => Some(k - 1),
        };
        let i = k as i128;
        let rpy = if square {
            [0; 3]
        } else {
            [
                [1_570_800, 0, 300_000],
                [0, -700_000, 1_100_000],
                [400_000, 1_570_800, 0],
            ][k % 3]
        };
        let angles = rpy.map(|x| g.num(Num::ratio(x, 1_000_000)));
        let xyz = [30 + 10 * i, -40 + 5 * i, -120 - 15 * i];
        let body_inertia = inertia(g, i);
        out.push(Described {
            name: format!("b{k}"),
            parent: parent.map(|p| first + p).or(root),
            placement: Placement {
                rotation: spatial::rpy(g, angles),
                translation: xyz.map(|x| n(g, x)),
            },
            joint: Some(Joint::new(JointKind::Revolute, coordinate + k, axes[k % 4])),
            inertia: body_inertia,
        });
    }
    (out, coordinate + 12)
}

/// The tree of [`described`], its joints' states, its columns (with
/// `velocity`, the velocity form's) and `M` in the bodies' own axes.
struct Built {
    tree: Tree,
    states: Vec<JointState>,
    columns: Vec<Vec<(usize, Spatial)>>,
    local: Vec<Vec<Id>>,
    n: usize,
}

fn build(g: &mut Graph, free: bool, square: bool, velocity: bool) -> Built {
    let (described, n) = described(g, free, square);
    let gravity = spatial::zero(g);
    let tree = Tree::new(g, &described, gravity);
    let states: Vec<JointState> = tree
        .bodies
        .iter()
        .map(|b| recursion::joint_state(g, b))
        .collect();
    let composite = recursion::composites(g, &tree, &states);
    let columns = recursion::mass_columns(g, &tree, &states, velocity);
    let local = recursion::local_mass(g, &tree, (&states, &composite), &columns, n);
    Built {
        tree,
        states,
        columns,
        local,
        n,
    }
}

/// Both forms of `M` (and of `M` in the velocity form's unknowns),
/// entry by entry, and the graph.
fn both(free: bool, square: bool, velocity: bool) -> (Graph, Vec<Id>, Vec<Id>) {
    let mut g = Graph::new();
    let b = build(&mut g, free, square, velocity);
    let world = mass(&mut g, &b.tree, &b.states, &b.columns, b.n);
    let flat = |m: Vec<Vec<Id>>| m.into_iter().flatten().collect();
    (g, flat(b.local), flat(world))
}

/// The two forms agree to rounding at several states.
fn assert_same(g: &Graph, local: &[Id], world: &[Id]) {
    for k in 0..6 {
        let state = |s: Sym| match s {
            Sym::Coord(i) => 0.9 * k as f64 - 1.7 + 0.41 * i as f64,
            _ => 0.0,
        };
        let (want, got) = (g.eval(local, &state), g.eval(world, &state));
        let scale = want.iter().fold(1.0_f64, |m, w| m.max(w.abs()));
        for (w, x) in want.iter().zip(&got) {
            assert!((w - x).abs() <= 1e-13 * scale, "{w} {x} at state {k}");
        }
    }
}

/// Turned frames, a branch and an axis off the coordinate axes, on the
/// world: the world's `M` is the bodies' own, and the cheaper.
#[test]
fn world_axes_give_the_same_mass_matrix() {
    let (g, local, world) = both(false, false, false);
    assert_same(&g, &local, &world);
    let ops = |m: &[Id]| crate::expr::squares::operations(&g, m);
    assert!(
        ops(&world) < ops(&local),
        "{} against {}",
        ops(&world),
        ops(&local)
    );
}

/// On a free base, in the coordinates and in the velocity form's
/// unknowns (the quaternion's columns, the base's position in its own
/// axes): the same matrices.
#[test]
fn world_axes_give_the_same_matrix_on_a_free_base() {
    for velocity in [false, true] {
        let (g, local, world) = both(true, false, velocity);
        assert_same(&g, &local, &world);
    }
}

/// Where every frame is unturned the bodies' own axes are the cheaper:
/// `cheaper` keeps them, and leaves the graph node for node as it was.
/// Where frames are turned it returns the world's, which `dynamics`
/// then reports.
#[test]
fn the_cheaper_form_is_kept_and_the_other_leaves_no_trace() {
    for square in [true, false] {
        let mut g = Graph::new();
        let Built {
            tree,
            states,
            columns,
            local,
            n,
        } = build(&mut g, false, square, false);
        let before = g.clone();
        let world = cheaper(&mut g, &tree, &states, &columns, &local);
        assert_eq!(world.is_some(), !square, "square {square}");
        if square {
            assert_eq!(g.len(), before.len());
            assert!(g.ids().all(|id| g.node(id) == before.node(id)));
            // Interned as before: a node the alternative had made is
            // made anew at the same id.
            let again = mass(&mut g, &tree, &states, &columns, n);
            let mut fresh = before.clone();
            let want = mass(&mut fresh, &tree, &states, &columns, n);
            assert_eq!(again, want);
        }
        let dynamics = recursion::dynamics(&mut g, &tree, n);
        assert_eq!(dynamics.mass_in_world, !square);
    }
}
