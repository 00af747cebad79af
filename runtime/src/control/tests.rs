//! Tests of `discretize` and `lqr_gain`.

use super::*;
use nalgebra::{Matrix1, Matrix2, Matrix2x1, Matrix4, Matrix4x1};

/// Largest entrywise relative error of `got` against `want` (absolute
/// where `want` is zero).
fn relative<const R: usize, const C: usize>(
    got: &SMatrix<f64, R, C>,
    want: &SMatrix<f64, R, C>,
) -> f64 {
    got.iter().zip(want.iter()).fold(0.0, |m, (g, w)| {
        let e = if *w == 0.0 {
            g.abs()
        } else {
            ((g - w) / w).abs()
        };
        m.max(e)
    })
}

/// `diag(λ)` discretized: `A_d = diag(e^{λh})`, `B_d = diag((e^{λh} − 1)/λ) B`,
/// the reference by `exp_m1` of each entry.
fn diagonal_reference(l: [f64; 2], b: [f64; 2], h: f64) -> (Matrix2<f64>, Matrix2x1<f64>) {
    let ad = Matrix2::new((l[0] * h).exp(), 0.0, 0.0, (l[1] * h).exp());
    let gamma = |x: f64| (x * h).exp_m1() / x;
    let bd = Matrix2x1::new(gamma(l[0]) * b[0], gamma(l[1]) * b[1]);
    (ad, bd)
}

/// `diag(−1e308, −1e308)` over `h = 50`: `‖A h‖` overflows, and a naive
/// scaling halves `h` 1100 times into 0 and returns `(I, 0)`. Exact:
/// `A_d = 0`, `B_d = 1e-308` (subnormal: to ~2 ulps of a normal number).
#[test]
fn discretize_survives_a_norm_beyond_the_range() {
    let a = Matrix2::new(-1e308, 0.0, 0.0, -1e308);
    let b = Matrix2x1::new(1.0f64, 1.0);
    let (ad, bd) = discretize(&a, &b, 50.0).expect("representable");
    assert_eq!(ad, Matrix2::zeros());
    for x in bd.iter() {
        assert!(((x - 1e-308) / 1e-308).abs() < 1e-13, "{bd}");
    }
    // A huge step on a moderately stiff A: A_d = 0 to the last bit,
    // B_d = −A⁻¹ B.
    for h in [1e300, 1e306, f64::MAX] {
        let l = [-1e6, -1.0];
        let a = Matrix2::new(l[0], 0.0, 0.0, l[1]);
        let (ad, bd) = discretize(&a, &b, h).expect("representable");
        assert_eq!(ad, Matrix2::zeros(), "h = {h}");
        assert!(relative(&bd, &Matrix2x1::new(1e-6, 1.0)) < 1e-14, "{bd}");
    }
    // The unstable counterpart overflows and says so.
    let a = Matrix2::new(1e308, 0.0, 0.0, 1.0);
    assert_eq!(discretize(&a, &b, 50.0), Err(ControlError::NonFinite));
}

/// A stiff `A` keeps its slow mode: `diag(−1e16, −1)`, `h = 1` must not
/// give `A_d[1,1] = 1` (`e^{−2⁻⁵⁵}` rounds to 1 if squared back naively),
/// and `diag(−1e12, −1)`, `h = 0.02` must not lose digits to the fast mode.
#[test]
fn discretize_keeps_the_slow_mode_of_a_stiff_matrix() {
    let b = [1.0, 1.0];
    for (l, h) in [
        ([-1e16f64, -1.0], 1.0f64),
        ([-1e12, -1.0], 0.02),
        ([-1e12, -1e-6], 0.02),
        ([-1e200, -3.0], 7.0),
        ([-1e3, 0.5], 3.0),
    ] {
        let a = Matrix2::new(l[0], 0.0, 0.0, l[1]);
        let (ad, bd) = discretize(&a, &Matrix2x1::from(b), h).expect("finite");
        let (ad_ref, bd_ref) = diagonal_reference(l, b, h);
        // Each squaring adds a rounding: ~log₂‖A h‖ of them.
        let allowed = 1e-15 * (l[0].abs() * h).log2().max(1.0);
        assert!(
            relative(&ad, &ad_ref) < allowed,
            "{l:?} {h}: {ad} vs {ad_ref}"
        );
        assert!(
            relative(&bd, &bd_ref) < allowed,
            "{l:?} {h}: {bd} vs {bd_ref}"
        );
    }
}

/// Non-diagonal references by closed forms: a stiff `A = V diag(λ) V⁻¹`
/// with `V = [[1, 1], [0, 1]]`, a rotation generator, and a Jordan
/// block.
#[test]
fn discretize_matches_closed_forms_of_non_diagonal_matrices() {
    let b = Matrix2x1::new(0.3, -1.7);
    // e^{Ah} = V e^{Dh} V⁻¹ = [[e₁, e₂ − e₁], [0, e₂]], Γ likewise.
    for (l, h) in [
        ([-1e12f64, -1.0], 0.02f64),
        ([-1e9, -2.0], 1.0),
        ([-50.0, -0.1], 0.3),
    ] {
        let a = Matrix2::new(l[0], l[1] - l[0], 0.0, l[1]);
        let (e1, e2) = ((l[0] * h).exp(), (l[1] * h).exp());
        let (g1, g2) = ((l[0] * h).exp_m1() / l[0], (l[1] * h).exp_m1() / l[1]);
        let ad_ref = Matrix2::new(e1, e2 - e1, 0.0, e2);
        let gamma = Matrix2::new(g1, g2 - g1, 0.0, g2);
        let (ad, bd) = discretize(&a, &b, h).expect("finite");
        assert!((ad - ad_ref).amax() < 1e-13, "{ad} vs {ad_ref}");
        assert!(relative(&bd, &(gamma * b)) < 1e-12, "{bd} vs {}", gamma * b);
    }
    // Full (not triangular) and exact in f64: A = Q diag(λ) Qᵀ with the
    // Hadamard Q = [[1, 1], [1, −1]]/√2, A = ½[[λ₁+λ₂, λ₁−λ₂], [λ₁−λ₂, λ₁+λ₂]].
    // A backward-stable exponential is accurate to ε ‖A h‖ ‖e^{Ah}‖ here
    // (the condition of e^X for a normal X is ‖X‖): the slow mode of a
    // full stiff A is held by the difference of two fast entries, and
    // forming A τ rounds each of them.
    for (l, h) in [
        ([-1e12f64, -1.0], 0.02f64),
        ([-1e6, -1.0], 1.0),
        ([-1e3, -0.5], 4.0),
    ] {
        let (sum, diff) = (l[0] + l[1], l[0] - l[1]);
        let a = Matrix2::new(sum, diff, diff, sum) * 0.5;
        let (e1, e2) = ((l[0] * h).exp(), (l[1] * h).exp());
        let (g1, g2) = ((l[0] * h).exp_m1() / l[0], (l[1] * h).exp_m1() / l[1]);
        let ad_ref = Matrix2::new(e1 + e2, e1 - e2, e1 - e2, e1 + e2) * 0.5;
        let gamma = Matrix2::new(g1 + g2, g1 - g2, g1 - g2, g1 + g2) * 0.5;
        let (ad, bd) = discretize(&a, &b, h).expect("finite");
        let bound = f64::EPSILON * l[0].abs() * h;
        let (ead, ebd) = (
            (ad - ad_ref).amax(),
            (bd - gamma * b).amax() / (gamma * b).amax(),
        );
        assert!(ead < bound, "{l:?}: {ead:e} ≥ {bound:e}: {ad} vs {ad_ref}");
        assert!(ebd < bound, "{l:?}: {ebd:e} ≥ {bound:e}");
    }
    // Rotation: e^{Ah} = [[cos, sin], [−sin, cos]] (ω h = 1000 rad).
    let (omega, h) = (2.0, 500.0);
    let a = Matrix2::new(0.0, omega, -omega, 0.0);
    let (ad, bd) = discretize(&a, &b, h).expect("finite");
    let (s, co) = (omega * h).sin_cos();
    let ad_ref = Matrix2::new(co, s, -s, co);
    let gamma = Matrix2::new(s, 1.0 - co, co - 1.0, s) / omega;
    assert!((ad - ad_ref).amax() < 1e-12, "{ad} vs {ad_ref}");
    assert!((bd - gamma * b).amax() < 1e-12, "{bd} vs {}", gamma * b);
    // Jordan block: e^{Ah} = e^{λh} [[1, h], [0, 1]].
    let (l, h) = (-1e4f64, 1e-3f64);
    let a = Matrix2::new(l, 1.0, 0.0, l);
    let (ad, _) = discretize(&a, &b, h).expect("finite");
    let e = (l * h).exp();
    assert!(
        relative(&ad, &Matrix2::new(e, e * h, 0.0, e)) < 1e-14,
        "{ad}"
    );
}

/// The Riccati residual is small with a tight tolerance but the gain
/// does not stabilize: `diag(1, 0.5)`, `B = [0, 1]ᵀ` (the unit mode
/// is out of reach) returned `Ok(K = [0, 0.266])`, `ρ(A − BK) = 1`.
#[test]
fn lqr_gain_of_an_unstabilizable_pair_is_not_converged() {
    let a = Matrix2::new(1.0, 0.0, 0.0, 0.5);
    let b = Matrix2x1::new(0.0, 1.0);
    let q = Matrix2::identity();
    let r = Matrix1::new(1.0);
    for tolerance in [1e-12, 1e-3, 0.1, 0.9] {
        assert_eq!(
            lqr_gain(&a, &b, &q, &r, tolerance, 10_000),
            Err(ControlError::NotConverged),
            "tolerance {tolerance}"
        );
    }
}

/// Tolerances `inf`, NaN (which ran every iteration: a hang at 10⁹),
/// zero, negative and ≥ 1, and a zero budget, are refused up front.
#[test]
fn lqr_gain_refuses_tolerances_that_cannot_work() {
    let a = Matrix1::new(1.2);
    let b = Matrix1::new(0.5);
    let (q, r) = (Matrix1::new(2.0), Matrix1::new(0.3));
    for tolerance in [f64::INFINITY, f64::NAN, 0.0, -1e-9, 1.0, 5.0] {
        assert_eq!(
            lqr_gain(&a, &b, &q, &r, tolerance, usize::MAX),
            Err(ControlError::InvalidParameter),
            "tolerance {tolerance}"
        );
    }
    assert_eq!(
        lqr_gain(&a, &b, &q, &r, 1e-12, 0),
        Err(ControlError::InvalidParameter)
    );
}

/// The cart-pole of `examples/cart_pole_lqr.rs` (upright, 10 ms hold):
/// a loose tolerance (0.1) is met by an early iteration's gain, whose
/// closed loop has ρ = 1.02, which must not be returned. Every returned
/// gain must stabilize:
/// ρ(A_d − B_d K) < 1, checked by the eigenvalues (an independent
/// test from the library's certificate).
#[test]
fn lqr_gain_with_a_loose_tolerance_still_stabilizes() {
    // ẍ, θ̈ of the cart-pole linearized upright (mc = 1, mp = 0.1,
    // l = 0.5, g = 9.81): A = [[0, I], [[0, mp g/mc], [0, (mc+mp) g/(mc l)]]].
    let (mc, mp, l, g) = (1.0f64, 0.1, 0.5, 9.81);
    let a = Matrix4::new(
        0.0,
        0.0,
        1.0,
        0.0, //
        0.0,
        0.0,
        0.0,
        1.0, //
        0.0,
        mp * g / mc,
        0.0,
        0.0, //
        0.0,
        (mc + mp) * g / (mc * l),
        0.0,
        0.0,
    );
    let b = Matrix4x1::new(0.0, 0.0, 1.0 / mc, 1.0 / (mc * l));
    let (ad, bd) = discretize(&a, &b, 0.01).expect("finite");
    let q = Matrix4::from_diagonal(&nalgebra::Vector4::new(1.0, 10.0, 0.1, 0.1));
    let r = Matrix1::new(0.1);
    let tight = lqr_gain(&ad, &bd, &q, &r, 1e-13, 100_000).expect("stabilizable");
    for tolerance in [0.5, 0.1, 1e-2, 1e-4, 1e-8, 1e-12] {
        let k = lqr_gain(&ad, &bd, &q, &r, tolerance, 100_000).expect("stabilizable");
        let closed: Matrix4<f64> = ad - bd * k;
        let rho = closed
            .complex_eigenvalues()
            .iter()
            .fold(0.0f64, |m, z| m.max(z.re.hypot(z.im)));
        assert!(rho < 1.0, "tolerance {tolerance}: ρ = {rho}");
        if tolerance <= 1e-8 {
            assert!((k - tight).amax() < 1e-4 * tight.amax(), "{k} vs {tight}");
        }
    }
}

/// The double integrator: `A_d = [[1, h], [0, 1]]`, `B_d = [h²/2, h]`.
#[test]
fn discretizes_the_double_integrator_exactly() {
    let a = Matrix2::new(0.0, 1.0, 0.0, 0.0);
    let b = Matrix2x1::new(0.0, 1.0);
    let (ad, bd) = discretize(&a, &b, 0.1).expect("finite");
    assert!((ad - Matrix2::new(1.0, 0.1, 0.0, 1.0)).amax() < 1e-15);
    assert!((bd - Matrix2x1::new(0.005, 0.1)).amax() < 1e-15);
    // A long step takes the squaring path: e^{a h} for a scalar a.
    let (ad, bd) = discretize(&Matrix1::new(-3.0), &Matrix1::new(1.0), 5.0).expect("finite");
    assert!((ad[0] - (-15.0f64).exp()).abs() < 1e-15);
    assert!((bd[0] - (1.0 - (-15.0f64).exp()) / 3.0).abs() < 1e-15);
}

/// A scalar system has the closed-form Riccati solution
/// `p = q + a² p r / (r + b² p)`, solved as a quadratic.
#[test]
fn scalar_gain_matches_the_closed_form() {
    let (a, b, q, r): (f64, f64, f64, f64) = (1.2, 0.5, 2.0, 0.3);
    // b² p² + (r − a² r − q b²) p − q r = 0.
    let (qa, qb, qc) = (b * b, r - a * a * r - q * b * b, -q * r);
    let p = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
    let k = b * p * a / (r + b * b * p);
    let got = lqr_gain(
        &Matrix1::new(a),
        &Matrix1::new(b),
        &Matrix1::new(q),
        &Matrix1::new(r),
        1e-14,
        1000,
    )
    .expect("stabilizable");
    assert!((got[0] - k).abs() < 1e-12, "{} vs {k}", got[0]);
    assert!((a - b * got[0]).abs() < 1.0, "closed loop stable");
}

#[test]
fn unstabilizable_pairs_and_bad_weights_are_errors() {
    // An unstable mode the input cannot reach.
    let a = Matrix2::new(2.0, 0.0, 0.0, 0.5);
    let b = Matrix2x1::new(0.0, 1.0);
    let q = Matrix2::identity();
    let r = Matrix1::new(1.0);
    assert_eq!(
        lqr_gain(&a, &b, &q, &r, 1e-12, 200),
        Err(ControlError::NotConverged)
    );
    assert_eq!(
        lqr_gain(&a, &b, &q, &Matrix1::new(-1.0), 1e-12, 200),
        Err(ControlError::NotPositiveDefinite)
    );
    assert_eq!(discretize(&a, &b, f64::NAN), Err(ControlError::NonFinite));
}

/// The cost `P_K` of a stabilizing gain by the plain fixed point
/// `P ← Q + KᵀRK + A_Kᵀ P A_K` (independent of the library's doubling).
fn cost_of_gain(
    a: &Matrix4<f64>,
    b: &Matrix4x1<f64>,
    q: &Matrix4<f64>,
    r: &Matrix1<f64>,
    k: &SMatrix<f64, 1, 4>,
) -> Matrix4<f64> {
    let closed = a - b * k;
    let s = q + k.transpose() * r * k;
    let mut p = s;
    for _ in 0..200_000 {
        p = s + closed.transpose() * p * closed;
    }
    p
}

/// The relative Riccati residual of `P`:
/// `‖Q + AᵀPA − AᵀPB (R + BᵀPB)⁻¹ BᵀPA − P‖ / ‖P‖` (largest entries).
fn riccati_residual(
    a: &Matrix4<f64>,
    b: &Matrix4x1<f64>,
    q: &Matrix4<f64>,
    r: &Matrix1<f64>,
    p: &Matrix4<f64>,
) -> f64 {
    let s = r + b.transpose() * p * b;
    let k = s.try_inverse().expect("R + BᵀPB invertible") * b.transpose() * p * a;
    let residual = q + a.transpose() * p * a - a.transpose() * p * b * k - p;
    residual.amax() / p.amax()
}

/// The cart-pole of `examples/cart_pole_lqr.rs` (`mc = 1`, `mp = 0.3`,
/// `l = 0.8`, upright, 10 ms hold) with loose tolerances: the gain's own
/// Riccati residual (of its cost `P_K`) is within the tolerance asked for.
/// The iteration's step alone once returned, at 0.1, a gain with residual
/// 0.26, 34 % from the Riccati solution (one entry 90 %).
#[test]
fn lqr_gain_meets_its_tolerance_as_a_riccati_residual() {
    let (mc, mp, l, g) = (1.0f64, 0.3, 0.8, 9.81);
    let mut a = Matrix4::zeros();
    a[(0, 2)] = 1.0;
    a[(1, 3)] = 1.0;
    a[(2, 1)] = mp * g / mc;
    a[(3, 1)] = (mc + mp) * g / (mc * l);
    let b = Matrix4x1::new(0.0, 0.0, 1.0 / mc, 1.0 / (mc * l));
    let (ad, bd) = discretize(&a, &b, 0.01).expect("finite");
    let q = Matrix4::from_diagonal(&nalgebra::Vector4::new(1.0, 10.0, 0.1, 0.1));
    let r = Matrix1::new(0.1);
    let tight = lqr_gain(&ad, &bd, &q, &r, 1e-13, 100_000).expect("stabilizable");
    for tolerance in [0.5, 0.1, 1e-2, 1e-3, 1e-4, 1e-6] {
        let k = lqr_gain(&ad, &bd, &q, &r, tolerance, 100_000).expect("stabilizable");
        let p = cost_of_gain(&ad, &bd, &q, &r, &k);
        let residual = riccati_residual(&ad, &bd, &q, &r, &p);
        let error = (k - tight).amax() / tight.amax();
        println!("tolerance {tolerance:e}: residual {residual:.2e}, K off by {error:.2e}");
        assert!(
            residual <= tolerance,
            "tolerance {tolerance:e}: relative Riccati residual {residual:e}"
        );
    }
}
