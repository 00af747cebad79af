//! Singular value decomposition by one-sided Jacobi rotations (Hestenes),
//! for fixed sizes, without allocation.
//!
//! Used for the Moore–Penrose form of the equation of motion. nalgebra's
//! own `SVD` is not used: it can return wrong singular values for small
//! rank-deficient matrices without reporting failure (nalgebra issue #1172,
//! reproduced here on the redundant double pendulum's `A M^{-1/2}`).
//! One-sided Jacobi is short, needs no bidiagonalisation, and computes small
//! singular values to high relative accuracy.

use crate::pow2::{exponent, ldexp};
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
/// `uᵢ = wᵢ/σᵢ` and `X⁺ r = Σᵢ wᵢ (vᵢ · r) / σᵢ²`. `X` is first scaled by
/// a power of two (exactly) to a largest entry near 1, so that no squared
/// norm overflows or underflows for an input whose entries are finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JacobiSvd<T, const R: usize, const C: usize> {
    /// `B V` of the scaled `X`.
    w: SMatrix<T, C, R>,
    v: SMatrix<T, R, R>,
    /// `X = 2^scale · X_scaled`.
    scale: i32,
}

impl<T: RealField + Copy, const R: usize, const C: usize> JacobiSvd<T, R, C> {
    /// Decomposes `x`. `None` when an entry of `x` is not finite, or its
    /// largest singular value is beyond `T`'s range (up to `√(R C)` times
    /// the largest entry), or the rotations do not converge (not observed
    /// for finite input).
    pub fn new(x: &SMatrix<T, R, C>) -> Option<Self> {
        if !x.iter().all(|e| e.is_finite()) {
            return None;
        }
        let largest = x.amax();
        let scale = if largest > T::zero() {
            exponent(largest)
        } else {
            0
        };
        let (w, v) = orthogonalize(x.map(|e| ldexp(e, -scale)).transpose())?;
        let svd = JacobiSvd { w, v, scale };
        svd.singular_values()
            .iter()
            .all(|s| s.is_finite())
            .then_some(svd)
    }

    /// The singular values, in no particular order (`min(R, C)` of them
    /// are meaningful; the others are zero).
    #[must_use]
    pub fn singular_values(&self) -> SVector<T, R> {
        SVector::from_fn(|i, _| ldexp(self.w.column(i).norm(), self.scale))
    }

    /// `X⁺ r`, the minimum-norm least-squares solution of `X y = r`, with
    /// singular values at or below `cut` counted as zero. `None` when `r`
    /// or the solution is not finite (the solution is beyond `T`'s range).
    #[must_use]
    pub fn solve(&self, r: &SVector<T, R>, cut: T) -> Option<SVector<T, C>> {
        if !r.iter().all(|e| e.is_finite()) {
            return None;
        }
        // X⁺ = 2^{-scale} X_scaled⁺.
        let mut y = SVector::<T, C>::zeros();
        for i in 0..R {
            let sigma2 = self.w.column(i).norm_squared();
            if ldexp(sigma2.sqrt(), self.scale) > cut && sigma2 > T::zero() {
                y += self.w.column(i) * (self.v.column(i).dot(r) / sigma2);
            }
        }
        let y = y.map(|e| ldexp(e, -self.scale));
        y.iter().all(|e| e.is_finite()).then_some(y)
    }

    /// `(Xᵀ)⁺ f`, the minimum-norm least-squares solution of `Xᵀ y = f`,
    /// with singular values at or below `cut` counted as zero: with
    /// `X = V Σ Uᵀ` and `wᵢ = σᵢ uᵢ`, `Σᵢ vᵢ (wᵢ · f) / σᵢ²`. Decomposing the
    /// wide `X` (`R < C`) and solving with its transpose orthogonalizes `R`
    /// columns of length `C` instead of `C` columns of length `R`, `C − R` of
    /// which would have to be rotated down to zero (the multipliers' `Aᵀ λ =
    /// Q_c`, [`crate::multipliers`]). `None` when `f` or the solution is not
    /// finite.
    #[must_use]
    pub fn solve_transpose(&self, f: &SVector<T, C>, cut: T) -> Option<SVector<T, R>> {
        if !f.iter().all(|e| e.is_finite()) {
            return None;
        }
        // (Xᵀ)⁺ = 2^{-scale} (X_scaledᵀ)⁺.
        let mut y = SVector::<T, R>::zeros();
        for i in 0..R {
            let sigma2 = self.w.column(i).norm_squared();
            if ldexp(sigma2.sqrt(), self.scale) > cut && sigma2 > T::zero() {
                y += self.v.column(i) * (self.w.column(i).dot(f) / sigma2);
            }
        }
        let y = y.map(|e| ldexp(e, -self.scale));
        y.iter().all(|e| e.is_finite()).then_some(y)
    }

    /// `(X Xᵀ)⁺ r`, with singular values at or below `cut` counted as zero:
    /// the multipliers `μ` whose `Xᵀ μ` is [`solve`](Self::solve)'s `y`
    /// (`X⁺ = Xᵀ (X Xᵀ)⁺`), the per-row impulses of an impact
    /// ([`crate::impact`]). `None` when `r` or the result is not finite.
    #[must_use]
    pub fn solve_gram(&self, r: &SVector<T, R>, cut: T) -> Option<SVector<T, R>> {
        if !r.iter().all(|e| e.is_finite()) {
            return None;
        }
        // X Xᵀ = 4^scale X_s X_sᵀ, and X_s X_sᵀ = V Σ² Vᵀ.
        let mut mu = SVector::<T, R>::zeros();
        for i in 0..R {
            let sigma2 = self.w.column(i).norm_squared();
            if ldexp(sigma2.sqrt(), self.scale) > cut && sigma2 > T::zero() {
                mu += self.v.column(i) * (self.v.column(i).dot(r) / sigma2);
            }
        }
        let mu = mu.map(|e| ldexp(e, -2 * self.scale));
        mu.iter().all(|e| e.is_finite()).then_some(mu)
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
        let xp =
            SMatrix::<f64, 4, 3>::from_fn(|i, j| svd.solve(&Vector3::ith(j, 1.0), cut).unwrap()[i]);
        assert!((x * xp * x - x).norm() < 1e-13 * x.norm()); // (1)
        assert!((xp * x * xp - xp).norm() < 1e-12 * xp.norm()); // (2)
        assert!(((x * xp).transpose() - x * xp).norm() < 1e-13); // (3)
        assert!(((xp * x).transpose() - xp * x).norm() < 1e-13); // (4)
    }

    /// `A M^{-1/2}` of the redundant double pendulum at rest (rank 2): with
    /// a plain `ε` convergence test the rotations cycle on rounding noise
    /// through all sweeps and a finite input is reported as non-finite.
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
        let xp =
            SMatrix::<f64, 4, 3>::from_fn(|i, j| svd.solve(&Vector3::ith(j, 1.0), cut).unwrap()[i]);
        assert!((x * xp * x - x).norm() < 1e-13 * x.norm());
        assert!((xp * x * xp - xp).norm() < 1e-12 * xp.norm());
    }

    /// `(Xᵀ)⁺ f` from the decomposition of `X` is the transpose's own
    /// `solve`, on a rank-deficient wide matrix (a doubled row).
    #[test]
    fn solve_transpose_is_the_transposes_pseudo_inverse() {
        let x = SMatrix::<f64, 3, 5>::from_row_slice(&[
            1.0, 2.0, 0.0, -1.0, 0.5, //
            0.0, 1.0, 3.0, 2.0, -2.0, //
            1.0, 2.0, 0.0, -1.0, 0.5,
        ]);
        let f = SVector::<f64, 5>::from([0.3, -1.0, 2.0, 0.7, 1.1]);
        let wide = JacobiSvd::new(&x).unwrap();
        let tall = JacobiSvd::new(&x.transpose()).unwrap();
        let cut = 1e-12 * wide.singular_values().max();
        let y = wide.solve_transpose(&f, cut).unwrap();
        let reference = tall.solve(&f, cut).unwrap();
        assert!((y - reference).amax() < 1e-14, "{y} {reference}");
        // The doubled row shares its multiplier equally (minimum norm).
        assert!((y[0] - y[2]).abs() < 1e-14, "{y}");
    }

    #[test]
    fn non_finite_input_is_reported() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut x = redundant_pendulum_x();
            x[(0, 0)] = bad;
            assert!(JacobiSvd::new(&x).is_none(), "{bad}");
        }
        // An infinite matrix is `None`, not a decomposition whose solve is NaN.
        assert!(JacobiSvd::new(&SMatrix::<f64, 2, 3>::repeat(f64::INFINITY)).is_none());
        let svd = JacobiSvd::new(&redundant_pendulum_x()).unwrap();
        assert_eq!(svd.solve(&Vector3::new(1.0, f64::NAN, 0.0), 0.0), None);
    }

    /// Entries near the ends of the range: the squared column norms
    /// overflowed (1e200) or underflowed (1e-200) and the singular values
    /// came out infinite or zero. Scaled by a power of two, the singular
    /// values and `X⁺` are those of the unscaled matrix times the scale,
    /// bit for bit.
    #[test]
    fn extreme_magnitudes_are_decomposed_exactly_scaled() {
        let x = redundant_pendulum_x();
        let reference = JacobiSvd::new(&x).unwrap();
        let r = Vector3::new(0.3, -1.2, 0.7);
        let cut = 1e-8 * reference.singular_values().max();
        let y = reference.solve(&r, cut).unwrap();
        for k in [-1000, -700, 700, 1000] {
            let scale = 2f64.powi(k);
            let svd = JacobiSvd::new(&(x * scale)).expect("finite");
            assert_eq!(svd.singular_values(), reference.singular_values() * scale);
            assert_eq!(svd.solve(&r, cut * scale), Some(y / scale), "2^{k}");
        }
        // Beyond the range: the largest singular value (√15 · 1e308) is not
        // representable; the solution of a subnormal matrix overflows.
        assert!(JacobiSvd::new(&SMatrix::<f64, 3, 5>::repeat(1e308)).is_none());
        let tiny = JacobiSvd::new(&SMatrix::<f64, 3, 5>::repeat(5e-324)).unwrap();
        assert_eq!(tiny.solve(&Vector3::new(1.0, 1.0, 1.0), 0.0), None);
    }
}
