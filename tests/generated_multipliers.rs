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
//! minimum-norm `λ` from the solve's factors, held to the runtime's
//! minimum norm (an SVD of `A`): with `M⁻¹` known and rows scaled (the
//! redundant double pendulum, the slider-crank), with `M(q)` factored (an
//! arm on bodies, a free slab on four corners).

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
/// constraints) and the slider-crank (its slider held twice), solved with
/// `M⁻¹` known and rows scaled: the generated solve's `λ` is the
/// minimum-norm one of the rows as written (weighted by the scaling), and
/// agrees with the runtime's minimum norm from the same force.
#[test]
fn a_redundant_set_with_a_known_inverse_has_the_minimum_norm_lambda_from_the_solve() {
    let system = RedundantDoublePendulum::new(1.0, 1.5, 1.0, 0.7, 9.81);
    let gap = multipliers_gap::<_, 4, 3>(&system, &consistent(&system, 17), true);
    check("RedundantDoublePendulum", gap);
    let crank = SliderCrank::new(1.0, 0.5, 0.3, 1.0, 2.0, 9.81);
    let gap = multipliers_gap::<_, 4, 4>(&crank, &consistent(&crank, 5), true);
    check("SliderCrank (slider twice)", gap);
}

/// Off the constraints the slider-crank's rows are only nearly dependent:
/// the rank rule's loose cutoff may drop one, yet `λ` is unique there, and
/// moving along a direction that is not quite null would change the force:
/// whichever way the solve went, `λ` is the one of `Aᵀλ = Fᶜ`.
#[test]
fn a_nearly_dependent_set_has_its_unique_lambda() {
    let crank = SliderCrank::new(1.0, 0.5, 0.3, 1.0, 2.0, 9.81);
    let mut checked = 0;
    for s in random_states(5) {
        if constrained::ConstrainedSystem::constraint_residual(&crank, &s).amax() < 1e-3 {
            continue;
        }
        let (_, force) = Generated::gauss(&crank, &s.q, &s.qd, s.t, None).expect("a solve");
        let (a, _) = Generated::constraint_matrices(&crank, &s.q, &s.qd, s.t);
        let reference = multipliers(&a, &force).expect("λ of Aᵀλ = Fᶜ");
        let (_, lambda) = crank.acceleration_and_multipliers(&s).expect("q̈ and λ");
        let gap = (lambda - reference).amax() / reference.amax();
        assert!(gap < 1e-8, "{gap:e}");
        checked += 1;
    }
    assert!(checked >= 12, "{checked} states off the constraints");
}

/// `random_states(seed)` projected onto the constraints (positions, then
/// velocities), where the redundant rows are dependent.
fn consistent<S, const N: usize, const K: usize>(system: &S, seed: u64) -> Vec<State<f64, N>>
where
    S: constrained::ConstrainedSystem<f64, N, K>,
{
    let states: Vec<State<f64, N>> = random_states(seed)
        .into_iter()
        .filter_map(|mut s| {
            constrained::stabilize::project(system, &mut s, 1e-13, 50).ok()?;
            Some(s)
        })
        .collect();
    assert!(states.len() >= 12, "{} states projected", states.len());
    states
}

constrained::constrained_system! {
    /// A planar arm of three links on bodies (`M(q)` factored) whose tip is
    /// held in `x` and `z`, and again by a combination of the two: three
    /// rows of rank two.
    pub struct HeldArm {
        bodies: [
            upper {
                joint: revolute(q1, [0.0, 1.0, 0.0]),
                mass: 1.2,
                com: [0.15, 0.0, 0.01],
                inertia: diag[0.002, 0.011, 0.010],
            },
            fore {
                parent: upper,
                joint: revolute(q2, [0.0, 1.0, 0.0]),
                xyz: [0.3, 0.0, 0.0],
                mass: 0.9,
                com: [0.12, 0.0, -0.01],
                inertia: diag[0.001, 0.008, 0.007],
            },
            hand {
                parent: fore,
                joint: revolute(q3, [0.0, 1.0, 0.0]),
                xyz: [0.25, 0.0, 0.0],
                mass: 0.4,
                com: [0.05, 0.0, 0.0],
                inertia: diag[0.0004, 0.001, 0.001],
            },
        ],
        constraints: [
            position(hand, [0.1, 0.0, 0.0]).x == 0.35,
            position(hand, [0.1, 0.0, 0.0]).z == 0.2,
            position(hand, [0.1, 0.0, 0.0]).x + 2.0 * position(hand, [0.1, 0.0, 0.0]).z == 0.75,
        ],
    }
}

constrained::constrained_system! {
    /// A slab on a free joint resting on its four corners (`z = 0` each):
    /// four rows and the quaternion's norm, of rank four, through the
    /// auxiliary mass; it slides and turns about the vertical.
    pub struct SlidingSlab {
        bodies: [
            slab {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: 2.0,
                com: [0.01, -0.02, 0.03],
                inertia: [[0.02, 0.001, 0.0], [0.001, 0.03, -0.002], [0.0, -0.002, 0.04]],
            },
        ],
        constraints: [
            position(slab, [0.2, 0.1, -0.05]).z == 0.0,
            position(slab, [-0.2, 0.1, -0.05]).z == 0.0,
            position(slab, [0.2, -0.1, -0.05]).z == 0.0,
            position(slab, [-0.2, -0.1, -0.05]).z == 0.0,
        ],
    }
}

/// The slab flat on its corners, slid and turned about the vertical, and
/// moving within the table's plane.
fn slab_states() -> Vec<State<f64, 7>> {
    let mut x = 29u64;
    (0..24)
        .map(|_| {
            let yaw = 3.0 * uniform(&mut x);
            let q = SVector::from_column_slice(&[
                uniform(&mut x),
                uniform(&mut x),
                0.05,
                (yaw / 2.0).cos(),
                0.0,
                0.0,
                (yaw / 2.0).sin(),
            ]);
            // ż = 0 and ω about the vertical: q̇ of the quaternion is
            // ½ q ⊗ (0, 0, 0, ω).
            let w = 2.0 * uniform(&mut x);
            let qd = SVector::from_column_slice(&[
                uniform(&mut x),
                uniform(&mut x),
                0.0,
                -0.5 * (yaw / 2.0).sin() * w,
                0.0,
                0.0,
                0.5 * (yaw / 2.0).cos() * w,
            ]);
            State::new(0.0, q, qd)
        })
        .collect()
}

/// Redundant sets solved with `M(q)` factored (an arm on bodies, a free
/// body through its auxiliary mass): the generated solve's `λ` is the
/// minimum-norm one, from `S`'s own factors, and agrees with the
/// runtime's minimum norm (an SVD of `A`) from the same force.
#[test]
fn a_redundant_set_on_bodies_has_the_minimum_norm_lambda_from_the_solve() {
    let held = multipliers_gap::<_, 3, 3>(&HeldArm::new(), &random_states(23), true);
    check("HeldArm (a row repeated)", held);
    let slab = multipliers_gap::<_, 7, 5>(&SlidingSlab::new(), &slab_states(), true);
    check("SlidingSlab (four corners)", slab);
}
