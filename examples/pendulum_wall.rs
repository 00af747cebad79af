//! A pendulum released from the horizontal hits a wall at `x = wall` and
//! bounces back with restitution `e`: the wall is a gap
//! (`unilateral: [x <= wall]`), the rod a constraint, each hit an event
//! resolved by the generated impact map (the impulsive form of Gauss's
//! principle), which leaves the rod's length rate at zero and reverses the
//! angular velocity exactly: `ω⁺ = −e ω⁻`.
//!
//! `cargo run --release --example pendulum_wall [-- --duration 6]`

#[path = "support/mod.rs"]
mod support;

use constrained::integrate::{Direction, Event, Events, StepOutcome};
use constrained::nalgebra::Vector2;
use constrained::{DormandPrince45, Stabilization, State};
use support::{plot, Options, Panel, Series};

#[path = "support/wall_pendulum.rs"]
mod wall_pendulum;
use wall_pendulum::WallPendulum;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(6.0);
    let (e, l) = (0.7, 1.0);
    let p = WallPendulum::new(1.0, l, 9.81, 0.4 * l);
    // From the horizontal on the far side, at rest.
    let start = State::new(0.0, Vector2::new(-l, 0.0), Vector2::zeros());
    let events = Events::new(
        |s: &State<f64, 2>| [p.gaps(&s.q, s.t)[0]],
        [Event::stop(Direction::Falling)],
    );
    let mut stepper = DormandPrince45::new(1e-11, 1e-12)
        .with_stabilization(Stabilization::projection(1e-12))
        .stepper(start, options.duration)?;
    let omega = |s: &State<f64, 2>| (s.q[0] * s.qd[1] - s.q[1] * s.qd[0]) / (l * l);
    let angle = |s: &State<f64, 2>| s.q[0].atan2(-s.q[1]);
    let (mut portrait, mut hits) = (Vec::new(), Vec::new());
    portrait.push((angle(&start), omega(&start)));
    loop {
        match stepper.step(&p, &events)? {
            StepOutcome::Event(c) => {
                let s = c.state;
                let hit = p.impact(&s.q, &s.qd, s.t, [true], [e])?;
                let after = State::new(s.t, s.q, hit.qd);
                hits.push((s.t, omega(&s), omega(&after)));
                portrait.push((angle(&s), omega(&s)));
                portrait.push((angle(&after), omega(&after)));
                stepper.set_state(after)?;
            }
            StepOutcome::Step => {
                let s = stepper.state();
                portrait.push((angle(s), omega(s)));
            }
            StepOutcome::Finished => break,
        }
    }
    println!("Pendulum on a wall, e = {e} (Dormand–Prince, events, impact map):");
    for (t, before, after) in &hits {
        println!(
            "  hit at t = {t:.9} s: ω⁻ = {before:+.9}, ω⁺ = {after:+.9}, ω⁺/ω⁻ + e = {:.1e}",
            after / before + e
        );
    }
    let out = options.plot_path("pendulum_wall");
    plot(
        &out,
        "Pendulum on a wall: restitution by the impulsive Gauss principle",
        &[Panel::new(
            "phase portrait (vertical jumps: ω⁺ = −e ω⁻ at the wall)",
            "angle from the downward vertical [rad]",
            "ω [rad/s]",
            vec![Series::new("θ, ω", portrait)],
        )],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
