//! The projections' Newton step through the generated factorizations
//! (`ConstrainedSystem::constraint_step`, used by `stabilize::project`)
//! against the dense step computed here, `M⁻¹Aᵀ (A M⁻¹ Aᵀ)⁺ r`, for every
//! reference model with constraints and a non-singular `M`. `r = A v`
//! lies in the range of `A`, so every {1}-inverse gives the same step (the
//! `M`-orthogonal projection of `v` onto the row space of `A`), redundant
//! rows included.

use constrained::models::*;
use constrained::nalgebra::{DMatrix, SVector};
use constrained::stabilize::project;
use constrained::{ConstrainedSystem, State};
use constrained_chains::{Chain2, Chain8};

fn dense_step<S, const N: usize, const K: usize>(
    system: &S,
    state: &State<f64, N>,
    r: &SVector<f64, K>,
) -> SVector<f64, N>
where
    S: ConstrainedSystem<f64, N, K>,
{
    let m = system.mass_matrix(state);
    let (a, _) = system.constraint_matrices(state);
    let minv_at = m
        .cholesky()
        .expect("M is positive definite")
        .solve(&a.transpose());
    let gram = DMatrix::from_fn(K, K, |i, j| (a * minv_at)[(i, j)]);
    let pinv = gram.pseudo_inverse(1e-12).expect("SVD converges");
    let mu = &pinv * DMatrix::from_fn(K, 1, |i, _| r[i]);
    SVector::<f64, N>::from_fn(|i, _| (0..K).map(|j| minv_at[(i, j)] * mu[(j, 0)]).sum())
}

fn next(x: &mut u64) -> f64 {
    *x = x
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*x >> 11) as f64 / (1u64 << 53) as f64) - 0.5
}

macro_rules! same {
    ($worst:expr, $model:ident, $n:literal, $k:literal, [$($p:expr),*]) => {{
        let system = $model::<f64>::new($($p),*);
        let mut worst = 0.0f64;
        for seed in 1..=5u64 {
            let mut x = seed;
            let q = SVector::<f64, $n>::from_fn(|_, _| next(&mut x) + 0.3);
            let qd = SVector::<f64, $n>::from_fn(|_, _| 2.0 * next(&mut x));
            let mut state = State::new(0.25, q, qd);
            project(&system, &mut state, 1e-13, 50).expect("a consistent state");
            let (a, _) = ConstrainedSystem::<f64, $n, $k>::constraint_matrices(&system, &state);
            let v = SVector::<f64, $n>::from_fn(|_, _| next(&mut x));
            let r = a * v;
            let (generated, kept) = ConstrainedSystem::<f64, $n, $k>::constraint_step(&system, &state, &r)
                .expect(concat!(stringify!($model), ": the generated step answers at a generic state"));
            assert!(kept.iter().filter(|&&k| k).count() > 0);
            let dense = dense_step::<_, $n, $k>(&system, &state, &r);
            worst = worst.max((generated - dense).amax() / dense.amax().max(1e-300));
        }
        println!("{:<28} generated step vs dense {worst:.1e}", stringify!($model));
        assert!(worst < 1e-9, "{}: {worst:e}", stringify!($model));
        $worst = $worst.max(worst);
    }};
}

#[test]
fn the_generated_step_is_the_dense_one() {
    let mut worst = 0.0f64;
    same!(worst, Appell, 3, 1, [9.81, 0.7]);
    same!(worst, SphericalPendulum, 3, 1, [1.5, 9.81, 1.2]);
    same!(worst, DoublePendulum, 4, 2, [1.0, 2.0, 1.0, 0.8, 9.81]);
    same!(
        worst,
        RedundantDoublePendulum,
        4,
        3,
        [1.0, 2.0, 1.0, 0.8, 9.81]
    );
    same!(worst, BeadOnRotatingHoop, 3, 2, [0.5, 9.81, 1.0, 2.0]);
    same!(worst, ChaplyginSleigh, 3, 1, [2.0, 0.4, 0.3, 0.0]);
    same!(worst, SliderCrank, 4, 4, [1.0, 2.0, 0.5, 1.5, 3.0, 9.81]);
    same!(
        worst,
        TwoLinkArmOnLine,
        2,
        1,
        [1.0, 0.5, 1.0, 1.0, 9.81, 0.5]
    );
    same!(worst, CartPoleCartesian, 3, 1, [1.0, 0.3, 0.8, 9.81, 0.0]);
    same!(worst, RollingDisk, 5, 2, [1.0, 0.5, 0.06, 0.12, 9.81]);
    same!(
        worst,
        ParallelogramFourBarAngles,
        3,
        2,
        [1.2, 0.15, 1.0, 2.0, 9.81]
    );
    // Constant masses: the entries of W are sums (x₁ − x₂ over a mass).
    same!(worst, Chain2, 4, 2, [9.81]);
    same!(worst, Chain8, 16, 8, [9.81]);
    println!("largest relative difference {worst:.1e}");
}

/// A semi-definite `M` has no generated step: the runtime's dense one.
#[test]
fn a_singular_mass_has_no_generated_step() {
    let top = RigidBodyQuaternion::<f64>::new(1.0, 2.0, 3.0);
    let state = State::new(
        0.0,
        SVector::<f64, 4>::new(1.0, 0.0, 0.0, 0.0),
        SVector::zeros(),
    );
    let r = SVector::<f64, 1>::new(0.1);
    assert!(ConstrainedSystem::<f64, 4, 1>::constraint_step(&top, &state, &r).is_none());
}

constrained::constrained_system! {
    /// A four-bar in its three link angles: crank (length `a`, about the
    /// origin), coupler (`b`) and rocker (`c`, about `(d, 0)`), uniform bars
    /// of mass `m` and moment of inertia `jm`, gravity along −y; the two loop
    /// closures.
    struct FourBarAngles {
        coordinates: [p1, p2, p3],
        parameters: [m, jm, a, b, c, d, g],
        definitions: [
            x1 = a / 2.0 * p1.cos(),
            y1 = a / 2.0 * p1.sin(),
            x2 = a * p1.cos() + b / 2.0 * p2.cos(),
            y2 = a * p1.sin() + b / 2.0 * p2.sin(),
            x3 = d + c / 2.0 * p3.cos(),
            y3 = c / 2.0 * p3.sin(),
        ],
        kinetic_energy: m / 2.0
            * (dt(x1).powi(2) + dt(y1).powi(2) + dt(x2).powi(2) + dt(y2).powi(2)
                + dt(x3).powi(2) + dt(y3).powi(2))
            + jm / 2.0 * (dot(p1).powi(2) + dot(p2).powi(2) + dot(p3).powi(2)),
        potential_energy: m * g * (y1 + y2 + y3),
        constraints: [
            a * p1.cos() + b * p2.cos() == d + c * p3.cos(),
            a * p1.sin() + b * p2.sin() == c * p3.sin(),
        ],
    }
}

constrained::constrained_system! {
    /// [`FourBarAngles`] with a third closure, redundant on the surface:
    /// the crank tip and the rocker tip are the coupler's length apart
    /// (which the two loop closures already imply).
    struct FourBarAnglesRedundant {
        coordinates: [p1, p2, p3],
        parameters: [m, jm, a, b, c, d, g],
        definitions: [
            x1 = a / 2.0 * p1.cos(),
            y1 = a / 2.0 * p1.sin(),
            x2 = a * p1.cos() + b / 2.0 * p2.cos(),
            y2 = a * p1.sin() + b / 2.0 * p2.sin(),
            x3 = d + c / 2.0 * p3.cos(),
            y3 = c / 2.0 * p3.sin(),
        ],
        kinetic_energy: m / 2.0
            * (dt(x1).powi(2) + dt(y1).powi(2) + dt(x2).powi(2) + dt(y2).powi(2)
                + dt(x3).powi(2) + dt(y3).powi(2))
            + jm / 2.0 * (dot(p1).powi(2) + dot(p2).powi(2) + dot(p3).powi(2)),
        potential_energy: m * g * (y1 + y2 + y3),
        constraints: [
            a * p1.cos() + b * p2.cos() == d + c * p3.cos(),
            a * p1.sin() + b * p2.sin() == c * p3.sin(),
            (a * p1.cos() - d - c * p3.cos()).powi(2) + (a * p1.sin() - c * p3.sin()).powi(2)
                == b.powi(2),
        ],
    }
}

/// A consistent state of the four-bar `[a, b, c, d]` with the crank at
/// `p1` turning at `w1`, the coupler above the line from the crank tip to
/// the rocker pivot.
fn four_bar_angles_state([a, b, c, d]: [f64; 4], p1: f64, w1: f64) -> State<f64, 3> {
    // The rocker tip Q: |Q − P| = b, |Q − (d, 0)| = c.
    let (px, py) = (a * p1.cos(), a * p1.sin());
    let (ex, ey) = (d - px, -py);
    let e = ex.hypot(ey);
    let along = (b * b - c * c + e * e) / (2.0 * e);
    let across = (b * b - along * along).sqrt();
    let (qx, qy) = (
        px + (along * ex - across * ey) / e,
        py + (along * ey + across * ex) / e,
    );
    let p2 = (qy - py).atan2(qx - px);
    let p3 = qy.atan2(qx - d);
    // Rates from the differentiated closures: a 2 × 2 solve for ω₂, ω₃.
    let (m11, m12, m21, m22) = (-b * p2.sin(), c * p3.sin(), b * p2.cos(), -c * p3.cos());
    let (r1, r2) = (a * p1.sin() * w1, -a * p1.cos() * w1);
    let det = m11 * m22 - m12 * m21;
    let (w2, w3) = ((r1 * m22 - m12 * r2) / det, (m11 * r2 - m21 * r1) / det);
    State::new(
        0.0,
        SVector::<f64, 3>::new(p1, p2, p3),
        SVector::<f64, 3>::new(w1, w2, w3),
    )
}

/// The four-bar in its three link angles with the two loop closures and a
/// third, distance closure that is redundant on the surface, integrated by
/// `DormandPrince45::new(1e-12, 1e-13)` with `Stabilization::projection(1e-12)`,
/// stopped with `ProjectionFailed` (here `residual: 3.7e-12` at t = 1.18:
/// the redundant row's velocity residual, left by positions within the
/// tolerance but not on the surface, which no velocity step reduces),
/// while its twin without the redundant row integrated fine. It must follow
/// the twin's trajectory (to 1e-9).
#[test]
fn projection_on_a_redundant_set_in_link_angles_follows_its_twin() {
    use constrained::{DormandPrince45, Stabilization};
    let lengths = [1.0, 2.5, 2.0, 3.0];
    let [a, b, c, d] = lengths;
    let (m, jm, g) = (1.2, 0.15, 9.81);
    let twin = FourBarAngles::<f64>::new(m, jm, a, b, c, d, g);
    let redundant = FourBarAnglesRedundant::<f64>::new(m, jm, a, b, c, d, g);
    let integrator =
        DormandPrince45::new(1e-12, 1e-13).with_stabilization(Stabilization::projection(1e-12));
    let times: Vec<f64> = (1..=40).map(|i| 0.1 * f64::from(i)).collect();
    for (p1, w1) in [(0.3, 6.0), (-1.0, 0.0), (2.0, -8.0), (0.0, 15.0)] {
        let start = four_bar_angles_state(lengths, p1, w1);
        let on_surface = twin.constraint_residual(&start.q, &start.qd, 0.0).amax();
        assert!(on_surface < 1e-14, "{on_surface:e}");
        let mut twin_samples = Vec::new();
        let mut redundant_samples = Vec::new();
        let mut s = start;
        integrator
            .advance_sampled(&twin, &mut s, 4.0, &times, |s| twin_samples.push(*s))
            .expect("the twin integrates");
        let mut s = start;
        integrator
            .advance_sampled(&redundant, &mut s, 4.0, &times, |s| {
                redundant_samples.push(*s)
            })
            .unwrap_or_else(|e| panic!("p1 = {p1}, w1 = {w1}: {e}"));
        let worst = twin_samples
            .iter()
            .zip(&redundant_samples)
            .map(|(a, b)| (a.q - b.q).amax().max((a.qd - b.qd).amax()))
            .fold(0.0, f64::max);
        println!("p1 = {p1}, w1 = {w1}: largest difference from the twin {worst:.1e}");
        assert!(worst < 1e-9, "p1 = {p1}, w1 = {w1}: {worst:e}");
    }
}
