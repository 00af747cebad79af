//! Appell's particle (Udwadia & Kalaba, eq. 28–33): a unit mass under
//! gravity whose speed is tied to its position, `ẋ² + ẏ² − ż² = 2αh` with
//! `h = x·y + sin t` — a constraint nonlinear in the velocities, which
//! Lagrange's classical equations cannot take and the paper's equations can.
//!
//! The macro derives `A q̈ = b` (eq. 30) and both equations of motion at
//! compile time. This example prints the derivation, checks eq. 30 at a
//! consistent state, simulates the particle, compares the two equations of
//! motion (generalized inverse, eq. 32; explicit Gibbs–Appell, eq. 33) at
//! every step, tracks the constraint residual, and plots the motion.
//!
//! `cargo run --release --example appell [-- --duration 20 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::models::AppellTimeDependent;
use constrained::nalgebra::Vector3;
use constrained::{DormandPrince45, State};
use support::{plot, Options, Panel, Series};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(5.0);
    let (g, alpha) = (9.81, 0.5);
    let system = AppellTimeDependent::<f64>::new(g, alpha);
    println!("{}", AppellTimeDependent::<f64>::DERIVATION);

    // A state on the constraint: choose x, y, z, ẋ, ẏ, t and solve for ż.
    let (x, y, z, xd, yd, t) = (0.3, -0.4, 1.0, 1.2, 0.7, 0.25_f64);
    let zd = (xd * xd + yd * yd - 2.0 * alpha * (x * y + t.sin())).sqrt();
    let (q, qd) = (Vector3::new(x, y, z), Vector3::new(xd, yd, zd));
    let (a, b) = system.constraint_matrices(&q, &qd, t);
    let b_eq30 = alpha * (y * xd + x * yd + t.cos()); // h_x = y, h_y = x, h_t = cos t
    let eq30 =
        a == Vector3::new(xd, yd, -zd).transpose() && (b[0] - b_eq30).abs() <= 1e-14 * b_eq30.abs();
    println!("Eq. 30 at q = ({x}, {y}, {z}), q̇ = ({xd}, {yd}, {zd:.6}), t = {t}: A = {a:.6}b = {:.12} (eq. 30: {b_eq30:.12}) {}", b[0], if eq30 { "✓" } else { "✗" });

    // Simulate, comparing the two equations of motion at every step.
    let mut state = State::new(t, q, qd);
    let mut progress = options.progress();
    let (mut path, mut residual) = (Vec::new(), Vec::new());
    let mut worst_difference: f64 = 0.0;
    let mut failed_gibbs_appell = 0;
    let stats = DormandPrince45::new(1e-10, 1e-12)
        .with_max_step(options.duration / 500.0)
        .advance_with(&system, &mut state, t + options.duration, |s| {
            progress.tick(s.t - t);
            let inverse = system.acceleration(&s.q, &s.qd, s.t);
            match system.acceleration_gibbs_appell(&s.q, &s.qd, s.t) {
                Ok(gibbs_appell) => {
                    worst_difference = worst_difference
                        .max((inverse - gibbs_appell).norm() / inverse.norm().max(1.0));
                }
                Err(_) => failed_gibbs_appell += 1,
            }
            path.push((s.t, s.q));
            residual.push((s.t, system.constraint_residual(&s.q, &s.qd, s.t)[0]));
        })?;
    let worst_residual = residual.iter().map(|(_, r)| r.abs()).fold(0.0, f64::max);
    let scale = state.qd.norm_squared(); // φ compares squared speeds
    println!(
        "Simulated {:.1} s with DormandPrince45 (rtol 1e-10): {} steps, {} rejected",
        options.duration, stats.steps, stats.rejected
    );
    println!("  eq. 32 (generalized inverse) vs eq. 33 (Gibbs–Appell): largest relative difference {worst_difference:.1e}");
    println!(
        "  constraint residual: largest |φ| = {worst_residual:.1e} (|q̇|² at the end: {scale:.1})"
    );

    let out = options.plot_path("appell");
    let coordinate =
        |i: usize, name: &str| Series::new(name, path.iter().map(|(t, q)| (*t, q[i])).collect());
    plot(
        &out,
        "Appell's particle: ẋ² + ẏ² − ż² = 2α(x·y + sin t)",
        &[
            Panel::new(
                "coordinates",
                "t [s]",
                "position [m]",
                vec![coordinate(0, "x"), coordinate(1, "y"), coordinate(2, "z")],
            ),
            Panel::new(
                "constraint residual |φ| (no stabilization)",
                "t [s]",
                "|φ| [m²/s²]",
                vec![Series::new("|φ|", residual)],
            )
            .log(),
        ],
    )?;
    println!("  plot: {}", out.display());

    let ok = eq30
        && worst_difference < 1e-9
        && failed_gibbs_appell == 0
        && worst_residual < 1e-6 * scale.max(1.0);
    if !ok {
        eprintln!("error: the checks above failed");
        std::process::exit(1);
    }
    Ok(())
}
