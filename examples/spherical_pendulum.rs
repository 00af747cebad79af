//! A spherical pendulum in Cartesian coordinates: three coordinates, one
//! holonomic constraint `x² + y² + z² = l²`. Started off the vertical plane
//! it traces the familiar precessing rosette; energy and the vertical
//! angular momentum are conserved, which this example measures along with
//! the constraint residual.
//!
//! `cargo run --release --example spherical_pendulum [-- --duration 60 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::models::SphericalPendulum;
use constrained::nalgebra::Vector3;
use constrained::{DormandPrince45, State};
use support::{plot, Options, Panel, Series};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(10.0);
    let (m, g, l) = (1.0, 9.81, 1.0);
    let system = SphericalPendulum::<f64>::new(m, g, l);
    let n = Vector3::new(0.6, 0.0, -0.8); // 37° from the downward vertical
    let mut state = State::new(0.0, n * l, Vector3::new(0.0, 2.0, 0.0));
    let energy = |s: &State<f64, 3>| 0.5 * m * s.qd.norm_squared() + m * g * s.q.z;
    let lz = |s: &State<f64, 3>| m * (s.q.x * s.qd.y - s.q.y * s.qd.x);
    let (e0, l0) = (energy(&state), lz(&state));
    let (mut top, mut drift, mut residual) = (Vec::new(), Vec::new(), Vec::new());
    let mut progress = options.progress();
    DormandPrince45::new(1e-10, 1e-12)
        .with_max_step(0.01)
        .advance_with(&system, &mut state, options.duration, |s| {
            progress.tick(s.t);
            top.push((s.q.x, s.q.y));
            drift.push((s.t, (energy(s) - e0) / e0.abs(), (lz(s) - l0) / l0.abs()));
            residual.push((s.t, system.constraint_residual(&s.q, &s.qd, s.t)[0]));
        })?;
    let worst = |i: usize| {
        drift
            .iter()
            .map(|d| if i == 0 { d.1.abs() } else { d.2.abs() })
            .fold(0.0, f64::max)
    };
    println!(
        "Spherical pendulum, {:.0} s (DormandPrince45, rtol 1e-10):",
        options.duration
    );
    println!(
        "  relative energy drift {:.1e}, relative drift of L_z {:.1e}",
        worst(0),
        worst(1)
    );
    let out = options.plot_path("spherical_pendulum");
    plot(
        &out,
        "Spherical pendulum in Cartesian coordinates",
        &[
            Panel::new(
                "seen from above: the precessing rosette",
                "x [m]",
                "y [m]",
                vec![Series::new("(x, y)", top)],
            )
            .equal(),
            Panel::new(
                "conservation and the constraint",
                "t [s]",
                "relative error",
                vec![
                    Series::new("|ΔE/E|", drift.iter().map(|d| (d.0, d.1)).collect()),
                    Series::new("|ΔL_z/L_z|", drift.iter().map(|d| (d.0, d.2)).collect()),
                    Series::new("|φ| / l²", residual),
                ],
            )
            .log(),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
