//! The effective mass of a positive semi-definite `M` (Udwadia & Schutte
//! 2010): the mass Gauss's principle is solved with, for the generated
//! solves' dense reference and for the runtime's own solves.

use super::equations::Generated;
use nalgebra::{RealField, SMatrix, SVector};

/// The mass matrix and forces Gauss's principle is solved with: `(M, F)`
/// itself, or for a positive semi-definite `M` Udwadia & Schutte's
/// auxiliary system `(M + s AᵀA, F + s Aᵀb)`. Adding `s Aᵀ(A q̈ − b) = 0` to
/// `M q̈ = F + Fᶜ` changes nothing on the solutions, and makes the mass
/// positive definite exactly where `[M; A]` has full column rank (elsewhere
/// the Cholesky factorization fails: `Err(MassNotPositiveDefinite)`, never
/// NaN). `s = tr M / ‖A‖²_F` puts the added term on the scale of `M`.
#[inline]
pub fn effective_mass<T, S, const N: usize, const K: usize>(
    m: &SMatrix<T, N, N>,
    f: &SVector<T, N>,
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
) -> (SMatrix<T, N, N>, SVector<T, N>)
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    if !S::SEMIDEFINITE_MASS {
        return (*m, *f);
    }
    let (m_aux, s) = auxiliary_mass(m, a);
    (m_aux, f + a.tr_mul(&(b * s)))
}

/// `(M + s AᵀA, s)` with `s = tr M / ‖A‖²_F` (1 where either vanishes): the
/// auxiliary mass of Udwadia & Schutte, positive definite wherever `[M; A]`
/// has full column rank.
pub(crate) fn auxiliary_mass<T: RealField + Copy, const N: usize, const K: usize>(
    m: &SMatrix<T, N, N>,
    a: &SMatrix<T, K, N>,
) -> (SMatrix<T, N, N>, T) {
    let norm = a.norm_squared();
    let s = if norm > T::zero() && m.trace() > T::zero() {
        m.trace() / norm
    } else {
        T::one()
    };
    // `s AᵀA`'s lower triangle as the sum of each row's outer product over
    // its nonzero entries (a contact row touches a few coordinates), then
    // mirrored: the sum stays exactly symmetric.
    let mut lower = SMatrix::<T, N, N>::zeros();
    for r in 0..K {
        let row = a.row(r);
        for i in 0..N {
            let x = row[i] * s;
            if x == T::zero() {
                continue;
            }
            for j in i..N {
                lower[(j, i)] += x * row[j];
            }
        }
    }
    let mut out = *m;
    for j in 0..N {
        for i in j..N {
            out[(i, j)] += lower[(i, j)];
            if i != j {
                out[(j, i)] += lower[(i, j)];
            }
        }
    }
    (out, s)
}
