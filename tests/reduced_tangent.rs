//! `linearize_reduced` against the constraint manifold itself (issue 30's
//! fuzz family): at pseudo-random consistent states of every holonomic
//! reference model, each column of the reduced `a` equals central
//! differences of the reduced flow `ẋᵣ = (q̇[coordinates], q̈[speeds])`,
//! where a perturbed reduced state is completed into a consistent full
//! state independently of the library's Jacobians: the dependent
//! coordinates by Gauss–Newton on the position constraints `φ(q) = 0`, the
//! dependent velocities by least squares on the velocity constraints, both
//! with nalgebra's SVD.

use super::linearize::consistent;
use constrained::models::*;
use constrained::nalgebra::{DMatrix, DVector, SMatrix};
use constrained::{ConstrainedSystem, ConstraintLevel, State};

/// `q` with the coordinates not in `free` moved onto `φ(q) = 0` (the
/// position-level rows), by Gauss–Newton with the SVD's least-squares step,
/// which also serves redundant rows.
fn complete_coordinates<S, const N: usize, const K: usize>(
    system: &S,
    state: &mut State<f64, N>,
    free: &[usize],
) where
    S: ConstrainedSystem<f64, N, K>,
{
    let rows: Vec<usize> = (0..K)
        .filter(|&i| S::CONSTRAINT_LEVELS[i] == ConstraintLevel::Position)
        .collect();
    let dependent: Vec<usize> = (0..N).filter(|j| !free.contains(j)).collect();
    for _ in 0..50 {
        let phi = system.constraint_residual(state);
        let (a, _) = system.constraint_matrices(state);
        let r = DVector::from_iterator(rows.len(), rows.iter().map(|&i| -phi[i]));
        if r.amax() < 1e-15 {
            return;
        }
        let jac = DMatrix::from_fn(rows.len(), dependent.len(), |i, j| {
            a[(rows[i], dependent[j])]
        });
        let step = jac.svd(true, true).solve(&r, 1e-12).expect("an SVD step");
        for (k, &j) in dependent.iter().enumerate() {
            state.q[j] += step[k];
        }
    }
    panic!("Gauss–Newton did not reach the manifold");
}

/// `q̇` with the velocities not in `free` chosen so that every velocity
/// constraint holds (they are affine in `q̇`, with `A` as their Jacobian).
fn complete_velocities<S, const N: usize, const K: usize>(
    system: &S,
    state: &mut State<f64, N>,
    free: &[usize],
) where
    S: ConstrainedSystem<f64, N, K>,
{
    let dependent: Vec<usize> = (0..N).filter(|j| !free.contains(j)).collect();
    for _ in 0..3 {
        let residual = system.constraint_velocity_residual(state);
        let (a, _) = system.constraint_matrices(state);
        let jac = DMatrix::from_fn(K, dependent.len(), |i, j| a[(i, dependent[j])]);
        let r = DVector::from_iterator(K, residual.iter().map(|x| -x));
        let step = jac.svd(true, true).solve(&r, 1e-12).expect("an SVD step");
        for (k, &j) in dependent.iter().enumerate() {
            state.qd[j] += step[k];
        }
    }
}

/// The reduced flow at the reduced state `x` near `base`.
fn reduced_flow<S, const N: usize, const K: usize>(
    system: &S,
    base: &State<f64, N>,
    coordinates: &[usize],
    speeds: &[usize],
    x: &[f64],
) -> Vec<f64>
where
    S: ConstrainedSystem<f64, N, K>,
{
    let mut state = *base;
    for (k, &j) in coordinates.iter().enumerate() {
        state.q[j] = x[k];
    }
    complete_coordinates(system, &mut state, coordinates);
    for (k, &j) in speeds.iter().enumerate() {
        state.qd[j] = x[coordinates.len() + k];
    }
    complete_velocities(system, &mut state, speeds);
    let qdd = system.acceleration(&state).expect("a motion near the base");
    coordinates
        .iter()
        .map(|&j| state.qd[j])
        .chain(speeds.iter().map(|&j| qdd[j]))
        .collect()
}

/// The largest difference between `a` and central differences of the
/// reduced flow, against the scale of `a`.
fn tangent_error<S, const N: usize, const K: usize, const NX: usize>(
    system: &S,
    base: &State<f64, N>,
    a: &SMatrix<f64, NX, NX>,
    coordinates: &[usize],
    speeds: &[usize],
) -> f64
where
    S: ConstrainedSystem<f64, N, K>,
{
    let x: Vec<f64> = coordinates
        .iter()
        .map(|&j| base.q[j])
        .chain(speeds.iter().map(|&j| base.qd[j]))
        .collect();
    let scale = a.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for c in 0..NX {
        let h = 1e-6 * x[c].abs().max(1.0);
        let (mut plus, mut minus) = (x.clone(), x.clone());
        plus[c] += h;
        minus[c] -= h;
        let fp = reduced_flow(system, base, coordinates, speeds, &plus);
        let fm = reduced_flow(system, base, coordinates, speeds, &minus);
        for r in 0..NX {
            let difference = (fp[r] - fm[r]) / (2.0 * h);
            worst = worst.max((a[(r, c)] - difference).abs() / scale);
        }
    }
    worst
}

macro_rules! check_reduced {
    ($model:ident, $n:literal, $k:literal, [$($p:expr),*]) => {{
        let system = $model::new($($p),*);
        let mut worst = 0.0f64;
        for seed in 0..12u64 {
            let base = consistent::<_, $n, $k>(&system, 1000 + seed);
            let reduced = system
                .linearize_reduced(&base.q, &base.qd, base.t)
                .expect("a generic state");
            let e = tangent_error::<_, $n, $k, _>(
                &system,
                &base,
                &reduced.a,
                &reduced.coordinates,
                &reduced.speeds,
            );
            assert!(
                e < 1e-6,
                "{} seed {seed}: reduced a off the manifold's tangent by {e:e}",
                stringify!($model)
            );
            worst = worst.max(e);
        }
        println!("{:<24} largest relative difference {worst:.1e}", stringify!($model));
    }};
}

/// The models with redundant rows (`RedundantDoublePendulum`,
/// `SliderCrank`) are not here: their `linearize_reduced` answers
/// `Err(SingularPartition)` at consistent states (an error, not a wrong
/// answer; the reduced form of a redundant set is still to do).
#[test]
fn reduced_linearization_is_the_manifolds_tangent_for_every_holonomic_model() {
    check_reduced!(DoublePendulum, 4, 2, [1.0, 2.0, 1.0, 0.8, 9.81]);
    check_reduced!(SphericalPendulum, 3, 1, [1.5, 9.81, 1.2]);
    check_reduced!(CartPoleCartesian, 3, 1, [1.0, 0.3, 0.8, 9.81, 0.4]);
    check_reduced!(TwoLinkArmOnLine, 2, 1, [1.0, 0.5, 1.0, 1.0, 9.81, 0.5]);
}
