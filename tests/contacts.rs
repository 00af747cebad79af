//! Contacts and loop closures on bodies, written as `position(..)` rows,
//! and their multipliers `λ` (`Q_c = Aᵀ λ`, `constrained::multipliers`):
//! a free body pinned at a point is the heavy top written by hand, its
//! pivot force Newton's `m (c̈ − g)`; a table on four feet, point-on-plane
//! rows or fixed points (redundant either way), carries `m g` in its
//! normal forces; two free bodies joined at a point conserve momentum and
//! the joint force is the one body's `m c̈`.

use constrained::floating::FreeMotion;
use constrained::models::{quaternion_state, HeavyTop};
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{Quaternion, SVector, UnitQuaternion, Vector3, Vector4};
use constrained::{constrained_system, ConstrainedSystem, DormandPrince45, Stabilization, State};

constrained_system! {
    /// A symmetric top as a free body pinned at its frame's origin: mass
    /// `m`, centre of mass `l` up its axis, moments `a` (about the pivot,
    /// across the axis) and `c` (about the axis).
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
        constraints: [position(top, [0.0, 0.0, 0.0]) == [0.0, 0.0, 0.0]],
    }
}

/// The attitude's angular acceleration in the world, `ω̇ = 2 (q̈ ⊗ q̄)_vec`
/// on the unit sphere, and the angular velocity `2 (q̇ ⊗ q̄)_vec`.
fn angular(q: &[f64], qd: &[f64], qdd: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
    let e = Quaternion::new(q[0], q[1], q[2], q[3]).conjugate();
    let w = (Quaternion::new(qd[0], qd[1], qd[2], qd[3]) * e).imag() * 2.0;
    let dw = (Quaternion::new(qdd[0], qdd[1], qdd[2], qdd[3]) * e).imag() * 2.0;
    (w, dw)
}

/// A point of a body fixed in the world: the pinned free body moves as the
/// heavy top of `constrained::models` (its attitude's `q̈` to 1e-12, the
/// pivot does not move), `Aᵀλ` is the constraint force, and the pivot's
/// three multipliers are the reaction `m (c̈ − g)` of Newton's law.
#[test]
fn a_pinned_free_body_is_the_heavy_top_and_lambda_is_the_pivot_force() {
    let (a, c, m, l) = (0.8, 0.3, 2.0, 0.4);
    let top = PinnedTop::new(a, c, m, l);
    let reference = HeavyTop::new(a, c, m, 9.81, l);
    let mut worst: f64 = 0.0;
    for k in 0..40 {
        let x = f64::from(k);
        let e = Vector4::new(
            1.0 + 0.3 * x.sin(),
            0.4 * x.cos(),
            -0.3,
            0.2 * (2.0 * x).sin(),
        );
        let w = Vector3::new(x.cos(), 2.0 * (0.5 * x).sin(), 3.0 - 0.1 * x);
        let r = quaternion_state(0.0, e, w);
        let (mut q, mut qd) = (SVector::<f64, 7>::zeros(), SVector::<f64, 7>::zeros());
        q.fixed_rows_mut::<4>(3).copy_from(&r.q);
        qd.fixed_rows_mut::<4>(3).copy_from(&r.qd);
        let s = State::new(0.0, q, qd);
        let (qdd, lambda) = top.acceleration_and_multipliers(&s).unwrap();
        let expected = reference.acceleration(&r.q, &r.qd, 0.0).unwrap();
        let scale = expected.norm().max(1.0);
        worst = worst.max((qdd.fixed_rows::<4>(3) - expected).norm() / scale);
        worst = worst.max(qdd.fixed_rows::<3>(0).norm() / scale);
        // Aᵀλ = Q_c.
        let (am, _) = ConstrainedSystem::constraint_matrices(&top, &s);
        let qc = ConstrainedSystem::constraint_force(&top, &s).unwrap();
        worst = worst.max((am.transpose() * lambda - qc).norm() / qc.norm().max(1.0));
        // Newton: the pivot force is m c̈ − m g, c = R [0, 0, l].
        let (w, dw) = angular(
            &s.q.as_slice()[3..],
            &s.qd.as_slice()[3..],
            &qdd.as_slice()[3..],
        );
        let rot = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[4], q[5], q[6]));
        let arm = rot * Vector3::new(0.0, 0.0, l);
        let cdd = dw.cross(&arm) + w.cross(&w.cross(&arm));
        let newton = (cdd - Vector3::new(0.0, 0.0, -9.81)) * m;
        worst = worst.max((lambda.fixed_rows::<3>(0) - newton).norm() / newton.norm());
    }
    println!("pinned free body against the heavy top, Aᵀλ and Newton: {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
    assert_eq!(
        <PinnedTop<f64> as ConstrainedSystem<f64, 7, 4>>::REDUNDANCY,
        0
    );
}

constrained_system! {
    /// A table, a free body with four feet at `(±a, ±b, 0)` resting on the
    /// plane `z = 0` (a point on a plane: one row each). Three rows would
    /// hold it: the four are redundant.
    pub struct TableOnPlane {
        parameters: [m, cx, cy, a, b],
        bodies: [
            table {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: m,
                com: [cx, cy, 0.3],
                inertia: diag[0.2, 0.3, 0.4],
            },
        ],
        constraints: [
            position(table, [a, b, 0.0]).z == 0.0,
            position(table, [-a, b, 0.0]).z == 0.0,
            position(table, [-a, -b, 0.0]).z == 0.0,
            position(table, [a, -b, 0.0]).z == 0.0,
        ],
    }
}

constrained_system! {
    /// The same table with its feet fixed on the ground (three rows each):
    /// twelve rows on six degrees of freedom.
    pub struct TableFixed {
        parameters: [m, cx, cy, a, b],
        bodies: [
            table {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: m,
                com: [cx, cy, 0.3],
                inertia: diag[0.2, 0.3, 0.4],
            },
        ],
        constraints: [
            position(table, [a, b, 0.0]) == [a, b, 0.0],
            position(table, [-a, b, 0.0]) == [-a, b, 0.0],
            position(table, [-a, -b, 0.0]) == [-a, -b, 0.0],
            position(table, [a, -b, 0.0]) == [a, -b, 0.0],
        ],
    }
}

/// Resting on four feet, the table does not move and its normal forces sum
/// to `m g` and balance the moment of its weight (`Σ λᵢ xᵢ = m g cₓ`); with
/// the centre of mass in the middle the minimum-norm forces are `m g / 4`
/// each. Both forms are redundant by the macro's measure.
#[test]
fn a_table_on_four_feet_carries_its_weight_in_its_normal_forces() {
    let (m, a, b) = (3.0, 0.5, 0.3);
    let rest = FreeMotion::at_rest(Vector3::zeros(), UnitQuaternion::identity());
    let (mut q, mut qd) = (SVector::<f64, 7>::zeros(), SVector::<f64, 7>::zeros());
    rest.write(0, &mut q, &mut qd).unwrap();
    let s = State::new(0.0, q, qd);
    let feet = [(a, b), (-a, b), (-a, -b), (a, -b)];
    for (cx, cy) in [(0.0, 0.0), (0.2, -0.1)] {
        let plane = TableOnPlane::new(m, cx, cy, a, b);
        let (qdd, lambda) = plane.acceleration_and_multipliers(&s).unwrap();
        assert!(qdd.norm() < 1e-13, "{qdd}");
        let normal: Vec<f64> = (0..4).map(|i| lambda[i]).collect();
        let weight = m * 9.81;
        let sum: f64 = normal.iter().sum();
        let mx: f64 = normal.iter().zip(&feet).map(|(f, p)| f * p.0).sum();
        let my: f64 = normal.iter().zip(&feet).map(|(f, p)| f * p.1).sum();
        println!("table on a plane, com ({cx}, {cy}): normal forces {normal:?}");
        assert!((sum - weight).abs() < 1e-12 * weight, "{sum}");
        assert!(
            (mx - weight * cx).abs() < 1e-12 * weight && (my - weight * cy).abs() < 1e-12 * weight
        );
        if cx == 0.0 {
            assert!(normal
                .iter()
                .all(|f| (f - weight / 4.0).abs() < 1e-12 * weight));
        }
        let fixed = TableFixed::new(m, cx, cy, a, b);
        let (qdd, lambda) = fixed.acceleration_and_multipliers(&s).unwrap();
        assert!(qdd.norm() < 1e-13, "{qdd}");
        let total = (0..4).fold(Vector3::zeros(), |f, i| f + lambda.fixed_rows::<3>(3 * i));
        assert!(
            (total - Vector3::new(0.0, 0.0, weight)).norm() < 1e-12 * weight,
            "{total}"
        );
        let (am, _) = ConstrainedSystem::constraint_matrices(&fixed, &s);
        let qc = ConstrainedSystem::constraint_force(&fixed, &s).unwrap();
        assert!((am.transpose() * lambda - qc).norm() < 1e-12 * weight);
    }
    assert_eq!(
        <TableOnPlane<f64> as ConstrainedSystem<f64, 7, 5>>::REDUNDANCY,
        1
    );
    assert_eq!(
        <TableFixed<f64> as ConstrainedSystem<f64, 7, 13>>::REDUNDANCY,
        6
    );
}

constrained_system! {
    /// Two free bodies joined at a point (a ball joint as a loop closure):
    /// the point `[0.3, 0, 0]` of `a` on the point `[0, 0, -0.2]` of `b`.
    pub struct Joined {
        gravity: [0.0, 0.0, 0.0],
        bodies: [
            a {
                joint: free(xa, ya, za, wa, ia, ja, ka),
                mass: 1.5,
                com: [0.05, 0.0, 0.0],
                inertia: diag[0.1, 0.2, 0.25],
            },
            b {
                joint: free(xb, yb, zb, wb, ib, jb, kb),
                mass: 0.7,
                com: [0.0, 0.02, 0.0],
                inertia: diag[0.05, 0.04, 0.03],
            },
        ],
        constraints: [position(a, [0.3, 0.0, 0.0]) == position(b, [0.0, 0.0, -0.2])],
    }
}

/// The centre of mass of body `k` of [`Joined`] and its velocity.
fn com_of(s: &State<f64, 14>, k: usize) -> (Vector3<f64>, Vector3<f64>) {
    let f = FreeMotion::read(7 * k, &s.q, &s.qd).unwrap();
    let local = [Vector3::new(0.05, 0.0, 0.0), Vector3::new(0.0, 0.02, 0.0)][k];
    let r = f.orientation * local;
    (f.position + r, f.linear + f.angular.cross(&r))
}

/// Two bodies joined at a point in zero gravity: over 10 s the joint holds
/// to 1e-10 and the total momentum is conserved; at every step the joint's
/// multipliers are the force on `a`'s point, `m_a c̈_a` (the only force on
/// `a`).
#[test]
fn two_bodies_joined_at_a_point_conserve_momentum_and_lambda_is_the_joint_force() {
    let sys = Joined::new();
    let ra = UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3);
    let rb = UnitQuaternion::from_euler_angles(-0.4, 0.1, 0.0);
    let a = FreeMotion {
        position: Vector3::zeros(),
        orientation: ra,
        linear: Vector3::new(0.1, 0.0, 0.0),
        angular: Vector3::new(0.0, 0.0, 1.0),
    };
    // b's point on a's, with b's velocity there matching a's.
    let pa = ra * Vector3::new(0.3, 0.0, 0.0);
    let pb = rb * Vector3::new(0.0, 0.0, -0.2);
    let wb = Vector3::new(0.5, -1.0, 0.2);
    let vb = a.linear + a.angular.cross(&pa) - wb.cross(&pb);
    let b = FreeMotion {
        position: a.position + pa - pb,
        orientation: rb,
        linear: vb,
        angular: wb,
    };
    let (mut q, mut qd) = (SVector::<f64, 14>::zeros(), SVector::<f64, 14>::zeros());
    a.write(0, &mut q, &mut qd).unwrap();
    b.write(7, &mut q, &mut qd).unwrap();
    let mut s = State::new(0.0, q, qd);
    let momentum = |s: &State<f64, 14>| com_of(s, 0).1 * 1.5 + com_of(s, 1).1 * 0.7;
    let p0 = momentum(&s);
    let e0 = sys.energy(&s.q, &s.qd, 0.0).unwrap();
    let mut worst_force: f64 = 0.0;
    let integrator =
        DormandPrince45::new(1e-12, 1e-12).with_stabilization(Stabilization::projection(1e-12));
    for step in 1..=20 {
        let (qdd, lambda) = sys.acceleration_and_multipliers(&s).unwrap();
        // c̈_a by a central difference of ċ_a along the exact flow would do;
        // here from q̈ directly: c̈ = p̈ + ω̇ × r + ω × (ω × r).
        let qs = s.q.as_slice();
        let (w, dw) = angular(&qs[3..7], &s.qd.as_slice()[3..7], &qdd.as_slice()[3..7]);
        let r = UnitQuaternion::from_quaternion(Quaternion::new(qs[3], qs[4], qs[5], qs[6]))
            * Vector3::new(0.05, 0.0, 0.0);
        let cdd = qdd.fixed_rows::<3>(0) + dw.cross(&r) + w.cross(&w.cross(&r));
        let f = lambda.fixed_rows::<3>(0);
        worst_force = worst_force.max((f - cdd * 1.5).norm() / f.norm().max(1e-3));
        integrator
            .advance(&sys, &mut s, 0.5 * f64::from(step))
            .expect("integrates");
    }
    let residual = ConstrainedSystem::constraint_residual(&sys, &s).amax();
    let dp = (momentum(&s) - p0).norm() / p0.norm();
    let de = (sys.energy(&s.q, &s.qd, 0.0).unwrap() - e0).abs() / e0;
    println!("joined bodies, 10 s: residual {residual:.1e}, momentum {dp:.1e}, energy {de:.1e}, joint force {worst_force:.1e}");
    assert!(
        residual < 1e-10 && dp < 1e-10 && de < 1e-10,
        "{residual:e} {dp:e} {de:e}"
    );
    assert!(worst_force < 1e-11, "{worst_force:e}");
}

/// `gauss` solves the joined bodies in their two quaternions' velocity
/// coordinates (`q̈ = ½ (q α + Gᵀ β)` each; `codegen/tests/velocity.rs`):
/// at 12 states — consistent ones, and ones with each quaternion scaled
/// off the unit sphere and given a rate along itself — its `q̈` and `Aᵀλ`
/// equal the runtime's dense solve of the model's own `M`, `F`, `A`, `b`
/// to 1e-12, with and without a correction of `b`, and it answered every
/// state itself (not bit for bit the dense solve's).
#[test]
fn the_joined_bodies_velocity_solve_equals_the_dense_one() {
    let sys = Joined::new();
    let mut states = Vec::new();
    for k in 0..12 {
        let x = f64::from(k);
        let ra = UnitQuaternion::from_euler_angles(0.3 * x.sin(), 0.2, -0.1 * x);
        let rb = UnitQuaternion::from_euler_angles(-0.4, 0.1 * x.cos(), 0.5);
        let a = FreeMotion {
            position: Vector3::new(0.1, -0.2, 0.05 * x),
            orientation: ra,
            linear: Vector3::new(0.1, 0.3 * x.cos(), 0.0),
            angular: Vector3::new(0.2 * x.sin(), -0.5, 1.0),
        };
        let pa = ra * Vector3::new(0.3, 0.0, 0.0);
        let pb = rb * Vector3::new(0.0, 0.0, -0.2);
        let wb = Vector3::new(0.5, -1.0, 0.2 * x);
        let b = FreeMotion {
            position: a.position + pa - pb,
            orientation: rb,
            linear: a.linear + a.angular.cross(&pa) - wb.cross(&pb),
            angular: wb,
        };
        let (mut q, mut qd) = (SVector::<f64, 14>::zeros(), SVector::<f64, 14>::zeros());
        a.write(0, &mut q, &mut qd).unwrap();
        b.write(7, &mut q, &mut qd).unwrap();
        if k % 2 == 1 {
            for (first, scale) in [(3, 0.8), (10, 1.25)] {
                for i in first..first + 4 {
                    qd[i] += 0.2 * q[i];
                    q[i] *= scale;
                }
            }
        }
        states.push(State::new(0.0, q, qd));
    }
    use crate::auxiliary::{against_dense, assert_close};
    let gaps = against_dense::<_, 14, 5>(&sys, &states);
    assert_close("Joined, on and off the sphere", &gaps);
    assert_eq!(
        gaps.own, 24,
        "the generated solve answered every state itself"
    );
}

/// The joined bodies' saddle-point factorization reads `TᵀMT` as it is
/// computed, with no check of its entries before: a non-finite state
/// (a quaternion's entry infinite or NaN, which reaches `M`; a rate that
/// is NaN, which reaches `F`) is still `NonFinite`, never a finite answer.
#[test]
fn the_joined_bodies_report_a_non_finite_state() {
    use constrained::DynamicsError;
    let sys = Joined::new();
    let ra = UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3);
    let mut q = SVector::<f64, 14>::zeros();
    // (w, i, j, k) per body, after its position.
    let qa = ra.quaternion();
    (q[3], q[4], q[5], q[6]) = (qa.w, qa.i, qa.j, qa.k);
    (q[9], q[10]) = (-0.4, 1.0);
    let qd = SVector::<f64, 14>::from_fn(|i, _| 0.1 * i as f64 - 0.5);
    assert!(sys.acceleration(&q, &qd, 0.0).is_ok());
    for bad in [f64::INFINITY, f64::NAN] {
        let mut q_bad = q;
        q_bad[4] = bad;
        assert_eq!(
            sys.acceleration(&q_bad, &qd, 0.0),
            Err(DynamicsError::NonFinite),
            "quaternion entry {bad}"
        );
        let mut qd_bad = qd;
        qd_bad[11] = bad;
        assert_eq!(
            sys.acceleration(&q, &qd_bad, 0.0),
            Err(DynamicsError::NonFinite),
            "rate {bad}"
        );
    }
}
