//! Numbers of the symbolic core: exact rationals, with `f64` only for what
//! was written as a float.
//!
//! DSL literals such as `9.81` or `0.5` are decimal and so exact rationals
//! (`981/100`, `1/2`). Keeping them exact keeps simplification exact
//! (`x/2 + x/2` is `x`, not `0.9999…x`), keeps the derivation text readable and
//! lets sympy compare the macro's expressions with its own exactly. A
//! rational that overflows `i128` — a URDF's 17-digit decimals multiplied
//! down a chain — becomes a big rational ([`Num::Big`]: an index into a
//! per-thread table of interned `BigRational`s, so that `Num` stays `Copy`
//! and equality stays an integer comparison), rounded to the nearest `f64`
//! only when the code is written. A float (a literal too long to be a
//! decimal rational, `π` of a URDF's `rpy`) absorbs whatever it is combined
//! with.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, ToPrimitive, Zero};
use std::cell::RefCell;
use std::collections::HashMap;

use std::cmp::Ordering;
use std::fmt;
use std::hash::{Hash, Hasher};

/// A constant: an exact rational `num/den` (reduced, `den > 0`), an exact
/// rational too large for `i128`, or a float.
#[derive(Clone, Copy, Debug)]
pub enum Num {
    /// Exact rational `numerator / denominator`, reduced, denominator positive.
    Rational(i128, i128),
    /// Exact rational whose numerator or denominator does not fit `i128`:
    /// the index of its entry in this thread's table (`BIG`), where equal
    /// values share one index. Never a value that fits `Rational`.
    Big(u32),
    /// Inexact: a literal too long to be a decimal rational, or `π`.
    Float(f64),
}

/// Exact values beyond `i128` never exceed this many bits in numerator or
/// denominator: a power that would (`(5/2)^1296`) stays symbolic, as a
/// float overflow does, so that no constant costs unbounded time or text.
const MAX_BITS: u64 = 2048;

/// The interned big rationals of this thread (the macro expands on one
/// thread): their values by index, and the index of each value.
struct BigTable {
    values: Vec<BigRational>,
    index: HashMap<BigRational, u32>,
}

thread_local! {
    static BIG: RefCell<BigTable> = RefCell::new(BigTable {
        values: Vec::new(),
        index: HashMap::new(),
    });
}

/// The value of `Num::Big(i)`.
fn big_value(i: u32) -> BigRational {
    BIG.with(|t| t.borrow().values[i as usize].clone())
}

/// `r` as a `Num`: `Rational` when it fits `i128`, an interned `Big`
/// otherwise; `None` past [`MAX_BITS`] (or, impossibly, past `u32::MAX`
/// entries).
fn from_big(r: BigRational) -> Option<Num> {
    if let (Some(n), Some(d)) = (r.numer().to_i128(), r.denom().to_i128()) {
        return Some(Num::Rational(n, d));
    }
    if r.numer().bits().max(r.denom().bits()) > MAX_BITS {
        return None;
    }
    BIG.with(|t| {
        let mut t = t.borrow_mut();
        if let Some(&i) = t.index.get(&r) {
            return Some(Num::Big(i));
        }
        let i = u32::try_from(t.values.len()).ok()?;
        t.values.push(r.clone());
        t.index.insert(r, i);
        Some(Num::Big(i))
    })
}

impl PartialEq for Num {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Num::Rational(a, b), Num::Rational(c, d)) => a == c && b == d,
            (Num::Big(a), Num::Big(b)) => a == b,
            (Num::Float(a), Num::Float(b)) => a.to_bits() == b.to_bits(),
            _ => false,
        }
    }
}
impl Eq for Num {}

impl Hash for Num {
    fn hash<H: Hasher>(&self, state: &mut H) {
        match self {
            Num::Rational(a, b) => (0u8, a, b).hash(state),
            Num::Float(f) => (1u8, f.to_bits()).hash(state),
            Num::Big(i) => (2u8, i).hash(state),
        }
    }
}

/// The greatest common divisor, in `u128` so that `|i128::MIN|` fits; 0
/// when it does not fit back into `i128` (both inputs `i128::MIN`), which
/// callers treat as "do not reduce".
fn gcd(a: i128, b: i128) -> i128 {
    let (a, b) = (a.unsigned_abs(), b.unsigned_abs());
    // Binary (Stein's): no division, which for 128 bits is a library call
    // (gcds and the divisions by them are frequent enough in an expansion
    // for that call to show); in 64 bits where both fit, as the
    // coefficients of most models do.
    let g = match (u64::try_from(a), u64::try_from(b)) {
        (Ok(a), Ok(b)) => u128::from(binary_gcd_u64(a, b)),
        _ => binary_gcd_u128(a, b),
    };
    i128::try_from(g).unwrap_or(0)
}

macro_rules! binary_gcd {
    ($name:ident, $t:ty) => {
        /// The greatest common divisor by Stein's algorithm (`gcd(0, b) = b`).
        fn $name(mut a: $t, mut b: $t) -> $t {
            if a == 0 || b == 0 {
                return a | b;
            }
            let shift = (a | b).trailing_zeros();
            a >>= a.trailing_zeros();
            loop {
                b >>= b.trailing_zeros();
                if a > b {
                    std::mem::swap(&mut a, &mut b);
                }
                b -= a;
                if b == 0 {
                    return a << shift;
                }
            }
        }
    };
}
binary_gcd!(binary_gcd_u64, u64);
binary_gcd!(binary_gcd_u128, u128);

/// `a / g` for a divisor `g` of `a` (> 0), in 64 bits where both fit.
fn divide(a: i128, g: i128) -> i128 {
    match (i64::try_from(a), i64::try_from(g)) {
        (Ok(a), Ok(g)) => i128::from(a / g),
        _ => a / g,
    }
}

/// The content of rational coefficients: the positive rational `c` with
/// every `xᵢ / c` an integer and those integers coprime (gcd of the
/// numerators over lcm of the denominators). `None` when a coefficient is
/// not an exact rational, when there are none, or when a step overflows.
pub fn content(coefficients: impl IntoIterator<Item = Num>) -> Option<Num> {
    let (mut numerator, mut denominator) = (0i128, 1i128);
    let mut any = false;
    for c in coefficients {
        let Num::Rational(p, q) = c else { return None };
        if p == 0 {
            continue;
        }
        any = true;
        numerator = gcd(numerator, p);
        let g = gcd(denominator, q);
        if numerator == 0 || g == 0 {
            return None;
        }
        denominator = divide(denominator, g).checked_mul(q)?;
    }
    any.then(|| Num::ratio(numerator, denominator))
}

impl Num {
    /// Zero.
    pub const ZERO: Num = Num::Rational(0, 1);
    /// One.
    pub const ONE: Num = Num::Rational(1, 1);
    /// Minus one.
    pub const MINUS_ONE: Num = Num::Rational(-1, 1);

    /// The integer `n`.
    pub fn int(n: i64) -> Num {
        Num::Rational(n.into(), 1)
    }

    /// `num/den` reduced; a float when `den` is zero (`±inf` or NaN, as `f64` says).
    pub fn ratio(num: i128, den: i128) -> Num {
        if den == 0 {
            return Num::Float(num as f64 / 0.0);
        }
        let g = gcd(num, den).max(1);
        let (mut n, mut d) = (divide(num, g), divide(den, g));
        if d < 0 {
            match (n.checked_neg(), d.checked_neg()) {
                (Some(nn), Some(dd)) => (n, d) = (nn, dd),
                _ => return Num::Float(num as f64 / den as f64),
            }
        }
        Num::Rational(n, d)
    }

    /// Parses a decimal literal (`12`, `0.5`, `1e-3`, `2.5E+2`) exactly when it
    /// fits, as a float otherwise. `None` when it is not a number at all.
    pub fn parse_decimal(text: &str) -> Option<Num> {
        let value: f64 = text.parse().ok()?;
        let (mantissa, exponent) = match text.find(['e', 'E']) {
            Some(i) => (&text[..i], text[i + 1..].parse::<i32>().ok()?),
            None => (text, 0),
        };
        let (int_part, frac_part) = mantissa.split_once('.').unwrap_or((mantissa, ""));
        let digits = format!("{int_part}{frac_part}");
        let scale = exponent - frac_part.len() as i32;
        let exact = digits.parse::<i128>().ok().and_then(|n| {
            let p = 10i128.checked_pow(scale.unsigned_abs())?;
            if scale >= 0 {
                Some(Num::ratio(n.checked_mul(p)?, 1))
            } else {
                Some(Num::ratio(n, p))
            }
        });
        Some(exact.unwrap_or(Num::Float(value)))
    }

    /// The value as `f64` (the nearest one for a big rational).
    pub fn to_f64(self) -> f64 {
        match self {
            // Exact operands, one rounding: the division itself.
            Num::Rational(n, d) if n.unsigned_abs() <= 1 << 53 && d <= 1 << 53 => {
                n as f64 / d as f64
            }
            // Larger ones are rounded once, to the nearest f64, not twice.
            Num::Rational(..) | Num::Big(_) => {
                self.exact().and_then(|x| x.to_f64()).unwrap_or(f64::NAN)
            }
            Num::Float(f) => f,
        }
    }

    /// The exact value, for a rational of either size.
    fn exact(self) -> Option<BigRational> {
        match self {
            // Already reduced, denominator positive: no gcd to compute.
            Num::Rational(n, d) => Some(BigRational::new_raw(BigInt::from(n), BigInt::from(d))),
            Num::Big(i) => Some(big_value(i)),
            Num::Float(_) => None,
        }
    }

    /// The exact value of a rational of either size (`None` for a float).
    pub fn exact_value(self) -> Option<BigRational> {
        self.exact()
    }

    /// Whether this is an exact rational (of either size), not a float.
    pub fn is_exact(self) -> bool {
        !matches!(self, Num::Float(_))
    }

    /// Whether this is exactly zero.
    pub fn is_zero(self) -> bool {
        self == Num::ZERO || matches!(self, Num::Float(f) if f == 0.0)
    }

    /// Whether this is exactly one.
    pub fn is_one(self) -> bool {
        self == Num::ONE || matches!(self, Num::Float(f) if f == 1.0)
    }

    /// Whether this is negative (from the sign alone: emission asks this
    /// of every term, and a rational past 2⁵³ once went through a big
    /// rational's reduction and conversion to answer it).
    pub fn is_negative(self) -> bool {
        match self {
            Num::Rational(n, _) => n < 0, // the denominator is positive
            Num::Big(i) => BIG.with(|t| t.borrow().values[i as usize].is_negative()),
            Num::Float(f) => f < 0.0,
        }
    }

    /// The value as an integer, when it is an exact integer.
    pub fn as_integer(self) -> Option<i64> {
        match self {
            Num::Rational(n, 1) => i64::try_from(n).ok(),
            _ => None,
        }
    }

    fn combine(
        self,
        other: Num,
        exact: impl Fn(i128, i128, i128, i128) -> Option<(i128, i128)>,
        big: impl Fn(BigRational, BigRational) -> BigRational,
        float: impl Fn(f64, f64) -> f64,
    ) -> Num {
        if let (Num::Rational(a, b), Num::Rational(c, d)) = (self, other) {
            if let Some((n, m)) = exact(a, b, c, d) {
                return Num::ratio(n, m);
            }
        }
        // Past i128 the value stays exact, as a big rational.
        if let (Some(x), Some(y)) = (self.exact(), other.exact()) {
            if let Some(value) = from_big(big(x, y)) {
                return value;
            }
        }
        Num::Float(float(self.to_f64(), other.to_f64()))
    }

    fn sum(self, other: Num) -> Num {
        self.combine(
            other,
            |a, b, c, d| {
                Some((
                    a.checked_mul(d)?.checked_add(c.checked_mul(b)?)?,
                    b.checked_mul(d)?,
                ))
            },
            |x, y| x + y,
            |x, y| x + y,
        )
    }

    fn product(self, other: Num) -> Num {
        // Integers (most coefficients): no gcd to take.
        if let (Num::Rational(a, 1), Num::Rational(c, 1)) = (self, other) {
            if let Some(p) = a.checked_mul(c) {
                return Num::Rational(p, 1);
            }
        }
        self.combine(
            other,
            |a, b, c, d| {
                // Cross-reduce first so that products of reduced fractions overflow late.
                let (g1, g2) = (gcd(a, d).max(1), gcd(c, b).max(1));
                let (a, b, c, d) = (divide(a, g1), divide(b, g2), divide(c, g2), divide(d, g1));
                Some((a.checked_mul(c)?, b.checked_mul(d)?))
            },
            |x, y| x * y,
            |x, y| x * y,
        )
    }

    /// `1 / self`.
    pub fn recip(self) -> Num {
        match self {
            Num::Rational(n, d) => Num::ratio(d, n),
            // Nonzero: zero fits i128.
            Num::Big(i) => {
                from_big(big_value(i).recip()).unwrap_or(Num::Float(1.0 / self.to_f64()))
            }
            Num::Float(f) => Num::Float(1.0 / f),
        }
    }

    /// `self ^ exponent` when the result is known exactly (integer exponent, or
    /// a perfect square under a half-integer exponent) or either is a float;
    /// `None` when it must stay symbolic (`2^(1/2)`), and when a float result
    /// overflows or underflows: folding `(5/2 · x)^1296` into `(5/2)^1296 ·
    /// x^1296` gave `∞ · 0 = NaN` at x = 0.2, where the power kept whole is
    /// an ordinary (subnormal) number at run time.
    pub fn pow(self, exponent: Num) -> Option<Num> {
        match self.pow_unchecked(exponent)? {
            Num::Float(f) if !f.is_finite() || (f == 0.0 && !self.is_zero()) => None,
            value => Some(value),
        }
    }

    fn pow_unchecked(self, exponent: Num) -> Option<Num> {
        if let (Num::Float(_), _) | (_, Num::Float(_)) = (self, exponent) {
            return Some(Num::Float(self.to_f64().powf(exponent.to_f64())));
        }
        if let Some(e) = exponent.as_integer() {
            return self.powi(e);
        }
        if let (Num::Rational(n, d), Num::Rational(p, 2)) = (self, exponent) {
            let (rn, rd) = (exact_sqrt(n)?, exact_sqrt(d)?);
            return Num::ratio(rn, rd).powi(i64::try_from(p).ok()?);
        }
        None
    }

    fn powi(self, e: i64) -> Option<Num> {
        // A nonzero rational whose power fits `i128`, as most do, without
        // the big-integer arithmetic below (the same value: `n/d` is
        // reduced, so `nᵏ/dᵏ` is too).
        if let (Num::Rational(n, d), Ok(k)) = (self, u32::try_from(e.unsigned_abs())) {
            match (n.checked_pow(k), d.checked_pow(k)) {
                (Some(pn), Some(pd)) if n != 0 && pn != i128::MIN => {
                    let value = Num::Rational(pn, pd);
                    return Some(if e < 0 { value.recip() } else { value });
                }
                _ => {}
            }
        }
        // `powf` with the exact integer (to 2⁵³): `powi(e as i32)` wrapped
        // 4294967295 to −1 and folded 2^4294967295 to 0.5.
        let Some(x) = self.exact() else {
            return Some(Num::Float(self.to_f64().powf(e as f64)));
        };
        if x.is_zero() {
            return Some(if e < 0 {
                Num::Float(f64::INFINITY)
            } else if e == 0 {
                Num::ONE
            } else {
                Num::ZERO
            });
        }
        // Exact when the result stays within MAX_BITS; symbolic otherwise.
        let k = e.unsigned_abs();
        let bits = x.numer().bits().max(x.denom().bits());
        if bits.saturating_mul(k) > MAX_BITS + 64 {
            return None;
        }
        let k = u32::try_from(k).ok()?;
        let value = from_big(num_traits::pow::Pow::pow(&x, k))?;
        Some(if e < 0 { value.recip() } else { value })
    }
}

fn exact_sqrt(n: i128) -> Option<i128> {
    if n < 0 {
        return None;
    }
    let r = (n as f64).sqrt().round() as i128;
    (r.checked_mul(r) == Some(n)).then_some(r)
}

impl std::ops::Add for Num {
    type Output = Num;
    fn add(self, other: Num) -> Num {
        self.sum(other)
    }
}

impl std::ops::Mul for Num {
    type Output = Num;
    fn mul(self, other: Num) -> Num {
        self.product(other)
    }
}

impl std::ops::Neg for Num {
    type Output = Num;
    fn neg(self) -> Num {
        self.product(Num::MINUS_ONE)
    }
}

impl std::ops::Div for Num {
    type Output = Num;
    fn div(self, other: Num) -> Num {
        self.product(other.recip())
    }
}

impl PartialOrd for Num {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        self.to_f64().partial_cmp(&other.to_f64())
    }
}

impl fmt::Display for Num {
    /// Integers as `3`, rationals as `3/4`, floats in Rust's shortest round-trip form.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Num::Rational(n, 1) => write!(f, "{n}"),
            Num::Rational(n, d) => write!(f, "{n}/{d}"),
            Num::Big(i) => write!(f, "{}", big_value(*i)),
            Num::Float(x) => write!(f, "{x:?}"),
        }
    }
}

#[cfg(test)]
#[path = "num_tests.rs"]
mod tests;
