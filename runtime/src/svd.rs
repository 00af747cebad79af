//! Singular value decomposition by one-sided Jacobi rotations (Hestenes),
//! for fixed sizes, without allocation.
//!
//! Used for the Moore–Penrose form of the equation of motion. nalgebra's
//! own `SVD` is not used: it can return wrong singular values for small
//! rank-deficient matrices without reporting failure (nalgebra issue #1172,
//! reproduced here on the redundant double pendulum's `A M^{-1/2}`).
//! One-sided Jacobi is short, needs no bidiagonalisation, and computes small
//! singular values to high relative accuracy.

use nalgebra::{RealField, SMatrix, SVector};

/// Sweeps after which an input is declared non-convergent (only non-finite
/// input gets near it: Jacobi converges quadratically, ~6–10 sweeps).
const MAX_SWEEPS: usize = 64;

/// The singular value decomposition of a fixed-size `X` (`R × C`) by
/// one-sided Jacobi: factor once with [`JacobiSvd::new`], then read the
/// singular values and solve as often as needed.
///
/// Jacobi is applied to the columns of `B = Xᵀ` (`C × R`): `B V = W` with
/// orthogonal columns `wᵢ` of norms `σᵢ`, so that `X = V Σ Uᵀ` with
/// `uᵢ = wᵢ/σᵢ` and `X⁺ r = Σᵢ wᵢ (vᵢ · r) / σᵢ²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JacobiSvd<T, const R: usize, const C: usize> {
    w: SMatrix<T, C, R>,
    v: SMatrix<T, R, R>,
}

impl<T: RealField + Copy, const R: usize, const C: usize> JacobiSvd<T, R, C> {
    /// Decomposes `x`. `None` when the rotations do not converge, which
    /// happens only for non-finite input.
    pub fn new(x: &SMatrix<T, R, C>) -> Option<Self> {
        let (w, v) = orthogonalize(x.transpose())?;
        Some(JacobiSvd { w, v })
    }

    /// The singular values, in no particular order (`min(R, C)` of them
    /// are meaningful; the others are zero).
    #[must_use]
    pub fn singular_values(&self) -> SVector<T, R> {
        SVector::from_fn(|i, _| self.w.column(i).norm())
    }

    /// `X⁺ r`, the minimum-norm least-squares solution of `X y = r`, with
    /// singular values at or below `cut` counted as zero.
    #[must_use]
    pub fn solve(&self, r: &SVector<T, R>, cut: T) -> SVector<T, C> {
        let mut y = SVector::<T, C>::zeros();
        for i in 0..R {
            let sigma2 = self.w.column(i).norm_squared();
            if sigma2.sqrt() > cut {
                y += self.w.column(i) * (self.v.column(i).dot(r) / sigma2);
            }
        }
        y
    }
}

/// One-sided Jacobi: rotates the columns of `b` until they are mutually
/// orthogonal, accumulating the rotations in `V`. Returns `(B V, V)`.
fn orthogonalize<T: RealField + Copy, const M: usize, const K: usize>(
    mut b: SMatrix<T, M, K>,
) -> Option<(SMatrix<T, M, K>, SMatrix<T, K, K>)> {
    let mut v = SMatrix::<T, K, K>::identity();
    // A computed dot product of length M carries a rounding error of up to
    // about M ε |b_p| |b_q|: a test tighter than that can be kept failing by
    // noise alone (observed: a rank-deficient 4 × 3 input cycling through
    // all 64 sweeps with the plain ε test).
    let eps = T::default_epsilon() * nalgebra::convert::<f64, T>(M.max(1) as f64);
    // Columns below M ε ‖B‖ are zero to working precision: rotating them only
    // stirs rounding noise and would never converge (rank deficiency).
    let negligible = {
        let e = eps * b.norm();
        e * e
    };
    for _ in 0..MAX_SWEEPS {
        let mut rotated = false;
        for p in 0..K {
            for q in p + 1..K {
                let alpha = b.column(p).norm_squared();
                let beta = b.column(q).norm_squared();
                let gamma = b.column(p).dot(&b.column(q));
                if alpha <= negligible
                    || beta <= negligible
                    || gamma.abs() <= eps * (alpha * beta).sqrt()
                {
                    continue;
                }
                rotated = true;
                let zeta = (beta - alpha) / (gamma + gamma);
                let t = zeta.signum() / (zeta.abs() + (T::one() + zeta * zeta).sqrt());
                let t = if zeta == T::zero() { T::one() } else { t };
                let c = T::one() / (T::one() + t * t).sqrt();
                let s = c * t;
                rotate(&mut b, p, q, c, s);
                rotate(&mut v, p, q, c, s);
            }
        }
        if !rotated {
            return Some((b, v));
        }
        if !b.iter().all(|e| e.is_finite()) {
            return None;
        }
    }
    None
}

fn rotate<T: RealField + Copy, const M: usize, const K: usize>(
    m: &mut SMatrix<T, M, K>,
    p: usize,
    q: usize,
    c: T,
    s: T,
) {
    for i in 0..M {
        let (mp, mq) = (m[(i, p)], m[(i, q)]);
        m[(i, p)] = c * mp - s * mq;
        m[(i, q)] = s * mp + c * mq;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3x4, SMatrix, Vector3};

    /// The matrix on which nalgebra 0.35's SVD returns a wrong decomposition
    /// (|U Σ Vᵀ − X| = 0.19): `A M^{-1/2}` of the redundant double pendulum.
    fn redundant_pendulum_x() -> Matrix3x4<f64> {
        Matrix3x4::new(
            -0.9146447279664707,
            0.2608436377334566,
            0.0,
            0.0,
            2.989170947895696,
            1.3943663384266562,
            -3.014564126137845,
            -1.406211560256959,
            -2.6972842145594416,
            3.016062287716998,
            -3.014564126137845,
            -1.406211560256959,
        )
    }

    #[test]
    fn singular_values_preserve_the_frobenius_norm() {
        // Σσᵢ² = |X|²_F for every matrix: the identity nalgebra's SVD breaks.
        let x = redundant_pendulum_x();
        let sv = JacobiSvd::new(&x).unwrap().singular_values();
        assert!((sv.norm_squared() - x.norm_squared()).abs() < 1e-13 * x.norm_squared());
        let ones = SMatrix::<f64, 3, 5>::repeat(1.0);
        let sv = JacobiSvd::new(&ones).unwrap().singular_values();
        assert!((sv.max() - 15f64.sqrt()).abs() < 1e-14, "{sv}");
    }

    #[test]
    fn pseudo_inverse_satisfies_penrose_conditions() {
        let x = redundant_pendulum_x();
        let svd = JacobiSvd::new(&x).unwrap();
        let cut = 1e-10 * svd.singular_values().max();
        // X⁺ applied to each unit vector gives X⁺ column by column.
        let xp = SMatrix::<f64, 4, 3>::from_fn(|i, j| svd.solve(&Vector3::ith(j, 1.0), cut)[i]);
        assert!((x * xp * x - x).norm() < 1e-13 * x.norm()); // (1)
        assert!((xp * x * xp - xp).norm() < 1e-12 * xp.norm()); // (2)
        assert!(((x * xp).transpose() - x * xp).norm() < 1e-13); // (3)
        assert!(((xp * x).transpose() - xp * x).norm() < 1e-13); // (4)
    }

    /// `A M^{-1/2}` of the redundant double pendulum at rest (rank 2): with
    /// a plain `ε` convergence test the rotations cycled on rounding noise
    /// through all sweeps and a finite input was reported as non-finite.
    #[test]
    fn converges_on_rank_deficient_input() {
        let x = Matrix3x4::<f64>::new(
            -0.8755813153194901,
            -2.1241346552683416,
            0.0,
            0.0,
            -2.3017072951345856,
            -1.074557622531044,
            3.4830760893855213,
            1.626082503894564,
            -3.931582441024651,
            -5.028587043410541,
            3.483076089385522,
            1.626082503894564,
        );
        let svd = JacobiSvd::new(&x).expect("finite input converges");
        let sv = svd.singular_values();
        assert!((sv.norm_squared() - x.norm_squared()).abs() < 1e-13 * x.norm_squared());
        let rank = sv.iter().filter(|&&s| s > 1e-10 * sv.max()).count();
        assert_eq!(rank, 2, "{sv}");
        let cut = 1e-8 * sv.max();
        let xp = SMatrix::<f64, 4, 3>::from_fn(|i, j| svd.solve(&Vector3::ith(j, 1.0), cut)[i]);
        assert!((x * xp * x - x).norm() < 1e-13 * x.norm());
        assert!((xp * x * xp - xp).norm() < 1e-12 * xp.norm());
    }

    #[test]
    fn non_finite_input_is_reported() {
        let mut x = redundant_pendulum_x();
        x[(0, 0)] = f64::NAN;
        assert!(JacobiSvd::new(&x).is_none());
    }
}
