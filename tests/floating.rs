//! A floating base: one body on a free joint (`free(x, y, z, qw, qx, qy,
//! qz)`), its attitude a unit quaternion whose norm is a constraint, solved
//! through the auxiliary mass. Checked against truths that owe nothing to
//! the recursions: conservation laws in zero gravity, the quaternion model
//! written by hand from `T = ½ ωᵀJω`, the exact torque-free spin about a
//! principal axis, and a centre of mass falling as ½ g t².

use constrained::floating::{FreeJointError, FreeMotion};
use constrained::models::{quaternion_state, RigidBodyQuaternion};
use constrained::nalgebra::{Matrix3, SVector, UnitQuaternion, Vector3, Vector4};
use constrained::{constrained_system, ConstrainedSystem, DormandPrince45, Stabilization, State};

constrained_system! {
    /// A rigid body of mass `m`, centre of mass `[cx, cy, cz]` in its frame
    /// and principal moments `i1, i2, i3` about it, free in space under
    /// gravity `[0, 0, gz]`.
    pub struct FreeBody {
        parameters: [m, cx, cy, cz, i1, i2, i3, gz],
        gravity: [0.0, 0.0, gz],
        bodies: [
            body {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: m,
                com: [cx, cy, cz],
                inertia: diag[i1, i2, i3],
            },
        ],
    }
}

type S = State<f64, 7>;

fn body(com: [f64; 3], gz: f64) -> FreeBody<f64> {
    FreeBody::new(1.7, com[0], com[1], com[2], 0.3, 0.5, 0.7, gz)
}

fn state(motion: &FreeMotion<f64>) -> S {
    let (mut q, mut qd) = (SVector::zeros(), SVector::zeros());
    motion.write(0, &mut q, &mut qd).unwrap();
    State::new(0.0, q, qd)
}

fn tumbling() -> FreeMotion<f64> {
    FreeMotion {
        position: Vector3::new(0.2, -0.4, 1.0),
        orientation: UnitQuaternion::from_euler_angles(0.3, -0.5, 1.1),
        linear: Vector3::new(0.3, 0.1, -0.2),
        angular: Vector3::new(0.4, 1.9, -0.7),
    }
}

/// The centre of mass in the world, its velocity, and the angular
/// momentum about the world's origin.
fn momenta(sys: &FreeBody<f64>, s: &S) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let f = FreeMotion::read(0, &s.q, &s.qd).unwrap();
    let r = f.orientation.to_rotation_matrix();
    let com = r * Vector3::new(sys.cx, sys.cy, sys.cz);
    let c = f.position + com;
    let cd = f.linear + f.angular.cross(&com);
    let spin = r * Matrix3::from_diagonal(&Vector3::new(sys.i1, sys.i2, sys.i3)) * f.body_angular();
    (c, cd, c.cross(&(sys.m * cd)) + spin)
}

/// In zero gravity over 20 s: energy, linear and angular momentum are
/// conserved to 1e-10 and the quaternion keeps its unit norm.
#[test]
fn a_free_body_conserves_energy_and_momenta() {
    let sys = body([0.1, -0.05, 0.2], 0.0);
    let mut s = state(&tumbling());
    let e0 = sys.energy(&s.q, &s.qd, 0.0).unwrap();
    let (_, p0, l0) = momenta(&sys, &s);
    DormandPrince45::new(1e-12, 1e-12)
        .with_stabilization(Stabilization::projection(1e-13))
        .advance(&sys, &mut s, 20.0)
        .expect("integrates");
    let e1 = sys.energy(&s.q, &s.qd, 0.0).unwrap();
    let (_, p1, l1) = momenta(&sys, &s);
    let de = (e1 - e0).abs() / e0;
    let (dp, dl) = ((p1 - p0).norm() / p0.norm(), (l1 - l0).norm() / l0.norm());
    let norm = (s.q.fixed_rows::<4>(3).norm() - 1.0).abs();
    println!("free body, 20 s: energy {de:.1e}, momentum {dp:.1e}, angular momentum {dl:.1e}, |q|-1 {norm:.1e}");
    assert!(
        de < 1e-10 && dp < 1e-10 && dl < 1e-10,
        "{de:e} {dp:e} {dl:e}"
    );
    assert!(norm < 1e-12, "{norm:e}");
}

/// With the centre of mass at the origin, the attitude's `q̈` is that of
/// the quaternion model written by hand from `T = ½ ωᵀJω`, and the origin
/// does not accelerate, at random tumbling states.
#[test]
fn the_attitude_moves_as_the_hand_written_quaternion_model() {
    let sys = body([0.0; 3], 0.0);
    let reference = RigidBodyQuaternion::new(0.3, 0.5, 0.7);
    let mut worst: f64 = 0.0;
    for k in 0..50 {
        let x = f64::from(k);
        let e = Vector4::new(x.sin() + 1.2, (1.3 * x).cos(), (0.7 * x).sin(), -0.4);
        let w = Vector3::new((2.1 * x).sin() * 3.0, (0.9 * x).cos(), 1.0 - 0.1 * x);
        let r = quaternion_state(0.0, e, w);
        let mut q = SVector::<f64, 7>::zeros();
        let mut qd = SVector::<f64, 7>::zeros();
        q.fixed_rows_mut::<4>(3).copy_from(&r.q);
        qd.fixed_rows_mut::<4>(3).copy_from(&r.qd);
        qd[0] = 0.5;
        let qdd = sys.acceleration(&q, &qd, 0.0).unwrap();
        let expected = reference.acceleration(&r.q, &r.qd, 0.0).unwrap();
        let scale = expected.norm().max(1.0);
        worst = worst.max((qdd.fixed_rows::<4>(3) - expected).norm() / scale);
        worst = worst.max(qdd.fixed_rows::<3>(0).norm() / scale);
    }
    println!("free body against the hand-written quaternion model: {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// Spinning about a principal axis through the centre of mass is a
/// steady rotation, `q(t) = q₀ ⊗ exp(ω t / 2)`: `q̈ = −|ω|²/4 q` exactly,
/// and a 10 s run follows the closed form.
#[test]
fn torque_free_spin_about_a_principal_axis_is_exact() {
    let sys = body([0.0; 3], 0.0);
    let q0 = UnitQuaternion::from_euler_angles(0.2, 0.4, -0.3);
    let spin = Vector3::new(0.0, 2.5, 0.0); // body axes: the middle principal axis
    let start = FreeMotion {
        position: Vector3::zeros(),
        orientation: q0,
        linear: Vector3::new(0.1, 0.0, 0.0),
        angular: q0 * spin,
    };
    let mut s = state(&start);
    let qdd = sys.acceleration(&s.q, &s.qd, 0.0).unwrap();
    let steady = s.q.fixed_rows::<4>(3) * (-spin.norm_squared() / 4.0);
    let err0 = (qdd.fixed_rows::<4>(3) - steady).norm() + qdd.fixed_rows::<3>(0).norm();
    assert!(err0 < 1e-13, "{err0:e}");
    let t = 10.0;
    DormandPrince45::new(1e-12, 1e-12)
        .with_stabilization(Stabilization::projection(1e-13))
        .advance(&sys, &mut s, t)
        .expect("integrates");
    let exact = q0 * UnitQuaternion::from_scaled_axis(spin * t);
    let got = FreeMotion::read(0, &s.q, &s.qd).unwrap();
    let angle = got.orientation.angle_to(&exact);
    let drift = (got.position - Vector3::new(0.1 * t, 0.0, 0.0)).norm();
    let rate = (got.body_angular() - spin).norm();
    println!(
        "principal spin, 10 s: attitude {angle:.1e} rad, position {drift:.1e}, rate {rate:.1e}"
    );
    assert!(
        angle < 1e-9 && drift < 1e-9 && rate < 1e-9,
        "{angle:e} {drift:e} {rate:e}"
    );
}

/// Dropped while tumbling, with its centre of mass off the origin: the
/// centre of mass falls as `c₀ + ċ₀ t + ½ g t²`, whatever the spin.
#[test]
fn a_dropped_body_falls_as_half_g_t_squared() {
    let sys = body([0.1, -0.05, 0.2], -9.81);
    let mut s = state(&tumbling());
    let (c0, cd0, _) = momenta(&sys, &s);
    let t = 2.0;
    DormandPrince45::new(1e-12, 1e-12)
        .with_stabilization(Stabilization::projection(1e-13))
        .advance(&sys, &mut s, t)
        .expect("integrates");
    let (c1, _, _) = momenta(&sys, &s);
    let exact = c0 + cd0 * t + Vector3::new(0.0, 0.0, -9.81) * (t * t / 2.0);
    let err = (c1 - exact).norm();
    println!("dropped body, 2 s: centre of mass {err:.1e} m from ½gt²");
    assert!(err < 1e-9, "{err:e}");
    // At rest with the centre of mass at the origin, q̈ is g, exactly.
    let still = body([0.0; 3], -9.81);
    let rest = state(&FreeMotion::at_rest(
        Vector3::zeros(),
        tumbling().orientation,
    ));
    let qdd = still.acceleration(&rest.q, &rest.qd, 0.0).unwrap();
    assert!((qdd[2] + 9.81).abs() < 1e-14 && qdd.fixed_rows::<2>(0).norm() < 1e-14);
    assert!(qdd.fixed_rows::<4>(3).norm() < 1e-14, "{qdd}");
}

/// The norm is the system's one constraint row, and the state helpers
/// write a state that satisfies it and its velocity, and read back the
/// twist; a zero quaternion or a range past the state is an error.
#[test]
fn the_state_helpers_round_trip_and_satisfy_the_norm() {
    let sys = body([0.1, -0.05, 0.2], -9.81);
    let motion = tumbling();
    let s = state(&motion);
    let phi = ConstrainedSystem::constraint_residual(&sys, &s);
    let dphi = ConstrainedSystem::constraint_velocity_residual(&sys, &s);
    assert!(phi.norm() < 1e-15 && dphi.norm() < 1e-15, "{phi} {dphi}");
    let back = FreeMotion::read(0, &s.q, &s.qd).unwrap();
    assert!((back.angular - motion.angular).norm() < 1e-14);
    assert!((back.linear - motion.linear).norm() < 1e-15);
    assert!(back.orientation.angle_to(&motion.orientation) < 1e-15);
    let mut q = s.q;
    q.fixed_rows_mut::<4>(3).fill(0.0);
    assert_eq!(
        FreeMotion::read(0, &q, &s.qd),
        Err(FreeJointError::NoAttitude)
    );
    assert_eq!(
        FreeMotion::read(1, &s.q, &s.qd),
        Err(FreeJointError::OutOfRange)
    );
}
