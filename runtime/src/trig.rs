//! The sine and cosine of one argument, as generated code evaluates every
//! joint angle's: for `f64` and `f32` the `libm` crate's `sincos` and
//! `sincosf` (FreeBSD's, as in musl: one argument reduction, both kernels,
//! each result under one ulp), for any other scalar `T::sin_cos`.
//!
//! With `std`, `f64::sin_cos` becomes the C library's `sincos` (LLVM joins
//! the `sin` and `cos` calls), which glibc on x86-64 evaluates more slowly
//! than libm does. Calling libm also makes a `std` build compute the same
//! bits as the `no_std` build of the same model (where nalgebra's scalars
//! already call `libm`), so that a host simulation and its firmware agree
//! exactly.
//!
//! The call is not replaced by the same FreeBSD algorithm written inline
//! (libm's call only for the arguments it leaves out): that is as fast
//! alone, and two evaluations at one angle in one function would share it
//! where an opaque call is made twice (the cart-pole's
//! `acceleration_jacobian` recomputes `sin_cos(θ)` in its tangent
//! right-hand sides), but inlined into a larger body such as the
//! four-bar's `acceleration` it makes the whole call markedly slower.
//! Nor by one branch-free evaluation of all of a function's angles at
//! once (each reduced by its nearest multiple of π/2, both kernels, the
//! quadrant chosen by bit masks, vectorized across the angles): that is
//! faster only where the quadrants vary unpredictably. Where the angles
//! change little from call to call, as a controller's and a simulation's
//! do, libm's branches are predicted and its short paths skip work the
//! batch always does, so in place the batch made most of the arms' and
//! the G1's `M`, `τ` and `q̈` slower.

use core::any::Any;
use nalgebra::RealField;

/// `(sin x, cos x)`: `libm::sincos` for `f64`, `libm::sincosf` for `f32`,
/// `T::sin_cos` otherwise. The type tests are constants after
/// monomorphization.
#[inline(always)]
pub fn sin_cos<T: RealField + Copy>(x: T) -> (T, T) {
    let any = &x as &dyn Any;
    if let Some(&v) = any.downcast_ref::<f64>() {
        if let Some(pair) = cast(libm::sincos(v)) {
            return pair;
        }
    } else if let Some(&v) = any.downcast_ref::<f32>() {
        if let Some(pair) = cast(libm::sincosf(v)) {
            return pair;
        }
    }
    x.sin_cos()
}

/// `(s, c)` as `T`'s, when `S` is `T`.
#[inline(always)]
fn cast<S: Any + Copy, T: Any + Copy>((s, c): (S, S)) -> Option<(T, T)> {
    let s = *(&s as &dyn Any).downcast_ref::<T>()?;
    let c = *(&c as &dyn Any).downcast_ref::<T>()?;
    Some((s, c))
}

#[cfg(test)]
mod tests {
    use super::sin_cos;

    /// A deterministic stream of `f64` in `[−span, span]` (xorshift).
    fn samples(count: usize, span: f64) -> impl Iterator<Item = f64> {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        (0..count).map(move |_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            ((state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * span
        })
    }

    #[test]
    fn f64_and_f32_take_libm_bit_for_bit() {
        for x in samples(10_000, 10.0).chain([0.0, -0.0, 1e300, f64::INFINITY]) {
            let bits = |(s, c): (f64, f64)| (s.to_bits(), c.to_bits());
            assert_eq!(bits(sin_cos(x)), bits(libm::sincos(x)), "{x}");
            let x = x as f32;
            let bits = |(s, c): (f32, f32)| (s.to_bits(), c.to_bits());
            assert_eq!(bits(sin_cos(x)), bits(libm::sincosf(x)), "{x}");
        }
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }

    /// Against the C library's `sin` and `cos` (glibc's on the test
    /// machines, an implementation independent of `libm`'s), each called
    /// alone, to a few ulps; and `f32` against the same in `f64`, rounded.
    #[test]
    fn agrees_with_the_c_library() {
        extern crate std;
        for x in samples(100_000, 100.0) {
            let (s, c) = sin_cos(x);
            let (rs, rc) = (std::hint::black_box(x).sin(), std::hint::black_box(x).cos());
            assert!((s - rs).abs() <= 4.0 * f64::EPSILON, "{x}: sin {s} {rs}");
            assert!((c - rc).abs() <= 4.0 * f64::EPSILON, "{x}: cos {c} {rc}");
            let (s, c) = sin_cos(x as f32);
            let (rs, rc) = (f64::from(x as f32).sin(), f64::from(x as f32).cos());
            assert!(
                (f64::from(s) - rs).abs() <= 4.0 * f64::from(f32::EPSILON),
                "{x}: sinf {s} {rs}"
            );
            assert!(
                (f64::from(c) - rc).abs() <= 4.0 * f64::from(f32::EPSILON),
                "{x}: cosf {c} {rc}"
            );
        }
    }
}
