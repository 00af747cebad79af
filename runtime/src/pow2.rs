//! Exact scaling by powers of two for a generic `T`, so that a quantity
//! whose magnitude is beyond `T`'s range in an intermediate step can be
//! carried as `2^e · x` instead.

use nalgebra::RealField;

/// `x` as `T`.
fn c<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert::<f64, T>(x)
}

/// `2^k` for `|k| ≤ 60`, exact in `f32` and `f64`.
pub(crate) fn pow2<T: RealField + Copy>(k: i32) -> T {
    debug_assert!(k.abs() <= 60);
    c(f64::from_bits(((1023 + i64::from(k)) as u64) << 52))
}

/// `x · 2^k`, exact unless the result leaves `T`'s normal range.
pub(crate) fn ldexp<T: RealField + Copy>(mut x: T, mut k: i32) -> T {
    while k > 60 {
        x *= pow2(60);
        k -= 60;
    }
    while k < -60 {
        x *= pow2(-60);
        k += 60;
    }
    x * pow2(k)
}

/// `⌊log₂ x⌋` (within one) for a positive finite `x`, saturated to `±2000`.
pub(crate) fn exponent<T: RealField + Copy>(x: T) -> i32 {
    let e = nalgebra::try_convert::<T, f64>(x.log2().floor()).unwrap_or(0.0);
    e.clamp(-2000.0, 2000.0) as i32
}
