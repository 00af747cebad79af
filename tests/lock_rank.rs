//! A free brick with its attitude locked (`orientation(brick) == [..]`)
//! has four independent rows (the lock's three and the quaternion's norm)
//! whatever parameters it declares. The macro measured the rank at states
//! drawn from the same stream as the parameters, projected onto the lock's
//! rows, which vanish at its half turns too; with five, seven or ten unused
//! parameters every state was a half turn, where the rows have rank 2, and
//! the brick was declared redundant (`REDUNDANCY` 2): `linearize_reduced`
//! failed with `SingularPartition` and the Gibbs–Appell form with
//! `Inconsistent` at ordinary states (`constrained_codegen`'s partition
//! unit tests cover 0 to 10 parameters and many seeds).

use constrained::floating::FreeMotion;
use constrained::nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};
use constrained::{constrained_system, ConstrainedSystem};

/// A free brick with its attitude locked at `target`, declaring the
/// parameters given.
macro_rules! locked_brick {
    ($(#[$doc:meta])* $name:ident { $($parameters:tt)* } at [$($target:tt)*]) => {
        constrained_system! {
            $(#[$doc])*
            pub struct $name {
                $($parameters)*
                bodies: [
                    brick {
                        joint: free(x, y, z, qw, qx, qy, qz),
                        mass: 2.0,
                        com: [0.1, 0.05, -0.2],
                        inertia: diag[0.01, 0.02, 0.03],
                    },
                ],
                constraints: [orientation(brick) == [$($target)*]],
            }
        }
    };
}

locked_brick! {
    /// The brick without parameters.
    LockedBrick {} at [0.0, 0.0, 0.0]
}

locked_brick! {
    /// Five unused parameters (the reported case).
    LockedBrickFive { parameters: [p0, p1, p2, p3, p4], } at [0.0, 0.0, 0.0]
}

locked_brick! {
    /// Seven unused parameters.
    LockedBrickSeven { parameters: [p0, p1, p2, p3, p4, p5, p6], } at [0.0, 0.0, 0.0]
}

locked_brick! {
    /// Ten unused parameters.
    LockedBrickTen {
        parameters: [p0, p1, p2, p3, p4, p5, p6, p7, p8, p9],
    } at [0.0, 0.0, 0.0]
}

locked_brick! {
    /// Locked at an attitude given by parameters, with two unused ones.
    LockedBrickTurned { parameters: [roll, pitch, yaw, p3, p4], } at [roll, pitch, yaw]
}

/// A state on the lock: anywhere, moving, its attitude the target's and
/// not turning.
fn locked_state(attitude: UnitQuaternion<f64>) -> (SVector<f64, 7>, SVector<f64, 7>) {
    let motion = FreeMotion {
        position: Vector3::new(0.2, -0.4, 1.0),
        orientation: attitude,
        linear: Vector3::new(0.3, 0.1, -0.2),
        angular: Vector3::zeros(),
    };
    let (mut q, mut qd) = (SVector::zeros(), SVector::zeros());
    motion.write(0, &mut q, &mut qd).unwrap();
    (q, qd)
}

/// `REDUNDANCY` 0; `acceleration` is the fall (`z̈ = −9.81`, nothing
/// else moves); the Gibbs–Appell form agrees with it; the reduced
/// linearization keeps the position and its rate (a double integrator).
macro_rules! check_locked_brick {
    ($system:expr, $ty:ty, $attitude:expr) => {{
        let system = $system;
        let name = stringify!($ty);
        assert_eq!(
            <$ty as ConstrainedSystem<f64, 7, 4>>::REDUNDANCY,
            0,
            "{name}"
        );
        let (q, qd) = locked_state($attitude);
        let qdd = system.acceleration(&q, &qd, 0.0).expect("positive masses");
        let mut fall = SVector::<f64, 7>::zeros();
        fall[2] = -9.81;
        assert!((qdd - fall).amax() < 1e-12, "{name}: q̈ {qdd:?}");
        let gibbs_appell = system
            .acceleration_gibbs_appell(&q, &qd, 0.0)
            .unwrap_or_else(|e| panic!("{name}: Gibbs–Appell {e:?}"));
        assert!(
            (gibbs_appell - qdd).amax() < 1e-12,
            "{name}: Gibbs–Appell {gibbs_appell:?} against {qdd:?}"
        );
        let reduced = system
            .linearize_reduced(&q, &qd, 0.0)
            .unwrap_or_else(|e| panic!("{name}: linearize_reduced {e:?}"));
        assert_eq!(
            (reduced.coordinates, reduced.speeds),
            ([0, 1, 2], [0, 1, 2]),
            "{name}"
        );
        let mut integrator = SMatrix::<f64, 6, 6>::zeros();
        integrator.fixed_view_mut::<3, 3>(0, 3).fill_with_identity();
        assert!(
            (reduced.a - integrator).amax() < 1e-12,
            "{name}: reduced A {:?}",
            reduced.a
        );
    }};
}

#[test]
fn a_locked_free_brick_is_not_redundant_whatever_its_parameters() {
    let identity = UnitQuaternion::identity();
    check_locked_brick!(LockedBrick::<f64>::new(), LockedBrick<f64>, identity);
    let p = [0.5; 10];
    check_locked_brick!(
        LockedBrickFive::new(p[0], p[1], p[2], p[3], p[4]),
        LockedBrickFive<f64>,
        identity
    );
    check_locked_brick!(
        LockedBrickSeven::new(p[0], p[1], p[2], p[3], p[4], p[5], p[6]),
        LockedBrickSeven<f64>,
        identity
    );
    check_locked_brick!(
        LockedBrickTen::new(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9]),
        LockedBrickTen<f64>,
        identity
    );
    let (roll, pitch, yaw) = (0.3, -1.2, 2.9);
    check_locked_brick!(
        LockedBrickTurned::new(roll, pitch, yaw, 0.5, 0.5),
        LockedBrickTurned<f64>,
        UnitQuaternion::from_euler_angles(roll, pitch, yaw)
    );
}
