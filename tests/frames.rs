//! Named frames and the centre of mass (the `frames` section) against
//! truths that do not use them: placements and the centre of mass of a
//! spatial arm written out by hand with nalgebra's rotations, the Jacobian
//! against central differences of the placement along `q̇`, `J q̇` against
//! the velocity of the same point written as `velocity(body, [..])` in a
//! twin system, `J̇ q̇` against central differences of `J(q + h q̇) q̇`, a
//! free base's frame against the twist `FreeMotion` writes (the quaternion
//! rates' convention), and the Panda's tool frame against the product of
//! its URDF's joint transforms written out here.

use constrained::constrained_system;
use constrained::nalgebra::{
    Isometry3, Matrix3, Rotation3, SMatrix, SVector, Translation3, UnitQuaternion, Vector3,
};

/// The three-link arm of these tests (a fixed tool, a slider on the
/// forearm) with the sections given after its bodies: `frames.rs` and
/// `centroidal.rs` name different frames on the same arm.
macro_rules! three_link_arm {
    ($(#[$attr:meta])* $name:ident { $($rest:tt)* }) => {
        constrained::constrained_system! {
            $(#[$attr])*
            pub struct $name {
                gravity: [0.0, 0.0, -9.81],
                bodies: [
                    base {
                        joint: revolute(q1, [0.0, 0.0, 1.0]),
                        mass: 2.0,
                        com: [0.0, 0.0, 0.2],
                        inertia: diag[0.05, 0.06, 0.03],
                    },
                    upper {
                        parent: base,
                        joint: revolute(q2, [0.0, 1.0, 0.0]),
                        xyz: [0.0, 0.0, 0.4],
                        mass: 1.5,
                        com: [0.25, 0.0, 0.0],
                        inertia: diag[0.01, 0.04, 0.045],
                    },
                    fore {
                        parent: upper,
                        joint: revolute(q3, [0.0, 1.0, 0.0]),
                        xyz: [0.5, 0.0, 0.0],
                        mass: 1.0,
                        com: [0.2, 0.0, 0.0],
                        inertia: diag[0.005, 0.02, 0.021],
                    },
                    tool {
                        parent: fore,
                        joint: fixed,
                        xyz: [0.0, 0.1, 0.0],
                        rpy: [PI / 2.0, 0.0, 0.0],
                        mass: 0.2,
                        com: [0.0, 0.0, 0.05],
                        inertia: diag[0.001, 0.002, 0.003],
                    },
                    slider {
                        parent: fore,
                        joint: prismatic(s, [1.0, 0.0, 0.0]),
                        xyz: [0.3, 0.0, 0.0],
                        mass: 0.5,
                        inertia: diag[0.0004, 0.0005, 0.0006],
                    },
                ],
                $($rest)*
            }
        }
    };
}
pub(crate) use three_link_arm;

three_link_arm! {
    /// The arm with three named frames: one on a body merged by a fixed
    /// joint, one a body's own frame, one turned every way.
    FramedArm {
        frames: [
            tip { body: tool, xyz: [0.0, 0.0, 0.1], rpy: [0.0, 0.0, 0.3] },
            elbow { body: fore },
            hand { body: slider, xyz: [0.05, 0.02, -0.01], rpy: [0.2, -0.4, 0.7] },
        ],
        derivatives: [inverse_dynamics],
    }
}

three_link_arm! {
    /// The same arm without frames, the velocity of `hand`'s origin written
    /// as a point of `slider` (the constraint's residual is that velocity).
    ArmPointVelocity {
        constraints: [velocity(slider, [0.05, 0.02, -0.01]) == [0.0, 0.0, 0.0]],
    }
}

constrained_system! {
    /// A floating trunk carrying a swinging leg, a frame at the foot.
    pub struct FloatingLeg {
        gravity: [0.0, 0.0, -9.81],
        bodies: [
            trunk {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: 3.0,
                com: [0.1, 0.0, 0.0],
                inertia: diag[0.03, 0.04, 0.05],
            },
            leg {
                parent: trunk,
                joint: revolute(a, [0.0, 1.0, 0.0]),
                xyz: [0.2, 0.0, 0.1],
                mass: 1.0,
                com: [0.0, 0.0, -0.2],
                inertia: diag[0.01, 0.01, 0.002],
            },
        ],
        frames: [foot { body: leg, xyz: [0.0, 0.0, -0.4] }],
        derivatives: [inverse_dynamics],
    }
}

constrained_system! {
    /// The Panda of `tests/bodies.rs` with its tool frame on the hand, a
    /// link merged into the last one by the flange's fixed joint.
    pub struct PandaTool {
        urdf: "data/panda_published.urdf",
        locked: [finger_joint1, finger_joint2],
        frames: [tool { body: hand, xyz: [0.0, 0.0, 0.1034] }],
        derivatives: [inverse_dynamics],
    }
}

constrained_system! {
    /// A link turning on a pedestal welded to the world: the pedestal,
    /// Pinocchio's universe, is not part of the centre of mass.
    pub struct OnPedestal {
        gravity: [0.0, 0.0, -9.81],
        bodies: [
            pedestal {
                joint: fixed,
                xyz: [0.0, 0.0, 0.3],
                mass: 5.0,
                com: [0.1, 0.0, 0.0],
                inertia: diag[0.1, 0.1, 0.1],
            },
            link {
                parent: pedestal,
                joint: revolute(q1, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.2],
                mass: 2.0,
                com: [0.3, 0.0, 0.0],
                inertia: diag[0.01, 0.02, 0.02],
            },
        ],
        frames: [],
    }
}

/// Fixed pseudo-random numbers in [-1.5, 1.5): a linear congruential
/// sequence.
pub(crate) fn numbers(seed: u64) -> impl FnMut() -> f64 {
    let mut x = seed;
    move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((x >> 11) as f64 / (1u64 << 53) as f64) * 3.0 - 1.5
    }
}

pub(crate) fn states<const N: usize>(seed: u64) -> Vec<(SVector<f64, N>, SVector<f64, N>)> {
    let mut next = numbers(seed);
    (0..10)
        .map(|_| {
            let q = SVector::from_fn(|_, _| next());
            let qd = SVector::from_fn(|_, _| next());
            (q, qd)
        })
        .collect()
}

/// `vee(½ (W − Wᵀ))`.
fn vee(w: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        (w[(2, 1)] - w[(1, 2)]) / 2.0,
        (w[(0, 2)] - w[(2, 0)]) / 2.0,
        (w[(1, 0)] - w[(0, 1)]) / 2.0,
    )
}

/// `[ṗ; ω]` by central differences of a placement along `q̇`: `ṗ` of the
/// positions, `ω = vee(Ṙ Rᵀ)`.
fn differenced<const N: usize>(
    placement: impl Fn(&SVector<f64, N>) -> (Matrix3<f64>, Vector3<f64>),
    q: &SVector<f64, N>,
    qd: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, 6> {
    let (r1, p1) = placement(&(q + qd * h));
    let (r0, p0) = placement(&(q - qd * h));
    let (r, _) = placement(q);
    let linear = (p1 - p0) / (2.0 * h);
    let angular = vee(&((r1 - r0) / (2.0 * h) * r.transpose()));
    SVector::<f64, 6>::from_iterator(linear.iter().chain(angular.iter()).copied())
}

/// `|a − b| / max(|b|, 1)`.
pub(crate) fn relative<const R: usize, const C: usize>(
    a: &SMatrix<f64, R, C>,
    b: &SMatrix<f64, R, C>,
) -> f64 {
    (a - b).norm() / b.norm().max(1.0)
}

fn rz(a: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), a)
}

fn ry(a: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vector3::y_axis(), a)
}

/// The arm's frames by hand: `(R, p)` of `tip`, `elbow`, `hand`, and the
/// centre of mass.
#[allow(clippy::type_complexity)]
fn arm_by_hand(q: &SVector<f64, 4>) -> ([(Matrix3<f64>, Vector3<f64>); 3], Vector3<f64>) {
    let (q1, q2, q3, s) = (q[0], q[1], q[2], q[3]);
    let r_upper = rz(q1) * ry(q2);
    let p_upper = Vector3::new(0.0, 0.0, 0.4);
    let r_fore = r_upper * ry(q3);
    let p_fore = p_upper + r_upper * Vector3::new(0.5, 0.0, 0.0);
    let r_tool = r_fore * Rotation3::from_euler_angles(std::f64::consts::FRAC_PI_2, 0.0, 0.0);
    let p_tool = p_fore + r_fore * Vector3::new(0.0, 0.1, 0.0);
    let r_tip = r_tool * rz(0.3);
    let p_tip = p_tool + r_tool * Vector3::new(0.0, 0.0, 0.1);
    let p_slider = p_fore + r_fore * Vector3::new(0.3 + s, 0.0, 0.0);
    let r_hand = r_fore * Rotation3::from_euler_angles(0.2, -0.4, 0.7);
    let p_hand = p_slider + r_fore * Vector3::new(0.05, 0.02, -0.01);
    let weighted = Vector3::new(0.0, 0.0, 0.2) * 2.0
        + (p_upper + r_upper * Vector3::new(0.25, 0.0, 0.0)) * 1.5
        + (p_fore + r_fore * Vector3::new(0.2, 0.0, 0.0)) * 1.0
        + (p_tool + r_tool * Vector3::new(0.0, 0.0, 0.05)) * 0.2
        + p_slider * 0.5;
    let frames = [
        (r_tip.into_inner(), p_tip),
        (r_fore.into_inner(), p_fore),
        (r_hand.into_inner(), p_hand),
    ];
    (frames, weighted / 5.2)
}

#[test]
fn arm_placements_and_center_of_mass_equal_the_hand_derivation() {
    let arm = FramedArm::<f64>::new();
    let mut worst: f64 = 0.0;
    for (q, _) in states::<4>(7) {
        let (frames, com) = arm_by_hand(&q);
        let generated = [
            arm.tip_placement(&q, 0.0),
            arm.elbow_placement(&q, 0.0),
            arm.hand_placement(&q, 0.0),
        ];
        for ((r, p), (hr, hp)) in generated.iter().zip(&frames) {
            worst = worst.max((r - hr).norm()).max((p - hp).norm());
        }
        worst = worst.max((arm.center_of_mass(&q, 0.0) - com).norm());
    }
    println!("arm placements and centre of mass: within {worst:.1e} of the hand derivation");
    assert!(worst <= 1e-14, "{worst}");
}

/// Every frame of a system: its placement, Jacobian, velocity and bias.
type Methods<'a, const N: usize> = [(
    &'a str,
    Box<dyn Fn(&SVector<f64, N>) -> (Matrix3<f64>, Vector3<f64>) + 'a>,
    Box<dyn Fn(&SVector<f64, N>) -> SMatrix<f64, 6, N> + 'a>,
    Box<dyn Fn(&SVector<f64, N>, &SVector<f64, N>) -> SVector<f64, 6> + 'a>,
    Box<dyn Fn(&SVector<f64, N>, &SVector<f64, N>) -> SVector<f64, 6> + 'a>,
)];

/// The worst relative disagreements over `states`: `J q̇` against central
/// differences of the placement, the velocity method against `J q̇`, and
/// `J̇ q̇` against central differences of `J(q + h q̇) q̇`.
fn check_frames<const N: usize>(
    frames: &Methods<N>,
    states: &[(SVector<f64, N>, SVector<f64, N>)],
) -> (f64, f64, f64) {
    let (mut jac, mut vel, mut bias) = (0.0_f64, 0.0_f64, 0.0_f64);
    let h = 1e-5;
    for (q, qd) in states {
        for (_, placement, jacobian, velocity, acceleration_bias) in frames {
            let j = jacobian(q);
            let jqd = j * qd;
            jac = jac.max(relative(&jqd, &differenced(placement, q, qd, h)));
            vel = vel.max(relative(&velocity(q, qd), &jqd));
            let ahead = jacobian(&(q + qd * h)) * qd;
            let behind = jacobian(&(q - qd * h)) * qd;
            let fd = (ahead - behind) / (2.0 * h);
            bias = bias.max(relative(&acceleration_bias(q, qd), &fd));
            // Each column alone: the direction of one coordinate.
            for k in 0..N {
                let e = SVector::<f64, N>::from_fn(|i, _| f64::from(u8::from(i == k)));
                let column: SVector<f64, 6> = j.column(k).into();
                jac = jac.max(relative(&column, &differenced(placement, q, &e, h)));
            }
        }
    }
    (jac, vel, bias)
}

#[test]
fn arm_jacobians_velocities_and_biases_agree_with_differences() {
    let arm = FramedArm::<f64>::new();
    let a = &arm;
    let frames: &Methods<4> = &[
        (
            "tip",
            Box::new(|q| a.tip_placement(q, 0.0)),
            Box::new(|q| a.tip_jacobian(q, 0.0)),
            Box::new(|q, qd| a.tip_velocity(q, qd, 0.0)),
            Box::new(|q, qd| a.tip_acceleration_bias(q, qd, 0.0)),
        ),
        (
            "elbow",
            Box::new(|q| a.elbow_placement(q, 0.0)),
            Box::new(|q| a.elbow_jacobian(q, 0.0)),
            Box::new(|q, qd| a.elbow_velocity(q, qd, 0.0)),
            Box::new(|q, qd| a.elbow_acceleration_bias(q, qd, 0.0)),
        ),
        (
            "hand",
            Box::new(|q| a.hand_placement(q, 0.0)),
            Box::new(|q| a.hand_jacobian(q, 0.0)),
            Box::new(|q, qd| a.hand_velocity(q, qd, 0.0)),
            Box::new(|q, qd| a.hand_acceleration_bias(q, qd, 0.0)),
        ),
    ];
    let (jac, vel, bias) = check_frames(frames, &states::<4>(11));
    println!("arm: J q̇ within {jac:.1e} of differences, velocity within {vel:.1e} of J q̇, J̇ q̇ within {bias:.1e}");
    assert!(
        jac <= 1e-7 && vel <= 1e-14 && bias <= 1e-6,
        "{jac} {vel} {bias}"
    );
}

#[test]
fn arm_frame_velocity_equals_the_velocity_of_the_same_point_of_the_body() {
    let (arm, twin) = (FramedArm::<f64>::new(), ArmPointVelocity::<f64>::new());
    let mut worst: f64 = 0.0;
    for (q, qd) in states::<4>(13) {
        let v = arm.hand_velocity(&q, &qd, 0.0);
        let point: Vector3<f64> = twin.constraint_residual(&q, &qd, 0.0);
        worst = worst.max((v.fixed_rows::<3>(0) - point).norm() / point.norm().max(1.0));
    }
    println!("hand: J q̇ within {worst:.1e} of velocity(slider, [..])");
    assert!(worst <= 1e-14, "{worst}");
}

#[test]
fn center_of_mass_and_jacobian_are_the_two_methods_at_once() {
    let arm = FramedArm::<f64>::new();
    let mut worst: f64 = 0.0;
    for (q, _) in states::<4>(19) {
        let (c, j) = arm.center_of_mass_and_jacobian(&q, 0.0);
        worst = worst.max(relative(&c, &arm.center_of_mass(&q, 0.0)));
        worst = worst.max(relative(&j, &arm.center_of_mass_jacobian(&q, 0.0)));
    }
    println!("arm: centre of mass and Jacobian at once within {worst:.1e} of each alone");
    assert!(worst <= 1e-15, "{worst}");
}

#[test]
fn arm_center_of_mass_jacobian_agrees_with_differences() {
    let arm = FramedArm::<f64>::new();
    let mut worst: f64 = 0.0;
    let h = 1e-5;
    for (q, qd) in states::<4>(17) {
        let j = arm.center_of_mass_jacobian(&q, 0.0);
        let fd = (arm.center_of_mass(&(q + qd * h), 0.0) - arm.center_of_mass(&(q - qd * h), 0.0))
            / (2.0 * h);
        worst = worst.max(relative(&(j * qd), &fd));
    }
    println!("arm: centre of mass J q̇ within {worst:.1e} of differences");
    assert!(worst <= 1e-7, "{worst}");
}

#[test]
fn a_body_welded_to_the_world_is_not_part_of_the_center_of_mass() {
    let system = OnPedestal::<f64>::new();
    for (q, _) in states::<1>(23) {
        let (s, c) = q[0].sin_cos();
        let com = Vector3::new(0.3 * c, 0.3 * s, 0.5);
        let jacobian = Vector3::new(-0.3 * s, 0.3 * c, 0.0);
        assert!((system.center_of_mass(&q, 0.0) - com).norm() <= 1e-15);
        assert!((system.center_of_mass_jacobian(&q, 0.0).column(0) - jacobian).norm() <= 1e-15);
    }
}

#[test]
fn f32_placement_agrees_with_f64() {
    let (a64, a32) = (FramedArm::<f64>::new(), FramedArm::<f32>::new());
    for (q, qd) in states::<4>(19) {
        let (r, p) = a64.tip_placement(&q, 0.0);
        let (r32, p32) = a32.tip_placement(&q.cast::<f32>(), 0.0);
        assert!((r32.cast::<f64>() - r).norm() <= 1e-5 && (p32.cast::<f64>() - p).norm() <= 1e-5);
        let j = a64.tip_jacobian(&q, 0.0);
        let j32 = a32.tip_jacobian(&q.cast::<f32>(), 0.0);
        assert!((j32.cast::<f64>() - j).norm() <= 1e-5 * j.norm().max(1.0));
        let b = a64.tip_acceleration_bias(&q, &qd, 0.0);
        let b32 = a32.tip_acceleration_bias(&q.cast::<f32>(), &qd.cast::<f32>(), 0.0);
        assert!((b32.cast::<f64>() - b).norm() <= 1e-4 * b.norm().max(1.0));
    }
}

#[test]
fn floating_foot_agrees_with_differences_in_quaternion_rates() {
    let leg = FloatingLeg::<f64>::new();
    let l = &leg;
    let frames: &Methods<8> = &[(
        "foot",
        Box::new(|q| l.foot_placement(q, 0.0)),
        Box::new(|q| l.foot_jacobian(q, 0.0)),
        Box::new(|q, qd| l.foot_velocity(q, qd, 0.0)),
        Box::new(|q, qd| l.foot_acceleration_bias(q, qd, 0.0)),
    )];
    // Any q and q̇, off the unit sphere and off its tangent too: `R(q/|q|)`
    // and its derivatives hold everywhere.
    let (jac, vel, bias) = check_frames(frames, &states::<8>(23));
    println!("floating leg: J q̇ within {jac:.1e} of differences, velocity within {vel:.1e}, J̇ q̇ within {bias:.1e}");
    assert!(
        jac <= 1e-7 && vel <= 1e-14 && bias <= 1e-6,
        "{jac} {vel} {bias}"
    );
}

#[test]
fn floating_foot_velocity_is_the_twist_free_motion_writes() {
    use constrained::floating::FreeMotion;
    let leg = FloatingLeg::<f64>::new();
    let mut worst: f64 = 0.0;
    let mut next = numbers(29);
    for _ in 0..10 {
        let base = FreeMotion {
            position: Vector3::from_fn(|_, _| next()),
            orientation: UnitQuaternion::from_euler_angles(next(), next(), next()),
            linear: Vector3::from_fn(|_, _| next()),
            angular: Vector3::from_fn(|_, _| next()),
        };
        let (mut q, mut qd) = (SVector::<f64, 8>::zeros(), SVector::<f64, 8>::zeros());
        base.write(0, &mut q, &mut qd)
            .expect("seven coordinates fit");
        (q[7], qd[7]) = (next(), next());
        let (r, p) = leg.foot_placement(&q, 0.0);
        let hinge = base.orientation * Vector3::y();
        // The leg turns about its hinge, carried by the trunk.
        let omega = base.angular + hinge * qd[7];
        let pivot = base.position + base.orientation * Vector3::new(0.2, 0.0, 0.1);
        let v = base.linear
            + base.angular.cross(&(p - base.position))
            + (hinge * qd[7]).cross(&(p - pivot));
        let twist = leg.foot_velocity(&q, &qd, 0.0);
        let expected = SVector::<f64, 6>::from_iterator(v.iter().chain(omega.iter()).copied());
        worst = worst.max(relative(&twist, &expected));
        // The frame's axes: the trunk's turned about the hinge.
        let turned = base.orientation.to_rotation_matrix() * ry(q[7]);
        worst = worst.max((r - turned.into_inner()).norm());
    }
    println!("floating leg: the foot's twist within {worst:.1e} of FreeMotion's");
    assert!(worst <= 1e-13, "{worst}");
}

/// The Panda's tool frame by hand: each joint of the URDF `Trans(xyz)
/// Rpy(rpy) Rz(qᵢ)`, then the flange, then the tool's offset.
fn panda_tool_by_hand(q: &SVector<f64, 7>) -> Isometry3<f64> {
    use std::f64::consts::FRAC_PI_2;
    let joints: [([f64; 3], f64); 7] = [
        ([0.0, 0.0, 0.333], 0.0),
        ([0.0, 0.0, 0.0], -FRAC_PI_2),
        ([0.0, -0.316, 0.0], FRAC_PI_2),
        ([0.0825, 0.0, 0.0], FRAC_PI_2),
        ([-0.0825, 0.384, 0.0], -FRAC_PI_2),
        ([0.0, 0.0, 0.0], FRAC_PI_2),
        ([0.088, 0.0, 0.0], FRAC_PI_2),
    ];
    let mut t = Isometry3::identity();
    for (i, (xyz, roll)) in joints.iter().enumerate() {
        let origin = Isometry3::from_parts(
            Translation3::new(xyz[0], xyz[1], xyz[2]),
            UnitQuaternion::from_euler_angles(*roll, 0.0, 0.0),
        );
        let turn = Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), q[i]),
        );
        t = t * origin * turn;
    }
    // The file's angle as written, not π/4: they differ in the thirteenth
    // digit, more than the agreement asked for.
    #[allow(clippy::approx_constant)]
    let flange = Isometry3::from_parts(
        Translation3::new(0.0, 0.0, 0.107),
        UnitQuaternion::from_euler_angles(0.0, 0.0, -0.785398163397),
    );
    t * flange * Translation3::new(0.0, 0.0, 0.1034)
}

#[test]
fn panda_tool_frame_equals_the_product_of_its_joint_transforms() {
    let panda = PandaTool::<f64>::new();
    let mut worst: f64 = 0.0;
    for (q, _) in states::<7>(31) {
        let (r, p) = panda.tool_placement(&q, 0.0);
        let t = panda_tool_by_hand(&q);
        let hand_r = t.rotation.to_rotation_matrix().into_inner();
        worst = worst
            .max((p - t.translation.vector).norm())
            .max((r - hand_r).norm());
    }
    println!("panda: tool placement within {worst:.1e} of the joint transforms' product");
    assert!(worst <= 1e-14, "{worst}");
}

#[test]
fn panda_tool_jacobian_and_bias_agree_with_differences() {
    let panda = PandaTool::<f64>::new();
    let p = &panda;
    let frames: &Methods<7> = &[(
        "tool",
        Box::new(|q| p.tool_placement(q, 0.0)),
        Box::new(|q| p.tool_jacobian(q, 0.0)),
        Box::new(|q, qd| p.tool_velocity(q, qd, 0.0)),
        Box::new(|q, qd| p.tool_acceleration_bias(q, qd, 0.0)),
    )];
    let (jac, vel, bias) = check_frames(frames, &states::<7>(37));
    println!("panda: J q̇ within {jac:.1e} of differences, velocity within {vel:.1e}, J̇ q̇ within {bias:.1e}");
    assert!(
        jac <= 1e-7 && vel <= 1e-14 && bias <= 1e-6,
        "{jac} {vel} {bias}"
    );
}
