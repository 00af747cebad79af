//! Stick–slip written in the DSL (`friction: [coulomb(v, N, μs, μk)]`) and
//! switched by `constrained::integrate::StickSlip` (Leine & Nijmeijer's
//! switch model): slipping, Coulomb's force `μk N` against the motion, its
//! sense fixed for the phase; sticking, the row `v = 0`, whose multiplier
//! is the friction the contact supplies, within `μs N`.
//!
//! A block on a flat floor against closed forms (it stays under `μs m g`,
//! slips with `a = (F − μk m g)/m` over it, stops at `v₁/(μk g)` after the
//! push is removed), and the crane driven to its target, which sticks for
//! good once its load's swing, damped at the rod's pivot, no longer needs
//! more friction than `μs N`.

use constrained::friction::Mode;
use constrained::integrate::{StickSlip, StickSlipOutcome};
use constrained::nalgebra::{Vector1, Vector3};
use constrained::{constrained_system, DormandPrince45, Stabilization, State};

constrained_system! {
    /// A block of mass `m` on a floor, pushed by `push`, with Coulomb
    /// friction (normal force `m g`).
    pub struct Block {
        coordinates: [x],
        parameters: [m, g, mu_s, mu_k],
        inputs: [push],
        mass: diag[m],
        forces: [push],
        friction: [coulomb(dot(x), m * g, mu_s, mu_k)],
    }
}

const M: f64 = 2.0;
const G: f64 = 9.81;
const MU_S: f64 = 0.5;
const MU_K: f64 = 0.3;

/// The block pushed by `push` from `start` to `t_end`: the switches
/// `(t, x, mode)` and the system and state at the end.
fn slide(
    block: Block,
    start: State<f64, 1>,
    t_end: f64,
) -> (Vec<(f64, f64, Mode)>, Block, State<f64, 1>) {
    let stepper = DormandPrince45::new(1e-12, 1e-14)
        .stepper(start, t_end)
        .unwrap();
    let mut run = StickSlip::new(block, stepper).unwrap();
    let mut switches = Vec::new();
    let done = run
        .finish(100_000, |_, outcome| {
            if let StickSlipOutcome::Switch { mode, state, .. } = outcome {
                switches.push((state.t, state.q[0], *mode));
            }
        })
        .unwrap();
    assert!(done);
    (switches, *run.system(), *run.state())
}

fn at_rest() -> State<f64, 1> {
    State::new(0.0, Vector1::new(0.0), Vector1::new(0.0))
}

/// Pushed with 90 % of `μs m g` from rest, the block sticks: no switch, not
/// a bit of motion, and the friction it needs is the push.
#[test]
fn a_block_pushed_below_the_static_limit_stays() {
    let push = 0.9 * MU_S * M * G;
    let block = Block::new(M, G, MU_S, MU_K, push);
    let (switches, system, end) = slide(block, at_rest(), 5.0);
    assert!(switches.is_empty(), "{switches:?}");
    assert_eq!(system.friction_modes(), [Mode::Stick]);
    assert_eq!((end.t, end.q[0], end.qd[0]), (5.0, 0.0, 0.0));
    let lambda =
        constrained::multipliers::Multipliers::constraint_multipliers(&system, &end).unwrap();
    assert!((lambda[0] + push).abs() < 1e-12 * push, "{lambda}");
}

/// Pushed with 1.2 `μs m g`, it slips from the start with
/// `a = (F − μk m g)/m`: `x = a t²/2`, `v = a t`.
#[test]
fn a_block_pushed_above_the_static_limit_slips_with_the_kinetic_force() {
    let push = 1.2 * MU_S * M * G;
    let block = Block::new(M, G, MU_S, MU_K, push);
    let (switches, system, end) = slide(block, at_rest(), 3.0);
    assert!(switches.is_empty(), "{switches:?}");
    assert_eq!(system.friction_modes(), [Mode::SlipPositive]);
    let a = (push - MU_K * M * G) / M;
    assert!((end.q[0] - a * 4.5).abs() < 1e-10 * a * 4.5, "{end:?}");
    assert!((end.qd[0] - a * 3.0).abs() < 1e-10 * a * 3.0, "{end:?}");
}

/// Pushed above the limit for 2 s, then released: it decelerates at
/// `μk g` and stops at `t₁ + v₁/(μk g)`, `x₁ + v₁²/(2 μk g)`, once, and
/// stays stopped (no force left to overcome `μs m g`).
#[test]
fn a_released_block_stops_at_the_closed_form_time_and_stays() {
    let push = 1.5 * MU_S * M * G;
    let (switches, mut block, state) = slide(Block::new(M, G, MU_S, MU_K, push), at_rest(), 2.0);
    assert!(switches.is_empty());
    block.push = 0.0;
    let (switches, system, end) = slide(block, state, 10.0);
    let a = (push - MU_K * M * G) / M;
    let (x1, v1) = (0.5 * a * 2.0 * 2.0, a * 2.0);
    let stop_t = 2.0 + v1 / (MU_K * G);
    let stop_x = x1 + v1 * v1 / (2.0 * MU_K * G);
    assert_eq!(switches.len(), 1, "{switches:?}");
    let (t, x, mode) = switches[0];
    assert_eq!(mode, Mode::Stick);
    assert!(
        (t - stop_t).abs() < 1e-9,
        "stop at {t}, closed form {stop_t}"
    );
    assert!(
        (x - stop_x).abs() < 1e-9,
        "stop at {x}, closed form {stop_x}"
    );
    assert_eq!(system.friction_modes(), [Mode::Stick]);
    assert_eq!(end.t, 10.0);
    assert!(end.qd[0] == 0.0 && (end.q[0] - x).abs() < 1e-15, "{end:?}");
}

#[path = "../examples/support/damped_crane.rs"]
mod damped_crane;
use damped_crane::DampedCrane;

/// The crane of `models::Crane` (`μs = μk = 0.05`) with a fraction `zeta`
/// of critical damping at the pivot (`c = 2 ζ ml √(g/l)`).
fn crane(zeta: f64) -> DampedCrane {
    let (ml, l, g): (f64, f64, f64) = (1.0, 1.5, 9.81);
    let c = 2.0 * zeta * ml * (g / l).sqrt();
    // mc, ml, l, g, mu_s, mu_k, kp, kd, umax, target, c
    DampedCrane::new(4.0, ml, l, g, 0.05, 0.05, 30.0, 12.0, 8.0, 2.0, c)
}

type Switches = Vec<(f64, f64, Mode)>;

/// Runs the crane to `t_end`: the switches `(t, xc, mode)`, the steps, the
/// system and the final state.
fn drive(zeta: f64, rtol: f64, t_end: f64) -> (Switches, usize, DampedCrane, State<f64, 3>) {
    let c = crane(zeta);
    let start = State::new(0.0, Vector3::new(0.0, 0.0, -c.l), Vector3::zeros());
    let stepper = DormandPrince45::new(rtol, rtol * 1e-2)
        .with_stabilization(Stabilization::projection(1e-12))
        .stepper(start, t_end)
        .unwrap();
    let mut run = StickSlip::new(c, stepper).unwrap();
    let mut switches = Vec::new();
    let done = run
        .finish(1_000_000, |_, outcome| {
            if let StickSlipOutcome::Switch { mode, state, .. } = outcome {
                switches.push((state.t, state.q[0], *mode));
            }
        })
        .unwrap();
    assert!(done);
    (
        switches,
        run.stepper().stats().steps,
        *run.system(),
        *run.state(),
    )
}

/// Undamped, the load's swing makes the friction the stuck trolley needs
/// oscillate about the drive's force, and the trolley keeps slipping: it
/// still switches in the last 50 s of 200 (the swing decays only through
/// the slips' friction).
#[test]
fn the_undamped_crane_keeps_switching() {
    let (switches, _, _, end) = drive(0.0, 1e-10, 200.0);
    assert_eq!(end.t, 200.0);
    let late = switches.iter().filter(|s| s.0 > 150.0).count();
    assert!(late >= 2, "{} switches, {late} after 150 s", switches.len());
}

/// With 5 % of critical damping at the pivot the crane sticks for good: its
/// last switch is a stick well before the end (200 s), inside the PD law's dead band `μs N / kp` around the
/// target; the friction the stuck trolley needs is then within `μs N` with
/// a margin. Every switch is where an integration 100 times tighter puts
/// it (time to 1e-6 s, position to 1e-8 m), in a few thousand steps.
#[test]
fn the_damped_crane_settles_where_a_tighter_integration_does() {
    let t_end = 200.0;
    let (switches, steps, system, end) = drive(0.05, 1e-10, t_end);
    let (reference, _, _, _) = drive(0.05, 1e-12, t_end);
    assert!(steps < 20_000, "{steps} steps");
    assert_eq!(end.t, t_end);
    assert_eq!(
        switches.len(),
        reference.len(),
        "{switches:?}\n{reference:?}"
    );
    for (s, r) in switches.iter().zip(&reference) {
        assert_eq!(s.2, r.2, "{s:?} vs {r:?}");
        assert!((s.0 - r.0).abs() < 1e-6, "time {s:?} vs {r:?}");
        assert!((s.1 - r.1).abs() < 1e-8, "position {s:?} vs {r:?}");
    }
    let &(t_stick, x_stick, mode) = switches.last().unwrap();
    assert_eq!(mode, Mode::Stick);
    assert!(t_stick < 100.0, "the last stick at {t_stick} s");
    assert_eq!(system.friction_modes(), [Mode::Stick]);
    // Held by the stick row: ẋc at rounding level (the projection's), the
    // trolley where it stuck.
    assert!(
        end.qd[0].abs() < 1e-14 && (end.q[0] - x_stick).abs() < 1e-12,
        "{end:?}"
    );
    let normal = system.mu_s * (system.mc + system.ml) * system.g;
    assert!(
        (x_stick - system.target).abs() <= normal / system.kp,
        "{x_stick}"
    );
    let lambda =
        constrained::multipliers::Multipliers::constraint_multipliers(&system, &end).unwrap();
    assert!(lambda[1].abs() < 0.9 * normal, "{lambda}");
    eprintln!(
        "crane: {} switches, {steps} steps, sticks for good at t = {t_stick:.9} s, xc = {x_stick:.12} m \
         (reference {:.9} s, {:.12} m)",
        switches.len(),
        reference.last().unwrap().0,
        reference.last().unwrap().1
    );
}
