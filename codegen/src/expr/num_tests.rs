//! Unit tests of `num`: exact arithmetic, powers and decimal literals.

use super::Num;

#[test]
fn decimal_literals_are_exact() {
    assert_eq!(Num::parse_decimal("9.81"), Some(Num::Rational(981, 100)));
    assert_eq!(Num::parse_decimal("0.5"), Some(Num::Rational(1, 2)));
    assert_eq!(Num::parse_decimal("2"), Some(Num::Rational(2, 1)));
    assert_eq!(Num::parse_decimal("1e-3"), Some(Num::Rational(1, 1000)));
    assert_eq!(Num::parse_decimal("2.5E+2"), Some(Num::Rational(250, 1)));
    assert_eq!(Num::parse_decimal("1e300"), Some(Num::Float(1e300)));
    assert_eq!(Num::parse_decimal("x"), None);
}

/// Integer powers of rationals are exact and reduced, with their sign,
/// on either side of `i128`: a power that fits is a `Rational`, one
/// that does not is a `Big`.
#[test]
fn integer_powers_are_exact_across_i128() {
    let power = |n: i128, d: i128, e: i128| Num::ratio(n, d).pow(Num::Rational(e, 1));
    assert_eq!(power(-3, 4, 5), Some(Num::Rational(-243, 1024)));
    assert_eq!(power(2, 3, -3), Some(Num::Rational(27, 8)));
    assert_eq!(power(-2, 3, -3), Some(Num::Rational(-27, 8)));
    assert_eq!(power(5, 7, 0), Some(Num::ONE));
    assert_eq!(power(2, 1, 126), Some(Num::Rational(1 << 126, 1)));
    assert_eq!(power(-2, 1, 127), Some(Num::Rational(i128::MIN, 1)));
    let big = power(3, 1, 100).expect("exact");
    assert!(matches!(big, Num::Big(_)), "{big:?}");
    assert_eq!(big * power(3, 1, -100).expect("exact"), Num::ONE);
}

#[test]
fn arithmetic_is_exact_and_reduced() {
    let third = Num::ratio(1, 3);
    assert_eq!(third + third + third, Num::ONE);
    assert_eq!(Num::ratio(2, -4), Num::Rational(-1, 2));
    assert_eq!(Num::ratio(3, 4) * Num::ratio(8, 9), Num::Rational(2, 3));
    assert_eq!(
        Num::ratio(9, 4).pow(Num::ratio(1, 2)),
        Some(Num::Rational(3, 2))
    );
    assert_eq!(
        Num::ratio(9, 4).pow(Num::ratio(-3, 2)),
        Some(Num::Rational(8, 27))
    );
    assert_eq!(Num::int(2).pow(Num::ratio(1, 2)), None);
    assert_eq!(Num::int(2).pow(Num::int(-3)), Some(Num::Rational(1, 8)));
}

#[test]
fn overflow_stays_exact() {
    let big = Num::Rational(i128::MAX / 2, 1);
    let three = big + big + big;
    assert!(matches!(three, Num::Big(_)));
    // Exact: subtracting brings it back into i128.
    assert_eq!(three + -(big + big), big);
    assert!(matches!(Num::int(10).pow(Num::int(60)), Some(Num::Big(_))));
    assert_eq!(
        Num::int(10)
            .pow(Num::int(60))
            .map(|x| x * Num::int(10).pow(Num::int(-58)).unwrap()),
        Some(Num::int(100))
    );
    // Interned: equal values are one index, so equality is exact.
    assert_eq!(
        Num::int(10).pow(Num::int(60)),
        Num::int(10).pow(Num::int(60))
    );
    assert_eq!(three.to_f64(), 3.0 * (i128::MAX / 2) as f64);
}

/// 17-digit decimals multiplied as down a robot's chain: the product is
/// exact and rounds to the nearest f64 only at the end.
#[test]
fn products_of_long_decimals_are_exact() {
    let a = Num::parse_decimal("0.12345678901234567").expect("a decimal");
    let b = Num::parse_decimal("0.98765432109876543").expect("a decimal");
    let mut p = Num::ONE;
    for _ in 0..3 {
        p = p * a * b;
    }
    assert!(matches!(p, Num::Big(_)));
    for _ in 0..3 {
        p = p / (a * b);
    }
    assert_eq!(p, Num::ONE);
}

/// Stein's gcd against Euclid's, in and beyond 64 bits, signs and
/// zeros included.
#[test]
fn the_binary_gcd_is_euclids() {
    fn euclid(a: i128, b: i128) -> i128 {
        let (mut a, mut b) = (a.unsigned_abs(), b.unsigned_abs());
        while b != 0 {
            (a, b) = (b, a % b);
        }
        i128::try_from(a).unwrap_or(0)
    }
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        x
    };
    for round in 0..20_000 {
        let wide = |v: u64, w: u64| (i128::from(v) << 60) ^ i128::from(w);
        let (a, b) = match round % 4 {
            0 => (i128::from(next() as i64), i128::from(next() as i64)),
            1 => (wide(next() >> 8, next()), wide(next() >> 8, next())),
            2 => {
                let g = i128::from(next() >> 20);
                (g * i128::from(next() >> 30), -g * i128::from(next() >> 30))
            }
            _ => (i128::from(next() % 7), i128::from(next() % 5)),
        };
        assert_eq!(super::gcd(a, b), euclid(a, b), "gcd({a}, {b})");
    }
    assert_eq!(super::gcd(0, 0), 0);
    assert_eq!(super::gcd(i128::MIN, 0), euclid(i128::MIN, 0));
}

#[test]
fn powers_beyond_the_float_range_stay_symbolic() {
    assert_eq!(Num::ratio(5, 2).pow(Num::int(1296)), None);
    assert_eq!(Num::ratio(2, 5).pow(Num::int(1296)), None);
    assert_eq!(Num::Float(1e300).pow(Num::int(2)), None);
    assert_eq!(Num::ZERO.pow(Num::int(3)), Some(Num::ZERO));
}
