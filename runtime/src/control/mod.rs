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
//! only when both checks hold for it: the closed loop `A_d − B_d K` is
//! certified stable (some power `(A_d − B_d K)^{2^j}` has 1-norm below ½,
//! which bounds its spectral radius below 1), and the Riccati residual of
//! the gain's own cost `P_K` (not of the iteration's `P`, whose step says
//! little where the closed loop is slow) is within the tolerance, relative
//! to `P_K`; Newton's step improves a gain that is not ([`lqr_gain`]).

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
    /// No gain was reached, within the iterations, that stabilizes the
    /// closed loop and whose Riccati residual is within the tolerance: the
    /// pair `(A_d, B_d)` is not stabilizable (or `(Q, A_d)` not
    /// detectable), the iteration converges slowly, or the tolerance lies
    /// below what rounding lets `T` resolve.
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
        scaled_and_squared(a, largest, h, triangular)?
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

/// `(e^{Ah}, W, e)` with `2^e W = φ₁(Ah) = ∫₀¹ e^{Ahs} ds` and `|W|` near 1,
/// for `A ≠ 0` (`largest` its largest entry in magnitude): the Taylor
/// series at `X = A h 2⁻ˢ`, then `s` doublings; for a `triangular` `A` the
/// diagonals set exactly at each. `Err(NonFinite)` when `e^{Aτ}` leaves
/// `T`'s range on the way.
#[allow(clippy::type_complexity)]
fn scaled_and_squared<T: RealField + Copy, const NX: usize>(
    a: &SMatrix<T, NX, NX>,
    largest: T,
    h: T,
    triangular: bool,
) -> Result<(SMatrix<T, NX, NX>, SMatrix<T, NX, NX>, i32), ControlError> {
    let identity = SMatrix::<T, NX, NX>::identity();
    let (x, s) = scaled_step(a, largest, h);
    let (mut f, mut w) = taylor(&x);
    // Doubling: e^{2Aτ} − I = 2F + F², φ₁(2Aτ) = (I + F/2) φ₁(Aτ). W is
    // kept as 2^e W with |W| near 1, so that it does not underflow where
    // h W does not.
    let mut e = 0i32;
    // Once every mode has decayed (‖I + F‖ < ½), e^{Aτ} itself is carried
    // and squared: I + F would keep a decayed e^{λτ} only to ε absolutely
    // (all of A_d to nothing where every mode has decayed), E = e^{Aτ}
    // keeps it relatively.
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
    Ok((ad, w, e))
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
/// with weights `Q` (positive semi-definite) and `R` (positive definite),
/// whose Riccati residual is within `tolerance`, checked after the fact.
///
/// The Riccati iteration runs until its step is below `tolerance` and its
/// gain is certified stable (module docs); then the gain is checked: its
/// cost `P_K`, the solution of `P = Q + KᵀRK + (A_d − B_d K)ᵀ P
/// (A_d − B_d K)`, must satisfy the Riccati equation to `tolerance`
/// relative, `‖Q + A_dᵀP_K A_d − A_dᵀP_K B_d (R + B_dᵀP_K B_d)⁻¹ B_dᵀP_K A_d
/// − P_K‖ ≤ tolerance ‖P_K‖` (largest entries). Where it does not, the
/// gain is improved by Newton's (Hewer's) step `K ← (R + B_dᵀP_K B_d)⁻¹
/// B_dᵀP_K A_d` and checked again. The iteration's step alone is no such
/// check: where the closed loop is slow (the cart-pole held for 10 ms,
/// `ρ(A_d − B_d K) ≈ 0.99`) it is a hundredth of the distance to the
/// solution, and at a tolerance of 0.1 the iteration once returned a gain
/// 34 % from the Riccati solution (one entry 90 %) with relative residual
/// 0.26.
///
/// The residual bounds how far `K` is from optimal, not `K`'s relative
/// error, which is larger by the conditioning of the Riccati equation
/// (about `1/(1 − ρ²)` for a closed loop of spectral radius `ρ`); each
/// Newton step squares it, so the gain returned is usually far better than
/// the tolerance asked for. Every gain returned is certified stable. At
/// most `max_iterations` steps of either kind, and at most 50 Newton steps.
///
/// `Err(InvalidParameter)` for a tolerance outside `(0, 1)` or
/// `max_iterations = 0`; `Err(NotConverged)` when no checked gain is
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
    let riccati = Riccati { a, b, q, r };
    let (mut k, used) = riccati.stabilizing_gain(tolerance, max_iterations)?;
    // Newton's steps converge quadratically from a stabilizing gain: where
    // NEWTON_STEPS of them do not reach the tolerance, it lies below what
    // rounding in `P_K` lets `T` resolve, and more would not help.
    for _ in used..max_iterations.min(used + NEWTON_STEPS) {
        let p = riccati.cost(&k).ok_or(ControlError::NotConverged)?;
        let next = riccati.gain(&p)?;
        let residual = riccati.residual(&p, &next);
        if !residual.is_finite() {
            return Err(ControlError::NotConverged);
        }
        if residual <= tolerance * p.amax() {
            return Ok(k);
        }
        // Hewer's step from a stabilizing gain stabilizes in exact
        // arithmetic; a gain that rounding left uncertified is not kept.
        if !certified_stable(&(a - b * next)) {
            return Err(ControlError::NotConverged);
        }
        k = next;
    }
    Err(ControlError::NotConverged)
}

/// The most Newton steps [`lqr_gain`] takes after the Riccati iteration.
const NEWTON_STEPS: usize = 50;

/// The discrete-time algebraic Riccati equation of `(A_d, B_d, Q, R)`.
struct Riccati<'m, T: RealField + Copy, const NX: usize, const NU: usize> {
    a: &'m SMatrix<T, NX, NX>,
    b: &'m SMatrix<T, NX, NU>,
    q: &'m SMatrix<T, NX, NX>,
    r: &'m SMatrix<T, NU, NU>,
}

impl<T: RealField + Copy, const NX: usize, const NU: usize> Riccati<'_, T, NX, NU> {
    /// `K = (R + BᵀPB)⁻¹ BᵀPA`.
    fn gain(&self, p: &SMatrix<T, NX, NX>) -> Result<SMatrix<T, NU, NX>, ControlError> {
        let s = self.r + self.b.transpose() * p * self.b;
        let chol = Cholesky::new(s).ok_or(ControlError::NotPositiveDefinite)?;
        Ok(chol.solve(&(self.b.transpose() * p * self.a)))
    }

    /// One step of the iteration, `Q + AᵀP(A − BK)` with `K` the gain of
    /// `P`, symmetrized (rounding would otherwise accumulate an
    /// antisymmetric part).
    fn step(&self, p: &SMatrix<T, NX, NX>, k: &SMatrix<T, NU, NX>) -> SMatrix<T, NX, NX> {
        let next = self.q + self.a.transpose() * p * (self.a - self.b * k);
        (next + next.transpose()) * c::<T>(0.5)
    }

    /// The largest entry of the Riccati residual `step(P) − P`, given the
    /// gain `k` of `P`.
    fn residual(&self, p: &SMatrix<T, NX, NX>, k: &SMatrix<T, NU, NX>) -> T {
        (self.step(p, k) - p).amax()
    }

    /// The Riccati iteration from `P = Q` until its step is within
    /// `tolerance` and its gain certified stable: that gain and the
    /// iterations used.
    fn stabilizing_gain(
        &self,
        tolerance: T,
        max_iterations: usize,
    ) -> Result<(SMatrix<T, NU, NX>, usize), ControlError> {
        let mut p = *self.q;
        // The stability check costs up to 64 products; after a failed one
        // the next waits until the iteration count has doubled.
        let mut next_check = 0usize;
        for iteration in 0..max_iterations {
            // R + BᵀPB is positive definite for a positive definite R and a
            // positive semi-definite P, which the iteration keeps in exact
            // arithmetic: a failure after the first step is a P that
            // diverged (an unstable mode out of reach of B) and lost it to
            // rounding.
            let k = match self.gain(&p) {
                Err(ControlError::NotPositiveDefinite) if iteration > 0 => {
                    return Err(ControlError::NotConverged)
                }
                other => other?,
            };
            let next = self.step(&p, &k);
            let residual = (next - p).amax();
            if !residual.is_finite() {
                return Err(ControlError::NotConverged);
            }
            if residual <= tolerance * next.amax() && iteration >= next_check {
                if certified_stable(&(self.a - self.b * k)) {
                    return Ok((k, iteration + 1));
                }
                if residual == T::zero() {
                    // A fixed point whose gain does not stabilize: no
                    // further iteration changes it.
                    return Err(ControlError::NotConverged);
                }
                next_check = 2 * iteration + 1;
            }
            p = next;
        }
        Err(ControlError::NotConverged)
    }

    /// The cost `P_K` of a stabilizing gain: `P = S + A_Kᵀ P A_K` with
    /// `S = Q + KᵀRK`, `A_K = A − BK`, by doubling (`P ← P + A_KᵀPA_K`,
    /// `A_K ← A_K²`, each doubling the terms of `Σ A_Kᵀʲ S A_Kʲ` summed)
    /// until the terms added no longer change `P`. `None` where they do not
    /// fall within 64 doublings or overflow (a gain that does not
    /// stabilize).
    fn cost(&self, k: &SMatrix<T, NU, NX>) -> Option<SMatrix<T, NX, NX>> {
        let mut power = self.a - self.b * k;
        let s = self.q + k.transpose() * self.r * k;
        let mut p = (s + s.transpose()) * c::<T>(0.5);
        for _ in 0..64 {
            let term = power.transpose() * p * power;
            if !term.iter().all(|x| x.is_finite()) {
                return None;
            }
            p += (term + term.transpose()) * c::<T>(0.5);
            if term.amax() <= T::default_epsilon() * p.amax() {
                return Some(p);
            }
            power = power * power;
        }
        None
    }
}

#[cfg(test)]
mod tests;
