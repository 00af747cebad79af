//! A planar five-bar linkage, the parallel mechanism of many pick-and-place
//! robots and plotters: two motors on the ground 0.2 m apart, each turning
//! a 0.15 m proximal link, joined by two 0.25 m distal links whose tips
//! meet at the end effector. Written as a tree of four bodies on revolute
//! joints about `y` and one loop closure, the tips' positions equal (two
//! rows in the `x`–`z` plane: the third, `y`, is identically zero):
//!
//! ```text
//! constraints: [
//!     position(left_distal, [0.25, 0.0, 0.0]).x == position(right_distal, [0.25, 0.0, 0.0]).x,
//!     position(left_distal, [0.25, 0.0, 0.0]).z == position(right_distal, [0.25, 0.0, 0.0]).z,
//!     q1 == a1 + d1 * sin(w * t),   // the motors' trajectories, rheonomic rows
//!     q3 == a3 + d3 * sin(w * t + phase),
//! ]
//! ```
//!
//! Driven through its motors' trajectories, the mechanism has no freedom
//! left: the generated solve gives the passive joints' motion, and the
//! multipliers of the two driving rows (`constrained::multipliers`,
//! `Q_c = Aᵀλ`) are the motor torques that produce it, gravity and inertia
//! included. Integrated by `DormandPrince45` with projection; the loop
//! closure's residual is plotted.
//!
//! `cargo run --release --example five_bar [-- --duration 6 --progress]`

#[path = "support/mod.rs"]
mod support;

use constrained::constrained_system;
use constrained::multipliers::Multipliers;
use constrained::nalgebra::SVector;
use constrained::{ConstrainedSystem, DormandPrince45, Stabilization, State};
use support::{plot, Options, Panel, Series};

constrained_system! {
    /// A planar five-bar linkage in the vertical `x`–`z` plane, its two
    /// motors (`q1`, `q3`) driven along sinusoids.
    pub struct FiveBar {
        parameters: [a1, d1, a3, d3, w, phase],
        bodies: [
            left_proximal {
                joint: revolute(q1, [0.0, 1.0, 0.0]),
                xyz: [-0.1, 0.0, 0.0],
                mass: 0.2,
                com: [0.075, 0.0, 0.0],
                inertia: diag[1.0e-5, 4.0e-4, 4.0e-4],
            },
            left_distal {
                parent: left_proximal,
                joint: revolute(q2, [0.0, 1.0, 0.0]),
                xyz: [0.15, 0.0, 0.0],
                mass: 0.15,
                com: [0.125, 0.0, 0.0],
                inertia: diag[1.0e-5, 8.0e-4, 8.0e-4],
            },
            right_proximal {
                joint: revolute(q3, [0.0, 1.0, 0.0]),
                xyz: [0.1, 0.0, 0.0],
                mass: 0.2,
                com: [0.075, 0.0, 0.0],
                inertia: diag[1.0e-5, 4.0e-4, 4.0e-4],
            },
            right_distal {
                parent: right_proximal,
                joint: revolute(q4, [0.0, 1.0, 0.0]),
                xyz: [0.15, 0.0, 0.0],
                mass: 0.15,
                com: [0.125, 0.0, 0.0],
                inertia: diag[1.0e-5, 8.0e-4, 8.0e-4],
            },
        ],
        constraints: [
            position(left_distal, [0.25, 0.0, 0.0]).x == position(right_distal, [0.25, 0.0, 0.0]).x,
            position(left_distal, [0.25, 0.0, 0.0]).z == position(right_distal, [0.25, 0.0, 0.0]).z,
            q1 == a1 + d1 * sin(w * t),
            q3 == a3 + d3 * sin(w * t + phase),
        ],
    }
}

/// The tips of both distal links for joint angles `q` (a rotation about
/// `y` by `θ` turns `x` towards `−z`).
fn tips(q: &SVector<f64, 4>) -> [(f64, f64); 2] {
    let tip = |base: f64, a: f64, b: f64| {
        let (x, z) = (base + 0.15 * a.cos(), -0.15 * a.sin());
        (x + 0.25 * (a + b).cos(), z - 0.25 * (a + b).sin())
    };
    [tip(-0.1, q[0], q[1]), tip(0.1, q[2], q[3])]
}

/// Solves the closure for the passive joints by Newton's method from a
/// guess (the elbows out), given the motors' angles.
fn assemble(q1: f64, q3: f64, mut q2: f64, mut q4: f64) -> Option<(f64, f64)> {
    for _ in 0..50 {
        let q = SVector::from([q1, q2, q3, q4]);
        let [l, r] = tips(&q);
        let (fx, fz) = (l.0 - r.0, l.1 - r.1);
        if fx.abs().max(fz.abs()) < 1e-15 {
            return Some((q2, q4));
        }
        let (sl, cl) = (q1 + q2).sin_cos();
        let (sr, cr) = (q3 + q4).sin_cos();
        // ∂(fx, fz)/∂(q2, q4).
        let j = [[-0.25 * sl, 0.25 * sr], [-0.25 * cl, 0.25 * cr]];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det.abs() < 1e-12 {
            return None;
        }
        q2 -= (j[1][1] * fx - j[0][1] * fz) / det;
        q4 -= (-j[1][0] * fx + j[0][0] * fz) / det;
    }
    None
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(6.0);
    // Motors about a pose with the end effector 0.3 m below the base.
    let (a1, d1, a3, d3, w, phase) = (1.9f64, 0.35, 1.25, 0.35, 2.0, 1.2);
    let linkage = FiveBar::new(a1, d1, a3, d3, w, phase);
    let (q1, q3) = (a1, a3 + d3 * phase.sin());
    let (q2, q4) = assemble(q1, q3, -1.3, 1.3).ok_or("the linkage does not assemble")?;
    let q = SVector::from([q1, q2, q3, q4]);
    // A consistent velocity: the motors' rates, the passive ones by the
    // velocity rows (solved by the generated constraint matrices at q̇ = 0).
    let rest = State::new(0.0, q, SVector::zeros());
    let (a, _) = ConstrainedSystem::constraint_matrices(&linkage, &rest);
    let drive = ConstrainedSystem::constraint_velocity_residual(&linkage, &rest);
    // A q̇ + (φ̇ at q̇ = 0) = 0: the 4 × 4 system for q̇.
    let qd = a.lu().solve(&(-drive)).ok_or("singular at the start")?;
    let mut state = State::new(0.0, q, qd);
    let integrator =
        DormandPrince45::new(1e-10, 1e-12).with_stabilization(Stabilization::projection(1e-12));
    let (period, steps) = (5e-3, (options.duration / 5e-3).round() as usize);
    let mut progress = options.progress();
    let (mut closure, mut effector, mut torques) = (Vec::new(), Vec::new(), Vec::new());
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        let (_, lambda) = linkage.acceleration_and_multipliers(&state)?;
        torques.push((state.t, lambda[2], lambda[3]));
        let next = state.t + period;
        integrator.advance(&linkage, &mut state, next)?;
        let phi = ConstrainedSystem::constraint_residual(&linkage, &state);
        let loop_gap = phi[0].abs().max(phi[1].abs());
        worst = worst.max(loop_gap);
        closure.push((state.t, loop_gap.max(1e-18)));
        effector.push(tips(&state.q)[0]);
        progress.tick(state.t);
    }
    let peak = torques
        .iter()
        .map(|t| t.1.abs().max(t.2.abs()))
        .fold(0.0, f64::max);
    println!(
        "five-bar, {:.0} s: loop closure within {worst:.1e} m, peak motor torque {peak:.3} N·m",
        options.duration
    );
    if worst > 1e-9 {
        return Err(format!("the loop opened by {worst:.1e} m").into());
    }
    let out = options.plot_path("five_bar");
    plot(
        &out,
        "Planar five-bar linkage: motors driven along sinusoids, torques from the multipliers",
        &[
            Panel::new(
                "end effector",
                "x [m]",
                "z [m]",
                vec![Series::new("path", effector)],
            )
            .equal(),
            Panel::new(
                "motor torques, the driving rows' λ",
                "t [s]",
                "[N·m]",
                vec![
                    Series::new("left", torques.iter().map(|t| (t.0, t.1)).collect()),
                    Series::new("right", torques.iter().map(|t| (t.0, t.2)).collect()),
                ],
            ),
            Panel::new(
                "loop-closure residual |φ|",
                "t [s]",
                "[m]",
                vec![Series::new("|φ|", closure)],
            )
            .log(),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
