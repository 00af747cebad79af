//! Event location where it used to hang or tunnel, against closed forms:
//! functions crossing zero at the same instant (identical, proportional,
//! opposite, 1e-15 s apart, and a bar landing flat on both ends), states
//! exactly on the surface (a ball started on the ground, a ball put back
//! on the ground by its handler after each impact), and pairs of crossings
//! closer than the search grid, found through the functions' known rates.

use constrained::integrate::{Direction, Event, Events, StepOutcome};
use constrained::nalgebra::{Vector1, Vector3};
use constrained::{constrained_system, DormandPrince45, IntegrationError, Rk4, State};

// A unit mass on a line under gravity `g`, held by a support force `n`
// when resting.
use crate::events::Ball;

constrained_system! {
    /// A uniform bar of mass `m` and length `l` in the vertical plane
    /// (centre `x`, `y`, angle `th`), its two ends over the ground; a
    /// support force `n` at its centre when it rests.
    struct Bar {
        coordinates: [x, y, th],
        parameters: [m, l, g],
        inputs: [n],
        mass: diag[m, m, m * l * l / 12.0],
        forces: [0.0, n - m * g, 0.0],
        unilateral: [y - l / 2.0 * th.sin() >= 0.0, y + l / 2.0 * th.sin() >= 0.0],
    }
}

const G: f64 = 9.81;

/// A free particle (`g = 0`) moving up at 1 from `y = 0`, with two event
/// functions of `y` that both cross at `y = 0.5`, run by the driver with
/// `handler`; returns the crossings reported (index, time).
fn crossings_of<F>(functions: F, handler: impl Fn(&mut State<f64, 1>)) -> Vec<(usize, f64)>
where
    F: Fn(f64) -> [f64; 2],
{
    let system = Ball::new(0.0, 0.0);
    let events = Events::new(
        move |s: &State<f64, 1>| functions(s.q.x),
        [Event::record(Direction::Either); 2],
    );
    let mut state = State::new(0.0, Vector1::new(0.0), Vector1::new(1.0));
    let mut found = Vec::new();
    Rk4::new(1.0)
        .advance_events(&system, &mut state, 2.0, &events, |c, s| {
            found.push((c.index, c.t));
            handler(s);
        })
        .expect("returns");
    assert_eq!(state.t, 2.0);
    found
}

/// Two event functions of the height.
type Pair = fn(f64) -> [f64; 2];

#[test]
fn functions_crossing_together_are_each_reported_once_in_index_order() {
    let cases: [(&str, Pair); 4] = [
        ("identical", |y| [y - 0.5, y - 0.5]),
        ("proportional", |y| [y - 0.5, 2.0 * (y - 0.5)]),
        ("opposite", |y| [y - 0.5, 0.5 - y]),
        ("1e-15 apart", |y| [y - 0.5, y - (0.5 + 1e-15)]),
    ];
    for (name, functions) in cases {
        let found = crossings_of(functions, |_| {});
        assert_eq!(found.len(), 2, "{name}: {found:?}");
        assert_eq!((found[0].0, found[1].0), (0, 1), "{name}: {found:?}");
        for (_, t) in &found {
            assert!((t - 0.5).abs() < 1e-14, "{name}: {found:?}");
        }
        // A handler that turns the particle back at the first: the second
        // function no longer crosses from the new state, and is not
        // reported; the particle comes back through neither.
        let bounced = crossings_of(functions, |s| s.qd = -s.qd);
        assert_eq!(bounced.len(), 1, "{name}: {bounced:?}");
        assert_eq!(bounced[0].0, 0);
    }
}

#[test]
fn the_stepper_says_which_functions_cross_together() {
    let system = Ball::new(0.0, 0.0);
    let events = Events::new(
        |s: &State<f64, 1>| [s.q.x - 0.5, s.q.x - 0.25, 0.5 - s.q.x],
        [Event::record(Direction::Either); 3],
    );
    let start = State::new(0.0, Vector1::new(0.0), Vector1::new(1.0));
    let mut stepper = Rk4::new(1.0).stepper(start, 1.0).unwrap();
    let mut found = Vec::new();
    while let StepOutcome::Event(c) = stepper.step(&system, &events).unwrap() {
        found.push((c.index, stepper.simultaneous()));
    }
    assert_eq!(
        found,
        [
            (1, [false, true, false]),
            (0, [true, false, true]),
            (2, [true, false, true]),
        ]
    );
    assert_eq!(stepper.simultaneous(), [false; 3]);
}

/// The closed-form landing times of a body dropped from rest at `h`
/// rebounding with restitution `e`: `t₁ = √(2h/g)`, each flight `e` times
/// the last, `tₖ₊₁ = tₖ + 2 eᵏ t₁`.
fn bounce_times(h: f64, e: f64, count: usize) -> Vec<f64> {
    let t1 = (2.0 * h / G).sqrt();
    let mut times = vec![t1];
    for k in 1..count {
        times.push(times[k - 1] + 2.0 * e.powi(k as i32) * t1);
    }
    times
}

#[test]
fn a_bar_dropped_flat_lands_on_both_ends_at_once_and_comes_to_rest() {
    let (m, l, e) = (2.0, 1.0, 0.5);
    let mut bar = Bar::new(m, l, G, 0.0);
    let gaps = Events::new(
        move |s: &State<f64, 3>| {
            let g = Bar::new(m, l, G, 0.0).gaps(&s.q, s.t);
            [g[0], g[1]]
        },
        [Event::record(Direction::Falling); 2],
    )
    .with_rates(move |s: &State<f64, 3>| {
        let r = Bar::new(m, l, G, 0.0).gap_rates(&s.q, &s.qd, s.t);
        [r[0], r[1]]
    });
    let drop = State::new(0.0, Vector3::new(0.0, 1.0, 0.0), Vector3::zeros());
    let mut stepper = DormandPrince45::new(1e-10, 1e-12)
        .stepper(drop, 5.0)
        .unwrap();
    let (mut landings, mut rested) = (Vec::new(), None);
    for _ in 0..10_000 {
        match stepper.step(&bar, &gaps) {
            Ok(StepOutcome::Event(c)) => {
                // Both ends land together: one impact with both active.
                // Both ends land together: one impact with both active.
                // (Close to Zeno's limit, where the bar falls at 1e-9 m/s,
                // its angle's rounding, 1e-23 rad, parts the two landings
                // by more than the time tolerance.)
                let together = stepper.simultaneous();
                if landings.len() < 30 {
                    assert_eq!(together, [true, true], "at {}", c.t);
                }
                landings.push(c.t);
                let hit = bar.impact(&c.state.q, &c.state.qd, c.t, together, [e, e]);
                let mut after = c.state;
                after.qd = hit.expect("an impact").qd;
                stepper.set_state(after).unwrap();
            }
            Ok(StepOutcome::Step) => {}
            Ok(StepOutcome::Finished) => break,
            // The end of the Zeno sequence: the contact persists.
            Err(IntegrationError::EventRepeats { t, .. }) => {
                assert!(rested.is_none());
                rested = Some(t);
                bar.n = m * G;
                let mut rest = *stepper.state();
                rest.qd = Vector3::zeros();
                stepper.set_state(rest).unwrap();
            }
            Err(other) => panic!("{other:?}"),
        }
    }
    let closed = bounce_times(1.0, e, landings.len());
    for (k, (t, exact)) in landings.iter().zip(&closed).enumerate().take(30) {
        assert!((t - exact).abs() < 1e-9, "landing {k}: {t} vs {exact}");
    }
    // Zeno's limit, t₁ (1 + 2e/(1 − e)), reached in tens of landings.
    let limit = (2.0 / G).sqrt() * (1.0 + 2.0 * e / (1.0 - e));
    assert!(landings.len() > 20, "{}", landings.len());
    let rested = rested.expect("the contact persists");
    assert!((rested - limit).abs() < 1e-6, "{rested} vs {limit}");
    let end = stepper.state();
    assert_eq!(end.t, 5.0);
    assert!(end.q.y.abs() < 1e-9 && end.q.z.abs() < 1e-15, "{end:?}");
    assert_eq!(end.qd, Vector3::zeros());
}

/// Bounces of a ball started on the ground moving up at `v0`, by RK4 steps
/// of 0.5 s (each flight a small part of the grid's first interval), with
/// `handler` applying the impact; returns the landing times.
fn bounces_from_the_ground(count: usize, handler: impl Fn(&mut State<f64, 1>)) -> Vec<f64> {
    let system = Ball::new(G, 0.0);
    let ground = Events::new(
        |s: &State<f64, 1>| [s.q.x],
        [Event::record(Direction::Falling)],
    );
    let mut state = State::new(0.0, Vector1::new(0.0), Vector1::new(0.1));
    let mut landings = Vec::new();
    let mut stepper = Rk4::new(0.5).stepper(state, 1.0).unwrap();
    while landings.len() < count {
        match stepper.step(&system, &ground).unwrap() {
            StepOutcome::Event(c) => {
                landings.push(c.t);
                state = c.state;
                handler(&mut state);
                stepper.set_state(state).unwrap();
            }
            StepOutcome::Step => assert!(stepper.state().q.x >= 0.0, "tunnelled"),
            StepOutcome::Finished => break,
        }
    }
    landings
}

#[test]
fn a_ball_on_the_ground_finds_its_next_landing() {
    let (v0, e): (f64, f64) = (0.1, 0.9);
    // Flight k lasts 2 eᵏ v₀ / g.
    let mut closed = vec![2.0 * v0 / G];
    for k in 1..20 {
        closed.push(closed[k - 1] + 2.0 * e.powi(k as i32) * v0 / G);
    }
    let rebound = |s: &mut State<f64, 1>| s.qd = -e * s.qd;
    let snapped = |s: &mut State<f64, 1>| {
        s.qd = -e * s.qd;
        s.q.x = 0.0; // the user's clean-up: exactly on the ground
    };
    for (name, landings) in [
        ("rebound", bounces_from_the_ground(20, rebound)),
        ("snapped", bounces_from_the_ground(20, snapped)),
    ] {
        assert_eq!(landings.len(), 20, "{name}: {landings:?}");
        for (k, (t, exact)) in landings.iter().zip(&closed).enumerate() {
            assert!((t - exact).abs() < 1e-10, "{name} {k}: {t} vs {exact}");
        }
    }
}

#[test]
fn put_back_on_the_ground_without_rebound_is_an_error_not_a_fall() {
    // Restitution 0 and the ball put exactly on the ground: gravity pulls
    // it through at once, so the contact did not open.
    let system = Ball::new(G, 0.0);
    let ground = Events::new(
        |s: &State<f64, 1>| [s.q.x],
        [Event::record(Direction::Falling)],
    );
    let mut state = State::new(0.0, Vector1::new(0.0), Vector1::new(0.1));
    let run = Rk4::new(0.5).advance_events(&system, &mut state, 8.0, &ground, |_, s| {
        s.qd.x = 0.0;
        s.q.x = 0.0;
    });
    match run {
        Err(IntegrationError::EventRepeats { t, event: 0 }) => {
            assert!((t - 0.2 / G).abs() < 1e-12, "{t}")
        }
        other => panic!("{other:?}"),
    }
    assert!(state.q.x >= 0.0);
}

/// A ball thrown up at `v₀ = 0.3 g` reaches its apex at 0.3 s; a ceiling
/// `c` just below the apex is touched for `width` seconds, its two
/// crossings at `0.3 ∓ width/2`: `c = v₀²/2g − g (width/2)²/2`.
fn ceiling(width: f64) -> (State<f64, 1>, f64, [f64; 2]) {
    let v0 = 0.3 * G;
    let c = v0 * v0 / (2.0 * G) - G * (width / 2.0).powi(2) / 2.0;
    let start = State::new(0.0, Vector1::new(0.0), Vector1::new(v0));
    (start, c, [0.3 - width / 2.0, 0.3 + width / 2.0])
}

#[test]
fn known_rates_find_two_crossings_closer_than_the_grid() {
    let system = Ball::new(G, 0.0);
    let (start, c, exact) = ceiling(1e-3);
    // The gap to the ceiling, c − y ≥ 0, and its rate −ẏ (∇g · q̇).
    let gap = Events::new(
        move |s: &State<f64, 1>| [c - s.q.x],
        [Event::record(Direction::Either)],
    );
    // One RK4 step of 1 s (exact on the parabola, as is its cubic
    // extension): both crossings, 1 ms apart, lie between the grid's
    // points 0.2 and 0.4.
    let rated = gap.with_rates(|s: &State<f64, 1>| [-s.qd.x]);
    let mut stepper = Rk4::new(1.0).stepper(start, 1.0).unwrap();
    let mut found = Vec::new();
    while let StepOutcome::Event(c) = stepper.step(&system, &rated).unwrap() {
        found.push((c.t, c.direction));
    }
    assert_eq!(stepper.stats().steps, 1);
    assert_eq!(
        found.iter().map(|f| f.1).collect::<Vec<_>>(),
        [Direction::Falling, Direction::Rising]
    );
    for ((t, _), exact) in found.iter().zip(exact) {
        assert!((t - exact).abs() < 1e-12, "{t} vs {exact}");
    }
    // Without the rates the grid alone sees neither.
    let mut plain = Rk4::new(1.0).stepper(start, 1.0).unwrap();
    assert_eq!(
        plain.step(&system, &gap).unwrap(),
        StepOutcome::Finished,
        "the grid separates them"
    );
}

#[test]
fn known_rates_find_pairs_under_dormand_prince() {
    // Pairs 0.29 s and 1 ms apart at rtol 1e-6, where DP45's steps are long.
    let system = Ball::new(G, 0.0);
    for width in [0.29, 1e-2, 1e-3] {
        let (start, c, exact) = ceiling(width);
        let gap = Events::new(
            move |s: &State<f64, 1>| [c - s.q.x],
            [Event::record(Direction::Either)],
        )
        .with_rates(|s: &State<f64, 1>| [-s.qd.x]);
        let mut state = start;
        let mut found = Vec::new();
        DormandPrince45::new(1e-6, 1e-6)
            .advance_events(&system, &mut state, 1.0, &gap, |c, _| found.push(c.t))
            .unwrap();
        assert_eq!(found.len(), 2, "width {width}: {found:?}");
        for (t, exact) in found.iter().zip(exact) {
            assert!((t - exact).abs() < 1e-9, "width {width}: {t} vs {exact}");
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

    /// Hostile sets of functions crossing together: four multiples `kᵢ (y − aᵢ)`
    /// of two levels, any directions, and a handler that does nothing,
    /// turns the particle back, halves its speed or puts it exactly on the
    /// level it crossed. The driver always returns, within a bounded
    /// number of handler calls: `Ok`, or `EventRepeats` where a state change
    /// left a function crossing again at once; no function is reported
    /// twice in one direction at one instant.
    #[test]
    fn simultaneous_crossings_never_hang(
        levels in proptest::array::uniform4(0usize..2),
        factors in proptest::array::uniform4(-2i32..=2),
        directions in proptest::array::uniform4(0usize..3),
        handler in 0usize..4,
        h in proptest::sample::select(vec![0.05, 0.3, 1.0]),
    ) {
        const LEVELS: [f64; 2] = [0.25, 0.5];
        let factors = factors.map(|k| if k == 0 { 1.0 } else { f64::from(k) });
        let kinds = directions.map(|d| {
            Event::record([Direction::Rising, Direction::Falling, Direction::Either][d])
        });
        let events = Events::new(
            move |s: &State<f64, 1>| {
                core::array::from_fn(|i| factors[i] * (s.q.x - LEVELS[levels[i]]))
            },
            kinds,
        );
        let system = Ball::new(0.0, 0.0);
        let mut state = State::new(0.0, Vector1::new(0.0), Vector1::new(1.0));
        let mut reports: Vec<(usize, f64, Direction)> = Vec::new();
        let run = Rk4::new(h).advance_events(&system, &mut state, 2.0, &events, |c, s| {
            reports.push((c.index, c.t, c.direction));
            match handler {
                1 => s.qd = -s.qd,
                2 => s.qd *= 0.5,
                3 => s.q.x = LEVELS[levels[c.index]],
                _ => {}
            }
        });
        proptest::prop_assert!(
            matches!(run, Ok(_) | Err(IntegrationError::EventRepeats { .. })),
            "{run:?}"
        );
        // Each level is crossed at most a few times over the run.
        proptest::prop_assert!(reports.len() <= 4 * 2 * 4, "{reports:?}");
        for (k, a) in reports.iter().enumerate() {
            let repeated = reports[..k]
                .iter()
                .any(|b| b.0 == a.0 && b.2 == a.2 && (b.1 - a.1).abs() < 1e-14);
            proptest::prop_assert!(!repeated, "{reports:?}");
        }
    }
}
