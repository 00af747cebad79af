//! URDF files read as Pinocchio reads them, against hand derivations:
//! sibling joints numbered by name (not file order), a joint name that is
//! not an identifier kept in `COORDINATES`, and `1.5708` read as 1.5708,
//! not as π/2 (unless `right_angles_within` asks for it).

use constrained::constrained_system;
use constrained::nalgebra::{Vector1, Vector3};

constrained_system! {
    /// Three pendulums: two on the base (`b-joint` written first), one
    /// under a fixed mount named `0_mount`.
    pub struct Siblings {
        urdf: "data/siblings.urdf",
    }
}

constrained_system! {
    /// A pendulum whose joint frame is turned by 1.5708 rad.
    pub struct NearRightAngle {
        urdf: "data/near_right_angle.urdf",
    }
}

constrained_system! {
    /// The same pendulum, its angles read as right angles within 1e-5 rad.
    pub struct NearRightAngleSnapped {
        urdf: "data/near_right_angle.urdf",
        right_angles_within: 1e-5,
    }
}

constrained_system! {
    /// The same pendulum with a tolerance too small to reach 1.5708.
    pub struct NearRightAngleNotSnapped {
        urdf: "data/near_right_angle.urdf",
        right_angles_within: 1e-6,
    }
}

const G: f64 = 9.81;

/// A pendulum about `y` of mass `m` with its centre `l` along its `x`:
/// `V = −m g l sin q`, so its gravity force is `∂V/∂q = −m g l cos q`.
fn pendulum_gravity(m: f64, l: f64, q: f64) -> f64 {
    -m * G * l * q.cos()
}

#[test]
fn sibling_joints_are_numbered_by_name_as_pinocchio_numbers_them() {
    // Depth-first, each link's child joints by name: `0_mount` (fixed, its
    // child `c_joint`), then `a_joint`, then `b-joint`.
    assert_eq!(
        Siblings::<f64>::COORDINATES,
        ["c_joint", "a_joint", "b-joint"]
    );
    let robot = Siblings::<f64>::new();
    let q = Vector3::new(0.3, -0.7, 1.1);
    let gravity = robot.gravity_forces(&q, 0.0);
    let expected = Vector3::new(
        pendulum_gravity(5.0, 0.1, q[0]),
        pendulum_gravity(1.0, 0.2, q[1]),
        pendulum_gravity(3.0, 0.3, q[2]),
    );
    assert!(
        (gravity - expected).amax() <= 1e-14 * expected.amax(),
        "{gravity}{expected}"
    );
    // Each joint carries its own link alone: M is diagonal, I_yy + m l².
    let m = robot.mass_matrix(&q, 0.0);
    let diagonal = Vector3::new(0.01 + 0.05, 0.01 + 0.04, 0.01 + 0.27);
    assert!((m.diagonal() - diagonal).amax() <= 1e-15, "{m}");
    assert!((m - constrained::nalgebra::Matrix3::from_diagonal(&diagonal)).amax() <= 1e-15);
}

#[test]
fn a_decimal_near_a_right_angle_is_read_as_written() {
    // The frame turned by a = 1.5708 about x, the joint about the child's
    // y: the axis is (0, cos a, sin a) and the centre, 0.5 along the
    // child's x, is at (0.5 cos q, 0.5 sin q sin a, −0.5 sin q cos a), so
    // V = −m g l sin q cos a and the gravity force is −m g l cos q cos a:
    // 3.7e-6 of m g l, where π/2 would give exactly zero.
    #[allow(clippy::approx_constant)] // the file's 1.5708, which is not π/2
    let a: f64 = 1.5708;
    let robot = NearRightAngle::<f64>::new();
    for q in [0.0, 0.4, -1.3, 2.9] {
        let q1 = Vector1::new(q);
        let gravity = robot.gravity_forces(&q1, 0.0)[0];
        let expected = -2.0 * G * 0.5 * q.cos() * a.cos();
        assert!(
            (gravity - expected).abs() <= 1e-9 * expected.abs(),
            "{gravity} vs {expected}"
        );
        assert!(gravity.abs() > 3e-6 * 2.0 * G * 0.5 * q.cos().abs() * 0.99);
    }
    assert_eq!(NearRightAngle::<f64>::COORDINATES, ["hinge"]);
}

#[test]
fn right_angles_within_a_tolerance_are_right_angles_when_asked() {
    // 1.5708 is 3.7e-6 rad from π/2: within 1e-5 it is π/2, so the joint
    // axis is horizontal and gravity gives its coordinate no force at all;
    // within 1e-6 it is read as written.
    #[allow(clippy::approx_constant)] // the file's 1.5708, which is not π/2
    let a: f64 = 1.5708;
    let (snapped, written) = (
        NearRightAngleSnapped::<f64>::new(),
        NearRightAngleNotSnapped::<f64>::new(),
    );
    for q in [0.0, 0.4, -1.3, 2.9] {
        let q1 = Vector1::new(q);
        assert_eq!(snapped.gravity_forces(&q1, 0.0)[0], 0.0);
        let expected = -2.0 * G * 0.5 * q.cos() * a.cos();
        let gravity = written.gravity_forces(&q1, 0.0)[0];
        assert!(
            (gravity - expected).abs() <= 1e-9 * expected.abs(),
            "{gravity} vs {expected}"
        );
        // The inertia about the axis does not depend on the turn.
        let (m, m_written) = (snapped.mass_matrix(&q1, 0.0), written.mass_matrix(&q1, 0.0));
        assert!((m[(0, 0)] - (0.02 + 2.0 * 0.25)).abs() <= 1e-15, "{m}");
        assert!((m_written[(0, 0)] - m[(0, 0)]).abs() <= 1e-15);
    }
}
