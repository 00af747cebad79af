//! URDF numbers as written: decimals read exactly, angles that are right
//! angles to double precision (or within the user's `right_angles_within`)
//! read as exact multiples of π/2.

use crate::bodies::spatial::V3;
use crate::expr::num::Num;
use crate::expr::Graph;
use syn::LitFloat;

pub(super) fn number(g: &mut Graph, text: &str) -> crate::expr::Id {
    g.num(Num::parse_decimal(text).unwrap_or(Num::ZERO))
}

pub(super) fn numbers(g: &mut Graph, texts: &[String; 3]) -> V3 {
    [0, 1, 2].map(|i| number(g, &texts[i]))
}

/// Angles as written, but for a multiple of π/2 to double precision
/// (see [`right_angle`]), or within `snap` of one, which is that multiple
/// exactly.
pub(super) fn angles(g: &mut Graph, texts: &[String; 3], snap: Option<f64>) -> V3 {
    [0, 1, 2].map(|i| match right_angle(&texts[i], snap) {
        Some(k) => {
            let pi = g.num(Num::Float(std::f64::consts::PI));
            let half = g.num(Num::ratio(k, 2)); // reduced: k may be even
            g.mul2(half, pi)
        }
        None => number(g, &texts[i]),
    })
}

/// `Some(k)` when the decimal `text` is `k π/2` (k ≠ 0) to double
/// precision: its nearest double within 4 ulps of the double nearest
/// `k π/2`. Such an angle is that multiple exactly, so a frame turned by a
/// right angle keeps its exact zeros, and no answer moves by more than
/// rounding. Any other decimal is read as written: `1.5708` and
/// `1.57079632679` are not π/2, as they are not to Pinocchio, MuJoCo or
/// Drake — unless the user asked for `right_angles_within: snap`, which
/// reads every angle within `snap` radians of `k π/2` as that multiple.
pub(super) fn right_angle(text: &str, snap: Option<f64>) -> Option<i128> {
    let value: f64 = text.trim().parse().ok()?;
    let quarter = std::f64::consts::FRAC_PI_2;
    let k = (value / quarter).round();
    if k == 0.0 || k.is_nan() || k.abs() >= 1e6 {
        return None;
    }
    let nearest = k * quarter;
    let within = snap.unwrap_or(0.0).max(4.0 * f64::EPSILON * nearest.abs());
    ((value - nearest).abs() <= within).then_some(k as i128)
}

/// The tolerance of `right_angles_within`: a finite number of radians in
/// (0, 0.01]. Anything wider would turn frames a user can see are not at
/// right angles (0.01 rad is over half a degree).
pub(super) fn tolerance(literal: &LitFloat) -> syn::Result<f64> {
    let value: f64 = literal.base10_parse()?;
    if value.is_finite() && value > 0.0 && value <= 0.01 {
        Ok(value)
    } else {
        Err(syn::Error::new(
            literal.span(),
            format!("`right_angles_within` is a tolerance in radians in (0, 0.01], not {value}"),
        ))
    }
}
