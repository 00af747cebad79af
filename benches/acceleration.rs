//! The generated generalized-inverse `acceleration` against what a user would
//! write instead: Appell's closed form eq. 32 by hand, and a dynamic-size
//! nalgebra implementation (A and b evaluated numerically into `DMatrix`,
//! Moore–Penrose inverse by SVD); and the planar N-link chain for N = 1…32,
//! whose cost should grow about linearly in N; the reference models, with
//! the configuration-dependent `M(q)` ones against a dense KKT solve (the
//! Jacobians and the projections have binaries of their own).

#[macro_use]
mod steps;

use constrained::models::{
    four_bar_state, Appell, AppellTimeDependent, ChaplyginSleigh, DoublePendulum,
    ParallelogramFourBar, ParallelogramFourBarAngles, RedundantDoublePendulum, RollingDisk,
    TwoLinkArmOnLine,
};
use constrained::nalgebra::Vector3;
use constrained_chains::*;
use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, BenchmarkId, Criterion};
use nalgebra::{DMatrix, DVector};
use std::hint::black_box;

const G: f64 = 9.81;
const ALPHA: f64 = 0.5;

/// The generated function behind the same call boundary as the others.
#[inline(never)]
fn appell_generated(
    system: &Appell<f64>,
    q: &Vector3<f64>,
    qd: &Vector3<f64>,
    t: f64,
) -> Vector3<f64> {
    system.acceleration(q, qd, t)
}

/// Appell's particle with h = z, eq. 32 written out by hand.
#[inline(never)]
fn appell_by_hand(q: &Vector3<f64>, qd: &Vector3<f64>, _t: f64) -> Vector3<f64> {
    let _ = q;
    let (xd, yd, zd) = (qd.x, qd.y, qd.z);
    let b = ALPHA * zd;
    let s = xd * xd + yd * yd + zd * zd;
    let factor = if s > 0.0 { (b - zd * G) / s } else { 0.0 };
    Vector3::new(factor * xd, factor * yd, -G - factor * zd)
}

/// The same equation with dynamic matrices: A, b evaluated numerically,
/// q̈ = a + M^{-1/2} (A M^{-1/2})⁺ (b − A a) with M = I and an SVD pseudo-inverse.
#[inline(never)]
fn appell_dynamic(q: &DVector<f64>, qd: &DVector<f64>, _t: f64) -> DVector<f64> {
    let _ = q;
    let m = DMatrix::<f64>::identity(3, 3);
    let f = DVector::from_vec(vec![0.0, 0.0, -G]);
    let a_mat = DMatrix::from_row_slice(1, 3, &[qd[0], qd[1], -qd[2]]);
    let b = DVector::from_vec(vec![ALPHA * qd[2]]);
    let acc = m.clone().cholesky().expect("positive definite").solve(&f);
    let pinv = a_mat.clone().pseudo_inverse(1e-12).expect("svd");
    &acc + pinv * (b - &a_mat * &acc)
}

/// The states every Appell implementation is timed on, shared with the
/// Python lambdify benchmark (benches/lambdify.py).
fn appell_states() -> Vec<(Vector3<f64>, Vector3<f64>, f64)> {
    let data: serde_json::Value = serde_json::from_str(include_str!("data/appell_states.json"))
        .expect("valid benchmark states");
    let v = |x: &serde_json::Value| {
        Vector3::from_iterator(
            x.as_array()
                .expect("array")
                .iter()
                .map(|e| e.as_f64().expect("number")),
        )
    };
    data["states"]
        .as_array()
        .expect("states")
        .iter()
        .map(|s| (v(&s["q"]), v(&s["qd"]), s["t"].as_f64().expect("t")))
        .collect()
}

fn appell(c: &mut Criterion) {
    let system = Appell::<f64>::new(G, ALPHA);
    let states = appell_states();
    let dynamic: Vec<(DVector<f64>, DVector<f64>, f64)> = states
        .iter()
        .map(|(q, qd, t)| {
            (
                DVector::from_column_slice(q.as_slice()),
                DVector::from_column_slice(qd.as_slice()),
                *t,
            )
        })
        .collect();
    // The three agree before they are timed.
    for ((q, qd, t), (qdyn, qddyn, _)) in states.iter().zip(&dynamic) {
        let generated = system.acceleration(q, qd, *t);
        assert!((generated - appell_by_hand(q, qd, *t)).norm() < 1e-13 * generated.norm());
        let dynamic = appell_dynamic(qdyn, qddyn, *t);
        assert!(
            (DVector::from_column_slice(generated.as_slice()) - dynamic).norm()
                < 1e-12 * generated.norm()
        );
    }
    // Each iteration evaluates all states: divide by their number for one call.
    let mut group = c.benchmark_group("appell_acceleration_12_states");
    paired_rounds(
        &mut group,
        || {
            for (q, qd, t) in &states {
                black_box(appell_generated(
                    &system,
                    black_box(q),
                    black_box(qd),
                    black_box(*t),
                ));
            }
        },
        || {
            for (q, qd, t) in &states {
                black_box(appell_by_hand(black_box(q), black_box(qd), black_box(*t)));
            }
        },
    );
    group.bench_function("dynamic_nalgebra_svd", |b| {
        b.iter(|| {
            for (q, qd, t) in &dynamic {
                black_box(appell_dynamic(black_box(q), black_box(qd), black_box(*t)));
            }
        })
    });
    group.finish();
}

/// The generated function for `h = x·y + sin t` behind the same call
/// boundary as the hand-written one.
#[inline(never)]
fn appell_xy_generated(
    system: &AppellTimeDependent<f64>,
    q: &Vector3<f64>,
    qd: &Vector3<f64>,
    t: f64,
) -> Vector3<f64> {
    system.acceleration(q, qd, t)
}

/// Eq. 32 by hand for `h = x·y + sin t` (`h_x = y`, `h_y = x`, `h_z = 0`,
/// `h_t = cos t`), with `g` and `α` arguments, as the generated code reads
/// them from its struct: neither side can fold them.
#[inline(never)]
fn appell_xy_by_hand(
    g: f64,
    alpha: f64,
    q: &Vector3<f64>,
    qd: &Vector3<f64>,
    t: f64,
) -> Vector3<f64> {
    let (x, y) = (q.x, q.y);
    let (xd, yd, zd) = (qd.x, qd.y, qd.z);
    let s = xd * xd + yd * yd + zd * zd;
    let numerator = alpha * (y * xd + x * yd + t.cos()) - zd * g;
    let factor = if s > 0.0 { numerator / s } else { 0.0 };
    Vector3::new(factor * xd, factor * yd, -g - factor * zd)
}

/// 1024 varied states (SplitMix64 from a fixed seed): positions, velocities
/// and times spread so that the branch predictor and `cos` see no pattern.
fn appell_xy_states() -> Vec<(Vector3<f64>, Vector3<f64>, f64)> {
    let mut seed = 0x005e_eda9_9e11_u64;
    let mut uniform = |lo: f64, hi: f64| {
        seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
    };
    (0..APPELL_XY_STATES)
        .map(|_| {
            let q = Vector3::new(uniform(-2.0, 2.0), uniform(-2.0, 2.0), uniform(-2.0, 2.0));
            let qd = Vector3::new(uniform(-3.0, 3.0), uniform(-3.0, 3.0), uniform(-3.0, 3.0));
            (q, qd, uniform(0.0, 10.0))
        })
        .collect()
}

/// States per iteration of the `h = x·y + sin t` group.
const APPELL_XY_STATES: usize = 1024;

/// Appell's particle with `h = x·y + sin t` (issue 15's target): the
/// generated `acceleration` against eq. 32 by hand over 1024 varied states,
/// parameters behind `black_box` on both sides.
fn appell_xy(c: &mut Criterion) {
    let (g, alpha) = (black_box(G), black_box(ALPHA));
    let system = AppellTimeDependent::<f64>::new(g, alpha);
    let states = appell_xy_states();
    for (q, qd, t) in &states {
        let generated = system.acceleration(q, qd, *t);
        let by_hand = appell_xy_by_hand(g, alpha, q, qd, *t);
        assert!((generated - by_hand).norm() <= 1e-12 * (1.0 + generated.norm()));
    }
    let mut group = c.benchmark_group("appell_xy_sin_t_1024_states");
    paired_rounds(
        &mut group,
        || {
            let system = black_box(&system);
            for (q, qd, t) in &states {
                black_box(appell_xy_generated(
                    system,
                    black_box(q),
                    black_box(qd),
                    black_box(*t),
                ));
            }
        },
        || {
            for (q, qd, t) in &states {
                black_box(appell_xy_by_hand(
                    black_box(g),
                    black_box(alpha),
                    black_box(q),
                    black_box(qd),
                    black_box(*t),
                ));
            }
        },
    );
    group.finish();
}

/// Rounds of each paired comparison against eq. 32 by hand.
const ROUNDS: usize = 5;

/// Times `generated` and `by_hand` alternately, [`ROUNDS`] times each
/// (`generated/1`, `hand_written_eq32/1`, `generated/2`, …), so that each
/// round's ratio compares two measurements taken seconds apart. On this
/// shared two-core machine one pair measured back to back moved by ±25 %
/// between runs (the 12-state ratio read 1.32× in one run and 0.82× in the
/// next), which is drift of the machine, not of the code; the report takes
/// the median of the rounds' ratios and prints their range beside it.
fn paired_rounds(
    group: &mut BenchmarkGroup<'_, WallTime>,
    mut generated: impl FnMut(),
    mut by_hand: impl FnMut(),
) {
    for round in 1..=ROUNDS {
        group.bench_function(format!("generated/{round}"), |b| b.iter(&mut generated));
        group.bench_function(format!("hand_written_eq32/{round}"), |b| {
            b.iter(&mut by_hand)
        });
    }
}

macro_rules! bench_chain {
    ($group:expr, $method:ident, $chain:ty, $links:literal, $m:literal) => {{
        let system = <$chain>::new(G);
        let (q, qd) = constrained_chains::benchmark_state::<$m>();
        $group.bench_with_input(BenchmarkId::from_parameter($links), &$links, |b, _| {
            b.iter(|| system.$method(black_box(&q), black_box(&qd), black_box(0.0)))
        });
    }};
}

macro_rules! bench_chains {
    ($c:expr, $name:literal, $method:ident) => {{
        let mut group = $c.benchmark_group($name);
        bench_chain!(group, $method, Chain1, 1, 2);
        bench_chain!(group, $method, Chain2, 2, 4);
        bench_chain!(group, $method, Chain4, 4, 8);
        bench_chain!(group, $method, Chain8, 8, 16);
        bench_chain!(group, $method, Chain16, 16, 32);
        bench_chain!(group, $method, Chain32, 32, 64);
        group.finish();
    }};
}

fn chain(c: &mut Criterion) {
    bench_chains!(c, "chain_acceleration", acceleration);
    bench_chains!(
        c,
        "chain_acceleration_gibbs_appell",
        acceleration_gibbs_appell
    );
    let mut group = c.benchmark_group("chain_rk4_step");
    bench_rk4_step!(group, Chain1, 1, 2, constrained::Rk4::new(1e-3));
    bench_rk4_step!(group, Chain2, 2, 4, constrained::Rk4::new(1e-3));
    bench_rk4_step!(group, Chain4, 4, 8, constrained::Rk4::new(1e-3));
    bench_rk4_step!(group, Chain8, 8, 16, constrained::Rk4::new(1e-3));
    bench_rk4_step!(group, Chain16, 16, 32, constrained::Rk4::new(1e-3));
    bench_rk4_step!(group, Chain32, 32, 64, constrained::Rk4::new(1e-3));
    group.finish();
}

/// Both equations of motion of every reference model, side by side.
fn models(c: &mut Criterion) {
    let mut group = c.benchmark_group("models");
    macro_rules! both {
        ($name:literal, $system:expr, $q:expr, $qd:expr) => {{
            let (system, q, qd) = ($system, $q, $qd);
            group.bench_function(concat!($name, "/acceleration"), |b| {
                b.iter(|| system.acceleration(black_box(&q), black_box(&qd), black_box(0.0)))
            });
            group.bench_function(concat!($name, "/gibbs_appell"), |b| {
                b.iter(|| {
                    system.acceleration_gibbs_appell(black_box(&q), black_box(&qd), black_box(0.0))
                })
            });
        }};
    }
    let (q3, qd3) = (Vector3::new(0.3, -0.2, 1.1), Vector3::new(1.2, 0.7, -0.4));
    both!("appell", Appell::<f64>::new(G, ALPHA), q3, qd3);
    let (q, qd) = constrained_chains::benchmark_state::<4>();
    both!(
        "double_pendulum",
        DoublePendulum::<f64>::new(1.1, 1.2, 1.05, 1.1, G),
        q,
        qd
    );
    both!(
        "redundant_double_pendulum",
        RedundantDoublePendulum::<f64>::new(1.1, 1.2, 1.05, 1.1, G),
        q,
        qd
    );
    both!(
        "chaplygin_sleigh",
        ChaplyginSleigh::<f64>::new(1.0, 0.2, 0.5, 0.3),
        q3,
        qd3
    );
    let (qa, qda) = (
        constrained::nalgebra::Vector2::new(0.3, 0.4),
        constrained::nalgebra::Vector2::new(0.1, -0.2),
    );
    both!(
        "two_link_arm",
        TwoLinkArmOnLine::<f64>::new(1.0, 0.5, 1.0, 1.0, G, 0.5),
        qa,
        qda
    );

    // Configuration-dependent M(q), factored in generated code, against a
    // dense heap-allocating KKT solve of the same M, F, A and b (what a
    // user without the macro's structure would write).
    macro_rules! kkt {
        ($name:literal, $system:expr, $q:expr, $qd:expr, $n:literal, $k:literal) => {{
            let (system, q, qd) = ($system, $q, $qd);
            group.bench_function(concat!($name, "/dense_kkt"), |b| {
                b.iter(|| {
                    dense_kkt::<$n, $k>(
                        &system.mass_matrix(black_box(&q), 0.0),
                        &system.forces(black_box(&q), black_box(&qd), 0.0),
                        &system.constraint_matrices(black_box(&q), black_box(&qd), 0.0),
                    )
                })
            });
        }};
    }
    let four_bar = ParallelogramFourBarAngles::<f64>::new(1.2, 0.15, 1.0, 2.0, G);
    let (qf, qdf) = (Vector3::new(0.7, 0.0, 0.7), Vector3::new(1.3, 0.0, 1.3));
    both!("four_bar_angles", four_bar, qf, qdf);
    kkt!("four_bar_angles", four_bar, qf, qdf, 3, 2);
    let cartesian = ParallelogramFourBar::<f64>::new(1.2, 0.15, 1.0, 2.0, G);
    let s = four_bar_state(&cartesian, 0.7, 1.3);
    both!("four_bar_cartesian", cartesian, s.q, s.qd);
    let disk = RollingDisk::<f64>::new(1.0, 0.5, 0.06, 0.12, G);
    let (qr, qdr) = rolling_disk_state(&disk);
    both!("rolling_disk", disk, qr, qdr);
    kkt!("rolling_disk", disk, qr, qdr, 5, 2);
    let pendulum = PendulumAngles8::<f64>::new(G);
    let (qp, qdp) = (
        constrained::nalgebra::SVector::<f64, 8>::from_fn(|i, _| (0.7 * i as f64).sin()),
        constrained::nalgebra::SVector::<f64, 8>::from_fn(|i, _| (1.1 * i as f64).cos()),
    );
    group.bench_function("pendulum_angles_8/acceleration", |b| {
        b.iter(|| pendulum.acceleration(black_box(&qp), black_box(&qdp), black_box(0.0)))
    });
    kkt!("pendulum_angles_8", pendulum, qp, qdp, 8, 0);
    group.finish();
}

/// A consistent state of the rolling disk: tilt, heading and spin chosen,
/// the contact point's velocity from the two rolling constraints (their
/// rows of `A` start with the unit vectors of `ẋ` and `ẏ`).
fn rolling_disk_state(
    disk: &RollingDisk<f64>,
) -> (
    constrained::nalgebra::SVector<f64, 5>,
    constrained::nalgebra::SVector<f64, 5>,
) {
    let q = constrained::nalgebra::SVector::<f64, 5>::from([0.1, -0.2, 0.9, 0.4, 0.3]);
    let mut qd = constrained::nalgebra::SVector::<f64, 5>::from([0.0, 0.0, 0.3, -0.7, 2.5]);
    let residual = disk.constraint_residual(&q, &qd, 0.0);
    qd[0] -= residual[0];
    qd[1] -= residual[1];
    (q, qd)
}

/// `[[M, Aᵀ], [A, 0]] [q̈; −λ] = [F; b]` by dense LU on the heap.
fn dense_kkt<const N: usize, const K: usize>(
    m: &constrained::nalgebra::SMatrix<f64, N, N>,
    f: &constrained::nalgebra::SVector<f64, N>,
    (a, b): &(
        constrained::nalgebra::SMatrix<f64, K, N>,
        constrained::nalgebra::SVector<f64, K>,
    ),
) -> Option<DVector<f64>> {
    let mut kkt = DMatrix::<f64>::zeros(N + K, N + K);
    let mut rhs = DVector::<f64>::zeros(N + K);
    for i in 0..N {
        for j in 0..N {
            kkt[(i, j)] = m[(i, j)];
        }
        for r in 0..K {
            kkt[(i, N + r)] = a[(r, i)];
            kkt[(N + r, i)] = a[(r, i)];
        }
        rhs[i] = f[i];
    }
    for r in 0..K {
        rhs[N + r] = b[r];
    }
    kkt.lu().solve(&rhs).map(|x| x.rows(0, N).into_owned())
}

criterion_group!(benches, appell, appell_xy, chain, models);
criterion_main!(benches);
