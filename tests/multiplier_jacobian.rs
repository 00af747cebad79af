//! The Jacobians of the constraint multipliers `λ(q, q̇, u)`
//! (`multiplier_jacobian`), against two independent truths: central
//! differences of `constraint_multipliers` (to 1e-6) and dual numbers
//! (`num_dual::Dual64` as the scalar of the same generated code, forward
//! mode through its solve: to 1e-11), at consistent states of every
//! reference model whose rows are independent, and of a free body pinned
//! at a point (quaternion coordinates, a semi-definite `M`). A redundant
//! set, whose minimum-norm `λ` is one choice among many, answers
//! `Err(NotDifferentiable)`. `acceleration_and_multiplier_jacobians` gives
//! the same `∂λ` and the `∂q̈` of `acceleration_jacobian` (to 1e-12).

// The macro's input counter is incremented after the last input too.
#![allow(unused_assignments, clippy::reversed_empty_ranges)]

use crate::contacts::PinnedTop;
use crate::linearize::consistent;
use constrained::models::*;
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{SMatrix, SVector};
use constrained::{DynamicsError, Jacobians, State};
use num_dual::Dual64;

/// `acceleration_jacobian` is plain or a `Result` as `acceleration` is for
/// the model: one shape for the test.
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

/// The largest entry of `a − b` against the scale of `b` (at least 1).
fn error<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>, b: &SMatrix<f64, R, C>) -> f64 {
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    (a - b).iter().fold(0.0f64, |m, x| m.max(x.abs())) / scale
}

macro_rules! check_multipliers {
    ($worst:expr, $model:ident, $n:literal, $k:literal, [$($p:expr),*], [$($input:ident = $u:expr),*]) => {{
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
        let lambda = |s: &$model<f64>, q: &SVector<f64, $n>, qd: &SVector<f64, $n>, t: f64| {
            Multipliers::<f64, $n, $k>::constraint_multipliers(s, &State::new(t, *q, *qd))
                .expect(concat!(stringify!($model), ": constraint_multipliers"))
        };
        for seed in [1u64, 2, 3] {
            let x = consistent::<_, $n, $k>(&system, seed);
            let (q, qd, t) = (x.q, x.qd, x.t);
            let jac = system.multiplier_jacobian(&q, &qd, t)
                .expect(concat!(stringify!($model), ": multiplier_jacobian"));
            let (both_q, both_l) = system.acceleration_and_multiplier_jacobians(&q, &qd, t)
                .expect(concat!(stringify!($model), ": both Jacobians"));
            assert_eq!(both_l, jac, "{}: the same ∂λ", stringify!($model));
            let alone = system.acceleration_jacobian(&q, &qd, t).answer()
                .expect(concat!(stringify!($model), ": acceleration_jacobian"));
            let same = error(&both_q.dq, &alone.dq).max(error(&both_q.dqd, &alone.dqd)).max(error(&both_q.du, &alone.du));
            assert!(same < 1e-12, "{}: ∂q̈ {same:e} from acceleration_jacobian's", stringify!($model));
            const NU: usize = $model::<f64>::INPUTS;
            let mut dq = SMatrix::<f64, $k, $n>::zeros();
            let mut dqd = SMatrix::<f64, $k, $n>::zeros();
            for c in 0..$n {
                let h = 1e-5 * q[c].abs().max(1.0);
                let (mut plus, mut minus) = (q, q);
                plus[c] += h;
                minus[c] -= h;
                dq.set_column(c, &((lambda(&system, &plus, &qd, t) - lambda(&system, &minus, &qd, t)) / (2.0 * h)));
                let h = 1e-5 * qd[c].abs().max(1.0);
                let (mut plus, mut minus) = (qd, qd);
                plus[c] += h;
                minus[c] -= h;
                dqd.set_column(c, &((lambda(&system, &q, &plus, t) - lambda(&system, &q, &minus, t)) / (2.0 * h)));
            }
            #[allow(unused_mut)]
            let mut du = SMatrix::<f64, $k, NU>::zeros();
            #[allow(unused_mut, unused_variables, unused_assignments)]
            let mut j = 0usize;
            $(
                let h = 1e-5 * ($u as f64).abs().max(1.0);
                let (mut plus, mut minus) = (build(), build());
                plus.$input += h;
                minus.$input -= h;
                du.set_column(j, &((lambda(&plus, &q, &qd, t) - lambda(&minus, &q, &qd, t)) / (2.0 * h)));
                j += 1;
            )*
            let central = error(&jac.dq, &dq).max(error(&jac.dqd, &dqd)).max(if NU > 0 { error(&jac.du, &du) } else { 0.0 });
            let dual_lambda = |s: &$model<Dual64>, q: SVector<Dual64, $n>, qd: SVector<Dual64, $n>| {
                let l = Multipliers::<Dual64, $n, $k>::constraint_multipliers(s, &State::new(Dual64::from(t), q, qd))
                    .expect(concat!(stringify!($model), ": dual multipliers"));
                SVector::<f64, $k>::from_fn(|i, _| l[i].eps)
            };
            let lift = |v: &SVector<f64, $n>, seed: Option<usize>| {
                SVector::<Dual64, $n>::from_fn(|i, _| if Some(i) == seed { Dual64::new(v[i], 1.0) } else { Dual64::from(v[i]) })
            };
            let plain = build_dual(None);
            let mut dual = 0.0f64;
            for c in 0..$n {
                let col = dual_lambda(&plain, lift(&q, Some(c)), lift(&qd, None));
                dual = dual.max(error(&jac.dq.column(c).into_owned(), &col));
                let col = dual_lambda(&plain, lift(&q, None), lift(&qd, Some(c)));
                dual = dual.max(error(&jac.dqd.column(c).into_owned(), &col));
            }
            for c in 0..NU {
                let col = dual_lambda(&build_dual(Some(c)), lift(&q, None), lift(&qd, None));
                dual = dual.max(error(&jac.du.column(c).into_owned(), &col));
            }
            println!("{:<24} seed {seed}: central differences {central:.1e}, dual numbers {dual:.1e}", stringify!($model));
            assert!(central < 1e-6, "{}: {central:e} against central differences", stringify!($model));
            assert!(dual < 1e-11, "{}: {dual:e} against dual numbers", stringify!($model));
            $worst = f64::max($worst, dual);
        }
    }};
}

#[test]
fn multiplier_jacobians_agree_with_central_differences_and_dual_numbers() {
    let mut worst = 0.0f64;
    check_multipliers!(worst, Appell, 3, 1, [9.81, 0.7], []);
    check_multipliers!(worst, SphericalPendulum, 3, 1, [1.5, 9.81, 1.2], []);
    check_multipliers!(worst, DoublePendulum, 4, 2, [1.0, 2.0, 1.0, 0.8, 9.81], []);
    check_multipliers!(worst, BeadOnRotatingHoop, 3, 2, [0.5, 9.81, 1.0, 2.0], []);
    check_multipliers!(
        worst,
        ChaplyginSleigh,
        3,
        1,
        [2.0, 0.4, 0.3, 0.0],
        [torque = 0.6]
    );
    check_multipliers!(
        worst,
        TwoLinkArmOnLine,
        2,
        1,
        [1.0, 0.5, 1.0, 1.0, 9.81, 0.5],
        []
    );
    check_multipliers!(
        worst,
        CartPoleCartesian,
        3,
        1,
        [1.0, 0.3, 0.8, 9.81, 0.0],
        [push = -0.6]
    );
    check_multipliers!(worst, RigidBodyQuaternion, 4, 1, [1.0, 2.0, 3.0], []);
    check_multipliers!(worst, HeavyTop, 4, 1, [1.0, 2.0, 1.0, 9.81, 0.5], []);
    check_multipliers!(worst, RollingDisk, 5, 2, [1.0, 0.5, 0.06, 0.12, 9.81], []);
    check_multipliers!(worst, PinnedTop, 7, 4, [0.8, 0.3, 2.0, 0.4], []);
    println!("largest difference from dual numbers over all models: {worst:.1e}");
}

/// Three rows on a double pendulum's two degrees of freedom: `λ` is not
/// unique, and its derivative is not given.
#[test]
fn a_redundant_set_has_no_multiplier_jacobian() {
    let system = RedundantDoublePendulum::<f64>::new(1.0, 2.0, 1.0, 0.8, 9.81);
    let x = consistent::<_, 4, 3>(&system, 1);
    assert_eq!(
        system.multiplier_jacobian(&x.q, &x.qd, x.t).err(),
        Some(DynamicsError::NotDifferentiable)
    );
}
