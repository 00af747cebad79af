//! The Franka Emika Panda of the example `panda` and of the firmware (in
//! `f32`), written once, and its operational-space controller: the joint
//! torques that make the tool point follow a path.

use constrained::constrained_system;
use constrained::nalgebra::{RealField, SMatrix, SVector, Vector3};
use constrained::{DynamicsError, State};

constrained_system! {
    /// The Franka Emika Panda's seven links, a motor torque at each joint.
    pub struct Panda {
        inputs: [tau1, tau2, tau3, tau4, tau5, tau6, tau7],
        gravity: [0.0, 0.0, -9.81],
        bodies: [
            link1 {
                parent: world,
                joint: revolute(q1, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.333],
                rpy: [0.0, 0.0, 0.0],
                mass: 4.9707,
                com: [0.0193 / 4.9707, 0.0103 / 4.9707, -0.4654 / 4.9707], // first moments m·c over m
                inertia: [[0.7470, -0.0002, 0.0086], [-0.0002, 0.7503, 0.0201], [0.0086, 0.0201, 0.0092]],
            },
            link2 {
                parent: link1,
                joint: revolute(q2, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.0],
                rpy: [-PI / 2.0, 0.0, 0.0],
                mass: 0.6469,
                com: [-0.0020 / 0.6469, -0.0186 / 0.6469, 0.0023 / 0.6469], // first moments m·c over m
                inertia: [[0.0085, -0.0040, 0.0103], [-0.0040, 0.0281, 0.0008], [0.0103, 0.0008, 0.0265]],
            },
            link3 {
                parent: link2,
                joint: revolute(q3, [0.0, 0.0, 1.0]),
                xyz: [0.0, -0.316, 0.0],
                rpy: [PI / 2.0, 0.0, 0.0],
                mass: 3.2286,
                com: [0.0888 / 3.2286, 0.1267 / 3.2286, -0.2147 / 3.2286], // first moments m·c over m
                inertia: [[0.0565, -0.0082, -0.0055], [-0.0082, 0.0529, -0.0044], [-0.0055, -0.0044, 0.0182]],
            },
            link4 {
                parent: link3,
                joint: revolute(q4, [0.0, 0.0, 1.0]),
                xyz: [0.0825, 0.0, 0.0],
                rpy: [PI / 2.0, 0.0, 0.0],
                mass: 3.5879,
                com: [-0.1908 / 3.5879, 0.3746 / 3.5879, 0.0985 / 3.5879], // first moments m·c over m
                inertia: [[0.0677, 0.0277, 0.0039], [0.0277, 0.0324, -0.0016], [0.0039, -0.0016, 0.0776]],
            },
            link5 {
                parent: link4,
                joint: revolute(q5, [0.0, 0.0, 1.0]),
                xyz: [-0.0825, 0.384, 0.0],
                rpy: [-PI / 2.0, 0.0, 0.0],
                mass: 1.2259,
                com: [-0.0147 / 1.2259, 0.0503 / 1.2259, -0.0471 / 1.2259], // first moments m·c over m
                inertia: [[0.0394, -0.0015, -0.0046], [-0.0015, 0.0315, 0.0022], [-0.0046, 0.0022, 0.0109]],
            },
            link6 {
                parent: link5,
                joint: revolute(q6, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.0],
                rpy: [PI / 2.0, 0.0, 0.0],
                mass: 1.6666,
                com: [0.1002 / 1.6666, -0.0235 / 1.6666, -0.0175 / 1.6666], // first moments m·c over m
                inertia: [[0.0025, 0.0015, -0.0001], [0.0015, 0.0106, 0.0001], [-0.0001, 0.0001, 0.0118]],
            },
            link7 {
                parent: link6,
                joint: revolute(q7, [0.0, 0.0, 1.0]),
                xyz: [0.088, 0.0, 0.0],
                rpy: [PI / 2.0, 0.0, 0.0],
                mass: 1.4655,
                com: [0.0004 / 1.4655, -0.0031 / 1.4655, 0.1453 / 1.4655], // first moments m·c over m
                inertia: [[0.0308, 0.0004, -0.0007], [0.0004, 0.0284, -0.0005], [-0.0007, -0.0005, 0.0067]],
            },

        ],
        forces: [tau1, tau2, tau3, tau4, tau5, tau6, tau7],
        // The tool point between the fingers: the flange 0.107 m along the
        // last axis, the hand's fingertip centre 0.1034 m beyond it.
        frames: [tool { body: link7, xyz: [0.0, 0.0, 0.2104], rpy: [0.0, 0.0, -PI / 4.0] }],
    }
}

/// The task-space (operational-space) controller's gains: the tool's
/// error obeys `ë + kd ė + kp e = 0`; the posture's `q̈₀ = posture_kp (q₀ −
/// q) − posture_kd q̇` acts in the Jacobian's null space.
#[derive(Clone, Copy, Debug)]
pub struct TaskGains<T> {
    /// The tool's stiffness, 1/s².
    pub kp: T,
    /// The tool's damping, 1/s.
    pub kd: T,
    /// The posture's stiffness, 1/s².
    pub posture_kp: T,
    /// The posture's damping, 1/s.
    pub posture_kd: T,
}

/// What the controller could not do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TaskError {
    /// The tool's linear Jacobian lost rank (a singular pose).
    Singular,
    /// The generated inverse dynamics refused the state.
    Dynamics(DynamicsError),
}

/// Task-space inverse dynamics: the torques that give the tool point the
/// acceleration `ẍ_d + kd (ẋ_d − ẋ) + kp (x_d − x)` (`J q̈ + J̇ q̇` through the
/// pseudo-inverse `J⁺ = Jᵀ (J Jᵀ)⁻¹` of the tool's linear Jacobian) and move
/// the redundant joint toward `rest` in the Jacobian's null space, then
/// `τ = inverse_dynamics(q, q̇, q̈)`: every quantity from the generated code
/// (`tool_placement`, `tool_jacobian`, `tool_acceleration_bias`).
pub fn task_torques<T: RealField + Copy>(
    arm: &Panda<T>,
    state: &State<T, 7>,
    (x_d, xd_d, xdd_d): (&Vector3<T>, &Vector3<T>, &Vector3<T>),
    rest: &SVector<T, 7>,
    gains: &TaskGains<T>,
) -> Result<SVector<T, 7>, TaskError> {
    let (q, qd, t) = (&state.q, &state.qd, state.t);
    let x = arm.tool_placement(q, t).1;
    let j: SMatrix<T, 3, 7> = arm.tool_jacobian(q, t).fixed_rows::<3>(0).into_owned();
    let bias: Vector3<T> = arm
        .tool_acceleration_bias(q, qd, t)
        .fixed_rows::<3>(0)
        .into_owned();
    let xd = j * qd;
    let task = xdd_d + (xd_d - xd) * gains.kd + (x_d - x) * gains.kp;
    let gram = (j * j.transpose())
        .try_inverse()
        .ok_or(TaskError::Singular)?;
    let pseudo_inverse = j.transpose() * gram;
    let null = SMatrix::<T, 7, 7>::identity() - pseudo_inverse * j;
    let posture = (rest - q) * gains.posture_kp - qd * gains.posture_kd;
    let qdd = pseudo_inverse * (task - bias) + null * posture;
    arm.inverse_dynamics(q, qd, &qdd, t)
        .map_err(TaskError::Dynamics)
}
