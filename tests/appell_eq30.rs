//! Appell's example yields exactly the paper's eq. 30:
//! `A = [ẋ, ẏ, −ż]`, `b = α (h_x ẋ + h_y ẏ + h_z ż + h_t)`,
//! with the partial derivatives of `h` written out by hand here.

use constrained::models::{Appell, AppellTimeDependent};
use constrained::nalgebra::Vector3;
use proptest::prelude::*;

use crate::common;

/// Equal to 1e-14 relative to `scale`, the sum of the magnitudes of the
/// terms that make up `expected` (relative to `|expected|` itself would ask
/// more than floating point can give where the terms cancel).
fn close(actual: f64, expected: f64, scale: f64) -> bool {
    (actual - expected).abs() <= 1e-14 * scale.max(f64::MIN_POSITIVE)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn eq30_with_h_equal_z((q, qd, t, g, alpha) in common::appell_state()) {
        let sys = Appell::new(g, alpha);
        let (a, b) = sys.constraint_matrices(&Vector3::from(q), &Vector3::from(qd), t);
        let [xd, yd, zd] = qd;
        // h = z: h_x = h_y = h_t = 0, h_z = 1.
        let expected_b = alpha * zd;
        prop_assert_eq!([a[0], a[1], a[2]], [xd, yd, -zd]);
        prop_assert!(close(b[0], expected_b, expected_b.abs()), "b = {} vs {}", b[0], expected_b);
    }

    #[test]
    fn eq30_with_time_dependent_h((q, qd, t, g, alpha) in common::appell_state()) {
        let sys = AppellTimeDependent::new(g, alpha);
        let (a, b) = sys.constraint_matrices(&Vector3::from(q), &Vector3::from(qd), t);
        let ([x, y, _], [xd, yd, zd]) = (q, qd);
        // h = x·y + sin t: h_x = y, h_y = x, h_z = 0, h_t = cos t.
        let expected_b = alpha * (y * xd + x * yd + 0.0 * zd + t.cos());
        let scale = alpha.abs() * ((y * xd).abs() + (x * yd).abs() + t.cos().abs());
        prop_assert_eq!([a[0], a[1], a[2]], [xd, yd, -zd]);
        prop_assert!(close(b[0], expected_b, scale), "b = {} vs {}", b[0], expected_b);
    }

    /// The same generated code compiled for f32 agrees with f64 to f32 precision.
    #[test]
    fn f32_agrees_with_f64((q, qd, t, g, alpha) in common::appell_state()) {
        let sys64 = AppellTimeDependent::new(g, alpha);
        let sys32 = AppellTimeDependent::<f32>::new(g as f32, alpha as f32);
        let (q32, qd32) = (Vector3::from(q).cast::<f32>(), Vector3::from(qd).cast::<f32>());
        let (a64, b64) = sys64.constraint_matrices(&Vector3::from(q), &Vector3::from(qd), t);
        let (a32, b32) = sys32.constraint_matrices(&q32, &qd32, t as f32);
        prop_assert!((a32.cast::<f64>() - a64).abs().max() < 1e-5 * a64.abs().max().max(1.0));
        // b involves cos t with |t| up to 100, where f32 rounding of t dominates.
        let scale = alpha.abs() * (q[0].abs() * qd[1].abs() + q[1].abs() * qd[0].abs() + 1.0);
        prop_assert!((f64::from(b32[0]) - b64[0]).abs() < 1e-4 * scale.max(1.0));
    }
}

#[test]
fn residual_is_the_constraint_as_written() {
    let sys = AppellTimeDependent::new(9.81, 0.5);
    let (q, qd, t) = (
        Vector3::new(1.0, 2.0, 3.0),
        Vector3::new(0.5, -1.0, 2.0),
        0.3_f64,
    );
    let phi = sys.constraint_residual(&q, &qd, t)[0];
    let expected = (0.25 + 1.0 - 4.0) / 2.0 - 0.5 * (1.0 * 2.0 + t.sin());
    assert!((phi - expected).abs() < 1e-15, "{phi} vs {expected}");
}

#[test]
fn constants_and_derivation() {
    assert_eq!(Appell::<f64>::DOF, 3);
    assert_eq!(Appell::<f64>::CONSTRAINTS, 1);
    let text = Appell::<f64>::DERIVATION;
    assert!(text.contains("A₁ = [ẋ, ẏ, −ż]"), "{text}");
    assert!(text.contains("b₁ = alpha·ż"), "{text}");
    let symbolic = Appell::<f64>::SYMBOLIC;
    assert_eq!(symbolic.a_matrix, &[&["dot(x)", "dot(y)", "-dot(z)"]]);
    assert_eq!(symbolic.coordinates, &["x", "y", "z"]);
}
