//! The DSL's non-smooth functions (`abs`, `signum`, `min`, `max`, `clamp`,
//! `hypot`) and constants (`PI`, `E`) against closed forms: a block sliding
//! with Coulomb friction stops where `v₀²/(2μg)` says, the crane's saturated
//! actuator gives exactly its limit, and `signum(0) = 0`.

use constrained::models::Crane;
use constrained::nalgebra::{SVector, Vector1, Vector3};
use constrained::{constrained_system, Rk4, State};

constrained_system! {
    /// A block on a table, Coulomb friction only.
    pub struct SlidingBlock {
        coordinates: [x],
        parameters: [m, g, mu],
        mass: diag[m],
        forces: [-mu * m * g * signum(dot(x))],
    }
}

/// Decelerates at μg until it stops at `v₀²/(2μg)`, then stays (the
/// friction force switches sign each step at rest: the velocity stays
/// within one step's impulse of zero).
#[test]
fn coulomb_friction_stops_the_block_where_the_closed_form_says() {
    let (m, g, mu, v0) = (2.0, 9.81, 0.3, 2.0);
    let block = SlidingBlock::<f64>::new(m, g, mu);
    let h = 1e-4;
    let mut state = State::new(0.0, Vector1::new(0.0), Vector1::new(v0));
    let t_stop = v0 / (mu * g);
    Rk4::new(h)
        .advance(&block, &mut state, 0.5 * t_stop)
        .expect("integrates");
    let expected_v = v0 - mu * g * 0.5 * t_stop;
    assert!((state.qd[0] - expected_v).abs() < 1e-12, "{}", state.qd[0]);
    // Just past the stop: where the closed form says, to the few steps'
    // worth of chatter since.
    let x_stop = v0 * v0 / (2.0 * mu * g);
    let (rk4, chatter) = (Rk4::new(h), mu * g * h);
    rk4.advance(&block, &mut state, t_stop + 10.0 * h)
        .expect("integrates");
    assert!(
        (state.q[0] - x_stop).abs() < 10.0 * chatter * h + 1e-12,
        "stopped at {} (closed form {x_stop})",
        state.q[0]
    );
    // Long after: the velocity stays within one step's impulse of zero, so
    // the block creeps by at most that speed.
    rk4.advance(&block, &mut state, 2.0 * t_stop)
        .expect("integrates");
    assert!(
        (state.q[0] - x_stop).abs() < chatter * (state.t - t_stop),
        "at rest at {} (closed form {x_stop})",
        state.q[0]
    );
    assert!(state.qd[0].abs() <= chatter, "{}", state.qd[0]);
}

fn crane() -> Crane<f64> {
    // mc, ml, l, g, mu, kp, kd, umax, target
    Crane::new(4.0, 1.0, 1.5, 9.81, 0.05, 30.0, 12.0, 8.0, 2.0)
}

/// Saturated, the drive is exactly `±umax`; unsaturated, the PD law; the
/// friction is `μ (mc + ml) g` against the motion and 0 at rest.
#[test]
fn crane_forces_are_the_saturated_drive_minus_friction() {
    let c = crane();
    let q = |xc: f64| Vector3::new(xc, xc, -c.l);
    let friction = c.mu * (c.mc + c.ml) * c.g;
    let cases = [
        // (xc, ẋc, drive, friction sign)
        (0.0, 0.0, c.umax, 0.0),                  // far: saturated, at rest
        (0.0, 0.5, c.umax, 1.0),                  // saturated, moving
        (4.0, -0.5, -c.umax, -1.0),               // saturated the other way
        (1.9, 0.2, 30.0 * 0.1 - 12.0 * 0.2, 1.0), // inside the band: PD
        (2.05, -0.1, 30.0 * -0.05 + 12.0 * 0.1, -1.0),
    ];
    for (xc, vc, drive, sign) in cases {
        let qd = Vector3::new(vc, vc, 0.0);
        let f = c.forces(&q(xc), &qd, 0.0);
        let expected = drive - sign * friction;
        assert!(
            (f[0] - expected).abs() < 1e-12,
            "xc = {xc}, ẋc = {vc}: {} vs {expected}",
            f[0]
        );
        assert_eq!((f[1], f[2]), (0.0, -c.ml * c.g));
    }
}

/// With the load hanging straight down and the trolley at rest, the rod
/// carries no horizontal force: the trolley accelerates at `umax / mc`.
#[test]
fn saturated_drive_accelerates_the_trolley_at_its_limit() {
    let c = crane();
    let q = Vector3::new(0.0, 0.0, -c.l);
    let qdd = c
        .acceleration(&q, &Vector3::zeros(), 0.0)
        .expect("positive masses");
    assert!((qdd[0] - c.umax / c.mc).abs() < 1e-12, "{}", qdd[0]);
    assert!(qdd[1].abs() < 1e-12 && qdd[2].abs() < 1e-12, "{qdd}");
}

/// The generated code is the same for `f32`.
#[test]
fn crane_in_f32_matches_f64() {
    let c64 = crane();
    let c32 = Crane::<f32>::new(4.0, 1.0, 1.5, 9.81, 0.05, 30.0, 12.0, 8.0, 2.0);
    let (q, qd) = (Vector3::new(0.3, 0.9, -1.37), Vector3::new(0.4, -0.2, 0.1));
    let a64 = c64.acceleration(&q, &qd, 0.0).expect("positive masses");
    let a32 = c32
        .acceleration(&q.cast::<f32>(), &qd.cast::<f32>(), 0.0)
        .expect("positive masses");
    assert!(
        (a32.cast::<f64>() - a64).norm() < 1e-5 * a64.norm(),
        "{a32} vs {a64}"
    );
}

constrained_system! {
    /// Every non-smooth function and constant once, in forces.
    pub struct Gallery {
        coordinates: [x, y],
        mass: diag[1.0, 1.0],
        forces: [
            abs(x) + signum(y) + min(x, y) + max(x, y) + clamp(x, -1.0, 1.0),
            hypot(x, y) + PI * E,
        ],
    }
}

#[test]
fn non_smooth_functions_evaluate_as_documented() {
    let g = Gallery::<f64>::default();
    let f = |x: f64, y: f64| g.forces(&SVector::from([x, y]), &SVector::zeros(), 0.0);
    let pe = std::f64::consts::PI * std::f64::consts::E;
    for (x, y, first) in [
        (-2.0, 0.0, 2.0 + 0.0 - 2.0 + 0.0 - 1.0),
        (0.5, -3.0, 0.5 - 1.0 - 3.0 + 0.5 + 0.5),
        (3.0, 4.0, 3.0 + 1.0 + 3.0 + 4.0 + 1.0),
    ] {
        let v = f(x, y);
        assert_eq!(v[0], first, "({x}, {y})");
        assert!((v[1] - ((x * x + y * y).sqrt() + pe)).abs() < 1e-14);
    }
}
