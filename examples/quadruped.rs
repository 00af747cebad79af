//! A quadruped with Solo-12's structure (`support/quadruped.rs`: a floating
//! base on a free joint, twelve joints, four feet fixed on the ground)
//! standing and shifting its weight under a joint-space PD controller,
//! `τ = K_p (q_ref(t) − q) − K_d q̇`, at 1 kHz. The reference swings the
//! four hip abduction joints together, which sways the base sideways over
//! its feet; the feet's forces, the multipliers `λ` of their rows
//! (`constrained::multipliers`: the force on each foot, in the world's
//! axes), move from one side to the other while their sum carries the
//! weight. Integrated by `DormandPrince45` with projection (tolerance
//! 1e-12), which keeps the feet in place.
//!
//! `cargo run --release --example quadruped [-- --duration 8 --progress]`

#[path = "support/quadruped.rs"]
mod quadruped;
#[path = "support/mod.rs"]
mod support;

use constrained::floating::FreeMotion;
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{SVector, UnitQuaternion, Vector3};
use constrained::{ConstrainedSystem, DormandPrince45, Stabilization, State};
use quadruped::{Quadruped, FOOT_OFFSET, HIPS, MASS, N, SEGMENT};
use support::{plot, Options, Panel, Series};

/// Hip flexion when standing; the knee is at `−2θ`, each foot under its hip.
const THETA: f64 = 0.8;

fn set_torques(robot: &mut Quadruped<f64>, tau: &[f64]) {
    [robot.t_fl_haa, robot.t_fl_hfe, robot.t_fl_kfe] = [tau[0], tau[1], tau[2]];
    [robot.t_fr_haa, robot.t_fr_hfe, robot.t_fr_kfe] = [tau[3], tau[4], tau[5]];
    [robot.t_hl_haa, robot.t_hl_hfe, robot.t_hl_kfe] = [tau[6], tau[7], tau[8]];
    [robot.t_hr_haa, robot.t_hr_hfe, robot.t_hr_kfe] = [tau[9], tau[10], tau[11]];
}

/// The joints' reference: standing, the hip abductions swinging by 0.12 rad
/// after the first second.
fn reference(t: f64) -> [f64; 12] {
    let sway = if t < 1.0 {
        0.0
    } else {
        0.12 * (std::f64::consts::PI * (t - 1.0) / 2.0).sin()
    };
    let mut q = [0.0; 12];
    for leg in 0..4 {
        q[3 * leg] = sway;
        q[3 * leg + 1] = THETA;
        q[3 * leg + 2] = -2.0 * THETA;
    }
    q
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(8.0);
    let (period, steps) = (1e-3, (options.duration / 1e-3).round() as usize);
    let mut feet = [0.0; 8];
    for (k, h) in HIPS.iter().enumerate() {
        feet[2 * k] = h[0];
        feet[2 * k + 1] = h[1] + h[1].signum() * FOOT_OFFSET;
    }
    let [a, b, c, d, e, f, g, h] = feet;
    let zero = 0.0;
    let mut robot = Quadruped::new(
        a, b, c, d, e, f, g, h, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero,
        zero,
    );
    let base = FreeMotion::at_rest(
        Vector3::new(0.0, 0.0, 2.0 * SEGMENT * THETA.cos()),
        UnitQuaternion::identity(),
    );
    let (mut q, mut qd) = (SVector::<f64, N>::zeros(), SVector::<f64, N>::zeros());
    base.write(0, &mut q, &mut qd)?;
    q.as_mut_slice()[7..].copy_from_slice(&reference(0.0));
    let mut state = State::new(0.0, q, qd);
    let integrator =
        DormandPrince45::new(1e-10, 1e-12).with_stabilization(Stabilization::projection(1e-12));
    let (kp, kd) = (6.0, 0.15);
    let mut progress = options.progress();
    let (mut forces, mut sway, mut residual) = (Vec::new(), Vec::new(), Vec::new());
    let (mut worst_foot, mut lowest): (f64, f64) = (0.0, f64::INFINITY);
    for step in 0..steps {
        let r = reference(state.t);
        let tau: Vec<f64> = (0..12)
            .map(|j| kp * (r[j] - state.q[7 + j]) - kd * state.qd[7 + j])
            .collect();
        set_torques(&mut robot, &tau);
        let (_, lambda) = robot.acceleration_and_multipliers(&state)?;
        let normal = [lambda[2], lambda[5], lambda[8], lambda[11]];
        lowest = lowest.min(normal.iter().copied().fold(f64::INFINITY, f64::min));
        let sample = step % 5 == 0; // every 5 ms on the plot
        if sample {
            forces.push((state.t, normal, normal.iter().sum::<f64>()));
            sway.push((state.t, state.q[1]));
        }
        let next = state.t + period;
        integrator.advance(&robot, &mut state, next)?;
        let foot = ConstrainedSystem::constraint_residual(&robot, &state).amax();
        worst_foot = worst_foot.max(foot);
        if sample {
            residual.push((state.t, foot.max(1e-18)));
        }
        progress.tick(state.t);
    }
    let weight = MASS * 9.81;
    println!(
        "quadruped, {:.0} s at 1 kHz: feet within {worst_foot:.1e} m of their places; \
         normal forces ≥ {lowest:.2} N (all pushing), weight {weight:.2} N",
        options.duration
    );
    if worst_foot > 1e-9 || lowest <= 0.0 {
        return Err(format!("feet moved {worst_foot:.1e} m or lifted ({lowest:.2} N)").into());
    }
    let out = options.plot_path("quadruped");
    let leg = |k: usize| forces.iter().map(|f| (f.0, f.1[k])).collect();
    plot(
        &out,
        "Quadruped (Solo-12's structure, floating base, 4 feet fixed): PD standing and swaying",
        &[
            Panel::new(
                "normal forces on the feet, λ_z",
                "t [s]",
                "[N]",
                vec![
                    Series::new("front left", leg(0)),
                    Series::new("front right", leg(1)),
                    Series::new("hind left", leg(2)),
                    Series::new("hind right", leg(3)),
                    Series::new(
                        "sum (m g = 24.3 N)",
                        forces.iter().map(|f| (f.0, f.2)).collect(),
                    ),
                ],
            ),
            Panel::new(
                "base sideways",
                "t [s]",
                "y [m]",
                vec![Series::new("y", sway)],
            ),
            Panel::new(
                "feet's distance from their places (projection at 1e-12)",
                "t [s]",
                "[m]",
                vec![Series::new("max |φ|", residual)],
            )
            .log(),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
