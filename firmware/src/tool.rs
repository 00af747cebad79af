//! The Panda's operational-space loop on the device: the tool point follows
//! a circle under task-space inverse dynamics (`examples/panda.rs`, part 3,
//! in f32 with RK4), every quantity from the generated frame kinematics.

use crate::panda::{task_torques, Panda, TaskError, TaskGains};
use crate::Failure;
use constrained::nalgebra::{ComplexField, SVector, Vector3};
use constrained::{Rk4, State};

/// Simulated time of the arm's loop, s.
pub const TOOL_DURATION: f32 = 1.0;
/// The controller's period (zero-order hold, one RK4 step), s.
pub const TOOL_PERIOD: f32 = 1e-3;

/// The tool's tracking error over the run.
pub struct ToolTrack {
    /// The largest |x_d − x|, m (the start's velocity error dies out).
    pub peak: f32,
    /// |x_d − x| at the end, m.
    pub last: f32,
}

/// One controller step, kept a function of its own (`inline(never)`) so
/// that the firmware's symbol table gives its code size.
#[inline(never)]
pub fn tool_controller_step(
    arm: &Panda<f32>,
    state: &State<f32, 7>,
    centre: &Vector3<f32>,
    rest: &SVector<f32, 7>,
) -> Result<SVector<f32, 7>, TaskError> {
    let gains = TaskGains {
        kp: 400.0,
        kd: 40.0,
        posture_kp: 25.0,
        posture_kd: 10.0,
    };
    // A circle of radius 0.1 m in the world's y–z plane, once every 2 s.
    let (r, w) = (0.1f32, core::f32::consts::PI);
    let (s, c) = (
        ComplexField::sin(w * state.t),
        ComplexField::cos(w * state.t),
    );
    let x_d = centre + Vector3::new(0.0, s, 1.0 - c) * r;
    let xd_d = Vector3::new(0.0, c, s) * (r * w);
    let xdd_d = Vector3::new(0.0, -s, c) * (r * w * w);
    task_torques(arm, state, (&x_d, &xd_d, &xdd_d), rest, &gains)
}

/// `TOOL_DURATION` seconds of the loop from rest at the ready pose, the
/// torques set every `TOOL_PERIOD` and held over one RK4 step.
pub fn track_circle() -> Result<ToolTrack, Failure> {
    let mut arm = Panda::<f32>::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let rest = SVector::<f32, 7>::from([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]);
    let mut state = State::new(0.0, rest, SVector::zeros());
    let centre = arm.tool_placement(&rest, 0.0).1;
    let rk4 = Rk4::new(TOOL_PERIOD);
    let mut track = ToolTrack {
        peak: 0.0,
        last: 0.0,
    };
    let error = |arm: &Panda<f32>, state: &State<f32, 7>| {
        let (r, w) = (0.1f32, core::f32::consts::PI);
        let (s, c) = (
            ComplexField::sin(w * state.t),
            ComplexField::cos(w * state.t),
        );
        let x_d = centre + Vector3::new(0.0, s, 1.0 - c) * r;
        (x_d - arm.tool_placement(&state.q, state.t).1).norm()
    };
    // A bounded loop: the number of periods, not a time comparison.
    let periods = (TOOL_DURATION / TOOL_PERIOD) as usize;
    for k in 0..periods {
        let tau = tool_controller_step(&arm, &state, &centre, &rest).map_err(|e| match e {
            TaskError::Dynamics(d) => Failure::Dynamics(d),
            TaskError::Singular => Failure::Singular,
        })?;
        [
            arm.tau1, arm.tau2, arm.tau3, arm.tau4, arm.tau5, arm.tau6, arm.tau7,
        ] = [tau[0], tau[1], tau[2], tau[3], tau[4], tau[5], tau[6]];
        track.peak = track.peak.max(error(&arm, &state));
        rk4.advance(&arm, &mut state, (k + 1) as f32 * TOOL_PERIOD)?;
    }
    track.last = error(&arm, &state);
    Ok(track)
}
