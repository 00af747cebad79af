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

/// Whether every entry is finite, without an early exit and over a slice
/// rather than through a chain of iterators or a matrix's iterator: the
/// generated Jacobians and evaluations end in this check over up to
/// thousands of entries (the G1's `inverse_dynamics_jacobian`: 1,682),
/// where a compare and a branch per entry, or a `try_fold` not inlined,
/// is a sixth of the call; over a slice the fold is a few SIMD
/// instructions per four entries.
#[inline]
pub fn all_finite<T: RealField + Copy>(m: &[T]) -> bool {
    m.iter().fold(true, |ok, x| ok & x.is_finite())
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
    use super::unstride;

    #[test]
    fn unstride_takes_each_pairs_first_in_order() {
        let v = unstride([[1.5_f64, 9.0], [-2.0, 9.0], [0.25, 9.0]]);
        assert_eq!(v.as_slice(), &[1.5, -2.0, 0.25]);
        let empty: [[f32; 2]; 0] = [];
        assert_eq!(unstride(empty).len(), 0);
    }
}
