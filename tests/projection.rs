//! The projections' Newton step through the generated factorizations
//! (`ConstrainedSystem::constraint_step`, used by `stabilize::project`)
//! against the dense step computed here, `M⁻¹Aᵀ (A M⁻¹ Aᵀ)⁺ r`, for every
//! reference model with constraints and a non-singular `M`. `r = A v`
//! lies in the range of `A`, so every {1}-inverse gives the same step (the
//! `M`-orthogonal projection of `v` onto the row space of `A`), redundant
//! rows included.

use constrained::models::*;
use constrained::nalgebra::{DMatrix, SVector};
use constrained::stabilize::project;
use constrained::{ConstrainedSystem, State};
use constrained_chains::{Chain2, Chain8};

fn dense_step<S, const N: usize, const K: usize>(
    system: &S,
    state: &State<f64, N>,
    r: &SVector<f64, K>,
) -> SVector<f64, N>
where
    S: ConstrainedSystem<f64, N, K>,
{
    let m = system.mass_matrix(state);
    let (a, _) = system.constraint_matrices(state);
    let minv_at = m
        .cholesky()
        .expect("M is positive definite")
        .solve(&a.transpose());
    let gram = DMatrix::from_fn(K, K, |i, j| (a * minv_at)[(i, j)]);
    let pinv = gram.pseudo_inverse(1e-12).expect("SVD converges");
    let mu = &pinv * DMatrix::from_fn(K, 1, |i, _| r[i]);
    SVector::<f64, N>::from_fn(|i, _| (0..K).map(|j| minv_at[(i, j)] * mu[(j, 0)]).sum())
}

fn next(x: &mut u64) -> f64 {
    *x = x
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*x >> 11) as f64 / (1u64 << 53) as f64) - 0.5
}

macro_rules! same {
    ($worst:expr, $model:ident, $n:literal, $k:literal, [$($p:expr),*]) => {{
        let system = $model::<f64>::new($($p),*);
        let mut worst = 0.0f64;
        for seed in 1..=5u64 {
            let mut x = seed;
            let q = SVector::<f64, $n>::from_fn(|_, _| next(&mut x) + 0.3);
            let qd = SVector::<f64, $n>::from_fn(|_, _| 2.0 * next(&mut x));
            let mut state = State::new(0.25, q, qd);
            project(&system, &mut state, 1e-13, 50).expect("a consistent state");
            let (a, _) = ConstrainedSystem::<f64, $n, $k>::constraint_matrices(&system, &state);
            let v = SVector::<f64, $n>::from_fn(|_, _| next(&mut x));
            let r = a * v;
            let (generated, kept) = ConstrainedSystem::<f64, $n, $k>::constraint_step(&system, &state, &r)
                .expect(concat!(stringify!($model), ": the generated step answers at a generic state"));
            assert!(kept.iter().filter(|&&k| k).count() > 0);
            let dense = dense_step::<_, $n, $k>(&system, &state, &r);
            worst = worst.max((generated - dense).amax() / dense.amax().max(1e-300));
        }
        println!("{:<28} generated step vs dense {worst:.1e}", stringify!($model));
        assert!(worst < 1e-9, "{}: {worst:e}", stringify!($model));
        $worst = $worst.max(worst);
    }};
}

#[test]
fn the_generated_step_is_the_dense_one() {
    let mut worst = 0.0f64;
    same!(worst, Appell, 3, 1, [9.81, 0.7]);
    same!(worst, SphericalPendulum, 3, 1, [1.5, 9.81, 1.2]);
    same!(worst, DoublePendulum, 4, 2, [1.0, 2.0, 1.0, 0.8, 9.81]);
    same!(
        worst,
        RedundantDoublePendulum,
        4,
        3,
        [1.0, 2.0, 1.0, 0.8, 9.81]
    );
    same!(worst, BeadOnRotatingHoop, 3, 2, [0.5, 9.81, 1.0, 2.0]);
    same!(worst, ChaplyginSleigh, 3, 1, [2.0, 0.4, 0.3, 0.0]);
    same!(worst, SliderCrank, 4, 4, [1.0, 2.0, 0.5, 1.5, 3.0, 9.81]);
    same!(
        worst,
        TwoLinkArmOnLine,
        2,
        1,
        [1.0, 0.5, 1.0, 1.0, 9.81, 0.5]
    );
    same!(worst, CartPoleCartesian, 3, 1, [1.0, 0.3, 0.8, 9.81, 0.0]);
    same!(worst, RollingDisk, 5, 2, [1.0, 0.5, 0.06, 0.12, 9.81]);
    same!(
        worst,
        ParallelogramFourBarAngles,
        3,
        2,
        [1.2, 0.15, 1.0, 2.0, 9.81]
    );
    // Constant masses: the entries of W are sums (x₁ − x₂ over a mass).
    same!(worst, Chain2, 4, 2, [9.81]);
    same!(worst, Chain8, 16, 8, [9.81]);
    println!("largest relative difference {worst:.1e}");
}

/// A semi-definite `M` has no generated step: the runtime's dense one.
#[test]
fn a_singular_mass_has_no_generated_step() {
    let top = RigidBodyQuaternion::<f64>::new(1.0, 2.0, 3.0);
    let state = State::new(
        0.0,
        SVector::<f64, 4>::new(1.0, 0.0, 0.0, 0.0),
        SVector::zeros(),
    );
    let r = SVector::<f64, 1>::new(0.1);
    assert!(ConstrainedSystem::<f64, 4, 1>::constraint_step(&top, &state, &r).is_none());
}
