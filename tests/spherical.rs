//! Spherical joints (`spherical(qw, qx, qy, qz)`, a unit quaternion whose
//! norm is a constraint) and URDF `floating` joints (the free joint).
//! Checked against truths written without bodies: the heavy top and the
//! Cartesian spherical pendulum of `constrained::models`, written from `T`
//! and `V` or `M` and `F`; energy conservation; and a floating-base robot
//! read from a URDF file against the same robot in the `bodies` section.

use constrained::models::{quaternion_state, HeavyTop, SphericalPendulum};
use constrained::nalgebra::{Quaternion, Rotation3, SVector, UnitQuaternion, Vector3, Vector4};
use constrained::{constrained_system, ConstrainedSystem, DormandPrince45, Stabilization, State};

constrained_system! {
    /// A symmetric top on a spherical joint at the world's origin: mass
    /// `m`, centre of mass `l` up its axis, moments `a` (about the pivot,
    /// across the axis) and `c` (about the axis).
    pub struct SphericalTop {
        parameters: [a, c, m, l],
        bodies: [
            top {
                joint: spherical(e0, e1, e2, e3),
                mass: m,
                com: [0.0, 0.0, l],
                inertia: diag[a - m * l * l, a - m * l * l, c],
            },
        ],
    }
}

constrained_system! {
    /// The same top with its joint frame placed by `xyz` and `rpy`, under
    /// gravity `[gx, gy, gz]` given in the world: in the joint frame it is
    /// the heavy top's when `[gx, gy, gz] = R(rpy) [0, 0, −9.81]`.
    pub struct PlacedTop {
        parameters: [a, c, m, l, gx, gy, gz],
        gravity: [gx, gy, gz],
        bodies: [
            top {
                joint: spherical(e0, e1, e2, e3),
                xyz: [0.3, -0.2, 1.0],
                rpy: [0.4, -0.7, 1.1],
                mass: m,
                com: [0.0, 0.0, l],
                inertia: diag[a - m * l * l, a - m * l * l, c],
            },
        ],
    }
}

/// Random attitudes and body angular velocities, `ω₃` scaled by `spin`.
fn tops(spin: f64) -> Vec<State<f64, 4>> {
    (0..40)
        .map(|k| {
            let x = f64::from(k);
            let e = Vector4::new(
                1.0 + 0.3 * x.sin(),
                0.4 * x.cos(),
                -0.3,
                0.2 * (2.0 * x).sin(),
            );
            let w = Vector3::new(x.cos(), 2.0 * (0.5 * x).sin(), spin * (3.0 - 0.1 * x));
            quaternion_state(0.0, e, w)
        })
        .collect()
}

/// A top on a spherical joint moves as the heavy top written from `T` and
/// `V` in quaternions: the same `q̈` to 1e-12 and the same energy to 1e-13
/// at 40 random consistent states; placed by `xyz` and `rpy` under gravity
/// turned the same way, still the heavy top's.
#[test]
fn a_top_on_a_spherical_joint_is_the_heavy_top() {
    let (a, c, m, l) = (0.8, 0.3, 2.0, 0.4);
    let top = SphericalTop::new(a, c, m, l);
    let (roll, pitch, yaw) = (0.4, -0.7, 1.1);
    let g = Rotation3::from_euler_angles(roll, pitch, yaw) * Vector3::new(0.0, 0.0, -9.81);
    let placed = PlacedTop::new(a, c, m, l, g.x, g.y, g.z);
    let reference = HeavyTop::new(a, c, m, 9.81, l);
    let (mut worst, mut energy): (f64, f64) = (0.0, 0.0);
    for s in tops(1.0) {
        let expected = reference.acceleration(&s.q, &s.qd, 0.0).unwrap();
        let scale = expected.norm().max(1.0);
        for got in [
            top.acceleration(&s.q, &s.qd, 0.0).unwrap(),
            placed.acceleration(&s.q, &s.qd, 0.0).unwrap(),
        ] {
            worst = worst.max((got - expected).norm() / scale);
        }
        let e = reference.energy(&s.q, &s.qd, 0.0).unwrap();
        energy = energy.max((top.energy(&s.q, &s.qd, 0.0).unwrap() - e).abs() / e.abs().max(1.0));
    }
    println!("spherical joint against the heavy top: q̈ {worst:.1e}, energy {energy:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
    assert!(energy < 1e-13, "{energy:e}");
    assert_eq!(
        <SphericalTop<f64> as ConstrainedSystem<f64, 4, 1>>::REDUNDANCY,
        0
    );
}

/// A rod on a spherical joint, its mass `m` at `l` below the pivot and no
/// inertia across it (a moment `c` about it only), not spinning about
/// itself (`ω₃ = 0`): its centre of mass accelerates as the Cartesian
/// spherical pendulum's point, `c̈ = ω̇ × r + ω × (ω × r)` from `q̈`, to 1e-12.
#[test]
fn a_rod_on_a_spherical_joint_is_the_spherical_pendulum() {
    let (m, l, c) = (1.3, 0.7, 0.02);
    // The heavy top upside down: its centre of mass at −l, a = m l².
    let rod = SphericalTop::new(m * l * l, c, m, -l);
    let pendulum = SphericalPendulum::new(m, 9.81, l);
    let mut worst: f64 = 0.0;
    for s in tops(0.0) {
        let qdd = rod.acceleration(&s.q, &s.qd, 0.0).unwrap();
        let conj = Quaternion::new(s.q[0], s.q[1], s.q[2], s.q[3]).conjugate();
        let quat = |v: &SVector<f64, 4>| Quaternion::new(v[0], v[1], v[2], v[3]);
        let w = (quat(&s.qd) * conj).imag() * 2.0;
        let dw = (quat(&qdd) * conj).imag() * 2.0;
        let rot = UnitQuaternion::from_quaternion(quat(&s.q));
        let r = rot * Vector3::new(0.0, 0.0, -l);
        let (rd, rdd) = (w.cross(&r), dw.cross(&r) + w.cross(&w.cross(&r)));
        let expected = pendulum.acceleration(&r, &rd, 0.0).unwrap();
        worst = worst.max((rdd - expected).norm() / expected.norm().max(1.0));
    }
    println!("rod on a spherical joint against the spherical pendulum: {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// The arm and ball of [`ArmAndBall`] as `$name`, with `$rest` (more
/// sections) after its bodies: written once for it and [`TetheredBall`].
macro_rules! arm_and_ball {
    ($(#[$attr:meta])* $name:ident $(, $($rest:tt)*)?) => {
        constrained_system! {
            $(#[$attr])*
            pub struct $name {
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
                        rpy: [PI / 2.0, 0.0, 0.3],
                        mass: 0.8,
                        com: [0.05, -0.02, -0.2],
                        inertia: [[0.01, 0.001, 0.0], [0.001, 0.012, -0.002], [0.0, -0.002, 0.006]],
                    },
                ],
                $($($rest)*)?
            }
        }
    };
}

arm_and_ball!(
    /// A revolute arm carrying a body on a spherical joint at its tip.
    ArmAndBall
);

/// The arm and its ball, unforced: over 10 s the energy is conserved to
/// 1e-9 and the quaternion keeps its unit norm (projection).
#[test]
fn a_chain_through_a_spherical_joint_conserves_energy() {
    let sys = ArmAndBall::<f64>::new();
    let r = quaternion_state(
        0.0,
        Vector4::new(0.9, 0.2, -0.3, 0.1),
        Vector3::new(1.5, -0.7, 2.0),
    );
    let q = SVector::<f64, 5>::from_column_slice(&[0.6, r.q[0], r.q[1], r.q[2], r.q[3]]);
    let qd = SVector::<f64, 5>::from_column_slice(&[-1.1, r.qd[0], r.qd[1], r.qd[2], r.qd[3]]);
    let mut s = State::new(0.0, q, qd);
    let e0 = sys.energy(&s.q, &s.qd, 0.0).unwrap();
    DormandPrince45::new(1e-12, 1e-12)
        .with_stabilization(Stabilization::projection(1e-13))
        .advance(&sys, &mut s, 10.0)
        .expect("integrates");
    let drift = (sys.energy(&s.q, &s.qd, 0.0).unwrap() - e0).abs() / e0.abs();
    let norm = (s.q.fixed_rows::<4>(1).norm() - 1.0).abs();
    println!("arm and ball, 10 s: energy {drift:.1e}, |q| − 1 {norm:.1e}");
    assert!(drift < 1e-9, "{drift:e}");
    assert!(norm < 1e-12, "{norm:e}");
}

constrained_system! {
    /// A floating torso with an arm, read from a URDF file whose root
    /// joint is `floating`.
    pub struct FloatingUrdf {
        urdf: "data/floating_arm.urdf",
    }
}

constrained_system! {
    /// The same robot in the `bodies` section, its coordinates named as
    /// the URDF section names them.
    pub struct FloatingBodies {
        bodies: [
            torso {
                joint: free(base_x, base_y, base_z, base_qw, base_qx, base_qy, base_qz),
                xyz: [0.1, 0.0, 0.5],
                rpy: [0.0, 0.0, PI / 2.0],
                mass: 3.2,
                com: [0.02, -0.01, 0.05],
                inertia: [[0.11, 0.01, -0.02], [0.01, 0.09, 0.005], [-0.02, 0.005, 0.07]],
            },
            arm {
                parent: torso,
                joint: revolute(shoulder, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.15, 0.2],
                rpy: [PI / 2.0, 0.0, 0.0],
                mass: 1.1,
                com: [0.0, 0.0, 0.25],
                inertia: diag[0.03, 0.03, 0.002],
            },
            hand {
                parent: arm,
                joint: fixed,
                xyz: [0.0, 0.0, 0.5],
                mass: 0.4,
                com: [0.05, 0.0, 0.0],
                inertia: diag[0.001, 0.002, 0.0015],
            },
        ],
    }
}

/// A URDF's `floating` joint is the free joint: the file's robot and the
/// same robot in `bodies` give the same `M`, `q̈` and inverse dynamics to
/// 1e-12 at 20 random consistent states, with the same coordinates.
#[test]
fn a_floating_urdf_joint_is_the_bodies_free_joint() {
    assert_eq!(FloatingUrdf::<f64>::DOF, 8);
    assert_eq!(
        <FloatingUrdf<f64> as ConstrainedSystem<f64, 8, 1>>::REDUNDANCY,
        0
    );
    let (urdf, bodies) = (FloatingUrdf::<f64>::new(), FloatingBodies::<f64>::new());
    let mut worst: f64 = 0.0;
    for k in 0..20 {
        let x = f64::from(k);
        let r = quaternion_state(
            0.0,
            Vector4::new(1.0 + x.sin(), 0.3 * x.cos(), -0.4, 0.2 * (3.0 * x).sin()),
            Vector3::new(x.cos(), 1.5 * (0.5 * x).sin(), 2.0 - 0.1 * x),
        );
        let mut q = SVector::<f64, 8>::zeros();
        let mut qd = SVector::<f64, 8>::zeros();
        q.fixed_rows_mut::<3>(0)
            .copy_from(&Vector3::new(0.2 * x, -0.1, 0.3 * x.cos()));
        qd.fixed_rows_mut::<3>(0)
            .copy_from(&Vector3::new(0.5, x.sin(), -0.3));
        q.fixed_rows_mut::<4>(3).copy_from(&r.q);
        qd.fixed_rows_mut::<4>(3).copy_from(&r.qd);
        q[7] = 1.3 * (0.7 * x).sin();
        qd[7] = 0.9 - 0.2 * x;
        let qdd = SVector::<f64, 8>::from_fn(|i, _| (x + i as f64).sin());
        let rel = |a: &[f64], b: &[f64]| {
            let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
            let n: f64 = b.iter().map(|y| y * y).sum();
            d.sqrt() / n.sqrt().max(1.0)
        };
        let (ma, mb) = (urdf.mass_matrix(&q, 0.0), bodies.mass_matrix(&q, 0.0));
        worst = worst.max(rel(ma.as_slice(), mb.as_slice()));
        let (aa, ab) = (
            urdf.acceleration(&q, &qd, 0.0).unwrap(),
            bodies.acceleration(&q, &qd, 0.0).unwrap(),
        );
        worst = worst.max(rel(aa.as_slice(), ab.as_slice()));
        let (ia, ib) = (
            urdf.inverse_dynamics(&q, &qd, &qdd, 0.0).unwrap(),
            bodies.inverse_dynamics(&q, &qd, &qdd, 0.0).unwrap(),
        );
        worst = worst.max(rel(ia.as_slice(), ib.as_slice()));
    }
    println!("floating URDF against the bodies section: {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
}

arm_and_ball!(
    /// [`ArmAndBall`] with a point of the ball held on the plane
    /// `z = −0.9`: one row besides the norm's, on the arm and the ball.
    TetheredBall,
    constraints: [position(ball, [0.1, 0.0, -0.4]).z == -0.9],
);

/// A spherical joint inside a chain, with a row on both its bodies, is
/// solved in the quaternion's velocity coordinates
/// (`codegen/tests/velocity.rs`): at 10 states, half of them with the
/// quaternion scaled off the unit sphere (by 0.84 to 1.16) and moving
/// along itself, `q̈` and `Aᵀλ` equal the runtime's dense solve of the
/// model's own system to 1e-12, with and without a correction of `b`, and
/// `A q̈ = b` holds to 1e-12.
/// (The states need not satisfy the plane's row: `q̈` is defined at any
/// state.)
#[test]
fn a_tethered_ball_in_velocity_coordinates_is_the_dense_solve() {
    let sys = TetheredBall::<f64>::new();
    let mut states = Vec::new();
    for k in 0..10 {
        let x = f64::from(k);
        let r = quaternion_state(
            0.0,
            Vector4::new(0.9, 0.2 * x.sin(), -0.3, 0.1 * x),
            Vector3::new(1.5, -0.7 * x.cos(), 2.0),
        );
        let mut q =
            SVector::<f64, 5>::from_column_slice(&[0.6 + 0.1 * x, r.q[0], r.q[1], r.q[2], r.q[3]]);
        let mut qd =
            SVector::<f64, 5>::from_column_slice(&[-1.1, r.qd[0], r.qd[1], r.qd[2], r.qd[3]]);
        if k % 2 == 1 {
            for i in 1..5 {
                qd[i] += 0.3 * q[i];
                q[i] *= 1.0 + 0.04 * (x - 5.0);
            }
        }
        states.push(State::new(0.0, q, qd));
    }
    use crate::auxiliary::{against_dense, assert_close};
    let gaps = against_dense::<_, 5, 2>(&sys, &states);
    assert_close("TetheredBall, on and off the sphere", &gaps);
    assert_eq!(
        gaps.own, 20,
        "the generated solve answered every state itself"
    );
    // Far off the sphere (|q| 1.35 here) the ball is still a rigid body
    // turned by R(q/|q|), so `M` stays positive semi-definite (rank 4 of
    // 5: singular along `q` alone) and the generated solve answers, as the
    // dense one does, with the same `q̈`.
    let r = quaternion_state(0.0, Vector4::new(0.9, 0.2, -0.3, 0.7), Vector3::zeros());
    let q = SVector::<f64, 5>::from_column_slice(&[
        1.3,
        1.35 * r.q[0],
        1.35 * r.q[1],
        1.35 * r.q[2],
        1.35 * r.q[3],
    ]);
    let qd = SVector::<f64, 5>::zeros();
    let (generated, _) =
        constrained::__private::Generated::gauss(&sys, &q, &qd, 0.0, None).expect("answers");
    let (dense, _) =
        constrained::__private::gauss_dense(&sys, &q, &qd, 0.0, None).expect("answers");
    let eigenvalues = sys.mass_matrix(&q, 0.0).symmetric_eigenvalues();
    assert!(eigenvalues.min() > -1e-12, "{eigenvalues}");
    assert!((generated - dense).amax() < 1e-12 * dense.amax().max(1.0));
}

trunk_on_ball_foot!(
    /// A trunk on a free joint and a foot on a ball joint below it, one
    /// point of the foot held: the point's rows in the trunk's axes
    /// (`equations/in_base.rs`) reach through the ball's quaternion.
    FootOnOnePoint,
    [ax, ay, az],
    [position(foot, [0.12, 0.03, -0.03]) == [ax, ay, az]]
);

/// A point beyond a ball joint under a free base, in the quaternions'
/// velocity coordinates: the point's rows in the base's axes take the
/// ball's columns through `T` as every other row does (`q̈ = T z`). At 8
/// moving states, half of them with both quaternions off the unit sphere,
/// `q̈` and `Aᵀλ` equal the runtime's dense solve to 1e-12, with and
/// without a correction of `b`, the generated solve answering every one.
#[test]
fn a_point_beyond_a_ball_joint_is_the_dense_solve() {
    let sys = FootOnOnePoint::<f64>::new(0.1, -0.05, 0.2);
    let states: Vec<_> = (0..8).map(crate::common::trunk_on_foot_state).collect();
    use crate::auxiliary::{against_dense, assert_close};
    let gaps = against_dense::<_, 11, 5>(&sys, &states);
    assert_close("FootOnOnePoint, on and off the spheres", &gaps);
    assert_eq!(
        gaps.own, 16,
        "the generated solve answered every state itself"
    );
}
