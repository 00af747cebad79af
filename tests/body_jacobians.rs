//! The Jacobian of `q̈` of trees of bodies (two long ones, whose tangent
//! systems contract the derivatives of the recursions' `M q̈` rather than
//! `∂M` entry by entry, in the directional and the per-column form):
//! against dual numbers through
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

constrained::constrained_system! {
    /// Sixteen joints on axes and frames turned every way, driven at each:
    /// long enough for the tangents to differentiate the recursions' `M q̈`
    /// (`PRODUCTS_FROM`), and dense enough in `q` for the directional form.
    pub struct TwistedChain {
        inputs: [u1, u2, u3, u4, u5, u6, u7, u8, u9, u10, u11, u12, u13, u14, u15, u16],
        bodies: [
            l0 {
                joint: revolute(q1, [0.0, 0.0, 1.0]),
                xyz: [0.05, -0.03, 0.10],
                rpy: [0.0, 0.0, 0.0],
                mass: 1.60,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l1 {
                parent: l0,
                joint: revolute(q2, [0.0, 1.0, 0.0]),
                xyz: [0.05, -0.03, 0.11],
                rpy: [0.3, -0.2, 0.1],
                mass: 1.55,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l2 {
                parent: l1,
                joint: revolute(q3, [0.6, 0.0, 0.8]),
                xyz: [0.05, -0.03, 0.12],
                rpy: [-0.4, 0.25, 0.2],
                mass: 1.50,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l3 {
                parent: l2,
                joint: revolute(q4, [0.0, 0.8, 0.6]),
                xyz: [0.05, -0.03, 0.13],
                rpy: [0.15, 0.35, -0.3],
                mass: 1.45,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l4 {
                parent: l3,
                joint: revolute(q5, [1.0, 0.0, 0.0]),
                xyz: [0.05, -0.03, 0.14],
                rpy: [0.2, -0.1, 0.45],
                mass: 1.40,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l5 {
                parent: l4,
                joint: revolute(q6, [0.0, 0.6, 0.8]),
                xyz: [0.05, -0.03, 0.15],
                rpy: [-0.3, 0.2, 0.1],
                mass: 1.35,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l6 {
                parent: l5,
                joint: revolute(q7, [0.8, 0.6, 0.0]),
                xyz: [0.05, -0.03, 0.16],
                rpy: [0.1, 0.3, -0.2],
                mass: 1.30,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l7 {
                parent: l6,
                joint: revolute(q8, [0.0, 0.0, 1.0]),
                xyz: [0.05, -0.03, 0.17],
                rpy: [0.25, -0.15, 0.05],
                mass: 1.25,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l8 {
                parent: l7,
                joint: revolute(q9, [0.0, 0.0, 1.0]),
                xyz: [0.05, -0.03, 0.18],
                rpy: [0.0, 0.0, 0.0],
                mass: 1.20,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l9 {
                parent: l8,
                joint: revolute(q10, [0.0, 1.0, 0.0]),
                xyz: [0.05, -0.03, 0.19],
                rpy: [0.3, -0.2, 0.1],
                mass: 1.15,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l10 {
                parent: l9,
                joint: revolute(q11, [0.6, 0.0, 0.8]),
                xyz: [0.05, -0.03, 0.20],
                rpy: [-0.4, 0.25, 0.2],
                mass: 1.10,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l11 {
                parent: l10,
                joint: revolute(q12, [0.0, 0.8, 0.6]),
                xyz: [0.05, -0.03, 0.21],
                rpy: [0.15, 0.35, -0.3],
                mass: 1.05,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l12 {
                parent: l11,
                joint: revolute(q13, [1.0, 0.0, 0.0]),
                xyz: [0.05, -0.03, 0.22],
                rpy: [0.2, -0.1, 0.45],
                mass: 1.00,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l13 {
                parent: l12,
                joint: revolute(q14, [0.0, 0.6, 0.8]),
                xyz: [0.05, -0.03, 0.23],
                rpy: [-0.3, 0.2, 0.1],
                mass: 0.95,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l14 {
                parent: l13,
                joint: revolute(q15, [0.8, 0.6, 0.0]),
                xyz: [0.05, -0.03, 0.24],
                rpy: [0.1, 0.3, -0.2],
                mass: 0.90,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
            l15 {
                parent: l14,
                joint: revolute(q16, [0.0, 0.0, 1.0]),
                xyz: [0.05, -0.03, 0.25],
                rpy: [0.25, -0.15, 0.05],
                mass: 0.85,
                com: [0.02, 0.01, 0.05],
                inertia: [[0.02, 0.001, -0.002], [0.001, 0.025, 0.0015], [-0.002, 0.0015, 0.015]],
            },
        ],
        forces: [u1, u2, u3, u4, u5, u6, u7, u8, u9, u10, u11, u12, u13, u14, u15, u16],
    }
}

constrained::constrained_system! {
    /// Four arms of four joints on a fixed base, axes along the body's
    /// own: sixteen coordinates, so the tangents differentiate the
    /// recursions' `M q̈`, and sparse, so they take the per-column form.
    /// A torque at each joint, three of them scaled: `∂q̈/∂u` is `M⁻¹`'s
    /// columns, which the Jacobian reads from `M⁻¹` formed block by block.
    /// With `inverse_dynamics`' derivatives, written in place (sixteen
    /// coordinates).
    pub struct FourArms {
        inputs: [u1, u2, u3, u4, u5, u6, u7, u8, u9, u10, u11, u12, u13, u14, u15, u16],
        bodies: [
            a0l0 { joint: revolute(q1, [0.0, 0.0, 1.0]), xyz: [0.2, 0.0, 0.0], mass: 0.8, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a0l1 { parent: a0l0, joint: revolute(q2, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.7, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a0l2 { parent: a0l1, joint: revolute(q3, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.6, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a0l3 { parent: a0l2, joint: revolute(q4, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.5, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a1l0 { joint: revolute(q5, [0.0, 0.0, 1.0]), xyz: [-0.2, 0.0, 0.0], mass: 0.8, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a1l1 { parent: a1l0, joint: revolute(q6, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.7, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a1l2 { parent: a1l1, joint: revolute(q7, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.6, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a1l3 { parent: a1l2, joint: revolute(q8, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.5, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a2l0 { joint: revolute(q9, [0.0, 0.0, 1.0]), xyz: [0.0, 0.2, 0.0], mass: 0.8, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a2l1 { parent: a2l0, joint: revolute(q10, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.7, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a2l2 { parent: a2l1, joint: revolute(q11, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.6, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a2l3 { parent: a2l2, joint: revolute(q12, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.5, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a3l0 { joint: revolute(q13, [0.0, 0.0, 1.0]), xyz: [0.0, -0.2, 0.0], mass: 0.8, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a3l1 { parent: a3l0, joint: revolute(q14, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.7, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a3l2 { parent: a3l1, joint: revolute(q15, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.6, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
            a3l3 { parent: a3l2, joint: revolute(q16, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, 0.15], mass: 0.5, com: [0.0, 0.0, 0.07], inertia: diag[0.004, 0.004, 0.002] },
        ],
        forces: [u1, -u2, 2.5 * u3, u4, u5, u6, u7, u8, u9, u10, u11, u12, u13, u14, u15, -0.5 * u16],
        derivatives: [inverse_dynamics],
    }
}

constrained::constrained_system! {
    /// A torso on two waist joints carrying two arms of seven joints, on a
    /// fixed base, a torque at each joint: one block of `M`, in which an
    /// arm joint's column of `∂τ` is zero in the other arm's rows, so the
    /// Jacobian's products with `M⁻¹` group the columns by those patterns
    /// (the waist's, each arm's) rather than by the block.
    pub struct TwoArmedTorso {
        inputs: [u1, u2, u3, u4, u5, u6, u7, u8, u9, u10, u11, u12, u13, u14, u15, u16],
        bodies: [
            waist { joint: revolute(q1, [0.0, 0.0, 1.0]), xyz: [0.0, 0.0, 0.8], mass: 4.0, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            torso { parent: waist, joint: revolute(q2, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.1], mass: 6.0, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            l1 { parent: torso, joint: revolute(q3, [0.0, 1.0, 0.0]), xyz: [0.0, 0.18, 0.3], mass: 0.9, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            l2 { parent: l1, joint: revolute(q4, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, -0.12], mass: 0.8, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            l3 { parent: l2, joint: revolute(q5, [0.0, 0.0, 1.0]), xyz: [0.0, 0.0, -0.12], mass: 0.7, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            l4 { parent: l3, joint: revolute(q6, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, -0.12], mass: 0.6, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            l5 { parent: l4, joint: revolute(q7, [0.0, 0.0, 1.0]), xyz: [0.0, 0.0, -0.12], mass: 0.5, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            l6 { parent: l5, joint: revolute(q8, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, -0.12], mass: 0.4, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            l7 { parent: l6, joint: revolute(q9, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, -0.12], mass: 0.3, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            r1 { parent: torso, joint: revolute(q10, [0.0, 1.0, 0.0]), xyz: [0.0, -0.18, 0.3], mass: 0.9, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            r2 { parent: r1, joint: revolute(q11, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, -0.12], mass: 0.8, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            r3 { parent: r2, joint: revolute(q12, [0.0, 0.0, 1.0]), xyz: [0.0, 0.0, -0.12], mass: 0.7, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            r4 { parent: r3, joint: revolute(q13, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, -0.12], mass: 0.6, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            r5 { parent: r4, joint: revolute(q14, [0.0, 0.0, 1.0]), xyz: [0.0, 0.0, -0.12], mass: 0.5, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            r6 { parent: r5, joint: revolute(q15, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, -0.12], mass: 0.4, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
            r7 { parent: r6, joint: revolute(q16, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, -0.12], mass: 0.3, com: [0.0, 0.0, 0.06], inertia: diag[0.003, 0.003, 0.0015] },
        ],
        forces: [u1, u2, u3, u4, u5, u6, u7, u8, u9, u10, u11, u12, u13, u14, u15, u16],
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

/// `$system::new(u[0], …, u[15])`: the sixteen inputs of a system of
/// sixteen torques, on any scalar.
macro_rules! sixteen {
    ($system:ty, $u:expr) => {{
        let u = $u;
        <$system>::new(
            u[0], u[1], u[2], u[3], u[4], u[5], u[6], u[7], u[8], u[9], u[10], u[11], u[12], u[13],
            u[14], u[15],
        )
    }};
}

#[test]
fn tree_jacobians_agree_with_dual_numbers_and_differences() {
    let d = Dual64::from;
    let u: [f64; 16] = std::array::from_fn(|k| 0.1 * (k as f64) - 0.7);
    agrees!(
        "twisted chain (products, directional)",
        sixteen!(TwistedChain<f64>, u),
        sixteen!(TwistedChain<Dual64>, u.map(Dual64::from)),
        16,
        0,
        23
    );
    agrees!(
        "four arms (products, per column)",
        sixteen!(FourArms<f64>, u),
        sixteen!(FourArms<Dual64>, u.map(Dual64::from)),
        16,
        0,
        29
    );
    agrees!(
        "torso with two arms (products, per column, a pattern per arm)",
        sixteen!(TwoArmedTorso<f64>, u),
        sixteen!(TwoArmedTorso<Dual64>, u.map(Dual64::from)),
        16,
        0,
        37
    );
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

/// Where a torque drives each joint, `∂q̈/∂u = M⁻¹ B` (`B` the torques'
/// constant factors): the generated Jacobian's `du`, which reads its
/// columns from `M⁻¹` formed block by block from the factors, against
/// nalgebra's inverse of the generated `M`, at ten random states.
#[test]
fn torque_columns_are_the_inverse_mass_matrix_scaled() {
    let u: [f64; 16] = std::array::from_fn(|k| 0.2 - 0.05 * (k as f64));
    let arms = sixteen!(FourArms<f64>, u);
    let mut factors = [1.0; 16];
    (factors[1], factors[2], factors[15]) = (-1.0, 2.5, -0.5);
    let b = SMatrix::<f64, 16, 16>::from_diagonal(&SVector::from(factors));
    let mut next = numbers(31);
    let mut worst = 0.0f64;
    for _ in 0..10 {
        let q = SVector::<f64, 16>::from_fn(|_, _| next() * 0.6);
        let qd = SVector::<f64, 16>::from_fn(|_, _| next());
        let jac = arms
            .try_acceleration_jacobian(&q, &qd, 0.0)
            .expect("the Jacobian");
        let m = arms.mass_matrix(&q, 0.0);
        let expected = m.try_inverse().expect("M is invertible") * b;
        worst = worst.max(relative(&jac.du, &expected));
    }
    println!("four arms: ∂q̈/∂u against M⁻¹ B {worst:.1e}");
    assert!(worst <= 1e-12, "∂q̈/∂u is {worst:e} from M⁻¹ B");
}

/// `acceleration_jacobian_to` writes every entry itself: into an output
/// that holds an earlier answer's leftovers (NaN in every entry here) it
/// writes, bit for bit, what `try_acceleration_jacobian` returns, at ten
/// random states. Across the solves that write in place: straight-line
/// columns with and without rows, structurally zero columns, the
/// per-column loop whose torque columns are read from `M⁻¹`, the
/// directional loop, and a floating base's velocity form (its saddle
/// point, and the legs' solve of a leg whose foot is held), which `_to`
/// runs for `∂q̈` alone.
#[test]
fn the_jacobian_written_into_a_used_output_is_the_returned_one() {
    use constrained::models::{CartPole, DoublePendulumAngles, ParallelogramFourBarAngles};
    use constrained::Jacobians;
    macro_rules! same {
        ($name:literal, $system:expr, $n:literal, $nu:literal, $seed:literal) => {{
            let system = $system;
            let mut next = numbers($seed);
            let mut out = Jacobians::<f64, $n, $nu>::zeros();
            for _ in 0..10 {
                let q = SVector::<f64, $n>::from_fn(|_, _| next() * 0.6);
                let qd = SVector::<f64, $n>::from_fn(|_, _| next());
                let value = system
                    .try_acceleration_jacobian(&q, &qd, 0.0)
                    .expect(concat!($name, ": the Jacobian"));
                out.dq.fill(f64::NAN);
                out.dqd.fill(f64::NAN);
                out.du.fill(f64::NAN);
                system
                    .acceleration_jacobian_to(&q, &qd, 0.0, &mut out)
                    .expect(concat!($name, ": the Jacobian written into `out`"));
                let bits = |j: &Jacobians<f64, $n, $nu>| {
                    (j.dq.iter().chain(j.dqd.iter()).chain(j.du.iter()))
                        .map(|x| x.to_bits())
                        .collect::<Vec<_>>()
                };
                assert_eq!(bits(&out), bits(&value), "{}", $name);
            }
        }};
    }
    let u: [f64; 16] = std::array::from_fn(|k| 0.1 * (k as f64) - 0.7);
    same!(
        "cart-pole",
        CartPole::<f64>::new(1.0, 0.3, 0.8, 9.81, 0.5),
        2,
        1,
        41
    );
    same!(
        "double pendulum",
        DoublePendulumAngles::<f64>::new(1.0, 0.7, 1.1, 0.9, 9.81),
        2,
        0,
        43
    );
    same!(
        "four-bar in link angles",
        ParallelogramFourBarAngles::<f64>::new(1.0, 0.1, 1.0, 2.0, 9.81),
        3,
        0,
        47
    );
    same!("twisted chain", sixteen!(TwistedChain<f64>, u), 16, 16, 53);
    same!("four arms", sixteen!(FourArms<f64>, u), 16, 16, 59);
    same!(
        "torso with two arms",
        sixteen!(TwoArmedTorso<f64>, u),
        16,
        16,
        61
    );
    same!("driven arm", DrivenArm::<f64>::new(0.7, -0.4), 4, 2, 67);
    same!("Panda", PandaTool::<f64>::new(), 7, 0, 71);
    same!("floating leg", FloatingLeg::<f64>::new(), 8, 0, 73);
    same!(
        "one leg, foot held",
        OnWorld::<f64>::new(0.19, 0.15, 0.4, -0.3, 0.2),
        10,
        3,
        79
    );
}

/// `acceleration_and_multiplier_jacobians_to` likewise: into outputs
/// filled with NaN it writes, bit for bit, what
/// `acceleration_and_multiplier_jacobians` returns, at ten random states,
/// where the velocity form solves the tangent systems in place (the legs'
/// solve, a floating base's saddle point) and where the runtime solves them.
#[test]
fn the_multiplier_jacobians_written_into_used_outputs_are_the_returned_ones() {
    use constrained::linearize::MultiplierJacobians;
    use constrained::models::ParallelogramFourBarAngles;
    use constrained::Jacobians;
    macro_rules! same {
        ($name:literal, $system:expr, $n:literal, $k:literal, $nu:literal, $seed:literal) => {{
            let system = $system;
            let mut next = numbers($seed);
            let mut out = Jacobians::<f64, $n, $nu>::zeros();
            let mut lambdas = MultiplierJacobians::<f64, $n, $k, $nu>::zeros();
            for _ in 0..10 {
                let q = SVector::<f64, $n>::from_fn(|_, _| next() * 0.6);
                let qd = SVector::<f64, $n>::from_fn(|_, _| next());
                let (jac, lj) = system
                    .acceleration_and_multiplier_jacobians(&q, &qd, 0.0)
                    .expect(concat!($name, ": the Jacobians"));
                out.dq.fill(f64::NAN);
                out.dqd.fill(f64::NAN);
                out.du.fill(f64::NAN);
                lambdas.dq.fill(f64::NAN);
                lambdas.dqd.fill(f64::NAN);
                lambdas.du.fill(f64::NAN);
                system
                    .acceleration_and_multiplier_jacobians_to(&q, &qd, 0.0, &mut out, &mut lambdas)
                    .expect(concat!($name, ": the Jacobians written into the outputs"));
                let bits = |j: &Jacobians<f64, $n, $nu>,
                            l: &MultiplierJacobians<f64, $n, $k, $nu>| {
                    (j.dq.iter().chain(j.dqd.iter()).chain(j.du.iter()))
                        .chain(l.dq.iter().chain(l.dqd.iter()).chain(l.du.iter()))
                        .map(|x| x.to_bits())
                        .collect::<Vec<_>>()
                };
                assert_eq!(bits(&out, &lambdas), bits(&jac, &lj), "{}", $name);
            }
        }};
    }
    same!(
        "one leg, foot held",
        OnWorld::<f64>::new(0.19, 0.15, 0.4, -0.3, 0.2),
        10,
        4,
        3,
        83
    );
    same!("floating leg", FloatingLeg::<f64>::new(), 8, 1, 0, 89);
    same!(
        "four-bar in link angles",
        ParallelogramFourBarAngles::<f64>::new(1.0, 0.1, 1.0, 2.0, 9.81),
        3,
        2,
        0,
        97
    );
}
