//! A heavy symmetric top in unit quaternions, from its energies. The mass
//! matrix `4 GᵀJG` is singular (rank 3); the unit-norm constraint completes
//! it, and the macro solves Gauss's principle through Udwadia & Schutte's
//! auxiliary mass. Released with spin only, the axis nutates between two
//! tilts while it precesses; started on the classical steady-precession
//! rate, it precesses without nutation.
//!
//! `cargo run --release --example spinning_top [-- --duration 10 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::models::{quaternion_state, HeavyTop};
use constrained::nalgebra::{Vector3, Vector4};
use constrained::{DormandPrince45, Stabilization};
use support::{plot, Options, Panel, Series};

/// The tilt θ of the symmetry axis from the vertical and its azimuth φ.
fn axis_angles(e: &Vector4<f64>) -> (f64, f64) {
    let (w, x, y, z) = (e[0], e[1], e[2], e[3]);
    let axis = Vector3::new(
        2.0 * (x * z + w * y),
        2.0 * (y * z - w * x),
        1.0 - 2.0 * (x * x + y * y),
    );
    (axis.z.clamp(-1.0, 1.0).acos(), axis.x.atan2(-axis.y))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(4.0);
    let (a, c, m, g, l) = (0.5, 0.2, 1.0, 9.81, 0.3);
    let top = HeavyTop::<f64>::new(a, c, m, g, l);
    let (theta0, spin): (f64, f64) = (0.5, 40.0);
    let e0 = Vector4::new((theta0 / 2.0).cos(), (theta0 / 2.0).sin(), 0.0, 0.0);
    let steady = {
        let (p, q) = (a * theta0.cos(), c * spin);
        (q - (q * q - 4.0 * p * m * g * l).sqrt()) / (2.0 * p)
    };
    let method =
        DormandPrince45::new(1e-11, 1e-12).with_stabilization(Stabilization::projection(1e-13));
    let times: Vec<f64> = (0..=400)
        .map(|i| options.duration * i as f64 / 400.0)
        .collect();
    let mut progress = options.progress();
    let mut tilt_released = Vec::new();
    let mut tilt_steady = Vec::new();
    let mut azimuth_steady = Vec::new();
    let mut released = quaternion_state(0.0, e0, Vector3::new(0.0, 0.0, spin));
    method.advance_sampled(&top, &mut released, options.duration, &times, |s| {
        progress.tick(s.t);
        tilt_released.push((s.t, axis_angles(&s.q).0));
    })?;
    let mut precessing = quaternion_state(0.0, e0, Vector3::new(0.0, steady * theta0.sin(), spin));
    method.advance_sampled(&top, &mut precessing, options.duration, &times, |s| {
        let (theta, phi) = axis_angles(&s.q);
        tilt_steady.push((s.t, theta));
        azimuth_steady.push((s.t, phi));
    })?;
    let (low, high) = tilt_released
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
    let drift = tilt_steady
        .iter()
        .map(|p| (p.1 - theta0).abs())
        .fold(0.0, f64::max);
    let (_, phi_end) = axis_angles(&precessing.q);
    println!(
        "Heavy symmetric top (unit quaternions, singular M), {:.0} s:",
        options.duration
    );
    println!("  released with spin {spin} rad/s at tilt {theta0} rad: nutates between {low:.4} and {high:.4} rad");
    println!(
        "  started at the steady rate Ω = {steady:.6} rad/s: tilt kept to {drift:.1e} rad, \
         azimuth {phi_end:.6} rad after {:.0} s (Ω t = {:.6})",
        options.duration,
        steady * options.duration
    );
    let out = options.plot_path("spinning_top");
    plot(
        &out,
        "Heavy symmetric top in unit quaternions",
        &[
            Panel::new(
                "tilt of the symmetry axis",
                "t [s]",
                "θ [rad]",
                vec![
                    Series::new("released with spin only", tilt_released),
                    Series::new("steady precession", tilt_steady),
                ],
            ),
            Panel::new(
                "azimuth of the axis, steady precession",
                "t [s]",
                "φ [rad]",
                vec![Series::new("φ(t)", azimuth_steady)],
            ),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
