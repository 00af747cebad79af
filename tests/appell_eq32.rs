//! Appell's example: the generated `acceleration` equals the paper's closed
//! form eq. 32, written out here by hand, at 10⁴ random states; the constraint
//! force is its second term; at rest (`A = 0`) the result is the documented
//! minimum-norm one, `q̈ = a`.

use constrained::models::{Appell, AppellTimeDependent};
use constrained::nalgebra::Vector3;
use proptest::prelude::*;

use crate::common;

/// Eq. 32: q̈ = [0, 0, −g] + (b − ż g) / (ẋ² + ẏ² + ż²) · [ẋ, ẏ, −ż].
fn eq32(qd: [f64; 3], g: f64, b: f64) -> [f64; 3] {
    let [xd, yd, zd] = qd;
    let factor = (b - zd * g) / (xd * xd + yd * yd + zd * zd);
    [factor * xd, factor * yd, -g - factor * zd]
}

fn assert_close(actual: Vector3<f64>, expected: [f64; 3], scale: f64) -> Result<(), TestCaseError> {
    for i in 0..3 {
        prop_assert!(
            (actual[i] - expected[i]).abs() <= 1e-12 * scale,
            "component {i}: {} vs eq. 32 {}",
            actual[i],
            expected[i]
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(10_000))]

    #[test]
    fn acceleration_is_eq32((q, qd, t, g, alpha) in common::appell_state()) {
        let sys = Appell::new(g, alpha);
        let qdd = sys.acceleration(&Vector3::from(q), &Vector3::from(qd), t);
        // h = z: b = α ż.
        let b = alpha * qd[2];
        // Relative to the size of the terms: |a| + |constraint term|.
        let factor = (b.abs() + (qd[2] * g).abs()) / Vector3::from(qd).norm();
        assert_close(qdd, eq32(qd, g, b), g + factor)?;
    }

    #[test]
    fn time_dependent_acceleration_is_eq32((q, qd, t, g, alpha) in common::appell_state()) {
        let sys = AppellTimeDependent::new(g, alpha);
        let qdd = sys.acceleration(&Vector3::from(q), &Vector3::from(qd), t);
        let ([x, y, _], [xd, yd, _]) = (q, qd);
        let b = alpha * (y * xd + x * yd + t.cos());
        let b_scale = alpha.abs() * ((y * xd).abs() + (x * yd).abs() + 1.0);
        let factor = (b_scale + (qd[2] * g).abs()) / Vector3::from(qd).norm();
        assert_close(qdd, eq32(qd, g, b), g + factor)?;
    }

    /// The constraint force is the second term of eq. 32 (unit mass).
    #[test]
    fn constraint_force_is_the_second_term((q, qd, t, g, alpha) in common::appell_state()) {
        let sys = Appell::new(g, alpha);
        let force = sys.constraint_force(&Vector3::from(q), &Vector3::from(qd), t);
        let b = alpha * qd[2];
        let [xd, yd, zd] = qd;
        // The second term of eq. 32 itself (not q̈ − a, which cancels).
        let factor = (b - zd * g) / (xd * xd + yd * yd + zd * zd);
        let scale = (b.abs() + (zd * g).abs()) / Vector3::from(qd).norm();
        assert_close(force, [factor * xd, factor * yd, -factor * zd], scale.max(1e-300))?;
    }
}

#[test]
fn at_rest_the_result_is_unconstrained() {
    // A = [ẋ, ẏ, −ż] = 0: every q̈ satisfies A q̈ = b only if b = 0, and the
    // minimum-norm (Moore–Penrose) answer is q̈ = a.
    let sys = Appell::new(9.81, 0.5);
    let q = Vector3::new(1.0, 2.0, 3.0);
    let qdd = sys.acceleration(&q, &Vector3::zeros(), 0.0);
    assert_eq!(qdd, Vector3::new(0.0, 0.0, -9.81));
    assert_eq!(
        sys.constraint_force(&q, &Vector3::zeros(), 0.0),
        Vector3::zeros()
    );
    let mp = sys
        .acceleration_moore_penrose(&q, &Vector3::zeros(), 0.0)
        .unwrap();
    assert_eq!(mp, qdd);
    // Inconsistent too (b = α·cos t ≠ 0 at rest): still finite, still q̈ = a.
    let sys = AppellTimeDependent::new(9.81, 0.5);
    let qdd = sys.acceleration(&q, &Vector3::zeros(), 0.0);
    assert_eq!(qdd, Vector3::new(0.0, 0.0, -9.81));
}

/// Independent truth: reference vectors computed outside this repository
/// with sympy/numpy, their values written below (h = x·y·z + sin t, φ
/// written undivided: ẋ² + ẏ² − ż² − 2αh).
#[test]
fn reference_vectors() {
    constrained::constrained_system! {
        struct AppellReference {
            coordinates: [x, y, z],
            parameters: [g, alpha],
            mass: diag[1.0, 1.0, 1.0],
            forces: [0.0, 0.0, -g],
            definitions: [h = x * y * z + t.sin()],
            constraints: [dot(x).powi(2) + dot(y).powi(2) - dot(z).powi(2) - 2.0 * alpha * h],
        }
    }
    let cases: [([f64; 9], [f64; 3]); 3] = [
        (
            [
                1.0958241942238534,
                -0.24448624099179073,
                1.4343916796455298,
                0.7894721162374556,
                -1.6232906084494019,
                1.9024894065470237,
                1.0445588079614119,
                9.81,
                0.5,
            ],
            [-2.305046087048394, 4.73957165578127, -4.255243002232609],
        ),
        (
            [
                1.1442572211078152,
                -1.4875454692978165,
                -0.19845624841773146,
                -0.5168079030696751,
                1.7070599553944072,
                0.5754604803226582,
                1.29104645308332,
                9.81,
                0.5,
            ],
            [0.9221518786601173, -3.045945186794449, -8.783193018388015],
        ),
        (
            [
                -0.22634320469067548,
                -1.0910451128608925,
                0.2183391480633392,
                -1.7447309755832987,
                1.3105246879703283,
                0.5266575964882594,
                1.0323509603414953,
                9.81,
                0.5,
            ],
            [1.6168680754952889, -1.2144826679765015, -9.32193859317236],
        ),
    ];
    for ([x, y, z, xd, yd, zd, t, g, alpha], expected) in cases {
        let sys = AppellReference::new(g, alpha);
        let qdd = sys.acceleration(&Vector3::new(x, y, z), &Vector3::new(xd, yd, zd), t);
        for i in 0..3 {
            assert!(
                (qdd[i] - expected[i]).abs() < 1e-12 * 10.0,
                "{qdd} vs {expected:?}"
            );
        }
    }
}
