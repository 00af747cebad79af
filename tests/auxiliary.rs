//! A positive semi-definite `M` (unit quaternions) is solved in generated
//! code through Udwadia & Schutte's auxiliary mass `M + s AᵀA`, factored on
//! its compile-time pattern. Held to the runtime's dense solve of the same
//! system (`gauss_dense`: nalgebra's Cholesky of `M + s AᵀA`, pivoted
//! `LDLᵀ` of `S`, and the constraint force as `M q̈ − F`) on `q̈` and on the
//! constraint force, with and without a correction `db` of `b`, and to
//! `A q̈ = b`: a free rigid body and the heavy top (`constrained::models`),
//! a free body pinned at a point, a table on four feet (redundant) and two
//! free bodies joined at a point of `contacts`, an arm carrying a ball on a spherical joint and a floating
//! torso with an arm of `spherical`. The quadruped's cases are in
//! `quadruped`.

use crate::contacts::{Joined, PinnedTop, TableOnPlane};
use crate::spherical::{ArmAndBall, FloatingBodies};
use constrained::__private::{gauss_dense, Generated};
use constrained::floating::FreeMotion;
use constrained::models::{quaternion_state, HeavyTop, RigidBodyQuaternion};
use constrained::nalgebra::{Quaternion, SVector, UnitQuaternion, Vector3, Vector4};
use constrained::State;

/// The worst gaps of the generated solve from the dense one over states.
#[derive(Debug, Default)]
pub(crate) struct Gaps {
    /// `‖q̈ − q̈_dense‖∞ / ‖q̈_dense‖∞`.
    pub acceleration: f64,
    /// `‖Fᶜ − Fᶜ_dense‖∞ / max(‖Fᶜ_dense‖∞, ‖F‖∞)` (the dense force is the
    /// difference `M q̈ − F`, exact only to rounding of `F`'s size).
    pub force: f64,
    /// `maxᵢ |Aᵢ q̈ − bᵢ| / (‖Aᵢ‖₁ ‖q̈‖∞ + |bᵢ|)` of the generated `q̈`.
    pub residual: f64,
    /// The solves (states, with and without the correction) where the
    /// generated `q̈` is not bit for bit the dense one's: the generated
    /// solve answered itself rather than handing the state to the dense
    /// one.
    pub own: usize,
}

/// The generated `gauss` against `gauss_dense` at every state, plain and
/// with a correction `db` of `b` (the Baumgarte term of
/// `acceleration_corrected`): `db = A δ`, `δ = (0.3, −0.2, 0.1, …)`, in the
/// range of `A` as a Baumgarte term of consistent constraints is, so that
/// a redundant set stays consistent.
pub(crate) fn against_dense<S, const N: usize, const K: usize>(
    system: &S,
    states: &[State<f64, N>],
) -> Gaps
where
    S: Generated<f64, N, K>,
{
    let delta = SVector::<f64, N>::from_fn(|i, _| [0.3, -0.2, 0.1][i % 3]);
    let mut gaps = Gaps::default();
    for s in states {
        let db = system.constraint_matrices(&s.q, &s.qd, s.t).0 * delta;
        for correction in [None, Some(&db)] {
            let (qdd, force) = Generated::gauss(system, &s.q, &s.qd, s.t, correction)
                .expect("the generated solve answers");
            let (dense_qdd, dense_force) =
                gauss_dense(system, &s.q, &s.qd, s.t, correction).expect("the dense solve answers");
            let forces = system.forces(&s.q, &s.qd, s.t);
            gaps.own += usize::from(qdd != dense_qdd);
            gaps.acceleration = gaps
                .acceleration
                .max((qdd - dense_qdd).amax() / dense_qdd.amax());
            gaps.force = gaps
                .force
                .max((force - dense_force).amax() / dense_force.amax().max(forces.amax()));
            let (a, mut b) = system.constraint_matrices(&s.q, &s.qd, s.t);
            if let Some(db) = correction {
                b += db;
            }
            let r = a * qdd - b;
            for i in 0..K {
                let scale = a.row(i).abs().sum() * qdd.amax() + b[i].abs();
                gaps.residual = gaps.residual.max(r[i].abs() / scale);
            }
        }
    }
    gaps
}

/// Asserts the three gaps below 1e-12 and prints them.
pub(crate) fn assert_close(name: &str, gaps: &Gaps) {
    println!(
        "{name:<28} generated auxiliary solve vs gauss_dense: q̈ {:.1e}, Fᶜ {:.1e}; A q̈ = b {:.1e}",
        gaps.acceleration, gaps.force, gaps.residual
    );
    assert!(gaps.acceleration < 1e-12, "{name}: {gaps:?}");
    assert!(gaps.force < 1e-12, "{name}: {gaps:?}");
    assert!(gaps.residual < 1e-12, "{name}: {gaps:?}");
}

/// A pseudo-random number in [−1, 1).
fn uniform(x: &mut u64) -> f64 {
    *x = x
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A unit quaternion (not normalized by the caller: `quaternion_state`
/// and `FreeMotion` normalize) and an angular velocity.
fn attitude(x: &mut u64) -> (Vector4<f64>, Vector3<f64>) {
    let e = Vector4::from_fn(|_, _| uniform(x)) + Vector4::new(1.5, 0.0, 0.0, 0.0);
    let w = Vector3::from_fn(|_, _| 3.0 * uniform(x));
    (e, w)
}

/// 24 consistent states of a body in quaternions alone.
fn quaternion_states() -> Vec<State<f64, 4>> {
    let mut x = 11u64;
    (0..24)
        .map(|k| {
            let (e, w) = attitude(&mut x);
            quaternion_state(0.1 * f64::from(k), e, w)
        })
        .collect()
}

/// A free body's state `(position, attitude, linear, angular)` written at
/// coordinate 0 of an `N`-vector.
fn free_state<const N: usize>(motion: &FreeMotion<f64>) -> (SVector<f64, N>, SVector<f64, N>) {
    let (mut q, mut qd) = (SVector::zeros(), SVector::zeros());
    motion.write(0, &mut q, &mut qd).expect("a free joint at 0");
    (q, qd)
}

/// The free rigid body and the heavy top: `M = 4 GᵀJG` of rank 3, the
/// unit norm its only row.
#[test]
fn a_body_in_quaternions_solves_as_the_dense_reference() {
    let states = quaternion_states();
    let body = RigidBodyQuaternion::new(1.0, 2.0, 3.5);
    assert_close(
        "RigidBodyQuaternion",
        &against_dense::<_, 4, 1>(&body, &states),
    );
    let top = HeavyTop::new(1.2, 0.4, 1.0, 9.81, 0.3);
    assert_close("HeavyTop", &against_dense::<_, 4, 1>(&top, &states));
}

/// A free body pinned at its origin (three position rows and the norm),
/// and a table resting on four feet on a plane (four rows for three
/// directions, and the norm: redundancy 1), moving on the plane and
/// spinning about the vertical so that `q̈ ≠ 0`.
#[test]
fn contacts_on_a_free_body_solve_as_the_dense_reference() {
    let mut x = 23u64;
    let pinned: Vec<State<f64, 7>> = (0..24)
        .map(|_| {
            let (e, w) = attitude(&mut x);
            let motion = FreeMotion {
                position: Vector3::zeros(),
                orientation: UnitQuaternion::from_quaternion(Quaternion::new(
                    e[0], e[1], e[2], e[3],
                )),
                linear: Vector3::zeros(),
                angular: w,
            };
            let (q, qd) = free_state(&motion);
            State::new(0.0, q, qd)
        })
        .collect();
    let top = PinnedTop::new(1.2, 0.4, 2.0, 0.3);
    assert_close("PinnedTop", &against_dense::<_, 7, 4>(&top, &pinned));
    let resting: Vec<State<f64, 7>> = (0..24)
        .map(|_| {
            let yaw = 3.0 * uniform(&mut x);
            let motion = FreeMotion {
                position: Vector3::new(uniform(&mut x), uniform(&mut x), 0.0),
                orientation: UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
                linear: Vector3::new(uniform(&mut x), uniform(&mut x), 0.0),
                angular: Vector3::new(0.0, 0.0, 4.0 * uniform(&mut x)),
            };
            let (q, qd) = free_state(&motion);
            State::new(0.0, q, qd)
        })
        .collect();
    let table = TableOnPlane::new(3.0, 0.2, -0.1, 0.5, 0.3);
    assert_close(
        "TableOnPlane (redundant)",
        &against_dense::<_, 7, 5>(&table, &resting),
    );
    // Two free bodies joined at a point: b's point on a's, b's velocity
    // there matching a's.
    let joined: Vec<State<f64, 14>> = (0..24)
        .map(|_| {
            let (ea, wa) = attitude(&mut x);
            let (eb, wb) = attitude(&mut x);
            let (ra, rb) = (
                UnitQuaternion::from_quaternion(Quaternion::new(ea[0], ea[1], ea[2], ea[3])),
                UnitQuaternion::from_quaternion(Quaternion::new(eb[0], eb[1], eb[2], eb[3])),
            );
            let a = FreeMotion {
                position: Vector3::from_fn(|_, _| uniform(&mut x)),
                orientation: ra,
                linear: Vector3::from_fn(|_, _| uniform(&mut x)),
                angular: wa,
            };
            let (pa, pb) = (
                ra * Vector3::new(0.3, 0.0, 0.0),
                rb * Vector3::new(0.0, 0.0, -0.2),
            );
            let b = FreeMotion {
                position: a.position + pa - pb,
                orientation: rb,
                linear: a.linear + a.angular.cross(&pa) - wb.cross(&pb),
                angular: wb,
            };
            let (mut q, mut qd) = (SVector::zeros(), SVector::zeros());
            a.write(0, &mut q, &mut qd).expect("a at 0");
            b.write(7, &mut q, &mut qd).expect("b at 7");
            State::new(0.0, q, qd)
        })
        .collect();
    assert_close(
        "Joined",
        &against_dense::<_, 14, 5>(&Joined::new(), &joined),
    );
}

/// Trees through quaternions: a revolute arm carrying a ball on a
/// spherical joint (the quaternion at coordinates 1–4), and a floating
/// torso with an arm (a free joint, then a revolute one).
#[test]
fn trees_through_quaternions_solve_as_the_dense_reference() {
    let mut x = 37u64;
    let arm: Vec<State<f64, 5>> = (0..24)
        .map(|_| {
            let (e, w) = attitude(&mut x);
            let r = quaternion_state(0.0, e, w);
            let mut q = SVector::<f64, 5>::zeros();
            let mut qd = SVector::<f64, 5>::zeros();
            (q[0], qd[0]) = (2.0 * uniform(&mut x), 2.0 * uniform(&mut x));
            q.fixed_rows_mut::<4>(1).copy_from(&r.q);
            qd.fixed_rows_mut::<4>(1).copy_from(&r.qd);
            State::new(0.0, q, qd)
        })
        .collect();
    assert_close(
        "ArmAndBall",
        &against_dense::<_, 5, 1>(&ArmAndBall::new(), &arm),
    );
    let floating: Vec<State<f64, 8>> = (0..24)
        .map(|_| {
            let (e, w) = attitude(&mut x);
            let motion = FreeMotion {
                position: Vector3::from_fn(|_, _| uniform(&mut x)),
                orientation: UnitQuaternion::from_quaternion(Quaternion::new(
                    e[0], e[1], e[2], e[3],
                )),
                linear: Vector3::from_fn(|_, _| uniform(&mut x)),
                angular: w,
            };
            let (mut q, mut qd) = free_state(&motion);
            (q[7], qd[7]) = (2.0 * uniform(&mut x), 2.0 * uniform(&mut x));
            State::new(0.0, q, qd)
        })
        .collect();
    assert_close(
        "FloatingBodies",
        &against_dense::<_, 8, 1>(&FloatingBodies::new(), &floating),
    );
}
