//! Stage 3, for bodies on quaternion joints: `gauss` in the quaternions'
//! velocity coordinates (`crate::bodies::free`). Each quaternion's
//! accelerations are written `q̈ = ½ (q α + Gᵀ β)` (`T = ½ [q, Gᵀ]`,
//! invertible wherever `q ≠ 0`, so nothing is approximated off the unit
//! sphere; `β` is the body's angular acceleration but for the term
//! `k (qᵀq̇) ω` that vanishes on the sphere), a free base's position's
//! `p̈ = R̂ z` (its own axes), and the saddle-point system
//! `[M Aᵀ; A 0] [q̈; μ] = [F; b]` multiplied by `Tᵀ` on the left becomes
//!
//! ```text
//! [ TᵀMT  TᵀAᵀ ] [ z ]   [ TᵀF ]
//! [ A T    0   ] [ μ ] = [  b  ],      q̈ = T z.
//! ```
//!
//! `TᵀMT` comes from the composite-rigid-body algorithm with the joint's
//! columns `S T` (`α`'s is zero: its row and column vanish; a free base's
//! position's are `[0; eⱼ]` in its own frame), `TᵀF` from the recursions'
//! body forces projected on the same columns, and the norm's row
//! `2qᵀ q̈ = b` becomes `|q|² α = b`, on `α` alone. So each pair
//! (`α`, the norm's multiplier) is a 2 × 2 block `[0 c; c 0]` whose
//! elimination changes no other entry of the matrix: `α = b_norm / c`
//! first, `b ← b − (A T)_α α` for the other rows, the rest — every other
//! coordinate, `β` included, and every other row — solved as the
//! saddle-point system of [`super::saddle_point`], and last the norm's
//! multiplier `μ_norm = ((TᵀF)_α − Σ (A T)_{rα} μ_r) / c`. For a floating
//! base the rest is the twist formulation's system: six base coordinates
//! instead of seven and a norm's row, `M`'s rows the base's composite
//! inertia in its own axes, and the rows of its feet premultiplied by
//! `R̂ᵀ` ([`super::in_base`]), so that none of it holds the attitude but
//! gravity.

use crate::bodies::spatial::M3;
use crate::bodies::{Body, JointKind};
use crate::expr::{Graph, Id};
use crate::numeric::sparsity::Structure;

/// `gauss`'s system in the quaternions' velocity coordinates.
pub struct Velocity {
    /// `TᵀF`, `A T` and each quaternion's norm's row.
    pub system: Transformed,
    /// `TᵀMT`, n × n (each `α`'s row and column zero).
    pub mass: Vec<Vec<Id>>,
    /// The coordinates solved by the saddle-point system (all but the
    /// `α`s), in order: the structure's first rows.
    pub coordinates: Vec<usize>,
    /// The rows solved by it (all but the norms'), in order: its last rows.
    pub rows: Vec<usize>,
    /// The saddle-point structure of the coordinates and rows kept.
    pub structure: Structure,
}

/// What the velocity form of a tree with quaternions is built from: the
/// tree's own terms and the rows of its points under a free base. It lives
/// here, beside the form that reads it, so that `mass_inverse` imports this
/// module and not the other way round.
#[derive(Clone, Copy)]
pub struct Bodies<'a> {
    /// `TᵀMT`.
    pub mass: &'a [Vec<Id>],
    /// `TᵀF`.
    pub forces: &'a [Id],
    /// The tree's bodies.
    pub bodies: &'a [Body],
    /// The rows of points under a free base, in its axes.
    pub in_base: &'a [super::in_base::InBaseRows],
    /// The bodies held at three or more points.
    pub held: &'a [crate::model::HeldBody],
}

/// The quaternions' `w` coordinates of a tree.
pub fn quaternions(tree: &[Body]) -> Vec<usize> {
    tree.iter()
        .filter(|b| b.joint.kind == JointKind::Quaternion)
        .map(|b| b.joint.coordinate)
        .collect()
}

/// `TᵀF`, `A T` and each quaternion's norm's row, before any order is
/// sought.
pub struct Transformed {
    /// Each quaternion's `w` coordinate (where its `α` is) and its norm's
    /// row.
    pub quaternions: Vec<(usize, usize)>,
    /// Each quaternion's coordinates `(w, x, y, z)` as expressions.
    pub q: Vec<[Id; 4]>,
    /// `TᵀF`.
    pub forces: Vec<Id>,
    /// `A T`, k × n (each norm's row nonzero at its `α` only); the rows
    /// of `in_base` premultiplied by `R̂ᵀ`.
    pub a: Vec<Vec<Id>>,
    /// The rows of points under a free base solved in its axes: their
    /// `b` and multipliers are `R̂ᵀ b` and `R̂ᵀ λ`.
    pub in_base: Vec<super::in_base::InBaseRows>,
    /// Each free base's `x` coordinate and `R̂`: its position's
    /// accelerations are `p̈ = R̂ z`.
    pub free: Vec<(usize, M3)>,
    /// The bodies held at three or more points of `in_base`, each solved
    /// through its own six rows (`super::held`).
    pub held: Vec<super::held::HeldRows>,
}

/// The velocity form of `gauss`'s system, where [`transformed`] finds it
/// and the rest has a saddle-point order under three quarters of
/// `range_cost`; `None` otherwise.
pub fn form(g: &mut Graph, bodies: Bodies, a: &[Vec<Id>], range_cost: usize) -> Option<Velocity> {
    let (velocity_mass, tree, forces) = (bodies.mass, bodies.bodies, bodies.forces);
    let mut system = transformed(g, (velocity_mass, tree), forces, a)?;
    points_in_base(g, &mut system, bodies);
    let (n, a) = (forces.len(), &system.a);
    let ws: Vec<usize> = system.quaternions.iter().map(|&(c, _)| c).collect();
    let coordinates: Vec<usize> = (0..n).filter(|i| !ws.contains(i)).collect();
    let dropped: Vec<usize> = system.held.iter().flat_map(|h| h.dropped()).collect();
    let rows: Vec<usize> = (0..a.len())
        .filter(|r| !system.quaternions.iter().any(|&(_, s)| s == *r))
        .filter(|r| !dropped.contains(r))
        .collect();
    let mass: Vec<Vec<Id>> = coordinates
        .iter()
        .map(|&i| coordinates.iter().map(|&j| velocity_mass[i][j]).collect())
        .collect();
    let reduced_a: Vec<Vec<Id>> = rows
        .iter()
        .map(|&r| coordinates.iter().map(|&j| a[r][j]).collect())
        .collect();
    let pattern = Structure::new(
        mass.iter()
            .map(|row| row.iter().map(|&e| !g.is_zero(e)).collect())
            .collect(),
    );
    // Every coordinate before any multiplier: a floating base's rows keep
    // their rank through its six coordinates, a leg's alone lose it where
    // the leg straightens (`super::saddle_point`).
    let costs = (range_cost, true);
    let structure =
        super::saddle_point::structure(g, (&mass, &pattern), &reduced_a, (None, &ws), costs)?;
    Some(Velocity {
        system,
        mass: velocity_mass.to_vec(),
        coordinates,
        rows,
        structure,
    })
}

/// The rows of points under the form's free bases, in their axes
/// (`super::in_base`), into `system`'s `A T`, and the bodies held at three
/// or more of them as their own six rows (`super::held`).
fn points_in_base(g: &mut Graph, system: &mut Transformed, bodies: Bodies) {
    let tree = bodies.bodies;
    // Only the triples under a base the tree's own form turns (both find
    // the same free joints; any other keeps its rows of `A T`).
    let mut in_base: Vec<_> = (bodies.in_base.iter())
        .filter(|rows| system.free.iter().any(|&(x, _)| x == rows.base))
        .cloned()
        .collect();
    for rows in &mut in_base {
        // A quaternion joint between the base and the point (a ball joint)
        // turns its own columns as any row's: `T`.
        for c in quaternions(tree).into_iter().filter(|&c| c != rows.w) {
            let own = crate::bodies::free::coordinates(g, c);
            let big_g = crate::bodies::free::g_matrix(g, own);
            for row in &mut rows.a {
                if c + 4 <= row.len() {
                    transform(g, (c, own, &big_g), row);
                }
            }
        }
        for (i, &r) in rows.rows.iter().enumerate() {
            system.a[r].clone_from(&rows.a[i]);
        }
    }
    let bases = (&in_base[..], &system.free[..]);
    system.held = super::held::reduce(g, bodies.held, bases);
    for held in &system.held {
        // The second point's rows carry the body's angular ones, as `A T`.
        for (i, &r) in held.angular().iter().enumerate() {
            let mut row = held.angular_rows[i].clone();
            transpose(g, tree, &mut row);
            system.a[r] = row;
        }
    }
    system.in_base = in_base;
}

/// `TᵀF` and `A T` for every quaternion of the tree, where `TᵀMT` has no
/// `α` row and each quaternion has its norm's row: a row of `A T` nonzero
/// at its `α` alone (`G A_q = 0` identically, decided on the expressions);
/// `None` otherwise.
pub fn transformed(
    g: &mut Graph,
    (velocity_mass, tree): (&[Vec<Id>], &[Body]),
    forces: &[Id],
    a: &[Vec<Id>],
) -> Option<Transformed> {
    let n = forces.len();
    let ws = quaternions(tree);
    if ws.is_empty() || velocity_mass.len() != n {
        return None;
    }
    let forces = forces.to_vec();
    let mut a = a.to_vec();
    let mut q: Vec<[Id; 4]> = Vec::with_capacity(ws.len());
    for &c in &ws {
        if c + 4 > n || (0..n).any(|j| !g.is_zero(velocity_mass[c][j])) {
            return None;
        }
        q.push(crate::bodies::free::coordinates(g, c));
    }
    for row in &mut a {
        transpose(g, tree, row);
    }
    let free = free_bases(g, tree);
    let mut quaternions = Vec::new();
    for &c in &ws {
        let norm = (0..a.len()).find(|&r| {
            let row = &a[r];
            !g.is_zero(row[c])
                && (0..n).all(|j| j == c || g.is_zero(row[j]))
                && !quaternions.iter().any(|&(_, s)| s == r)
        })?;
        quaternions.push((c, norm));
    }
    Some(Transformed {
        quaternions,
        q,
        forces,
        a,
        in_base: Vec::new(),
        free,
        held: Vec::new(),
    })
}

/// `x ← Tᵀ x` on the quaternion whose `w` is `c`: `x_c ← ½ qᵀ x_q`,
/// `x_{c+1+j} ← ½ (G x_q)_j` (a row of `A` times `T`, or `F`).
fn transform(g: &mut Graph, (c, q, big_g): (usize, [Id; 4], &[[Id; 4]; 3]), x: &mut [Id]) {
    let own: Vec<Id> = x[c..c + 4].to_vec();
    if own.iter().all(|&e| g.is_zero(e)) {
        return;
    }
    let half = g.num(crate::expr::num::Num::Rational(1, 2));
    let dot = |g: &mut Graph, w: [Id; 4]| {
        let pairs: Vec<(Id, Id)> = w
            .iter()
            .zip(&own)
            .filter(|(_, &e)| !g.is_zero(e))
            .map(|(&wk, &e)| (wk, e))
            .collect();
        let terms: Vec<Id> = pairs.into_iter().map(|(wk, e)| g.mul2(wk, e)).collect();
        let sum = g.add(&terms);
        g.mul2(half, sum)
    };
    x[c] = dot(g, q);
    for (j, row) in big_g.iter().enumerate() {
        x[c + 1 + j] = dot(g, *row);
    }
}

/// Each free base of the tree: its `x` coordinate and `R̂`.
fn free_bases(g: &mut Graph, tree: &[Body]) -> Vec<(usize, M3)> {
    let mut out = Vec::new();
    for i in 0..tree.len() {
        if let Some(x) = crate::bodies::free::free_base_in_tree(g, tree, i) {
            let q = crate::bodies::free::coordinates(g, tree[i].joint.coordinate);
            out.push((x, crate::bodies::free::rotation(g, q)));
        }
    }
    out
}

/// `x ← Tᵀ x` for the whole tree: each quaternion's
/// (`½ [qᵀ; G] x_q`) and each free base's `x_p ← R̂ᵀ x_p` (`p̈ = R̂ z`). A
/// row of `A` becomes one of `A T`, generalized forces `TᵀQ`.
pub fn transpose(g: &mut Graph, tree: &[Body], x: &mut [Id]) {
    let n = x.len();
    for c in quaternions(tree) {
        if c + 4 > n {
            continue;
        }
        let own = crate::bodies::free::coordinates(g, c);
        let big_g = crate::bodies::free::g_matrix(g, own);
        transform(g, (c, own, &big_g), x);
    }
    for (p, r) in free_bases(g, tree) {
        if p + 3 > n {
            continue;
        }
        let own = [x[p], x[p + 1], x[p + 2]];
        if own.iter().all(|&e| g.is_zero(e)) {
            continue;
        }
        for (j, slot) in x[p..p + 3].iter_mut().enumerate() {
            let terms: Vec<Id> = (0..3).map(|i| g.mul2(r[i][j], own[i])).collect();
            *slot = g.add(&terms);
        }
    }
}

/// `TᵀF` from `F = Q − c` with the bias forces `c` written in the
/// velocity form's unknowns directly (`velocity_bias`, from the
/// recursions' own forces, free of the products `R̂ᵀR̂` and `G Gᵀ` that
/// `Tᵀ c` would multiply out): `Tᵀ (F + c) − Tᵀc`.
pub fn forces(g: &mut Graph, bodies: &crate::model::BodyTerms, f: &[Id]) -> Option<Vec<Id>> {
    let bias = bodies.velocity_bias.as_ref()?;
    if bias.len() != f.len() || bodies.bias.len() != f.len() {
        return None;
    }
    let mut applied: Vec<Id> = f
        .iter()
        .zip(&bodies.bias)
        .map(|(&f, &c)| g.add2(f, c))
        .collect();
    transpose(g, &bodies.tree, &mut applied);
    Some(
        applied
            .iter()
            .zip(bias)
            .map(|(&q, &c)| g.sub(q, c))
            .collect(),
    )
}
