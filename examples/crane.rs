//! An overhead crane moves its load 2 m along the rail: a saturated PD
//! actuator (`clamp`) drives the trolley against Coulomb friction
//! (`signum` of its speed), and the load swings on its rod (a position-level
//! constraint). The non-smooth functions sit in `forces`, which the macro
//! never differentiates; at a kink or jump an integrator with a fixed step
//! is the honest choice (an adaptive one would shrink its step to resolve
//! the jump, with nothing to gain).
//!
//! `cargo run --release --example crane [-- --duration 20 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::models::Crane;
use constrained::nalgebra::Vector3;
use constrained::{Rk4, Stabilization, State};
use support::{plot, Options, Panel, Series};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(12.0);
    // mc, ml, l, g, mu, kp, kd, umax, target
    let crane = Crane::<f64>::new(4.0, 1.0, 1.5, 9.81, 0.05, 30.0, 12.0, 8.0, 2.0);
    let mut state = State::new(0.0, Vector3::new(0.0, 0.0, -crane.l), Vector3::zeros());
    let (mut trolley, mut drive, mut sway, mut residual) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut progress = options.progress();
    let mut saturated_steps = 0usize;
    let mut steps = 0usize;
    Rk4::new(1e-3)
        .with_stabilization(Stabilization::projection(1e-12))
        .advance_with(&crane, &mut state, options.duration, |s| {
            progress.tick(s.t);
            let (xc, vc) = (s.q[0], s.qd[0]);
            let u = (crane.kp * (crane.target - xc) - crane.kd * vc).clamp(-crane.umax, crane.umax);
            steps += 1;
            if u.abs() == crane.umax {
                saturated_steps += 1;
            }
            trolley.push((s.t, xc));
            drive.push((s.t, u));
            sway.push((s.t, (s.q[1] - xc).atan2(-s.q[2]).to_degrees()));
            residual.push((s.t, crane.constraint_residual(&s.q, &s.qd, s.t).amax()));
        })?;
    let max_sway = sway.iter().map(|s| s.1.abs()).fold(0.0, f64::max);
    let arrival = trolley
        .iter()
        .find(|p| (p.0 > 0.0) && (p.1 - crane.target).abs() < 0.01)
        .map(|p| p.0);
    let max_residual = residual.iter().map(|r| r.1).fold(0.0, f64::max);
    println!(
        "Overhead crane, {:.0} s (RK4, h = 1 ms, projection):",
        options.duration
    );
    println!(
        "  drive saturated at ±{} N for {:.0} % of the steps; trolley within 1 cm of the target after {}",
        crane.umax,
        100.0 * saturated_steps as f64 / steps.max(1) as f64,
        arrival.map_or("never".to_string(), |t| format!("{t:.2} s"))
    );
    println!(
        "  final position {:.4} m (target {} m; friction leaves a dead band of μ(mc+ml)g/kp = {:.4} m)",
        state.q[0],
        crane.target,
        crane.mu * (crane.mc + crane.ml) * crane.g / crane.kp
    );
    println!("  largest sway {max_sway:.2}°, largest |φ| {max_residual:.1e}");
    let out = options.plot_path("crane");
    let t_end = options.duration;
    plot(
        &out,
        "Overhead crane: saturated drive, Coulomb friction",
        &[
            Panel::new(
                "trolley position",
                "t [s]",
                "x_c [m]",
                vec![
                    Series::new("x_c(t)", trolley),
                    Series::new("target", vec![(0.0, crane.target), (t_end, crane.target)]),
                ],
            ),
            Panel::new(
                "drive force, clamp(kp e − kd ẋc, ±umax)",
                "t [s]",
                "u [N]",
                vec![Series::new("u(t)", drive)],
            ),
            Panel::new(
                "load sway",
                "t [s]",
                "angle [°]",
                vec![Series::new("sway(t)", sway)],
            ),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
