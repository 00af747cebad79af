//! The flat-feet rows of the Contacts section: the Unitree G1 on a
//! floating base standing on two flat feet (`build.rs`'s `g1_flat`), each
//! sole point held in place and each foot's attitude held: 36 coordinates,
//! 13 independent rows (six a foot and the quaternion's norm), against
//! Pinocchio's two `CONTACT_6D` constraints on the same soles.

use crate::Rng;
use constrained::multipliers::{multipliers, Multipliers};
use constrained::nalgebra::{Matrix3, Rotation3, SVector, Vector3};
use constrained::{ConstrainedSystem, State};
use std::fmt::Write as _;

include!(concat!(env!("OUT_DIR"), "/g1_flat.rs"));

/// The G1's coordinates: the base's seven and 29 joints.
const N: usize = 36;
/// Its rows: each foot's sole point (three) and attitude (three), and the
/// quaternion's norm.
pub const K: usize = 13;

/// The G1 with each foot's sole at `(x, y, z)` and its attitude at
/// `(roll, pitch, yaw)`: the left foot's six, then the right's.
fn flat(p: &[f64; 12]) -> G1Flat<f64> {
    G1Flat::new(
        p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11],
    )
}

/// Each sole's placement in the world at `q`: rotation and position.
fn soles(q: &SVector<f64, N>) -> [(Matrix3<f64>, Vector3<f64>); 2] {
    let any = flat(&[0.0; 12]);
    [
        any.left_sole_placement(q, 0.0),
        any.right_sole_placement(q, 0.0),
    ]
}

/// A G1 state ([`crate::g1_pose`], as the three-point rows draw theirs),
/// each sole held where it places it and as it turns it, the rates on the
/// rows' null space ([`crate::on_the_rows`]).
fn state(rng: &mut Rng) -> (G1Flat<f64>, State<f64, N>) {
    let (q, qd) = crate::g1_pose::<N>(rng);
    let mut places = [0.0; 12];
    for (k, (r, p)) in soles(&q).iter().enumerate() {
        let (roll, pitch, yaw) = Rotation3::from_matrix_unchecked(*r).euler_angles();
        places[6 * k..6 * k + 6].copy_from_slice(&[p.x, p.y, p.z, roll, pitch, yaw]);
    }
    let system = flat(&places);
    let s = crate::on_the_rows::<_, N, K>(&system, (q, qd), |a| {
        a.pseudo_inverse(1e-12).expect("a pseudo-inverse")
    });
    (system, s)
}

/// The states of `write`, `time` and `spin`: `STATES` from a generator of
/// their own.
pub fn states() -> Vec<(G1Flat<f64>, State<f64, N>)> {
    let mut rng = Rng(67);
    (0..crate::STATES).map(|_| state(&mut rng)).collect()
}

/// The states' records for Pinocchio's side (`g1flat 35`: Pinocchio's `q`,
/// `v`, `τ` (zero: unpowered) and `a`; our `λ` of each foot as Pinocchio's
/// `CONTACT_6D` in `LOCAL` gives it, the force and then the torque on the
/// foot at its sole in the sole's axes (ours are in world axes: turned by
/// `Rᵀ`); each sole's place and attitude `(x, y, z, roll, pitch, yaw)`, and
/// the sole point in its link's frame), each `q̈` checked against `A q̈ = b`
/// (to 1e-12) and against the runtime's dense Moore–Penrose solve (to
/// 1e-12), and each `λ` against the runtime's (an SVD of `A`, to 1e-10)
/// first.
pub fn write(out: &mut String) {
    let (mut residual, mut dense, mut worst): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for (system, s) in states() {
        let (qdd, lambda) = system.acceleration_and_multipliers(&s).expect("q̈ and λ");
        let (a, b) = ConstrainedSystem::constraint_matrices(&system, &s);
        residual = residual.max(crate::residual(&a, &b, &qdd));
        let exact = ConstrainedSystem::acceleration_moore_penrose(&system, &s).expect("q̈");
        dense = dense.max((qdd - exact).amax() / exact.amax());
        let (m, f) = (
            ConstrainedSystem::mass_matrix(&system, &s),
            ConstrainedSystem::forces(&system, &s),
        );
        let reference = multipliers(&a, &(m * qdd - f)).expect("λ of Aᵀλ = Fᶜ");
        worst = worst.max((lambda - reference).amax() / reference.amax());
        let mut local = Vec::with_capacity(K - 1);
        for (k, (r, _)) in soles(&s.q).iter().enumerate() {
            for part in 0..2 {
                let at = 6 * k + 3 * part;
                let world = Vector3::new(lambda[at], lambda[at + 1], lambda[at + 2]);
                local.extend((r.transpose() * world).iter());
            }
        }
        let (config, velocity, acceleration) = crate::pinocchio_coordinates(&s, &qdd);
        let places = [
            system.l_x,
            system.l_y,
            system.l_z,
            system.l_roll,
            system.l_pitch,
            system.l_yaw,
            system.r_x,
            system.r_y,
            system.r_z,
            system.r_roll,
            system.r_pitch,
            system.r_yaw,
        ];
        let _ = writeln!(out, "g1flat {}", N - 1);
        crate::line(out, "q", config.iter());
        crate::line(out, "v", velocity.iter());
        crate::line(out, "tau", [0.0; N - 1].iter());
        crate::line(out, "a", acceleration.iter());
        crate::line(out, "lambda", local.iter());
        crate::line(out, "feet", places.iter());
        crate::line(out, "sole", SOLE.iter());
    }
    assert!(residual < 1e-12, "A q̈ = b only to {residual:e}");
    assert!(dense < 1e-12, "q̈ only within {dense:e} of the dense solve");
    assert!(worst < 1e-10, "λ differs from the runtime's by {worst:e}");
    eprintln!(
        "contacts: the flat-footed G1's A q̈ = b to {residual:.1e}, q̈ within {dense:.1e} of the runtime's dense solve, λ within {worst:.1e} of the runtime's SVD"
    );
}
