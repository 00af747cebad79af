//! Kinematics of named frames and of the centre of mass, as expressions of
//! `q` (and `q̇`): what a controller reads (task-space placements,
//! Jacobians, velocities and acceleration biases), built from the world
//! frames of [`super::world_frames`] and differentiated exactly by
//! `crate::expr::diff`.
//!
//! Conventions are Pinocchio's `LOCAL_WORLD_ALIGNED`: a frame's velocity is
//! `[v; ω]`, the velocity of its origin and its angular velocity, both in
//! world axes, and `J` maps `q̇` to it. Where a joint is a quaternion the
//! columns are by the quaternion's rates (`q̇`, as everywhere in this
//! library), the rotation being `R(q/|q|)`, so a rate along `q` itself moves
//! nothing.

use super::spatial::{self, M3, V3};
use super::{Described, Placement};
use crate::expr::diff::{AtRest, Differentiator};
use crate::expr::{Graph, Id, Sym};

/// One named frame's expressions.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The frame's name as written.
    pub name: String,
    /// `R`: the frame's axes in the world, as columns.
    pub rotation: M3,
    /// `p`: its origin in the world.
    pub position: V3,
    /// `J`, 6 × n, rows `[v; ω]` in world axes (`LOCAL_WORLD_ALIGNED`).
    pub jacobian: Vec<Vec<Id>>,
    /// `J q̇ = [ṗ; ω]`.
    pub velocity: Vec<Id>,
    /// `J̇ q̇ = [p̈; ω̇]` at `q̈ = 0`: the classical acceleration's bias.
    pub bias: Vec<Id>,
}

/// The centre of mass of every body, its Jacobian and velocity, and the
/// centroidal momentum.
#[derive(Clone, Debug)]
pub struct CenterOfMass {
    /// `c = Σ mᵢ cᵢ / Σ mᵢ`, world coordinates.
    pub position: V3,
    /// `∂c/∂q`, 3 × n.
    pub jacobian: Vec<Vec<Id>>,
    /// `ċ = (∂c/∂q) q̇`.
    pub velocity: V3,
    /// `A_G = ∂h_G/∂q̇`, 6 × n: the centroidal momentum matrix, rows
    /// `[linear; angular about c]` in world axes.
    pub centroidal_map: Vec<Vec<Id>>,
    /// `Ȧ_G q̇`: the rate of `h_G = A_G q̇` at `q̈ = 0`.
    pub centroidal_bias: Vec<Id>,
}

/// What the `frames` section asks for: each named frame, and the centre of
/// mass that comes with the section.
#[derive(Clone, Debug)]
pub struct Kinematics {
    /// The named frames, in the order written.
    pub frames: Vec<Frame>,
    /// The centre of mass; `None` where the bodies have no mass at all.
    pub center_of_mass: Option<CenterOfMass>,
}

/// The frame placed by `offset` in a body whose world frame is `body`.
pub fn frame(g: &mut Graph, name: String, body: &Placement, offset: &Placement, n: usize) -> Frame {
    let placed = body.then(g, offset);
    let rotation = placed.rotation.map(|row| spatial::hold3(g, row));
    let position = spatial::hold3(g, placed.translation);
    let mut partials = Differentiator::new();
    let mut jacobian: Vec<Vec<Id>> = (0..6).map(|_| Vec::with_capacity(n)).collect();
    for k in 0..n {
        let linear = position.map(|p| partials.partial(g, p, Sym::Coord(k)));
        let turned = rotation.map(|row| row.map(|r| partials.partial(g, r, Sym::Coord(k))));
        let angular = spin(g, &turned, &rotation);
        for (row, &e) in jacobian.iter_mut().zip(linear.iter().chain(&angular)) {
            row.push(e);
        }
    }
    let mut rate = AtRest::default();
    let linear = position.map(|p| rate.derivative(g, p));
    let turned = rotation.map(|row| row.map(|r| rate.derivative(g, r)));
    let angular = spin(g, &turned, &rotation);
    let velocity: Vec<Id> = linear
        .iter()
        .chain(&angular)
        .map(|&v| spatial::hold(g, v))
        .collect();
    // `q̇` is held by `AtRest`: the derivative of `J(q) q̇` along the motion
    // at `q̈ = 0` is `J̇ q̇`.
    let bias = velocity.iter().map(|&v| rate.derivative(g, v)).collect();
    Frame {
        name,
        rotation,
        position,
        jacobian,
        velocity,
        bias,
    }
}

/// `vee(Ṙ Rᵀ)`, the angular velocity in world axes of a frame turned by
/// `R` at the rate `Ṙ`, as the axial vector of `½ (Ṙ Rᵀ − R Ṙᵀ)`: `R` is
/// orthogonal for every `q`, so `Ṙ Rᵀ` is skew and this is exact.
fn spin(g: &mut Graph, rate: &M3, rotation: &M3) -> V3 {
    let m = spatial::mat_mul(g, rate, &spatial::transpose(rotation));
    let two = g.int(2);
    let mut axial = |i: usize, j: usize| {
        let d = g.sub(m[i][j], m[j][i]);
        g.div(d, two)
    };
    [axial(2, 1), axial(0, 2), axial(1, 0)]
}

/// The centre of mass of the described bodies (fixed ones included) in
/// the world, `Σ (mᵢ pᵢ + Rᵢ hᵢ) / Σ mᵢ` with `hᵢ = mᵢ cᵢ` in the body's
/// axes, its Jacobian `∂c/∂q`, its velocity and the centroidal momentum
/// ([`centroidal`]); `None` where the total mass is the constant zero.
pub fn center_of_mass(
    g: &mut Graph,
    described: &[Described],
    world: &[Placement],
    n: usize,
) -> Option<CenterOfMass> {
    let mut masses = Vec::new();
    let mut moments: Vec<V3> = Vec::new();
    for (d, frame) in described.iter().zip(world) {
        if g.is_zero(d.inertia.mass) {
            continue;
        }
        let at_origin = spatial::scale(g, d.inertia.mass, frame.translation);
        let offset = spatial::mat_vec(g, &frame.rotation, d.inertia.first_moment);
        moments.push(spatial::add(g, at_origin, offset));
        masses.push(d.inertia.mass);
    }
    let total = g.add(&masses);
    if g.is_zero(total) {
        return None;
    }
    let position = [0, 1, 2].map(|i| {
        let terms: Vec<Id> = moments.iter().map(|m| m[i]).collect();
        let sum = g.add(&terms);
        let c = g.div(sum, total);
        spatial::hold(g, c)
    });
    let mut partials = Differentiator::new();
    let jacobian = position
        .iter()
        .map(|&c| {
            (0..n)
                .map(|k| partials.partial(g, c, Sym::Coord(k)))
                .collect()
        })
        .collect();
    let mut rate = AtRest::default();
    let velocity = position.map(|c| {
        let v = rate.derivative(g, c);
        spatial::hold(g, v)
    });
    let momentum = centroidal(g, described, world, &position, &mut rate);
    let centroidal_map = (0..6).map(|_| Vec::with_capacity(n)).collect();
    let centroidal_map = (0..n).fold(centroidal_map, |mut rows: Vec<Vec<Id>>, k| {
        for (row, &h) in rows.iter_mut().zip(&momentum) {
            row.push(partials.partial(g, h, Sym::Vel(k)));
        }
        rows
    });
    // `h_G` is `A_G(q) q̇`: its rate at `q̈ = 0` is `Ȧ_G q̇`.
    let centroidal_bias = momentum.iter().map(|&h| rate.derivative(g, h)).collect();
    Some(CenterOfMass {
        position,
        jacobian,
        velocity,
        centroidal_map,
        centroidal_bias,
    })
}

/// The centroidal momentum `h_G = [P; L_G]` in world axes: the total
/// linear momentum and the angular momentum about the centre of mass `c`,
/// linear in `q̇`. Each movable body (those on fixed joints merged into it,
/// as [`super::Tree::new`] merges them) contributes its spatial momentum
/// `I v`, its twist `v = [vee(Rᵀ Ṙ); Rᵀ ṗ]` in its own axes at its origin
/// from the rates of its world frame `(R, p)`, carried to the world's
/// origin (`f = R f_b`, `n = R n_b + p × f`); then `L_G = L_O − c × P`.
/// Bodies fixed to the world move with nothing and are left out.
fn centroidal(
    g: &mut Graph,
    described: &[Described],
    world: &[Placement],
    c: &V3,
    rate: &mut AtRest,
) -> [Id; 6] {
    let z = spatial::zero(g);
    let tree = super::Tree::new(g, described, z);
    let movable = described
        .iter()
        .zip(world)
        .filter(|(d, _)| d.joint.is_some());
    let (mut linear, mut angular) = (Vec::new(), Vec::new());
    for (body, (_, frame)) in tree.bodies.iter().zip(movable) {
        if body.inertia.is_zero(g) {
            continue;
        }
        let r = &frame.rotation;
        let p_rate = frame.translation.map(|p| rate.derivative(g, p));
        let r_rate = r.map(|row| row.map(|e| rate.derivative(g, e)));
        let twist = spatial::Spatial {
            angular: body_spin(g, &r_rate, r),
            linear: spatial::mat_t_vec(g, r, p_rate),
        };
        let own = body.inertia.apply(g, twist);
        let f = spatial::mat_vec(g, r, own.linear);
        let turned = spatial::mat_vec(g, r, own.angular);
        let moment = spatial::cross(g, frame.translation, f);
        linear.push(f);
        angular.push(spatial::add(g, turned, moment));
    }
    let p = sum(g, &linear);
    let about_origin = sum(g, &angular);
    let shift = spatial::cross(g, *c, p);
    let l = spatial::sub(g, about_origin, shift);
    let l = spatial::hold3(g, l);
    [p[0], p[1], p[2], l[0], l[1], l[2]]
}

/// `Σ vᵢ`, each entry held.
fn sum(g: &mut Graph, parts: &[V3]) -> V3 {
    [0, 1, 2].map(|i| {
        let terms: Vec<Id> = parts.iter().map(|v| v[i]).collect();
        let s = g.add(&terms);
        spatial::hold(g, s)
    })
}

/// `vee(Rᵀ Ṙ)`, the angular velocity in the body's own axes of a frame
/// turned by `R` at the rate `Ṙ`, as the axial vector of
/// `½ (Rᵀ Ṙ − Ṙᵀ R)` (exact as in [`spin`]).
fn body_spin(g: &mut Graph, rate: &M3, rotation: &M3) -> V3 {
    let (r, d) = (spatial::transpose(rotation), spatial::transpose(rate));
    let two = g.int(2);
    let mut axial = |i: usize, j: usize| {
        let a = spatial::dot(g, r[i], d[j]);
        let b = spatial::dot(g, d[i], r[j]);
        let diff = g.sub(a, b);
        g.div(diff, two)
    };
    [axial(2, 1), axial(0, 2), axial(1, 0)]
}
