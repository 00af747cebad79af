//! The runtime fault matrix (issue 13): every reference model × every
//! equation of motion × hostile states and parameters × f32 and f64, and
//! every integrator × settings that cannot work. The contract it checks:
//!
//! - no panic, no hang;
//! - every `Ok` is finite (non-finite values are `Err`, whatever the input);
//! - every `Ok` from finite input is right: `A q̈ = b` holds to a relative
//!   residual of `1e-8` (f64) or `1e-2` (f32), or, where it has no solution,
//!   `q̈` is its least-squares solution (the normal equations hold); the
//!   exception is a redundant model off its constraint surface, whose
//!   dependent rows are dropped unchecked by design (`constrained::rank`);
//! - the Gibbs–Appell acceleration, where it answers, holds every row of
//!   `A q̈ = b` (redundant models off their surface included: issue 30), and
//!   agrees with the generalized-inverse one on models without redundancy.
//!
//! It prints its tally; every failure is listed with its model, state and
//! method.

use constrained::__private::Generated;
use constrained::models::*;
use constrained::nalgebra::{RealField, SMatrix, SVector};
use constrained::rank::relative_residual_at;
use constrained::stabilize::project;
use constrained::{
    BogackiShampine32, ConstrainedSystem, DormandPrince45, IntegrationError, Rk4,
    SemiImplicitEuler, Stabilization, State, ThreeEighthsRule,
};
use std::fmt::Debug;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What the matrix found.
#[derive(Default, Debug)]
struct Tally {
    evaluations: usize,
    ok: usize,
    err: usize,
    failures: Vec<String>,
}

impl Tally {
    fn fail(&mut self, what: String) {
        self.failures.push(what);
    }
}

/// One method's answer, its error as text.
type Evaluation<T, const N: usize> = Result<SVector<T, N>, String>;

/// A scalar under test, with the tolerances that fit it.
trait Scalar: RealField + Copy + Debug + 'static {
    const NAME: &'static str;
    /// Largest relative residual of `A q̈ = b` accepted.
    const RESIDUAL: f64;
    /// Largest relative difference between GA and GI accepted.
    const AGREEMENT: f64;
    /// Scales that reach overflow and underflow of squares in `T`.
    const HUGE: f64;
    const TINY: f64;
    const SUBNORMAL: f64;
    /// The value in f64 (exact for both scalars).
    fn f64(self) -> f64;
    fn of(x: f64) -> Self {
        constrained::nalgebra::convert(x)
    }
}

impl Scalar for f64 {
    const NAME: &'static str = "f64";
    const RESIDUAL: f64 = 1e-8;
    const AGREEMENT: f64 = 1e-6;
    const HUGE: f64 = 1e154;
    const TINY: f64 = 1e-154;
    const SUBNORMAL: f64 = 1e-310;
    fn f64(self) -> f64 {
        self
    }
}

impl Scalar for f32 {
    const NAME: &'static str = "f32";
    const RESIDUAL: f64 = 1e-2;
    const AGREEMENT: f64 = 1e-1;
    const HUGE: f64 = 1e19;
    const TINY: f64 = 1e-19;
    const SUBNORMAL: f64 = 1e-40;
    fn f64(self) -> f64 {
        f64::from(self)
    }
}

/// The hostile variants of a nominal state: name, state, and whether the
/// state lies on the constraint surface.
fn states<T: Scalar, const N: usize>(
    nominal: State<T, N>,
) -> Vec<(&'static str, State<T, N>, bool)> {
    let scaled = |s: f64| {
        let mut x = nominal;
        x.q *= T::of(s);
        x.qd *= T::of(s);
        x
    };
    let mut off = nominal;
    for i in 0..N {
        off.q[i] += T::of(1e-3 * (i as f64 + 1.0));
        off.qd[i] -= T::of(2e-3 * (i as f64 + 1.0));
    }
    let mut fast = nominal;
    fast.qd *= T::of(T::HUGE);
    let mut nan = nominal;
    nan.q[0] = T::of(f64::NAN);
    let mut inf = nominal;
    inf.qd[N - 1] = T::of(f64::INFINITY);
    let mut late = nominal;
    late.t = T::of(if T::NAME == "f64" { 1e300 } else { 1e38 });
    vec![
        ("nominal", nominal, true),
        ("off the surface", off, false),
        ("huge", scaled(T::HUGE), false),
        ("huge velocities", fast, false),
        ("tiny", scaled(T::TINY), false),
        ("subnormal", scaled(T::SUBNORMAL), false),
        (
            "zero",
            State::new(nominal.t, SVector::zeros(), SVector::zeros()),
            false,
        ),
        ("NaN position", nan, false),
        ("infinite velocity", inf, false),
        ("late", late, false),
    ]
}

fn finite<T: Scalar, const R: usize, const C: usize>(m: &SMatrix<T, R, C>) -> bool {
    m.iter().all(|x| x.is_finite())
}

/// `‖Aᵀ D² (A q̈ − b)‖ ≤ tol ‖D A‖ ‖D (A q̈ − b)‖` with `D` scaling each row
/// to unit largest entry: `q̈` minimizes the scaled residual of `A q̈ = b`.
fn least_squares<T: Scalar, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    qdd: &SVector<T, N>,
    tol: f64,
) -> bool {
    let mut da = *a;
    let mut r = a * qdd - b;
    for i in 0..K {
        let largest = da.row(i).amax();
        if largest > T::zero() {
            da.row_mut(i).scale_mut(T::one() / largest);
            r[i] /= largest;
        }
    }
    let gradient = da.transpose() * r;
    gradient.norm() <= T::of(tol) * da.norm() * r.norm()
}

/// Judges one model at one state with every equation of motion.
fn judge<T, S, const N: usize, const K: usize>(
    tally: &mut Tally,
    label: &str,
    system: &S,
    state: &State<T, N>,
    on_surface: bool,
    finite_input: bool,
) where
    T: Scalar,
    S: ConstrainedSystem<T, N, K> + Generated<T, N, K>,
{
    let redundant = S::GENERIC_RANK < K;
    let db = SVector::<T, K>::from_element(T::of(1e-3));
    let (a, b) = ConstrainedSystem::constraint_matrices(system, state);
    let judgeable = finite_input && finite(&a) && finite(&b);
    let methods: [(&str, &dyn Fn() -> Evaluation<T, N>); 4] = [
        ("acceleration", &|| {
            ConstrainedSystem::acceleration(system, state).map_err(|e| e.to_string())
        }),
        ("acceleration_corrected", &|| {
            ConstrainedSystem::acceleration_corrected(system, state, &db).map_err(|e| e.to_string())
        }),
        ("acceleration_moore_penrose", &|| {
            ConstrainedSystem::acceleration_moore_penrose(system, state).map_err(|e| e.to_string())
        }),
        ("acceleration_gibbs_appell", &|| {
            ConstrainedSystem::acceleration_gibbs_appell(system, state).map_err(|e| e.to_string())
        }),
    ];
    let mut gi = None;
    for (name, method) in methods {
        tally.evaluations += 1;
        let what = format!(
            "{label}, {name} (q = {:?}, q̇ = {:?}, t = {:?})",
            state.q.as_slice(),
            state.qd.as_slice(),
            state.t
        );
        let result = match catch_unwind(AssertUnwindSafe(method)) {
            Ok(result) => result,
            Err(_) => {
                tally.fail(format!("{what}: PANIC"));
                continue;
            }
        };
        let Ok(qdd) = result else {
            tally.err += 1;
            continue;
        };
        tally.ok += 1;
        if !finite(&qdd) {
            tally.fail(format!("{what}: non-finite Ok {qdd:?}"));
            continue;
        }
        if !finite_input {
            continue;
        }
        if !judgeable {
            tally.fail(format!("{what}: finite Ok although A or b is not finite"));
            continue;
        }
        // Rule 1 of constrained::rank: a redundant model's dependent rows are
        // dropped unchecked off its surface, and b + db is off it too. Not
        // so Gibbs–Appell's: every Ok of it holds every row (issue 30).
        if redundant
            && (!on_surface || name == "acceleration_corrected")
            && name != "acceleration_gibbs_appell"
        {
            continue;
        }
        let target = if name == "acceleration_corrected" {
            b + db
        } else {
            b
        };
        // Backward error, as the library states it: against the size of
        // the terms the solve summed, max(‖q̈‖, ‖a‖) with a = M⁻¹F.
        let size = qdd.amax().max(unconstrained_size(system, state));
        let residual: f64 = Scalar::f64(relative_residual_at(&a, &target, &qdd, size));
        // The Gibbs–Appell form enforces r independent rows of A q̈ = b and
        // answers only where the others hold too (no least squares).
        let consistent = if name == "acceleration_gibbs_appell" {
            residual <= T::RESIDUAL.max(Scalar::f64(T::default_epsilon().sqrt()))
        } else {
            residual <= T::RESIDUAL || least_squares(&a, &target, &qdd, T::RESIDUAL)
        };
        if !consistent {
            tally.fail(format!(
                "{what}: relative residual {residual:e}, not least squares either"
            ));
        }
        // Gauss's principle: the constraint force M q̈ − F is ideal, a
        // combination Aᵀλ of the constraint normals.
        let gauss_applies = !redundant || on_surface;
        if consistent
            && gauss_applies
            && name != "acceleration_corrected"
            && !ideal(system, state, &a, &qdd, T::RESIDUAL.sqrt())
        {
            tally.fail(format!(
                "{what}: M q̈ − F is not in the range of Aᵀ (not Gauss's minimiser)"
            ));
        }
        match name {
            "acceleration" => gi = Some(qdd),
            "acceleration_gibbs_appell" if !redundant => {
                if let Some(gi) = gi {
                    // Both are backward stable: they agree to the size of
                    // the terms they summed, not necessarily to ‖q̈‖.
                    let scale = Scalar::f64(gi.amax().max(qdd.amax()).max(size));
                    let difference = Scalar::f64((gi - qdd).amax()) / scale.max(f64::MIN_POSITIVE);
                    if difference > T::AGREEMENT {
                        tally.fail(format!(
                            "{what}: differs from the GI acceleration by {difference:e}"
                        ));
                    }
                }
            }
            _ => {}
        }
    }
}

/// `‖(I − P)(M q̈ − F)‖ ≤ tol (‖M q̈‖ + ‖F‖)` with `P` the orthogonal
/// projector onto the range of `Aᵀ`, in f64 by nalgebra's SVD of `Aᵀ`
/// (independent of the library's solvers).
fn ideal<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &State<T, N>,
    a: &SMatrix<T, K, N>,
    qdd: &SVector<T, N>,
    tol: f64,
) -> bool
where
    T: Scalar,
    S: ConstrainedSystem<T, N, K>,
{
    let to64 = |x: T| x.f64();
    let m = ConstrainedSystem::mass_matrix(system, state).map(to64);
    let f = ConstrainedSystem::forces(system, state).map(to64);
    // Scaled by M's largest entry, so that M q̈ cannot overflow.
    let unit = m.amax();
    let (m, f) = if unit > 0.0 {
        (m / unit, f / unit)
    } else {
        (m, f)
    };
    let (a, qdd) = (a.map(to64), qdd.map(to64));
    let force = m * qdd - f;
    // Backward-error scale: a solve is exact for M perturbed by ε‖M‖.
    let scale = m.norm() * qdd.norm() + f.norm();
    if !(scale.is_finite()) || K == 0 {
        return K != 0 || force.norm() <= tol * scale.max(f64::MIN_POSITIVE);
    }
    // Orthonormal basis of the rows of A by modified Gram–Schmidt (twice,
    // for orthogonality), dropping rows dependent to 1e-10.
    // Rows scaled to unit largest entry first (subnormal and huge rows).
    let mut basis: Vec<SVector<f64, N>> = Vec::new();
    for i in 0..K {
        let largest = a.row(i).amax();
        if largest.is_nan() || largest <= 0.0 {
            continue;
        }
        let mut v = a.row(i).transpose() / largest;
        for _ in 0..2 {
            for e in &basis {
                v -= e * e.dot(&v);
            }
        }
        let norm = v.norm();
        if norm > 1e-10 {
            basis.push(v / norm);
        }
    }
    let mut projected = SVector::<f64, N>::zeros();
    for e in &basis {
        projected += e * e.dot(&force);
    }
    (force - projected).norm() <= tol * scale
}

/// `‖M⁻¹F‖∞` (0 where M has no Cholesky factor, e.g. a quaternion model's
/// semi-definite M): the size of the unconstrained acceleration.
fn unconstrained_size<T, S, const N: usize, const K: usize>(system: &S, state: &State<T, N>) -> T
where
    T: Scalar,
    S: ConstrainedSystem<T, N, K>,
{
    let m = ConstrainedSystem::mass_matrix(system, state);
    let f = ConstrainedSystem::forces(system, state);
    match m.cholesky() {
        Some(c) => {
            let a = c.solve(&f);
            if a.iter().all(|x| x.is_finite()) {
                a.amax()
            } else {
                T::zero()
            }
        }
        None => T::zero(),
    }
}

/// A consistent state near a pseudo-random one by projection (`true`),
/// else the raw one (`false`).
fn nominal<T, S, const N: usize, const K: usize>(system: &S, seed: u64) -> (State<T, N>, bool)
where
    T: Scalar,
    S: ConstrainedSystem<T, N, K>,
{
    let mut x = seed;
    let mut next = || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        T::of(((x >> 11) as f64 / (1u64 << 53) as f64) - 0.5)
    };
    let q = SVector::<T, N>::from_fn(|_, _| next() + T::of(0.3));
    let qd = SVector::<T, N>::from_fn(|_, _| next());
    let mut state = State::new(T::of(0.25), q, qd);
    let tolerance = T::of(if T::NAME == "f64" { 1e-12 } else { 1e-5 });
    let raw = state;
    if project(system, &mut state, tolerance, 50).is_err() {
        return (raw, false);
    }
    (state, true)
}

/// Every hostile state and parameter set of one model in `T`.
fn model<T, S, const N: usize, const K: usize, const P: usize>(
    tally: &mut Tally,
    name: &str,
    build: impl Fn([T; P]) -> S,
    params: [f64; P],
) where
    T: Scalar,
    S: ConstrainedSystem<T, N, K> + Generated<T, N, K>,
{
    let nominal_params = params.map(T::of);
    let system = build(nominal_params);
    let (start, consistent) = nominal(&system, 7);
    for (state_name, state, on_surface) in states(start) {
        // A redundant model's dependent rows vanish with the residual of
        // the others; f32's projection (to 1e-5) leaves them visible.
        let on_surface = on_surface && consistent && (S::GENERIC_RANK == K || T::NAME == "f64");
        let finite_input =
            state.q.iter().chain(state.qd.iter()).all(|x| x.is_finite()) && state.t.is_finite();
        let label = format!("{name} ({}), {state_name} state", T::NAME);
        judge(tally, &label, &system, &state, on_surface, finite_input);
    }
    // Hostile parameters at the nominal state.
    for (what, value) in [
        ("NaN", f64::NAN),
        ("infinite", f64::INFINITY),
        ("huge", T::HUGE),
        ("zero", 0.0),
    ] {
        for i in 0..P {
            let mut p = nominal_params;
            p[i] = T::of(value);
            let system = build(p);
            let label = format!("{name} ({}), parameter {i} {what}", T::NAME);
            let finite_input = value.is_finite();
            judge(tally, &label, &system, &start, false, finite_input);
        }
    }
}

macro_rules! every_model {
    ($tally:expr, $t:ty) => {{
        let t = &mut *$tally;
        model::<$t, _, 3, 1, 2>(t, "Appell", |p| Appell::new(p[0], p[1]), [9.81, 0.7]);
        model::<$t, _, 3, 1, 2>(
            t,
            "AppellTimeDependent",
            |p| AppellTimeDependent::new(p[0], p[1]),
            [9.81, 0.7],
        );
        model::<$t, _, 3, 1, 3>(
            t,
            "SphericalPendulum",
            |p| SphericalPendulum::new(p[0], p[1], p[2]),
            [1.5, 9.81, 1.2],
        );
        model::<$t, _, 4, 2, 5>(
            t,
            "DoublePendulum",
            |p| DoublePendulum::new(p[0], p[1], p[2], p[3], p[4]),
            [1.0, 2.0, 1.0, 0.8, 9.81],
        );
        model::<$t, _, 4, 3, 5>(
            t,
            "RedundantDoublePendulum",
            |p| RedundantDoublePendulum::new(p[0], p[1], p[2], p[3], p[4]),
            [1.0, 2.0, 1.0, 0.8, 9.81],
        );
        model::<$t, _, 3, 2, 4>(
            t,
            "BeadOnRotatingHoop",
            |p| BeadOnRotatingHoop::new(p[0], p[1], p[2], p[3]),
            [0.5, 9.81, 1.0, 2.0],
        );
        model::<$t, _, 3, 1, 4>(
            t,
            "ChaplyginSleigh",
            |p| ChaplyginSleigh::new(p[0], p[1], p[2], p[3]),
            [2.0, 0.4, 0.3, 0.5],
        );
        model::<$t, _, 4, 4, 6>(
            t,
            "SliderCrank",
            |p| SliderCrank::new(p[0], p[1], p[2], p[3], p[4], p[5]),
            [1.0, 2.0, 0.5, 1.5, 3.0, 9.81],
        );
        model::<$t, _, 2, 1, 6>(
            t,
            "TwoLinkArmOnLine",
            |p| TwoLinkArmOnLine::new(p[0], p[1], p[2], p[3], p[4], p[5]),
            [1.0, 0.5, 1.0, 1.0, 9.81, 0.5],
        );
        model::<$t, _, 3, 1, 9>(
            t,
            "Crane",
            |p| Crane::new(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8]),
            [5.0, 1.0, 2.0, 9.81, 0.1, 4.0, 3.0, 20.0, 1.0],
        );
        model::<$t, _, 2, 0, 5>(
            t,
            "CartPole",
            |p| CartPole::new(p[0], p[1], p[2], p[3], p[4]),
            [1.0, 0.3, 0.8, 9.81, 0.0],
        );
        model::<$t, _, 2, 0, 5>(
            t,
            "DoublePendulumAngles",
            |p| DoublePendulumAngles::new(p[0], p[1], p[2], p[3], p[4]),
            [1.0, 2.0, 1.0, 0.8, 9.81],
        );
        model::<$t, _, 4, 1, 3>(
            t,
            "RigidBodyQuaternion",
            |p| RigidBodyQuaternion::new(p[0], p[1], p[2]),
            [1.0, 2.0, 3.0],
        );
        model::<$t, _, 4, 1, 5>(
            t,
            "HeavyTop",
            |p| HeavyTop::new(p[0], p[1], p[2], p[3], p[4]),
            [1.0, 2.0, 1.0, 9.81, 0.5],
        );
        model::<$t, _, 5, 2, 5>(
            t,
            "RollingDisk",
            |p| RollingDisk::new(p[0], p[1], p[2], p[3], p[4]),
            [1.0, 0.5, 0.06, 0.12, 9.81],
        );
        model::<$t, _, 9, 8, 5>(
            t,
            "ParallelogramFourBar",
            |p| ParallelogramFourBar::new(p[0], p[1], p[2], p[3], p[4]),
            [1.2, 0.15, 1.0, 2.0, 9.81],
        );
    }};
}

#[test]
fn every_model_every_equation_every_hostile_state() {
    let mut tally = Tally::default();
    every_model!(&mut tally, f64);
    every_model!(&mut tally, f32);
    report(&tally, "fault matrix");
}

/// The quadruped (`examples/support/quadruped.rs`), whose `acceleration`
/// is the saddle-point solve (`[M Aᵀ; A 0]` in a compile-time order that
/// does not pivot, handing the solve to the runtime's dense one where a
/// pivot fails), through the same hostile states and parameters as the
/// reference models, in f64 and f32: no panic, every `Ok` finite, every
/// `Ok` from finite input holding `A q̈ = b`.
#[test]
fn the_quadruped_in_the_fault_matrix() {
    use crate::quadruped::model::Quadruped;
    let feet = [
        0.1946, 0.1465, 0.1946, -0.1465, -0.1946, 0.1465, -0.1946, -0.1465,
    ];
    let mut tally = Tally::default();
    macro_rules! quadruped {
        ($t:ty) => {
            model::<$t, _, 19, 13, 8>(
                &mut tally,
                "Quadruped",
                |p| {
                    let z = <$t>::of(0.3);
                    Quadruped::new(
                        p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], z, z, z, z, z, z, z, z, z,
                        z, z, z,
                    )
                },
                feet,
            )
        };
    }
    quadruped!(f64);
    quadruped!(f32);
    assert!(tally.ok > 0, "no Ok to judge");
    report(&tally, "quadruped fault matrix");
}

/// Prints the tally as `what` and asserts that nothing failed.
fn report(tally: &Tally, what: &str) {
    println!(
        "{what}: {} evaluations, {} Ok (each judged), {} Err, {} failures",
        tally.evaluations,
        tally.ok,
        tally.err,
        tally.failures.len()
    );
    assert!(
        tally.failures.is_empty(),
        "{} failures:\n{}",
        tally.failures.len(),
        tally.failures.join("\n")
    );
}

/// The models `gauss` solves in their quaternions' velocity coordinates
/// besides the quadruped — two free bodies joined at a point (two
/// quaternions) and a ball on a spherical joint inside a chain with a
/// point on a plane — through the same hostile states, in f64 and f32: no
/// panic, every `Ok` finite, every `Ok` from finite input holding
/// `A q̈ = b`.
#[test]
fn the_velocity_coordinates_in_the_fault_matrix() {
    use crate::contacts::Joined;
    use crate::spherical::TetheredBall;
    let mut tally = Tally::default();
    macro_rules! both {
        ($t:ty) => {
            model::<$t, _, 14, 5, 0>(&mut tally, "Joined", |_| Joined::new(), []);
            model::<$t, _, 5, 2, 0>(&mut tally, "TetheredBall", |_| TetheredBall::new(), []);
        };
    }
    both!(f64);
    both!(f32);
    assert!(tally.ok > 0, "no Ok to judge");
    report(&tally, "velocity coordinates' fault matrix");
}

/// Every integrator with settings that cannot work: an `Err` up front, never
/// a hang or a panic; with good settings from hostile states, `Ok` only with
/// a finite state.
#[test]
fn every_integrator_with_bad_settings_and_hostile_states() {
    let system = DoublePendulum::new(1.0, 2.0, 1.0, 0.8, 9.81);
    let start = system.state_from_angles(0.0, [0.4, -0.7], [0.9, 0.3]);
    let bad_steps = [0.0, -0.1, f64::NAN, f64::INFINITY];
    let bad_stabilizations = [
        Stabilization::projection(f64::NAN),
        Stabilization::projection(-1.0),
        Stabilization::baumgarte(f64::NAN),
        Stabilization::baumgarte(f64::INFINITY),
    ];
    let mut cases = 0;
    let mut check = |what: String,
                     result: Result<constrained::Stats, IntegrationError<f64>>,
                     s: &State<f64, 4>| {
        cases += 1;
        match result {
            Ok(_) => panic!("{what}: Ok with settings that cannot work (state {s:?})"),
            Err(IntegrationError::InvalidParameter)
            | Err(IntegrationError::EndBeforeStart { .. }) => {}
            Err(e) => panic!("{what}: {e:?}, not reported up front"),
        }
    };
    for h in bad_steps {
        let mut s = start;
        check(
            format!("Rk4({h})"),
            Rk4::new(h).advance(&system, &mut s, 1.0),
            &s,
        );
        let mut s = start;
        check(
            format!("ThreeEighthsRule({h})"),
            ThreeEighthsRule::new(h).advance(&system, &mut s, 1.0),
            &s,
        );
        let mut s = start;
        check(
            format!("SemiImplicitEuler({h})"),
            SemiImplicitEuler::new(h).advance(&system, &mut s, 1.0),
            &s,
        );
    }
    for tol in [0.0, -1e-6, f64::NAN, f64::INFINITY] {
        let mut s = start;
        check(
            format!("DormandPrince45({tol}, {tol})"),
            DormandPrince45::new(tol, tol).advance(&system, &mut s, 1.0),
            &s,
        );
        let mut s = start;
        check(
            format!("BogackiShampine32({tol}, {tol})"),
            BogackiShampine32::new(tol, tol).advance(&system, &mut s, 1.0),
            &s,
        );
        let mut s = start;
        check(
            format!("DormandPrince45 max_step {tol}"),
            DormandPrince45::new(1e-6, 1e-9)
                .with_max_step(tol)
                .advance(&system, &mut s, 1.0),
            &s,
        );
    }
    for stabilization in bad_stabilizations {
        let mut s = start;
        check(
            format!("Rk4 {stabilization:?}"),
            Rk4::new(1e-3)
                .with_stabilization(stabilization)
                .advance(&system, &mut s, 1.0),
            &s,
        );
        let mut s = start;
        check(
            format!("DormandPrince45 {stabilization:?}"),
            DormandPrince45::new(1e-6, 1e-9)
                .with_stabilization(stabilization)
                .advance(&system, &mut s, 1.0),
            &s,
        );
    }
    for t_end in [f64::NAN, f64::NEG_INFINITY, -1.0] {
        let mut s = start;
        check(
            format!("Rk4 to {t_end}"),
            Rk4::new(1e-3).advance(&system, &mut s, t_end),
            &s,
        );
        let mut s = start;
        check(
            format!("DormandPrince45 to {t_end}"),
            DormandPrince45::new(1e-6, 1e-9).advance(&system, &mut s, t_end),
            &s,
        );
    }
    let mut s = start;
    check(
        "Rk4 with no step budget".into(),
        Rk4::new(1e-3)
            .with_max_steps(0)
            .advance(&system, &mut s, 1.0),
        &s,
    );
    // Good settings from hostile states: Ok only with a finite state.
    let mut judged = 0;
    for (name, state, _) in states(start) {
        for integrator in 0..3 {
            let mut s = state;
            let result = match integrator {
                0 => Rk4::new(1e-3).advance(&system, &mut s, 0.05),
                1 => DormandPrince45::new(1e-6, 1e-9).advance(&system, &mut s, 0.05),
                _ => Rk4::new(1e-3)
                    .with_stabilization(Stabilization::projection(1e-10))
                    .advance(&system, &mut s, 0.05),
            };
            judged += 1;
            if result.is_ok() {
                assert!(
                    s.q.iter().chain(s.qd.iter()).all(|x| x.is_finite()),
                    "{name} state, integrator {integrator}: Ok with a non-finite state {s:?}"
                );
            }
        }
    }
    println!("integrators: {cases} bad settings, all Err up front; {judged} runs from hostile states judged");
}

/// A fixed-seed generator (64-bit LCG), uniform in `[0, 1)`.
struct Lcg(u64);

impl Lcg {
    fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// `10^u`, `u` uniform in `[lo, hi)`.
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(lo + (hi - lo) * self.uniform())
    }

    fn matrix<const R: usize, const C: usize>(&mut self) -> SMatrix<f64, R, C> {
        SMatrix::from_fn(|_, _| 2.0 * self.uniform() - 1.0)
    }

    /// A random orthogonal matrix: the Q of a random matrix's QR.
    fn orthogonal<const N: usize>(&mut self) -> SMatrix<f64, N, N> {
        let m = self.matrix::<N, N>();
        let q = dynamic(&m).qr().q();
        SMatrix::from_iterator(q.iter().copied())
    }
}

/// A fixed-size matrix as a dynamic one (for nalgebra's decompositions).
fn dynamic<const R: usize, const C: usize>(
    m: &SMatrix<f64, R, C>,
) -> constrained::nalgebra::DMatrix<f64> {
    constrained::nalgebra::DMatrix::from_iterator(R, C, m.iter().copied())
}

/// `e^{Ah}` and `∫₀ʰ e^{As} ds` of a symmetric `A` by its eigendecomposition
/// (nalgebra's symmetric eigensolver, independent of the library):
/// `V diag(e^{λh}) Vᵀ` and `V diag((e^{λh} − 1)/λ) Vᵀ`.
fn symmetric_reference<const N: usize>(
    a: &SMatrix<f64, N, N>,
    h: f64,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>) {
    let eigen = dynamic(a).symmetric_eigen();
    let v = eigen.eigenvectors;
    let exp =
        constrained::nalgebra::DMatrix::from_diagonal(&eigen.eigenvalues.map(|l| (l * h).exp()));
    let phi = constrained::nalgebra::DMatrix::from_diagonal(&eigen.eigenvalues.map(|l| {
        if l == 0.0 {
            h
        } else {
            (l * h).exp_m1() / l
        }
    }));
    let fixed = |m: constrained::nalgebra::DMatrix<f64>| SMatrix::from_iterator(m.iter().copied());
    (
        fixed(&v * exp * v.transpose()),
        fixed(&v * phi * v.transpose()),
    )
}

/// The spectral radius by nalgebra's eigenvalues.
fn spectral_radius<const N: usize>(m: &SMatrix<f64, N, N>) -> f64 {
    dynamic(m)
        .complex_eigenvalues()
        .iter()
        .fold(0.0, |r, z| r.max(z.re.hypot(z.im)))
}

/// `discretize` against a reference exponential and `lqr_gain` checked by
/// its closed loop, from fixed seeds (issue 30):
///
/// - symmetric `A = Q diag(λ) Qᵀ` (`λ` from −10⁶ to −10⁻³, some positive,
///   `h` from 10⁻⁴ to 10): `A_d` and `B_d` within the backward-stable
///   bound `ε ‖A h‖ ‖e^{Ah}‖` (times a small constant) of the
///   eigendecomposition; in f32 within `100 ε_f32 (1 + ‖A h‖)`;
/// - triangular `A` (stiff diagonals up to 10¹⁶): the diagonal of `A_d`
///   equal to `e^{aᵢᵢ h}` to 1e-13 relative, the other triangle exactly 0;
/// - `A` scaled to the ends of the range: `Ok` exactly when the reference
///   is finite, then close to it;
/// - `lqr_gain` on random stabilizable pairs, with tolerances from 1e-12
///   to 0.5: every `Ok` has `ρ(A_d − B_d K) < 1` (nalgebra's eigenvalues),
///   and at tight tolerances `K` is the optimum (Kleinman's identity: with
///   `P` the Lyapunov solution of the closed loop, `K = (R + BᵀPB)⁻¹BᵀPA`);
///   on unstabilizable pairs (an unstable or marginal mode out of reach of
///   `B`, in a random basis) `NotConverged`.
#[test]
fn control_against_references_from_fixed_seeds() {
    use constrained::control::{discretize, lqr_gain, ControlError};
    let mut rng = Lcg(20261130);
    let mut checked = 0;
    let mut failures = Vec::new();
    // Symmetric, f64 and f32.
    for case in 0..300 {
        let q = rng.orthogonal::<4>();
        let lambda = SVector::<f64, 4>::from_fn(|i, _| {
            let magnitude = rng.log_uniform(-3.0, 6.0);
            if i == 3 && case % 5 == 0 {
                magnitude.min(2.0)
            } else {
                -magnitude
            }
        });
        let a = q * SMatrix::<f64, 4, 4>::from_diagonal(&lambda) * q.transpose();
        let a = (a + a.transpose()) * 0.5;
        let b = rng.matrix::<4, 2>();
        let h = rng.log_uniform(-4.0, 1.0);
        let (ad_ref, gamma) = symmetric_reference(&a, h);
        let bd_ref = gamma * b;
        let norm = a.norm() * h;
        match discretize(&a, &b, h) {
            Ok((ad, bd)) => {
                let bound = 16.0 * f64::EPSILON * (1.0 + norm);
                let ead = (ad - ad_ref).norm() / ad_ref.norm().max(1e-300);
                let ebd = (bd - bd_ref).norm() / bd_ref.norm().max(1e-300);
                if !(ead <= bound.max(1e-14) && ebd <= bound.max(1e-14)) {
                    failures.push(format!(
                        "discretize symmetric case {case} (‖Ah‖ = {norm:e}): A_d {ead:e}, B_d {ebd:e} > {bound:e}"
                    ));
                }
            }
            Err(e) => failures.push(format!("discretize symmetric case {case}: {e}")),
        }
        let (a32, b32) = (a.cast::<f32>(), b.cast::<f32>());
        match discretize(&a32, &b32, h as f32) {
            Ok((ad, bd)) => {
                let bound = 100.0 * f64::from(f32::EPSILON) * (1.0 + norm);
                let ead = (ad.cast::<f64>() - ad_ref).norm() / ad_ref.norm().max(1e-300);
                let ebd = (bd.cast::<f64>() - bd_ref).norm() / bd_ref.norm().max(1e-300);
                if !(ead <= bound && ebd <= bound) {
                    failures.push(format!(
                        "discretize f32 case {case} (‖Ah‖ = {norm:e}): A_d {ead:e}, B_d {ebd:e} > {bound:e}"
                    ));
                }
            }
            Err(e) => failures.push(format!("discretize f32 case {case}: {e}")),
        }
        checked += 2;
    }
    // Triangular: exact diagonals, the other triangle exactly zero.
    for case in 0..200 {
        let mut a = rng.matrix::<4, 4>() * rng.log_uniform(-2.0, 3.0);
        for i in 0..4 {
            a[(i, i)] = -rng.log_uniform(-3.0, 16.0);
            for j in 0..i {
                a[(i, j)] = 0.0;
            }
        }
        if case % 2 == 1 {
            a = a.transpose();
        }
        let h = rng.log_uniform(-3.0, 1.0);
        match discretize(&a, &SMatrix::<f64, 4, 1>::repeat(1.0), h) {
            Ok((ad, _)) => {
                for i in 0..4 {
                    let want = (a[(i, i)] * h).exp();
                    let got = ad[(i, i)];
                    let ok = if want == 0.0 {
                        got == 0.0
                    } else {
                        ((got - want) / want).abs() < 1e-13
                    };
                    if !ok {
                        failures.push(format!(
                            "discretize triangular case {case}: A_d[{i},{i}] = {got:e}, e^(a h) = {want:e}"
                        ));
                    }
                    for j in 0..4 {
                        if a[(i, j)] == 0.0 && a[(j, i)] != 0.0 && ad[(i, j)] != 0.0 {
                            failures.push(format!(
                                "discretize triangular case {case}: A_d[{i},{j}] = {:e}, not 0",
                                ad[(i, j)]
                            ));
                        }
                    }
                }
            }
            Err(e) => failures.push(format!("discretize triangular case {case}: {e}")),
        }
        checked += 1;
    }
    // The ends of the range: A = s · (stable symmetric) and h = x / s,
    // with s from 1e-300 to 1e300 and x from 1e-20 to 1e308: ‖A h‖ up to
    // ~1e309, beyond the range (the old scaling halved h into 0 there).
    for case in 0..200 {
        let q = rng.orthogonal::<3>();
        let lambda = SVector::<f64, 3>::from_fn(|_, _| -rng.log_uniform(0.0, 1.0));
        let base = q * SMatrix::<f64, 3, 3>::from_diagonal(&lambda) * q.transpose();
        let base = (base + base.transpose()) * 0.5;
        let scale = rng.log_uniform(-300.0, 300.0);
        let x = if case % 5 == 0 {
            rng.log_uniform(306.0, 308.25)
        } else {
            rng.log_uniform(-20.0, 306.0)
        };
        let h = x / scale;
        if !(h.is_finite() && h > 0.0) {
            continue;
        }
        let a = base * scale;
        let b = SMatrix::<f64, 3, 1>::new(1.0, -2.0, 0.5);
        // The reference from the unscaled base: e^{A h} = e^{base (s h)},
        // ∫₀ʰ e^{As} ds = ∫₀^{sh} e^{base u} du / s.
        let (ad_ref, gamma) = symmetric_reference(&base, scale * h);
        let bd_ref = gamma * b / scale;
        let representable = bd_ref.iter().all(|x| x.is_finite() && *x != 0.0);
        match discretize(&a, &b, h) {
            Ok((ad, bd)) => {
                let ead = (ad - ad_ref).amax();
                // amax, not norm: squares of 1e-200 underflow.
                let ebd = (bd - bd_ref).amax() / bd_ref.amax();
                // B_d near the subnormal range keeps fewer digits.
                let subnormal = bd_ref.amax() < 1e-290;
                if !(ead < 1e-12 && (ebd < 1e-12 || subnormal && ebd < 1e-3)) {
                    failures.push(format!(
                        "discretize at scale {scale:e}, h = {h:e} (case {case}): A_d off by {ead:e}, B_d by {ebd:e}"
                    ));
                }
            }
            Err(ControlError::NonFinite) if !representable => {}
            Err(e) => failures.push(format!(
                "discretize at scale {scale:e}, h = {h:e} (case {case}): {e}"
            )),
        }
        checked += 1;
    }
    // lqr_gain: random stabilizable pairs, loose and tight tolerances.
    let mut gains = 0;
    for case in 0..200 {
        let a = rng.matrix::<4, 4>() * 1.5;
        let b = rng.matrix::<4, 2>();
        let q = SMatrix::<f64, 4, 4>::from_diagonal(&SVector::from_fn(|_, _| {
            rng.log_uniform(-2.0, 2.0)
        }));
        let r = SMatrix::<f64, 2, 2>::from_diagonal(&SVector::from_fn(|_, _| {
            rng.log_uniform(-2.0, 2.0)
        }));
        let tolerance = [1e-12, 1e-9, 1e-4, 0.1, 0.5][case % 5];
        match lqr_gain(&a, &b, &q, &r, tolerance, 100_000) {
            Ok(k) => {
                gains += 1;
                let closed = a - b * k;
                let rho = spectral_radius(&closed);
                let stable = rho < 1.0;
                if !stable {
                    failures.push(format!(
                        "lqr_gain case {case} (tolerance {tolerance}): ρ(A − BK) = {rho}"
                    ));
                } else if tolerance <= 1e-9 {
                    // Kleinman: P = Σ (A−BK)ᵀᵏ (Q + KᵀRK) (A−BK)ᵏ, by the
                    // Kronecker form of the Lyapunov equation.
                    let c = q + k.transpose() * r * k;
                    let kron = constrained::nalgebra::DMatrix::<f64>::from_fn(16, 16, |i, j| {
                        let delta = if i == j { 1.0 } else { 0.0 };
                        delta - closed[(j % 4, i % 4)] * closed[(j / 4, i / 4)]
                    });
                    let rhs = constrained::nalgebra::DVector::<f64>::from_fn(16, |i, _| {
                        c[(i % 4, i / 4)]
                    });
                    let p = kron.lu().solve(&rhs).expect("stable closed loop");
                    let p = SMatrix::<f64, 4, 4>::from_fn(|i, j| p[i + 4 * j]);
                    let optimal = (r + b.transpose() * p * b)
                        .try_inverse()
                        .expect("R + BᵀPB > 0")
                        * b.transpose()
                        * p
                        * a;
                    let error = (optimal - k).amax() / optimal.amax();
                    if error > 1e-6 {
                        failures.push(format!(
                            "lqr_gain case {case}: K off the optimum by {error:e}"
                        ));
                    }
                }
            }
            Err(e) => failures.push(format!("lqr_gain case {case} (stabilizable): {e}")),
        }
        checked += 1;
    }
    // Unstabilizable: a mode of modulus ≥ 1 out of reach of B, hidden by a
    // random orthogonal change of basis (the marginal one unrotated).
    for case in 0..60 {
        let mut a = SMatrix::<f64, 3, 3>::zeros();
        a.fixed_view_mut::<2, 2>(0, 0)
            .copy_from(&(rng.matrix::<2, 2>() * 1.5));
        let hidden = [1.0, 1.05, 1.3, -1.1, -2.0][case % 5];
        a[(2, 2)] = hidden;
        let mut b = SMatrix::<f64, 3, 1>::zeros();
        b.fixed_view_mut::<2, 1>(0, 0)
            .copy_from(&rng.matrix::<2, 1>());
        if hidden != 1.0 {
            let t = rng.orthogonal::<3>();
            a = t * a * t.transpose();
            b = t * b;
        }
        let tolerance = [1e-12, 1e-6, 0.1][case % 3];
        let result = lqr_gain(
            &a,
            &b,
            &SMatrix::<f64, 3, 3>::identity(),
            &SMatrix::<f64, 1, 1>::new(1.0),
            tolerance,
            10_000,
        );
        if result != Err(ControlError::NotConverged) {
            failures.push(format!(
                "lqr_gain unstabilizable case {case} (hidden mode {hidden}, tolerance {tolerance}): {result:?}"
            ));
        }
        checked += 1;
    }
    println!(
        "control: {checked} cases ({gains} gains, each with ρ(A − BK) < 1), {} failures",
        failures.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
