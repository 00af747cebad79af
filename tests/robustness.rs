//! The generalized-inverse equation where it can go wrong: a mass matrix
//! that is not positive definite is reported, never NaN; f32 works; and the
//! redundant double pendulum integrates like the plain one, although
//! Runge–Kutta stages sit off the constraint surface where the redundant
//! row is weakly independent (rank decisions need a real tolerance:
//! `constrained::rank`).

use constrained::constrained_system;
use constrained::models::*;
use constrained::nalgebra::{SVector, Vector2, Vector3, Vector4};
use constrained::DynamicsError;

#[test]
fn non_positive_definite_mass_is_reported() {
    // Diagonal mass from a parameter.
    let bad = SphericalPendulum::new(-1.0, 9.81, 1.0);
    let (q, qd) = (Vector3::new(0.0, 0.6, -0.8), Vector3::new(0.3, 0.0, 0.0));
    assert_eq!(
        bad.acceleration(&q, &qd, 0.0),
        Err(DynamicsError::MassNotPositiveDefinite)
    );
    assert_eq!(
        bad.constraint_force(&q, &qd, 0.0),
        Err(DynamicsError::MassNotPositiveDefinite)
    );
    // Full M(q) through the run-time Cholesky factorization: M₂₂ = m2·l2² < 0.
    let bad = TwoLinkArmOnLine::new(1.0, -0.5, 1.0, 1.0, 9.81, 0.5);
    let (q, qd) = (Vector2::new(0.3, 0.4), Vector2::new(0.1, -0.2));
    assert_eq!(
        bad.acceleration(&q, &qd, 0.0),
        Err(DynamicsError::MassNotPositiveDefinite)
    );
    assert_eq!(
        bad.acceleration_moore_penrose(&q, &qd, 0.0),
        Err(DynamicsError::MassNotPositiveDefinite)
    );
    // The same arm with physical masses is fine.
    let good = TwoLinkArmOnLine::new(1.0, 0.5, 1.0, 1.0, 9.81, 0.5);
    assert!(good
        .acceleration(&q, &qd, 0.0)
        .unwrap()
        .iter()
        .all(|x: &f64| x.is_finite()));
}

#[test]
fn f32_agrees_with_f64() {
    let (q, qd) = (Vector3::new(0.3, -0.4, 1.0), Vector3::new(1.2, 0.7, -0.5));
    let a64 = AppellTimeDependent::<f64>::new(9.81, 0.5).acceleration(&q, &qd, 0.25);
    let a32 = AppellTimeDependent::<f32>::new(9.81, 0.5).acceleration(&q.cast(), &qd.cast(), 0.25);
    assert!(
        (a32.cast::<f64>() - a64).norm() < 1e-5 * a64.norm(),
        "{a32} vs {a64}"
    );
    let p = [1.0f32, 1.5, 1.2, 0.8, 9.81];
    let sys = RedundantDoublePendulum::<f32>::new(p[0], p[1], p[2], p[3], p[4]);
    let (t1, t2) = (0.7f32, -1.9f32);
    let q = Vector4::new(
        1.2 * t1.sin(),
        -1.2 * t1.cos(),
        1.2 * t1.sin() + 0.8 * t2.sin(),
        -1.2 * t1.cos() - 0.8 * t2.cos(),
    );
    let qdd = sys.acceleration(&q, &Vector4::zeros(), 0.0).unwrap();
    let (a, b) = sys.constraint_matrices(&q, &Vector4::zeros(), 0.0);
    assert!(
        (a * qdd - b).norm() < 1e-4 * (a.norm() * qdd.norm() + b.norm()),
        "f32 redundant: A q̈ − b = {}",
        a * qdd - b
    );
}

/// Classical RK4 on (q, q̇) for a fixed step (the runtime's integrators are
/// tested on their own; this one keeps the test independent of them).
/// `q̈(q, q̇)` of an autonomous system.
type Dynamics<'a, const N: usize> =
    &'a dyn Fn(&SVector<f64, N>, &SVector<f64, N>) -> SVector<f64, N>;

fn rk4<const N: usize>(
    f: Dynamics<'_, N>,
    q: &mut SVector<f64, N>,
    qd: &mut SVector<f64, N>,
    h: f64,
) {
    let k1 = (*qd, f(q, qd));
    let k2 = (
        *qd + k1.1 * (h / 2.0),
        f(&(*q + k1.0 * (h / 2.0)), &(*qd + k1.1 * (h / 2.0))),
    );
    let k3 = (
        *qd + k2.1 * (h / 2.0),
        f(&(*q + k2.0 * (h / 2.0)), &(*qd + k2.1 * (h / 2.0))),
    );
    let k4 = (*qd + k3.1 * h, f(&(*q + k3.0 * h), &(*qd + k3.1 * h)));
    *q += (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * (h / 6.0);
    *qd += (k1.1 + k2.1 * 2.0 + k3.1 * 2.0 + k4.1) * (h / 6.0);
}

#[test]
fn redundant_double_pendulum_integrates_like_the_plain_one() {
    let p = [1.0, 1.5, 1.2, 0.8, 9.81];
    let plain = DoublePendulum::new(p[0], p[1], p[2], p[3], p[4]);
    let redundant = RedundantDoublePendulum::new(p[0], p[1], p[2], p[3], p[4]);
    let start = plain.state_from_angles(0.0, [0.7, -1.9], [1.3, -0.4]);
    let (q0, qd0) = (start.q, start.qd);
    let (mut qa, mut qda, mut qb, mut qdb) = (q0, qd0, q0, qd0);
    let h = 1e-3;
    let (mut drift_plain, mut drift_redundant): (f64, f64) = (0.0, 0.0);
    for _ in 0..3000 {
        rk4(
            &|q, qd| plain.acceleration(q, qd, 0.0).unwrap(),
            &mut qa,
            &mut qda,
            h,
        );
        rk4(
            &|q, qd| redundant.acceleration(q, qd, 0.0).unwrap(),
            &mut qb,
            &mut qdb,
            h,
        );
        drift_plain = drift_plain.max(plain.constraint_residual(&qa, &qda, 0.0).amax());
        let phi = redundant.constraint_residual(&qb, &qdb, 0.0);
        drift_redundant = drift_redundant.max(phi[0].abs().max(phi[1].abs()));
    }
    // 3 s of chaotic motion: the two agree to integration accuracy, and the
    // redundant row adds no drift (RK4 drifts by itself, unstabilised).
    assert!((qa - qb).norm() < 1e-8, "plain {qa} vs redundant {qb}");
    assert!(drift_plain < 1e-6, "plain drift {drift_plain}");
    assert!(
        (drift_redundant - drift_plain).abs() <= 1e-3 * drift_plain,
        "drift: redundant {drift_redundant} vs plain {drift_plain}"
    );
}

constrained_system! {
    /// Two five-link arms (the Panda's first links, rounded) on a torso
    /// turning about the vertical: a branched tree whose `M` couples the
    /// arms only through the waist and is large enough to be factored as
    /// its entries are computed. The right hand's link holds `payload`.
    pub struct TwoArms {
        parameters: [payload],
        gravity: [0.0, 0.0, -9.81],
        bodies: [
            torso {
                joint: revolute(waist, [0.0, 0.0, 1.0]),
                mass: 20.0,
                com: [0.0, 0.0, 0.2],
                inertia: diag[0.4, 0.3, 0.2],
            },
            left1 {
                parent: torso,
                joint: revolute(left_q1, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.25, 0.4],
                mass: 4.97,
                com: [0.004, 0.002, -0.094],
                inertia: [[0.70, -0.0002, 0.0086], [-0.0002, 0.70, 0.0201], [0.0086, 0.0201, 0.0092]],
            },
            left2 {
                parent: left1,
                joint: revolute(left_q2, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.0],
                rpy: [-1.0 * PI / 2.0, 0.0, 0.0],
                mass: 0.65,
                com: [-0.003, -0.028, 0.003],
                inertia: [[0.0080, -0.0039, 0.0102], [-0.0039, 0.0282, 0.0007], [0.0102, 0.0007, 0.0257]],
            },
            left3 {
                parent: left2,
                joint: revolute(left_q3, [0.0, 0.0, 1.0]),
                xyz: [0.0, -0.316, 0.0],
                rpy: [1.0 * PI / 2.0, 0.0, 0.0],
                mass: 3.23,
                com: [0.027, 0.039, -0.066],
                inertia: [[0.0372, -0.0048, -0.0114], [-0.0048, 0.0361, -0.0128], [-0.0114, -0.0128, 0.0108]],
            },
            left4 {
                parent: left3,
                joint: revolute(left_q4, [0.0, 0.0, 1.0]),
                xyz: [0.0825, 0.0, 0.0],
                rpy: [1.0 * PI / 2.0, 0.0, 0.0],
                mass: 3.59,
                com: [-0.053, 0.104, 0.027],
                inertia: [[0.0260, 0.0077, -0.0013], [0.0077, 0.0196, 0.0086], [-0.0013, 0.0086, 0.0283]],
            },
            left5 {
                parent: left4,
                joint: revolute(left_q5, [0.0, 0.0, 1.0]),
                xyz: [-0.0825, 0.384, 0.0],
                rpy: [-1.0 * PI / 2.0, 0.0, 0.0],
                mass: 1.23,
                com: [-0.012, 0.041, -0.038],
                inertia: [[0.0356, -0.0021, -0.0040], [-0.0021, 0.0294, 0.0007], [-0.0040, 0.0007, 0.0086]],
            },
            right1 {
                parent: torso,
                joint: revolute(right_q1, [0.0, 0.0, 1.0]),
                xyz: [0.0, -0.25, 0.4],
                mass: 4.97,
                com: [0.004, 0.002, -0.094],
                inertia: [[0.70, -0.0002, 0.0086], [-0.0002, 0.70, 0.0201], [0.0086, 0.0201, 0.0092]],
            },
            right2 {
                parent: right1,
                joint: revolute(right_q2, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.0],
                rpy: [-1.0 * PI / 2.0, 0.0, 0.0],
                mass: 0.65,
                com: [-0.003, -0.028, 0.003],
                inertia: [[0.0080, -0.0039, 0.0102], [-0.0039, 0.0282, 0.0007], [0.0102, 0.0007, 0.0257]],
            },
            right3 {
                parent: right2,
                joint: revolute(right_q3, [0.0, 0.0, 1.0]),
                xyz: [0.0, -0.316, 0.0],
                rpy: [1.0 * PI / 2.0, 0.0, 0.0],
                mass: 3.23,
                com: [0.027, 0.039, -0.066],
                inertia: [[0.0372, -0.0048, -0.0114], [-0.0048, 0.0361, -0.0128], [-0.0114, -0.0128, 0.0108]],
            },
            right4 {
                parent: right3,
                joint: revolute(right_q4, [0.0, 0.0, 1.0]),
                xyz: [0.0825, 0.0, 0.0],
                rpy: [1.0 * PI / 2.0, 0.0, 0.0],
                mass: 3.59,
                com: [-0.053, 0.104, 0.027],
                inertia: [[0.0260, 0.0077, -0.0013], [0.0077, 0.0196, 0.0086], [-0.0013, 0.0086, 0.0283]],
            },
            right5 {
                parent: right4,
                joint: revolute(right_q5, [0.0, 0.0, 1.0]),
                xyz: [-0.0825, 0.384, 0.0],
                rpy: [-1.0 * PI / 2.0, 0.0, 0.0],
                mass: payload,
                com: [-0.012, 0.041, -0.038],
                inertia: [[0.0356, -0.0021, -0.0040], [-0.0021, 0.0294, 0.0007], [-0.0040, 0.0007, 0.0086]],
            },
        ],
    }
}

/// A branched tree's `M` factored as its entries are computed (the pivots,
/// not the entries, are checked): `M q̈ = F` against nalgebra's Cholesky
/// solve of the generated `M` and `F`; a non-finite entry is
/// `NonFinite` (infinite or NaN mass), a finite `M` that is not positive
/// definite is `MassNotPositiveDefinite` (a negative mass), never NaN.
#[test]
fn a_branched_mass_reports_what_is_wrong() {
    let q = SVector::<f64, 11>::from_fn(|i, _| 0.3 * i as f64 - 1.4);
    let qd = SVector::<f64, 11>::from_fn(|i, _| 0.7 - 0.15 * i as f64);
    let arms = TwoArms::new(1.23);
    let qdd = arms.acceleration(&q, &qd, 0.0).expect("solves");
    let m = arms.mass_matrix(&q, 0.0);
    let f = arms.forces(&q, &qd, 0.0);
    let reference = m.cholesky().expect("positive definite").solve(&f);
    assert!(
        (qdd - reference).norm() <= 1e-12 * reference.norm(),
        "{qdd} vs {reference}"
    );
    for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        assert_eq!(
            TwoArms::new(bad).acceleration(&q, &qd, 0.0),
            Err(DynamicsError::NonFinite),
            "payload {bad}"
        );
    }
    assert_eq!(
        TwoArms::new(-40.0).acceleration(&q, &qd, 0.0),
        Err(DynamicsError::MassNotPositiveDefinite)
    );
}
