//! The rotation of a spherical joint, alone or as the attitude of a free
//! (floating) joint, in a quaternion `(w, x, y, z)`, four coordinates with
//! the norm `w² + x² + y² + z² = 1` as a constraint (the `bodies` and
//! `urdf` lowerings add it). A free joint is three prismatic joints along
//! the parent's axes followed by this spherical one, so that its seven
//! coordinates are the position of the body's origin and its attitude, and
//! their rates are `q̇` like any joint's.
//!
//! The body is turned by `R̂ = R(q/|q|) = I + k (w ṽ + ṽ²)`, `k = 2/|q|²`
//! ([`rotation`]): a rotation for every `q ≠ 0`, so the body stays rigid
//! off the unit sphere. Its angular velocity is `ω = k G(q) q̇` with
//! `G = [−v, w I − ṽ]` (the vector part of `2 q̄ ⊗ q̇ / |q|²`, the
//! angular velocity of `q/|q|`: `G q = 0`). The columns of `k G` are the
//! joint's motion subspace, `Sₖ = [k Gₖ; 0]`, which varies with `q`:
//! `Σ Ṡₖ q̇ₖ = [−k (qᵀq̇) ω; 0]` ([`subspace_rate`], since
//! `G(q̇) q̇ = 0`), which the recursions add to `aᵢ`. `S q = 0`: the
//! direction `q` itself moves nothing, `M` is singular there and the
//! norm's constraint row completes it (the auxiliary-mass solve).
//!
//! **Velocity coordinates.** `T = ½ [q, Gᵀ]` is invertible wherever
//! `q ≠ 0` (`[qᵀ; G] T = ½ |q|² I`, since `G Gᵀ = |q|² I`), so the
//! quaternion's accelerations can be written `q̈ = ½ (q α + Gᵀ β)` exactly,
//! on the unit sphere or off it. In `(α, β)` the joint's columns are
//! `S q = 0` and `½ S Gᵀ = [I; 0]` ([`velocity_subspace`]): `Tᵀ M T` has
//! a zero row and column for `α` and the body's own axes for `β`
//! (`ω̇ = β − k (qᵀq̇) ω`), and the norm's row `2qᵀ q̈ = b` reads
//! `|q|² α = b`, `α` alone (`crate::equations::velocity`). A free base on
//! the world ([`free_base`]) also has its position's accelerations in its
//! own axes, `p̈ = R̂ z`.

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
            joint: Some(Joint::new(JointKind::Prismatic, coordinate + k, unit)),
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
        joint: Some(Joint::new(
            JointKind::Quaternion,
            coordinate,
            super::spatial::zero(g),
        )),
        inertia,
    }
}

/// The coordinate of `x` when described body `i` is a free joint's body
/// on the world (what [`described`] makes with no parent and the world's
/// own axes): a quaternion joint whose parents are the three massless
/// slides along the world's `x`, `y`, `z`, at its origin. Its position's
/// accelerations are then solved in the base's axes, and its rows
/// `position(body, r) == c` with them (`crate::equations::velocity`).
/// The world is the world up to the bodies fixed to it at its own frame
/// ([`super::grounded`]), which the tree merges into it: a URDF's
/// `floating` joint from a `world` link, or `free(..)` under a body on
/// `fixed`, is the same base as `free(..)` on the world, and
/// [`free_base_in_tree`] finds it in the tree.
pub fn free_base(g: &Graph, described: &[Described], i: usize) -> Option<usize> {
    free_base_by(g, i, |k| {
        let d = described.get(k)?;
        let parent = super::grounded(g, described, d.parent);
        Some((parent, &d.placement, d.joint, &d.inertia))
    })
}

/// [`free_base`] among a tree's movable bodies, where a parent `None` is
/// the world with every body fixed to it merged in ([`super::Tree::new`]).
pub fn free_base_in_tree(g: &Graph, bodies: &[super::Body], i: usize) -> Option<usize> {
    free_base_by(g, i, |k| {
        let b = bodies.get(k)?;
        Some((b.parent, &b.placement, Some(b.joint), &b.inertia))
    })
}

type Part<'a> = (
    Option<usize>,
    &'a Placement,
    Option<super::Joint>,
    &'a Inertia,
);

fn free_base_by<'a>(g: &Graph, i: usize, get: impl Fn(usize) -> Option<Part<'a>>) -> Option<usize> {
    let (mut parent, placement, joint, _) = get(i)?;
    let joint = joint?;
    if joint.kind != JointKind::Quaternion || !placement.is_identity(g) {
        return None;
    }
    for k in (0..3).rev() {
        let (up, placement, slide, inertia) = get(parent?)?;
        let slide = slide?;
        let axis_is_k = (0..3).all(|m| match g.as_num(slide.axis[m]) {
            Some(a) if m == k => a.is_one(),
            Some(a) => a.is_zero(),
            None => false,
        });
        if slide.kind != JointKind::Prismatic
            || slide.coordinate + 3 - k != joint.coordinate
            || !axis_is_k
            || !placement.is_identity(g)
            || !inertia.is_zero(g)
        {
            return None;
        }
        parent = up;
    }
    parent.is_none().then(|| joint.coordinate - 3)
}

/// The quaternion's four coordinates as expressions, `w` at `first`.
pub fn coordinates(g: &mut Graph, first: usize) -> [Id; 4] {
    [0, 1, 2, 3].map(|k| g.sym(Sym::Coord(first + k)))
}

/// `R̂(q) = R(q/|q|)`, the body's axes in its parent's:
/// `I + k (w ṽ + ṽ²)` with `k = 2/|q|²`, a rotation wherever `q ≠ 0`
/// (on the unit sphere it is the familiar `I + 2w ṽ + 2ṽ²`). Normalized,
/// the body stays rigid off the sphere, `Ṙ̂ = R̂ ω̃` with the joint's
/// `ω = 2 G q̇ / |q|²` ([`subspace`]), and `R̂ᵀR̂ = I` holds of the numbers
/// whatever `q`.
pub fn rotation(g: &mut Graph, q: [Id; 4]) -> M3 {
    let [w, x, y, z] = q;
    let k = twice_inverse_norm(g, q);
    let mut prod = |a: Id, b: Id| {
        let ab = g.mul(&[k, a, b]);
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

/// `k = 2/|q|²`, the scale of [`rotation`] and [`subspace`].
pub fn twice_inverse_norm(g: &mut Graph, q: [Id; 4]) -> Id {
    let two = g.int(2);
    let s = squared_norm(g, q);
    let s = super::spatial::hold(g, s);
    g.div(two, s)
}

/// The four columns `Sₖ = [k Gₖ; 0]` (`k = 2/|q|²`) of the joint's
/// motion subspace, in the body's frame: `ω = S q̇ = 2 G q̇ / |q|²`.
pub fn subspace(g: &mut Graph, q: [Id; 4]) -> [Spatial; 4] {
    let [w, x, y, z] = q;
    let columns: [V3; 4] = [
        [g.neg(x), g.neg(y), g.neg(z)],
        [w, g.neg(z), y],
        [z, w, g.neg(x)],
        [g.neg(y), x, w],
    ];
    let zero = super::spatial::zero(g);
    let k = twice_inverse_norm(g, q);
    columns.map(|c| Spatial {
        angular: super::spatial::scale(g, k, c),
        linear: zero,
    })
}

/// `Σₖ Ṡₖ q̇ₖ = −(2 qᵀq̇ / |q|²) ω`, the angular part of the joint's
/// velocity-product term (`ω = S q̇`, the joint's own angular velocity;
/// `G(q̇) q̇ = 0`, so only `k`'s rate remains). Zero on the norm's
/// velocity constraint `qᵀq̇ = 0`, not off it.
pub fn subspace_rate(g: &mut Graph, q: [Id; 4], rates: [Id; 4], omega: V3) -> V3 {
    let products: Vec<Id> = q.iter().zip(&rates).map(|(&a, &b)| g.mul2(a, b)).collect();
    let dot = g.add(&products);
    let k = twice_inverse_norm(g, q);
    let minus = g.int(-1);
    let factor = g.mul(&[minus, k, dot]);
    super::spatial::scale(g, factor, omega)
}

/// The joint's angular columns in the joint frame's axes, `R(q/|q|) k Gₘ =
/// k Eₘ` with `E(q)` the left quaternion matrix (`ω_parent = 2 E q̇ / |q|²`,
/// `q = (w, x, y, z)`): the columns of [`subspace`] carried out of the body
/// without the rotation's products.
pub fn parent_columns(g: &mut Graph, q: [Id; 4]) -> [V3; 4] {
    let [w, x, y, z] = q;
    let columns: [V3; 4] = [
        [g.neg(x), g.neg(y), g.neg(z)],
        [w, z, g.neg(y)],
        [g.neg(z), w, x],
        [y, g.neg(x), w],
    ];
    let k = twice_inverse_norm(g, q);
    columns.map(|c| super::spatial::scale(g, k, c))
}

/// The joint's columns for `β` in the velocity coordinates (the module's
/// `½ S Gᵀ`): `eⱼ` in the body's axes, `j = 0, 1, 2`. (`α`'s, `S q`, is
/// zero.)
pub fn velocity_subspace(g: &mut Graph) -> [Spatial; 3] {
    let zero = g.int(0);
    let one = g.int(1);
    let zeros = super::spatial::zero(g);
    [0, 1, 2].map(|j| {
        let mut angular = [zero; 3];
        angular[j] = one;
        Spatial {
            angular,
            linear: zeros,
        }
    })
}

/// `|q|²`: the scale of the norm's constraint.
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

/// `G(q)`, 3 × 4: `ω = k G q̇`, `k = 2/|q|²` (the module's).
pub fn g_matrix(g: &mut Graph, q: [Id; 4]) -> [[Id; 4]; 3] {
    G_PATTERN.map(|row| row.map(|(plus, k)| if plus { q[k] } else { g.neg(q[k]) }))
}

/// `|q|² − 1`, the norm's constraint.
pub fn norm(g: &mut Graph, q: [Id; 4]) -> Id {
    let sum = squared_norm(g, q);
    let one = g.int(1);
    g.sub(sum, one)
}
