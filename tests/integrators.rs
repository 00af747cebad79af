//! The runtime's integrators on problems with known answers: convergence
//! order, conservation laws, constraint drift with and without
//! stabilization, f32, and errors as values.

use constrained::models::{AppellTimeDependent, DoublePendulum, SphericalPendulum};
use constrained::nalgebra::{Vector2, Vector3};

use constrained::{
    constrained_system, BogackiShampine32, DormandPrince45, IntegrationError, Rk4,
    SemiImplicitEuler, Stabilization, State, ThreeEighthsRule,
};

constrained_system! {
    /// A free particle on a circle of radius r: uniform circular motion,
    /// x = r cos ωt, y = r sin ωt, a nonlinear constraint with a known solution.
    struct Circle {
        coordinates: [x, y],
        parameters: [r],
        mass: diag[1.0, 1.0],
        constraints: [x.powi(2) + y.powi(2) == r.powi(2)],
    }
}

constrained_system! {
    /// ẍ = x²: blows up in finite time (at t = ln 2 ≈ 0.69 from x = ẋ... = 1).
    struct BlowUp {
        coordinates: [x],
        mass: diag[1.0],
        forces: [x.powi(3)],
    }
}

const OMEGA: f64 = 1.3;

fn circle_start() -> State<f64, 2> {
    State::new(0.0, Vector2::new(1.0, 0.0), Vector2::new(0.0, OMEGA))
}

fn circle_error(state: &State<f64, 2>) -> f64 {
    let t = state.t;
    (state.q - Vector2::new((OMEGA * t).cos(), (OMEGA * t).sin())).norm()
}

/// The errors at t = 4 on the circle for three halving step sizes, and the
/// ratios of successive errors: 2^p for a method of order p.
fn error_ratios(steps: [f64; 3], advance: impl Fn(&mut State<f64, 2>, f64)) -> Vec<f64> {
    let errors: Vec<f64> = steps
        .iter()
        .map(|&h| {
            let mut s = circle_start();
            advance(&mut s, h);
            assert_eq!(s.t, 4.0);
            circle_error(&s)
        })
        .collect();
    errors.windows(2).map(|pair| pair[0] / pair[1]).collect()
}

#[test]
fn rk4_converges_at_order_4() {
    let system = Circle::new(1.0);
    let ratios = error_ratios([0.04, 0.02, 0.01], |s, h| {
        Rk4::new(h).advance(&system, s, 4.0).unwrap();
    });
    assert!(
        ratios.iter().all(|r| (14.0..18.0).contains(r)),
        "{ratios:?}"
    );
}

#[test]
fn three_eighths_rule_converges_at_order_4() {
    let system = Circle::new(1.0);
    let ratios = error_ratios([0.04, 0.02, 0.01], |s, h| {
        ThreeEighthsRule::new(h).advance(&system, s, 4.0).unwrap();
    });
    assert!(
        ratios.iter().all(|r| (14.0..18.0).contains(r)),
        "{ratios:?}"
    );
}

#[test]
fn dormand_prince_converges_at_order_5() {
    let system = Circle::new(1.0);
    let ratios = error_ratios([0.2, 0.1, 0.05], |s, h| {
        DormandPrince45::new(1e-6, 1e-6)
            .advance_fixed(&system, s, 4.0, h)
            .unwrap();
    });
    assert!(
        ratios.iter().all(|r| (28.0..37.0).contains(r)),
        "{ratios:?}"
    );
}

#[test]
fn bogacki_shampine_converges_at_order_3() {
    let system = Circle::new(1.0);
    let ratios = error_ratios([0.04, 0.02, 0.01], |s, h| {
        BogackiShampine32::new(1e-6, 1e-6)
            .advance_fixed(&system, s, 4.0, h)
            .unwrap();
    });
    assert!(ratios.iter().all(|r| (7.0..9.5).contains(r)), "{ratios:?}");
}

#[test]
fn bogacki_shampine_meets_its_tolerance_with_three_evaluations_a_step() {
    let system = Circle::new(1.0);
    for rtol in [1e-4, 1e-6, 1e-8] {
        let mut s = circle_start();
        let stats = BogackiShampine32::new(rtol, rtol)
            .advance(&system, &mut s, 10.0)
            .unwrap();
        let error = circle_error(&s);
        assert!(
            error < 100.0 * rtol * 10.0,
            "rtol {rtol}: error {error} after {stats:?}"
        );
        assert_eq!(
            stats.evaluations,
            3 * (stats.steps + stats.rejected) + 2,
            "FSAL: 3 evaluations a step"
        );
    }
}

#[test]
fn dormand_prince_meets_its_tolerance_and_adapts() {
    let system = Circle::new(1.0);
    for rtol in [1e-6, 1e-9, 1e-12] {
        let mut s = circle_start();
        let stats = DormandPrince45::new(rtol, rtol)
            .advance(&system, &mut s, 10.0)
            .unwrap();
        assert_eq!(s.t, 10.0);
        let error = circle_error(&s);
        assert!(
            error < 100.0 * rtol * 10.0,
            "rtol {rtol}: error {error} after {stats:?}"
        );
    }
    // Tighter tolerance, more steps; a hard start forces rejections.
    let mut s = circle_start();
    let loose = DormandPrince45::new(1e-4, 1e-4)
        .advance(&system, &mut s, 10.0)
        .unwrap();
    let mut s = circle_start();
    let tight = DormandPrince45::new(1e-10, 1e-10)
        .advance(&system, &mut s, 10.0)
        .unwrap();
    assert!(tight.steps > 5 * loose.steps, "{loose:?} vs {tight:?}");
    assert_eq!(
        tight.evaluations,
        6 * (tight.steps + tight.rejected) + 2,
        "FSAL: 6 evaluations a step"
    );
}

#[test]
fn spherical_pendulum_conserves_energy_and_angular_momentum() {
    let (m, g, l) = (1.3, 9.81, 0.8);
    let system = SphericalPendulum::new(m, g, l);
    let n = Vector3::new(0.6, 0.0, -0.8);
    let v = Vector3::new(0.0, 1.9, 0.0); // tangent to the sphere at n
    let mut s = State::new(0.0, n * l, v);
    let energy = |s: &State<f64, 3>| 0.5 * m * s.qd.norm_squared() + m * g * s.q.z;
    let lz = |s: &State<f64, 3>| m * (s.q.x * s.qd.y - s.q.y * s.qd.x);
    let (e0, l0) = (energy(&s), lz(&s));
    let (mut worst_e, mut worst_l) = (0.0f64, 0.0f64);
    DormandPrince45::new(1e-10, 1e-12)
        .advance_with(&system, &mut s, 100.0, |s| {
            worst_e = worst_e.max(((energy(s) - e0) / e0).abs());
            worst_l = worst_l.max(((lz(s) - l0) / l0).abs());
        })
        .unwrap();
    assert_eq!(s.t, 100.0);
    assert!(worst_e < 1e-8, "relative energy drift {worst_e}");
    assert!(worst_l < 1e-8, "relative drift of L_z {worst_l}");
}

fn double_pendulum() -> (DoublePendulum<f64>, State<f64, 4>) {
    let (l1, l2) = (1.2, 0.8);
    let system = DoublePendulum::new(1.0, 1.5, l1, l2, 9.81);
    (
        system,
        system.state_from_angles(0.0, [2.0, -1.0], [0.5, 1.5]),
    )
}

/// Largest |φ| over 10⁵ RK4 steps (100 s), and its value after the first 1%.
fn drift(stabilization: Stabilization<f64>) -> (f64, f64) {
    let (system, mut s) = double_pendulum();
    let (mut worst, mut early, mut steps) = (0.0f64, 0.0f64, 0usize);
    Rk4::new(1e-3)
        .with_stabilization(stabilization)
        .advance_with(&system, &mut s, 100.0, |s| {
            let phi = system.constraint_residual(&s.q, &s.qd, s.t).amax();
            worst = worst.max(phi);
            steps += 1;
            if steps == 1000 {
                early = worst;
            }
        })
        .unwrap();
    assert_eq!(steps, 100_000);
    (worst, early)
}

#[test]
fn drift_grows_without_stabilization_and_is_controlled_with_it() {
    let (none, none_early) = drift(Stabilization::None);
    let (projected, _) = drift(Stabilization::projection(1e-12));
    let (baumgarte, _) = drift(Stabilization::baumgarte(10.0));
    println!("max |φ| over 1e5 RK4 steps: none {none:e} (after 1e3: {none_early:e}), projection {projected:e}, Baumgarte {baumgarte:e}");
    assert!(
        none > 10.0 * none_early,
        "drift should grow: {none_early:e} → {none:e}"
    );
    assert!(projected < 1e-9, "projection: {projected:e}");
    assert!(
        baumgarte < none / 10.0 && baumgarte < 1e-6,
        "Baumgarte: {baumgarte:e} vs none {none:e}"
    );
}

#[test]
fn every_integrator_runs_in_f32() {
    let system32 = AppellTimeDependent::<f32>::new(9.81, 0.5);
    let system64 = AppellTimeDependent::<f64>::new(9.81, 0.5);
    let (x, y, xd, yd): (f64, f64, f64, f64) = (0.3, -0.4, 1.2, 0.7);
    let zd = (xd * xd + yd * yd - 2.0 * 0.5 * (x * y)).sqrt();
    let start64 = State::new(0.0, Vector3::new(x, y, 1.0), Vector3::new(xd, yd, zd));
    let start32 = State::new(0.0f32, start64.q.cast(), start64.qd.cast());
    let mut s64 = start64;
    DormandPrince45::new(1e-12, 1e-12)
        .advance(&system64, &mut s64, 1.0)
        .unwrap();
    let mut a = start32;
    Rk4::new(1e-3f32).advance(&system32, &mut a, 1.0).unwrap();
    let mut b = start32;
    DormandPrince45::new(1e-5f32, 1e-6)
        .advance(&system32, &mut b, 1.0)
        .unwrap();
    let mut c = start32;
    SemiImplicitEuler::new(1e-4f32)
        .advance(&system32, &mut c, 1.0)
        .unwrap();
    for (name, s, tol) in [("rk4", a, 1e-4), ("dp45", b, 1e-4), ("euler", c, 1e-2)] {
        let err = (s.q.cast::<f64>() - s64.q).norm();
        assert!(err < tol, "{name} in f32: error {err}");
    }
}

#[test]
fn failures_are_values() {
    let system = BlowUp::new();
    let one = constrained::nalgebra::Vector1::new(1.0);
    let start = State::new(0.0, one, one);
    let mut s = start;
    let error = Rk4::new(0.1).advance(&system, &mut s, 10.0).unwrap_err();
    assert!(
        matches!(error, IntegrationError::NonFiniteState { .. }),
        "{error:?}"
    );
    let mut s = start;
    let error = DormandPrince45::new(1e-8, 1e-8)
        .advance(&system, &mut s, 10.0)
        .unwrap_err();
    assert!(
        matches!(
            error,
            IntegrationError::StepSizeUnderflow { .. }
                | IntegrationError::NonFiniteState { .. }
                | IntegrationError::TooManySteps { .. }
        ),
        "{error:?}"
    );
    println!("blow-up with DormandPrince45: {error}");
    let mut s = start;
    let error = Rk4::new(0.001)
        .with_max_steps(10)
        .advance(&system, &mut s, 1.0)
        .unwrap_err();
    assert_eq!(error, IntegrationError::TooManySteps { t: s.t, steps: 10 });
    let mut s = start;
    assert_eq!(
        Rk4::new(0.1).advance(&system, &mut s, -1.0).unwrap_err(),
        IntegrationError::EndBeforeStart {
            t: 0.0,
            t_end: -1.0
        }
    );
    assert_eq!(
        Rk4::new(-0.1).advance(&system, &mut s, 1.0).unwrap_err(),
        IntegrationError::InvalidParameter
    );
    assert_eq!(
        Rk4::new(f64::NAN)
            .advance(&system, &mut s, 1.0)
            .unwrap_err(),
        IntegrationError::InvalidParameter
    );
    // A non-positive-definite mass is reported with its time.
    let bad = SphericalPendulum::new(-1.0, 9.81, 1.0);
    let mut s = State::new(
        0.5,
        Vector3::new(0.0, 0.6, -0.8),
        Vector3::new(0.3, 0.0, 0.0),
    );
    let error = Rk4::new(0.1).advance(&bad, &mut s, 1.0).unwrap_err();
    assert_eq!(
        error.to_string(),
        "at t = 0.5: the mass matrix is not positive definite at this state"
    );
}

/// Samples every 20 ms over 10 s on the circle: the dense output is as
/// accurate as the steps themselves, and sampling changes neither the steps
/// nor the evaluations, while sampling by calling `advance` to each time
/// restarts the step-size control every time.
#[test]
fn dense_output_samples_without_extra_evaluations() {
    let system = Circle::new(1.0);
    let times: Vec<f64> = (0..=500).map(|i| i as f64 * 0.02).collect();
    for (tol, bound) in [(1e-6, 1e-4), (1e-9, 1e-7)] {
        let method = DormandPrince45::new(tol, tol);
        let mut plain = circle_start();
        let mut step_error: f64 = 0.0;
        let unsampled = method
            .advance_with(&system, &mut plain, 10.0, |s| {
                step_error = step_error.max(circle_error(s))
            })
            .unwrap();
        let mut sampled_state = circle_start();
        let mut samples = Vec::new();
        let sampled = method
            .advance_sampled(&system, &mut sampled_state, 10.0, &times, |s| {
                samples.push(*s)
            })
            .unwrap();
        assert_eq!(sampled, unsampled);
        assert_eq!(sampled_state, plain, "the same steps, to the bit");
        assert_eq!(samples.len(), times.len());
        let mut sample_error: f64 = 0.0;
        for (s, &t) in samples.iter().zip(&times) {
            assert_eq!(s.t, t);
            sample_error = sample_error.max(circle_error(s));
        }
        // Restarting at every sample (the only way before dense output).
        let mut looped = circle_start();
        let mut restarted = 0;
        for &t in &times[1..] {
            restarted += method.advance(&system, &mut looped, t).unwrap().evaluations;
        }
        println!(
            "tol {tol:e}: {} evaluations sampled and unsampled ({} when restarting at each sample); \
             largest error at the steps {step_error:.2e}, at the 501 samples {sample_error:.2e}",
            sampled.evaluations, restarted
        );
        assert!(
            sample_error < bound && sample_error < 3.0 * step_error.max(tol),
            "{sample_error:e}"
        );
        assert!(restarted > sampled.evaluations);
    }
}

/// Bogacki–Shampine samples through the cubic Hermite interpolant, within
/// its tolerance too.
#[test]
fn dense_output_of_bogacki_shampine() {
    let system = Circle::new(1.0);
    let times: Vec<f64> = (0..=100).map(|i| i as f64 * 0.05).collect();
    let mut s = circle_start();
    let mut worst: f64 = 0.0;
    BogackiShampine32::new(1e-8, 1e-8)
        .advance_sampled(&system, &mut s, 5.0, &times, |s| {
            worst = worst.max(circle_error(s))
        })
        .unwrap();
    assert!(worst < 1e-6, "{worst:e}");
}

#[test]
fn dense_output_rejects_times_out_of_order_or_range() {
    let system = Circle::new(1.0);
    let method = DormandPrince45::new(1e-8, 1e-8);
    for times in [
        &[0.5, 0.2][..],
        &[-0.1][..],
        &[0.5, 1.5][..],
        &[f64::NAN][..],
    ] {
        let mut s = circle_start();
        let result = method.advance_sampled(&system, &mut s, 1.0, times, |_| {});
        assert_eq!(result, Err(IntegrationError::InvalidParameter), "{times:?}");
        assert_eq!(s, circle_start(), "no step taken");
    }
    // The start and the end are samples like any other.
    let mut s = circle_start();
    let mut seen = Vec::new();
    method
        .advance_sampled(&system, &mut s, 1.0, &[0.0, 0.0, 1.0], |s| seen.push(s.t))
        .unwrap();
    assert_eq!(seen, [0.0, 0.0, 1.0]);
}
