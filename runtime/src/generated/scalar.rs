//! The scalar functions generated code calls: literals as `T`, the
//! branch-free finiteness bound, and the DSL's `signum` and unit step;
//! and `unstride`, through which a large `inverse_dynamics` (or bodies'
//! `forces`) returns its joint forces.

use nalgebra::{RealField, SVector};

/// Converts a compile-time `f64` literal of generated code into the scalar `T`.
///
/// Generated code writes every literal through this function so that the same
/// code serves `f32` and `f64`; the conversion is a constant the optimiser folds.
#[inline(always)]
pub fn lit<T: RealField + Copy>(value: f64) -> T {
    nalgebra::convert::<f64, T>(value)
}

/// The largest magnitude a row of the scaled constraints `D (b − A a)`
/// (row scale `d < 1`) may have for the model's own row, that value over
/// `d`, to stay finite: `T`'s largest finite value times `d`. Generated code
/// compares against it branch-free, so that a row that is finite only
/// because it was scaled sends the solve to the runtime's check.
#[inline(always)]
pub fn unscaled_bound<T: RealField + Copy>(d: f64) -> T {
    largest::<T>() * lit::<T>(d)
}

/// `√ε`: how closely a redundant set's minimum-norm `λ`, from the solve's
/// factors, must give the solve's force, relative to its largest term.
/// Rows dependent to rounding move it by rounding (grown by the rows'
/// conditioning, so not a few `ε`); a row the rank rule's loose cutoff
/// dropped while nearly independent (within 1e-3 rad) moves it by about
/// its angle. Past this the rows were not dependent, `λ` is unique, and
/// the runtime answers.
#[inline(always)]
pub fn half_precision<T: RealField + Copy>() -> T {
    T::default_epsilon().sqrt()
}

/// `T`'s largest finite value (NaN for a `T` without one, so that a
/// comparison with it fails and sends the solve to the runtime's check).
/// `s <= largest()` is a finiteness test in one floating-point comparison,
/// where `is_finite` moves the bits to an integer register and back.
#[inline(always)]
pub fn largest<T: RealField + Copy>() -> T {
    match T::max_value() {
        Some(max) => max,
        None => T::zero() / T::zero(),
    }
}

/// The sign of `x` with `signum(0) = 0` (the DSL's `signum`; `f64::signum`
/// returns 1 at +0). NaN stays NaN.
#[inline(always)]
pub fn signum<T: RealField + Copy>(x: T) -> T {
    if x > T::zero() {
        T::one()
    } else if x < T::zero() {
        -T::one()
    } else {
        x * T::zero()
    }
}

/// The unit step, `1` for `x ≥ 0` and `0` below, as derivatives of `min`,
/// `max` and `abs` use it. NaN stays NaN.
#[inline(always)]
pub fn step<T: RealField + Copy>(x: T) -> T {
    if x >= T::zero() {
        T::one()
    } else if x < T::zero() {
        T::zero()
    } else {
        x
    }
}

/// Whether every entry is finite, decided by one sum: `x − x` is zero for
/// a finite `x` and NaN for an infinite or NaN one, and a NaN survives
/// every sum, so the entries are all finite exactly where the sum of
/// their `x − x` is zero. The generated Jacobians and evaluations end in
/// this check over up to thousands of entries, most of them structural
/// zeros; summed in sixteen independent lanes, the compiler makes it a
/// subtraction and an addition per vector of entries (where a fold of
/// `is_finite` takes a mask, two compares and two `and`s, and an early
/// exit a branch per entry), and, inlined into the generated code's AVX
/// copies, four entries a vector. No lane's chain of additions is longer
/// than a sixteenth of the entries.
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` is the test itself, not a slip
pub fn all_finite<T: RealField + Copy>(m: &[T]) -> bool {
    let mut lanes = [T::zero(); 16];
    let mut chunks = m.chunks_exact(16);
    for chunk in &mut chunks {
        for (lane, &x) in lanes.iter_mut().zip(chunk) {
            *lane += x - x;
        }
    }
    for (lane, &x) in lanes.iter_mut().zip(chunks.remainder()) {
        *lane += x - x;
    }
    lanes.iter().fold(T::zero(), |sum, &lane| sum + lane) == T::zero()
}

/// The vector of `strided`'s first slots: how a large generated
/// evaluation returns its entries, each written two slots apart and, on
/// x86, the array passed through `black_box` first. LLVM's SLP vectorizer
/// starts from stores to adjacent addresses and pairs the expressions they
/// store; the adjacent joint forces of recursive Newton–Euler are
/// different bodies' forces, alike in shape only, so pairing them buys two
/// lanes of unrelated work for shuffles at every leaf. Apart, and hidden,
/// the stores seed nothing. On other targets, where this was not
/// measured (a Cortex-M4F has no vector unit to mislead), the array is not
/// hidden and the compiler keeps its values in registers as from a
/// literal. The values are the same bits either way.
#[inline(always)]
pub fn unstride<T: RealField + Copy, const N: usize>(strided: [[T; 2]; N]) -> SVector<T, N> {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    let strided = core::hint::black_box(strided);
    let mut out = [T::zero(); N];
    for (o, [first, _]) in out.iter_mut().zip(strided) {
        *o = first;
    }
    SVector::from_array_storage(nalgebra::ArrayStorage([out]))
}

#[cfg(test)]
mod tests {
    use super::{all_finite, unstride};

    #[test]
    fn all_finite_agrees_with_is_finite_at_every_position() {
        // Lengths around the sixteen lanes, so that the odd value falls in
        // a chunk, in the remainder, or is the only entry; the finite
        // values include the extremes, whose `x − x` is still zero.
        let finite = [
            0.0,
            -0.0,
            1.5,
            -3.25e300,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
        ];
        for len in [0_usize, 1, 15, 16, 17, 31, 32, 33, 100] {
            let base: Vec<f64> = (0..len).map(|i| finite[i % finite.len()]).collect();
            assert!(all_finite(&base), "{len} finite entries");
            for at in 0..len {
                for odd in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN, -f64::NAN] {
                    let mut m = base.clone();
                    m[at] = odd;
                    assert!(!all_finite(&m), "{odd} at {at} of {len}");
                    let single: Vec<f32> = m.iter().map(|&x| x as f32).collect();
                    assert_eq!(all_finite(&single), single.iter().all(|x| x.is_finite()));
                }
            }
        }
    }

    #[test]
    fn unstride_takes_each_pairs_first_in_order() {
        let v = unstride([[1.5_f64, 9.0], [-2.0, 9.0], [0.25, 9.0]]);
        assert_eq!(v.as_slice(), &[1.5, -2.0, 0.25]);
        let empty: [[f32; 2]; 0] = [];
        assert_eq!(unstride(empty).len(), 0);
    }
}
