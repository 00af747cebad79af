//! A bead on a hoop spinning about its vertical diameter at a constant rate
//! ω: the second constraint (the bead stays in the hoop's plane) depends
//! explicitly on time. Above the critical rate ω² r > g the bottom becomes
//! unstable and the bead settles into oscillation about the angle
//! `cos ψ* = g / (ω² r)` away from it.
//!
//! `cargo run --release --example bead_on_hoop [-- --duration 30 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::models::BeadOnRotatingHoop;
use constrained::nalgebra::Vector3;
use constrained::{DormandPrince45, State};
use support::{plot, Options, Panel, Series};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(10.0);
    let (m, g, r, omega) = (0.1, 9.81, 0.5, 6.0);
    let system = BeadOnRotatingHoop::<f64>::new(m, g, r, omega);
    let psi_star = (g / (omega * omega * r)).acos();
    // Start slightly off the bottom, at rest in the rotating frame.
    let psi0: f64 = 0.05;
    let q = Vector3::new(r * psi0.sin(), 0.0, -r * psi0.cos());
    let qd = Vector3::new(0.0, r * psi0.sin() * omega, 0.0);
    let mut state = State::new(0.0, q, qd);
    let (mut angle, mut residual) = (Vec::new(), Vec::new());
    let mut progress = options.progress();
    DormandPrince45::new(1e-10, 1e-12)
        .with_max_step(0.01)
        .advance_with(&system, &mut state, options.duration, |s| {
            progress.tick(s.t);
            let along = s.q.x * (omega * s.t).cos() + s.q.y * (omega * s.t).sin();
            angle.push((s.t, along.atan2(-s.q.z)));
            residual.push((s.t, system.constraint_residual(&s.q, &s.qd, s.t).amax()));
        })?;
    let low = angle.iter().map(|a| a.1).fold(f64::INFINITY, f64::min);
    let high = angle.iter().map(|a| a.1).fold(f64::NEG_INFINITY, f64::max);
    println!(
        "Bead on a hoop at ω = {omega} rad/s (critical {:.2} rad/s), {:.0} s:",
        (g / r).sqrt(),
        options.duration
    );
    println!(
        "  no friction: ψ swings between {low:.3} and {high:.3} rad, around the off-bottom equilibrium ψ* = {psi_star:.3} rad"
    );
    let out = options.plot_path("bead_on_hoop");
    let t_end = options.duration;
    plot(
        &out,
        "Bead on a rotating hoop (time-dependent constraint)",
        &[
            Panel::new(
                "angle from the bottom, in the hoop's plane",
                "t [s]",
                "ψ [rad]",
                vec![
                    Series::new("ψ(t)", angle),
                    Series::new(
                        "ψ* = acos(g/(ω² r))",
                        vec![(0.0, psi_star), (t_end, psi_star)],
                    ),
                ],
            ),
            Panel::new(
                "constraint residual",
                "t [s]",
                "max |φ|",
                vec![Series::new("max |φ|", residual)],
            )
            .log(),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
