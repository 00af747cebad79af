//! A discrete-time linear-quadratic regulator for the linear models of
//! [`crate::linearize`]: zero-order-hold discretization and the Riccati
//! iteration, on the stack, for controllers that design their gain on the
//! device.
//!
//! For `δẋ = A δx + B δu` held over steps of `h`:
//! `A_d = e^{A h}`, `B_d = ∫₀ʰ e^{A s} ds B = h φ₁(A h) B` with
//! `φ₁(X) = Σ Xᵏ/(k+1)!`, by scaling and squaring: `h` is split as
//! `2^s τ` with `s` chosen from `log₂ ‖A‖₁ + log₂ h` (never by halving `h`,
//! which underflowed to zero for `‖A h‖` beyond `T`'s range), the Taylor
//! series of `F = e^{Aτ} − I` and `W = φ₁(Aτ)` summed at `‖Aτ‖₁ ≤ ½`, then
//! doubled back `s` times as `F ← 2F + F²`, `W ← W + F W / 2`. Carrying
//! `e^{Aτ} − I` rather than `e^{Aτ}` keeps a slow mode of a stiff `A`
//! (`e^{−2^{-55}}` rounds to 1; `−2^{-55}` does not), and `W` carries its
//! own power of two, so neither is lost to rounding or to the range of `T`.
//! Once every mode has decayed (`‖I + F‖₁ < ½`) `e^{Aτ}` itself is carried
//! and squared, which keeps a decayed `A_d` to its own relative precision.
//! For a triangular `A` the diagonals are set from `expm1` at every
//! doubling (Al-Mohy & Higham, SIAM J. Matrix Anal. Appl. 31, 2009).
//!
//! The gain `K` of `u = −K δx` minimises `Σ δxᵀ Q δx + δuᵀ R δu`:
//! `P = Q + A_dᵀ P A_d − A_dᵀ P B_d (R + B_dᵀ P B_d)⁻¹ B_dᵀ P A_d` iterated
//! from `P = Q`, `K = (R + B_dᵀ P B_d)⁻¹ B_dᵀ P A_d`. A gain is returned
//! only when both checks hold for it: the Riccati residual of its `P` is
//! within the tolerance, and the closed loop `A_d − B_d K` is certified
//! stable (some power `(A_d − B_d K)^{2^j}` has 1-norm below ½, which
//! bounds its spectral radius below 1).

use crate::pow2::{exponent, ldexp, pow2};
use nalgebra::{Cholesky, RealField, SMatrix};

/// Why no gain was computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlError {
    /// A matrix or the step was not finite, or the step not positive, or
    /// the result is beyond the range of the scalar type.
    NonFinite,
    /// `R + B_dᵀ P B_d` is not positive definite (`R` must be).
    NotPositiveDefinite,
    /// The Riccati iteration did not reach, within its iterations, a `P`
    /// whose residual is within the tolerance and whose gain stabilizes the
    /// closed loop: the pair `(A_d, B_d)` is not stabilizable (or `(Q, A_d)`
    /// not detectable), or it converges slowly.
    NotConverged,
    /// A setting that cannot work: a tolerance that is not in `(0, 1)`
    /// (NaN, infinite, zero, negative, or so loose that any `P` passes), or
    /// no iterations allowed.
    InvalidParameter,
}

impl core::fmt::Display for ControlError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            ControlError::NonFinite => "a matrix or the step is not finite",
            ControlError::NotPositiveDefinite => "R + BᵀPB is not positive definite",
            ControlError::NotConverged => {
                "the Riccati iteration did not converge to a stabilizing gain"
            }
            ControlError::InvalidParameter => {
                "the tolerance must lie in (0, 1) and at least one iteration be allowed"
            }
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ControlError {}

/// `x` as `T`.
fn c<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert::<f64, T>(x)
}

/// `φ₁(y) = (e^y − 1)/y`, 1 at 0.
fn phi1<T: RealField + Copy>(y: T) -> T {
    if y == T::zero() {
        T::one()
    } else {
        y.exp_m1() / y
    }
}

/// The diagonals of `F = e^{Aτ} − I` (or of `e^{Aτ}` itself once
/// `decayed`) and `W = φ₁(Aτ)` (stored as `2^{-e} W`) of a triangular `A`
/// after `doubling` doublings of `X = A τ₀`: `e^{2^k x_ii} − 1` (or
/// `e^{2^k x_ii}`) and `φ₁(2^k x_ii)`.
fn exact_diagonal<T: RealField + Copy, const N: usize>(
    x: &SMatrix<T, N, N>,
    doubling: i32,
    e: i32,
    decayed: bool,
    f: &mut SMatrix<T, N, N>,
    w: &mut SMatrix<T, N, N>,
) {
    for i in 0..N {
        let xi = x[(i, i)];
        let y = ldexp(xi, doubling);
        f[(i, i)] = if decayed { y.exp() } else { y.exp_m1() };
        w[(i, i)] = if y >= T::zero() || y.exp() > T::default_epsilon() {
            ldexp(phi1(y), -e)
        } else {
            // φ₁(y) = −1/y to working precision, and y may have overflowed
            // (λh beyond T's range) where 2^{-e}/y does not underflow:
            // −1/y = −2^{-k}/(2^{k-doubling}·x) with x scaled near 1.
            let k = -exponent(-xi);
            ldexp(-T::one() / ldexp(xi, k), k - doubling - e)
        };
    }
}

/// The 1-norm (largest column sum of magnitudes).
fn norm1<T: RealField + Copy, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> T {
    m.column_iter().fold(T::zero(), |acc, col| {
        acc.max(col.iter().fold(T::zero(), |s, x| s + x.abs()))
    })
}

/// Terms of the Taylor series of `F` and `W`: at `‖X‖₁ ≤ ½` the first term
/// left out is below `2⁻¹⁷/17! ≈ 2e-20` of `‖X‖` (`F`) or of 1 (`W`).
const TAYLOR_TERMS: i32 = 16;

/// `(A_d, B_d)`: the exact zero-order-hold discretization of
/// `δẋ = A δx + B δu` over a step `h` (module docs), for `‖A h‖` up to the
/// end of `T`'s range (`A = −10³⁰⁸ I`, `h = 50` gives `A_d = 0`,
/// `B_d = 10⁻³⁰⁸ B`). Accuracy: for a triangular (or diagonal) `A` the
/// diagonal of `A_d` and of `∫e^{As}ds` is `e^{λh}` and `(e^{λh} − 1)/λ`
/// entry by entry, slow modes of a stiff `A` included; otherwise the
/// error is of order `ε ‖A h‖ ‖e^{Ah}‖`, that of a backward-stable
/// exponential (the condition of `e^X` for a normal `X` is `‖X‖`: the slow
/// mode of a full stiff `A` is carried by differences of its fast entries).
/// `Err(NonFinite)` for a non-finite input or a step that is not positive,
/// or when `A_d` or `B_d` exceeds `T`'s range.
pub fn discretize<T: RealField + Copy, const NX: usize, const NU: usize>(
    a: &SMatrix<T, NX, NX>,
    b: &SMatrix<T, NX, NU>,
    h: T,
) -> Result<(SMatrix<T, NX, NX>, SMatrix<T, NX, NU>), ControlError> {
    let finite = a.iter().chain(b.iter()).all(|x| x.is_finite()) && h.is_finite();
    if !finite || h <= T::zero() {
        return Err(ControlError::NonFinite);
    }
    let identity = SMatrix::<T, NX, NX>::identity();
    let largest = a.amax();
    // For a triangular A (diagonal included) the diagonals of F and W are
    // set from e^{λτ} − 1 and φ₁(λτ) at every doubling (Al-Mohy & Higham,
    // 2009): exact entry by entry, where the doubling keeps them only to ε
    // of the largest entry (a decayed e^{−21} beside a fast mode).
    let upper = (0..NX).all(|i| (0..i).all(|j| a[(i, j)] == T::zero()));
    let lower = (0..NX).all(|i| (i + 1..NX).all(|j| a[(i, j)] == T::zero()));
    let triangular = upper || lower;
    let (ad, w, w_exponent) = if largest == T::zero() {
        (identity, identity, 0)
    } else {
        let (x, s) = scaled_step(a, largest, h);
        let (mut f, mut w) = taylor(&x);
        // Doubling: e^{2Aτ} − I = 2F + F², φ₁(2Aτ) = (I + F/2) φ₁(Aτ). W is
        // kept as 2^e W with |W| near 1, so that it does not underflow
        // where h W does not.
        let mut e = 0i32;
        // Once every mode has decayed (‖I + F‖ < ½), e^{Aτ} itself is
        // carried and squared: I + F would keep a decayed e^{λτ} only to ε
        // absolutely (all of A_d to nothing where every mode has decayed),
        // E = e^{Aτ} keeps it relatively.
        let mut decayed = false;
        for doubling in 1..=s {
            if decayed {
                w = (w + f * w) * c::<T>(0.5);
                f = f * f;
            } else {
                w += f * w * c::<T>(0.5);
                f = f * c::<T>(2.0) + f * f;
            }
            if triangular {
                exact_diagonal(&x, doubling, e, decayed, &mut f, &mut w);
            }
            if !decayed && norm1(&(identity + f)) < c(0.5) {
                f += identity;
                decayed = true;
            }
            let size = w.amax();
            if size < pow2::<T>(-60) && size > T::zero() {
                w *= pow2::<T>(60);
                e -= 60;
            } else if size > pow2::<T>(60) {
                w *= pow2::<T>(-60);
                e += 60;
            }
            if !f.iter().all(|v| v.is_finite()) {
                return Err(ControlError::NonFinite);
            }
        }
        let mut ad = if decayed { f } else { identity + f };
        if triangular {
            // 1 + (e^{λh} − 1) keeps e^{λh} only to ε absolutely.
            for i in 0..NX {
                ad[(i, i)] = ldexp(x[(i, i)], s).exp();
            }
        }
        (ad, w, e)
    };
    // Γ = h W 2^e, with h split into its power of two so that h·W cannot
    // overflow where Γ does not.
    let eh = exponent(h);
    let h_scaled = ldexp(h, -eh);
    let gamma = w.map(|v| ldexp(v * h_scaled, w_exponent + eh));
    let out = (ad, gamma * b);
    if out.0.iter().chain(out.1.iter()).all(|x| x.is_finite()) {
        Ok(out)
    } else {
        Err(ControlError::NonFinite)
    }
}

/// `(X, s)` with `X = A h 2⁻ˢ`, `‖X‖₁ ≤ ½`, for `A ≠ 0` (`largest` its
/// largest entry in magnitude).
fn scaled_step<T: RealField + Copy, const NX: usize>(
    a: &SMatrix<T, NX, NX>,
    largest: T,
    h: T,
) -> (SMatrix<T, NX, NX>, i32) {
    // A = 2^ea A' with |A'| < 2 entrywise, exactly; ‖A h‖₁ =
    // 2^ea h ‖A'‖₁ is found by its logarithm, which cannot overflow.
    let ea = exponent(largest);
    let a_scaled = a.map(|x| ldexp(x, -ea));
    let theta = c::<T>(0.5);
    let log_norm = norm1(&a_scaled).log2() + c::<T>(f64::from(ea)) + h.log2();
    let mut s = nalgebra::try_convert::<T, f64>((log_norm - theta.log2()).ceil())
        .unwrap_or(0.0)
        .clamp(0.0, 4000.0) as i32;
    // X = A τ = A' · h 2^(ea − s); one more halving if the logarithm
    // rounded the wrong way.
    let mut x = a_scaled * ldexp(h, ea - s);
    while norm1(&x) > theta {
        s += 1;
        x = a_scaled * ldexp(h, ea - s);
    }
    (x, s)
}

/// `(F, W)` = `(e^X − I, φ₁(X))` by their Taylor series, for `‖X‖₁ ≤ ½`.
fn taylor<T: RealField + Copy, const NX: usize>(
    x: &SMatrix<T, NX, NX>,
) -> (SMatrix<T, NX, NX>, SMatrix<T, NX, NX>) {
    let x = *x;
    let mut term = x;
    let mut f = x;
    let mut w = SMatrix::<T, NX, NX>::identity() + x * c::<T>(0.5);
    for k in 2..=TAYLOR_TERMS {
        term = term * x * c::<T>(1.0 / f64::from(k));
        f += term;
        w += term * c::<T>(1.0 / f64::from(k + 1));
    }
    (f, w)
}

/// Whether `m` is certified Schur stable (spectral radius below 1): some
/// `m^{2^j}`, `j < 64`, has 1-norm below ½, and `ρ(m)^{2^j} ≤ ‖m^{2^j}‖₁`.
/// Not certified when the powers overflow (`ρ > 1`) or never fall (`ρ = 1`,
/// or so close to 1 that 2⁶⁴ steps do not tell).
fn certified_stable<T: RealField + Copy, const N: usize>(m: &SMatrix<T, N, N>) -> bool {
    let mut power = *m;
    for _ in 0..64 {
        // Entry by entry: an overflowed power holds NaN (∞ − ∞), which a
        // `max` over column sums would skip.
        if !power.iter().all(|x| x.is_finite()) {
            return false;
        }
        let size = norm1(&power);
        if size < c(0.5) {
            return true;
        }
        power = power * power;
    }
    false
}

/// The gain `K` (`u = −K δx`) of the discrete-time LQR for `(A_d, B_d)`
/// with weights `Q` (positive semi-definite) and `R` (positive definite):
/// the Riccati iteration until the residual of `P` (its relative change in
/// one more step) is below `tolerance` *and* `A_d − B_d K` is certified
/// stable (module docs), at most `max_iterations` steps. A tolerance met by
/// a gain that does not stabilize (a loose one, early in the iteration)
/// does not end the iteration.
///
/// `Err(InvalidParameter)` for a tolerance outside `(0, 1)` or
/// `max_iterations = 0`; `Err(NotConverged)` when no certified gain is
/// reached (the pair is not stabilizable: `diag(1, 0.5)`, `B = [0, 1]ᵀ`);
/// `Err(NonFinite)` for a non-finite input.
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
    // NaN fails both comparisons.
    let usable = tolerance > T::zero() && tolerance < T::one();
    if !usable || max_iterations == 0 {
        return Err(ControlError::InvalidParameter);
    }
    let gain = |p: &SMatrix<T, NX, NX>| -> Result<SMatrix<T, NU, NX>, ControlError> {
        let s = r + b.transpose() * p * b;
        let chol = Cholesky::new(s).ok_or(ControlError::NotPositiveDefinite)?;
        Ok(chol.solve(&(b.transpose() * p * a)))
    };
    let mut p = *q;
    // The stability check costs up to 64 products; after a failed one the
    // next waits until the iteration count has doubled.
    let mut next_check = 0usize;
    for iteration in 0..max_iterations {
        // R + BᵀPB is positive definite for a positive definite R and a
        // positive semi-definite P, which the iteration keeps in exact
        // arithmetic: a failure after the first step is a P that diverged
        // (an unstable mode out of reach of B) and lost it to rounding.
        let k = match gain(&p) {
            Err(ControlError::NotPositiveDefinite) if iteration > 0 => {
                return Err(ControlError::NotConverged)
            }
            other => other?,
        };
        let next = q + a.transpose() * p * (a - b * k);
        // Symmetrize: rounding would otherwise accumulate an antisymmetric part.
        let next = (next + next.transpose()) * c::<T>(0.5);
        // The Riccati residual of P (and of the gain K it gives).
        let residual = (next - p).amax();
        let scale = next.amax();
        if !residual.is_finite() {
            return Err(ControlError::NotConverged);
        }
        if residual <= tolerance * scale && iteration >= next_check {
            if certified_stable(&(a - b * k)) {
                return Ok(k);
            }
            if residual == T::zero() {
                // A fixed point whose gain does not stabilize: no further
                // iteration changes it.
                return Err(ControlError::NotConverged);
            }
            next_check = 2 * iteration + 1;
        }
        p = next;
    }
    Err(ControlError::NotConverged)
}

#[cfg(test)]
mod tests;
