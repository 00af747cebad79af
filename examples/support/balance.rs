//! The balance controller of the example `quadruped_balance`: whole-body
//! inverse dynamics for the quadruped of `quadruped.rs` standing on its four
//! feet, from the generated kinematics alone.
//!
//! 1. **Accelerations.** Nineteen equations in the nineteen `q̈`: each foot
//!    at rest (`J_f q̈ + J̇_f q̇ = 0`, three rows a foot, from
//!    `{foot}_jacobian` and `{foot}_acceleration_bias`), the quaternion's
//!    norm kept (`eᵀ ë + |ė|² = 0`), the centre of mass with the acceleration
//!    `c̈_d + K_d (ċ_d − ċ) + K_p (c_d − c)` (`m c̈ = A_G q̈ + Ȧ_G q̇`, the
//!    linear rows of `centroidal_map` and `centroidal_map_bias`), and the
//!    trunk with the angular acceleration `K_p φ − K_d ω` (`φ` the rotation
//!    vector that turns it onto its target, from `trunk_placement`;
//!    `ω̇ = J_ω q̈ + J̇_ω q̇` from the angular rows of `trunk_jacobian` and
//!    `trunk_acceleration_bias`). Twelve joints and the base's six degrees
//!    of freedom, less the twelve the feet hold, leave exactly the six the
//!    two tasks ask for: the system is square.
//! 2. **Forces.** Floating-base inverse dynamics, `M q̈ + c = Sᵀ τ + Jᵀ λ`
//!    (`inverse_dynamics` is the left side): the base's seven rows, which no
//!    motor drives, fix the feet's forces up to the internal ones that
//!    squeeze the ground; the controller takes the least-squares forces,
//!    `Σ |f_k|²` smallest, then the joints' rows give the torques.
//!
//! With the feet held by the model's own rows, the constrained dynamics
//! has one solution for a given `τ`: the simulator then moves with the
//! controller's `q̈` and the ground pushes with its `λ`.

use crate::quadruped::{MASS, N};
use constrained::nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Vector3};
use constrained::{DynamicsError, State};

quadruped_system!(
    /// The quadruped with the frames its balance controller reads: the
    /// trunk (the base's own frame) and the four feet's contact points,
    /// where the model's rows hold them.
    Balancing,
    [],
    frames: [
        trunk { body: base },
        fl_foot { body: fl_lower, xyz: [0.0, 0.008, -0.16] },
        fr_foot { body: fr_lower, xyz: [0.0, -0.008, -0.16] },
        hl_foot { body: hl_lower, xyz: [0.0, 0.008, -0.16] },
        hr_foot { body: hr_lower, xyz: [0.0, -0.008, -0.16] },
    ]
);

type Jacobian = SMatrix<f64, 6, N>;

/// The gains: the centre of mass's error obeys `ë + kd ė + kp e = 0`, the
/// trunk's rotation error the same with its own pair.
#[derive(Clone, Copy, Debug)]
pub struct Gains {
    /// The centre of mass's stiffness, 1/s².
    pub com_kp: f64,
    /// The centre of mass's damping, 1/s.
    pub com_kd: f64,
    /// The trunk's stiffness, 1/s².
    pub trunk_kp: f64,
    /// The trunk's damping, 1/s.
    pub trunk_kd: f64,
}

/// The centre of mass's target: position, velocity, acceleration.
pub type Target = (Vector3<f64>, Vector3<f64>, Vector3<f64>);

/// What the controller commands and expects.
#[derive(Clone, Copy, Debug)]
pub struct Command {
    /// The joints' torques, in the model's order of inputs.
    pub tau: SVector<f64, 12>,
    /// The accelerations it asked for.
    pub qdd: SVector<f64, N>,
    /// The force of the ground on each foot, world axes (front-left,
    /// front-right, hind-left, hind-right).
    pub feet: [Vector3<f64>; 4],
}

/// What the controller could not do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BalanceError {
    /// The tasks' equations, or the base's rows of the forces, lost rank
    /// (a leg stretched straight).
    Singular,
    /// The generated inverse dynamics refused the state.
    Dynamics(DynamicsError),
}

/// Each foot's Jacobian and `J̇ q̇`, in the model's order of feet.
fn feet(robot: &Balancing<f64>, state: &State<f64, N>) -> [(Jacobian, SVector<f64, 6>); 4] {
    let (q, qd, t) = (&state.q, &state.qd, state.t);
    [
        (
            robot.fl_foot_jacobian(q, t),
            robot.fl_foot_acceleration_bias(q, qd, t),
        ),
        (
            robot.fr_foot_jacobian(q, t),
            robot.fr_foot_acceleration_bias(q, qd, t),
        ),
        (
            robot.hl_foot_jacobian(q, t),
            robot.hl_foot_acceleration_bias(q, qd, t),
        ),
        (
            robot.hr_foot_jacobian(q, t),
            robot.hr_foot_acceleration_bias(q, qd, t),
        ),
    ]
}

/// The rotation vector that turns `r` onto `target` (world axes): with
/// `φ̇ = ω` to first order, `ω̇ = kp φ − kd ω` makes `φ̈ + kd φ̇ + kp φ = 0`.
pub fn attitude_error(r: &Matrix3<f64>, target: &Matrix3<f64>) -> Vector3<f64> {
    Rotation3::from_matrix_unchecked(target * r.transpose()).scaled_axis()
}

/// The nineteen accelerations of the four feet held, the norm kept, the
/// centre of mass's and the trunk's tasks.
fn accelerations(
    robot: &Balancing<f64>,
    state: &State<f64, N>,
    feet: &[(Jacobian, SVector<f64, 6>); 4],
    (c_d, cd_d, cdd_d): &Target,
    gains: &Gains,
) -> Result<SVector<f64, N>, BalanceError> {
    let (q, qd, t) = (&state.q, &state.qd, state.t);
    let mut rows = SMatrix::<f64, N, N>::zeros();
    let mut rhs = SVector::<f64, N>::zeros();
    for (k, (j, bias)) in feet.iter().enumerate() {
        rows.fixed_view_mut::<3, N>(3 * k, 0)
            .copy_from(&j.fixed_rows::<3>(0));
        rhs.fixed_rows_mut::<3>(3 * k)
            .copy_from(&-bias.fixed_rows::<3>(0));
    }
    // d²/dt² ½|e|² = eᵀ ë + |ė|²: the quaternion's rates along itself move
    // nothing, so the tasks alone leave that direction free.
    let (e, ed) = (q.fixed_rows::<4>(3), qd.fixed_rows::<4>(3));
    rows.fixed_view_mut::<1, 4>(12, 3).copy_from(&e.transpose());
    rhs[12] = -ed.norm_squared();
    let map = robot.centroidal_map(q, t);
    let map_bias = robot.centroidal_map_bias(q, qd, t);
    let c = robot.center_of_mass(q, t);
    let cd = robot.center_of_mass_velocity(q, qd, t);
    let com = cdd_d + (cd_d - cd) * gains.com_kd + (c_d - c) * gains.com_kp;
    rows.fixed_view_mut::<3, N>(13, 0)
        .copy_from(&(map.fixed_rows::<3>(0) / MASS));
    rhs.fixed_rows_mut::<3>(13)
        .copy_from(&(com - map_bias.fixed_rows::<3>(0) / MASS));
    let trunk = robot.trunk_jacobian(q, t);
    let trunk_bias = robot.trunk_acceleration_bias(q, qd, t);
    let omega = (trunk * qd).fixed_rows::<3>(3).into_owned();
    let phi = attitude_error(&robot.trunk_placement(q, t).0, &Matrix3::identity());
    let turn = phi * gains.trunk_kp - omega * gains.trunk_kd;
    rows.fixed_view_mut::<3, N>(16, 0)
        .copy_from(&trunk.fixed_rows::<3>(3));
    rhs.fixed_rows_mut::<3>(16)
        .copy_from(&(turn - trunk_bias.fixed_rows::<3>(3)));
    rows.lu().solve(&rhs).ok_or(BalanceError::Singular)
}

/// The torques and the feet's forces that give `qdd`: the base's rows of
/// `M q̈ + c = Sᵀ τ + Jᵀ λ` solved for the least-squares forces, the joints'
/// rows for the torques.
fn forces(
    robot: &Balancing<f64>,
    state: &State<f64, N>,
    feet: &[(Jacobian, SVector<f64, 6>); 4],
    qdd: &SVector<f64, N>,
) -> Result<(SVector<f64, 12>, [Vector3<f64>; 4]), BalanceError> {
    let (q, qd, t) = (&state.q, &state.qd, state.t);
    let id = robot
        .inverse_dynamics(q, qd, qdd, t)
        .map_err(BalanceError::Dynamics)?;
    // The base's rows: the feet's forces and the norm row's multiplier. The
    // norm's column (0; e) is orthogonal to every foot's (a rate along e
    // moves no foot), so the minimum-norm solution of the seven rows has
    // the least Σ |f_k|² of the feet.
    let mut base = SMatrix::<f64, 7, 13>::zeros();
    for (k, (j, _)) in feet.iter().enumerate() {
        base.fixed_view_mut::<7, 3>(0, 3 * k)
            .copy_from(&j.fixed_view::<3, 7>(0, 0).transpose());
    }
    base.fixed_view_mut::<4, 1>(3, 12)
        .copy_from(&q.fixed_rows::<4>(3));
    let gram = (base * base.transpose())
        .try_inverse()
        .ok_or(BalanceError::Singular)?;
    let lambda = base.transpose() * (gram * id.fixed_rows::<7>(0));
    let mut tau = id.fixed_rows::<12>(7).into_owned();
    let mut force = [Vector3::zeros(); 4];
    for (k, (j, _)) in feet.iter().enumerate() {
        force[k] = lambda.fixed_rows::<3>(3 * k).into_owned();
        tau -= j.fixed_view::<3, 12>(0, 7).transpose() * force[k];
    }
    Ok((tau, force))
}

/// The balance controller's command at `state`: the centre of mass toward
/// `target`, the trunk level and facing `x`, the feet at rest.
pub fn balance(
    robot: &Balancing<f64>,
    state: &State<f64, N>,
    target: &Target,
    gains: &Gains,
) -> Result<Command, BalanceError> {
    let feet = feet(robot, state);
    let qdd = accelerations(robot, state, &feet, target, gains)?;
    let (tau, pushes) = forces(robot, state, &feet, &qdd)?;
    Ok(Command {
        tau,
        qdd,
        feet: pushes,
    })
}
