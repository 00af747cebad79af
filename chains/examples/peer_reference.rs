//! The states and answers the peer benchmarks (`benches/peers/`: Pinocchio
//! and MuJoCo, compiled against their wheels) check themselves against
//! before they report a time. Written by `scripts/benchmarks.sh`:
//!
//! ```text
//! cargo run --release -p constrained-chains --example peer_reference -- FILE
//! ```
//!
//! The peers model the same systems in relative joint angles (a revolute
//! joint per link), so every answer here is converted to them:
//! - `chain N g h`, then the lines `masses`, `lengths`, `q`, `v` (relative
//!   joint angles and rates of `benchmark_state`), `qdd` (the generated
//!   Cartesian chain's `acceleration`, as relative angle accelerations),
//!   `q1` and `v1` (after one plain RK4 step of the Cartesian chain of size
//!   h, in relative angles);
//! - `four_bar m jm l d g`, then `q`, `v` (crank, coupler relative to the
//!   crank, rocker) and `qdd` from `ParallelogramFourBarAngles`, and the
//!   same at rest (`q_rest`, `v_rest`, `qdd_rest`): MuJoCo drops the
//!   `J̇ q̇` term of its constraints, so it is checked where that is zero.

use constrained::models::ParallelogramFourBarAngles;
use constrained::nalgebra::{SVector, Vector3};
use constrained::{ConstrainedSystem, Rk4, State};
use constrained_chains::*;
use std::fmt::Write as _;

const G: f64 = 9.81;
const H: f64 = 1e-3;

/// Absolute link angles and rates of a Cartesian chain state (from the
/// downward vertical), from each link's vector `(dx, dy) = l (sin θ, −cos θ)`.
fn link_angles<const M: usize>(q: &SVector<f64, M>, qd: &SVector<f64, M>) -> (Vec<f64>, Vec<f64>) {
    let (mut angles, mut rates) = (Vec::new(), Vec::new());
    let (mut x, mut y, mut vx, mut vy) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..M / 2 {
        let (dx, dy) = (q[2 * i] - x, q[2 * i + 1] - y);
        let (dvx, dvy) = (qd[2 * i] - vx, qd[2 * i + 1] - vy);
        angles.push(dx.atan2(-dy));
        // θ̇ = (dx dvy − dy dvx)/l², the rotation rate of the link vector.
        rates.push((dx * dvy - dy * dvx) / (dx * dx + dy * dy));
        (x, y, vx, vy) = (q[2 * i], q[2 * i + 1], qd[2 * i], qd[2 * i + 1]);
    }
    (angles, rates)
}

/// Absolute link angle accelerations from the Cartesian ones:
/// `θ̈ = (cos θ Δẍ + sin θ Δÿ)/l` (the tangential component; the normal one
/// is the centripetal `l θ̇²`).
fn link_accelerations<const M: usize>(q: &SVector<f64, M>, qdd: &SVector<f64, M>) -> Vec<f64> {
    let (angles, _) = link_angles(q, &SVector::<f64, M>::zeros());
    let (mut ax, mut ay) = (0.0, 0.0);
    (0..M / 2)
        .map(|i| {
            let (dax, day) = (qdd[2 * i] - ax, qdd[2 * i + 1] - ay);
            (ax, ay) = (qdd[2 * i], qdd[2 * i + 1]);
            let th = angles[i];
            (th.cos() * dax + th.sin() * day) / length(i + 1)
        })
        .collect()
}

/// Absolute angles to the joint angles of a serial chain (each relative to
/// its parent link).
fn relative(absolute: &[f64]) -> Vec<f64> {
    let mut previous = 0.0;
    absolute
        .iter()
        .map(|&a| {
            let r = a - previous;
            previous = a;
            r
        })
        .collect()
}

fn line(out: &mut String, name: &str, values: &[f64]) {
    let _ = write!(out, "{name}");
    for v in values {
        let _ = write!(out, " {v:.17e}");
    }
    out.push('\n');
}

fn chain<S: ConstrainedSystem<f64, M, K>, const M: usize, const K: usize>(
    out: &mut String,
    system: &S,
) {
    let n = M / 2;
    let (q, qd) = benchmark_state::<M>();
    let mut s = State::new(0.0, q, qd);
    let qdd = system.acceleration(&s).expect("the chain's q̈");
    Rk4::new(H)
        .advance(system, &mut s, H)
        .expect("one RK4 step");
    let (angles, rates) = link_angles(&q, &qd);
    let (angles1, rates1) = link_angles(&s.q, &s.qd);
    let _ = writeln!(out, "chain {n} {G:.17e} {H:.17e}");
    line(out, "masses", &(1..=n).map(mass).collect::<Vec<_>>());
    line(out, "lengths", &(1..=n).map(length).collect::<Vec<_>>());
    line(out, "q", &relative(&angles));
    line(out, "v", &relative(&rates));
    line(out, "qdd", &relative(&link_accelerations(&q, &qdd)));
    line(out, "q1", &relative(&angles1));
    line(out, "v1", &relative(&rates1));
}

fn main() {
    let path = std::env::args().nth(1).expect("usage: peer_reference FILE");
    let mut out = String::new();
    chain(&mut out, &Chain1::new(G));
    chain(&mut out, &Chain2::new(G));
    chain(&mut out, &Chain4::new(G));
    chain(&mut out, &Chain8::new(G));
    chain(&mut out, &Chain16::new(G));
    chain(&mut out, &Chain32::new(G));

    // The four-bar of the benchmarks (benches/acceleration.rs): link angles
    // from the x axis; the peers' coupler joint is relative to the crank.
    let (m, jm, l, d) = (1.2, 0.15, 1.0, 2.0);
    let four_bar = ParallelogramFourBarAngles::<f64>::new(m, jm, l, d, G);
    let to_joints = |p: &Vector3<f64>| [p[0], p[1] - p[0], p[2]];
    let _ = writeln!(
        out,
        "four_bar {m:.17e} {jm:.17e} {l:.17e} {d:.17e} {G:.17e}"
    );
    for (suffix, q, qd) in [
        ("", Vector3::new(0.7, 0.0, 0.7), Vector3::new(1.3, 0.0, 1.3)),
        ("_rest", Vector3::new(0.7, 0.0, 0.7), Vector3::zeros()),
    ] {
        let qdd = four_bar
            .acceleration(&q, &qd, 0.0)
            .expect("the four-bar's q̈");
        line(&mut out, &format!("q{suffix}"), &to_joints(&q));
        line(&mut out, &format!("v{suffix}"), &to_joints(&qd));
        line(&mut out, &format!("qdd{suffix}"), &to_joints(&qdd));
    }
    std::fs::write(&path, out).expect("writes the reference file");
}
