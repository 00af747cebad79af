//! A 7-joint arm — the Franka Emika Panda, described here as bodies from
//! published parameters (the kinematics of Franka's documentation, the
//! inertial parameters identified by Ledezma & Haddadin) — under the two
//! classic model-based controllers, both computed by the generated code:
//!
//! 1. **gravity compensation**: `τ = g(q)` (`gravity_forces`) holds the arm
//!    still wherever it is put;
//! 2. **computed-torque tracking**: `τ = M(q) (q̈_d + K_d ė + K_p e) + c(q, q̇)`,
//!    one call of `inverse_dynamics`, makes every joint's error
//!    `e = q_d − q` obey `ë + K_d ė + K_p e = 0`, so an initial error dies
//!    out with the chosen time constant while the arm follows a trajectory;
//! 3. **operational-space tracking** (task-space inverse dynamics): the
//!    tool point follows a circle, `q̈ = J⁺ (ẍ_d + K_d ė + K_p e − J̇ q̇) +
//!    (I − J⁺ J) q̈₀` with a posture `q̈₀` in the null space, then
//!    `τ = inverse_dynamics(q, q̇, q̈)`, from the generated frame kinematics
//!    (`tool_placement`, `tool_jacobian`, `tool_acceleration_bias`), so the
//!    task error obeys `ë + K_d ė + K_p e = 0`.
//!
//! The controller runs at 1 kHz (its torques held over each millisecond,
//! as the integrators hold inputs); the arm is integrated by
//! `DormandPrince45`.
//!
//! `cargo run --release --example panda [-- --duration 4 --progress]`

#[path = "support/panda.rs"]
mod panda;
#[path = "support/mod.rs"]
mod support;

use constrained::nalgebra::{SVector, Vector3};
use constrained::{DormandPrince45, State};
use panda::{task_torques, Panda, TaskGains};
use support::{plot, Options, Panel, Series};

type Vector7 = SVector<f64, 7>;

fn apply(arm: &mut Panda<f64>, tau: &Vector7) {
    [
        arm.tau1, arm.tau2, arm.tau3, arm.tau4, arm.tau5, arm.tau6, arm.tau7,
    ] = [tau[0], tau[1], tau[2], tau[3], tau[4], tau[5], tau[6]];
}

/// The desired motion: each joint swings about the ready pose.
fn desired(t: f64) -> (Vector7, Vector7, Vector7) {
    let ready = Vector7::from([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]);
    let (mut q, mut qd, mut qdd) = (ready, Vector7::zeros(), Vector7::zeros());
    for j in 0..7 {
        let (a, w) = (0.3, 1.0 + 0.25 * j as f64);
        q[j] += a * (w * t).sin();
        qd[j] = a * w * (w * t).cos();
        qdd[j] = -a * w * w * (w * t).sin();
    }
    (q, qd, qdd)
}

/// The tool's desired path: a circle of radius 0.1 m in the world's `y`–`z`
/// plane through `start`, once every two seconds; position, velocity and
/// acceleration.
fn circle(start: &Vector3<f64>, t: f64) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let (r, w) = (0.1, std::f64::consts::PI);
    let (s, c) = (w * t).sin_cos();
    (
        start + r * Vector3::new(0.0, s, 1.0 - c),
        r * w * Vector3::new(0.0, c, s),
        r * w * w * Vector3::new(0.0, -s, c),
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(4.0);
    let (period, steps) = (1e-3, (options.duration / 1e-3).round() as usize);
    let integrator = DormandPrince45::new(1e-10, 1e-12);
    let mut arm = Panda::<f64>::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut progress = options.progress();

    // 1. Gravity compensation: released at rest in the desired pose.
    let (start, _, _) = desired(0.0);
    let mut state = State::new(0.0, start, Vector7::zeros());
    let mut drift = Vec::new();
    for _ in 0..steps {
        let hold = arm.gravity_forces(&state.q, state.t)?;
        apply(&mut arm, &hold);
        let next = state.t + period;
        integrator.advance(&arm, &mut state, next)?;
        drift.push((state.t, (state.q - start).norm().max(1e-300)));
    }
    let held = drift.iter().map(|d| d.1).fold(0.0, f64::max);

    // 2. Computed torque, from 0.2 rad off the trajectory on every joint.
    let (kp, kd) = (100.0, 20.0); // ë + 20 ė + 100 e = 0: a double pole at −10 /s
    let mut state = State::new(0.0, start + Vector7::repeat(0.2), Vector7::zeros());
    let (mut error, mut angles, mut torques) = (Vec::new(), Vec::new(), Vec::new());
    let (mut peak, mut energy_in) = (0.0f64, 0.0);
    for _ in 0..steps {
        let t = state.t;
        let (q_d, qd_d, qdd_d) = desired(t);
        let e = q_d - state.q;
        let command = qdd_d + kd * (qd_d - state.qd) + kp * e;
        let tau = arm.inverse_dynamics(&state.q, &state.qd, &command, t)?;
        apply(&mut arm, &tau);
        peak = peak.max(tau.amax());
        energy_in += tau.dot(&state.qd) * period;
        error.push((t, e.norm().max(1e-300)));
        angles.push((t, state.q[1], q_d[1], state.q[3], q_d[3]));
        torques.push((t, tau[1], tau[3]));
        integrator.advance(&arm, &mut state, t + period)?;
        progress.tick(state.t);
    }
    let (q_d, _, _) = desired(state.t);
    let last = (q_d - state.q).norm();

    // 3. Operational space: the tool follows a circle from rest at the ready
    // pose; the elbow's redundancy is held near that pose in the null space.
    let gains = TaskGains {
        kp: 400.0, // ë + 40 ė + 400 e = 0: a double pole at −20 /s
        kd: 40.0,
        posture_kp: 25.0,
        posture_kd: 10.0,
    };
    let mut state = State::new(0.0, start, Vector7::zeros());
    let centre = arm.tool_placement(&start, 0.0).1;
    let (mut task_error, mut path) = (Vec::new(), Vec::new());
    for _ in 0..steps {
        let t = state.t;
        let (x_d, xd_d, xdd_d) = circle(&centre, t);
        let x = arm.tool_placement(&state.q, t).1;
        let tau = task_torques(&arm, &state, (&x_d, &xd_d, &xdd_d), &start, &gains)
            .map_err(|e| format!("operational space: {e:?}"))?;
        apply(&mut arm, &tau);
        task_error.push((t, (x_d - x).norm().max(1e-300)));
        path.push((t, x[1], x_d[1], x[2], x_d[2]));
        integrator.advance(&arm, &mut state, t + period)?;
        progress.tick(state.t);
    }
    let x_end = arm.tool_placement(&state.q, state.t).1;
    let tool_last = (circle(&centre, state.t).0 - x_end).norm();
    let tool_peak = task_error.iter().map(|e| e.1).fold(0.0, f64::max);
    // With exact dynamics the error obeys ë + K_d ė + K_p e = 0 between
    // samples and dies out as (1 + 10 t) e^(−10 t); what remains is the
    // torque held over each millisecond while the trajectory moves on.
    println!(
        "Panda, {} s at 1 kHz: gravity compensation drifts {held:.1e} rad; \
         computed torque: error {:.2} rad -> {last:.1e} rad, peak torque {peak:.0} N·m, \
         work done {energy_in:.1} J; operational space: tool error {tool_peak:.1e} m -> \
         {tool_last:.1e} m on a 0.1 m circle",
        options.duration,
        0.2 * 7f64.sqrt(),
    );
    // The bound: the transient's envelope at the end, plus the 1e-2 rad the
    // held torque leaves (a short run, as the test command's, is judged by
    // the envelope; the default 4 s by the floor).
    let envelope = 0.2 * 7f64.sqrt() * (1.0 + 10.0 * state.t) * (-10.0 * state.t).exp();
    // The tool starts at rest where the circle starts at v₀ = 0.31 m/s: its
    // error is v₀ t e^(−20 t), which peaks at v₀/(20 e) = 5.8e-3 m and dies
    // out, down to what holding each torque for a millisecond leaves.
    let tool_envelope = 0.1 * std::f64::consts::PI * state.t * (-20.0 * state.t).exp();
    if held > 1e-6 || last > 1e-2 + envelope || tool_last > 1e-3 + tool_envelope {
        return Err(format!(
            "the controllers did not hold (drift {held:.1e}, error {last:.1e}, \
             tool {tool_last:.1e})"
        )
        .into());
    }
    let out = options.plot_path("panda");
    plot(
        &out,
        "Franka Panda (bodies from published parameters): computed torque, gravity compensation, operational space",
        &[
            Panel::new(
                "joints 2 and 4 follow the trajectory",
                "t [s]",
                "[rad]",
                vec![
                    Series::new("q₂", angles.iter().map(|a| (a.0, a.1)).collect()),
                    Series::new("q₂ desired", angles.iter().map(|a| (a.0, a.2)).collect()),
                    Series::new("q₄", angles.iter().map(|a| (a.0, a.3)).collect()),
                    Series::new("q₄ desired", angles.iter().map(|a| (a.0, a.4)).collect()),
                ],
            ),
            Panel::new(
                "tracking error |q_d − q| (computed torque) and drift (gravity compensation)",
                "t [s]",
                "[rad]",
                vec![Series::new("|e|", error), Series::new("drift", drift)],
            )
            .log(),
            Panel::new(
                "operational space: the tool's y and z follow the circle",
                "t [s]",
                "[m]",
                vec![
                    Series::new("y", path.iter().map(|a| (a.0, a.1)).collect()),
                    Series::new("y desired", path.iter().map(|a| (a.0, a.2)).collect()),
                    Series::new("z", path.iter().map(|a| (a.0, a.3)).collect()),
                    Series::new("z desired", path.iter().map(|a| (a.0, a.4)).collect()),
                ],
            ),
            Panel::new(
                "operational space: tool error |x_d − x|",
                "t [s]",
                "[m]",
                vec![Series::new("|e|", task_error)],
            )
            .log(),
            Panel::new(
                "joint torques",
                "t [s]",
                "[N·m]",
                vec![
                    Series::new("τ₂", torques.iter().map(|a| (a.0, a.1)).collect()),
                    Series::new("τ₄", torques.iter().map(|a| (a.0, a.2)).collect()),
                ],
            ),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
