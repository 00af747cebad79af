//! The centroidal momentum (`centroidal_map`, `centroidal_map_bias`,
//! `center_of_mass_velocity`) and the derivatives of inverse dynamics
//! (`inverse_dynamics_jacobian`) against truths that do not use them:
//! `A_G q̇` against each body's momentum written here from its frame's
//! twist and its inertia as the DSL gives it; on a free base, against the
//! generalized momentum `M q̇`, whose base rows are the total linear
//! momentum and, through the quaternion's rates, the angular momentum about
//! the base; on the Panda, its linear rows against the URDF's masses times
//! the centre of mass's velocity and its vertical angular momentum against
//! the first joint's generalized momentum; `Ȧ_G q̇` against central
//! differences of `A_G q̇` along a trajectory; `∂τ/∂q` and `∂τ/∂q̇` against
//! central differences of `inverse_dynamics`, and on a planar two-link arm
//! against its Coriolis, centrifugal and gravity terms written by hand.

use crate::body_jacobians::FourArms;
use crate::frames::{numbers, relative, states, three_link_arm, FloatingLeg, FramedArm, PandaTool};
use constrained::constrained_system;
use constrained::nalgebra::{Matrix3, Quaternion, SMatrix, SVector, UnitQuaternion, Vector3};

three_link_arm! {
    /// The arm of `frames.rs` with a frame at each body's origin, so that
    /// each body's momentum can be written from its frame's twist.
    MomentumArm {
        frames: [
            at_base { body: base },
            at_upper { body: upper },
            at_fore { body: fore },
            at_tool { body: tool },
            at_slider { body: slider },
        ],
    }
}

constrained_system! {
    /// A planar two-link arm turning about `z`, gravity along `−y`: the
    /// textbook's `M`, Coriolis and gravity terms in closed form.
    pub struct PlanarPair {
        gravity: [0.0, -9.81, 0.0],
        bodies: [
            link1 {
                joint: revolute(q1, [0.0, 0.0, 1.0]),
                mass: 1.3,
                com: [0.4, 0.0, 0.0],
                inertia: diag[0.01, 0.02, 0.07],
            },
            link2 {
                parent: link1,
                joint: revolute(q2, [0.0, 0.0, 1.0]),
                xyz: [0.9, 0.0, 0.0],
                mass: 0.8,
                com: [0.35, 0.0, 0.0],
                inertia: diag[0.005, 0.03, 0.05],
            },
        ],
        derivatives: [inverse_dynamics],
    }
}

type V<const N: usize> = SVector<f64, N>;

/// `[P; L_G]` of the arm from its bodies: each body's mass, centre of mass
/// and inertia about it as `MomentumArm` writes them, its placement and
/// twist from its frame's methods (checked against differences and a hand
/// derivation in `frames.rs`), the centre of mass summed here.
fn arm_momentum(arm: &MomentumArm<f64>, q: &V<4>, qd: &V<4>) -> V<6> {
    type Frame = (Matrix3<f64>, Vector3<f64>, V<6>);
    let frames: [Frame; 5] = [
        (
            arm.at_base_placement(q, 0.0),
            arm.at_base_velocity(q, qd, 0.0),
        ),
        (
            arm.at_upper_placement(q, 0.0),
            arm.at_upper_velocity(q, qd, 0.0),
        ),
        (
            arm.at_fore_placement(q, 0.0),
            arm.at_fore_velocity(q, qd, 0.0),
        ),
        (
            arm.at_tool_placement(q, 0.0),
            arm.at_tool_velocity(q, qd, 0.0),
        ),
        (
            arm.at_slider_placement(q, 0.0),
            arm.at_slider_velocity(q, qd, 0.0),
        ),
    ]
    .map(|((r, p), twist)| (r, p, twist));
    let inertias: [(f64, Vector3<f64>, [f64; 3]); 5] = [
        (2.0, Vector3::new(0.0, 0.0, 0.2), [0.05, 0.06, 0.03]),
        (1.5, Vector3::new(0.25, 0.0, 0.0), [0.01, 0.04, 0.045]),
        (1.0, Vector3::new(0.2, 0.0, 0.0), [0.005, 0.02, 0.021]),
        (0.2, Vector3::new(0.0, 0.0, 0.05), [0.001, 0.002, 0.003]),
        (0.5, Vector3::zeros(), [0.0004, 0.0005, 0.0006]),
    ];
    // Each body's centre of mass and its velocity, world axes.
    let points: Vec<(f64, Vector3<f64>, Vector3<f64>)> = frames
        .iter()
        .zip(&inertias)
        .map(|((r, p, twist), (m, com, _))| {
            let (v, w) = (twist.fixed_rows::<3>(0), twist.fixed_rows::<3>(3));
            let arm_ = r * com;
            (*m, p + arm_, v + w.cross(&arm_))
        })
        .collect();
    let total: f64 = points.iter().map(|(m, _, _)| m).sum();
    let c = points
        .iter()
        .fold(Vector3::zeros(), |s, (m, ci, _)| s + ci * *m)
        / total;
    let (mut linear, mut angular) = (Vector3::zeros(), Vector3::zeros());
    for (((r, _, twist), (_, _, diag)), (m, ci, vi)) in frames.iter().zip(&inertias).zip(&points) {
        let w: Vector3<f64> = twist.fixed_rows::<3>(3).into();
        let about_com = r * Matrix3::from_diagonal(&Vector3::from(*diag)) * r.transpose();
        linear += vi * *m;
        angular += about_com * w + (ci - c).cross(&(vi * *m));
    }
    V::<6>::from_iterator(linear.iter().chain(angular.iter()).copied())
}

#[test]
fn arm_centroidal_momentum_equals_the_sum_of_the_bodies_momenta() {
    let arm = MomentumArm::<f64>::new();
    let (mut momentum, mut linear) = (0.0_f64, 0.0_f64);
    for (q, qd) in states::<4>(41) {
        let h = arm.centroidal_map(&q, 0.0) * qd;
        momentum = momentum.max(relative(&h, &arm_momentum(&arm, &q, &qd)));
        // P = m ċ, the centre of mass's velocity its Jacobian's.
        let cd = arm.center_of_mass_velocity(&q, &qd, 0.0);
        let jc = arm.center_of_mass_jacobian(&q, 0.0) * qd;
        linear = linear.max(relative(&cd, &jc));
        let p: Vector3<f64> = h.fixed_rows::<3>(0).into();
        linear = linear.max(relative(&p, &(cd * 5.2)));
    }
    println!(
        "arm: A_G q̇ within {momentum:.1e} of the bodies' momenta, P within {linear:.1e} of m ċ"
    );
    assert!(momentum <= 1e-14 && linear <= 1e-14, "{momentum} {linear}");
}

/// The worst relative disagreement over `states` of `A_G q̈ + Ȧ_G q̇` with
/// central differences of `A_G(q(t)) q̇(t)` along `q(t) = q + q̇ t + ½ q̈ t²`.
fn rate_of_momentum<const N: usize>(
    map: impl Fn(&V<N>) -> SMatrix<f64, 6, N>,
    bias: impl Fn(&V<N>, &V<N>) -> V<6>,
    seed: u64,
) -> f64 {
    let mut next = numbers(seed);
    let mut worst: f64 = 0.0;
    let h = 1e-5;
    for (q, qd) in states::<N>(seed) {
        let qdd = V::<N>::from_fn(|_, _| next());
        let along = |t: f64| map(&(q + qd * t + qdd * (t * t / 2.0))) * (qd + qdd * t);
        let differenced = (along(h) - along(-h)) / (2.0 * h);
        let exact = map(&q) * qdd + bias(&q, &qd);
        worst = worst.max(relative(&exact, &differenced));
    }
    worst
}

#[test]
fn centroidal_bias_agrees_with_the_rate_of_the_momentum() {
    let arm = FramedArm::<f64>::new();
    let on_arm = rate_of_momentum(
        |q| arm.centroidal_map(q, 0.0),
        |q, qd| arm.centroidal_map_bias(q, qd, 0.0),
        43,
    );
    let leg = FloatingLeg::<f64>::new();
    let on_leg = rate_of_momentum(
        |q| leg.centroidal_map(q, 0.0),
        |q, qd| leg.centroidal_map_bias(q, qd, 0.0),
        47,
    );
    let panda = PandaTool::<f64>::new();
    let on_panda = rate_of_momentum(
        |q| panda.centroidal_map(q, 0.0),
        |q, qd| panda.centroidal_map_bias(q, qd, 0.0),
        53,
    );
    println!("Ȧ_G q̇: within {on_arm:.1e} (arm), {on_leg:.1e} (floating leg), {on_panda:.1e} (panda) of differences");
    assert!(
        on_arm <= 1e-8 && on_leg <= 1e-8 && on_panda <= 1e-8,
        "{on_arm} {on_leg} {on_panda}"
    );
}

/// The columns `E` of `ω = 2 E q̇_Q` for a unit quaternion `Q` (world
/// axes): column `j` is the vector part of `eⱼ ⊗ Q*`.
fn rates_to_spin(q: &Quaternion<f64>) -> SMatrix<f64, 3, 4> {
    let conjugate = q.conjugate();
    SMatrix::<f64, 3, 4>::from_fn(|i, j| {
        let mut unit = [0.0; 4];
        unit[j] = 1.0;
        let e = Quaternion::new(unit[0], unit[1], unit[2], unit[3]);
        (e * conjugate).imag()[i]
    })
}

#[test]
fn floating_centroidal_momentum_equals_the_base_rows_of_the_generalized_momentum() {
    use constrained::floating::FreeMotion;
    let leg = FloatingLeg::<f64>::new();
    let mut next = numbers(59);
    let mut worst: f64 = 0.0;
    for _ in 0..10 {
        let base = FreeMotion {
            position: Vector3::from_fn(|_, _| next()),
            orientation: UnitQuaternion::from_euler_angles(next(), next(), next()),
            linear: Vector3::from_fn(|_, _| next()),
            angular: Vector3::from_fn(|_, _| next()),
        };
        let (mut q, mut qd) = (V::<8>::zeros(), V::<8>::zeros());
        base.write(0, &mut q, &mut qd)
            .expect("seven coordinates fit");
        (q[7], qd[7]) = (next(), next());
        // Off the quaternion's tangent too: a radial rate moves nothing.
        for k in 3..7 {
            qd[k] += 0.3 * q[k];
        }
        let p = leg
            .generalized_momentum(&q, &qd, 0.0)
            .expect("finite momentum");
        // ∂T/∂ẋ is the linear momentum, ∂T/∂q̇_Q = 2 Eᵀ L_O about the
        // base's origin, and E Eᵀ = 1 on the unit sphere.
        let linear: Vector3<f64> = p.fixed_rows::<3>(0).into();
        let quaternion = Quaternion::new(q[3], q[4], q[5], q[6]);
        let about_base = rates_to_spin(&quaternion) * p.fixed_rows::<4>(3) / 2.0;
        let c = leg.center_of_mass(&q, 0.0);
        let about_com = about_base - (c - base.position).cross(&linear);
        let expected = V::<6>::from_iterator(linear.iter().chain(about_com.iter()).copied());
        let h = leg.centroidal_map(&q, 0.0) * qd;
        worst = worst.max(relative(&h, &expected));
    }
    println!("floating leg: A_G q̇ within {worst:.1e} of the base rows of M q̇");
    assert!(worst <= 1e-13, "{worst}");
}

/// The Panda's total mass, summed from its URDF file.
fn panda_mass() -> f64 {
    let urdf = include_str!("data/panda_published.urdf");
    urdf.split("<mass value=\"")
        .skip(1)
        .map(|rest| {
            let number = rest.split('"').next().expect("a quoted mass");
            number.parse::<f64>().expect("a number")
        })
        .sum()
}

#[test]
fn panda_centroidal_momentum_agrees_with_its_mass_and_first_joint() {
    let panda = PandaTool::<f64>::new();
    let mass = panda_mass();
    let (mut linear, mut vertical) = (0.0_f64, 0.0_f64);
    for (q, qd) in states::<7>(61) {
        let h = panda.centroidal_map(&q, 0.0) * qd;
        let p: Vector3<f64> = h.fixed_rows::<3>(0).into();
        let cd = panda.center_of_mass_velocity(&q, &qd, 0.0);
        linear = linear.max(relative(&p, &(cd * mass)));
        // The first joint turns every moving body about the world's z axis:
        // its generalized momentum is the z part of the angular momentum
        // about any point of that axis, L_G + c × P.
        let l: Vector3<f64> = h.fixed_rows::<3>(3).into();
        let c = panda.center_of_mass(&q, 0.0);
        let about_axis = (l + c.cross(&p)).z;
        let first = panda
            .generalized_momentum(&q, &qd, 0.0)
            .expect("finite momentum")[0];
        vertical = vertical.max((about_axis - first).abs() / first.abs().max(1.0));
    }
    println!("panda: P within {linear:.1e} of m ċ, L_z about the first axis within {vertical:.1e} of its joint's momentum");
    assert!(linear <= 1e-14 && vertical <= 1e-14, "{linear} {vertical}");
}

/// The worst relative disagreement of `(∂τ/∂q, ∂τ/∂q̇)` with central
/// differences of `τ` over random states and accelerations.
fn inverse_dynamics_differences<const N: usize>(
    tau: impl Fn(&V<N>, &V<N>, &V<N>) -> V<N>,
    jacobian: impl Fn(&V<N>, &V<N>, &V<N>) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>),
    seed: u64,
) -> (f64, f64) {
    let mut next = numbers(seed);
    // Truncation h² and rounding ε/h balance near 1e-5.
    let h = 1e-5;
    let (mut by_q, mut by_qd) = (0.0_f64, 0.0_f64);
    for (q, qd) in states::<N>(seed) {
        let qdd = V::<N>::from_fn(|_, _| next());
        let (dq, dqd) = jacobian(&q, &qd, &qdd);
        let mut fq = SMatrix::<f64, N, N>::zeros();
        let mut fqd = SMatrix::<f64, N, N>::zeros();
        for k in 0..N {
            let e = V::<N>::from_fn(|i, _| if i == k { h } else { 0.0 });
            let col = (tau(&(q + e), &qd, &qdd) - tau(&(q - e), &qd, &qdd)) / (2.0 * h);
            fq.set_column(k, &col);
            let col = (tau(&q, &(qd + e), &qdd) - tau(&q, &(qd - e), &qdd)) / (2.0 * h);
            fqd.set_column(k, &col);
        }
        by_q = by_q.max(relative(&dq, &fq));
        by_qd = by_qd.max(relative(&dqd, &fqd));
    }
    (by_q, by_qd)
}

#[test]
fn inverse_dynamics_jacobian_agrees_with_differences() {
    let arm = FramedArm::<f64>::new();
    let on_arm = inverse_dynamics_differences(
        |q, qd, qdd| arm.inverse_dynamics(q, qd, qdd, 0.0).expect("finite"),
        |q, qd, qdd| {
            arm.inverse_dynamics_jacobian(q, qd, qdd, 0.0)
                .expect("finite")
        },
        67,
    );
    let leg = FloatingLeg::<f64>::new();
    let on_leg = inverse_dynamics_differences(
        |q, qd, qdd| leg.inverse_dynamics(q, qd, qdd, 0.0).expect("finite"),
        |q, qd, qdd| {
            leg.inverse_dynamics_jacobian(q, qd, qdd, 0.0)
                .expect("finite")
        },
        71,
    );
    let panda = PandaTool::<f64>::new();
    let on_panda = inverse_dynamics_differences(
        |q, qd, qdd| panda.inverse_dynamics(q, qd, qdd, 0.0).expect("finite"),
        |q, qd, qdd| {
            panda
                .inverse_dynamics_jacobian(q, qd, qdd, 0.0)
                .expect("finite")
        },
        73,
    );
    // Sixteen coordinates: the pair written in place, through `_to`.
    let arms = four_arms();
    let on_arms = inverse_dynamics_differences(
        |q, qd, qdd| arms.inverse_dynamics(q, qd, qdd, 0.0).expect("finite"),
        |q, qd, qdd| {
            let mut out = (
                SMatrix::from_element(f64::NAN),
                SMatrix::from_element(f64::NAN),
            );
            arms.inverse_dynamics_jacobian_to(q, qd, qdd, 0.0, &mut out)
                .expect("finite");
            out
        },
        79,
    );
    for (name, (a, b)) in [
        ("arm", on_arm),
        ("floating leg", on_leg),
        ("panda", on_panda),
        ("four arms", on_arms),
    ] {
        println!("{name}: ∂τ/∂q within {a:.1e}, ∂τ/∂q̇ within {b:.1e} of differences");
    }
    for (a, b) in [on_arm, on_leg, on_panda, on_arms] {
        assert!(
            a <= 1e-7 && b <= 1e-7,
            "{on_arm:?} {on_leg:?} {on_panda:?} {on_arms:?}"
        );
    }
}

/// The four arms of `body_jacobians`, each joint driven.
fn four_arms() -> FourArms<f64> {
    let u: [f64; 16] = core::array::from_fn(|i| 0.1 * i as f64 - 0.7);
    FourArms::new(
        u[0], u[1], u[2], u[3], u[4], u[5], u[6], u[7], u[8], u[9], u[10], u[11], u[12], u[13],
        u[14], u[15],
    )
}

/// `inverse_dynamics_jacobian_to` writes the method's answer, bit for bit,
/// into every entry of a pair that held anything (here NaN), whether the
/// pair is written in place (the four arms' sixteen coordinates: the
/// structural nonzeros into zeros) or stored from one literal (the
/// Panda's seven); and its `Err` is the method's.
#[test]
fn inverse_dynamics_jacobian_to_writes_the_methods_answer_into_any_pair() {
    fn same<const N: usize>(
        method: Result<(SMatrix<f64, N, N>, SMatrix<f64, N, N>), constrained::DynamicsError>,
        to: impl FnOnce(
            &mut (SMatrix<f64, N, N>, SMatrix<f64, N, N>),
        ) -> Result<(), constrained::DynamicsError>,
    ) {
        let mut out = (
            SMatrix::from_element(f64::NAN),
            SMatrix::from_element(f64::NAN),
        );
        let written = to(&mut out);
        match method {
            Ok((dq, dqd)) => {
                assert_eq!(written, Ok(()));
                for (a, b) in dq
                    .iter()
                    .chain(dqd.iter())
                    .zip(out.0.iter().chain(out.1.iter()))
                {
                    assert_eq!(a.to_bits(), b.to_bits(), "{a} against {b}");
                }
            }
            Err(e) => assert_eq!(written, Err(e)),
        }
    }
    let (arms, panda) = (four_arms(), PandaTool::<f64>::new());
    let mut next = numbers(83);
    for i in 0..12 {
        let [q, qd, qdd] = [(); 3].map(|()| SVector::<f64, 16>::from_fn(|_, _| next()));
        // Some states overflow, so that the `Err` is compared too.
        let qd = if i % 4 == 3 { qd * 1e200 } else { qd };
        assert_eq!(
            arms.inverse_dynamics_jacobian(&q, &qd, &qdd, 0.0).is_err(),
            i % 4 == 3,
            "state {i}"
        );
        same(arms.inverse_dynamics_jacobian(&q, &qd, &qdd, 0.0), |out| {
            arms.inverse_dynamics_jacobian_to(&q, &qd, &qdd, 0.0, out)
        });
        let [q, qd, qdd] = [q, qd, qdd].map(|v| v.fixed_rows::<7>(0).into_owned());
        same(panda.inverse_dynamics_jacobian(&q, &qd, &qdd, 0.0), |out| {
            panda.inverse_dynamics_jacobian_to(&q, &qd, &qdd, 0.0, out)
        });
    }
}

/// `τ`, `∂τ/∂q` and `∂τ/∂q̇` of `PlanarPair` by hand: `M`, `h = m₂ l₁ l_c2
/// sin q₂` for the Coriolis and centrifugal terms, and gravity.
#[allow(clippy::type_complexity)]
fn planar_by_hand(
    q: &V<2>,
    qd: &V<2>,
    qdd: &V<2>,
) -> (V<2>, SMatrix<f64, 2, 2>, SMatrix<f64, 2, 2>) {
    let (m1, m2, l1, lc1, lc2, i1, i2, g) = (1.3, 0.8, 0.9, 0.4, 0.35, 0.07, 0.05, 9.81);
    let (s1, c1) = q[0].sin_cos();
    let (s2, c2) = q[1].sin_cos();
    let (s12, c12) = (q[0] + q[1]).sin_cos();
    let k = m2 * l1 * lc2;
    let m11 = m1 * lc1 * lc1 + i1 + m2 * (l1 * l1 + lc2 * lc2) + i2 + 2.0 * k * c2;
    let m12 = m2 * lc2 * lc2 + i2 + k * c2;
    let m22 = m2 * lc2 * lc2 + i2;
    let h = k * s2;
    let tau = V::<2>::new(
        m11 * qdd[0] + m12 * qdd[1] - h * (2.0 * qd[0] * qd[1] + qd[1] * qd[1])
            + (m1 * lc1 + m2 * l1) * g * c1
            + m2 * lc2 * g * c12,
        m12 * qdd[0] + m22 * qdd[1] + h * qd[0] * qd[0] + m2 * lc2 * g * c12,
    );
    let dh = k * c2;
    let by_q = SMatrix::<f64, 2, 2>::new(
        -(m1 * lc1 + m2 * l1) * g * s1 - m2 * lc2 * g * s12,
        -2.0 * k * s2 * qdd[0]
            - k * s2 * qdd[1]
            - dh * (2.0 * qd[0] * qd[1] + qd[1] * qd[1])
            - m2 * lc2 * g * s12,
        -m2 * lc2 * g * s12,
        -k * s2 * qdd[0] + dh * qd[0] * qd[0] - m2 * lc2 * g * s12,
    );
    let by_qd = SMatrix::<f64, 2, 2>::new(
        -2.0 * h * qd[1],
        -2.0 * h * (qd[0] + qd[1]),
        2.0 * h * qd[0],
        0.0,
    );
    (tau, by_q, by_qd)
}

#[test]
fn planar_inverse_dynamics_jacobian_equals_the_hand_derivation() {
    let pair = PlanarPair::<f64>::new();
    let mut next = numbers(79);
    let (mut tau_err, mut q_err, mut qd_err) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (q, qd) in states::<2>(79) {
        let qdd = V::<2>::from_fn(|_, _| next());
        let (tau, by_q, by_qd) = planar_by_hand(&q, &qd, &qdd);
        let generated = pair.inverse_dynamics(&q, &qd, &qdd, 0.0).expect("finite");
        let (dq, dqd) = pair
            .inverse_dynamics_jacobian(&q, &qd, &qdd, 0.0)
            .expect("finite");
        tau_err = tau_err.max(relative(&generated, &tau));
        q_err = q_err.max(relative(&dq, &by_q));
        qd_err = qd_err.max(relative(&dqd, &by_qd));
    }
    println!("planar pair: τ within {tau_err:.1e}, ∂τ/∂q within {q_err:.1e}, ∂τ/∂q̇ within {qd_err:.1e} of the hand derivation");
    assert!(
        tau_err <= 1e-14 && q_err <= 1e-14 && qd_err <= 1e-14,
        "{tau_err} {q_err} {qd_err}"
    );
}

#[test]
fn f32_centroidal_map_and_inverse_dynamics_jacobian_agree_with_f64() {
    let (a64, a32) = (FramedArm::<f64>::new(), FramedArm::<f32>::new());
    for (q, qd) in states::<4>(83) {
        let (q32, qd32) = (q.cast::<f32>(), qd.cast::<f32>());
        let map = a64.centroidal_map(&q, 0.0);
        let map32 = a32.centroidal_map(&q32, 0.0).cast::<f64>();
        assert!((map32 - map).norm() <= 1e-5 * map.norm().max(1.0));
        let bias = a64.centroidal_map_bias(&q, &qd, 0.0);
        let bias32 = a32.centroidal_map_bias(&q32, &qd32, 0.0).cast::<f64>();
        assert!((bias32 - bias).norm() <= 1e-4 * bias.norm().max(1.0));
        let (dq, _) = a64
            .inverse_dynamics_jacobian(&q, &qd, &qd, 0.0)
            .expect("finite");
        let (dq32, _) = a32
            .inverse_dynamics_jacobian(&q32, &qd32, &qd32, 0.0)
            .expect("finite");
        assert!((dq32.cast::<f64>() - dq).norm() <= 1e-4 * dq.norm().max(1.0));
    }
}

/// A value that overflows is an error, not a matrix holding it: the
/// check over the two n × n matrices (`all_finite` over their storage)
/// sees an infinity wherever it lands and a NaN from any input the
/// matrices read, and passes a state whose values are all finite.
#[test]
fn an_inverse_dynamics_jacobian_that_overflows_is_an_error() {
    use constrained::DynamicsError;
    let panda = PandaTool::<f64>::new();
    let q = SVector::<f64, 7>::from_fn(|i, _| 0.1 * i as f64);
    let qdd = SVector::<f64, 7>::zeros();
    assert!(panda.inverse_dynamics_jacobian(&q, &q, &qdd, 0.0).is_ok());
    for k in 0..7 {
        // q̇ₖ² overflows in the Coriolis terms that qₖ's rate reaches.
        let mut fast = SVector::<f64, 7>::zeros();
        fast[k] = 1e200;
        assert_eq!(
            panda.inverse_dynamics_jacobian(&q, &fast, &qdd, 0.0).err(),
            Some(DynamicsError::NonFinite),
            "rate {k}"
        );
        // The first joint turns about gravity's axis: neither `τ` nor its
        // derivatives depend on its angle, so a NaN there is not read.
        if k == 0 {
            continue;
        }
        let mut lost = q;
        lost[k] = f64::NAN;
        assert_eq!(
            panda.inverse_dynamics_jacobian(&lost, &q, &qdd, 0.0).err(),
            Some(DynamicsError::NonFinite),
            "angle {k}"
        );
        assert_eq!(
            panda.inverse_dynamics(&lost, &q, &qdd, 0.0).err(),
            Some(DynamicsError::NonFinite),
            "τ at angle {k}"
        );
    }
}
