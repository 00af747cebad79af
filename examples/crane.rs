//! An overhead crane moves its load 2 m along the rail: a saturated PD
//! actuator (`clamp`) drives the trolley against Coulomb friction, and the
//! load swings on its rod (a position-level constraint) from a damped pivot
//! (5 % of critical damping). The friction is a `friction:` entry, switched
//! between stick (the trolley's speed held at zero by a constraint row) and
//! slip (the kinetic force against the motion) at events by
//! `integrate::StickSlip`: the trolley stops, slips while the swinging load
//! pulls harder than static friction holds, and sticks for good once the
//! swing has decayed. (`constrained::models::Crane` writes the same friction
//! with `signum`, which an adaptive integrator cannot step past once the
//! trolley stops.)
//!
//! `cargo run --release --example crane [-- --duration 60 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::friction::Mode;
use constrained::integrate::{StickSlip, StickSlipOutcome};
use constrained::nalgebra::Vector3;
use constrained::{DormandPrince45, Stabilization, State};
use support::{plot, Options, Panel, Series};

#[path = "support/damped_crane.rs"]
mod damped_crane;
use damped_crane::DampedCrane;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(60.0);
    let (ml, l, g): (f64, f64, f64) = (1.0, 1.5, 9.81);
    let damping = 2.0 * 0.05 * ml * (g / l).sqrt();
    // mc, ml, l, g, mu_s, mu_k, kp, kd, umax, target, c
    let crane = DampedCrane::new(4.0, ml, l, g, 0.06, 0.05, 30.0, 12.0, 8.0, 2.0, damping);
    let start = State::new(0.0, Vector3::new(0.0, 0.0, -l), Vector3::zeros());
    let stepper = DormandPrince45::new(1e-10, 1e-12)
        .with_stabilization(Stabilization::projection(1e-12))
        .stepper(start, options.duration)?;
    let mut run = StickSlip::new(crane, stepper)?;
    let (mut trolley, mut drive, mut sway, mut stuck) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut progress = options.progress();
    let mut switches: Vec<(f64, f64, Mode)> = Vec::new();
    let finished = run.finish(10_000_000, |run, outcome| {
        let s = run.state();
        progress.tick(s.t);
        let (xc, vc) = (s.q[0], s.qd[0]);
        let u = (crane.kp * (crane.target - xc) - crane.kd * vc).clamp(-crane.umax, crane.umax);
        trolley.push((s.t, xc));
        drive.push((s.t, u));
        sway.push((s.t, (s.q[1] - xc).atan2(-s.q[2]).to_degrees()));
        let mode = run.system().friction_modes()[0];
        stuck.push((s.t, if mode == Mode::Stick { 1.0 } else { 0.0 }));
        if let StickSlipOutcome::Switch { mode, state, .. } = outcome {
            switches.push((state.t, state.q[0], *mode));
        }
    })?;
    if !finished {
        return Err("the call budget ran out".into());
    }
    let end = *run.state();
    let steps = run.stepper().stats().steps;
    println!(
        "Overhead crane, {:.0} s (Dormand–Prince 1e-10, stick–slip switched at events):",
        options.duration
    );
    println!(
        "  {} switches in {steps} steps; final position {:.6} m (target {} m, dead band ±{:.4} m)",
        switches.len(),
        end.q[0],
        crane.target,
        crane.mu_s * (crane.mc + crane.ml) * crane.g / crane.kp
    );
    match switches.last() {
        Some(&(t, x, Mode::Stick)) => println!("  sticks for good at t = {t:.6} s, xc = {x:.9} m"),
        Some(&(t, _, mode)) => println!("  last switch at t = {t:.6} s: {mode:?}"),
        None => println!("  no switch"),
    }
    let out = options.plot_path("crane");
    let t_end = options.duration;
    plot(
        &out,
        "Overhead crane: saturated drive, Coulomb stick–slip, damped swing",
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
            Panel::new(
                "friction mode",
                "t [s]",
                "stuck",
                vec![Series::new("1 = stick, 0 = slip", stuck)],
            ),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
