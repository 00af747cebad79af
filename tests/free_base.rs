//! A floating base is the same base however it is written, and its legs'
//! solve gives the dense solve's answers. A trunk on one three-joint leg,
//! its foot held at a point, written three ways — `free(..)` on the world,
//! `free(..)` under a body on `fixed`, and `tests/data/one_leg.urdf`'s
//! `floating` joint from a `world` link — gives the same `q̈` and `λ` to
//! 1e-14 (`codegen/tests/free_base.rs`: the same generated solve, the leg
//! eliminated through its foot). Under a fixed body that lifts the base's
//! frame the general solve answers, with the same accelerations at the
//! lifted state. The Unitree Go1 from example-robot-data's URDF is checked
//! against Pinocchio's `constraintDynamics` in the peers' harness
//! (`benches/peers`), which reads the file from the package index.

use crate::auxiliary::{against_dense, assert_close};
use constrained::floating::FreeMotion;
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{SVector, UnitQuaternion, Vector3};
use constrained::State;

/// The trunk on `free(..)` under `$parent` (with `$mount`'s bodies before
/// it) and the leg of `tests/data/one_leg.urdf`, its foot at `(px, py, 0)`.
macro_rules! one_leg {
    ($(#[$attr:meta])* $name:ident, $parent:ident, [$($mount:tt)*]) => {
        constrained::constrained_system! {
            $(#[$attr])*
            pub struct $name {
                parameters: [px, py],
                inputs: [t1, t2, t3],
                bodies: [
                    $($mount)*
                    trunk {
                        parent: $parent,
                        joint: free(base_x, base_y, base_z, base_qw, base_qx, base_qy, base_qz),
                        mass: 1.16,
                        com: [0.01, -0.005, 0.002],
                        inertia: diag[0.0058, 0.0194, 0.0246],
                    },
                    hip {
                        parent: trunk,
                        joint: revolute(haa, [1.0, 0.0, 0.0]),
                        xyz: [0.1946, 0.0875, 0.0],
                        mass: 0.149,
                        com: [0.0, 0.014, 0.0],
                        inertia: diag[4.0e-5, 7.0e-5, 4.0e-5],
                    },
                    upper {
                        parent: hip,
                        joint: revolute(hfe, [0.0, 1.0, 0.0]),
                        xyz: [0.0, 0.014, 0.0],
                        mass: 0.149,
                        com: [0.0, 0.016, -0.078],
                        inertia: diag[4.2e-4, 4.1e-4, 2.4e-5],
                    },
                    lower {
                        parent: upper,
                        joint: revolute(kfe, [0.0, 1.0, 0.0]),
                        xyz: [0.0, 0.037, -0.16],
                        mass: 0.031,
                        com: [0.0, 0.007, -0.079],
                        inertia: diag[1.2e-4, 1.2e-4, 2.1e-6],
                    },
                ],
                forces: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, t1, t2, t3],
                constraints: [position(lower, [0.0, 0.008, -0.16]) == [px, py, 0.0]],
            }
        }
    };
}

one_leg!(
    /// The base on the world.
    OnWorld,
    world,
    []
);
one_leg!(
    /// The base under a massless body fixed to the world at its frame.
    UnderFixed,
    mount,
    [mount { joint: fixed },]
);
one_leg!(
    /// The base under a fixed body 0.3 above the world's origin: the base's
    /// coordinates are its position in that body's frame.
    Lifted,
    mount,
    [mount { joint: fixed, xyz: [0.0, 0.0, 0.3] },]
);

constrained::constrained_system! {
    /// The same robot from its URDF.
    pub struct FromUrdf {
        parameters: [px, py],
        inputs: [t1, t2, t3],
        urdf: "data/one_leg.urdf",
        forces: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, t1, t2, t3],
        constraints: [position(lower, [0.0, 0.008, -0.16]) == [px, py, 0.0]],
    }
}

/// A pseudo-random number in [−1, 1).
fn uniform(x: &mut u64) -> f64 {
    *x = x
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A state of `N` coordinates: the base at about `height`, turned and
/// moving, each joint about `pose` (per joint of a leg of three) with rates.
fn state<const N: usize>(x: &mut u64, height: f64, pose: [f64; 3]) -> State<f64, N> {
    let base = FreeMotion {
        position: Vector3::new(
            0.05 * uniform(x),
            0.05 * uniform(x),
            height + 0.03 * uniform(x),
        ),
        orientation: UnitQuaternion::from_euler_angles(
            0.2 * uniform(x),
            0.2 * uniform(x),
            uniform(x),
        ),
        linear: Vector3::new(0.5 * uniform(x), 0.5 * uniform(x), 0.5 * uniform(x)),
        angular: Vector3::new(uniform(x), uniform(x), uniform(x)),
    };
    let (mut q, mut qd) = (SVector::zeros(), SVector::zeros());
    base.write(0, &mut q, &mut qd)
        .expect("seven coordinates fit");
    for j in 7..N {
        q[j] = pose[(j - 7) % 3] + 0.3 * uniform(x);
        qd[j] = 2.0 * uniform(x);
    }
    State::new(0.0, q, qd)
}

/// `‖a − b‖∞ / ‖b‖∞`.
fn gap<const M: usize>(a: &SVector<f64, M>, b: &SVector<f64, M>) -> f64 {
    (a - b).amax() / b.amax()
}

#[test]
fn one_robot_written_three_ways_moves_the_same() {
    let mut x = 7u64;
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..24 {
        let s = state::<10>(&mut x, 0.25, [0.0, 0.8, -1.6]);
        let p: [f64; 5] = std::array::from_fn(|_| uniform(&mut x));
        let (px, py) = (0.19 + 0.05 * p[0], 0.15 + 0.05 * p[1]);
        let tau = [p[2], p[3], p[4]];
        let on_world = OnWorld::new(px, py, tau[0], tau[1], tau[2]);
        let reference = on_world
            .acceleration_and_multipliers(&s)
            .expect("q̈ and λ on the world");
        let under_fixed = UnderFixed::new(px, py, tau[0], tau[1], tau[2])
            .acceleration_and_multipliers(&s)
            .expect("q̈ and λ under a fixed body");
        let urdf = FromUrdf::new(px, py, tau[0], tau[1], tau[2])
            .acceleration_and_multipliers(&s)
            .expect("q̈ and λ from the URDF");
        for (qdd, lambda) in [under_fixed, urdf] {
            worst.0 = worst.0.max(gap(&qdd, &reference.0));
            worst.1 = worst.1.max(gap(&lambda, &reference.1));
        }
    }
    println!("one leg, three ways: q̈ {:.1e}, λ {:.1e}", worst.0, worst.1);
    assert!(worst.0 <= 1e-14 && worst.1 <= 1e-14, "{worst:?}");
}

/// The base lifted by a fixed body takes the general solve (its rows are
/// not the feet's in the base's axes: `p` is not the base's world
/// position); at the state whose base coordinates are 0.3 lower, the same
/// robot in the same place, its `q̈` is the one on the world (the lift is
/// a translation: accelerations are unchanged).
#[test]
fn a_lifted_base_takes_the_general_solve_with_the_same_answers() {
    let mut x = 11u64;
    let p: [f64; 5] = std::array::from_fn(|_| uniform(&mut x));
    let (px, py) = (0.19 + 0.05 * p[0], 0.15 + 0.05 * p[1]);
    let on_world = OnWorld::new(px, py, p[2], p[3], p[4]);
    let lifted = Lifted::new(px, py, p[2], p[3], p[4]);
    let mut worst: f64 = 0.0;
    let mut at = Vec::new();
    for _ in 0..24 {
        let s = state::<10>(&mut x, 0.25, [0.0, 0.8, -1.6]);
        let (qdd, _) = on_world.acceleration_and_multipliers(&s).expect("q̈");
        let mut lowered = s.q;
        lowered[2] -= 0.3;
        at.push(State::new(s.t, lowered, s.qd));
        let (moved, _) = lifted
            .acceleration_and_multipliers(&at[at.len() - 1])
            .expect("q̈");
        worst = worst.max(gap(&moved, &qdd));
    }
    println!("lifted base vs on the world: q̈ {worst:.1e}");
    assert!(worst <= 1e-12, "{worst:e}");
    assert_close("Lifted one leg", &against_dense::<_, 10, 4>(&lifted, &at));
}
