//! `acceleration_and_multipliers` takes each row's `λ` from the generated
//! solve itself — the multipliers of `S λ = r` it solved for `q̈` — where
//! that solve kept every row: held to the runtime's solve of `Aᵀ λ = Fᶜ`
//! (`constrained::multipliers::multipliers`, orthogonal factors of `Aᵀ`)
//! from the same solve's force, to 1e-10 relative, at 24 states of models
//! of every strategy: `M` diagonal with rows scaled (the double pendulum,
//! the four-bar), `M` a common mass times the identity (the spherical
//! pendulum), one row (Appell's particle), `M` in
//! quaternions through the auxiliary mass (the heavy top); the quadruped's
//! in `quadruped`. A redundant set (whose `λ` is not unique) gives the
//! force instead, and the runtime's minimum norm answers.

use constrained::__private::{Generated, Reaction};
use constrained::models::{
    quaternion_state, Appell, DoublePendulum, HeavyTop, ParallelogramFourBar,
    RedundantDoublePendulum, SliderCrank, SphericalPendulum,
};
use constrained::multipliers::{multipliers, Multipliers};
use constrained::nalgebra::{SVector, Vector3, Vector4};
use constrained::State;

/// A pseudo-random number in [−1, 1).
fn uniform(x: &mut u64) -> f64 {
    *x = x
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// States with coordinates and velocities in [−1.5, 1.5).
pub(crate) fn random_states<const N: usize>(seed: u64) -> Vec<State<f64, N>> {
    let mut x = seed;
    (0..24)
        .map(|_| {
            let q = SVector::<f64, N>::from_fn(|_, _| 1.5 * uniform(&mut x));
            let qd = SVector::<f64, N>::from_fn(|_, _| 1.5 * uniform(&mut x));
            State::new(0.2, q, qd)
        })
        .collect()
}

/// The largest gap, relative to `‖λ‖∞`, between the generated `λ` and the
/// runtime's from the generated force, over `states`; `generated` says
/// whether every state must have the generated `λ` (else: none may).
pub(crate) fn multipliers_gap<S, const N: usize, const K: usize>(
    system: &S,
    states: &[State<f64, N>],
    generated: bool,
) -> f64
where
    S: Generated<f64, N, K>,
{
    let mut gap: f64 = 0.0;
    for s in states {
        let (_, force) = Generated::gauss(system, &s.q, &s.qd, s.t, None).expect("a solve");
        let (a, _) = system.constraint_matrices(&s.q, &s.qd, s.t);
        let reference = multipliers(&a, &force).expect("λ of Aᵀλ = Fᶜ");
        let (qdd, reaction) =
            Generated::gauss_multipliers(system, &s.q, &s.qd, s.t).expect("a solve");
        let (_, lambda) = system.acceleration_and_multipliers(s).expect("q̈ and λ");
        let own = match reaction {
            Reaction::Multipliers(l) => {
                assert!(generated, "a redundant set's λ is not the solve's");
                l
            }
            Reaction::Force(f) => {
                assert!(!generated, "every row kept, yet no λ from the solve");
                assert_eq!(f, force);
                reference
            }
        };
        let (plain, _) = Generated::gauss(system, &s.q, &s.qd, s.t, None).expect("a solve");
        assert_eq!(qdd, plain, "the same q̈ either way");
        assert_eq!(
            own, lambda,
            "acceleration_and_multipliers returns the solve's λ"
        );
        gap = gap.max((own - reference).amax() / reference.amax().max(f64::MIN_POSITIVE));
    }
    gap
}

fn check(name: &str, gap: f64) {
    println!("{name:<26} generated λ vs Aᵀλ = Fᶜ solved: {gap:.1e}");
    assert!(gap < 1e-10, "{name}: {gap:e}");
}

#[test]
fn the_generated_multipliers_are_the_unique_ones() {
    check(
        "DoublePendulum",
        multipliers_gap::<_, 4, 2>(
            &DoublePendulum::new(1.0, 1.5, 1.0, 0.7, 9.81),
            &random_states(3),
            true,
        ),
    );
    check(
        "ParallelogramFourBar",
        multipliers_gap::<_, 9, 8>(
            &ParallelogramFourBar::new(1.0, 0.1, 1.0, 2.0, 9.81),
            &random_states(7),
            true,
        ),
    );
    check(
        "SphericalPendulum (μ I)",
        multipliers_gap::<_, 3, 1>(
            &SphericalPendulum::new(2.0, 9.81, 1.3),
            &random_states(11),
            true,
        ),
    );
    check(
        "Appell (one row)",
        multipliers_gap::<_, 3, 1>(&Appell::new(9.81, 0.5), &random_states(9), true),
    );
    let mut x = 13u64;
    let tops: Vec<State<f64, 4>> = (0..24)
        .map(|_| {
            let e = Vector4::from_fn(|_, _| uniform(&mut x)) + Vector4::new(1.5, 0.0, 0.0, 0.0);
            let w = Vector3::from_fn(|_, _| 3.0 * uniform(&mut x));
            quaternion_state(0.0, e, w)
        })
        .collect();
    check(
        "HeavyTop (auxiliary mass)",
        multipliers_gap::<_, 4, 1>(&HeavyTop::new(1.2, 0.4, 1.0, 9.81, 0.3), &tops, true),
    );
}

/// The redundant double pendulum (three rows of rank two on the
/// constraints) and the slider-crank (its slider held twice): `λ` is not
/// unique, and the runtime's minimum norm answers.
#[test]
fn a_redundant_set_leaves_lambda_to_the_runtime() {
    let system = RedundantDoublePendulum::new(1.0, 1.5, 1.0, 0.7, 9.81);
    let gap = multipliers_gap::<_, 4, 3>(&system, &random_states(17), false);
    assert!(gap == 0.0, "{gap:e}");
    let crank = SliderCrank::new(1.0, 0.5, 0.3, 1.0, 2.0, 9.81);
    let gap = multipliers_gap::<_, 4, 4>(&crank, &random_states(5), false);
    assert!(gap == 0.0, "{gap:e}");
}
