//! Issue 30: the Jacobians of `q̈` never answer `Ok` where `acceleration`
//! does not, nor with entries that are not the derivative of the `q̈` it
//! returned: at extreme states (overflow, underflow, `f32`) and near the
//! four-bar's branch point, where `acceleration` recomputes the rank
//! decision of its fast solve. The truth is the library's own
//! `acceleration`, by central differences where those converge.

use constrained::models::*;
use constrained::nalgebra::{RealField, SVector};
use constrained::{DynamicsError, Jacobians};

/// The inherent methods return a plain value or a `Result`, as
/// `acceleration` does for the model: one shape for the tests.
trait Answer<V> {
    fn answer(self) -> Result<V, DynamicsError>;
}

impl<V> Answer<V> for Result<V, DynamicsError> {
    fn answer(self) -> Result<V, DynamicsError> {
        self
    }
}

impl<T, const N: usize, const NU: usize> Answer<Jacobians<T, N, NU>> for Jacobians<T, N, NU> {
    fn answer(self) -> Result<Jacobians<T, N, NU>, DynamicsError> {
        Ok(self)
    }
}

impl<T: RealField, const N: usize> Answer<SVector<T, N>> for SVector<T, N> {
    fn answer(self) -> Result<SVector<T, N>, DynamicsError> {
        Ok(self)
    }
}

/// Whether every entry is finite.
fn finite<T: RealField + Copy, const N: usize, const NU: usize>(j: &Jacobians<T, N, NU>) -> bool {
    j.is_finite()
}

/// `acceleration` and `acceleration_jacobian` of `$system` at `($q, $qd)`,
/// as `Result`s.
macro_rules! both {
    ($system:expr, $q:expr, $qd:expr) => {{
        let (q, qd) = ($q, $qd);
        let acc = $system.acceleration(&q, &qd, 0.0).answer();
        let jac = $system.acceleration_jacobian(&q, &qd, 0.0).answer();
        (acc, jac)
    }};
}

/// Central differences of `acceleration` along coordinate or velocity `c`
/// with step `h`, `None` where either side fails.
macro_rules! central {
    ($system:expr, $q:expr, $qd:expr, $c:expr, $n:expr, $h:expr) => {{
        let (mut qp, mut qm, mut qdp, mut qdm) = ($q, $q, $qd, $qd);
        if $c < $n {
            qp[$c] += $h;
            qm[$c] -= $h;
        } else {
            qdp[$c - $n] += $h;
            qdm[$c - $n] -= $h;
        }
        let plus = $system.acceleration(&qp, &qdp, 0.0).answer();
        let minus = $system.acceleration(&qm, &qdm, 0.0).answer();
        match (plus, minus) {
            (Ok(p), Ok(m)) => Some((p - m) / (2.0 * $h)),
            _ => None,
        }
    }};
}

/// Where `acceleration` is `Err(NonFinite)` the Jacobian is an `Err` too,
/// never an `Ok` (the crane once answered `Ok` at 1e154: its row scaled to
/// finite values hid the overflow of `A M⁻¹ Aᵀ` that sends `acceleration`
/// to the runtime's check).
#[test]
fn the_jacobian_is_err_wherever_acceleration_is_err_at_overflowing_states() {
    let crane = Crane::<f64>::new(5.0, 1.0, 2.0, 9.81, 0.1, 4.0, 3.0, 20.0, 1.0);
    let big = SVector::<f64, 3>::from_element(1e154);
    let (acc, jac) = both!(crane, big, big);
    assert_eq!(
        acc.err(),
        Some(DynamicsError::NonFinite),
        "crane acceleration at 1e154"
    );
    assert!(jac.is_err(), "crane Jacobian at 1e154: {jac:?}");

    let sphere = SphericalPendulum::<f32>::new(1.5, 9.81, 1.2);
    let bead = BeadOnRotatingHoop::<f32>::new(0.5, 9.81, 1.0, 2.0);
    let big = SVector::<f32, 3>::from_element(1e19);
    for (name, acc, ok) in [
        {
            let (q, qd) = (big, big);
            let acc = sphere.acceleration(&q, &qd, 0.0).answer();
            let jac = sphere.acceleration_jacobian(&q, &qd, 0.0).answer();
            ("spherical pendulum", acc, jac.map(|j| finite(&j)))
        },
        {
            let (q, qd) = (big, big);
            let acc = bead.acceleration(&q, &qd, 0.0).answer();
            let jac = bead.acceleration_jacobian(&q, &qd, 0.0).answer();
            ("bead on hoop", acc, jac.map(|j| finite(&j)))
        },
    ] {
        if acc.is_err() {
            assert!(
                ok.is_err(),
                "{name} (f32, 1e19): acceleration {acc:?}, Jacobian Ok"
            );
        } else {
            assert_eq!(ok, Ok(true), "{name} (f32, 1e19): an Ok Jacobian is finite");
        }
    }
}

/// Near the parallelogram four-bar's branch point `acceleration` finds the
/// fast solve's dropped row violated and recomputes with every row kept:
/// the Jacobian must be the derivative of that `q̈`, equal to central
/// differences of `acceleration` wherever they converge (two steps 10×
/// apart agreeing to 1e-7), or an `Err`. It once gave ∂p̈₁/∂p₁ = −2.29
/// at θ = 1e-4 where the differences converge to 5.6058e4.
#[test]
fn the_four_bar_jacobian_near_its_branch_point_is_the_derivative_of_acceleration() {
    let four_bar = ParallelogramFourBar::<f64>::new(1.2, 0.15, 1.0, 2.0, 9.81);
    let mut compared = 0;
    for theta in [
        1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 1e-6, 1e-7, 1e-8,
    ] {
        let state = four_bar_state(&four_bar, theta, 1.3);
        let (q, qd) = (state.q, state.qd);
        let jac = match four_bar.acceleration_jacobian(&q, &qd, 0.0) {
            Ok(j) => j,
            Err(e) => {
                println!("θ = {theta:e}: {e:?}");
                continue;
            }
        };
        assert!(jac.is_finite(), "θ = {theta:e}: an Ok Jacobian is finite");
        for c in 0..18 {
            let column = if c < 9 {
                jac.dq.column(c)
            } else {
                jac.dqd.column(c - 9)
            };
            // Steps relative to θ, so that the differences stay on one side
            // of the branch point.
            let h = theta * 1e-3;
            let (Some(d1), Some(d2)) = (
                central!(four_bar, q, qd, c, 9, h),
                central!(four_bar, q, qd, c, 9, h / 10.0),
            ) else {
                continue;
            };
            let scale = d2.amax().max(1e-300);
            if (d1 - d2).amax() > 1e-7 * scale {
                continue; // the differences have not converged
            }
            compared += 1;
            let err = (column - d2).amax() / scale;
            assert!(
                err < 1e-6,
                "θ = {theta:e}, column {c}: Jacobian {:?} against central differences {:?} ({err:e})",
                column.as_slice(),
                d2.as_slice()
            );
        }
    }
    println!("{compared} columns equal to converged central differences");
    assert!(compared > 100, "only {compared} columns compared");
}

/// Central differences of `acceleration` along every coordinate and
/// velocity with steps relative to each component, where two steps 10×
/// apart agree to 1e-7 of the column: `(column, difference)` pairs.
macro_rules! converged_columns {
    ($system:expr, $q:expr, $qd:expr, $n:expr) => {{
        let mut out = Vec::new();
        for c in 0..2 * $n {
            let x: f64 = if c < $n { $q[c] } else { $qd[c - $n] };
            let h = x.abs().max(1e-300) * 1e-5;
            if let (Some(d1), Some(d2)) = (
                central!($system, $q, $qd, c, $n, h),
                central!($system, $q, $qd, c, $n, h / 10.0),
            ) {
                let scale = d2.amax();
                if scale.is_finite() && (d1 - d2).amax() <= 1e-7 * scale {
                    out.push((c, d2));
                }
            }
        }
        out
    }};
}

/// At extreme states an `Ok` Jacobian is finite and the derivative of
/// `acceleration`: `AppellTimeDependent` at q̇ = 1e154 (`A M⁻¹ Aᵀ`
/// overflows), `RigidBodyQuaternion` and `Appell` at 1e-154.
#[test]
fn an_ok_jacobian_at_extreme_states_is_the_derivative_of_acceleration() {
    macro_rules! probe {
        ($system:expr, $n:literal, $q:expr, $qd:expr) => {{
            let (q, qd): (SVector<f64, $n>, SVector<f64, $n>) = ($q, $qd);
            let (acc, jac) = both!($system, q, qd);
            println!("{}: acceleration {acc:?}", stringify!($system));
            match jac {
                Err(e) => println!("  Jacobian {e:?}"),
                Ok(j) => {
                    let columns = converged_columns!($system, q, qd, $n);
                    let mut worst = 0.0f64;
                    for (c, d) in &columns {
                        let column = if *c < $n {
                            j.dq.column(*c).into_owned()
                        } else {
                            j.dqd.column(*c - $n).into_owned()
                        };
                        let err = (column - d).amax() / d.amax().max(f64::MIN_POSITIVE);
                        if err.is_nan() || err > 1e-6 {
                            println!(
                                "  column {c}: {:?} against {:?}",
                                column.as_slice(),
                                d.as_slice()
                            );
                        }
                        worst = worst.max(if err.is_nan() { f64::INFINITY } else { err });
                    }
                    println!(
                        "  Jacobian Ok, finite {}, {} columns compared, worst {worst:e}",
                        j.is_finite(),
                        columns.len()
                    );
                    assert!(
                        j.is_finite(),
                        "{}: an Ok Jacobian is finite",
                        stringify!($system)
                    );
                    assert!(worst <= 1e-6, "{}: {worst:e}", stringify!($system));
                }
            }
        }};
    }
    let appell_t = AppellTimeDependent::<f64>::new(9.81, 0.7);
    probe!(
        appell_t,
        3,
        SVector::from([1.0, 1.0, 1.0]),
        SVector::from_element(1e154)
    );
    let appell = Appell::<f64>::new(9.81, 0.7);
    probe!(
        appell,
        3,
        SVector::from_element(1e-154),
        SVector::from_element(1e-154)
    );
    let body = RigidBodyQuaternion::<f64>::new(1.0, 2.0, 3.0);
    probe!(
        body,
        4,
        SVector::from_element(1e-154),
        SVector::from_element(1e-154)
    );
}

/// `f32` at 1e-40 (subnormal): the true derivative (≈4e40) overflows
/// `f32`, so the Jacobian must be an `Err`, not the all-zero `dq` it once
/// was; wherever an `f32` Jacobian is `Ok`, it is finite and agrees with
/// the `f64` one at the same state.
#[test]
fn f32_jacobians_at_subnormal_states_are_err_or_the_f64_derivative() {
    macro_rules! probe {
        ($model:ident, $n:literal, $fallible:literal, [$($p:expr),*]) => {{
            let (s32, s64) = ($model::<f32>::new($($p as f32),*), $model::<f64>::new($($p),*));
            let x = 1e-40f32;
            let (q32, q64) = (SVector::<f32, $n>::from_element(x), SVector::<f64, $n>::from_element(f64::from(x)));
            let j32 = s32.acceleration_jacobian(&q32, &q32, 0.0).answer();
            let j64 = s64.acceleration_jacobian(&q64, &q64, 0.0).answer();
            println!(
                "{}: f32 {:?}, f64 {:?}",
                stringify!($model),
                j32.as_ref().map(|j| j.dq.amax().max(j.dqd.amax())),
                j64.as_ref().map(|j| j.dq.amax().max(j.dqd.amax()))
            );
            // A plain-valued Jacobian (constant `M`) says "no derivative" by
            // non-finite entries, as it does for one that overflows.
            let plain = !$fallible;
            let overflows = j64.as_ref().map_or(true, |j| {
                !j.is_finite() || j.dq.amax().max(j.dqd.amax()) > f64::from(f32::MAX)
            });
            if let (true, Ok(j)) = (plain && overflows, &j32) {
                assert!(!j.is_finite(), "{}: f32 finite where the derivative overflows", stringify!($model));
            } else if let Ok(j) = j32 {
                assert!(j.is_finite(), "{}: an Ok f32 Jacobian is finite", stringify!($model));
                let j64 = j64.expect("f64 Jacobian where the f32 one is Ok");
                for (a, b) in [(j.dq, j64.dq), (j.dqd, j64.dqd)] {
                    let a = a.map(f64::from);
                    let err = (a - b).amax() / b.amax().max(f64::MIN_POSITIVE);
                    assert!(err < 1e-3, "{}: f32 {a} against f64 {b}", stringify!($model));
                }
            }
        }};
    }
    probe!(SphericalPendulum, 3, true, [1.5, 9.81, 1.2]);
    probe!(BeadOnRotatingHoop, 3, true, [0.5, 9.81, 1.0, 2.0]);
    probe!(
        Crane,
        3,
        true,
        [5.0, 1.0, 2.0, 9.81, 0.1, 4.0, 3.0, 20.0, 1.0]
    );
    probe!(DoublePendulum, 4, true, [1.0, 2.0, 1.0, 0.8, 9.81]);
    probe!(AppellTimeDependent, 3, false, [9.81, 0.7]);
}

/// The four-bar near its branch point in `f32` (once wrong for θ ≤ 1e-3):
/// an `Ok` Jacobian agrees with the `f64` one, which the test above holds
/// to central differences, to 2e-2 (`f32`'s precision times the
/// conditioning of `S`: 5e-3 at θ = 3e-3, where the fast solve still keeps
/// every row; the recomputed solve is within 1e-4 below), or is an `Err`
/// (θ ≤ 1e-5, where `A`'s smallest singular value is at `f32`'s rounding).
#[test]
fn the_f32_four_bar_jacobian_near_its_branch_point_is_err_or_the_f64_one() {
    let (f32_bar, f64_bar) = (
        ParallelogramFourBar::<f32>::new(1.2, 0.15, 1.0, 2.0, 9.81),
        ParallelogramFourBar::<f64>::new(1.2, 0.15, 1.0, 2.0, 9.81),
    );
    for theta in [1e-1f32, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5, 1e-6] {
        let s32 = four_bar_state(&f32_bar, theta, 1.3);
        let s64 = four_bar_state(&f64_bar, f64::from(theta), 1.3);
        let j32 = f32_bar.acceleration_jacobian(&s32.q, &s32.qd, 0.0);
        let j64 = match f64_bar.acceleration_jacobian(&s64.q, &s64.qd, 0.0) {
            Ok(j) => j,
            // Where f64 finds no derivative it can resolve, f32 cannot.
            Err(e) => {
                assert_eq!(e, DynamicsError::NotDifferentiable, "θ = {theta:e}");
                assert!(j32.is_err(), "θ = {theta:e}: f32 Ok where f64 is {e:?}");
                continue;
            }
        };
        let Ok(j) = j32 else {
            println!("θ = {theta:e}: f32 {j32:?}");
            continue;
        };
        assert!(j.is_finite());
        let mut worst = 0.0f64;
        for (a, b) in [(j.dq, j64.dq), (j.dqd, j64.dqd)] {
            let a = a.map(f64::from);
            worst = worst.max((a - b).amax() / b.amax());
        }
        let bound = 2e-2;
        println!("θ = {theta:e}: f32 against f64 {worst:.1e} (bound {bound:.1e})");
        assert!(
            worst < bound,
            "θ = {theta:e}: f32 Jacobian off by {worst:e}"
        );
    }
}

/// Appell's particle at rest (`q̇ = 0`, where `A = [ẋ, ẏ, −ż]` vanishes):
/// `q̈` is homogeneous of degree one in `q̇` and has no derivative there.
/// `try_acceleration_jacobian`, `try_linearize` and `linearize_reduced`
/// say so, `Err(NotDifferentiable)`, in `f32` and `f64`, time-dependent
/// constraint or not; the plain-valued forms (pinned: `M` is a constant)
/// return every entry NaN, never a mixture that passes for a number. They
/// once returned 18 non-finite entries as a plain value with no way to
/// ask why. Moving, the same methods answer, finite.
#[test]
fn appell_at_rest_has_no_derivative_and_says_so() {
    let mut cases = 0;
    macro_rules! at_rest {
        ($t:ty) => {{
            let appell = Appell::<$t>::new(9.81, 0.7);
            let timed = AppellTimeDependent::<$t>::new(9.81, 0.7);
            let rest = SVector::<$t, 3>::zeros();
            for q in [[0.3, -0.4, 1.0], [0.0, 0.0, 0.0], [2.0, 1.0, -3.0]] {
                let q = SVector::<$t, 3>::from(q);
                for t in [0.0, 0.25, 1.5] {
                    let no = Err(DynamicsError::NotDifferentiable);
                    assert_eq!(appell.try_acceleration_jacobian(&q, &rest, t), no);
                    assert_eq!(timed.try_acceleration_jacobian(&q, &rest, t), no);
                    assert_eq!(appell.try_linearize(&q, &rest, t).err(), no.err());
                    assert_eq!(timed.try_linearize(&q, &rest, t).err(), no.err());
                    assert_eq!(appell.linearize_reduced(&q, &rest, t).err(), no.err());
                    for j in [
                        appell.acceleration_jacobian(&q, &rest, t),
                        timed.acceleration_jacobian(&q, &rest, t),
                    ] {
                        let entries = j.dq.iter().chain(j.dqd.iter());
                        assert!(entries.clone().all(|x| x.is_nan()), "{j:?}");
                    }
                    let (a, _) = appell.linearize(&q, &rest, t);
                    assert!(a.rows(3, 3).iter().all(|x| x.is_nan()), "{a}");
                    cases += 2;
                }
                let moving = SVector::<$t, 3>::from([0.3, 0.2, 0.1]);
                for system_jacobian in [
                    appell.try_acceleration_jacobian(&q, &moving, 0.25),
                    timed.try_acceleration_jacobian(&q, &moving, 0.25),
                ] {
                    let j = system_jacobian.expect("moving: differentiable");
                    assert!(j.is_finite());
                }
            }
        }};
    }
    at_rest!(f64);
    at_rest!(f32);
    assert_eq!(cases, 36);
}

/// The parallelogram four-bar 1e-8 rad from its branch point: the
/// Jacobian of every row (`∂p̈₁/∂p₁ = 5.6e8`) is what central differences
/// of `acceleration` give for steps above 1e-12, but below 1e-13 they give
/// 2.66, because `acceleration` keeps the fast solve's dropped-row `q̈`
/// wherever the dropped row holds to its tolerance: it jumps, by up to
/// `1000 ε κ = 9e-5` of `q̈` (`κ = 4e8`, the rank decision's conditioning),
/// and has no derivative `f64` resolves. The Jacobian once answered
/// `Ok(5.6e8)`; now it and `linearize` are `Err(NotDifferentiable)` from
/// 3e-5 rad in, where `1000 ε κ` passes `√ε`, and `Ok` at 1e-4.
#[test]
fn the_four_bar_jacobian_is_err_where_acceleration_jumps_at_its_rank_tolerance() {
    let four_bar = ParallelogramFourBar::<f64>::new(1.2, 0.15, 1.0, 2.0, 9.81);
    // The two scales of the derivative at 1e-8, ∂p̈₁/∂p₁ (row 2, column 2).
    let state = four_bar_state(&four_bar, 1e-8, 1.3);
    let (q, qd) = (state.q, state.qd);
    // Opaque to the compiler, which would otherwise reject the macro's
    // unused branch `c - 9` as an overflow.
    let c = std::hint::black_box(2usize);
    let fine = central!(four_bar, q, qd, c, 9, 1e-13).expect("finite")[2];
    let coarse = central!(four_bar, q, qd, c, 9, 1e-11).expect("finite")[2];
    println!("θ = 1e-8: ∂p̈₁/∂p₁ by steps of 1e-13: {fine:e}, of 1e-11: {coarse:e}");
    assert!(
        fine.abs() < 10.0 && (coarse - 5.6057e8).abs() < 1e5,
        "{fine}, {coarse}"
    );
    for theta in [1e-8, -1e-8, 1e-7, 1e-6, 1e-5, 3e-5] {
        for omega in [0.0, 1.3, -2.0] {
            let s = four_bar_state(&four_bar, theta, omega);
            assert_eq!(
                four_bar.acceleration_jacobian(&s.q, &s.qd, 0.0).err(),
                Some(DynamicsError::NotDifferentiable),
                "θ = {theta:e}, ω = {omega}"
            );
            assert_eq!(
                four_bar.linearize(&s.q, &s.qd, 0.0).err(),
                Some(DynamicsError::NotDifferentiable),
                "θ = {theta:e}, ω = {omega}"
            );
        }
    }
    let s = four_bar_state(&four_bar, 1e-4, 1.3);
    let j = four_bar
        .acceleration_jacobian(&s.q, &s.qd, 0.0)
        .expect("θ = 1e-4: differentiable to √ε");
    assert!((j.dq[(2, 2)] - 5.6058e4).abs() < 1.0, "{}", j.dq[(2, 2)]);
}
