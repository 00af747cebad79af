//! The impact map (`unilateral: [..]` and the generated `impact`: the
//! model's mass matrix, constraint and gap rows, then the runtime's solve
//! of the impulsive Gauss principle), per impact, on the three models of
//! the examples: the pendulum on a wall (Cartesian, the rod a constraint;
//! two coordinates, one constraint, one gap), the rimless wheel at heel
//! strike (three coordinates, two constraints pinning the new foot) and the
//! compass-gait walker at heel strike (four coordinates in energies, two
//! constraints). Each answer is checked against its closed form before it
//! is timed.

#[path = "../examples/support/compass_gait.rs"]
mod compass_gait;
#[path = "../examples/support/rimless_wheel.rs"]
mod rimless_wheel;

use compass_gait::CompassGait;
use constrained::nalgebra::{Vector2, Vector3, Vector4};
use criterion::{criterion_group, criterion_main, Criterion};
use rimless_wheel::RimlessWheel;
use std::hint::black_box;

#[path = "../examples/support/wall_pendulum.rs"]
mod wall_pendulum;
use wall_pendulum::WallPendulum;

/// The pendulum at the wall (rod at 0.4 rad, ω = 2.5 rad/s, e = 0.7): the
/// angular velocity after is `−e ω`.
fn pendulum(c: &mut Criterion) {
    let (l, th, omega, e) = (0.8f64, 0.4f64, 2.5f64, 0.7f64);
    let p = WallPendulum::new(1.3, l, 9.81, l * th.sin());
    let q = Vector2::new(l * th.sin(), -l * th.cos());
    let qd = Vector2::new(l * omega * th.cos(), l * omega * th.sin());
    let hit = p.impact(&q, &qd, 0.0, [true], [e]).expect("impact");
    let after = (q[0] * hit.qd[1] - q[1] * hit.qd[0]) / (l * l);
    assert!((after + e * omega).abs() < 1e-13, "{after}");
    c.bench_function("impact/pendulum_wall", |b| {
        b.iter(|| black_box(&p).impact(black_box(&q), black_box(&qd), 0.0, [true], [e]))
    });
}

/// The rimless wheel (8 spokes, slope 0.1) at heel strike rotating at
/// −1.2 rad/s, the next spoke pinned: the rate after is McGeer's
/// `(I + m l² cos a2)/(I + m l²)` times the rate before.
fn wheel(c: &mut Criterion) {
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
    let omega = -1.2;
    let stance = -w.gamma - w.a2 / 2.0;
    let th = stance - w.phase;
    let (x, y) = (w.px - w.l * stance.sin(), w.py + w.l * stance.cos());
    let q = Vector3::new(x, y, th);
    let qd = Vector3::new(-omega * (y - w.py), omega * (x - w.px), omega);
    let next = w.phase + w.a2;
    let after = RimlessWheel {
        phase: next,
        px: x + w.l * (th + next).sin(),
        py: y - w.l * (th + next).cos(),
        ..w
    };
    let hit = after.impact(&q, &qd, 0.0, [false], [0.0]).expect("impact");
    let ml2 = w.m * w.l * w.l;
    let eta = (w.inertia + ml2 * w.a2.cos()) / (w.inertia + ml2);
    assert!((hit.qd[2] - eta * omega).abs() < 1e-12, "{}", hit.qd[2]);
    c.bench_function("impact/rimless_wheel", |b| {
        b.iter(|| black_box(&after).impact(black_box(&q), black_box(&qd), 0.0, [false], [0.0]))
    });
}

/// The compass gait (Goswami et al.'s walker, 3° slope) at heel strike,
/// legs symmetric about the slope's normal: after the strike the new
/// stance foot is at rest and the angular momentum of the whole walker
/// about it is conserved.
fn walker(c: &mut Criterion) {
    let w = CompassGait::new(10.0, 5.0, 0.5, 0.5, 9.81, 3f64.to_radians(), 0.0, 0.0, 0.0);
    let (delta, ws, wf) = (0.27, -1.09, -0.38);
    let l = w.a + w.b;
    let (t1, t2) = (-w.gamma - delta, -w.gamma + delta);
    let q = Vector4::new(-l * t1.sin(), l * t1.cos(), t1, t2);
    let qd = Vector4::new(-l * t1.cos() * ws, -l * t1.sin() * ws, ws, wf);
    assert!(
        w.gaps(&q, 0.0)[0].abs() < 1e-14,
        "the swing foot is on the slope"
    );
    let foot = (q[0] + l * t2.sin(), q[1] - l * t2.cos());
    let after = CompassGait {
        s: 1.0,
        px: foot.0,
        py: foot.1,
        ..w
    };
    let hit = after.impact(&q, &qd, 0.0, [false], [0.0]).expect("impact");
    let pinned = after.constraint_velocity_residual(&q, &hit.qd, 0.0);
    assert!(pinned.amax() < 1e-13, "{pinned}");
    // Angular momentum about the new foot: the hip's and both legs' masses.
    let momentum = |v: &Vector4<f64>| {
        let point = |r: (f64, f64), u: (f64, f64), m: f64| {
            m * ((r.0 - foot.0) * u.1 - (r.1 - foot.1) * u.0)
        };
        let leg = |th: f64, w_th: f64| {
            let r = (q[0] + w.b * th.sin(), q[1] - w.b * th.cos());
            let u = (v[0] + w.b * th.cos() * w_th, v[1] + w.b * th.sin() * w_th);
            point(r, u, w.m)
        };
        point((q[0], q[1]), (v[0], v[1]), w.mh) + leg(q[2], v[2]) + leg(q[3], v[3])
    };
    let (h0, h1) = (momentum(&qd), momentum(&hit.qd));
    assert!((h1 - h0).abs() < 1e-12 * h0.abs(), "{h0} -> {h1}");
    c.bench_function("impact/compass_gait", |b| {
        b.iter(|| black_box(&after).impact(black_box(&q), black_box(&qd), 0.0, [false], [0.0]))
    });
}

criterion_group!(benches, pendulum, wheel, walker);
criterion_main!(benches);
