//! The Chaplygin sleigh: a body on a knife edge that cannot slide sideways,
//! a nonholonomic constraint linear in the velocities. Launched spinning,
//! the sleigh trades rotation for forward motion and ends up gliding in a
//! straight line, although no force acts and energy is conserved.
//!
//! `cargo run --release --example chaplygin_sleigh [-- --duration 40 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::models::ChaplyginSleigh;
use constrained::nalgebra::Vector3;
use constrained::{DormandPrince45, State};
use support::{plot, Options, Panel, Series};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(20.0);
    let (m, inertia, a) = (1.0, 0.2, 0.3);
    let system = ChaplyginSleigh::<f64>::new(m, inertia, a, 0.0);
    // Contact-point speed u along the blade and spin ω fix a consistent q̇.
    let (theta, u, omega): (f64, f64, f64) = (0.0, 0.2, 3.0);
    let qd = Vector3::new(
        u * theta.cos() - a * theta.sin() * omega,
        u * theta.sin() + a * theta.cos() * omega,
        omega,
    );
    let mut state = State::new(0.0, Vector3::new(0.0, 0.0, theta), qd);
    let energy = |s: &State<f64, 3>| {
        0.5 * m * (s.qd.x * s.qd.x + s.qd.y * s.qd.y) + 0.5 * inertia * s.qd.z * s.qd.z
    };
    let e0 = energy(&state);
    let (mut path, mut spin, mut residual, mut worst_energy) =
        (Vec::new(), Vec::new(), Vec::new(), 0.0f64);
    let mut progress = options.progress();
    DormandPrince45::new(1e-10, 1e-12)
        .with_max_step(0.02)
        .advance_with(&system, &mut state, options.duration, |s| {
            progress.tick(s.t);
            path.push((s.q.x, s.q.y));
            spin.push((s.t, s.qd.z));
            residual.push((s.t, system.constraint_residual(&s.q, &s.qd, s.t)[0]));
            worst_energy = worst_energy.max(((energy(s) - e0) / e0).abs());
        })?;
    println!("Chaplygin sleigh, {:.0} s: spin {omega} → {:.2e} rad/s, relative energy drift {worst_energy:.1e}", options.duration, state.qd.z);
    let out = options.plot_path("chaplygin_sleigh");
    plot(
        &out,
        "Chaplygin sleigh: nonholonomic, energy conserving, spin decays",
        &[
            Panel::new(
                "path of the centre of mass",
                "x [m]",
                "y [m]",
                vec![Series::new("(x, y)", path)],
            )
            .equal(),
            Panel::new(
                "spin and the constraint residual",
                "t [s]",
                "[rad/s], [m/s]",
                vec![Series::new("|θ̇|", spin), Series::new("|φ|", residual)],
            )
            .log(),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
