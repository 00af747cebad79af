//! Stick–slip (Leine & Nijmeijer's switch model) on the crane: slipping,
//! Coulomb's force `μN` against the motion (its sense fixed for the phase,
//! no `signum` to chatter on); sticking, the velocity-level constraint
//! `ẋc = 0`, whose multiplier is the friction the rail must supply. The
//! switches are events: slipping ends where `ẋc` crosses zero (stick if the
//! friction needed stays within `μN`, else slip the other way); sticking
//! ends where `μN − |λ|` falls through zero. The crane's `signum` friction
//! exhausts an adaptive integrator's step budget once the trolley stops;
//! switched, 80 s of sticking and slipping take about 6,000 steps. The
//! switches are written in the test, on the generated model, the events
//! stepper and the runtime's impact map; the DSL has no friction section.

use constrained::impact::impact_with_gaps;
use constrained::integrate::{Direction, Event, Events, StepOutcome};
use constrained::nalgebra::{SMatrix, Vector3};
use constrained::{constrained_system, DormandPrince45, Stabilization, State};

constrained_system! {
    /// The crane of `constrained::models::Crane` with its friction
    /// switched: `stuck = 1` holds the trolley (`ẋc = 0`, the second
    /// constraint) and removes the sliding friction; `stuck = 0` drops the
    /// constraint's row and applies `μ (mc + ml) g` against `sense`.
    pub struct SwitchedCrane {
        coordinates: [xc, x, y],
        parameters: [mc, ml, l, g, mu, kp, kd, umax, target, stuck, sense],
        mass: diag[mc, ml, ml],
        definitions: [
            drive = clamp(kp * (target - xc) - kd * dot(xc), -umax, umax),
            friction = (1.0 - stuck) * mu * (mc + ml) * g * sense,
        ],
        forces: [drive - friction, 0.0, -ml * g],
        constraints: [
            (x - xc).powi(2) + y.powi(2) == l.powi(2),
            stuck * dot(xc) == 0.0,
        ],
    }
}

type Crane = SwitchedCrane<f64>;

fn crane() -> Crane {
    // mc, ml, l, g, mu, kp, kd, umax, target, stuck, sense
    SwitchedCrane::new(4.0, 1.0, 1.5, 9.81, 0.05, 30.0, 12.0, 8.0, 2.0, 0.0, 1.0)
}

/// The friction the stuck trolley needs: the constraint force on `xc`
/// less the rod's (which pulls the trolley as much as it pulls the load).
fn needed(c: &Crane, s: &State<f64, 3>) -> f64 {
    let stuck = SwitchedCrane { stuck: 1.0, ..*c };
    // An error (none is expected: constant positive masses) becomes NaN,
    // which the event location reports as `EventNotFinite`.
    stuck
        .constraint_force(&s.q, &s.qd, s.t)
        .map_or(f64::NAN, |fc| fc[0] + fc[1])
}

/// The state with the trolley stopped, by the impulsive Gauss principle
/// (the rod kept): the velocity closest to `s.qd` with `ẋc = 0`.
fn stop(c: &Crane, s: &State<f64, 3>) -> State<f64, 3> {
    let stuck = SwitchedCrane { stuck: 1.0, ..*c };
    let (a, _) = stuck.constraint_matrices(&s.q, &s.qd, s.t);
    let r = stuck.constraint_velocity_residual(&s.q, &s.qd, s.t);
    let none = SMatrix::<f64, 0, 3>::zeros();
    let m = stuck.mass_matrix(&s.q, s.t);
    let hit = impact_with_gaps::<f64, 3, 2, 0, 2>(&m, &a, &r, &none, &[], &[], &s.qd).unwrap();
    // ẋc = 0 holds to rounding (1e-19); exactly, so that the next phase's
    // event function starts at zero and its first crossing is a real one.
    let mut qd = hit.qd;
    qd[0] = 0.0;
    State::new(s.t, s.q, qd)
}

/// Runs to `t_end`; returns the switches `(t, xc, stuck)`, the steps and
/// the final state.
fn run(rtol: f64, t_end: f64) -> (Vec<(f64, f64, bool)>, usize, State<f64, 3>) {
    let mut c = crane();
    let normal = c.mu * (c.mc + c.ml) * c.g;
    let start = State::new(0.0, Vector3::new(0.0, 0.0, -c.l), Vector3::zeros());
    let mut stepper = DormandPrince45::new(rtol, rtol * 1e-2)
        .with_stabilization(Stabilization::projection(1e-12))
        .stepper(start, t_end)
        .unwrap();
    let mut switches = Vec::new();
    for _ in 0..1_000_000 {
        let current = c;
        let events = Events::new(
            // Slipping: ẋc through zero; sticking: μN − |λ| through zero.
            // The function of the other phase is held at 1 (no crossing).
            move |s: &State<f64, 3>| {
                if current.stuck == 1.0 {
                    [1.0, normal - needed(&current, s).abs()]
                } else {
                    [s.qd[0], 1.0]
                }
            },
            [
                Event::stop(Direction::Either),
                Event::stop(Direction::Falling),
            ],
        );
        match stepper.step(&c, &events).unwrap() {
            StepOutcome::Event(e) => {
                let s = e.state;
                let stopped = stop(&c, &s);
                let lambda = needed(&c, &stopped);
                let stick = c.stuck == 0.0 && lambda.abs() < normal;
                c = SwitchedCrane {
                    stuck: if stick { 1.0 } else { 0.0 },
                    sense: if stick { c.sense } else { -lambda.signum() },
                    ..c
                };
                // From the stopped state either way: a slip reversing from
                // the crossing's tiny old-side velocity would cross again.
                switches.push((s.t, s.q[0], stick));
                stepper.set_state(stopped).unwrap();
            }
            StepOutcome::Step => {}
            StepOutcome::Finished => break,
        }
    }
    (switches, stepper.stats().steps, *stepper.state())
}

/// Over 80 s the trolley stops at the target's dead band, sticks while the
/// swinging load needs less friction than `μN`, and slips when it needs
/// more (the load's swing is undamped while the trolley sticks, so the
/// sticking is intermittent: 125 switches in 80 s, a stick the last; the
/// swing decays only during slips, and is still above `μN/(ml g)` at
/// 400 s). Every switch is where an integration 100 times tighter puts
/// it, and the run takes a few thousand steps (the `signum` friction of
/// `models::Crane` exhausts a million at t ≈ 4 s).
#[test]
fn the_switched_crane_sticks_and_slips_where_a_tighter_integration_does() {
    let (switches, steps, end) = run(1e-10, 80.0);
    let (reference, _, _) = run(1e-12, 80.0);
    assert!(steps < 10_000, "{steps} steps");
    assert_eq!(end.t, 80.0);
    assert_eq!(switches.len(), reference.len());
    assert!(switches.len() > 10, "{switches:?}");
    for (s, r) in switches.iter().zip(&reference) {
        assert_eq!(s.2, r.2, "{s:?} vs {r:?}");
        assert!((s.0 - r.0).abs() < 1e-7, "time {s:?} vs {r:?}");
        assert!((s.1 - r.1).abs() < 1e-8, "position {s:?} vs {r:?}");
    }
    // Sticks and slips alternate, from the first stop on.
    assert!(switches.windows(2).all(|w| w[0].2 != w[1].2));
    let c = crane();
    let band = c.mu * (c.mc + c.ml) * c.g / c.kp;
    // A stick holds the trolley: a slip starts where the stick began.
    for w in switches.windows(2).filter(|w| w[0].2) {
        assert!((w[1].1 - w[0].1).abs() < 1e-12, "{w:?}");
    }
    // The sticks close in on the target, the last ones inside the dead
    // band of the PD law against friction.
    let sticks: Vec<f64> = switches.iter().filter(|s| s.2).map(|s| s.1).collect();
    assert!(
        sticks
            .iter()
            .rev()
            .take(10)
            .all(|x| (x - c.target).abs() <= band),
        "{sticks:?}"
    );
    let &(_, x_last, stuck) = switches.last().unwrap();
    assert!(stuck && (end.q[0] - x_last).abs() < 1e-12 && end.qd[0].abs() < 1e-15);
}
