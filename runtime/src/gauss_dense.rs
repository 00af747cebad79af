//! Gauss's principle solved densely at run time: the reference the tests
//! hold the generated solves of a configuration-dependent `M` and of a
//! positive semi-definite one (through its auxiliary mass) to. Its rank
//! decision is checked like the generated solver's.

use crate::generated::{effective_mass, Generated, Motion};
use crate::inverse::PivotedLdlt;
use crate::rank::{checked, corrected_constraints, safe_minimum};
use crate::DynamicsError;
use nalgebra::{RealField, SMatrix, SVector};

/// `M = L Lᵀ` and `a = M⁻¹ F`; `Err` when `M` is not positive definite.
#[inline]
fn unconstrained<T: RealField + Copy, const N: usize>(
    m: SMatrix<T, N, N>,
    f: &SVector<T, N>,
) -> Result<
    (
        nalgebra::linalg::Cholesky<T, nalgebra::Const<N>>,
        SVector<T, N>,
    ),
    DynamicsError,
> {
    let chol = nalgebra::linalg::Cholesky::new(m).ok_or(DynamicsError::MassNotPositiveDefinite)?;
    let a = chol.solve(f);
    Ok((chol, a))
}

/// Gauss's principle for a mass matrix that is only known at run time:
/// `M = L Lᵀ` (Cholesky), `a = M⁻¹ F`, `S = A M⁻¹ Aᵀ` factored by
/// [`PivotedLdlt`], `λ = S^{1} (b + correction − A a)`, `q̈ = a + M⁻¹ Aᵀ λ`.
#[inline]
pub fn gauss_dense<T, S, const N: usize, const K: usize>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    correction: Option<&SVector<T, K>>,
) -> Result<Motion<T, N>, DynamicsError>
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    let (a, b) = corrected_constraints(system, q, qd, t, correction);
    let (m, f) = (system.mass_matrix(q, t), system.forces(q, qd, t));
    // An overflowed M or F would be solved as a limit (1/∞ = 0): say so.
    if !(m.iter().all(|x| x.is_finite()) && f.iter().all(|x| x.is_finite())) {
        return Err(DynamicsError::NonFinite);
    }
    let (m_eff, f_eff) = effective_mass::<T, S, N, K>(&m, &f, &a, &b);
    let (chol, acc) = unconstrained(m_eff, &f_eff)?;
    if K == 0 {
        return Ok((acc, SVector::zeros()));
    }
    // `Y = L⁻¹ Aᵀ`, so that `S = A M⁻¹ Aᵀ = Yᵀ Y` and `M⁻¹ Aᵀ λ = L⁻ᵀ (Y λ)`:
    // one triangular solve per row of `A` where `M⁻¹ Aᵀ` takes two. The
    // factor's upper triangle is never read.
    let l = chol.l_dirty();
    let mut y = a.transpose();
    l.solve_lower_triangular_unchecked_mut(&mut y);
    let gram = y.tr_mul(&y);
    let ldlt = PivotedLdlt::factor(&gram);
    let lambda = ldlt.solve_unchecked(&(b - a * acc));
    let mut reaction = y * lambda;
    l.tr_solve_lower_triangular_unchecked_mut(&mut reaction);
    let qdd = acc + reaction;
    // The actual system's constraint force (the auxiliary one's λ carries
    // the added s AᵀA term).
    let force = if S::SEMIDEFINITE_MASS {
        m * qdd - f
    } else {
        a.transpose() * lambda
    };
    // A pivot of an underflowed S is not trusted either (crate::rank).
    let underflow = gram.diagonal().iter().any(|&s| s < safe_minimum());
    if !underflow && ldlt.rank() >= S::GENERIC_RANK {
        return Ok((qdd, force));
    }
    match checked(system, q, qd, t, correction, qdd) {
        None => Ok((qdd, force)),
        Some(recomputed) => recomputed,
    }
}
