//! Impacts (`unilateral: [..]` and the generated `impact`) against closed
//! forms: a pendulum on a wall rebounds with exactly `−e` times its angular
//! velocity (in an angle and in Cartesian coordinates with the rod as a
//! constraint), a central collision conserves momentum, and each heel
//! strike of the rimless wheel conserves the angular momentum about the new
//! contact and scales the rate by McGeer's `(I + m l² cos 2α)/(I + m l²)`.

use constrained::nalgebra::{Vector1, Vector2, Vector3};
use constrained::{constrained_system, DynamicsError};

#[path = "../examples/support/rimless_wheel.rs"]
mod rimless_wheel;
pub use rimless_wheel::RimlessWheel;

constrained_system! {
    /// A pendulum in its angle, a wall at horizontal distance `wall`.
    pub struct AnglePendulum {
        coordinates: [th],
        parameters: [m, l, g, wall],
        mass: diag[m * l.powi(2)],
        forces: [-m * g * l * th.sin()],
        unilateral: [l * th.sin() <= wall],
    }
}

// The same pendulum in Cartesian coordinates, the rod a constraint: the
// example's model, written once.
#[path = "../examples/support/wall_pendulum.rs"]
mod wall_pendulum;
use wall_pendulum::WallPendulum as CartesianPendulum;

constrained_system! {
    /// Two bodies on a line, `d` apart at contact.
    pub struct TwoBodies {
        coordinates: [x1, x2],
        parameters: [m1, m2, d],
        mass: diag[m1, m2],
        unilateral: [x2 - x1 >= d],
    }
}

#[test]
fn gaps_and_their_gradients_are_generated() {
    let p = AnglePendulum::<f64>::new(1.0, 0.8, 9.81, 0.3);
    let th = 0.25f64;
    assert!((p.gaps(&Vector1::new(th), 0.0)[0] - (0.3 - 0.8 * th.sin())).abs() < 1e-16);
    assert!((p.gap_jacobian(&Vector1::new(th), 0.0)[(0, 0)] + 0.8 * th.cos()).abs() < 1e-16);
    assert_eq!(AnglePendulum::<f64>::GAPS, 1);
    // The symbolic export: the gap and its gradient's row in sympy syntax
    // (the text itself is pinned by the codegen snapshots).
    let symbolic = AnglePendulum::<f64>::SYMBOLIC_GAPS;
    assert_eq!((symbolic.gaps.len(), symbolic.gap_jacobian.len()), (1, 1));
    assert!(symbolic.gaps[0].contains("sin(th)"), "{symbolic:?}");
    assert_eq!(symbolic.gap_jacobian[0], &["-l*cos(th)"]);
    let wheel_gaps = RimlessWheel::<f64>::SYMBOLIC_GAPS;
    assert_eq!(wheel_gaps.gap_jacobian[0].len(), 3);
    let two = TwoBodies::<f64>::new(1.0, 2.0, 0.5);
    let q = Vector2::new(1.0, 2.0);
    assert_eq!(two.gaps(&q, 0.0), Vector1::new(0.5));
    // The wheel's gradient against central differences.
    let w = wheel(0.3);
    let q = Vector3::new(0.2, 0.9, -0.1);
    let jac = w.gap_jacobian(&q, 0.0);
    let h = 1e-6;
    for j in 0..3 {
        let mut dq = Vector3::zeros();
        dq[j] = h;
        let fd = (w.gaps(&(q + dq), 0.0)[0] - w.gaps(&(q - dq), 0.0)[0]) / (2.0 * h);
        assert!(
            (fd - jac[(0, j)]).abs() < 1e-9,
            "{j}: {fd} vs {}",
            jac[(0, j)]
        );
    }
}

#[test]
fn a_pendulum_on_a_wall_rebounds_with_minus_e_times_its_angular_velocity() {
    let (m, l, g) = (1.3, 0.8, 9.81);
    for &(th, omega, e) in &[(0.4f64, 2.5f64, 0.5f64), (0.4, 2.5, 0.0), (1.0, 0.3, 1.0)] {
        let wall = l * th.sin();
        // In the angle: no constraint, one gap.
        let p = AnglePendulum::new(m, l, g, wall);
        let hit = p
            .impact(&Vector1::new(th), &Vector1::new(omega), 0.0, [true], [e])
            .unwrap();
        assert!(
            (hit.qd[0] + e * omega).abs() <= 1e-15 * omega.abs(),
            "{}",
            hit.qd[0]
        );
        // The impulse is the angular impulse m l² (ω⁺ − ω⁻).
        let expected = m * l * l * (-e * omega - omega);
        assert!((hit.impulse[0] - expected).abs() <= 1e-14 * expected.abs());
        // In Cartesian coordinates with the rod a constraint: the same.
        let c = CartesianPendulum::new(m, l, g, wall);
        let q = Vector2::new(l * th.sin(), -l * th.cos());
        let qd = Vector2::new(l * omega * th.cos(), l * omega * th.sin());
        let hit = c.impact(&q, &qd, 0.0, [true], [e]).unwrap();
        let omega_after = (q[0] * hit.qd[1] - q[1] * hit.qd[0]) / (l * l);
        assert!(
            (omega_after + e * omega).abs() <= 1e-14 * omega.abs(),
            "{omega_after}"
        );
        // The rod keeps its length's rate at zero; its impulse is along
        // the rod, the wall's along −x.
        assert!(c.constraint_velocity_residual(&q, &hit.qd, 0.0)[0].abs() < 1e-14);
        let wall_impulse = -hit.row_impulses[1];
        let rod = 2.0 * hit.row_impulses[0] * q; // ∇φ = 2 (x, y)
        assert!((rod + Vector2::new(wall_impulse, 0.0) - hit.impulse).amax() < 1e-13);
        // Inactive, nothing happens (the rod's residual is already zero).
        let free = c.impact(&q, &qd, 0.0, [false], [e]).unwrap();
        assert!((free.qd - qd).amax() < 1e-15);
    }
}

#[test]
fn a_central_collision_conserves_momentum() {
    for &(m1, m2, u1, u2, e) in &[
        (1.0, 1.0, 1.0, 0.0, 1.0),
        (2.0, 5.0, 3.0, -1.0, 0.4),
        (1e3, 1e-3, 0.5, -2.0, 0.0),
    ] {
        let two = TwoBodies::<f64>::new(m1, m2, 0.1);
        let (q, qd) = (Vector2::new(0.0, 0.1), Vector2::new(u1, u2));
        let hit = two.impact(&q, &qd, 0.0, [true], [e]).unwrap();
        let p = m1 * u1 + m2 * u2;
        let after = m1 * hit.qd[0] + m2 * hit.qd[1];
        assert!(
            (after - p).abs() <= 1e-14 * (m1 * u1.abs() + m2 * u2.abs()),
            "{after} vs {p}"
        );
        let (rel_before, rel_after) = (u2 - u1, hit.qd[1] - hit.qd[0]);
        assert!((rel_after + e * rel_before).abs() <= 1e-13 * rel_before.abs());
        // Energy lost: (1 − e²) of the relative motion's.
        let reduced = m1 * m2 / (m1 + m2);
        let lost = 0.5 * (m1 * u1 * u1 + m2 * u2 * u2)
            - 0.5 * (m1 * hit.qd[0].powi(2) + m2 * hit.qd[1].powi(2));
        let expected = 0.5 * reduced * (1.0 - e * e) * rel_before * rel_before;
        assert!(
            (lost - expected).abs() <= 1e-12 * (1.0 + expected),
            "{lost} vs {expected}"
        );
    }
    // Non-finite input is an error, not NaN.
    let two = TwoBodies::<f64>::new(1.0, 1.0, 0.1);
    let bad = two.impact(
        &Vector2::new(0.0, 0.1),
        &Vector2::new(f64::NAN, 0.0),
        0.0,
        [true],
        [1.0],
    );
    assert_eq!(bad, Err(DynamicsError::NonFinite));
}

/// The wheel of the tests and the example: 8 spokes (a2 = π/4), slope 0.1.
pub fn wheel(phase: f64) -> RimlessWheel<f64> {
    // m, inertia, l, g, a2, gamma, phase, px, py
    RimlessWheel::new(
        1.0,
        0.05,
        1.0,
        9.81,
        std::f64::consts::FRAC_PI_4,
        0.1,
        phase,
        0.0,
        0.0,
    )
}

/// The state of the wheel at heel strike: the stance spoke at `th + phase`
/// pinned at the origin, the next spoke on the slope (its angle solved in
/// closed form: the two feet are `2 l sin(a2/2)` apart along the slope),
/// rotating at `omega` about the stance foot.
fn heel_strike(w: &RimlessWheel<f64>, omega: f64) -> (Vector3<f64>, Vector3<f64>) {
    // Both feet on the slope: the two spokes' bisector points down the
    // slope's normal, at −γ from straight down.
    let stance = -w.gamma - w.a2 / 2.0;
    let th = stance - w.phase;
    let (x, y) = (w.px - w.l * stance.sin(), w.py + w.l * stance.cos());
    // Rotation about the pinned foot: v = ω × (r − p).
    let qd = Vector3::new(-omega * (y - w.py), omega * (x - w.px), omega);
    (Vector3::new(x, y, th), qd)
}

/// Angular momentum about the point `c`: `I ω + m (r − c) × v`.
fn angular_momentum(
    w: &RimlessWheel<f64>,
    q: &Vector3<f64>,
    qd: &Vector3<f64>,
    c: Vector2<f64>,
) -> f64 {
    w.inertia * qd[2] + w.m * ((q[0] - c[0]) * qd[1] - (q[1] - c[1]) * qd[0])
}

#[test]
fn each_heel_strike_conserves_angular_momentum_about_the_new_contact() {
    for &(phase, omega) in &[(0.0, -1.2), (0.7, -0.4), (-2.0, -3.0)] {
        let w = wheel(phase);
        let (q, qd) = heel_strike(&w, omega);
        assert!(
            w.gaps(&q, 0.0)[0].abs() < 1e-15,
            "the next foot is on the slope"
        );
        assert!(w.constraint_residual(&q, &qd, 0.0).amax() < 1e-15);
        assert!(w.constraint_velocity_residual(&q, &qd, 0.0).amax() < 1e-15);
        // The switch: the next spoke becomes the stance, pinned where it is.
        let next = w.phase + w.a2;
        let foot = Vector2::new(
            q[0] + w.l * (q[2] + next).sin(),
            q[1] - w.l * (q[2] + next).cos(),
        );
        let after = RimlessWheel {
            phase: next,
            px: foot[0],
            py: foot[1],
            ..w
        };
        assert!(after.constraint_residual(&q, &qd, 0.0).amax() < 1e-15);
        let hit = after.impact(&q, &qd, 0.0, [false], [0.0]).unwrap();
        // The new foot is at rest, the old one lifts off.
        assert!(after.constraint_velocity_residual(&q, &hit.qd, 0.0).amax() < 1e-14);
        let (h0, h1) = (
            angular_momentum(&w, &q, &qd, foot),
            angular_momentum(&w, &q, &hit.qd, foot),
        );
        assert!((h1 - h0).abs() <= 1e-12 * h0.abs(), "{h0} -> {h1}");
        // McGeer's ratio, with the inertia about the hub.
        let ml2 = w.m * w.l * w.l;
        let eta = (w.inertia + ml2 * w.a2.cos()) / (w.inertia + ml2);
        assert!(
            (hit.qd[2] - eta * omega).abs() <= 1e-12 * omega.abs(),
            "{}",
            hit.qd[2] / omega
        );
    }
}

/// McGeer's steady rate just after each heel strike: with
/// `η = (I + m l² cos a2)/(I + m l²)` and the energy a step gains on the
/// slope, `k = 4 m g l sin(a2/2) sin γ / (I + m l²)` (in `ω²`), the rate
/// after strike `n + 1` is `ω²ₙ₊₁ = η² (ω²ₙ + k)`, whose fixed point is
/// `ω² = η² k / (1 − η²)`.
fn mcgeer_steady_rate(w: &RimlessWheel<f64>) -> f64 {
    let j = w.inertia + w.m * w.l * w.l;
    let eta = (w.inertia + w.m * w.l * w.l * w.a2.cos()) / j;
    let k = 4.0 * w.m * w.g * w.l * (w.a2 / 2.0).sin() * w.gamma.sin() / j;
    -(eta * eta * k / (1.0 - eta * eta)).sqrt()
}

/// Rolls the wheel from just after a heel strike at rate `omega` through
/// `strikes` heel strikes (located as events on the next foot's gap,
/// Dormand–Prince with projection), returning the rate after each.
pub fn roll(w: RimlessWheel<f64>, omega: f64, strikes: usize) -> Vec<f64> {
    use constrained::integrate::{Direction, Event, Events, StepOutcome};
    use constrained::{DormandPrince45, Stabilization, State};
    // Start just after a strike: both feet on the slope, rotating at
    // `omega` about the new one.
    let before = RimlessWheel {
        phase: w.phase - w.a2,
        ..w
    };
    let (q, _) = heel_strike(&before, omega);
    let foot = |w: &RimlessWheel<f64>, q: &Vector3<f64>, phase: f64| {
        Vector2::new(
            q[0] + w.l * (q[2] + phase).sin(),
            q[1] - w.l * (q[2] + phase).cos(),
        )
    };
    let f = foot(&w, &q, w.phase);
    let qd = Vector3::new(-omega * (q[1] - f[1]), omega * (q[0] - f[0]), omega);
    let mut wheel = RimlessWheel {
        px: f[0],
        py: f[1],
        ..w
    };
    let mut rates = Vec::new();
    let integrator =
        DormandPrince45::new(1e-12, 1e-13).with_stabilization(Stabilization::projection(1e-13));
    let mut stepper = integrator.stepper(State::new(0.0, q, qd), 1e3).unwrap();
    for _ in 0..100_000 {
        let current = wheel;
        let events = Events::new(
            move |s: &State<f64, 3>| [current.gaps(&s.q, s.t)[0]],
            [Event::stop(Direction::Falling)],
        );
        match stepper.step(&wheel, &events).unwrap() {
            StepOutcome::Event(c) => {
                let next = wheel.phase + wheel.a2;
                let f = foot(&wheel, &c.state.q, next);
                wheel = RimlessWheel {
                    phase: next,
                    px: f[0],
                    py: f[1],
                    ..wheel
                };
                let s = c.state;
                let hit = wheel.impact(&s.q, &s.qd, s.t, [false], [0.0]).unwrap();
                rates.push(hit.qd[2]);
                stepper.set_state(State::new(s.t, s.q, hit.qd)).unwrap();
                if rates.len() == strikes {
                    break;
                }
            }
            StepOutcome::Step => {}
            StepOutcome::Finished => break,
        }
    }
    rates
}

#[test]
fn the_rimless_wheel_converges_to_mcgeers_steady_rate() {
    let w = wheel(0.0);
    let steady = mcgeer_steady_rate(&w);
    // From faster and from slower than steady (both pass over the top).
    for omega in [2.0 * steady, 0.8 * steady] {
        let rates = roll(w, omega, 40);
        assert_eq!(rates.len(), 40, "it kept rolling");
        // Geometric convergence at η² ≈ 0.52 a step: the last is steady.
        let last = rates[rates.len() - 1];
        assert!(
            (last - steady).abs() <= 1e-8 * steady.abs(),
            "{last} vs {steady}"
        );
        // Each strike follows McGeer's map of the previous one.
        let j = w.inertia + w.m * w.l * w.l;
        let eta = (w.inertia + w.m * w.l * w.l * w.a2.cos()) / j;
        let k = 4.0 * w.m * w.g * w.l * (w.a2 / 2.0).sin() * w.gamma.sin() / j;
        for pair in rates.windows(2) {
            let predicted = -(eta * eta * (pair[0] * pair[0] + k)).sqrt();
            assert!(
                (pair[1] - predicted).abs() <= 1e-9 * steady.abs(),
                "{pair:?}"
            );
        }
    }
}

/// The same heel strike in `f32` (the firmware's scalar): McGeer's ratio to
/// `f32` precision.
#[test]
fn a_heel_strike_in_f32() {
    let w = wheel(0.0);
    let (q, qd) = heel_strike(&w, -1.2);
    let next = w.phase + w.a2;
    let foot = (
        q[0] + w.l * (q[2] + next).sin(),
        q[1] - w.l * (q[2] + next).cos(),
    );
    let after = RimlessWheel::<f32>::new(
        w.m as f32,
        w.inertia as f32,
        w.l as f32,
        w.g as f32,
        w.a2 as f32,
        w.gamma as f32,
        next as f32,
        foot.0 as f32,
        foot.1 as f32,
    );
    let hit = after
        .impact(&q.cast::<f32>(), &qd.cast::<f32>(), 0.0, [false], [0.0])
        .unwrap();
    let ml2 = w.m * w.l * w.l;
    let eta = (w.inertia + ml2 * w.a2.cos()) / (w.inertia + ml2);
    let ratio = f64::from(hit.qd[2]) / -1.2;
    assert!((ratio - eta).abs() < 1e-5, "{ratio} vs {eta}");
}
