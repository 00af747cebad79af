//! The redundant-contacts rows of the Contacts section: the Unitree G1 on
//! a floating base standing on three points of each foot (`build.rs`'s
//! `g1_standing`): 36 coordinates, 19 rows (the six points' 18 and the
//! quaternion's norm) of rank 13, so `λ` is not unique and the minimum
//! norm is returned. Ours only: `q̈`, `q̈` and `λ` (the minimum norm from
//! the solve's own factors), and `q̈` with `λ` found by the runtime's SVD of
//! `A` from the solve's force (what a redundant set cost before), each
//! checked before it is timed.

use crate::clock::{median_ns, paired_ratio};
use crate::Rng;
use constrained::__private::Generated;
use constrained::multipliers::{multipliers, Multipliers};
use constrained::nalgebra::SVector;
use constrained::{ConstrainedSystem, State};
use std::fmt::Write as _;
use std::hint::black_box;

include!(concat!(env!("OUT_DIR"), "/g1_standing.rs"));

/// The G1's coordinates: the base's seven and 29 joints.
const N: usize = 36;
/// Its rows: the six points' 18 and the quaternion's norm.
const K: usize = 19;

/// The G1 with its six points held at `places` (`(x, y, z)` each: the
/// left foot's three, then the right's).
fn standing(places: &[f64; 18]) -> G1Standing<f64> {
    let p = places;
    G1Standing::new(
        p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12], p[13],
        p[14], p[15], p[16], p[17],
    )
}

/// A G1 state ([`crate::g1_pose`]), the feet's points held where it
/// places them, the rates on the rows' null space ([`crate::on_the_rows`]).
fn state(rng: &mut Rng) -> (G1Standing<f64>, State<f64, N>) {
    let (q, qd) = crate::g1_pose::<N>(rng);
    let at_rest = State::new(0.0, q, SVector::zeros());
    let placed = ConstrainedSystem::constraint_residual(&standing(&[0.0; 18]), &at_rest);
    let system = standing(&std::array::from_fn(|i| placed[i]));
    let s = crate::on_the_rows::<_, N, K>(&system, (q, qd), |a| {
        a.pseudo_inverse(1e-12).expect("a pseudo-inverse")
    });
    (system, s)
}

/// The states of both `write` and `time`: `STATES` from a generator of
/// their own.
fn states() -> Vec<(G1Standing<f64>, State<f64, N>)> {
    let mut rng = Rng(61);
    (0..crate::STATES).map(|_| state(&mut rng)).collect()
}

/// The G1's joints in our order (after the base's seven coordinates), for
/// Pinocchio's side to place each by its name.
pub fn joints() -> &'static [&'static str] {
    let names = &G1Standing::<f64>::COORDINATES;
    assert_eq!(names[0], "root_joint_x", "the G1's base comes first");
    &names[7..]
}

/// The states' records for Pinocchio's side (`g1 35`: Pinocchio's `q`,
/// `v`, `τ` (zero: unpowered) and `a`, our `λ` of the six points (world
/// axes, the force on the foot), the points' places and the points
/// in their feet's frames), each `q̈` checked
/// against `A q̈ = b` first (to 1e-12, as `time` checks it).
pub fn write(out: &mut String) {
    for (system, s) in states() {
        let (qdd, lambda) = system.acceleration_and_multipliers(&s).expect("q̈ and λ");
        let (a, b) = ConstrainedSystem::constraint_matrices(&system, &s);
        let residual = crate::residual(&a, &b, &qdd);
        assert!(residual < 1e-12, "A q̈ = b only to {residual:e}");
        let (config, velocity, acceleration) = crate::pinocchio_coordinates(&s, &qdd);
        let places = [
            system.l0_x,
            system.l0_y,
            system.l0_z,
            system.l1_x,
            system.l1_y,
            system.l1_z,
            system.l2_x,
            system.l2_y,
            system.l2_z,
            system.r0_x,
            system.r0_y,
            system.r0_z,
            system.r1_x,
            system.r1_y,
            system.r1_z,
            system.r2_x,
            system.r2_y,
            system.r2_z,
        ];
        let _ = writeln!(out, "g1 {}", N - 1);
        crate::line(out, "q", config.iter());
        crate::line(out, "v", velocity.iter());
        crate::line(out, "tau", [0.0; N - 1].iter());
        crate::line(out, "a", acceleration.iter());
        crate::line(out, "lambda", lambda.iter().take(K - 1));
        crate::line(out, "feet", places.iter());
        crate::line(out, "points", SOLE_POINTS.iter().flatten());
    }
}

/// `passes` passes of `what` over the states, and nothing else (`contacts
/// spin`, for cachegrind).
pub fn spin(what: &str, passes: usize) {
    crate::spin::<_, N, K>(what, passes, &states());
}

/// `q̈` with the runtime's minimum-norm `λ`: the solve's force, then an SVD
/// of `A` (`constrained::multipliers::multipliers`).
fn through_the_runtime(
    system: &G1Standing<f64>,
    s: &State<f64, N>,
) -> (SVector<f64, N>, SVector<f64, K>) {
    let (qdd, force) = Generated::gauss(system, &s.q, &s.qd, s.t, None).expect("a solve");
    let (a, _) = Generated::constraint_matrices(system, &s.q, &s.qd, s.t);
    (qdd, multipliers(&a, &force).expect("λ of Aᵀλ = Fᶜ"))
}

/// Checks each state's `A q̈ = b` (relative, as the other systems', to
/// 1e-12), `q̈` against the runtime's dense solve (to 1e-12) and `λ`
/// against the runtime's minimum norm (relative to the largest entry, to
/// 1e-10), then times the three ways per state; one JSON line each.
pub fn time(round: &str) {
    let cases = states();
    let (mut worst, mut residual, mut dense): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for (system, s) in &cases {
        let (qdd, lambda) = system.acceleration_and_multipliers(s).expect("q̈ and λ");
        let (a, b) = ConstrainedSystem::constraint_matrices(system, s);
        residual = residual.max(crate::residual(&a, &b, &qdd));
        let (_, reference) = through_the_runtime(system, s);
        worst = worst.max((lambda - reference).amax() / reference.amax());
        // How far that leaves q̈ from the runtime's dense Moore–Penrose
        // solve (an SVD), which satisfies every row to rounding.
        let exact = ConstrainedSystem::acceleration_moore_penrose(system, s).expect("q̈");
        dense = dense.max((qdd - exact).amax() / exact.amax());
    }
    assert!(residual < 1e-12, "A q̈ = b only to {residual:e}");
    assert!(dense < 1e-12, "q̈ only within {dense:e} of the dense solve");
    assert!(
        worst < 1e-10,
        "λ differs from the runtime's minimum norm by {worst:e}"
    );
    eprintln!(
        "contacts: the G1's A q̈ = b to {residual:.1e}, q̈ within {dense:.1e} of the runtime's dense solve, its minimum-norm λ within {worst:.1e} of the runtime's SVD"
    );
    let per_state = |ns: f64| ns / cases.len() as f64;
    let acceleration = median_ns(|| {
        for (system, s) in &cases {
            let _ = black_box(ConstrainedSystem::acceleration(
                black_box(system),
                black_box(s),
            ));
        }
    });
    let both = median_ns(|| {
        for (system, s) in &cases {
            let _ = black_box(black_box(system).acceleration_and_multipliers(black_box(s)));
        }
    });
    let runtime = median_ns(|| {
        for (system, s) in &cases {
            black_box(through_the_runtime(black_box(system), black_box(s)));
        }
    });
    // `q̈` and `λ` against `q̈` alone, batch against batch: the target's
    // ratio, which the two medians above, taken seconds apart on a shared
    // machine, gave anywhere from 1.0 to 1.7 in one afternoon.
    let paired = paired_ratio(
        || {
            for (system, s) in &cases {
                let _ = black_box(ConstrainedSystem::acceleration(
                    black_box(system),
                    black_box(s),
                ));
            }
        },
        || {
            for (system, s) in &cases {
                let _ = black_box(black_box(system).acceleration_and_multipliers(black_box(s)));
            }
        },
    );
    for (what, ns) in [
        ("acceleration", acceleration),
        ("acceleration_and_multipliers", both),
        ("acceleration_and_runtime_multipliers", runtime),
    ] {
        println!(
            "{{\"peer\": \"constrained\", \"what\": \"{what}\", \"system\": \"g1_points\", \"n\": {N}, \
             \"rows\": {K}, \"ns\": {:.3}, \"states\": {}, \"round\": {round}, \"worst\": {worst:.3e}, \
             \"residual\": {residual:.3e}, \"dense\": {dense:.3e}, \"paired\": {paired:.4}, \"ok\": true}}",
            per_state(ns),
            cases.len()
        );
    }
}
