//! Event location in the integrators (`constrained::integrate::events`) and
//! the single-step API, against closed forms: a ball bouncing with
//! restitution `e` (the bounce times are a geometric series), crossings
//! twice inside one step, `e = 0` coming to rest, Zeno, and errors.

use constrained::integrate::{Action, Direction, Event, Events, StepOutcome};
use constrained::nalgebra::Vector1;
use constrained::{
    constrained_system, BogackiShampine32, DormandPrince45, IntegrationError, Rk4,
    SemiImplicitEuler, State,
};

constrained_system! {
    /// A ball of unit mass over the ground `y = 0`, under gravity `g` and a
    /// support force `n` (zero in flight).
    pub struct Ball {
        coordinates: [y],
        parameters: [g],
        inputs: [n],
        mass: diag[1.0],
        forces: [n - g],
    }
}

const G: f64 = 9.81;
const H0: f64 = 1.0;

/// The height, falling through zero: an impact.
fn ground<T: constrained::nalgebra::RealField + Copy>(
) -> Events<T, impl Fn(&State<T, 1>) -> [T; 1], 1> {
    Events::new(
        |s: &State<T, 1>| [s.q.x],
        [Event::record(Direction::Falling)],
    )
}

/// The closed-form impact times of a ball dropped from rest at `H0`: the
/// first after `t₁ = √(2H₀/g)`, each flight after it `e` times the last,
/// `tₖ₊₁ = tₖ + 2 eᵏ t₁`.
fn bounce_times(e: f64, count: usize) -> Vec<f64> {
    let t1 = (2.0 * H0 / G).sqrt();
    let mut times = vec![t1];
    for k in 1..count {
        times.push(times[k - 1] + 2.0 * e.powi(k as i32) * t1);
    }
    times
}

fn drop_state() -> State<f64, 1> {
    State::new(0.0, Vector1::new(H0), Vector1::new(0.0))
}

/// Bounces by the event's state change `v → −e v` through `advance_events`.
fn bounces(
    e: f64,
    count: usize,
    advance: impl Fn(&mut State<f64, 1>, f64, &mut dyn FnMut(f64, &mut State<f64, 1>)),
) -> Vec<f64> {
    let closed = bounce_times(e, count + 1);
    // End between the last bounce wanted and the next.
    let t_end = (closed[count - 1] + closed[count]) / 2.0;
    let mut state = drop_state();
    let mut times = Vec::new();
    advance(&mut state, t_end, &mut |t, s| {
        times.push(t);
        s.qd = -e * s.qd;
    });
    assert_eq!(state.t, t_end);
    times
}

fn assert_times(found: &[f64], e: f64, count: usize, tolerance: f64, method: &str) {
    let closed = bounce_times(e, count);
    assert_eq!(found.len(), count, "{method}: {found:?}");
    let worst = found
        .iter()
        .zip(&closed)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst <= tolerance, "{method}: worst {worst:e}");
}

#[test]
fn ball_bounces_at_the_closed_form_times_for_20_bounces() {
    let system = Ball::new(G, 0.0);
    let events = ground::<f64>();
    for e in [0.8, 0.5] {
        let dp = bounces(e, 20, |state, t_end, bounce| {
            let run = DormandPrince45::new(1e-10, 1e-12)
                .advance_events(&system, state, t_end, &events, |c, s| bounce(c.t, s))
                .unwrap();
            assert_eq!(run.stopped, None);
            assert_eq!(run.event_stats.crossings, 20);
        });
        assert_times(&dp, e, 20, 1e-10, "DormandPrince45");
        let bs = bounces(e, 20, |state, t_end, bounce| {
            BogackiShampine32::new(1e-8, 1e-10)
                .advance_events(&system, state, t_end, &events, |c, s| bounce(c.t, s))
                .unwrap();
        });
        assert_times(&bs, e, 20, 1e-10, "BogackiShampine32");
        // Fixed steps, crossings on the cubic Hermite interpolant: exact
        // for a parabola, as RK4's steps are.
        let rk = bounces(e, 20, |state, t_end, bounce| {
            Rk4::new(0.01)
                .advance_events(&system, state, t_end, &events, |c, s| bounce(c.t, s))
                .unwrap();
        });
        assert_times(&rk, e, 20, 1e-10, "Rk4");
    }
}

#[test]
fn the_bounce_state_is_on_the_ground_and_the_apex_follows() {
    // Between bounces k and k+1 the apex is (eᵏ v₁)²/(2g), v₁ = √(2gH₀).
    let (system, events, e) = (Ball::new(G, 0.0), ground::<f64>(), 0.7);
    let mut stepper = DormandPrince45::new(1e-11, 1e-13)
        .stepper(drop_state(), bounce_times(e, 6)[4] + e.powi(5) * 0.45)
        .unwrap();
    let (mut apex, mut impacts) = (0.0f64, Vec::new());
    loop {
        match stepper.step(&system, &events).unwrap() {
            StepOutcome::Event(c) => {
                assert_eq!(
                    (c.index, c.direction, c.action),
                    (0, Direction::Falling, Action::Continue)
                );
                // Within the tolerance before the crossing, still above.
                assert!(c.state.q.x > 0.0 && c.state.q.x < 1e-12, "{}", c.state.q.x);
                impacts.push((apex, -c.state.qd.x));
                apex = 0.0;
                let mut s = c.state;
                s.qd = -e * s.qd;
                stepper.set_state(s).unwrap();
            }
            StepOutcome::Step => apex = apex.max(stepper.state().q.x),
            StepOutcome::Finished => break,
        }
    }
    let v1 = (2.0 * G * H0).sqrt();
    for (k, &(_, speed)) in impacts.iter().enumerate() {
        let expected = v1 * e.powi(k as i32);
        assert!(
            (speed - expected).abs() < 1e-9,
            "impact {k}: {speed} vs {expected}"
        );
    }
    assert_eq!(impacts.len(), 5);
}

/// A ball thrown up at 1 m/s from the ground crosses `y = c` twice, on the
/// way up and down, 28 ms apart: `t = (v₀ ∓ √(v₀² − 2gc))/g`.
fn twice() -> (State<f64, 1>, f64, [f64; 2]) {
    let (v0, level) = (1.0, 0.05);
    let root = (v0 * v0 - 2.0 * G * level).sqrt();
    let state = State::new(0.0, Vector1::new(0.0), Vector1::new(v0));
    (state, level, [(v0 - root) / G, (v0 + root) / G])
}

#[test]
fn a_function_crossing_twice_within_one_step_is_found_twice() {
    let (start, level, exact) = twice();
    let system = Ball::new(G, 0.0);
    let events = Events::new(
        move |s: &State<f64, 1>| [s.q.x - level],
        [Event::record(Direction::Either)],
    );
    // One RK4 step of 0.12 s, 4.3× the gap: the function is negative at
    // both of its ends, so a check of the ends alone finds nothing; the
    // default grid (4 interior points, 24 ms apart) separates the two.
    let mut stepper = Rk4::new(0.12).stepper(start, 0.12).unwrap();
    let mut found = Vec::new();
    while let StepOutcome::Event(c) = stepper.step(&system, &events).unwrap() {
        found.push((c.t, c.direction));
    }
    assert_eq!(stepper.stats().steps, 1);
    assert_eq!(found.len(), 2, "{found:?}");
    assert_eq!(
        (found[0].1, found[1].1),
        (Direction::Rising, Direction::Falling)
    );
    for ((t, _), exact) in found.iter().zip(exact) {
        assert!((t - exact).abs() < 1e-12, "{t} vs {exact}");
    }
    // …and the grid is what finds them: with the ends alone, none.
    let mut ends_only = Rk4::new(0.12).stepper(start, 0.12).unwrap();
    let outcome = ends_only.step(&system, &events.with_samples(0)).unwrap();
    assert_eq!(outcome, StepOutcome::Finished);
    // Dormand–Prince, on its own steps.
    let mut dp = DormandPrince45::new(1e-6, 1e-6)
        .stepper(start, 0.12)
        .unwrap();
    let mut found = Vec::new();
    loop {
        match dp.step(&system, &events).unwrap() {
            StepOutcome::Event(c) => found.push(c.t),
            StepOutcome::Step => {}
            StepOutcome::Finished => break,
        }
    }
    assert_eq!(found.len(), 2, "{found:?} in {:?}", dp.stats());
    for (t, exact) in found.iter().zip(exact) {
        assert!((t - exact).abs() < 1e-12, "{t} vs {exact}");
    }
}

/// The ball of [`twice`] thrown from 0.12 s earlier (the same parabola),
/// by RK4 steps of 0.06 s (exact on a parabola): the crossings fall in the
/// fourth step, `[0.06, 0.12]`, whose ends are both below the level. The
/// steps before it are uninterrupted, so screening looks at it, sees the
/// curvature of the three step ends it has, and searches its grid; and the
/// untriggered steps before are screened.
#[test]
fn screening_searches_a_step_whose_ends_curve_towards_zero() {
    let (start, level, exact) = twice();
    let system = Ball::new(G, 0.0);
    let back = 0.12;
    let earlier = State::new(
        -back,
        Vector1::new(start.q.x - start.qd.x * back - G * back * back / 2.0),
        Vector1::new(start.qd.x + G * back),
    );
    let events = Events::new(
        move |s: &State<f64, 1>| [s.q.x - level],
        [Event::record(Direction::Either)],
    );
    let run = |events: &Events<f64, _, 1>| {
        let mut state = earlier;
        let mut found = Vec::new();
        let run = Rk4::new(0.06)
            .advance_events(&system, &mut state, 0.12, events, |c, _| found.push(c.t))
            .unwrap();
        (found, run.event_stats)
    };
    let (found, stats) = run(&events);
    assert_eq!(found.len(), 2, "{found:?}");
    for (t, exact) in found.iter().zip(exact) {
        assert!((t - exact).abs() < 1e-12, "{t} vs {exact}");
    }
    // Steps [−0.06, 0] and [0, 0.06] had a previous step: the first of
    // them is far from the level for its curvature and is screened; the
    // second ends 7.7 mm below it, curving up: searched (so is the fourth).
    assert_eq!(stats.screened, 1, "{stats:?}");
    // Without screening every step's grid is searched, with the same answer.
    let (unscreened, all) = run(&events.with_screening(false));
    assert_eq!(unscreened, found);
    assert_eq!(all.screened, 0);
    assert!(all.samples > stats.samples, "{all:?} vs {stats:?}");
}

/// A long untriggered run is almost entirely screened: the cost of event
/// location there is one call of the closure per step.
#[test]
fn an_untriggered_run_skips_the_grid_of_almost_every_step() {
    let system = Ball::new(G, 0.0);
    let far = Events::new(
        |s: &State<f64, 1>| [s.q.x + 100.0],
        [Event::stop(Direction::Falling)],
    );
    let mut state = drop_state();
    let run = DormandPrince45::new(1e-8, 1e-10)
        .advance_events(&system, &mut state, 1.0, &far, |_, _| {})
        .unwrap();
    let steps = run.stats.steps;
    assert!(run.stopped.is_none());
    // The first step has no previous one and is searched; the rest are
    // screened (the height's curvature is g/2, tiny against 100 m).
    assert_eq!(run.event_stats.screened, steps - 1, "{run:?}");
    assert_eq!(run.event_stats.samples, 4);
}

#[test]
fn restarting_at_a_crossing_reports_it_once_or_says_it_did_not_separate() {
    let (start, level, exact) = twice();
    let events = Events::new(
        move |s: &State<f64, 1>| [s.q.x - level],
        [Event::record(Direction::Either)],
    );
    // A controller's switch: the system changes at the crossing, the state
    // does not (set_state with the crossing's own state refreshes the
    // derivative). The crossing is not reported again; the next one is.
    let mut system = Ball::new(G, 0.0);
    let mut stepper = DormandPrince45::new(1e-10, 1e-12)
        .stepper(start, 0.2)
        .unwrap();
    let mut found = Vec::new();
    loop {
        match stepper.step(&system, &events).unwrap() {
            StepOutcome::Event(c) => {
                found.push((c.t, c.direction));
                system.n = 0.0;
                stepper.set_state(c.state).unwrap();
            }
            StepOutcome::Step => {}
            StepOutcome::Finished => break,
        }
    }
    assert_eq!(found.len(), 2, "{found:?}");
    assert!((found[0].0 - exact[0]).abs() < 1e-12 && (found[1].0 - exact[1]).abs() < 1e-12);
    // An impact law that does not turn the ball back (its fall halved, not
    // reversed, at the downward crossing): EventRepeats.
    let mut stepper = DormandPrince45::new(1e-10, 1e-12)
        .stepper(start, 0.2)
        .unwrap();
    let mut result = Ok(StepOutcome::Step);
    for _ in 0..100 {
        result = stepper.step(&system, &events);
        match result {
            Ok(StepOutcome::Event(c)) if c.direction == Direction::Falling => {
                let mut kicked = c.state;
                kicked.qd *= 0.5;
                stepper.set_state(kicked).unwrap();
            }
            Ok(StepOutcome::Finished) | Err(_) => break,
            Ok(_) => {}
        }
    }
    match result {
        Err(IntegrationError::EventRepeats { t, event: 0 }) => {
            assert!((t - exact[1]).abs() < 1e-12, "{t}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn with_zero_restitution_the_ball_comes_to_rest() {
    // At the impact the velocity becomes 0 and the force into the ground
    // (−g) would take it through: the contact persists, so the model
    // switches to it — the support force n = g — and the ball rests.
    let mut system = Ball::new(G, 0.0);
    let events = ground::<f64>();
    let mut stepper = DormandPrince45::new(1e-10, 1e-12)
        .stepper(drop_state(), 10.0)
        .unwrap();
    let mut impacts = 0;
    loop {
        match stepper.step(&system, &events).unwrap() {
            StepOutcome::Event(c) => {
                impacts += 1;
                let mut s = c.state;
                s.qd.x = 0.0;
                if (system.n - system.g) <= 0.0 {
                    system.n = system.g; // the contact's force
                }
                stepper.set_state(s).unwrap();
            }
            StepOutcome::Step => {}
            StepOutcome::Finished => break,
        }
    }
    let s = stepper.state();
    assert_eq!((impacts, s.t), (1, 10.0));
    assert!(s.q.x.abs() < 1e-12 && s.qd.x == 0.0, "{s:?}");
    assert!(stepper.stats().steps < 40, "{:?}", stepper.stats());
}

#[test]
fn without_the_switch_zero_restitution_is_an_error_not_a_hang() {
    // v → 0 alone leaves the ball on the ground with gravity pulling it
    // through: each crossing comes sooner, until one is within the time
    // tolerance of the state just set: EventRepeats, after a few events.
    let system = Ball::new(G, 0.0);
    let events = ground::<f64>();
    let mut state = drop_state();
    let mut impacts = 0;
    let result = DormandPrince45::new(1e-10, 1e-12).advance_events(
        &system,
        &mut state,
        10.0,
        &events,
        |_, s| {
            impacts += 1;
            s.qd.x = 0.0;
        },
    );
    let t1 = (2.0 * H0 / G).sqrt();
    match result {
        Err(IntegrationError::EventRepeats { t, event: 0 }) => {
            // After a few crossings each sooner than the last (3e-8 s, …).
            assert!((t - t1).abs() < 1e-6, "{t}")
        }
        other => panic!("{other:?}"),
    }
    assert!((1..20).contains(&impacts), "{impacts}");
    assert!(state.q.x >= 0.0, "{state:?}");
}

#[test]
fn a_zeno_sequence_of_bounces_ends_in_an_error_at_its_limit() {
    // e = 0.5: the bounces accumulate at t∞ = t₁ (1 + 2e/(1 − e)) = 3 t₁;
    // the run asked past it stops near t∞ with EventRepeats, in a bounded
    // number of steps.
    let system = Ball::new(G, 0.0);
    let events = ground::<f64>();
    let e = 0.5;
    let mut state = drop_state();
    let mut impacts = 0;
    let result = DormandPrince45::new(1e-10, 1e-12).advance_events(
        &system,
        &mut state,
        5.0,
        &events,
        |_, s| {
            impacts += 1;
            s.qd = -e * s.qd;
        },
    );
    let limit = 3.0 * (2.0 * H0 / G).sqrt();
    assert!(
        matches!(result, Err(IntegrationError::EventRepeats { .. })),
        "{result:?}"
    );
    assert!((state.t - limit).abs() < 1e-9, "{} vs {limit}", state.t);
    assert!((30..80).contains(&impacts), "{impacts}");
}

#[test]
fn stop_events_end_the_run_at_the_crossing() {
    let system = Ball::new(G, 0.0);
    let events = Events::new(
        |s: &State<f64, 1>| [s.q.x - 0.5, s.q.x],
        [
            Event::record(Direction::Falling),
            Event::stop(Direction::Falling),
        ],
    );
    let mut state = drop_state();
    let mut seen = Vec::new();
    let run = SemiImplicitEuler::new(1e-3)
        .advance_events(&system, &mut state, 10.0, &events, |c, _| {
            seen.push(c.index)
        })
        .unwrap();
    let stopped = run.stopped.expect("stopped at the ground");
    assert_eq!((stopped.index, seen), (1, vec![0, 1]));
    assert_eq!(state, stopped.state);
    // Semi-implicit Euler is first order: the time to 1e-3.
    assert!(
        (stopped.t - (2.0 * H0 / G).sqrt()).abs() < 2e-3,
        "{}",
        stopped.t
    );
}

#[test]
fn event_errors_are_values() {
    let system = Ball::new(G, 0.0);
    let nan = Events::new(
        |_: &State<f64, 1>| [f64::NAN],
        [Event::record(Direction::Either)],
    );
    let mut state = drop_state();
    let result = Rk4::new(0.01).advance_events(&system, &mut state, 1.0, &nan, |_, _| {});
    assert_eq!(
        result.map(|r| r.stats),
        Err(IntegrationError::EventNotFinite { t: 0.0, event: 0 })
    );
    let bad = ground::<f64>().with_tolerance(-1.0);
    let result = Rk4::new(0.01).advance_events(&system, &mut state, 1.0, &bad, |_, _| {});
    assert_eq!(
        result.map(|r| r.stats),
        Err(IntegrationError::InvalidParameter)
    );
    assert!(Rk4::new(0.0).stepper::<1, 0>(drop_state(), 1.0).is_err());
    assert!(matches!(
        DormandPrince45::new(1e-6, 1e-6).stepper::<1, 0>(drop_state(), -1.0),
        Err(IntegrationError::EndBeforeStart { .. })
    ));
}

#[test]
fn no_events_costs_no_evaluations_and_gives_the_same_steps() {
    use constrained::models::DoublePendulum;
    let system = DoublePendulum::<f64>::new(1.0, 1.5, 1.2, 0.8, 9.81);
    let start = constrained::models::double_pendulum_state(1.2, 0.8, 0.0, [2.0, -1.0], [0.5, 1.5]);
    let dp = DormandPrince45::new(1e-9, 1e-11);
    let mut plain = start;
    let stats = dp.advance(&system, &mut plain, 5.0).unwrap();
    let mut stepped = start;
    let run = dp
        .advance_events(&system, &mut stepped, 5.0, &Events::none(), |_, _| {})
        .unwrap();
    assert_eq!(run.stats, stats);
    assert_eq!(stepped, plain);
}
