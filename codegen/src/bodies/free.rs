//! The rotation of a spherical joint, alone or as the attitude of a free
//! (floating) joint, in a unit quaternion
//! `(w, x, y, z)`, four coordinates with the norm `w² + x² + y² + z² = 1`
//! as a constraint (the `bodies` and `urdf` lowerings add it). A free joint is three
//! prismatic joints along the parent's axes followed by this spherical one,
//! so that its seven coordinates are the position of the body's origin and
//! its attitude, and their rates are `q̇` like any joint's.
//!
//! The body angular velocity is `ω = 2 G(q) q̇` with
//! `G = [−v, w I − ṽ]`: the vector part of `2 q̄ ⊗ q̇`. Its columns are the
//! joint's motion subspace, `Sₖ = [2 Gₖ; 0]`, which varies with `q`; but
//! `Σ Ṡₖ q̇ₖ = [2 (q̄̇ ⊗ q̇)_vec; 0] = 0`, since `q̄̇ ⊗ q̇ = |q̇|²` is a scalar,
//! so the recursions' `aᵢ = Xᵢ a_λ + Sᵢ q̈ᵢ + vᵢ × Sᵢ q̇ᵢ` stays exact.
//! `G q = 0`: the direction `q` itself moves nothing, `M` is singular there
//! and the norm's constraint row completes it (the auxiliary-mass solve).
//!
//! **Velocity coordinates.** `T = ½ [q, Gᵀ]` is invertible wherever
//! `q ≠ 0` (`[qᵀ; G] T = ½ |q|² I`, since `G Gᵀ = |q|² I`), so the
//! quaternion's accelerations can be written `q̈ = ½ (q α + Gᵀ β)` exactly,
//! on the unit sphere or off it. In `(α, β)` the joint's columns are
//! `S q = 0` and `½ S Gᵀ = [|q|² I; 0]` ([`velocity_subspace`]): `Tᵀ M T` has
//! a zero row and column for `α` and the body's own axes for `β` (on the
//! sphere `β = ω̇`, since `ω̇ = 2 G q̈ + 2 G(q̇) q̇ = |q|² β`), and the norm's
//! row `2qᵀ q̈ = b` reads `|q|² α = b`, `α` alone
//! (`crate::equations::velocity`).

use super::spatial::{Inertia, Spatial, M3, V3};
use super::{Described, Joint, JointKind, Placement};
use crate::expr::{Graph, Id, Sym};

/// A free joint as four described bodies: three massless slides along the
/// axes of the frame `placement` puts in `parent`, then the body itself on
/// a quaternion joint. `first` is the index the first slide will have among
/// the described bodies, `coordinate` that of `x` in `q` (the quaternion's
/// `w` is `coordinate + 3`). The `bodies` section's `free(..)` and the
/// URDF's `floating` joints both come here.
pub fn described(
    g: &mut Graph,
    name: &str,
    (parent, placement, first): (Option<usize>, Placement, usize),
    coordinate: usize,
    inertia: Inertia,
) -> Vec<Described> {
    let zero = g.int(0);
    let one = g.int(1);
    let mut out = Vec::with_capacity(4);
    for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
        let mut unit = [zero; 3];
        unit[k] = one;
        let identity = Placement::identity(g);
        out.push(Described {
            name: format!("{name}/{axis}"),
            parent: if k == 0 { parent } else { Some(first + k - 1) },
            placement: if k == 0 { placement } else { identity },
            joint: Some(Joint {
                kind: JointKind::Prismatic,
                coordinate: coordinate + k,
                axis: unit,
            }),
            inertia: Inertia::zero(g),
        });
    }
    let identity = Placement::identity(g);
    out.push(spherical(
        g,
        name,
        (Some(first + 2), identity),
        coordinate + 3,
        inertia,
    ));
    out
}

/// A body on a spherical joint: a quaternion joint whose `w` is
/// coordinate `coordinate`, its frame placed by `placement` in `parent`'s.
pub fn spherical(
    g: &mut Graph,
    name: &str,
    (parent, placement): (Option<usize>, Placement),
    coordinate: usize,
    inertia: Inertia,
) -> Described {
    Described {
        name: name.to_string(),
        parent,
        placement,
        joint: Some(Joint {
            kind: JointKind::Quaternion,
            coordinate,
            axis: super::spatial::zero(g),
        }),
        inertia,
    }
}

/// The quaternion's four coordinates as expressions, `w` at `first`.
pub fn coordinates(g: &mut Graph, first: usize) -> [Id; 4] {
    [0, 1, 2, 3].map(|k| g.sym(Sym::Coord(first + k)))
}

/// `R(q)`, the body's axes in its parent's: `I + 2w ṽ + 2ṽ²`, a rotation
/// on the unit sphere (where the norm's constraint holds).
pub fn rotation(g: &mut Graph, q: [Id; 4]) -> M3 {
    let [w, x, y, z] = q;
    let two = g.int(2);
    let mut prod = |a: Id, b: Id| {
        let ab = g.mul(&[two, a, b]);
        super::spatial::hold(g, ab)
    };
    let (xx, yy, zz) = (prod(x, x), prod(y, y), prod(z, z));
    let (xy, xz, yz) = (prod(x, y), prod(x, z), prod(y, z));
    let (wx, wy, wz) = (prod(w, x), prod(w, y), prod(w, z));
    let one = g.int(1);
    let diag = |g: &mut Graph, a: Id, b: Id| {
        let s = g.add2(a, b);
        g.sub(one, s)
    };
    [
        [diag(g, yy, zz), g.sub(xy, wz), g.add2(xz, wy)],
        [g.add2(xy, wz), diag(g, xx, zz), g.sub(yz, wx)],
        [g.sub(xz, wy), g.add2(yz, wx), diag(g, xx, yy)],
    ]
    .map(|row| super::spatial::hold3(g, row))
}

/// The four columns `Sₖ = [2 Gₖ; 0]` of the joint's motion subspace, in
/// the body's frame.
pub fn subspace(g: &mut Graph, q: [Id; 4]) -> [Spatial; 4] {
    let [w, x, y, z] = q;
    let columns: [V3; 4] = [
        [g.neg(x), g.neg(y), g.neg(z)],
        [w, g.neg(z), y],
        [z, w, g.neg(x)],
        [g.neg(y), x, w],
    ];
    let zero = super::spatial::zero(g);
    let two = g.int(2);
    columns.map(|c| Spatial {
        angular: super::spatial::scale(g, two, c),
        linear: zero,
    })
}

/// The joint's columns for `β` in the velocity coordinates (the module's
/// `½ S Gᵀ`): `|q|² eⱼ` in the body's axes, `j = 0, 1, 2`. (`α`'s, `S q`,
/// is zero.)
pub fn velocity_subspace(g: &mut Graph, q: [Id; 4]) -> [Spatial; 3] {
    let scale = squared_norm(g, q);
    let zero = g.int(0);
    let zeros = super::spatial::zero(g);
    [0, 1, 2].map(|j| {
        let mut angular = [zero; 3];
        angular[j] = scale;
        Spatial {
            angular,
            linear: zeros,
        }
    })
}

/// `|q|²`: the scale of [`velocity_subspace`], and of the norm's
/// constraint.
pub fn squared_norm(g: &mut Graph, q: [Id; 4]) -> Id {
    let two = g.int(2);
    let squares: Vec<Id> = q.iter().map(|&c| g.pow(c, two)).collect();
    g.add(&squares)
}

/// `G(q)`'s entries as (sign, index into `(w, x, y, z)`).
pub const G_PATTERN: [[(bool, usize); 4]; 3] = [
    [(false, 1), (true, 0), (true, 3), (false, 2)],
    [(false, 2), (false, 3), (true, 0), (true, 1)],
    [(false, 3), (true, 2), (false, 1), (true, 0)],
];

/// `G(q)`, 3 × 4: `ω = 2 G q̇` (the module's).
pub fn g_matrix(g: &mut Graph, q: [Id; 4]) -> [[Id; 4]; 3] {
    G_PATTERN.map(|row| row.map(|(plus, k)| if plus { q[k] } else { g.neg(q[k]) }))
}

/// `|q|² − 1`, the norm's constraint.
pub fn norm(g: &mut Graph, q: [Id; 4]) -> Id {
    let sum = squared_norm(g, q);
    let one = g.int(1);
    g.sub(sum, one)
}
