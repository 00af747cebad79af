//! Stage 3, for bodies on quaternion joints: `gauss` in the quaternions'
//! velocity coordinates (`crate::bodies::free`). Each quaternion's
//! accelerations are written `q̈ = ½ (q α + Gᵀ β)` (`T = ½ [q, Gᵀ]`,
//! invertible wherever `q ≠ 0`, so nothing is approximated off the unit
//! sphere; on it `β` is the body's angular acceleration), and
//! the saddle-point system `[M Aᵀ; A 0] [q̈; μ] = [F; b]` multiplied by
//! `Tᵀ` on the left becomes
//!
//! ```text
//! [ TᵀMT  TᵀAᵀ ] [ z ]   [ TᵀF ]
//! [ A T    0   ] [ μ ] = [  b  ],      q̈ = T z.
//! ```
//!
//! `TᵀMT` comes from the composite-rigid-body algorithm with the joint's
//! columns `S T` (`α`'s is zero: its row and column vanish), and the norm's
//! row `2qᵀ q̈ = b` becomes `|q|² α = b`, on `α` alone. So each pair
//! (`α`, the norm's multiplier) is a 2 × 2 block `[0 c; c 0]` whose
//! elimination changes no other entry of the matrix: `α = b_norm / c`
//! first, `b ← b − (A T)_α α` for the other rows, the rest — every other
//! coordinate, `β` included, and every other row — solved as the
//! saddle-point system of [`super::saddle_point`], and last the norm's
//! multiplier `μ_norm = ((TᵀF)_α − Σ (A T)_{rα} μ_r) / c`. For a floating
//! base the rest is the twist formulation's system: six base coordinates
//! instead of seven and a norm's row, and `M`'s quaternion rows are the
//! body's composite inertia rather than its products with `G`.

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
    /// `A T`, k × n (each norm's row nonzero at its `α` only).
    pub a: Vec<Vec<Id>>,
}

/// The velocity form of `gauss`'s system, where [`transformed`] finds it
/// and the rest has a saddle-point order under three quarters of
/// `range_cost`; `None` otherwise.
pub fn form(
    g: &mut Graph,
    (velocity_mass, tree): (&[Vec<Id>], &[Body]),
    forces: &[Id],
    a: &[Vec<Id>],
    range_cost: usize,
) -> Option<Velocity> {
    let system = transformed(g, (velocity_mass, tree), forces, a)?;
    let (n, a) = (forces.len(), &system.a);
    let ws: Vec<usize> = system.quaternions.iter().map(|&(c, _)| c).collect();
    let coordinates: Vec<usize> = (0..n).filter(|i| !ws.contains(i)).collect();
    let rows: Vec<usize> = (0..a.len())
        .filter(|r| !system.quaternions.iter().any(|&(_, s)| s == *r))
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
    let structure =
        super::saddle_point::structure(g, (&mass, &pattern), &reduced_a, (None, &ws), range_cost)?;
    Some(Velocity {
        system,
        mass: velocity_mass.to_vec(),
        coordinates,
        rows,
        structure,
    })
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
    let mut forces = forces.to_vec();
    let mut a = a.to_vec();
    let mut q: Vec<[Id; 4]> = Vec::with_capacity(ws.len());
    for &c in &ws {
        if c + 4 > n || (0..n).any(|j| !g.is_zero(velocity_mass[c][j])) {
            return None;
        }
        let own = crate::bodies::free::coordinates(g, c);
        let big_g = crate::bodies::free::g_matrix(g, own);
        transform(g, (c, own, &big_g), &mut forces);
        for row in &mut a {
            transform(g, (c, own, &big_g), row);
        }
        q.push(own);
    }
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
