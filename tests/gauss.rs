//! The generalized-inverse equation for every reference model, at consistent
//! states built analytically for each: `A q̈ = b` holds, the constraint force
//! is `M q̈ − F`, and — the paper's claim — the choice of inverse does not
//! matter: the generated {1}-inverse, the Moore–Penrose form and random
//! {1,4}-inverses `X⁺ + Y(I − X X⁺)` of `X = A M^{-1/2}` (computed here with
//! dynamic nalgebra, independently of the generated code) give the same `q̈`;
//! and so does the explicit Gibbs–Appell form (the equivalence theorem).

use constrained::models::*;
use constrained::nalgebra::{SVector, Vector2, Vector3, Vector4};
use constrained::{ConstrainedSystem, State};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// Checks every claim at one consistent state; `seed` drives the random Y.
fn check<S: ConstrainedSystem<f64, N, K>, const N: usize, const K: usize>(
    system: &S,
    state: &State<f64, N>,
    seed: u64,
) -> Result<(), TestCaseError> {
    let phi = system.constraint_residual(state);
    prop_assume!(phi.norm() < 1e-9, "state not consistent: φ = {}", phi);
    let qdd = system.acceleration(state).expect("positive definite mass");
    let (a, b) = system.constraint_matrices(state);
    let m = system.mass_matrix(state);
    let f = system.forces(state);

    // A q̈ = b, relative to the size of the terms.
    let scale = (a.abs() * qdd.abs()).norm() + b.norm() + 1.0;
    prop_assert!(
        (a * qdd - b).norm() <= 1e-12 * scale,
        "A q̈ − b = {}",
        a * qdd - b
    );

    // acceleration_corrected solves A q̈ = b + db (constraint stabilization).
    let db = SVector::<f64, K>::from_fn(|i, _| 0.1 * (i as f64 + 1.0) * (1.0 + b.norm()));
    let corrected = system
        .acceleration_corrected(state, &db)
        .expect("positive definite mass");
    let singular = constrained::svd::JacobiSvd::new(&a)
        .expect("finite")
        .singular_values();
    if singular.iter().all(|&s| s > 1e-6 * singular.max()) {
        let target = b + db;
        prop_assert!(
            (a * corrected - target).norm() <= 1e-10 * scale * 10.0,
            "A q̈ − (b + db) = {}",
            a * corrected - target
        );
    }

    // Fᶜ = M q̈ − F.
    let force = system
        .constraint_force(state)
        .expect("positive definite mass");
    let expected = m * qdd - f;
    prop_assert!((force - expected).norm() <= 1e-10 * (expected.norm() + f.norm() + 1.0));

    // Every {1,4}-inverse of X = A M^{-1/2} gives the same q̈ (eq. 24).
    let md = DMatrix::from_column_slice(N, N, m.as_slice());
    let eig = md.clone().symmetric_eigen();
    let inv_sqrt = &eig.eigenvectors
        * DMatrix::from_diagonal(&eig.eigenvalues.map(|l| 1.0 / l.sqrt()))
        * eig.eigenvectors.transpose();
    let ad = DMatrix::from_column_slice(K, N, a.as_slice());
    let x = &ad * &inv_sqrt;
    let acc = md
        .clone()
        .cholesky()
        .expect("positive definite")
        .solve(&DVector::from_column_slice(f.as_slice()));
    let rhs = DVector::from_column_slice(b.as_slice()) - &ad * &acc;
    // X⁺ = Xᵀ (X Xᵀ)⁺ from the symmetric eigendecomposition of X Xᵀ (a third
    // algorithm: not the generated LDLᵀ, not the runtime's Jacobi SVD; and
    // not nalgebra's SVD, which is wrong on some of these matrices, #1172).
    let gram = &x * x.transpose();
    let eig = gram.symmetric_eigen();
    let cut = 1e-12 * eig.eigenvalues.amax().max(f64::MIN_POSITIVE);
    let inv = eig.eigenvalues.map(|l| if l > cut { 1.0 / l } else { 0.0 });
    let xp = x.transpose()
        * &eig.eigenvectors
        * DMatrix::from_diagonal(&inv)
        * eig.eigenvectors.transpose();
    let mut rng = seed;
    for trial in 0..4 {
        let y = if trial == 0 {
            DMatrix::zeros(N, K) // Moore–Penrose itself
        } else {
            DMatrix::from_fn(N, K, |_, _| {
                rng = rng
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((rng >> 11) as f64 / (1u64 << 53) as f64) * 20.0 - 10.0
            })
        };
        let g14 = &xp + &y * (DMatrix::identity(K, K) - &x * &xp);
        let other = &acc + &inv_sqrt * (&g14 * &rhs);
        let diff = (DVector::from_column_slice(qdd.as_slice()) - &other).norm();
        prop_assert!(
            diff <= 1e-10 * (other.norm() + 1.0),
            "{{1,4}}-inverse #{trial}: |Δq̈| = {diff}"
        );
    }
    // The paper's equivalence theorem: the explicit Gibbs–Appell form gives
    // the same q̈, and the generalized-inverse q̈ solves its system.
    let ga = system
        .acceleration_gibbs_appell(state)
        .expect("generic state: A has rank r");
    prop_assert!(
        (ga - qdd).norm() <= 1e-10 * (qdd.norm() + 1.0),
        "Gibbs–Appell: {} vs {}",
        ga,
        qdd
    );
    let (s, rhs) = system.gibbs_appell_matrices(state).expect("generic state");
    prop_assert!(
        (s * qdd - rhs).norm() <= 1e-10 * (s.abs() * qdd.abs() + rhs.abs()).norm().max(1.0)
    );
    // The generated Moore–Penrose form (Jacobi SVD in the runtime).
    let mp = system
        .acceleration_moore_penrose(state)
        .expect("finite state");
    prop_assert!(
        (mp - qdd).norm() <= 1e-10 * (qdd.norm() + 1.0),
        "Moore–Penrose: {} vs {}",
        mp,
        qdd
    );
    Ok(())
}

/// A random unit vector perpendicular to nothing in particular.
fn sphere(u: f64, v: f64) -> Vector3<f64> {
    let (theta, z) = (u * std::f64::consts::TAU, 2.0 * v - 1.0);
    let r = (1.0 - z * z).sqrt();
    Vector3::new(r * theta.cos(), r * theta.sin(), z)
}

fn double_pendulum_state(p: &[f64; 5], th: [f64; 4]) -> State<f64, 4> {
    constrained::models::double_pendulum_state(p[2], p[3], 0.0, [th[0], th[1]], [th[2], th[3]])
}

fn params<const P: usize>() -> impl Strategy<Value = [f64; P]> {
    prop::array::uniform::<_, P>(0.5..2.0f64)
}

/// A rate, exactly zero one time in ten: states at rest are common (every
/// simulation from rest starts there) and make `b` and the velocity terms
/// vanish, which uniform sampling never produces.
fn rate() -> impl Strategy<Value = f64> {
    prop_oneof![1 => Just(0.0), 9 => -3.0..3.0f64]
}

/// Two angles and two rates of the double pendulum.
fn angles() -> impl Strategy<Value = [f64; 4]> {
    (-3.0..3.0f64, -3.0..3.0f64, rate(), rate()).prop_map(|(a, b, c, d)| [a, b, c, d])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn appell(p in params::<2>(), q in prop::array::uniform3(-2.0..2.0f64),
              v in prop::array::uniform2(1.0..3.0f64), t in -5.0..5.0f64, seed: u64) {
        for h_time_dependent in [false, true] {
            let [g, alpha] = p;
            let [x, y, z] = q;
            let h = if h_time_dependent { x * y + t.sin() } else { z };
            let radicand = v[0] * v[0] + v[1] * v[1] - 2.0 * alpha * h;
            prop_assume!(radicand > 0.1);
            let state = State::new(t, Vector3::from(q), Vector3::new(v[0], v[1], radicand.sqrt()));
            if h_time_dependent {
                check(&AppellTimeDependent::new(g, alpha), &state, seed)?;
            } else {
                check(&Appell::new(g, alpha), &state, seed)?;
            }
        }
    }

    #[test]
    fn spherical_pendulum(p in params::<3>(), u in prop::array::uniform4(0.0..1.0f64), speed in rate(), seed: u64) {
        let n = sphere(u[0], u[1]);
        let v = sphere(u[2], u[3]) * speed;
        let state = State::new(0.0, n * p[2], v - n * n.dot(&v));
        check(&SphericalPendulum::new(p[0], p[1], p[2]), &state, seed)?;
    }

    #[test]
    fn double_pendulum_and_its_redundant_twin(p in params::<5>(), th in angles(), seed: u64) {
        let state = double_pendulum_state(&p, th);
        let plain = DoublePendulum::new(p[0], p[1], p[2], p[3], p[4]);
        let redundant = RedundantDoublePendulum::new(p[0], p[1], p[2], p[3], p[4]);
        check(&plain, &state, seed)?;
        check(&redundant, &state, seed)?;
        // The redundant constraint changes nothing (S is singular there).
        let (a, b) = (plain.acceleration(&state.q, &state.qd, 0.0).unwrap(),
                      redundant.acceleration(&state.q, &state.qd, 0.0).unwrap());
        prop_assert!((a - b).norm() <= 1e-12 * (a.norm() + 1.0), "{a} vs {b}");
        let fa = plain.constraint_force(&state.q, &state.qd, 0.0).unwrap();
        let fb = redundant.constraint_force(&state.q, &state.qd, 0.0).unwrap();
        prop_assert!((fa - fb).norm() <= 1e-11 * (fa.norm() + 1.0), "{fa} vs {fb}");
    }

    #[test]
    fn bead_on_rotating_hoop(p in params::<4>(), psi in -3.0..3.0f64, psid in rate(), t in -5.0..5.0f64, seed: u64) {
        let [m, g, r, w] = p;
        let (s, c) = ((w * t).sin(), (w * t).cos());
        let q = Vector3::new(r * psi.sin() * c, r * psi.sin() * s, -r * psi.cos());
        let qd = Vector3::new(
            r * (psi.cos() * psid * c - psi.sin() * w * s),
            r * (psi.cos() * psid * s + psi.sin() * w * c),
            r * psi.sin() * psid,
        );
        check(&BeadOnRotatingHoop::new(m, g, r, w), &State::new(t, q, qd), seed)?;
    }

    #[test]
    fn chaplygin_sleigh(p in params::<4>(), pose in prop::array::uniform3(-3.0..3.0f64), rates in (rate(), rate()), seed: u64) {
        let [m, inertia, a, torque] = p;
        let [x, y, th] = pose;
        let (u, thd) = rates; // u: speed of the contact point along the blade
        let qd = Vector3::new(u * th.cos() - a * th.sin() * thd, u * th.sin() + a * th.cos() * thd, thd);
        check(&ChaplyginSleigh::new(m, inertia, a, torque), &State::new(0.0, Vector3::new(x, y, th), qd), seed)?;
    }

    #[test]
    fn two_link_arm_on_line(p in params::<5>(), th in prop::array::uniform2(-3.0..3.0f64), w1 in rate(), seed: u64) {
        let [m1, m2, l1, l2, g] = p;
        let [t1, t2] = th;
        // The line passes through the tip: height = y of the tip.
        let height = l1 * t1.sin() + l2 * (t1 + t2).sin();
        let system = TwoLinkArmOnLine::new(m1, m2, l1, l2, g, height);
        // φ̇ = A q̇ = 0 fixes the second rate from the first.
        let (a, _) = system.constraint_matrices(&Vector2::new(t1, t2), &Vector2::zeros(), 0.0);
        prop_assume!(a[1].abs() > 1e-3);
        let qd = Vector2::new(w1, -a[0] * w1 / a[1]);
        check(&system, &State::new(0.0, Vector2::new(t1, t2), qd), seed)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// Crank angle θ and rate ω fix the mechanism: x₂ = r cos θ + √(l² − r² sin² θ).
    #[test]
    fn slider_crank(p in params::<6>(), th in -3.0..3.0f64, w in rate(), seed: u64) {
        let [m1, m2, r, rod, k, g] = p;
        let l = r * (1.1 + rod); // the rod must be longer than the crank
        let slider_crank = SliderCrank::new(m1, m2, r, l, k, g);
        let (s, c) = (th.sin(), th.cos());
        let root = (l * l - r * r * s * s).sqrt();
        let x2 = r * c + root;
        let x2_dot = -r * s * w - r * r * s * c * w / root;
        let q = Vector4::new(r * c, r * s, x2, 0.0);
        let qd = Vector4::new(-r * s * w, r * c * w, x2_dot, 0.0);
        check(&slider_crank, &State::new(0.0, q, qd), seed)?;
    }
}

constrained::constrained_system! {
    /// A particle on a circle described in skew coordinates: a constant but
    /// non-diagonal mass matrix, inverted exactly at compile time.
    struct SkewParticle {
        coordinates: [u, v],
        parameters: [g],
        mass: [[2.0, 0.5], [0.5, 1.0]],
        forces: [0.0, -g],
        constraints: [u.powi(2) + u * v + v.powi(2) == 1.0],
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// Constant, non-diagonal M: the same claims (Gibbs–Appell with eq. 37).
    #[test]
    fn constant_non_diagonal_mass(g in 0.5..20.0f64, phi in -3.0..3.0f64, w in rate(), seed: u64) {
        // u² + uv + v² = 1: a point of the ellipse and its tangent.
        let (c, s) = (phi.cos(), phi.sin());
        let radius = 1.0 / (1.0 + c * s).sqrt();
        let q = Vector2::new(radius * c, radius * s);
        let normal = Vector2::new(2.0 * q.x + q.y, q.x + 2.0 * q.y);
        let qd = Vector2::new(-normal.y, normal.x) * w;
        let system = SkewParticle::new(g);
        // A plain vector: M is a positive-definite constant, nothing can fail.
        let qdd: SVector<f64, 2> = system.acceleration(&q, &qd, 0.0);
        prop_assert!(qdd.iter().all(|x| x.is_finite()));
        check(&system, &State::new(0.0, q, qd), seed)?;
    }
}

/// The runtime's pivoted {1}-inverse and the generated structured one agree
/// on the redundant pendulum, where S is singular.
#[test]
fn pivoted_and_structured_inverses_agree() {
    let p = [1.0, 1.5, 1.2, 0.8, 9.81];
    let system = RedundantDoublePendulum::new(p[0], p[1], p[2], p[3], p[4]);
    let state = double_pendulum_state(&p, [0.7, -1.9, 1.3, -0.4]);
    let m = system.mass_matrix(&state.q, 0.0);
    let f = system.forces(&state.q, &state.qd, 0.0);
    let (a, b) = system.constraint_matrices(&state.q, &state.qd, 0.0);
    let minv = m.try_inverse().unwrap();
    let acc = minv * f;
    let s = a * minv * a.transpose();
    let sv = s.singular_values();
    assert!(sv.min() < 1e-12 * sv.max(), "S should be singular: {sv}");
    let lambda = constrained::inverse::PivotedLdlt::new(&s)
        .expect("finite")
        .solve(&(b - a * acc))
        .expect("representable");
    let pivoted: SVector<f64, 4> = acc + minv * a.transpose() * lambda;
    let generated = system.acceleration(&state.q, &state.qd, 0.0).unwrap();
    assert!(
        (pivoted - generated).norm() < 1e-12 * generated.norm(),
        "{pivoted} vs {generated}"
    );
}
