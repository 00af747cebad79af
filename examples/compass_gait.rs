//! The compass-gait walker on a slope (Goswami, Thuilot & Espiau 1996):
//! two straight legs hinged at the hip, a point mass `mh` at the hip and
//! `m` on each leg, walking down a slope of 3° with no actuation. The stance
//! foot is pinned by two constraints, the swing foot's height over the
//! slope is a gap; at heel strike (the gap falling through zero with the
//! swing leg in front: the swing foot's scuffing at mid-stance is ignored,
//! as in the model's literature) the legs swap roles and the generated
//! impact map gives the post-strike velocities: plastic, the new foot
//! pinned, which conserves the angular momentum about it and the trailing
//! leg's about the hip. The stable period-one gait is found by Newton's
//! method on the stride map, from the rounded values Goswami et al. publish
//! for this walker (legs at 0.218 and −0.323 rad, rates −1.09 and −0.377
//! rad/s, which it reproduces to their three digits; the other period-one
//! gait, with longer steps, is unstable), and a walk from 5 % off it
//! converges to it.
//!
//! `cargo run --release --example compass_gait`

#[path = "support/compass_gait.rs"]
mod compass_gait;
#[path = "support/mod.rs"]
mod support;

use compass_gait::CompassGait;
use constrained::integrate::{Direction, Event, Events, StepOutcome};
use constrained::nalgebra::{Matrix3, Vector3, Vector4};
use constrained::{DormandPrince45, Stabilization, State};
use support::{plot, Options, Panel, Series};

type Walker = CompassGait<f64>;

/// The state just after a strike with leg 1 in stance, its foot at the
/// origin: the legs symmetric about the slope's normal, the stance leg at
/// `−γ + δ`, rotating at `ws`, the swing leg at `wf`.
fn start(w: &Walker, p: &Vector3<f64>) -> (Walker, State<f64, 4>) {
    let (delta, ws, wf) = (p[0], p[1], p[2]);
    let l = w.a + w.b;
    let (t1, t2) = (-w.gamma + delta, -w.gamma - delta);
    let q = Vector4::new(-l * t1.sin(), l * t1.cos(), t1, t2);
    let qd = Vector4::new(-l * t1.cos() * ws, -l * t1.sin() * ws, ws, wf);
    let walker = CompassGait {
        s: 0.0,
        px: 0.0,
        py: 0.0,
        ..*w
    };
    (walker, State::new(0.0, q, qd))
}

/// Walks `strides` strides from `state`, calling `record` at every step
/// and strike; returns the walker and state just after the last strike.
fn walk(
    mut w: Walker,
    state: State<f64, 4>,
    strides: usize,
    mut record: impl FnMut(&Walker, &State<f64, 4>),
) -> Result<(Walker, State<f64, 4>), Box<dyn std::error::Error>> {
    let mut stepper = DormandPrince45::new(1e-11, 1e-12)
        .with_stabilization(Stabilization::projection(1e-12))
        .stepper(state, 1e3)?;
    let mut done = 0;
    while done < strides {
        let current = w;
        let events = Events::new(
            move |s: &State<f64, 4>| [current.gaps(&s.q, s.t)[0]],
            [Event::stop(Direction::Falling)],
        );
        match stepper.step(&w, &events)? {
            StepOutcome::Event(c) => {
                let s = c.state;
                let (stance, swing) = if w.s == 0.0 {
                    (s.q[2], s.q[3])
                } else {
                    (s.q[3], s.q[2])
                };
                // Heel strike only with the swing leg in front and the legs
                // apart; otherwise the swing foot scuffs: ignored.
                if swing < stance + 0.05 {
                    continue;
                }
                record(&w, &s);
                let l = w.a + w.b;
                let foot = (s.q[0] + l * swing.sin(), s.q[1] - l * swing.cos());
                w = CompassGait {
                    s: 1.0 - w.s,
                    px: foot.0,
                    py: foot.1,
                    ..w
                };
                let hit = w.impact(&s.q, &s.qd, s.t, [false], [0.0])?;
                let after = State::new(s.t, s.q, hit.qd);
                record(&w, &after);
                stepper.set_state(after)?;
                done += 1;
            }
            StepOutcome::Step => record(&w, stepper.state()),
            StepOutcome::Finished => return Err("the walker stopped".into()),
        }
    }
    Ok((w, *stepper.state()))
}

/// The stride map on `(δ, ω_stance, ω_swing)` just after a strike.
fn stride(w: &Walker, p: &Vector3<f64>) -> Result<Vector3<f64>, Box<dyn std::error::Error>> {
    let (walker, state) = start(w, p);
    let (after, s) = walk(walker, state, 1, |_, _| {})?;
    let (stance, swing) = if after.s == 0.0 { (2, 3) } else { (3, 2) };
    Ok(Vector3::new(
        s.q[stance] + w.gamma,
        s.qd[stance],
        s.qd[swing],
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(0.0);
    // mh, m, a, b, g, gamma (3°), s, px, py
    let w = CompassGait::new(10.0, 5.0, 0.5, 0.5, 9.81, 3f64.to_radians(), 0.0, 0.0, 0.0);
    // Newton on P(p) − p = 0, the Jacobian by central differences, from
    // Goswami et al.'s rounded gait.
    let mut p = Vector3::new(0.27, -1.09, -0.38);
    let mut residual = f64::INFINITY;
    let mut jacobian = Matrix3::zeros();
    for _ in 0..10 {
        let r = stride(&w, &p)? - p;
        residual = r.amax();
        if residual < 1e-10 {
            break;
        }
        let h = 1e-6;
        let mut jac = Matrix3::zeros();
        for j in 0..3 {
            let mut dp = Vector3::zeros();
            dp[j] = h;
            let column = (stride(&w, &(p + dp))? - stride(&w, &(p - dp))?) / (2.0 * h) - dp / h;
            jac.set_column(j, &column);
        }
        p -= jac.lu().solve(&r).ok_or("singular stride Jacobian")?;
        jacobian = jac + Matrix3::identity();
    }
    println!("Compass gait on a 3° slope (Dormand–Prince, events, impact map):");
    println!(
        "  period-one gait after a strike: half-angle {:.9} rad, stance {:+.9} rad/s, swing {:+.9} rad/s (|P(p) − p| = {residual:.1e})",
        p[0], p[1], p[2]
    );
    let eigen = jacobian.complex_eigenvalues().map(|z| z.norm());
    println!(
        "  |eigenvalues| of the stride map there: {:.3} {:.3} {:.3}",
        eigen[0], eigen[1], eigen[2]
    );
    // A walk from 5 % off the gait: the phase portrait of leg 1.
    let (walker, state) = start(&w, &(p * 1.05));
    let mut portrait = Vec::new();
    walk(walker, state, 30, |_, s| portrait.push((s.q[2], s.qd[2])))?;
    // The same walk stride by stride: the distance to the gait after each.
    let (mut k, mut distance) = (p * 1.05, Vec::new());
    for n in 1..=30 {
        k = stride(&w, &k)?;
        distance.push((n as f64, (k - p).amax().max(1e-16)));
    }
    println!(
        "  from 5 % off: distance to the gait after 1, 10, 30 strides: {:.1e}, {:.1e}, {:.1e}",
        distance[0].1, distance[9].1, distance[29].1
    );
    let out = options.plot_path("compass_gait");
    plot(
        &out,
        "Compass-gait walker on a 3° slope: convergence to its limit cycle",
        &[
            Panel::new(
                "phase portrait of leg 1 (stance and swing in turn; jumps: heel strikes)",
                "θ₁ [rad]",
                "θ̇₁ [rad/s]",
                vec![Series::new("from 5 % off the gait", portrait)],
            ),
            Panel::new(
                "distance to the period-one gait after each strike",
                "stride",
                "max |p − p*|",
                vec![Series::new("(δ, ω_stance, ω_swing)", distance)],
            )
            .log(),
        ],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
