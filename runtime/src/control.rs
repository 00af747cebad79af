//! A discrete-time linear-quadratic regulator for the linear models of
//! [`crate::linearize`]: zero-order-hold discretization and the Riccati
//! iteration, on the stack, for controllers that design their gain on the
//! device.
//!
//! For `δẋ = A δx + B δu` held over steps of `h`:
//! `A_d = e^{A h}`, `B_d = ∫₀ʰ e^{A s} ds B`, both by one Taylor series of
//! the block matrix after scaling `h` down until `‖A h‖ ≤ ½` and squaring
//! back. The gain `K` of `u = −K δx` minimises `Σ δxᵀ Q δx + δuᵀ R δu`:
//! `P = Q + A_dᵀ P A_d − A_dᵀ P B_d (R + B_dᵀ P B_d)⁻¹ B_dᵀ P A_d` iterated
//! from `P = Q` to a fixed point, `K = (R + B_dᵀ P B_d)⁻¹ B_dᵀ P A_d`.

use nalgebra::{Cholesky, RealField, SMatrix};

/// Why no gain was computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlError {
    /// A matrix or the step was not finite, or the step not positive.
    NonFinite,
    /// `R + B_dᵀ P B_d` is not positive definite (`R` must be).
    NotPositiveDefinite,
    /// The Riccati iteration did not settle within its iterations: the
    /// pair `(A_d, B_d)` is not stabilizable, or it converges slowly.
    NotConverged,
}

impl core::fmt::Display for ControlError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            ControlError::NonFinite => "a matrix or the step is not finite",
            ControlError::NotPositiveDefinite => "R + BᵀPB is not positive definite",
            ControlError::NotConverged => "the Riccati iteration did not converge",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ControlError {}

/// `(A_d, B_d)`: the exact zero-order-hold discretization of
/// `δẋ = A δx + B δu` over a step `h`.
pub fn discretize<T: RealField + Copy, const NX: usize, const NU: usize>(
    a: &SMatrix<T, NX, NX>,
    b: &SMatrix<T, NX, NU>,
    h: T,
) -> Result<(SMatrix<T, NX, NX>, SMatrix<T, NX, NU>), ControlError> {
    let finite = a.iter().chain(b.iter()).all(|x| x.is_finite()) && h.is_finite();
    if !finite || h <= T::zero() {
        return Err(ControlError::NonFinite);
    }
    // Scale h by 2^-s so that ‖A h‖₁ ≤ 1/2 (at most 1100 halvings: f64's range).
    let norm = a.column_iter().fold(T::zero(), |m, c| m.max(c.lp_norm(1))) * h;
    let half = nalgebra::convert::<f64, T>(0.5);
    let mut squarings = 0u32;
    let mut scaled = h;
    let mut size = norm;
    while size > half && squarings < 1100 {
        scaled *= half;
        size *= half;
        squarings += 1;
    }
    // Taylor series of e^{A τ} and ∫₀^τ e^{A s} ds to 20 terms (‖Aτ‖ ≤ ½:
    // the remainder is below 2^-20/20!).
    let mut phi = SMatrix::<T, NX, NX>::identity();
    let mut gamma = SMatrix::<T, NX, NX>::identity() * scaled;
    let mut term = SMatrix::<T, NX, NX>::identity();
    let mut k = T::one();
    for _ in 0..20 {
        term = term * a * scaled / k;
        phi += term;
        gamma += term * scaled / (k + T::one());
        k += T::one();
    }
    // Doubling: e^{2Aτ} = e^{Aτ}², ∫₀^{2τ} = ∫₀^τ + e^{Aτ} ∫₀^τ.
    for _ in 0..squarings {
        gamma = gamma + phi * gamma;
        phi = phi * phi;
    }
    let out = (phi, gamma * b);
    if out.0.iter().chain(out.1.iter()).all(|x| x.is_finite()) {
        Ok(out)
    } else {
        Err(ControlError::NonFinite)
    }
}

/// The gain `K` (`u = −K δx`) of the discrete-time LQR for `(A_d, B_d)`
/// with weights `Q` (positive semi-definite) and `R` (positive definite):
/// the Riccati iteration to a relative change below `tolerance`, at most
/// `max_iterations` steps.
pub fn lqr_gain<T: RealField + Copy, const NX: usize, const NU: usize>(
    a: &SMatrix<T, NX, NX>,
    b: &SMatrix<T, NX, NU>,
    q: &SMatrix<T, NX, NX>,
    r: &SMatrix<T, NU, NU>,
    tolerance: T,
    max_iterations: usize,
) -> Result<SMatrix<T, NU, NX>, ControlError> {
    let finite = [a.iter(), q.iter()]
        .into_iter()
        .flatten()
        .chain(b.iter())
        .chain(r.iter())
        .all(|x| x.is_finite());
    if !finite {
        return Err(ControlError::NonFinite);
    }
    let gain = |p: &SMatrix<T, NX, NX>| -> Result<SMatrix<T, NU, NX>, ControlError> {
        let s = r + b.transpose() * p * b;
        let chol = Cholesky::new(s).ok_or(ControlError::NotPositiveDefinite)?;
        Ok(chol.solve(&(b.transpose() * p * a)))
    };
    let mut p = *q;
    for _ in 0..max_iterations {
        let k = gain(&p)?;
        let next = q + a.transpose() * p * (a - b * k);
        // Symmetrize: rounding would otherwise accumulate an antisymmetric part.
        let next = (next + next.transpose()) * nalgebra::convert::<f64, T>(0.5);
        let change = (next - p).amax();
        let scale = next.amax();
        if !change.is_finite() {
            return Err(ControlError::NotConverged);
        }
        p = next;
        if change <= tolerance * scale {
            return gain(&p);
        }
    }
    Err(ControlError::NotConverged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1, Matrix2, Matrix2x1};

    /// The double integrator: `A_d = [[1, h], [0, 1]]`, `B_d = [h²/2, h]`.
    #[test]
    fn discretizes_the_double_integrator_exactly() {
        let a = Matrix2::new(0.0, 1.0, 0.0, 0.0);
        let b = Matrix2x1::new(0.0, 1.0);
        let (ad, bd) = discretize(&a, &b, 0.1).expect("finite");
        assert!((ad - Matrix2::new(1.0, 0.1, 0.0, 1.0)).amax() < 1e-15);
        assert!((bd - Matrix2x1::new(0.005, 0.1)).amax() < 1e-15);
        // A long step takes the squaring path: e^{a h} for a scalar a.
        let (ad, bd) = discretize(&Matrix1::new(-3.0), &Matrix1::new(1.0), 5.0).expect("finite");
        assert!((ad[0] - (-15.0f64).exp()).abs() < 1e-15);
        assert!((bd[0] - (1.0 - (-15.0f64).exp()) / 3.0).abs() < 1e-15);
    }

    /// A scalar system has the closed-form Riccati solution
    /// `p = q + a² p r / (r + b² p)`, solved as a quadratic.
    #[test]
    fn scalar_gain_matches_the_closed_form() {
        let (a, b, q, r): (f64, f64, f64, f64) = (1.2, 0.5, 2.0, 0.3);
        // b² p² + (r − a² r − q b²) p − q r = 0.
        let (qa, qb, qc) = (b * b, r - a * a * r - q * b * b, -q * r);
        let p = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
        let k = b * p * a / (r + b * b * p);
        let got = lqr_gain(
            &Matrix1::new(a),
            &Matrix1::new(b),
            &Matrix1::new(q),
            &Matrix1::new(r),
            1e-14,
            1000,
        )
        .expect("stabilizable");
        assert!((got[0] - k).abs() < 1e-12, "{} vs {k}", got[0]);
        assert!((a - b * got[0]).abs() < 1.0, "closed loop stable");
    }

    #[test]
    fn unstabilizable_pairs_and_bad_weights_are_errors() {
        // An unstable mode the input cannot reach.
        let a = Matrix2::new(2.0, 0.0, 0.0, 0.5);
        let b = Matrix2x1::new(0.0, 1.0);
        let q = Matrix2::identity();
        let r = Matrix1::new(1.0);
        assert_eq!(
            lqr_gain(&a, &b, &q, &r, 1e-12, 200),
            Err(ControlError::NotConverged)
        );
        assert_eq!(
            lqr_gain(&a, &b, &q, &Matrix1::new(-1.0), 1e-12, 200),
            Err(ControlError::NotPositiveDefinite)
        );
        assert_eq!(discretize(&a, &b, f64::NAN), Err(ControlError::NonFinite));
    }
}
