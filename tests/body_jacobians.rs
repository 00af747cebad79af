//! The Jacobian of `q̈` of trees of bodies: against dual numbers through
//! the same generated `acceleration` (to 1e-12) and central differences
//! (to 1e-6), on an arm of revolute, prismatic and fixed joints (alone, and
//! driven with a frame and `inverse_dynamics`' derivatives, as the peers'
//! robots are written), the Panda from its URDF, a floating base (a
//! quaternion, solved through its auxiliary mass) and a trunk on one leg
//! whose foot is held (the legs' solve).

use crate::frames::{numbers, three_link_arm, FloatingLeg, FramedArm, PandaTool};
use crate::free_base::OnWorld;
use constrained::nalgebra::{SMatrix, SVector};
use constrained::{ConstrainedSystem, State};
use num_dual::Dual64;

three_link_arm! {
    /// The arm driven at its shoulder and slider, with a frame and
    /// `inverse_dynamics`' derivatives, as the peers' robots are written.
    DrivenArm {
        inputs: [u1, u2],
        forces: [u1, 0.0, 0.0, u2],
        frames: [hand { body: slider }],
        derivatives: [inverse_dynamics],
    }
}

/// `‖a − b‖∞` against the scale of `b` (at least 1).
fn relative<const N: usize>(a: &SMatrix<f64, N, N>, b: &SMatrix<f64, N, N>) -> f64 {
    (a - b).amax() / b.amax().max(1.0)
}

/// `(∂q̈/∂q, ∂q̈/∂q̇)` by dual numbers: the generated `acceleration` run on
/// `Dual64`, one seeded coordinate or rate per column.
fn dual<S, const N: usize, const K: usize>(
    system: &S,
    state: &State<f64, N>,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>)
where
    S: ConstrainedSystem<Dual64, N, K>,
{
    let lift = |v: &SVector<f64, N>, seed: Option<usize>| {
        SVector::<Dual64, N>::from_fn(|i, _| {
            Dual64::new(v[i], f64::from(u8::from(seed == Some(i))))
        })
    };
    let column = |q, qd| {
        let at = State::new(Dual64::from(state.t), q, qd);
        let a = system.acceleration(&at).expect("a dual q̈");
        SVector::<f64, N>::from_fn(|i, _| a[i].eps)
    };
    let (mut dq, mut dqd) = (SMatrix::<f64, N, N>::zeros(), SMatrix::<f64, N, N>::zeros());
    for c in 0..N {
        dq.set_column(c, &column(lift(&state.q, Some(c)), lift(&state.qd, None)));
        dqd.set_column(c, &column(lift(&state.q, None), lift(&state.qd, Some(c))));
    }
    (dq, dqd)
}

/// `(∂q̈/∂q, ∂q̈/∂q̇)` by central differences of `acceleration`.
fn central<S, const N: usize, const K: usize>(
    system: &S,
    state: &State<f64, N>,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>)
where
    S: ConstrainedSystem<f64, N, K>,
{
    let acc = |q, qd| system.acceleration(&State::new(state.t, q, qd)).expect("q̈");
    let (mut dq, mut dqd) = (SMatrix::<f64, N, N>::zeros(), SMatrix::<f64, N, N>::zeros());
    let h = 1e-6;
    for c in 0..N {
        let step = SVector::<f64, N>::from_fn(|i, _| if i == c { h } else { 0.0 });
        let (q, qd) = (state.q, state.qd);
        dq.set_column(c, &((acc(q + step, qd) - acc(q - step, qd)) / (2.0 * h)));
        dqd.set_column(c, &((acc(q, qd + step) - acc(q, qd - step)) / (2.0 * h)));
    }
    (dq, dqd)
}

/// The generated Jacobian of `$plain` at ten random states against dual
/// numbers through `$dual` (the same system on `Dual64`) and differences.
macro_rules! agrees {
    ($name:literal, $plain:expr, $dual:expr, $n:literal, $k:literal, $seed:literal) => {{
        let (plain, on_duals) = ($plain, $dual);
        let mut next = numbers($seed);
        let (mut exact, mut differences) = (0.0f64, 0.0f64);
        for _ in 0..10 {
            let q = SVector::<f64, $n>::from_fn(|_, _| next() * 0.6);
            let qd = SVector::<f64, $n>::from_fn(|_, _| next());
            let state = State::new(0.0, q, qd);
            let jac = plain
                .try_acceleration_jacobian(&q, &qd, 0.0)
                .expect(concat!($name, ": the Jacobian"));
            let (dq, dqd) = dual::<_, $n, $k>(&on_duals, &state);
            exact = exact
                .max(relative(&jac.dq, &dq))
                .max(relative(&jac.dqd, &dqd));
            let (dq, dqd) = central::<_, $n, $k>(&plain, &state);
            differences = differences
                .max(relative(&jac.dq, &dq))
                .max(relative(&jac.dqd, &dqd));
        }
        println!(
            "{}: dual numbers {exact:.1e}, central differences {differences:.1e}",
            $name
        );
        assert!(exact <= 1e-12, "{}: {exact:e} from dual numbers", $name);
        assert!(
            differences <= 1e-6,
            "{}: {differences:e} from differences",
            $name
        );
    }};
}

#[test]
fn tree_jacobians_agree_with_dual_numbers_and_differences() {
    let d = Dual64::from;
    agrees!(
        "driven arm",
        DrivenArm::<f64>::new(0.7, -0.4),
        DrivenArm::<Dual64>::new(d(0.7), d(-0.4)),
        4,
        0,
        13
    );
    agrees!(
        "arm",
        FramedArm::<f64>::new(),
        FramedArm::<Dual64>::new(),
        4,
        0,
        3
    );
    agrees!(
        "Panda",
        PandaTool::<f64>::new(),
        PandaTool::<Dual64>::new(),
        7,
        0,
        5
    );
    agrees!(
        "floating leg",
        FloatingLeg::<f64>::new(),
        FloatingLeg::<Dual64>::new(),
        8,
        1,
        7
    );
    agrees!(
        "one leg, foot held",
        OnWorld::<f64>::new(0.19, 0.15, 0.4, -0.3, 0.2),
        OnWorld::<Dual64>::new(d(0.19), d(0.15), d(0.4), d(-0.3), d(0.2)),
        10,
        4,
        11
    );
}
