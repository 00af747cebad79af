//! A planar two-link arm in joint angles — a configuration-dependent,
//! non-diagonal mass matrix `M(q)` with Coriolis and gravity forces — whose
//! tip is held on the horizontal line `y = h` (a holonomic constraint in
//! generalized coordinates). Released at rest, the arm falls while its tip
//! slides along the line.
//!
//! `cargo run --release --example two_link_arm [-- --duration 20 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::models::TwoLinkArmOnLine;
use constrained::nalgebra::Vector2;
use constrained::{DormandPrince45, Stabilization, State};
use support::{plot, Options, Panel, Series};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(5.0);
    let (m1, m2, l1, l2, g) = (1.0, 0.8, 1.0, 0.8, 9.81);
    let (th1, th2): (f64, f64) = (1.2, -1.6);
    let height = l1 * th1.sin() + l2 * (th1 + th2).sin(); // the line through the tip
    let system = TwoLinkArmOnLine::<f64>::new(m1, m2, l1, l2, g, height);
    let mut state = State::new(0.0, Vector2::new(th1, th2), Vector2::zeros());
    let (mut tip, mut angles, mut residual) = (Vec::new(), Vec::new(), Vec::new());
    let mut progress = options.progress();
    DormandPrince45::new(1e-10, 1e-12)
        .with_max_step(0.005)
        .with_stabilization(Stabilization::baumgarte(20.0))
        .advance_with(&system, &mut state, options.duration, |s| {
            progress.tick(s.t);
            let (a, b) = (s.q[0], s.q[0] + s.q[1]);
            tip.push((l1 * a.cos() + l2 * b.cos(), l1 * a.sin() + l2 * b.sin()));
            angles.push((s.t, s.q[0], s.q[1]));
            residual.push((s.t, system.constraint_residual(&s.q, &s.qd, s.t)[0]));
        })?;
    let worst = residual.iter().map(|r| r.1.abs()).fold(0.0, f64::max);
    println!(
        "Two-link arm, tip on y = {height:.3} m, {:.0} s: largest |φ| = {worst:.1e} (Baumgarte)",
        options.duration
    );
    let out = options.plot_path("two_link_arm");
    plot(
        &out,
        "Two-link arm, M(q) non-diagonal, tip held on a line",
        &[
            Panel::new(
                "joint angles",
                "t [s]",
                "[rad]",
                vec![
                    Series::new("θ₁", angles.iter().map(|a| (a.0, a.1)).collect()),
                    Series::new("θ₂", angles.iter().map(|a| (a.0, a.2)).collect()),
                ],
            ),
            Panel::new(
                "tip: it stays on the line",
                "x_tip [m]",
                "y_tip [m]",
                vec![Series::new("tip", tip)],
            )
            .equal(),
            Panel::new(
                "constraint residual (Baumgarte)",
                "t [s]",
                "|φ| [m]",
                vec![Series::new("|φ|", residual)],
            )
            .log(),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
