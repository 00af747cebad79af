//! Shared by the integration tests.
#![allow(dead_code)] // each test binary uses its own subset

use proptest::prelude::*;

/// A random state of Appell's particle and its parameters:
/// `(q, q̇, t, g, α)`, not necessarily on the constraint.
pub fn appell_state() -> impl Strategy<Value = ([f64; 3], [f64; 3], f64, f64, f64)> {
    (
        prop::array::uniform3(-10.0..10.0f64),
        prop::array::uniform3(-10.0..10.0f64),
        -100.0..100.0f64,
        0.1..20.0f64,
        -3.0..3.0f64,
    )
}

/// A trunk on a free joint with a foot on a ball joint 0.4 below it,
/// `$name` with the given parameters and constraints
/// (`rank_decisions::FootOnThreePoints`, `spherical::FootOnOnePoint`).
macro_rules! trunk_on_ball_foot {
    ($(#[$attr:meta])* $name:ident, [$($p:ident),*], [$($c:tt)*]) => {
        constrained::constrained_system! {
            $(#[$attr])*
            pub struct $name {
                parameters: [$($p),*],
                bodies: [
                    trunk {
                        joint: free(x, y, z, qw, qx, qy, qz),
                        mass: 8.0,
                        com: [0.03, -0.02, 0.25],
                        inertia: [[0.2, 0.01, 0.0], [0.01, 0.15, 0.0], [0.0, 0.0, 0.1]],
                    },
                    foot {
                        parent: trunk,
                        joint: spherical(fw, fx, fy, fz),
                        xyz: [0.0, 0.0, -0.4],
                        mass: 0.6,
                        com: [0.03, 0.0, -0.02],
                        inertia: [[1.5e-4, 0.0, 1.0e-5], [0.0, 8.0e-4, 0.0], [1.0e-5, 0.0, 8.5e-4]],
                    },
                ],
                constraints: [$($c)*],
            }
        }
    };
}

/// The `k`-th moving state of a trunk on a ball-jointed foot
/// (`trunk_on_ball_foot!`), both quaternions turned, an odd `k`'s off
/// the unit spheres (the trunk's scaled by `1 + 0.05 (k − 4)`, the foot's
/// by its inverse).
pub fn trunk_on_foot_state(k: u32) -> constrained::State<f64, 11> {
    use constrained::nalgebra::{SVector, UnitQuaternion};
    let x = f64::from(k);
    let trunk = UnitQuaternion::from_euler_angles(0.2 * x.sin(), -0.1, 0.3 * x);
    let foot = UnitQuaternion::from_euler_angles(0.4, 0.1 * x, -0.2 * x.cos());
    let scale = if k % 2 == 1 {
        1.0 + 0.05 * (x - 4.0)
    } else {
        1.0
    };
    let mut q = SVector::<f64, 11>::zeros();
    q[0] = 0.1 * x;
    q[2] = 0.8;
    for (i, v) in [trunk.w, trunk.i, trunk.j, trunk.k].into_iter().enumerate() {
        q[3 + i] = scale * v;
    }
    for (i, v) in [foot.w, foot.i, foot.j, foot.k].into_iter().enumerate() {
        q[7 + i] = v / scale;
    }
    let qd = SVector::<f64, 11>::from_fn(|i, _| (0.7 * (i as f64 + x)).sin());
    constrained::State::new(0.0, q, qd)
}
