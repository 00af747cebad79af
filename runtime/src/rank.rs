//! The rank decision, checked after the fact.
//!
//! The fast solve of `S λ = r` drops a constraint whose pivot falls below
//! [`rank_tolerance`] (a loose `sin²θ < 1e-6`, [`crate::inverse`]). That is
//! right for redundancy, and wrong near a branch point: a four-bar linkage
//! close to its collinear configuration still has a full-rank `A` at
//! `θ = 1e-4`, but `sin²θ ≈ 3e-10` there, and dropping the row returned a
//! `q̈` that violates `A q̈ = b` by `1.8 θ` relative. So a drop is accepted
//! only when one of these holds:
//!
//! 1. **The drop is the redundancy of the model.** The macro measures the
//!    rank `r` of `A` at consistent states at compile time
//!    (`Generated::GENERIC_RANK`). Keeping `r` rows is what a redundant model
//!    does everywhere on its constraint surface, and near it, where an
//!    integrator's stages sit and the redundant rows are only weakly
//!    independent (enforcing them there gives spurious forces). Unless a
//!    kept row is itself nearly dependent on the rows before it (its
//!    pivot's `sin²θ` below [`conditioning_tolerance`]): the rows dropped
//!    then hold only to rounding grown by `1/sin²θ`, and rule 2 decides.
//! 2. **The dropped rows are satisfied anyway.** Every row's residual after
//!    the solve, `|Aᵢ q̈ − bᵢ|`, is at most [`consistency_tolerance`] times
//!    its scale `Σⱼ |Aᵢⱼ q̈ⱼ| + |bᵢ|`.
//!
//! Otherwise the acceleration is recomputed by the minimum-norm solve: the
//! Moore–Penrose form on the rows scaled to unit size (no squaring of `A`,
//! so no loss of the small singular values, and no underflow of `A M⁻¹ Aᵀ`
//! for tiny coordinates in `f32`), keeping every singular value above
//! rounding level, at most `r` of them. A row kept near a branch point gives
//! the large, physical constraint force.
//!
//! Where the recomputation does not satisfy `A q̈ = b` either (it has no
//! solution here — exactly at a singular configuration with an inconsistent
//! `b` — or none that `T` resolves, e.g. masses 1e150 apart), the `Result`
//! methods return `Err(DynamicsError::Unsatisfiable)` and the plain-valued
//! ones (constant positive definite `M`) the [`least_squares`] solution
//! (never NaN for finite input, unless it is not representable).
//!
//! The verdicts measure the backward error: a row holds when its residual
//! is at most `1000 ε` of `‖Aᵢ‖₁ max(‖a‖, ‖z‖, ‖q̈‖) + |bᵢ|`, the size of
//! the terms the solve summed (`q̈ = a + z`). Where `a` and `z` nearly cancel
//! (a particle resting on a surface, or a light trolley under a 1e154 kg
//! load) `q̈` is the exact answer of data perturbed by `ε`, not `q̈` to
//! `ε` of itself.
//!
//! Limits, for *redundant* models: near a branch point a drop of no more
//! rows than the model's redundancy is accepted unchecked (rule 1), the
//! recomputation keeps the `r` strongest directions without a final check
//! (off the surface the rows it drops are violated by design).

use crate::generated::{effective_mass, Generated, Motion};
use crate::inverse::rank_tolerance;
use crate::svd::JacobiSvd;
use crate::DynamicsError;
use nalgebra::{RealField, SMatrix, SVector};

/// The largest relative row residual accepted after a row was dropped:
/// `1000 ε` (2.2e-13 in `f64`, 1.2e-4 in `f32`).
#[inline]
pub fn consistency_tolerance<T: RealField + Copy>() -> T {
    T::default_epsilon() * nalgebra::convert::<f64, T>(1000.0)
}

/// Where a redundant set keeps as many rows as its rank, a kept row whose
/// pivot's `sin²θ` is below this (`10⁻³`, a thousand times the rank
/// tolerance) is nearly dependent on the rows before it: the kept system is
/// ill-conditioned and the dropped rows hold only to rounding grown by
/// `1/sin²θ`. Such a decision is verified by rule 2 like a drop, and a
/// violated row sends `q̈` to the minimum-norm solve, which keeps the
/// strongest directions whatever the attitude. The saddle-point solves test
/// each multiplier's pivot against the same bound (below it, the dense
/// solve answers).
#[inline]
pub fn conditioning_tolerance<T: RealField + Copy>() -> T {
    nalgebra::convert::<f64, T>(1e-3)
}

/// Below this, a diagonal entry of `S = A M⁻¹ Aᵀ` may have lost its
/// precision to underflow (`ε⁴`: 1.9e-28 in `f32`, 2.4e-63 in `f64`), and a
/// kept pivot is verified like a dropped one.
#[inline]
pub fn safe_minimum<T: RealField + Copy>() -> T {
    let eps = T::default_epsilon();
    (eps * eps) * (eps * eps)
}

/// `maxᵢ |Aᵢ q̈ − bᵢ| / (‖Aᵢ‖₁ ‖q̈‖∞ + |bᵢ|)`: how far `q̈` is from
/// satisfying each row of `A q̈ = b`, relative to the size its terms can
/// have (rounding in `q̈` is relative to `‖q̈‖`, not to the components the
/// row happens to touch; 0 for a row whose terms all vanish). NaN input
/// gives NaN.
pub fn relative_residual<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    qdd: &SVector<T, N>,
) -> T {
    relative_residual_at(a, b, qdd, qdd.amax())
}

/// [`relative_residual`] with the accelerations' size given: a solve that
/// formed `q̈ = a + z` rounds at the size of `max(‖a‖, ‖z‖)`, not of `q̈`
/// (a particle resting on a surface has `q̈ ≈ 0` from `a = g` and `z = −g`),
/// so its backward error is measured against that.
pub fn relative_residual_at<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    qdd: &SVector<T, N>,
    size: T,
) -> T {
    let mut worst = T::zero();
    for i in 0..K {
        let (mut value, mut row) = (-b[i], T::zero());
        for j in 0..N {
            value += a[(i, j)] * qdd[j];
            row += a[(i, j)].abs();
        }
        let scale = row * size + b[i].abs();
        let relative = if scale > T::zero() {
            value.abs() / scale
        } else {
            value.abs()
        };
        #[allow(clippy::eq_op)] // NaN is the one value unequal to itself
        if relative != relative {
            return relative;
        }
        if relative > worst {
            worst = relative;
        }
    }
    worst
}

/// The fast solve's acceleration `candidate`, called when it kept fewer
/// rows than `GENERIC_RANK` (or `S` underflowed; the caller decides, rule 1
/// of the module docs), checked by rule 2: `None` when it stands (the
/// caller keeps its own `q̈` and constraint force), else the minimum-norm
/// recomputation, itself checked: `Err(Unsatisfiable)` when it does not
/// satisfy `A q̈ = b` either (no solution here, or none that `T` can
/// resolve), and the recomputation's error where it cannot be done
/// (non-finite input).
///
/// The rare path: kept out of line, so that the fast solve it guards stays
/// as small as it was (and the constraint force, when not asked for, is
/// still never computed).
#[cold]
#[inline(never)]
pub fn checked<T, S, const N: usize, const K: usize>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    correction: Option<&SVector<T, K>>,
    candidate: SVector<T, N>,
) -> Option<Result<Motion<T, N>, DynamicsError>>
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    let (a, b) = corrected_constraints(system, q, qd, t, correction);
    if relative_residual(&a, &b, &candidate) <= consistency_tolerance() {
        return None;
    }
    let cut = tight_cut::<T, N, K>();
    let (motion, size) = match minimum_norm_motion(system, q, qd, t, &a, &b, cut, S::GENERIC_RANK) {
        Ok(solved) => solved,
        Err(error) => return Some(Err(error)),
    };
    // A redundant model keeps its r strongest directions, and the rows it
    // drops off its surface are violated by design (rule 1): only a model
    // without redundancy can be held to every row.
    if S::GENERIC_RANK < K
        || relative_residual_at(&a, &b, &motion.0, size) <= consistency_tolerance()
    {
        Some(Ok(motion))
    } else {
        Some(Err(DynamicsError::Unsatisfiable))
    }
}

/// `(A, b + correction)` at the state: the constraints a solve must satisfy.
pub(crate) fn corrected_constraints<T, S, const N: usize, const K: usize>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    correction: Option<&SVector<T, K>>,
) -> (SMatrix<T, K, N>, SVector<T, K>)
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    let (a, b) = system.constraint_matrices(q, qd, t);
    match correction {
        Some(db) => (a, b + db),
        None => (a, b),
    }
}

/// What the total (plain-valued) methods return where [`checked`] fails:
/// the least-squares solution of the row-scaled `A q̈ = b` (minimum norm in
/// the metric of `M`), NaN only where it is not representable.
#[cold]
#[inline(never)]
pub fn least_squares<T, S, const N: usize, const K: usize>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    correction: Option<&SVector<T, K>>,
) -> Motion<T, N>
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    let (a, b) = corrected_constraints(system, q, qd, t, correction);
    let cut = tight_cut::<T, N, K>();
    match minimum_norm_motion(system, q, qd, t, &a, &b, cut, S::GENERIC_RANK) {
        Ok((motion, _)) => motion,
        Err(_) => {
            let nan = SVector::from_element(T::zero() / T::zero());
            (nan, nan)
        }
    }
}

/// `q̈ = a + L⁻ᵀ (D A L⁻ᵀ)⁺ D (b − A a)` with `M = L Lᵀ` (or the auxiliary
/// mass of a semi-definite `M`) and `D` scaling each row of `A` to unit
/// largest entry, which changes nothing in `A q̈ = b` but keeps the SVD away
/// from overflow and underflow. Singular values at or below `relative_cut`
/// times the largest count as zero, and so do all but the `max_rank`
/// largest. Returns `(q̈, Fᶜ)` and the size of the accelerations it
/// summed, `max(‖a‖, ‖z‖, ‖q̈‖)`, for [`relative_residual_at`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn minimum_norm_motion<T, S, const N: usize, const K: usize>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    relative_cut: T,
    max_rank: usize,
) -> Result<(Motion<T, N>, T), DynamicsError>
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    // A non-finite row would vanish from the SVD's rank and the constraint
    // with it: say so instead.
    if !(a.iter().all(|x| x.is_finite()) && b.iter().all(|x| x.is_finite())) {
        return Err(DynamicsError::NonFinite);
    }
    let (m, f) = (system.mass_matrix(q, t), system.forces(q, qd, t));
    // An overflowed M or F would be solved as a limit (1/∞ = 0): say so.
    if !(m.iter().all(|x| x.is_finite()) && f.iter().all(|x| x.is_finite())) {
        return Err(DynamicsError::NonFinite);
    }
    let (m_eff, f_eff) = effective_mass::<T, S, N, K>(&m, &f, a, b);
    let chol =
        nalgebra::linalg::Cholesky::new(m_eff).ok_or(DynamicsError::MassNotPositiveDefinite)?;
    let acc = chol.solve(&f_eff);
    if K == 0 {
        return Ok(((acc, SVector::zeros()), acc.amax()));
    }
    let (mut scaled_a, mut scaled_r) = (*a, b - a * acc);
    for i in 0..K {
        // Divided, not multiplied by the reciprocal, which overflows for
        // a subnormal row.
        let largest = scaled_a.row(i).amax();
        if largest > T::zero() {
            scaled_a.row_mut(i).unscale_mut(largest);
            scaled_r[i] /= largest;
        }
    }
    let l = chol.l();
    // X = D A L⁻ᵀ, computed as Xᵀ = L⁻¹ (D A)ᵀ.
    let xt = l
        .solve_lower_triangular(&scaled_a.transpose())
        .ok_or(DynamicsError::MassNotPositiveDefinite)?;
    let svd = JacobiSvd::new(&xt.transpose()).ok_or(DynamicsError::NonFinite)?;
    let cut = singular_value_cut(svd.singular_values(), relative_cut, max_rank);
    let y = svd.solve(&scaled_r, cut).ok_or(DynamicsError::NonFinite)?;
    let z = l
        .transpose()
        .solve_upper_triangular(&y)
        .ok_or(DynamicsError::MassNotPositiveDefinite)?;
    let qdd = acc + z;
    let force = if S::SEMIDEFINITE_MASS {
        m * qdd - f
    } else {
        l * y // M z = L Lᵀ L⁻ᵀ y
    };
    let size = acc.amax().max(z.amax()).max(qdd.amax());
    Ok(((qdd, force), size))
}

/// The threshold at or below which the singular values `sigma` count as
/// zero: `relative_cut` times the largest, raised so that at most
/// `max_rank` of them stay (the `(max_rank + 1)`-th largest and all below
/// it go).
fn singular_value_cut<T: RealField + Copy, const K: usize>(
    sigma: SVector<T, K>,
    relative_cut: T,
    max_rank: usize,
) -> T {
    let mut cut = relative_cut * sigma.max();
    if max_rank < K {
        let mut sorted = sigma;
        sorted
            .as_mut_slice()
            .sort_unstable_by(|x, y| y.partial_cmp(x).unwrap_or(core::cmp::Ordering::Equal));
        if let Some(&next) = sorted.get(max_rank) {
            cut = cut.max(next);
        }
    }
    cut
}

/// The Moore–Penrose form of eq. 24 (`acceleration_moore_penrose`):
/// the row-scaled minimum-norm solve with singular values below `√rank_tolerance` of
/// the largest counted as zero (the same `sin θ` threshold as the default
/// {1}-inverse).
pub fn moore_penrose<T, S, const N: usize, const K: usize>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
) -> Result<SVector<T, N>, DynamicsError>
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    let (a, b) = system.constraint_matrices(q, qd, t);
    let cut = rank_tolerance::<T>().sqrt();
    let ((qdd, _), size) = minimum_norm_motion(system, q, qd, t, &a, &b, cut, K)?;
    // The cut is a rank decision like the fast solve's, checked the same way.
    if relative_residual_at(&a, &b, &qdd, size) <= consistency_tolerance() {
        return Ok(qdd);
    }
    let ((qdd, _), size) = minimum_norm_motion(
        system,
        q,
        qd,
        t,
        &a,
        &b,
        tight_cut::<T, N, K>(),
        S::GENERIC_RANK,
    )?;
    // The Moore–Penrose form is the least-squares reading of inconsistent
    // constraints: its answer must satisfy them, or be that least-squares one.
    if relative_residual_at(&a, &b, &qdd, size) <= consistency_tolerance()
        || least_squares_holds(&a, &b, &qdd)
    {
        Ok(qdd)
    } else {
        Err(DynamicsError::Unsatisfiable)
    }
}

/// The normal equations of the row-scaled least-squares problem,
/// `‖Aᵀ D² (A q̈ − b)‖ ≤ √ε ‖D A‖ ‖D (A q̈ − b)‖`.
fn least_squares_holds<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    qdd: &SVector<T, N>,
) -> bool {
    let (mut da, mut r) = (*a, a * qdd - b);
    for i in 0..K {
        let largest = da.row(i).amax();
        if largest > T::zero() {
            da.row_mut(i).unscale_mut(largest);
            r[i] /= largest;
        }
    }
    (da.transpose() * r).norm() <= T::default_epsilon().sqrt() * da.norm() * r.norm()
}

/// The relative singular-value cut of the recomputation: rounding level,
/// `4 (N + K) ε`.
pub(crate) fn tight_cut<T: RealField + Copy, const N: usize, const K: usize>() -> T {
    T::default_epsilon() * nalgebra::convert::<f64, T>((4 * (N + K)) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2x3, Vector2, Vector3};

    #[test]
    fn relative_residual_is_scale_free_and_zero_for_exact_rows() {
        let a = Matrix2x3::new(1.0, 2.0, 0.0, 0.0, 1e-30, 1e-30);
        let qdd = Vector3::new(1.0, 1.0, 1.0);
        let b = Vector2::new(3.0, 2e-30);
        assert_eq!(relative_residual(&a, &b, &qdd), 0.0);
        // Off by 1% of its own terms in the tiny row.
        let b = Vector2::new(3.0, 2e-30 * 1.01);
        let r: f64 = relative_residual(&a, &b, &qdd);
        assert!((r - 0.02 / 4.02).abs() < 1e-12, "{r}");
        // The scale is ‖Aᵢ‖₁ ‖q̈‖∞: a row touching only a vanishing
        // component is not judged against that component alone.
        let a = Matrix2x3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
        let qdd = Vector3::new(3.0, 1e-16, 0.0);
        let r: f64 = relative_residual(&a, &Vector2::new(3.0, 0.0), &qdd);
        assert!((r - 1e-16 / 3.0).abs() < 1e-30, "{r}");
        assert!(relative_residual(&a, &Vector2::new(f64::NAN, 0.0), &qdd).is_nan());
    }

    #[test]
    fn tolerances_in_f32_and_f64() {
        assert!((consistency_tolerance::<f64>() - 2.22e-13).abs() < 1e-15);
        assert!((consistency_tolerance::<f32>() - 1.19e-4).abs() < 1e-6);
        assert!(safe_minimum::<f32>() > 0.0 && safe_minimum::<f32>() < 1e-27);
    }
}
