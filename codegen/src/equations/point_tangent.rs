//! Part of stage 3: the tangents' terms of the rows `position(body, r) == c`
//! under a free base ([`super::in_base`]), from the point's motion and its
//! partials by the recursions ([`crate::bodies::point_motion`]) instead
//! of `A`'s and `b`'s entries differentiated one by one (`super::tangent`).
//!
//! A point's three rows of the model are `u = A q̈ − b = p̈ + R̂ V` with
//! `V = ω̇ × r + r̈ᵣ + ω × (ω × r) + 2 ω × ṙᵣ` the point's acceleration in
//! the base's axes (`ω̇ = e − κ ω`, `e = k G q̈₍q₎`, `κ = k qᵀq̇`; `r`, `ṙᵣ`,
//! `r̈ᵣ` its position, velocity and acceleration relative to the base;
//! `ω`, `k`, `G` of `super::in_base`), and what its multipliers do to the
//! coordinates is `W = Aᵀλ`: `λ` on the base's position,
//! `(k Gₗ)·(r × λ′)` on the quaternion's `qₗ`, `Jⱼ·λ′` on a joint `j`
//! between, with `λ′ = R̂ᵀλ`. The tangent systems read `b̃ᵥ = −∂u/∂v` and
//! `∂W/∂v` at fixed `q̈` and `λ`. With `∂R̂/∂qₘ = R̂ (k Gₘ)^` and
//! `ṙ = ṙᵣ + ω × r`:
//!
//! - by a coordinate or rate of the path, `−R̂ ∂V` of the recursions;
//! - by the quaternion's `qₘ`, `−R̂ ((k Gₘ) × V + (∂ω̇ + ω × ∂ω) × r + 2 ∂ω × ṙ)`,
//!   and by its rate the same without the first term (`∂ω`, `∂ω̇` of
//!   their expressions);
//! - `∂Wⱼ/∂qᵢ = a_min · c_max` (the Hessian of `r`,
//!   `crate::bodies::point_motion`), with `cⱼ = Σ Jⱼ × λ′` over the
//!   body's points;
//! - `∂Wⱼ/∂qₘ = ∂W₍q₎ₘ/∂qⱼ = (k Gₘ)·cⱼ` (`∂λ′/∂qₘ = λ′ × k Gₘ`);
//! - `W₍q₎` by the quaternion's coordinates, of its expressions.
//!
//! `u` and `W` depend on nothing else. Exact, not approximate: they are
//! the model's own rows, rewritten.

use super::in_base::{turning, InBaseRows};
use crate::bodies::free;
use crate::bodies::point_motion::{point_motion, PathColumn, PointMotion};
use crate::bodies::spatial::{self, cross, Spatial, V3};
use crate::expr::diff::Differentiator;
use crate::expr::{Graph, Id, Sym};

/// The terms of the rows that [`point_tangents`] takes over, per column
/// `q₁ … qₙ, q̇₁ … q̇ₙ`.
pub struct PointTangents {
    /// The model's rows whose `A` and `b` are not to be differentiated
    /// entry by entry.
    pub rows: Vec<usize>,
    /// `[column]`: `(i, ∂Wᵢ/∂v)`, added to `F̃ᵢ`.
    pub forces: Vec<Vec<(usize, Id)>>,
    /// `[column]`: `(r, b̃ᵣ)`.
    pub rhs: Vec<Vec<(usize, Id)>>,
    /// `(r, j, ∂ψᵣ/∂qⱼ)` of the velocity-level rows `ψ = ṗ + R̂ ṙ`: every
    /// entry of `rows` that can be nonzero.
    pub velocity: Vec<(usize, usize, Id)>,
}

/// The base's quantities every point under it reads.
struct Base {
    /// `R̂`.
    rotation: spatial::M3,
    /// The columns `k Gₘ`.
    turns: [V3; 4],
    /// `(v₀, a₀) = ([ω; 0], [ω̇; 0])`.
    root: (Spatial, Spatial),
    /// Per coordinate `qₘ` of the quaternion, `(∂ω̇ + ω × ∂ω, 2 ∂ω)`, and
    /// per rate `q̇ₘ` the same by it.
    by_coordinate: [(V3, V3); 4],
    /// `∂ω/∂qₘ`.
    omega_by_coordinate: [V3; 4],
    by_rate: [(V3, V3); 4],
}

/// The terms of every triple of `in_base` whose path is known, over the
/// `2 n` columns of the coordinates and rates.
pub fn point_tangents(g: &mut Graph, in_base: &[InBaseRows], n: usize) -> PointTangents {
    let mut out = PointTangents {
        rows: Vec::new(),
        forces: vec![Vec::new(); 2 * n],
        rhs: vec![Vec::new(); 2 * n],
        velocity: Vec::new(),
    };
    // The points of one body share its path and their forces' sums.
    let mut groups: Vec<(&[PathColumn], Vec<&InBaseRows>)> = Vec::new();
    for rows in in_base {
        let Some(path) = rows.path.as_deref() else {
            continue;
        };
        let same =
            |group: &Vec<&InBaseRows>| group[0].body.0 == rows.body.0 && group[0].w == rows.w;
        match groups.iter_mut().find(|(_, group)| same(group)) {
            Some((_, group)) => group.push(rows),
            None => groups.push((path, vec![rows])),
        }
    }
    let mut d = Differentiator::new();
    for (path, group) in groups {
        let w = group[0].w;
        let base = base(g, &mut d, w);
        let mut sums = Sums::new(g, path.len());
        for rows in group {
            let motion = point_motion(g, path, rows.point, base.root);
            let at = Point {
                base: &base,
                rows,
                motion: &motion,
            };
            point_rows(g, &at, w, &mut out);
            point_velocity(g, &at, w, &mut out);
            sums.add(g, &base, rows, &motion);
            out.rows.extend(rows.rows);
        }
        body_forces(g, &mut d, (&base, w, path), &sums, &mut out);
    }
    out
}

/// One point's rows, with what they read.
struct Point<'a> {
    base: &'a Base,
    rows: &'a InBaseRows,
    motion: &'a PointMotion,
}

/// `b̃` of one point's three rows in every column where it can be nonzero:
/// the path's coordinates and rates and the quaternion's.
fn point_rows(g: &mut Graph, at: &Point, w: usize, out: &mut PointTangents) {
    let (base, rows, motion) = (at.base, at.rows, at.motion);
    let n = out.rhs.len() / 2;
    let mut write = |g: &mut Graph, column: usize, v: V3| {
        let turned = spatial::mat_vec(g, &base.rotation, v);
        for (&row, &e) in rows.rows.iter().zip(&turned) {
            let minus = g.neg(e);
            push(g, &mut out.rhs[column], (row, minus));
        }
    };
    // By the path's coordinates and rates, a coordinate's columns summed
    // (a mimic's several).
    let mut by_q: Vec<(usize, V3)> = Vec::new();
    let mut by_rate: Vec<(usize, V3)> = Vec::new();
    for col in &motion.columns {
        accumulate(g, &mut by_q, col.coordinate, col.acceleration_by_q);
        accumulate(g, &mut by_rate, col.coordinate, col.acceleration_by_rate);
    }
    for (c, v) in by_q {
        write(g, c, v);
    }
    for (c, v) in by_rate {
        write(g, n + c, v);
    }
    let r = rows.point;
    // By the quaternion's coordinates (turning `R̂` too) and rates.
    for m in 0..4 {
        let (turn, twice) = base.by_coordinate[m];
        let moved = [
            cross(g, base.turns[m], motion.acceleration),
            cross(g, turn, r),
            cross(g, twice, motion.velocity),
        ];
        let v = spatial::sum(g, &moved);
        write(g, w + m, v);
        let (turn, twice) = base.by_rate[m];
        let moved = [cross(g, turn, r), cross(g, twice, motion.velocity)];
        let v = spatial::sum(g, &moved);
        write(g, n + w + m, v);
    }
}

/// `∂ψ/∂q` of one point's three velocity-level rows `ψ = ṗ + R̂ ṙ`:
/// `R̂ ∂ṙ` by the path's coordinates, `R̂ ((k Gₘ) × ṙ + ∂ω × r)` by the
/// quaternion's.
fn point_velocity(g: &mut Graph, at: &Point, w: usize, out: &mut PointTangents) {
    let (base, rows, motion) = (at.base, at.rows, at.motion);
    let mut velocity: Vec<(usize, V3)> = Vec::new();
    for col in &motion.columns {
        accumulate(g, &mut velocity, col.coordinate, col.velocity_by_q);
    }
    for m in 0..4 {
        let parts = [
            cross(g, base.turns[m], motion.velocity),
            cross(g, base.omega_by_coordinate[m], rows.point),
        ];
        velocity.push((w + m, spatial::sum(g, &parts)));
    }
    for (c, v) in velocity {
        let turned = spatial::mat_vec(g, &base.rotation, v);
        for (&row, &e) in rows.rows.iter().zip(&turned) {
            if !g.is_zero(e) {
                out.velocity.push((row, c, e));
            }
        }
    }
}

/// The sums over a body's points of `Jⱼ × λ′` (`cⱼ`, per column of the
/// path) and of `r × λ′` (`ρ`).
struct Sums {
    columns: Vec<V3>,
    rho: V3,
}

impl Sums {
    fn new(g: &mut Graph, columns: usize) -> Sums {
        let zero = spatial::zero(g);
        Sums {
            columns: vec![zero; columns],
            rho: zero,
        }
    }

    fn add(&mut self, g: &mut Graph, base: &Base, rows: &InBaseRows, motion: &PointMotion) {
        let lam: V3 = rows.rows.map(|i| g.sym(Sym::Multiplier(i)));
        let turned = spatial::mat_t_vec(g, &base.rotation, lam);
        let lam = spatial::hold3(g, turned);
        for (c, col) in self.columns.iter_mut().zip(&motion.columns) {
            let moment = cross(g, col.jacobian, lam);
            *c = spatial::add(g, *c, moment);
        }
        let moment = cross(g, rows.point, lam);
        self.rho = spatial::add(g, self.rho, moment);
    }
}

/// `∂W/∂v` of a body's points: the joints' rows by the path's and the
/// quaternion's coordinates and the quaternion's rows by the path's (the
/// module docs), the quaternion's rows by the rest as expressions.
fn body_forces(
    g: &mut Graph,
    d: &mut Differentiator,
    (base, w, path): (&Base, usize, &[PathColumn]),
    sums: &Sums,
    out: &mut PointTangents,
) {
    let n = out.forces.len() / 2;
    let sums_c: Vec<V3> = sums.columns.iter().map(|&c| spatial::hold3(g, c)).collect();
    for (i, pi) in path.iter().enumerate() {
        // `∂Wⱼ/∂qᵢ = ∂Wᵢ/∂qⱼ = aᵢ · cⱼ` for `i` not after `j`.
        for (j, pj) in path.iter().enumerate().skip(i) {
            let t = spatial::dot(g, pi.column.angular, sums_c[j]);
            push(g, &mut out.forces[pi.coordinate], (pj.coordinate, t));
            if j != i {
                push(g, &mut out.forces[pj.coordinate], (pi.coordinate, t));
            }
        }
        // `∂W₍q₎ₘ/∂qᵢ = ∂Wᵢ/∂qₘ = (k Gₘ) · cᵢ`.
        for (m, &turn) in base.turns.iter().enumerate() {
            let t = spatial::dot(g, turn, sums_c[i]);
            push(g, &mut out.forces[pi.coordinate], (w + m, t));
            push(g, &mut out.forces[w + m], (pi.coordinate, t));
        }
    }
    let rho = spatial::hold3(g, sums.rho);
    let quaternion: Vec<Id> = base
        .turns
        .iter()
        .map(|&t| spatial::dot(g, t, rho))
        .collect();
    let order = g.reachable(&quaternion);
    let on_path = |c: usize| path.iter().any(|p| p.coordinate == c);
    for c in (0..n).filter(|&c| !on_path(c)) {
        let var = Sym::Coord(c);
        for &id in &order {
            d.partial(g, id, var);
        }
        for (m, &e) in quaternion.iter().enumerate() {
            let de = d.partial(g, e, var);
            push(g, &mut out.forces[c], (w + m, de));
        }
    }
}

/// `(row, e)` into a column's terms, unless `e` is zero.
fn push(g: &Graph, terms: &mut Vec<(usize, Id)>, (row, e): (usize, Id)) {
    if !g.is_zero(e) {
        terms.push((row, e));
    }
}

/// `v` added to the coordinate's entry of `sums`.
fn accumulate(g: &mut Graph, sums: &mut Vec<(usize, V3)>, coordinate: usize, v: V3) {
    match sums.iter_mut().find(|(c, _)| *c == coordinate) {
        Some((_, total)) => *total = spatial::add(g, *total, v),
        None => sums.push((coordinate, v)),
    }
}

/// [`Base`] of the free base whose quaternion's `w` is `w`.
fn base(g: &mut Graph, d: &mut Differentiator, w: usize) -> Base {
    let t = turning(g, w);
    let rotation = free::rotation(g, t.q);
    let turns = [0, 1, 2, 3].map(|m| {
        let column: V3 = [0, 1, 2].map(|l| g.mul2(t.k, t.big_g[l][m]));
        spatial::hold3(g, column)
    });
    // `ω̇ = e − κ ω`.
    let mut spin = spatial::zero(g);
    for (m, &column) in turns.iter().enumerate() {
        let accel = g.sym(Sym::Accel(w + m));
        let part = spatial::scale(g, accel, column);
        spin = spatial::add(g, spin, part);
    }
    let minus_kappa = t.minus_kappa(g);
    let slowed = spatial::scale(g, minus_kappa, t.omega);
    let spin = spatial::add(g, spin, slowed);
    let spin = spatial::hold3(g, spin);
    let zero = spatial::zero(g);
    let root = (
        Spatial {
            angular: t.omega,
            linear: zero,
        },
        Spatial {
            angular: spin,
            linear: zero,
        },
    );
    let mut by = |g: &mut Graph, var: Sym| {
        let partial =
            |g: &mut Graph, d: &mut Differentiator, v: V3| v.map(|e| d.partial(g, e, var));
        let (omega, spin) = (partial(g, d, t.omega), partial(g, d, spin));
        let turned = cross(g, t.omega, omega);
        let turn = spatial::add(g, spin, turned);
        let two = g.int(2);
        let twice = spatial::scale(g, two, omega);
        (spatial::hold3(g, turn), spatial::hold3(g, twice))
    };
    let by_coordinate = [0, 1, 2, 3].map(|m| by(g, Sym::Coord(w + m)));
    let by_rate = [0, 1, 2, 3].map(|m| by(g, Sym::Vel(w + m)));
    let omega_by_coordinate = [0, 1, 2, 3].map(|m| {
        let partial = t.omega.map(|e| d.partial(g, e, Sym::Coord(w + m)));
        spatial::hold3(g, partial)
    });
    Base {
        rotation,
        turns,
        root,
        by_coordinate,
        omega_by_coordinate,
        by_rate,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free base with a leg of a tilted revolute, a prismatic and a
    /// helical joint down to a fixed foot held at two points, and an arm
    /// of two revolute joints held at one: every kind of constant column,
    /// a body between the joints and the point, and two points sharing
    /// their body's sums.
    const WALKER: &str = "
        pub struct Walker {
            parameters: [c0, c1, c2, c3, c4, c5, c6, c7, c8],
            bodies: [
                base { joint: free(x, y, z, qw, qx, qy, qz), mass: 2.0, inertia: diag[0.1, 0.2, 0.3] },
                hip {
                    parent: base, joint: revolute(a, [0.6, 0.8, 0.0]),
                    xyz: [0.2, 0.1, -0.05], rpy: [0.3, -0.2, 0.5],
                    mass: 0.3, inertia: diag[0.01, 0.02, 0.03],
                },
                slide {
                    parent: hip, joint: prismatic(s, [0.0, 0.0, 1.0]), xyz: [0.0, 0.05, -0.1],
                    mass: 0.2, inertia: diag[0.01, 0.01, 0.02],
                },
                shin {
                    parent: slide, joint: helical(h, [0.0, 1.0, 0.0], 0.05),
                    xyz: [0.1, 0.0, -0.2], rpy: [0.1, 0.2, 0.3],
                    mass: 0.1, inertia: diag[0.01, 0.02, 0.01],
                },
                foot { parent: shin, joint: fixed, xyz: [0.0, 0.0, -0.15], rpy: [0.0, 0.4, 0.0] },
                arm {
                    parent: base, joint: revolute(b, [0.0, 0.0, 1.0]), xyz: [-0.2, 0.0, 0.0],
                    mass: 0.3, inertia: diag[0.02, 0.01, 0.02],
                },
                hand {
                    parent: arm, joint: revolute(c, [1.0, 0.0, 0.0]), xyz: [0.0, 0.3, 0.0],
                    mass: 0.2, inertia: diag[0.01, 0.01, 0.01],
                },
            ],
            constraints: [
                position(foot, [0.01, 0.02, -0.03]) == [c0, c1, c2],
                position(foot, [0.05, -0.02, -0.03]) == [c3, c4, c5],
                position(hand, [0.0, 0.1, 0.0]) == [c6, c7, c8],
            ],
        }";

    /// The Walker's equations, its point rows and their terms.
    fn walker() -> (super::super::Equations, Graph, PointTangents) {
        let eq = crate::analyse(WALKER.parse().expect("tokens")).expect("expands");
        let mut g = eq.system.graph.clone();
        let n = eq.system.dof();
        let in_base = super::super::in_base::rows(&mut g, &eq.system.constraints, n);
        assert_eq!(in_base.len(), 3);
        assert!(in_base.iter().all(|rows| rows.path.is_some()));
        let terms = point_tangents(&mut g, &in_base, n);
        assert_eq!(terms.rows.len(), 9);
        (eq, g, terms)
    }

    /// Each `(got, expected)` pair agrees at random states (seed `stream`),
    /// off the quaternion's unit sphere; the number of nonzero ones.
    fn agree(g: &Graph, pairs: &[(Id, Id)], stream: u64, what: &str) -> usize {
        let ids: Vec<Id> = pairs.iter().flat_map(|&(a, b)| [a, b]).collect();
        let mut nonzero = 0;
        for point in crate::numeric::rng::sample_points(stream) {
            let values = g.eval(&ids, &point);
            for (k, pair) in values.chunks(2).enumerate() {
                let (got, expected) = (pair[0], pair[1]);
                assert!(
                    (got - expected).abs() <= 1e-9 * (1.0 + expected.abs()),
                    "{what}, entry {k}: {got} against {expected}"
                );
                nonzero += usize::from(expected != 0.0);
            }
        }
        nonzero
    }

    /// The sum of the terms of `row`, as one expression.
    fn total(g: &mut Graph, terms: &[(usize, Id)], row: usize) -> Id {
        let parts: Vec<Id> = terms.iter().filter(|t| t.0 == row).map(|t| t.1).collect();
        g.add(&parts)
    }

    /// The terms from the points' motion are those of `A`'s and `b`'s
    /// entries differentiated one by one, `∂b/∂v − (∂A/∂v) q̈` and
    /// `(∂A/∂v)ᵀ λ`, in every column.
    #[test]
    fn the_points_terms_are_those_of_the_rows_entries() {
        let (eq, mut g, terms) = walker();
        let n = eq.system.dof();
        let mut d = Differentiator::new();
        let minus = g.int(-1);
        let mut checked = 0;
        for c in 0..2 * n {
            let var = if c < n {
                Sym::Coord(c)
            } else {
                Sym::Vel(c - n)
            };
            let mut pairs = Vec::new();
            for &r in &terms.rows {
                let mut expected = vec![d.partial(&mut g, eq.b[r], var)];
                for (i, &a) in eq.a[r].iter().enumerate() {
                    let da = d.partial(&mut g, a, var);
                    let qdd = g.sym(Sym::Accel(i));
                    expected.push(g.mul(&[minus, da, qdd]));
                }
                let expected = g.add(&expected);
                pairs.push((total(&mut g, &terms.rhs[c], r), expected));
            }
            for i in 0..n {
                let mut expected = Vec::new();
                for &r in &terms.rows {
                    let da = d.partial(&mut g, eq.a[r][i], var);
                    let lam = g.sym(Sym::Multiplier(r));
                    expected.push(g.mul2(da, lam));
                }
                let expected = g.add(&expected);
                pairs.push((total(&mut g, &terms.forces[c], i), expected));
            }
            checked += agree(&g, &pairs, 7, &format!("column {c}"));
        }
        // Not a comparison of zeros.
        assert!(checked > 500, "{checked} nonzero entries compared");
    }

    /// `∂ψ/∂q` of the points' velocity-level rows is that of `ψ`'s
    /// expressions.
    #[test]
    fn the_points_velocity_jacobian_is_that_of_the_rows() {
        let (eq, mut g, terms) = walker();
        let mut d = Differentiator::new();
        let mut pairs = Vec::new();
        for &r in &terms.rows {
            for j in 0..eq.system.dof() {
                let expected = d.partial(&mut g, eq.velocity_constraints[r], Sym::Coord(j));
                let got: Vec<(usize, Id)> = (terms.velocity.iter())
                    .filter(|v| (v.0, v.1) == (r, j))
                    .map(|v| (r, v.2))
                    .collect();
                pairs.push((total(&mut g, &got, r), expected));
            }
        }
        let nonzero = agree(&g, &pairs, 8, "∂ψ/∂q");
        assert!(nonzero > 100, "{nonzero} nonzero entries of ∂ψ/∂q compared");
    }
}
