//! The quaternions' velocity coordinates (`equations::velocity`), checked
//! numerically against the model's own `M`, `F` and `A` at the generator's
//! random sample points (arbitrary values, so every quaternion is off the
//! unit sphere): `TᵀMT` from the composite-rigid-body algorithm with the
//! columns `S T` equals `T` times `M` times `T` formed from numbers, and
//! `TᵀF`, `A T` likewise, with `T = ½ [q, Gᵀ]` written out here from
//! `G = [−v, w I − ṽ]` and, for a free base, `p̈ = R̂ z`; each norm's row of
//! `A T` is `|q|²` on `α` alone. The model's `A` and `b` equal the symbolic
//! derivatives of φ (the rows of a point under a free base are a closed
//! form), and those rows in the base's axes are `R̂ᵀ A T` and `R̂ᵀ b`.
//! For the quadruped (one free joint), a pinned top (one, with a point
//! fixed), two free bodies joined at a point (two) and a ball on a
//! spherical joint at an arm's tip, a point of it on a plane (one, inside
//! the chain); `gauss` takes the velocity form for each. (It did not for
//! the last two while the saddle-point order was tested at the raw sample
//! points: off the unit sphere their `M` has pivots of either sign, and no
//! order passed; the points are now put on the sphere.)

use constrained_codegen::equations::in_base::rows;
use constrained_codegen::equations::mass_inverse::MassInverse;
use constrained_codegen::equations::velocity::transformed;
use constrained_codegen::expr::diff::Differentiator;
use constrained_codegen::expr::{Id, Sym};
use constrained_codegen::model::Level;
use constrained_codegen::numeric::rng::sample_points;
use constrained_codegen::{analyse_with, Options};

const PINNED_TOP: &str = "
    pub struct PinnedTop {
        parameters: [a, c, m, l],
        bodies: [
            top {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: m,
                com: [0.0, 0.0, l],
                inertia: diag[a - m * l * l, a - m * l * l, c],
            },
        ],
        constraints: [position(top, [0.0, 0.1, 0.0]) == [0.0, 0.0, 0.0]],
    }";

const JOINED: &str = "
    pub struct Joined {
        bodies: [
            a {
                joint: free(xa, ya, za, wa, ia, ja, ka),
                mass: 2.0,
                inertia: diag[0.1, 0.2, 0.3],
            },
            b {
                joint: free(xb, yb, zb, wb, ib, jb, kb),
                mass: 1.5,
                com: [0.0, 0.1, 0.0],
                inertia: diag[0.05, 0.04, 0.02],
            },
        ],
        constraints: [position(a, [0.3, 0.0, 0.0]) == position(b, [0.0, 0.0, -0.2])],
    }";

/// `T` at one point, n × n: the identity but for each quaternion's block.
fn transformation(n: usize, quaternions: &[usize], value: &dyn Fn(Sym) -> f64) -> Vec<Vec<f64>> {
    let mut t: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| f64::from(u8::from(i == j))).collect())
        .collect();
    for &c in quaternions {
        let [w, x, y, z] = [0, 1, 2, 3].map(|k| value(Sym::Coord(c + k)));
        // Rows of G, written out: ω = k G q̇, k = 2/|q|².
        let g = [[-x, w, z, -y], [-y, -z, w, x], [-z, y, -x, w]];
        for k in 0..4 {
            t[c + k][c] = 0.5 * [w, x, y, z][k];
            for j in 0..3 {
                t[c + k][c + 1 + j] = 0.5 * g[j][k];
            }
        }
    }
    t
}

fn close(what: &str, got: f64, want: f64, scale: f64) {
    assert!(
        (got - want).abs() <= 1e-11 * scale.max(1.0),
        "{what}: {got} against {want}"
    );
}

/// `A` and `b` of every constraint by the symbolic derivative of φ itself
/// (the generator's own rows of points under a free base are a closed form,
/// checked against these).
fn derivatives(eq: &mut constrained_codegen::equations::Equations) -> (Vec<Vec<Id>>, Vec<Id>) {
    let n = eq.system.forces.len();
    let mut d = Differentiator::new();
    let g = &mut eq.system.graph;
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for c in &eq.system.constraints {
        let velocity = match c.level {
            Level::Velocity => c.phi,
            Level::Position => d.time_derivative(g, c.phi, n).1,
        };
        let (row, rest) = d.time_derivative(g, velocity, n);
        a.push(row);
        b.push(g.neg(rest));
    }
    (a, b)
}

/// Checks the velocity form of `text` at every sample point; returns how
/// many quaternions it has.
fn check(text: &str) -> usize {
    let tokens: proc_macro2::TokenStream = text.parse().expect("tokens");
    let mut eq = analyse_with(tokens, Options { jacobians: false }).expect("valid");
    let bodies = eq.system.bodies.clone().expect("a tree");
    let terms = eq.velocity.clone().expect("quaternion joints");
    let (velocity_mass, velocity_forces) = (terms.mass, terms.forces);
    let (a, b) = derivatives(&mut eq);
    let (mass, forces) = (eq.system.mass.clone(), eq.system.forces.clone());
    let (n, k) = (forces.len(), a.len());
    let in_base = rows(&mut eq.system.graph, &eq.system.constraints, n);
    let v = transformed(
        &mut eq.system.graph,
        (&velocity_mass, &bodies.tree),
        &velocity_forces,
        &a,
    )
    .expect("each quaternion's norm's row");
    let g = &eq.system.graph;
    let quaternions: Vec<usize> = v.quaternions.iter().map(|&(c, _)| c).collect();
    let mut roots: Vec<Id> = mass.iter().flatten().copied().collect();
    roots.extend(forces.iter().copied());
    roots.extend(a.iter().flatten().copied());
    roots.extend(velocity_mass.iter().flatten().copied());
    roots.extend(v.forces.iter().copied());
    roots.extend(v.a.iter().flatten().copied());
    roots.extend(b.iter().copied());
    roots.extend(eq.a.iter().flatten().copied());
    roots.extend(eq.b.iter().copied());
    for t in &in_base {
        roots.extend(t.a.iter().flatten().copied());
        roots.extend(t.b.iter().copied());
    }
    for point in sample_points(0x7e10_c171) {
        let x = g.eval(&roots, &point);
        let (m, rest) = x.split_at(n * n);
        let (f, rest) = rest.split_at(n);
        let (am, rest) = rest.split_at(k * n);
        let (vm, rest) = rest.split_at(n * n);
        let (vf, rest) = rest.split_at(n);
        let (va, rest) = rest.split_at(k * n);
        let (bm, rest) = rest.split_at(k);
        let (model_a, rest) = rest.split_at(k * n);
        let (model_b, mut rest) = rest.split_at(k);
        let mut t = transformation(n, &quaternions, &point);
        for &(p, _) in &v.free {
            // p̈ = R̂ z, R̂ = R(q/|q|) written out here: I + k (w ṽ + ṽ²),
            // k = 2/|q|², the quaternion right after the position.
            let [w, x, y, z] = [3, 4, 5, 6].map(|c| point(Sym::Coord(p + c)));
            let k = 2.0 / (w * w + x * x + y * y + z * z);
            let r = [
                [
                    1.0 - k * (y * y + z * z),
                    k * (x * y - w * z),
                    k * (x * z + w * y),
                ],
                [
                    k * (x * y + w * z),
                    1.0 - k * (x * x + z * z),
                    k * (y * z - w * x),
                ],
                [
                    k * (x * z - w * y),
                    k * (y * z + w * x),
                    1.0 - k * (x * x + y * y),
                ],
            ];
            for i in 0..3 {
                for j in 0..3 {
                    t[p + i][p + j] = r[i][j];
                }
            }
        }
        let scale = m
            .iter()
            .chain(f)
            .chain(am)
            .chain(bm)
            .fold(0.0_f64, |s, v| s.max(v.abs()));
        for i in 0..n {
            for j in 0..n {
                let want: f64 = (0..n)
                    .flat_map(|p| (0..n).map(move |r| (p, r)))
                    .map(|(p, r)| t[p][i] * m[p * n + r] * t[r][j])
                    .sum();
                close(&format!("TᵀMT ({i}, {j})"), vm[i * n + j], want, scale);
            }
            let want: f64 = (0..n).map(|p| t[p][i] * f[p]).sum();
            close(&format!("TᵀF {i}"), vf[i], want, scale);
            for r in 0..k {
                let want: f64 = (0..n).map(|p| am[r * n + p] * t[p][i]).sum();
                close(&format!("A T ({r}, {i})"), va[r * n + i], want, scale);
                close(
                    &format!("A ({r}, {i})"),
                    model_a[r * n + i],
                    am[r * n + i],
                    scale,
                );
            }
        }
        for r in 0..k {
            close(&format!("b {r}"), model_b[r], bm[r], scale);
        }
        for (triple, own) in in_base.iter().enumerate() {
            // R̂ᵀ (A T) and R̂ᵀ b, with the free base's R̂ (the only one).
            let p = v.free.first().expect("a free base").0;
            let (aa, more) = rest.split_at(3 * n);
            let (bb, more) = more.split_at(3);
            rest = more;
            let r_hat = |i: usize, j: usize| t[p + i][p + j];
            for i in 0..3 {
                for j in 0..n {
                    let want: f64 = (0..3).map(|l| r_hat(l, i) * va[own.rows[l] * n + j]).sum();
                    close(
                        &format!("triple {triple}: R̂ᵀ A T ({i}, {j})"),
                        aa[i * n + j],
                        want,
                        scale,
                    );
                }
                let want: f64 = (0..3).map(|l| r_hat(l, i) * bm[own.rows[l]]).sum();
                close(&format!("triple {triple}: R̂ᵀ b {i}"), bb[i], want, scale);
            }
        }
        for &(c, norm) in &v.quaternions {
            let q2: f64 = (0..4).map(|k| point(Sym::Coord(c + k)).powi(2)).sum();
            close("the norm's row at α", va[norm * n + c], q2, 1.0);
            for i in (0..n).filter(|&i| i != c) {
                assert!(g.is_zero(v.a[norm][i]), "the norm's row at {i}");
                assert!(g.is_zero(velocity_mass[c][i]), "TᵀMT's α row at {i}");
            }
        }
    }
    let chosen = match &eq.mass_inverse {
        MassInverse::Auxiliary(f) => f.velocity.is_some(),
        _ => false,
    };
    assert!(chosen, "gauss takes the velocity form");
    v.quaternions.len()
}

#[test]
fn the_quadruped_in_velocity_coordinates_is_its_model_transformed() {
    let text = constrained_codegen::tools::fixtures::quadruped().expect("the quadruped");
    assert_eq!(check(&text), 1);
}

#[test]
fn a_pinned_top_in_velocity_coordinates_is_its_model_transformed() {
    assert_eq!(check(PINNED_TOP), 1);
}

#[test]
fn two_joined_free_bodies_in_velocity_coordinates_are_their_model_transformed() {
    assert_eq!(check(JOINED), 2);
}

const TETHERED_BALL: &str = "
    pub struct TetheredBall {
        bodies: [
            arm {
                joint: revolute(q1, [0.0, 1.0, 0.0]),
                mass: 1.2,
                com: [0.0, 0.0, -0.3],
                inertia: diag[0.02, 0.03, 0.004],
            },
            ball {
                parent: arm,
                joint: spherical(e0, e1, e2, e3),
                xyz: [0.0, 0.0, -0.6],
                rpy: [1.5707963267948966, 0.0, 0.3],
                mass: 0.8,
                com: [0.05, -0.02, -0.2],
                inertia: [[0.01, 0.001, 0.0], [0.001, 0.012, -0.002], [0.0, -0.002, 0.006]],
            },
        ],
        constraints: [position(ball, [0.1, 0.0, -0.4]).z == -0.9],
    }";

#[test]
fn a_spherical_joint_inside_a_chain_in_velocity_coordinates_is_its_model_transformed() {
    assert_eq!(check(TETHERED_BALL), 1);
}
