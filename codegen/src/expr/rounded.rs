//! Functions of constants evaluated at compile time, exactly and rounded
//! once: the sine and cosine of a constant angle (a frame's `rpy` from a
//! URDF file, a body's fixed placement) become the `f64` nearest their
//! true values, so the generated code computes no `sin_cos` of a constant
//! and whatever multiplies them (a locked subtree's merged inertia) folds
//! into constants too.
//!
//! The value is summed as a Taylor series in fixed point with [`BITS`]
//! fractional bits (each of the at most a hundred or so terms truncated by
//! one unit, far below the 2⁻⁵³ of the result), then rounded to the
//! nearest `f64`, ties to even.

use super::num::Num;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};

/// Fractional bits of the fixed-point sums.
const BITS: u32 = 320;

/// Angles beyond this (in radians) are not evaluated here: their series
/// would cancel more digits than the fixed point keeps margin for, and no
/// file writes one.
const LARGEST: f64 = 16.0;

/// `(sin x, cos x)` of a constant angle, each the `f64` nearest its exact
/// value; `None` for a non-finite or too large `x`. The angle is first the
/// `f64` nearest `x`, as every other reader of a URDF file takes
/// `rpy="1.5708"`: its cosine is then Pinocchio's to the last bit, where
/// the cosine of the decimal itself differs from it by 7e-12 of its size.
pub fn sin_cos(x: Num) -> Option<(f64, f64)> {
    let value = x.to_f64();
    if !value.is_finite() || value.abs() > LARGEST {
        return None;
    }
    let exact = BigRational::from_float(value)?;
    // X = x · 2^BITS, truncated (one unit).
    let scaled = (exact.numer() << BITS) / exact.denom();
    let one = BigInt::one() << BITS;
    let square = (&scaled * &scaled) >> BITS;
    let series = |first: BigInt, start: u64| {
        let (mut sum, mut term) = (first.clone(), first);
        let mut k = start;
        // Each term is the last times −x² / ((k + 1)(k + 2)): bounded by
        // the factorial's growth (|x| ≤ LARGEST ends it within 200 terms).
        for _ in 0..400 {
            term = -((&term * &square) >> BITS) / BigInt::from((k + 1) * (k + 2));
            if term.is_zero() {
                break;
            }
            sum += &term;
            k += 2;
        }
        sum
    };
    let sin = series(scaled, 1);
    let cos = series(one, 0);
    Some((nearest(&sin), nearest(&cos)))
}

/// The `f64` nearest `s · 2^−BITS`, ties to even.
fn nearest(s: &BigInt) -> f64 {
    let magnitude = s.abs();
    let bits = magnitude.bits();
    let value = if bits <= 53 {
        magnitude.to_f64().unwrap_or(0.0) * 2f64.powi(-(BITS as i32))
    } else {
        let drop = bits - 53;
        let mut kept = &magnitude >> drop;
        let rest = &magnitude - (&kept << drop);
        let half = BigInt::one() << (drop - 1);
        if rest > half || (rest == half && (&kept & BigInt::one()).is_one()) {
            kept += 1;
        }
        // kept ≤ 2^53: exact; the power of two is exact too.
        kept.to_f64().unwrap_or(f64::NAN) * 2f64.powi(drop as i32 - BITS as i32)
    };
    if s.is_negative() {
        -value
    } else {
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_and_cosine_of_constants_are_the_nearest_doubles() {
        // Values whose nearest doubles are known (from the exact values
        // sin 1 = 0.84147098480789650665…, cos 1 = 0.54030230586813971740…).
        let (s, c) = sin_cos(Num::int(1)).expect("small");
        assert_eq!((s, c), (0.8414709848078965, 0.5403023058681398));
        // 1.5708, as the double nearest it (exact values from a 50-digit
        // evaluation of the double's sine and cosine).
        let x = Num::parse_decimal("1.5708").expect("a decimal");
        let (s, c) = sin_cos(x).expect("small");
        assert_eq!((s, c), (0.9999999999932537, -3.673205103346574e-6));
        // Against the platform's functions, which are within an ulp.
        for text in ["0.2618", "-0.785398163397", "3.0", "-6.2", "1e-9", "15.9"] {
            let x = Num::parse_decimal(text).expect("a decimal");
            let v = x.to_f64();
            let (s, c) = sin_cos(x).expect("small");
            assert!(
                (s - v.sin()).abs() <= 2.0 * f64::EPSILON * s.abs().max(1e-300),
                "{text}"
            );
            assert!(
                (c - v.cos()).abs() <= 2.0 * f64::EPSILON * c.abs().max(1e-300),
                "{text}"
            );
        }
        assert_eq!(sin_cos(Num::Float(f64::NAN)), None);
        assert_eq!(sin_cos(Num::int(100)), None);
        assert_eq!(sin_cos(Num::ZERO), Some((0.0, 1.0)));
    }
}
