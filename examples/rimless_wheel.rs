//! A rimless wheel rolls down a slope (McGeer 1990, passive dynamic
//! walking): between heel strikes it pivots on one spoke, a pendulum
//! upside down; each strike is located as an event (the next foot's gap
//! `unilateral: [..]` falling through zero) and resolved by the generated
//! impact map, plastic, with the new foot pinned: the impulsive form of
//! Gauss's principle. From a push too fast or too slow it converges to the
//! limit cycle whose rate after a strike is McGeer's closed form
//! `ω² = η² k / (1 − η²)`, `η = (I + m l² cos 2α)/(I + m l²)`,
//! `k = 4 m g l sin α sin γ / (I + m l²)` (spokes `2α` apart, slope `γ`).
//!
//! `cargo run --release --example rimless_wheel`

#[path = "support/rimless_wheel.rs"]
mod rimless_wheel;
#[path = "support/mod.rs"]
mod support;

use constrained::integrate::{Direction, Event, Events, StepOutcome};
use constrained::nalgebra::{Vector2, Vector3};
use constrained::{DormandPrince45, Stabilization, State};
use rimless_wheel::RimlessWheel;
use support::{plot, Options, Panel, Series};

/// The foot of the spoke at `th + phase`.
fn foot(w: &RimlessWheel<f64>, q: &Vector3<f64>, phase: f64) -> Vector2<f64> {
    Vector2::new(
        q[0] + w.l * (q[2] + phase).sin(),
        q[1] - w.l * (q[2] + phase).cos(),
    )
}

/// A run's phase portrait and its rates after each strike.
type Run = (Vec<(f64, f64)>, Vec<f64>);

/// One run from just after a strike at rate `omega`: the phase portrait
/// (stance spoke's angle from the slope's normal, rate) and the rate after
/// each strike.
fn roll(
    w: RimlessWheel<f64>,
    omega: f64,
    strikes: usize,
) -> Result<Run, Box<dyn std::error::Error>> {
    // Both feet on the slope (the spokes' bisector along its normal), the
    // stance foot at the origin, rotating about it.
    let stance = -w.gamma + w.a2 / 2.0;
    let q = Vector3::new(-w.l * stance.sin(), w.l * stance.cos(), stance - w.phase);
    let qd = Vector3::new(-omega * q[1], omega * q[0], omega);
    let mut wheel = w;
    let (mut portrait, mut rates) = (Vec::new(), Vec::new());
    let mut stepper = DormandPrince45::new(1e-12, 1e-13)
        .with_stabilization(Stabilization::projection(1e-13))
        .stepper(State::new(0.0, q, qd), 1e4)?;
    let angle = |w: &RimlessWheel<f64>, s: &State<f64, 3>| s.q[2] + w.phase + w.gamma;
    while rates.len() < strikes {
        let current = wheel;
        let events = Events::new(
            move |s: &State<f64, 3>| [current.gaps(&s.q, s.t)[0]],
            [Event::stop(Direction::Falling)],
        );
        match stepper.step(&wheel, &events)? {
            StepOutcome::Event(c) => {
                let s = c.state;
                portrait.push((angle(&wheel, &s), s.qd[2]));
                let next = wheel.phase + wheel.a2;
                let f = foot(&wheel, &s.q, next);
                wheel = RimlessWheel {
                    phase: next,
                    px: f[0],
                    py: f[1],
                    ..wheel
                };
                let hit = wheel.impact(&s.q, &s.qd, s.t, [false], [0.0])?;
                rates.push(hit.qd[2]);
                let after = State::new(s.t, s.q, hit.qd);
                portrait.push((angle(&wheel, &after), after.qd[2]));
                stepper.set_state(after)?;
            }
            StepOutcome::Step => {
                let s = stepper.state();
                portrait.push((angle(&wheel, s), s.qd[2]));
            }
            StepOutcome::Finished => break,
        }
    }
    Ok((portrait, rates))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(0.0);
    // m, inertia, l, g, a2 (8 spokes), gamma, phase, px, py
    let w = RimlessWheel::new(
        1.0,
        0.05,
        1.0,
        9.81,
        std::f64::consts::FRAC_PI_4,
        0.1,
        0.0,
        0.0,
        0.0,
    );
    let j = w.inertia + w.m * w.l * w.l;
    let eta = (w.inertia + w.m * w.l * w.l * w.a2.cos()) / j;
    let k = 4.0 * w.m * w.g * w.l * (w.a2 / 2.0).sin() * w.gamma.sin() / j;
    let steady = -(eta * eta * k / (1.0 - eta * eta)).sqrt();
    println!(
        "Rimless wheel, 8 spokes, slope {} rad (Dormand–Prince, events, impact map):",
        w.gamma
    );
    println!("  McGeer's steady rate after a strike: {steady:.12} rad/s (η = {eta:.6})");
    let mut panels = Vec::new();
    let mut portraits = Vec::new();
    let mut errors = Vec::new();
    for (label, start) in [("fast push", 2.0 * steady), ("slow push", 0.8 * steady)] {
        let (portrait, rates) = roll(w, start, 40)?;
        let last = rates.last().copied().unwrap_or(f64::NAN);
        println!(
            "  {label}: {} strikes, last rate {last:.12} (relative error {:.1e})",
            rates.len(),
            ((last - steady) / steady).abs()
        );
        portraits.push(Series::new(label, portrait));
        let error = rates
            .iter()
            .enumerate()
            .map(|(i, r)| ((i + 1) as f64, ((r - steady) / steady).abs().max(1e-16)))
            .collect();
        errors.push(Series::new(label, error));
    }
    panels.push(Panel::new(
        "phase portrait: stance spoke angle from the slope normal vs rate (jumps: heel strikes)",
        "angle [rad]",
        "rate [rad/s]",
        portraits,
    ));
    panels.push(
        Panel::new(
            "rate after each strike vs McGeer's closed form",
            "strike",
            "relative error",
            errors,
        )
        .log(),
    );
    let out = options.plot_path("rimless_wheel");
    plot(
        &out,
        "Rimless wheel on a slope: convergence to McGeer's limit cycle",
        &panels,
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}
