//! The cost of event location (`constrained::integrate::events`): whole
//! runs with two event functions that never trigger against the same runs
//! without events — the double pendulum (Dormand–Prince 4(5) and RK4; the
//! cheapest evaluations, ≈ 60 ns) and the 32-link chain (RK4) — and
//! the evaluations per located crossing of a bouncing ball (written to
//! `<target>/benchmarks/events.json` for the report when
//! `CONSTRAINED_TARGET_DIR` is set).

use constrained::integrate::{Direction, Event, Events};
use constrained::models::{double_pendulum_state, DoublePendulum};
use constrained::nalgebra::Vector1;
use constrained::{constrained_system, DormandPrince45, Rk4, State};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

constrained_system! {
    /// A ball of unit mass under gravity `g`.
    struct Ball {
        coordinates: [y],
        parameters: [g],
        mass: diag[1.0],
        forces: [-g],
    }
}

/// Two functions of the state that stay negative over the run: the lower
/// bob 10 m above the pivot, the upper one 10 m to its left.
fn never() -> Events<f64, impl Fn(&State<f64, 4>) -> [f64; 2], 2> {
    Events::new(
        |s: &State<f64, 4>| [s.q[3] - 10.0, -10.0 - s.q[0]],
        [
            Event::record(Direction::Either),
            Event::stop(Direction::Rising),
        ],
    )
}

/// Rounds of each comparison, the plain run and the runs with events
/// alternating within a round (the report takes the median of the rounds'
/// ratios: on a loaded machine the load drifts between benchmarks).
const ROUNDS: usize = 3;

fn untriggered(c: &mut Criterion) {
    let system = DoublePendulum::<f64>::new(1.0, 1.5, 1.2, 0.8, 9.81);
    let start = double_pendulum_state(1.2, 0.8, 0.0, [2.0, -1.0], [0.5, 1.5]);
    let events = never();
    let unscreened = never().with_screening(false);
    let dp = DormandPrince45::new(1e-8, 1e-10);
    let rk4 = Rk4::new(1e-3);
    // A system whose steps cost more (RK4 step ≈ 2.7 µs): the same fixed
    // cost per step is a smaller part of it.
    let chain = constrained_chains::Chain32::new(9.81);
    let (q, qd) = constrained_chains::benchmark_state::<64>();
    let chain_start = State::new(0.0, q, qd);
    let far = Events::new(
        |s: &State<f64, 64>| [s.q[63] - 100.0, -100.0 - s.q[0]],
        [
            Event::record(Direction::Either),
            Event::stop(Direction::Rising),
        ],
    );
    let far_unscreened = far.with_screening(false);
    let mut group = c.benchmark_group("events");
    for round in 1..=ROUNDS {
        group.bench_function(format!("dp45_double_pendulum_5s/plain/{round}"), |b| {
            b.iter(|| {
                let mut s = black_box(start);
                dp.advance(&system, &mut s, 5.0).map(|_| s)
            })
        });
        group.bench_function(
            format!("dp45_double_pendulum_5s/untriggered/{round}"),
            |b| {
                b.iter(|| {
                    let mut s = black_box(start);
                    dp.advance_events(&system, &mut s, 5.0, &events, |_, _| {})
                        .map(|run| (s, run.stopped.is_none()))
                })
            },
        );
        group.bench_function(
            format!("dp45_double_pendulum_5s/untriggered_unscreened/{round}"),
            |b| {
                b.iter(|| {
                    let mut s = black_box(start);
                    dp.advance_events(&system, &mut s, 5.0, &unscreened, |_, _| {})
                        .map(|run| (s, run.stopped.is_none()))
                })
            },
        );
        group.bench_function(format!("rk4_double_pendulum_1s/plain/{round}"), |b| {
            b.iter(|| {
                let mut s = black_box(start);
                rk4.advance(&system, &mut s, 1.0).map(|_| s)
            })
        });
        group.bench_function(format!("rk4_double_pendulum_1s/untriggered/{round}"), |b| {
            b.iter(|| {
                let mut s = black_box(start);
                rk4.advance_events(&system, &mut s, 1.0, &events, |_, _| {})
                    .map(|run| (s, run.stopped.is_none()))
            })
        });
        group.bench_function(
            format!("rk4_double_pendulum_1s/untriggered_unscreened/{round}"),
            |b| {
                b.iter(|| {
                    let mut s = black_box(start);
                    rk4.advance_events(&system, &mut s, 1.0, &unscreened, |_, _| {})
                        .map(|run| (s, run.stopped.is_none()))
                })
            },
        );
        group.bench_function(format!("rk4_chain32_0.1s/plain/{round}"), |b| {
            b.iter(|| {
                let mut s = black_box(chain_start);
                rk4.advance(&chain, &mut s, 0.1).map(|_| s)
            })
        });
        group.bench_function(format!("rk4_chain32_0.1s/untriggered/{round}"), |b| {
            b.iter(|| {
                let mut s = black_box(chain_start);
                rk4.advance_events(&chain, &mut s, 0.1, &far, |_, _| {})
                    .map(|run| (s, run.stopped.is_none()))
            })
        });
        group.bench_function(
            format!("rk4_chain32_0.1s/untriggered_unscreened/{round}"),
            |b| {
                b.iter(|| {
                    let mut s = black_box(chain_start);
                    rk4.advance_events(&chain, &mut s, 0.1, &far_unscreened, |_, _| {})
                        .map(|run| (s, run.stopped.is_none()))
                })
            },
        );
    }
    group.finish();
    write_counts(&system, &start);
}

/// Evaluations per crossing (20 bounces of a ball, e = 0.8, DP45) and per
/// step (the untriggered run), as JSON for `benches/report.py`.
fn write_counts(system: &DoublePendulum<f64>, start: &State<f64, 4>) {
    let Ok(target) = std::env::var("CONSTRAINED_TARGET_DIR") else {
        return;
    };
    let ball = Ball::new(9.81);
    let ground = Events::new(
        |s: &State<f64, 1>| [s.q.x],
        [Event::record(Direction::Falling)],
    );
    let mut state = State::new(0.0, Vector1::new(1.0), Vector1::new(0.0));
    // Just past the 20th bounce (t₂₀ ≈ 8.885 t₁, the 21st ≈ 8.94 t₁).
    let t_end = 8.9 * (2.0f64 / 9.81).sqrt();
    let bounces = DormandPrince45::new(1e-10, 1e-12)
        .advance_events(&ball, &mut state, t_end, &ground, |_, s| s.qd = -0.8 * s.qd)
        .expect("the ball bounces");
    let mut s = *start;
    let quiet = DormandPrince45::new(1e-8, 1e-10)
        .advance_events(system, &mut s, 5.0, &never(), |_, _| {})
        .expect("integrates");
    let json = format!(
        "{{\"bounces\": {{\"crossings\": {}, \"refinements\": {}, \"samples\": {}, \"steps\": {}, \"evaluations\": {}}}, \
         \"untriggered\": {{\"samples\": {}, \"screened\": {}, \"steps\": {}, \"evaluations\": {}}}}}",
        bounces.event_stats.crossings,
        bounces.event_stats.refinements,
        bounces.event_stats.samples,
        bounces.stats.steps,
        bounces.stats.evaluations,
        quiet.event_stats.samples,
        quiet.event_stats.screened,
        quiet.stats.steps,
        quiet.stats.evaluations,
    );
    let dir = std::path::Path::new(&target).join("benchmarks");
    let written =
        std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(dir.join("events.json"), json));
    if let Err(error) = written {
        eprintln!("events.json not written: {error}");
    }
}

criterion_group!(benches, untriggered);
criterion_main!(benches);
