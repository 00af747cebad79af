use crate::constrained_system;

constrained_system! {
    /// A free rigid body in unit quaternions `(e0, e1, e2, e3)`, the
    /// standard singularity-free attitude, with principal moments of inertia
    /// `j1, j2, j3`. Its body angular velocity is `ω = 2 G(e) ė`, so
    /// `T = ½ ωᵀ J ω` gives `M = 4 Gᵀ J G`, of rank 3: the direction `e`
    /// itself carries no kinetic energy. The unit-norm constraint supplies
    /// it (`[M; A]` has full rank), and the macro solves Gauss's principle
    /// through Udwadia & Schutte's auxiliary mass `M + s AᵀA`.
    pub struct RigidBodyQuaternion {
        coordinates: [e0, e1, e2, e3],
        parameters: [j1, j2, j3],
        definitions: [
            w1 = 2.0 * (-e1 * dot(e0) + e0 * dot(e1) + e3 * dot(e2) - e2 * dot(e3)),
            w2 = 2.0 * (-e2 * dot(e0) - e3 * dot(e1) + e0 * dot(e2) + e1 * dot(e3)),
            w3 = 2.0 * (-e3 * dot(e0) + e2 * dot(e1) - e1 * dot(e2) + e0 * dot(e3)),
        ],
        kinetic_energy: (j1 * w1.powi(2) + j2 * w2.powi(2) + j3 * w3.powi(2)) / 2.0,
        constraints: [e0.powi(2) + e1.powi(2) + e2.powi(2) + e3.powi(2) == 1.0],
    }
}

constrained_system! {
    /// A heavy symmetric top on a fixed pivot, in unit quaternions: moments
    /// of inertia `a` (about axes through the pivot perpendicular to the
    /// symmetry axis) and `c` (about it), mass `m` at distance `l` along
    /// the symmetry axis, gravity `g`. The symmetry axis's vertical
    /// component is `e0² − e1² − e2² + e3²` on the unit sphere.
    pub struct HeavyTop {
        coordinates: [e0, e1, e2, e3],
        parameters: [a, c, m, g, l],
        definitions: [
            w1 = 2.0 * (-e1 * dot(e0) + e0 * dot(e1) + e3 * dot(e2) - e2 * dot(e3)),
            w2 = 2.0 * (-e2 * dot(e0) - e3 * dot(e1) + e0 * dot(e2) + e1 * dot(e3)),
            w3 = 2.0 * (-e3 * dot(e0) + e2 * dot(e1) - e1 * dot(e2) + e0 * dot(e3)),
            height = l * (e0.powi(2) - e1.powi(2) - e2.powi(2) + e3.powi(2)),
        ],
        kinetic_energy: (a * (w1.powi(2) + w2.powi(2)) + c * w3.powi(2)) / 2.0,
        potential_energy: m * g * height,
        constraints: [e0.powi(2) + e1.powi(2) + e2.powi(2) + e3.powi(2) == 1.0],
    }
}

use crate::nalgebra::{Matrix3x4, RealField, Vector3, Vector4};
use crate::State;

/// `G(e)`, with which the body angular velocity of a unit quaternion `e`
/// is `ω = 2 G(e) ė` (the definitions `w1, w2, w3` of the models above),
/// and `ė = ½ Gᵀ ω`.
pub fn quaternion_rate_matrix<T: RealField + Copy>(e: &Vector4<T>) -> Matrix3x4<T> {
    Matrix3x4::new(
        -e[1], e[0], e[3], -e[2], //
        -e[2], -e[3], e[0], e[1], //
        -e[3], e[2], -e[1], e[0],
    )
}

/// A consistent state of [`RigidBodyQuaternion`] or [`HeavyTop`]: the
/// attitude `e` (normalised here) and the body angular velocity `ω`, as
/// `(e, ė = ½ Gᵀ ω)` at time `t`.
pub fn quaternion_state<T: RealField + Copy>(
    t: T,
    e: Vector4<T>,
    omega: Vector3<T>,
) -> State<T, 4> {
    let e = e.normalize();
    let half = T::one() / (T::one() + T::one());
    State::new(t, e, quaternion_rate_matrix(&e).transpose() * omega * half)
}
