//! The generated Jacobians of `q̈` (issue 12), for every reference model at
//! consistent states, against two independent truths: central differences
//! of `acceleration` (to 1e-7) and dual numbers (`num_dual::Dual64` as the
//! scalar of the same generated code, forward mode through its
//! factorization: to 1e-12). Dual numbers differentiate the code
//! `acceleration` runs, rank decisions and all, so they also check that
//! the Jacobian is the one of the `q̈` actually returned.

// The macro's input counter is incremented after the last input too.
#![allow(unused_assignments, clippy::reversed_empty_ranges)] // NU = 0 for most models

use constrained::models::*;
use constrained::nalgebra::{SMatrix, SVector};
use constrained::stabilize::project;
use constrained::{ConstrainedSystem, DynamicsError, Jacobians, State};
use num_dual::Dual64;

/// The inherent methods return a plain value or a `Result`, as
/// `acceleration` does for the model: one shape for the test.
trait Answer<V> {
    fn answer(self) -> Result<V, DynamicsError>;
}

impl<V> Answer<V> for Result<V, DynamicsError> {
    fn answer(self) -> Result<V, DynamicsError> {
        self
    }
}

impl<const N: usize, const NU: usize> Answer<Jacobians<f64, N, NU>> for Jacobians<f64, N, NU> {
    fn answer(self) -> Result<Jacobians<f64, N, NU>, DynamicsError> {
        Ok(self)
    }
}

impl<const R: usize, const NU: usize> Answer<(SMatrix<f64, R, R>, SMatrix<f64, R, NU>)>
    for (SMatrix<f64, R, R>, SMatrix<f64, R, NU>)
{
    fn answer(self) -> Result<(SMatrix<f64, R, R>, SMatrix<f64, R, NU>), DynamicsError> {
        Ok(self)
    }
}

/// A pseudo-random state projected onto the constraints (position and
/// velocity level).
pub(crate) fn consistent<S, const N: usize, const K: usize>(system: &S, seed: u64) -> State<f64, N>
where
    S: ConstrainedSystem<f64, N, K>,
{
    let mut x = seed;
    let mut next = || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((x >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let q = SVector::<f64, N>::from_fn(|_, _| next() + 0.3);
    let qd = SVector::<f64, N>::from_fn(|_, _| 2.0 * next());
    let mut state = State::new(0.25, q, qd);
    project(system, &mut state, 1e-13, 50).expect("a consistent state near the seed");
    state
}

/// The largest entry of `a − b` against the scale of `b`.
fn error<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>, b: &SMatrix<f64, R, C>) -> f64 {
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    (a - b).iter().fold(0.0f64, |m, x| m.max(x.abs())) / scale
}

/// Largest errors against central differences and dual numbers.
#[derive(Default, Debug)]
struct Errors {
    central: f64,
    dual: f64,
}

macro_rules! check_model {
    ($errors:expr, $model:ident, $n:literal, $k:literal, [$($p:expr),*], [$($input:ident = $u:expr),*]) => {{
        let build = || {
            #[allow(unused_mut)]
            let mut s = $model::<f64>::new($($p),*);
            $( s.$input = $u; )*
            s
        };
        #[allow(unused_variables)]
        let build_dual = |seed: Option<usize>| {
            #[allow(unused_mut)]
            let mut s = $model::<Dual64>::new($(Dual64::from($p)),*);
            #[allow(unused_mut, unused_variables, unused_assignments)]
            let mut j = 0usize;
            $(
                s.$input = if seed == Some(j) { Dual64::new($u, 1.0) } else { Dual64::from($u) };
                j += 1;
            )*
            s
        };
        let system = build();
        let acc = |s: &$model<f64>, q: &SVector<f64, $n>, qd: &SVector<f64, $n>, t: f64| {
            ConstrainedSystem::<f64, $n, $k>::acceleration(s, &State::new(t, *q, *qd))
                .expect(concat!(stringify!($model), ": acceleration"))
        };
        for seed in [1u64, 2, 3] {
            let x = consistent::<_, $n, $k>(&system, seed);
            let (q, qd, t) = (x.q, x.qd, x.t);
            let jac = system.acceleration_jacobian(&q, &qd, t).answer()
                .expect(concat!(stringify!($model), ": acceleration_jacobian"));
            const NU: usize = $model::<f64>::INPUTS;
            // Central differences, column by column.
            let mut dq = SMatrix::<f64, $n, $n>::zeros();
            let mut dqd = SMatrix::<f64, $n, $n>::zeros();
            for c in 0..$n {
                let h = 1e-5 * q[c].abs().max(1.0);
                let (mut plus, mut minus) = (q, q);
                plus[c] += h;
                minus[c] -= h;
                dq.set_column(c, &((acc(&system, &plus, &qd, t) - acc(&system, &minus, &qd, t)) / (2.0 * h)));
                let h = 1e-5 * qd[c].abs().max(1.0);
                let (mut plus, mut minus) = (qd, qd);
                plus[c] += h;
                minus[c] -= h;
                dqd.set_column(c, &((acc(&system, &q, &plus, t) - acc(&system, &q, &minus, t)) / (2.0 * h)));
            }
            #[allow(unused_mut)]
            let mut du = SMatrix::<f64, $n, NU>::zeros();
            #[allow(unused_mut, unused_variables, unused_assignments)]
            let mut j = 0usize;
            $(
                let h = 1e-5 * ($u as f64).abs().max(1.0);
                let (mut plus, mut minus) = (build(), build());
                plus.$input += h;
                minus.$input -= h;
                du.set_column(j, &((acc(&plus, &q, &qd, t) - acc(&minus, &q, &qd, t)) / (2.0 * h)));
                j += 1;
            )*
            let central = error(&jac.dq, &dq).max(error(&jac.dqd, &dqd)).max(if NU > 0 { error(&jac.du, &du) } else { 0.0 });
            // Dual numbers: one column per seeded variable.
            let dual_acc = |s: &$model<Dual64>, q: SVector<Dual64, $n>, qd: SVector<Dual64, $n>| {
                let a = ConstrainedSystem::<Dual64, $n, $k>::acceleration(s, &State::new(Dual64::from(t), q, qd))
                    .expect(concat!(stringify!($model), ": dual acceleration"));
                SVector::<f64, $n>::from_fn(|i, _| a[i].eps)
            };
            let lift = |v: &SVector<f64, $n>, seed: Option<usize>| {
                SVector::<Dual64, $n>::from_fn(|i, _| if Some(i) == seed { Dual64::new(v[i], 1.0) } else { Dual64::from(v[i]) })
            };
            let plain = build_dual(None);
            let mut dual = 0.0f64;
            for c in 0..$n {
                let col = dual_acc(&plain, lift(&q, Some(c)), lift(&qd, None));
                dual = dual.max(error(&jac.dq.column(c).into_owned(), &col));
                let col = dual_acc(&plain, lift(&q, None), lift(&qd, Some(c)));
                dual = dual.max(error(&jac.dqd.column(c).into_owned(), &col));
            }
            for c in 0..NU {
                let col = dual_acc(&build_dual(Some(c)), lift(&q, None), lift(&qd, None));
                dual = dual.max(error(&jac.du.column(c).into_owned(), &col));
            }
            // `linearize` is the Jacobian in block form.
            let (a, b) = system.linearize(&q, &qd, t).answer().expect("linearize");
            for i in 0..$n {
                for c in 0..$n {
                    assert_eq!(a[(i, c)], 0.0);
                    assert_eq!(a[(i, $n + c)], if i == c { 1.0 } else { 0.0 });
                    assert_eq!(a[($n + i, c)], jac.dq[(i, c)]);
                    assert_eq!(a[($n + i, $n + c)], jac.dqd[(i, c)]);
                }
                for c in 0..NU {
                    assert_eq!(b[(i, c)], 0.0);
                    assert_eq!(b[($n + i, c)], jac.du[(i, c)]);
                }
            }
            println!("{:<24} seed {seed}: central differences {central:.1e}, dual numbers {dual:.1e}", stringify!($model));
            assert!(central < 1e-7, "{}: {central:e} against central differences", stringify!($model));
            assert!(dual < 1e-12, "{}: {dual:e} against dual numbers", stringify!($model));
            $errors.central = $errors.central.max(central);
            $errors.dual = $errors.dual.max(dual);
        }
    }};
}

#[test]
fn jacobians_agree_with_central_differences_and_dual_numbers_for_every_model() {
    let mut e = Errors::default();
    check_model!(e, Appell, 3, 1, [9.81, 0.7], []);
    check_model!(e, AppellTimeDependent, 3, 1, [9.81, 0.7], []);
    check_model!(e, SphericalPendulum, 3, 1, [1.5, 9.81, 1.2], []);
    check_model!(e, DoublePendulum, 4, 2, [1.0, 2.0, 1.0, 0.8, 9.81], []);
    check_model!(
        e,
        RedundantDoublePendulum,
        4,
        3,
        [1.0, 2.0, 1.0, 0.8, 9.81],
        []
    );
    check_model!(e, BeadOnRotatingHoop, 3, 2, [0.5, 9.81, 1.0, 2.0], []);
    check_model!(
        e,
        ChaplyginSleigh,
        3,
        1,
        [2.0, 0.4, 0.3, 0.0],
        [torque = 0.6]
    );
    check_model!(e, SliderCrank, 4, 4, [1.0, 2.0, 0.5, 1.5, 3.0, 9.81], []);
    check_model!(
        e,
        TwoLinkArmOnLine,
        2,
        1,
        [1.0, 0.5, 1.0, 1.0, 9.81, 0.5],
        []
    );
    check_model!(
        e,
        Crane,
        3,
        1,
        [5.0, 1.0, 2.0, 9.81, 0.1, 4.0, 3.0, 20.0, 1.0],
        []
    );
    check_model!(e, CartPole, 2, 0, [1.0, 0.3, 0.8, 9.81, 0.0], [push = 1.7]);
    check_model!(
        e,
        CartPoleCartesian,
        3,
        1,
        [1.0, 0.3, 0.8, 9.81, 0.0],
        [push = -0.6]
    );
    check_model!(
        e,
        DoublePendulumAngles,
        2,
        0,
        [1.0, 2.0, 1.0, 0.8, 9.81],
        []
    );
    check_model!(e, RigidBodyQuaternion, 4, 1, [1.0, 2.0, 3.0], []);
    check_model!(e, HeavyTop, 4, 1, [1.0, 2.0, 1.0, 9.81, 0.5], []);
    check_model!(e, RollingDisk, 5, 2, [1.0, 0.5, 0.06, 0.12, 9.81], []);
    check_model!(
        e,
        ParallelogramFourBarAngles,
        3,
        2,
        [1.2, 0.15, 1.0, 2.0, 9.81],
        []
    );
    check_model!(
        e,
        ParallelogramFourBar,
        9,
        8,
        [1.2, 0.15, 1.0, 2.0, 9.81],
        []
    );
    println!("largest errors over all models: {e:?}");
}

/// Eigenvalues sorted by (real, imaginary) part.
fn eigenvalues<const M: usize>(a: &SMatrix<f64, M, M>) -> Vec<(f64, f64)> {
    let dynamic = constrained::nalgebra::DMatrix::from_column_slice(M, M, a.as_slice());
    let mut e: Vec<(f64, f64)> = dynamic
        .complex_eigenvalues()
        .iter()
        .map(|z| (z.re, z.im))
        .collect();
    // By imaginary part, then real part: rounding leaves real parts of
    // ±1e-15 on imaginary pairs.
    e.sort_by(|x, y| (x.1, x.0).partial_cmp(&(y.1, y.0)).expect("finite"));
    e
}

/// Each wanted eigenvalue matched to the nearest one not yet matched.
fn assert_close(what: &str, got: &[(f64, f64)], want: &[(f64, f64)], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: {got:?} vs {want:?}");
    let mut free: Vec<(f64, f64)> = got.to_vec();
    for w in want {
        let distance = |g: &(f64, f64)| (g.0 - w.0).hypot(g.1 - w.1);
        let (i, d) = free
            .iter()
            .enumerate()
            .map(|(i, g)| (i, distance(g)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("as many as wanted");
        assert!(d < tol, "{what}: {got:?} vs {want:?}");
        free.remove(i);
    }
}

/// The upright cart-pole has eigenvalues 0, 0, ±√(g (mc + mp) / (mc l))
/// (the textbook result for a point mass on a massless rod). The
/// generalized form's `linearize` and the Cartesian form's reduced
/// linearization both give them; the Cartesian form's full linearization
/// has two more, spurious, from the rod's direction.
#[test]
fn cart_pole_eigenvalues_at_the_upright_state_in_both_forms() {
    let (mc, mp, l, g) = (1.0f64, 0.3, 0.8, 9.81);
    let rate = (g * (mc + mp) / (mc * l)).sqrt();
    let want = vec![(-rate, 0.0), (0.0, 0.0), (0.0, 0.0), (rate, 0.0)];

    let generalized = CartPole::new(mc, mp, l, g, 0.0);
    let up = SVector::<f64, 2>::new(0.0, std::f64::consts::PI);
    let (a, b) = generalized
        .linearize(&up, &SVector::zeros(), 0.0)
        .expect("upright");
    assert_close("generalized", &eigenvalues(&a), &want, 1e-12);
    // The push accelerates the cart by 1/mc and turns the pole by 1/(mc l).
    assert!((b[(2, 0)] - 1.0 / mc).abs() < 1e-14);
    assert!((b[(3, 0)] - 1.0 / (mc * l)).abs() < 1e-14);

    let cartesian = CartPoleCartesian::new(mc, mp, l, g, 0.0);
    let up = SVector::<f64, 3>::new(0.0, 0.0, l);
    let reduced = cartesian
        .linearize_reduced(&up, &SVector::zeros(), 0.0)
        .expect("upright");
    println!(
        "Cartesian cart-pole, reduced state (q{:?}, q̇{:?})",
        reduced.coordinates, reduced.speeds
    );
    // The double zero is a Jordan block: rounding splits it by ~√ε.
    assert_close("Cartesian, reduced", &eigenvalues(&reduced.a), &want, 1e-7);
    let (full, _) = cartesian
        .linearize(&up, &SVector::zeros(), 0.0)
        .expect("upright");
    let spurious = eigenvalues(&full);
    assert_eq!(spurious.len(), 6);
    println!("Cartesian cart-pole, full linearization: {spurious:?}");
}

/// The double pendulum hanging at rest: the reduced linearization of the
/// Cartesian form (two rod constraints) and the linearization of the
/// angle form have the eigenvalues ±iω₁, ±iω₂ of the closed form
/// `ω² = g (m₁ + m₂)(l₁ + l₂ ± √((l₁ + l₂)² − 4 l₁ l₂ m₁/(m₁ + m₂))) / (2 m₁ l₁ l₂)`.
#[test]
fn double_pendulum_normal_modes_in_both_forms() {
    let (m1, m2, l1, l2, g): (f64, f64, f64, f64, f64) = (1.0, 2.0, 1.0, 0.8, 9.81);
    let root = ((l1 + l2).powi(2) - 4.0 * l1 * l2 * m1 / (m1 + m2)).sqrt();
    let omega = |sign: f64| (g * (m1 + m2) * (l1 + l2 + sign * root) / (2.0 * m1 * l1 * l2)).sqrt();
    let (w1, w2) = (omega(-1.0), omega(1.0));
    let want = vec![(0.0, -w2), (0.0, -w1), (0.0, w1), (0.0, w2)];

    let angles = DoublePendulumAngles::new(m1, m2, l1, l2, g);
    let (a, _) = angles
        .linearize(&SVector::zeros(), &SVector::zeros(), 0.0)
        .expect("hanging");
    assert_close("angles", &eigenvalues(&a), &want, 1e-10);

    let cartesian = DoublePendulum::new(m1, m2, l1, l2, g);
    let hanging = SVector::<f64, 4>::new(0.0, -l1, 0.0, -l1 - l2);
    let reduced = cartesian
        .linearize_reduced(&hanging, &SVector::zeros(), 0.0)
        .expect("hanging");
    assert_close("Cartesian, reduced", &eigenvalues(&reduced.a), &want, 1e-10);
}

/// The Jacobian the runtime solves densely (Cholesky of `M`, pivoted `LDLᵀ`
/// of `S`) from the motion the generated solver returned: the reference for
/// the generated structured solve.
fn dense<S, const N: usize, const K: usize, const NU: usize, const D: usize>(
    system: &S,
    state: &State<f64, N>,
) -> Jacobians<f64, N, NU>
where
    S: constrained::__private::Generated<f64, N, K> + constrained::__private::Tangent<f64, N, K, D>,
{
    let motion = system
        .gauss(&state.q, &state.qd, state.t, None)
        .expect("the motion exists");
    constrained::linearize::acceleration_jacobian::<f64, S, N, K, NU, D>(
        system, &state.q, &state.qd, state.t, motion,
    )
}

fn jacobian_difference<const N: usize, const NU: usize>(
    a: &Jacobians<f64, N, NU>,
    b: &Jacobians<f64, N, NU>,
) -> f64 {
    error(&a.dq, &b.dq)
        .max(error(&a.dqd, &b.dqd))
        .max(if NU > 0 { error(&a.du, &b.du) } else { 0.0 })
}

/// The generated code solves the tangent systems through the structured
/// factorizations of `acceleration` (of `S`, and of `M` where it depends on
/// `q`); it must give the runtime's dense answer: at consistent states of
/// every model with a non-singular `M` (with
/// a redundant row dropped by the rank rule in the redundant double
/// pendulum and the slider-crank), and near the four-bar's branch point,
/// where the rank decision is made state by state.
#[test]
fn the_structured_solve_equals_the_dense_one() {
    macro_rules! same {
        ($model:ident, $n:literal, $k:literal, $nu:literal, [$($p:expr),*]) => {{
            let system = $model::<f64>::new($($p),*);
            let mut worst = 0.0f64;
            for seed in 1..=3u64 {
                let state = consistent::<_, $n, $k>(&system, seed);
                let generated = system
                    .acceleration_jacobian(&state.q, &state.qd, state.t)
                    .answer()
                    .expect("the Jacobians exist");
                let reference = dense::<_, $n, $k, $nu, { 2 * $n + $nu }>(&system, &state);
                worst = worst.max(jacobian_difference(&generated, &reference));
            }
            println!("{:<24} structured vs dense {worst:.1e}", stringify!($model));
            assert!(worst < 1e-11, "{}: {worst:e}", stringify!($model));
        }};
    }
    same!(Appell, 3, 1, 0, [9.81, 0.7]);
    same!(AppellTimeDependent, 3, 1, 0, [9.81, 0.7]);
    same!(SphericalPendulum, 3, 1, 0, [1.5, 9.81, 1.2]);
    same!(DoublePendulum, 4, 2, 0, [1.0, 2.0, 1.0, 0.8, 9.81]);
    same!(RedundantDoublePendulum, 4, 3, 0, [1.0, 2.0, 1.0, 0.8, 9.81]);
    same!(BeadOnRotatingHoop, 3, 2, 0, [0.5, 9.81, 1.0, 2.0]);
    same!(ChaplyginSleigh, 3, 1, 1, [2.0, 0.4, 0.3, 0.6]);
    same!(SliderCrank, 4, 4, 0, [1.0, 2.0, 0.5, 1.5, 3.0, 9.81]);
    same!(
        Crane,
        3,
        1,
        0,
        [5.0, 1.0, 2.0, 9.81, 0.1, 4.0, 3.0, 20.0, 1.0]
    );
    same!(CartPoleCartesian, 3, 1, 1, [1.0, 0.3, 0.8, 9.81, 1.7]);
    // M(q): the generated LDLᵀ of M on its pattern, then of S.
    same!(CartPole, 2, 0, 1, [1.0, 0.3, 0.8, 9.81, 1.7]);
    same!(DoublePendulumAngles, 2, 0, 0, [1.0, 2.0, 1.0, 0.8, 9.81]);
    same!(TwoLinkArmOnLine, 2, 1, 0, [1.0, 0.5, 1.0, 1.0, 9.81, 0.5]);
    same!(RollingDisk, 5, 2, 0, [1.0, 0.5, 0.06, 0.12, 9.81]);
    same!(
        ParallelogramFourBarAngles,
        3,
        2,
        0,
        [1.2, 0.15, 1.0, 2.0, 9.81]
    );

    // From 3e-5 rad in, both say the derivative is not resolved
    // (`Err(NotDifferentiable)`: `acceleration` jumps at its rank tolerance).
    let four_bar = ParallelogramFourBar::<f64>::new(1.2, 0.15, 1.0, 2.0, 9.81);
    let mut worst = 0.0f64;
    for theta in [1e-1, 1e-3, 1e-4, 1e-5, 1e-8] {
        let state = four_bar_state(&four_bar, theta, 1.3);
        let generated = four_bar.acceleration_jacobian(&state.q, &state.qd, state.t);
        let motion =
            constrained::__private::Generated::gauss(&four_bar, &state.q, &state.qd, state.t, None)
                .expect("the motion exists");
        let reference = constrained::linearize::try_acceleration_jacobian::<_, _, 9, 8, 0, 18>(
            &four_bar, &state.q, &state.qd, state.t, motion,
        );
        match (generated, reference) {
            (Ok(generated), Ok(reference)) => {
                worst = worst.max(jacobian_difference(&generated, &reference));
            }
            (generated, reference) => assert_eq!(
                generated.err(),
                reference.err(),
                "θ = {theta:e}: structured and dense differ in kind"
            ),
        }
    }
    println!("ParallelogramFourBar     structured vs dense near the branch point {worst:.1e}");
    assert!(worst < 1e-6, "four-bar near its branch point: {worst:e}");
}

/// A configuration-dependent `M` is factored in generated code on its
/// compile-time pattern; `acceleration` must equal the runtime's dense
/// Cholesky solve at random (not necessarily consistent) states, to
/// rounding: 1e-14 relative per unit of κ(M).
#[test]
fn the_generated_factorization_of_m_equals_the_dense_solve() {
    macro_rules! same {
        ($model:ident, $n:literal, $k:literal, [$($p:expr),*]) => {{
            let system = $model::<f64>::new($($p),*);
            let mut worst = 0.0f64;
            let mut x = 7u64;
            let mut next = || {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((x >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
            };
            for _ in 0..200 {
                let q = SVector::<f64, $n>::from_fn(|_, _| 2.0 * next());
                let qd = SVector::<f64, $n>::from_fn(|_, _| 2.0 * next());
                let t = next();
                let generated = system.acceleration(&q, &qd, t).expect("M is positive definite");
                let (dense, _) = constrained::__private::gauss_dense::<f64, _, $n, $k>(&system, &q, &qd, t, None)
                    .expect("M is positive definite");
                // Two backward-stable solves differ by up to κ(M)·ε: the
                // rolling disk's Euler angles make M nearly singular where
                // the disk lies almost flat.
                let sv = system.mass_matrix(&q, t).singular_values();
                let conditioning = sv.max() / sv.min();
                let scale = dense.amax().max(1.0) * conditioning.max(1.0);
                worst = worst.max((generated - dense).amax() / scale);
            }
            println!("{:<24} generated M(q) vs dense {worst:.1e} (relative, per unit of κ(M))", stringify!($model));
            assert!(worst < 1e-14, "{}: {worst:e}", stringify!($model));
        }};
    }
    same!(CartPole, 2, 0, [1.0, 0.3, 0.8, 9.81, 1.7]);
    same!(DoublePendulumAngles, 2, 0, [1.0, 2.0, 1.0, 0.8, 9.81]);
    same!(TwoLinkArmOnLine, 2, 1, [1.0, 0.5, 1.0, 1.0, 9.81, 0.5]);
    same!(RollingDisk, 5, 2, [1.0, 0.5, 0.06, 0.12, 9.81]);
    same!(
        ParallelogramFourBarAngles,
        3,
        2,
        [1.2, 0.15, 1.0, 2.0, 9.81]
    );
}
