//! Impacts: the impulsive form of Gauss's principle.
//!
//! At an impact the velocities jump while the positions stay. The
//! post-impact velocity `q̇⁺` is the one closest to the pre-impact `q̇⁻` in
//! the kinetic-energy metric,
//!
//! ```text
//! minimise ½ (q̇⁺ − q̇⁻)ᵀ M (q̇⁺ − q̇⁻)   subject to   A q̇⁺ = c,
//! ```
//!
//! where each row of `A q̇⁺ = c` is an impacting contact with Newton's law
//! (`∇gᵢ · q̇⁺ = −e ∇gᵢ · q̇⁻`) or a persistent constraint at velocity level
//! (its residual `φ̇` brought to zero). It is eq. 24 of the equation of
//! motion with velocities for accelerations (the mathematics guide,
//! `docs/math.md`, "Impacts"):
//!
//! ```text
//! q̇⁺ = q̇⁻ + M⁻¹ Aᵀ λ,   (A M⁻¹ Aᵀ) λ = c − A q̇⁻,   impulse P = M (q̇⁺ − q̇⁻) = Aᵀ λ.
//! ```
//!
//! # The rank rule
//! The same as `acceleration`'s (`constrained::rank`): `λ` by the pivoted
//! `LDLᵀ` {1}-inverse of `A M⁻¹ Aᵀ`, which drops rows within about 1e-3 rad
//! of the others ([`crate::inverse::rank_tolerance`]); the drop stands when
//! every row of `A q̇⁺ = c` holds to [`consistency_tolerance`] (relative,
//! backward error) anyway. Otherwise `q̇⁺` is recomputed by the row-scaled
//! minimum-norm solve (SVD of `D A L⁻ᵀ`, singular values above rounding
//! level kept), and where that does not satisfy the rows either — they
//! contradict each other, e.g. two parallel contacts asked for different
//! rebound velocities — the result is `Err(DynamicsError::Unsatisfiable)`.
//! A redundant but consistent set (a contact whose rows repeat a persistent
//! constraint's) is solved, with the impulse shared as the {1}-inverse
//! shares it (the generalized impulse `P` is unique; the per-row split of
//! dependent rows is not).
//!
//! A positive semi-definite `M` (a body in unit quaternions) is replaced by
//! Udwadia & Schutte's `M + s AᵀA`, which has the same minimiser on
//! `A q̇⁺ = c` (the added term is constant there) and is definite where
//! `[M; A]` has full column rank.

use crate::generated::auxiliary_mass;
use crate::inverse::PivotedLdlt;
use crate::rank::{consistency_tolerance, relative_residual_at, tight_cut};
use crate::svd::JacobiSvd;
use crate::DynamicsError;
use nalgebra::linalg::Cholesky;
use nalgebra::{Const, RealField, SMatrix, SVector};

/// The result of an impact: the post-impact velocities and the impulse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impact<T, const N: usize, const R: usize> {
    /// `q̇⁺`.
    pub qd: SVector<T, N>,
    /// The generalized impulse `P = M (q̇⁺ − q̇⁻) = Aᵀ λ`.
    pub impulse: SVector<T, N>,
    /// `λ`, one per row (zero for rows that took no part): the impulse
    /// each row applied, in the units of the row (for a gap with a unit
    /// normal gradient, the contact impulse).
    pub row_impulses: SVector<T, R>,
}

/// The impact map: `q̇⁺` closest to `qd` in the metric of `m` with
/// `A q̇⁺ = target` on the rows where `rows` is `true` (module docs).
///
/// Rows marked `false` are left out entirely (their velocity is free).
/// Errors: `NonFinite` for non-finite input, `MassNotPositiveDefinite`
/// when neither `M` nor `M + s AᵀA` is definite, `Unsatisfiable` when the
/// rows contradict each other at working precision.
///
/// ```
/// use constrained_runtime::impact::impact_map;
/// use nalgebra::{Matrix1x2, Matrix2, Vector1, Vector2};
/// // Two unit masses on a line, the first at 1 m/s, the second at rest;
/// // the gap x₂ − x₁ ≥ 0 closes with restitution 1/2.
/// let (m, a) = (Matrix2::<f64>::identity(), Matrix1x2::new(-1.0, 1.0));
/// let qd = Vector2::new(1.0, 0.0);
/// let e = 0.5;
/// let target = Vector1::new(-e * (a * qd)[0]);
/// let hit = impact_map(&m, &a, &target, &[true], &qd).unwrap();
/// assert!((hit.qd - Vector2::new(0.25, 0.75)).amax() < 1e-15); // momentum 1
/// assert!((hit.row_impulses[0] - 0.75).abs() < 1e-15);
/// ```
pub fn impact_map<T, const N: usize, const R: usize>(
    m: &SMatrix<T, N, N>,
    a: &SMatrix<T, R, N>,
    target: &SVector<T, R>,
    rows: &[bool; R],
    qd: &SVector<T, N>,
) -> Result<Impact<T, N, R>, DynamicsError>
where
    T: RealField + Copy,
{
    let a = SMatrix::<T, R, N>::from_fn(|i, j| if rows[i] { a[(i, j)] } else { T::zero() });
    let c = SVector::<T, R>::from_fn(|i, _| if rows[i] { target[i] } else { T::zero() });
    let finite = |x: &T| x.is_finite();
    let all_finite = m.iter().all(finite)
        && a.iter().all(finite)
        && c.iter().all(finite)
        && qd.iter().all(finite);
    if !all_finite {
        return Err(DynamicsError::NonFinite);
    }
    let (chol, s) = metric(m, &a)?;
    let r = c - a * qd;
    // The fast {1}-inverse, kept when every row holds.
    let w = chol.solve(&a.transpose());
    if let Some(lambda) = PivotedLdlt::new(&(a * w)).and_then(|ldlt| ldlt.solve(&r)) {
        let jump = w * lambda;
        if holds(&a, &c, qd, &jump) {
            return Ok(finish(m, &a, qd, jump, lambda, s));
        }
    }
    let (jump, lambda) = minimum_norm(&chol, &a, &r)?;
    if holds(&a, &c, qd, &jump) {
        Ok(finish(m, &a, qd, jump, lambda, s))
    } else {
        Err(DynamicsError::Unsatisfiable)
    }
}

/// The impact map of a system with bilateral constraints and gaps: rows
/// `0..K` are the persistent constraints (`a`, their velocity-level
/// residual `residual` brought to zero: `A Δq̇ = −φ̇⁻`), rows `K..K + U`
/// the gaps' gradients `gap_jacobian`, those marked `active` impacting with
/// Newton's law `∇gᵢ · q̇⁺ = −eᵢ ∇gᵢ · q̇⁻`. `R` must be `K + U` (checked
/// at compile time). What the generated `impact` method calls.
#[allow(clippy::too_many_arguments)]
pub fn impact_with_gaps<T, const N: usize, const K: usize, const U: usize, const R: usize>(
    m: &SMatrix<T, N, N>,
    a: &SMatrix<T, K, N>,
    residual: &SVector<T, K>,
    gap_jacobian: &SMatrix<T, U, N>,
    active: &[bool; U],
    restitution: &[T; U],
    qd: &SVector<T, N>,
) -> Result<Impact<T, N, R>, DynamicsError>
where
    T: RealField + Copy,
{
    const { assert!(R == K + U, "R must be K + U") };
    let stacked = SMatrix::<T, R, N>::from_fn(|i, j| match i.checked_sub(K) {
        None => a[(i, j)],
        Some(g) => gap_jacobian[(g, j)],
    });
    let before = stacked * qd;
    let mut rows = [true; R];
    let mut target = SVector::<T, R>::zeros();
    for i in 0..R {
        match i.checked_sub(K) {
            None => target[i] = before[i] - residual[i],
            Some(g) => {
                rows[i] = active[g];
                target[i] = -restitution[g] * before[i];
            }
        }
    }
    impact_map(m, &stacked, &target, &rows, qd)
}

/// The Cholesky factor of `M`, or of `M + s AᵀA` (with `s`) where `M` is
/// only semi-definite.
fn metric<T: RealField + Copy, const N: usize, const R: usize>(
    m: &SMatrix<T, N, N>,
    a: &SMatrix<T, R, N>,
) -> Result<(Cholesky<T, Const<N>>, T), DynamicsError> {
    if let Some(chol) = Cholesky::new(*m) {
        return Ok((chol, T::zero()));
    }
    let (m_aux, s) = auxiliary_mass(m, a);
    Cholesky::new(m_aux)
        .map(|chol| (chol, s))
        .ok_or(DynamicsError::MassNotPositiveDefinite)
}

/// Whether `A (q̇⁻ + Δ) = c` holds row by row to the consistency tolerance,
/// measured against the size of the velocities summed.
fn holds<T: RealField + Copy, const N: usize, const R: usize>(
    a: &SMatrix<T, R, N>,
    c: &SVector<T, R>,
    qd: &SVector<T, N>,
    jump: &SVector<T, N>,
) -> bool {
    let after = qd + jump;
    if !after.iter().all(|x| x.is_finite()) {
        return false;
    }
    let size = qd.amax().max(jump.amax()).max(after.amax());
    relative_residual_at(a, c, &after, size) <= consistency_tolerance()
}

/// `Δ = L⁻ᵀ Xᵀ (X Xᵀ)⁺ D r` with `X = D A L⁻ᵀ`, `M = L Lᵀ`, `D` scaling
/// each row of `A` to a largest entry of 1; and `λ = D (X Xᵀ)⁺ D r`, so
/// that `M Δ = Aᵀ λ`.
fn minimum_norm<T: RealField + Copy, const N: usize, const R: usize>(
    chol: &Cholesky<T, Const<N>>,
    a: &SMatrix<T, R, N>,
    r: &SVector<T, R>,
) -> Result<(SVector<T, N>, SVector<T, R>), DynamicsError> {
    let (mut scaled_a, mut scaled_r) = (*a, *r);
    let mut scale = SVector::<T, R>::from_element(T::one());
    for i in 0..R {
        let largest = scaled_a.row(i).amax();
        if largest > T::zero() {
            scaled_a.row_mut(i).unscale_mut(largest);
            scaled_r[i] /= largest;
            scale[i] = largest;
        }
    }
    let l = chol.l();
    let xt = l
        .solve_lower_triangular(&scaled_a.transpose())
        .ok_or(DynamicsError::MassNotPositiveDefinite)?;
    let svd = JacobiSvd::new(&xt.transpose()).ok_or(DynamicsError::NonFinite)?;
    let cut = tight_cut::<T, N, R>() * svd.singular_values().max();
    let mu = svd
        .solve_gram(&scaled_r, cut)
        .ok_or(DynamicsError::NonFinite)?;
    let jump = l
        .transpose()
        .solve_upper_triangular(&(xt * mu))
        .ok_or(DynamicsError::MassNotPositiveDefinite)?;
    Ok((jump, mu.component_div(&scale)))
}

/// The result, with the per-row impulses of the auxiliary metric moved back
/// to `M`'s: `M_aux Δ = Aᵀ λ` gives `M Δ = Aᵀ (λ − s A Δ)`.
fn finish<T: RealField + Copy, const N: usize, const R: usize>(
    m: &SMatrix<T, N, N>,
    a: &SMatrix<T, R, N>,
    qd: &SVector<T, N>,
    jump: SVector<T, N>,
    lambda: SVector<T, R>,
    s: T,
) -> Impact<T, N, R> {
    Impact {
        qd: qd + jump,
        impulse: m * jump,
        row_impulses: lambda - (a * jump) * s,
    }
}

#[cfg(test)]
mod tests;
