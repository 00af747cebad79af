//! The joint model's rows beyond revolute and prismatic, each against a
//! derivation that does not use it:
//! - a helical joint, by hand (one body), and as the revolute and prismatic
//!   joints along one axis that it is, with the prismatic coordinate `h θ`;
//! - a URDF `planar` joint, by hand (`M` and `g` from the centres of mass);
//! - URDF `<mimic>` on moving joints, as the same robot written with
//!   `bodies` where every joint has its coordinate, mapped by `G`
//!   (`M = Gᵀ M_full G`, `τ = Gᵀ τ_full`), and on a fixed joint, held at
//!   its offset.

use constrained::constrained_system;
use constrained::nalgebra::{SMatrix, SVector, Vector2, Vector4};

const G: f64 = 9.81;

constrained_system! {
    /// One body on a screw about `z`: 0.05 m per radian.
    pub struct Screw {
        bodies: [
            nut {
                joint: helical(theta, [0.0, 0.0, 1.0], 0.05),
                mass: 1.5,
                com: [0.2, 0.0, 0.0],
                inertia: diag[0.01, 0.02, 0.03],
            },
        ],
    }
}

constrained_system! {
    /// A link turning about `x`, carrying a screw about a skew axis.
    pub struct ScrewArm {
        bodies: [
            arm {
                joint: revolute(q1, [1.0, 0.0, 0.0]),
                mass: 2.0,
                com: [0.0, 0.1, 0.3],
                inertia: [[0.03, 0.001, 0.0], [0.001, 0.02, 0.002], [0.0, 0.002, 0.01]],
            },
            nut {
                parent: arm,
                joint: helical(theta, [0.0, 1.0, 1.0], 0.04),
                xyz: [0.1, 0.0, 0.5],
                rpy: [0.0, 0.3, 0.0],
                mass: 0.8,
                com: [0.05, 0.02, -0.1],
                inertia: [[0.004, 0.0, 0.0005], [0.0, 0.003, 0.0], [0.0005, 0.0, 0.002]],
            },
        ],
    }
}

constrained_system! {
    /// The same, the screw written as a massless revolute joint and a
    /// prismatic one along the same axis (`d = 0.04 θ` in the test).
    pub struct ScrewArmSplit {
        bodies: [
            arm {
                joint: revolute(q1, [1.0, 0.0, 0.0]),
                mass: 2.0,
                com: [0.0, 0.1, 0.3],
                inertia: [[0.03, 0.001, 0.0], [0.001, 0.02, 0.002], [0.0, 0.002, 0.01]],
            },
            spin {
                parent: arm,
                joint: revolute(s, [0.0, 1.0, 1.0]),
                xyz: [0.1, 0.0, 0.5],
                rpy: [0.0, 0.3, 0.0],
            },
            nut {
                parent: spin,
                joint: prismatic(d, [0.0, 1.0, 1.0]),
                mass: 0.8,
                com: [0.05, 0.02, -0.1],
                inertia: [[0.004, 0.0, 0.0005], [0.0, 0.003, 0.0], [0.0005, 0.0, 0.002]],
            },
        ],
    }
}

constrained_system! {
    /// A puck on a vertical plane with a pendulum under it (URDF `planar`).
    pub struct Planar {
        urdf: "data/planar.urdf",
    }
}

constrained_system! {
    /// A turntable, a wrist mimicking it, two fingers mimicking each other
    /// and a tip mimicking a fixed joint.
    pub struct Mimic {
        urdf: "data/mimic.urdf",
    }
}

constrained_system! {
    /// `data/mimic.urdf` written with `bodies`, every joint with its own
    /// coordinate, and the tip fixed at its mimic's offset.
    pub struct MimicFull {
        bodies: [
            table {
                joint: revolute(turn, [0.0, 0.0, 1.0]),
                xyz: [0.0, 0.0, 0.2],
                mass: 2.0,
                com: [0.05, 0.0, 0.1],
                inertia: [[0.02, 0.001, 0.0], [0.001, 0.03, 0.002], [0.0, 0.002, 0.04]],
            },
            wrist {
                parent: table,
                joint: revolute(w, [0.0, 1.0, 0.0]),
                xyz: [0.3, 0.0, 0.1],
                rpy: [0.2, 0.0, 0.0],
                mass: 0.7,
                com: [0.1, 0.02, 0.0],
                inertia: [[0.002, 0.0, 0.0005], [0.0, 0.004, 0.0], [0.0005, 0.0, 0.003]],
            },
            left {
                parent: wrist,
                joint: prismatic(l, [0.0, 1.0, 0.0]),
                xyz: [0.2, 0.0, 0.0],
                mass: 0.2,
                com: [0.0, 0.01, 0.02],
                inertia: diag[0.0002, 0.0001, 0.0002],
            },
            right {
                parent: wrist,
                joint: prismatic(r, [0.0, 1.0, 0.0]),
                xyz: [0.2, 0.0, 0.0],
                mass: 0.25,
                com: [0.0, -0.01, 0.02],
                inertia: diag[0.0002, 0.0001, 0.0003],
            },
            tip {
                parent: table,
                joint: fixed,
                xyz: [-0.1, 0.0, 0.05],
                rpy: [0.0, 0.0, 0.3],
                mass: 0.1,
                com: [0.03, 0.0, 0.0],
                inertia: diag[0.0001, 0.0001, 0.0001],
            },
        ],
    }
}

/// The largest entry of `a − b` over the largest of `b` (or 1).
fn relative<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>, b: &SMatrix<f64, R, C>) -> f64 {
    (a - b).amax() / b.amax().max(1.0)
}

/// Some states, deterministic and spread.
fn states<const N: usize>(count: usize) -> Vec<[SVector<f64, N>; 3]> {
    (0..count)
        .map(|k| {
            let x = |j: usize, scale: f64| ((k * 7 + j * 3) as f64 * 0.618_034).sin() * scale;
            [
                SVector::from_fn(|j, _| x(j, 1.3)),
                SVector::from_fn(|j, _| x(j + 11, 2.0)),
                SVector::from_fn(|j, _| x(j + 23, 3.0)),
            ]
        })
        .collect()
}

#[test]
fn a_screw_alone_by_hand() {
    // The centre moves θ̇ (z × r) + h θ̇ z: M = I_zz + m (r² + h²); it rises
    // h per radian, so V = m g h θ + const and g(θ) = m g h.
    let screw = Screw::<f64>::new();
    for [q, qd, _] in states::<1>(5) {
        let m = screw.mass_matrix(&q, 0.0)[0];
        assert!((m - (0.03 + 1.5 * (0.04 + 0.0025))).abs() <= 1e-15, "{m}");
        let gravity = screw.gravity_forces(&q, 0.0)[0];
        assert!((gravity - 1.5 * G * 0.05).abs() <= 1e-14, "{gravity}");
        // M constant, nothing else moves: the bias is gravity alone.
        let tau = screw.inverse_dynamics(&q, &qd, &SVector::zeros(), 0.0)[0];
        assert!((tau - gravity).abs() <= 1e-14, "{tau}");
    }
}

#[test]
fn the_derivation_names_each_joint_as_the_table_does() {
    let screw = Screw::<f64>::DERIVATION;
    assert!(
        screw.contains("helical about [0, 0, 1], pitch 1/20, theta"),
        "{screw}"
    );
    let mimic = Mimic::<f64>::DERIVATION;
    assert!(
        mimic.contains("revolute about [0, 1, 0], 1/2·turn + 3/10"),
        "{mimic}"
    );
    assert!(
        mimic.contains("prismatic along [0, 1, 0], −left_finger + 1/100"),
        "{mimic}"
    );
}

#[test]
fn a_screw_is_a_turn_and_a_slide_along_one_axis() {
    let (screw, split) = (ScrewArm::<f64>::new(), ScrewArmSplit::<f64>::new());
    // (q1, θ) ↦ (q1, s = θ, d = h θ).
    let h = 0.04;
    let g = SMatrix::<f64, 3, 2>::new(1.0, 0.0, 0.0, 1.0, 0.0, h);
    for [q, qd, qdd] in states::<2>(20) {
        let full = |x: &Vector2<f64>| g * x;
        let m = screw.mass_matrix(&q, 0.0);
        let m_full = g.transpose() * split.mass_matrix(&full(&q), 0.0) * g;
        assert!(relative(&m, &m_full) <= 1e-14, "{m}{m_full}");
        let tau = screw.inverse_dynamics(&q, &qd, &qdd, 0.0).expect("finite");
        let tau_full = g.transpose()
            * split
                .inverse_dynamics(&full(&q), &full(&qd), &full(&qdd), 0.0)
                .expect("finite");
        assert!(relative(&tau, &tau_full) <= 1e-13, "{tau}{tau_full}");
        let gravity = g.transpose() * split.gravity_forces(&full(&q), 0.0).expect("finite");
        let found = screw.gravity_forces(&q, 0.0).expect("finite");
        assert!(relative(&found, &gravity) <= 1e-14, "{found}{gravity}");
    }
}

/// `R(θ) v` in the plane.
fn turn(theta: f64, v: [f64; 2]) -> [f64; 2] {
    let (s, c) = theta.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

#[test]
fn a_planar_joint_by_hand() {
    let planar = Planar::<f64>::new();
    assert_eq!(
        Planar::<f64>::COORDINATES,
        ["slide_x", "slide_y", "slide_theta", "swing"]
    );
    // In the plane (the joint frame's x–y, with y up: the frame is rolled
    // by a right angle), the centres are c₁ = p + R(θ) a and
    // c₂ = p + R(θ) b + R(θ + φ) d; both bodies turn about the normal.
    let (a, b, d) = ([0.2, -0.1], [0.2, -0.1], [0.0, -0.3]);
    let (m1, i1, m2, i2) = (2.0, 0.05, 0.5, 0.003);
    for [q, _, _] in states::<4>(10) {
        let (theta, phi) = (q[2], q[3]);
        // ∂R(α)v/∂α = R(α + π/2) v.
        let right = std::f64::consts::FRAC_PI_2;
        let da = turn(theta + right, a);
        let (db, dd) = (turn(theta + right, b), turn(theta + phi + right, d));
        // Jacobians of the centres (2 × 4), columns x, y, θ, φ.
        let j1 = SMatrix::<f64, 2, 4>::new(1.0, 0.0, da[0], 0.0, 0.0, 1.0, da[1], 0.0);
        let j2 = SMatrix::<f64, 2, 4>::new(
            1.0,
            0.0,
            db[0] + dd[0],
            dd[0],
            0.0,
            1.0,
            db[1] + dd[1],
            dd[1],
        );
        let w1 = Vector4::new(0.0, 0.0, 1.0, 0.0);
        let w2 = Vector4::new(0.0, 0.0, 1.0, 1.0);
        let expected = m1 * j1.transpose() * j1
            + m2 * j2.transpose() * j2
            + i1 * w1 * w1.transpose()
            + i2 * w2 * w2.transpose();
        let m = planar.mass_matrix(&q, 0.0);
        assert!(relative(&m, &expected) <= 1e-14, "{m}{expected}");
        // V = g (m₁ c₁ʸ + m₂ c₂ʸ).
        let gravity: Vector4<f64> = G * (m1 * j1.row(1) + m2 * j2.row(1)).transpose();
        let found = planar.gravity_forces(&q, 0.0).expect("finite");
        assert!(relative(&found, &gravity) <= 1e-14, "{found}{gravity}");
    }
}

#[test]
fn mimic_joints_follow_the_coordinates_they_name() {
    assert_eq!(Mimic::<f64>::COORDINATES, ["turn", "left_finger"]);
    let (mimic, full) = (Mimic::<f64>::new(), MimicFull::<f64>::new());
    // (turn, l) ↦ (turn, w = 0.5 turn + 0.3, l, r = −l + 0.01).
    let g = SMatrix::<f64, 4, 2>::new(1.0, 0.0, 0.5, 0.0, 0.0, 1.0, 0.0, -1.0);
    let offset = Vector4::new(0.0, 0.3, 0.0, 0.01);
    for [q, qd, qdd] in states::<2>(20) {
        let at = g * q + offset;
        let m = mimic.mass_matrix(&q, 0.0);
        let m_full = g.transpose() * full.mass_matrix(&at, 0.0) * g;
        assert!(relative(&m, &m_full) <= 1e-14, "{m}{m_full}");
        let tau = mimic.inverse_dynamics(&q, &qd, &qdd, 0.0).expect("finite");
        let tau_full = g.transpose()
            * full
                .inverse_dynamics(&at, &(g * qd), &(g * qdd), 0.0)
                .expect("finite");
        assert!(relative(&tau, &tau_full) <= 1e-13, "{tau}{tau_full}");
        // q̈ solves M q̈ = −c with the reduced M and c.
        let accel = mimic
            .acceleration(&q, &qd, 0.0)
            .expect("M is positive definite");
        let bias = g.transpose()
            * full
                .inverse_dynamics(&at, &(g * qd), &Vector4::zeros(), 0.0)
                .expect("finite");
        let residual = m_full * accel + bias;
        assert!(
            residual.amax() <= 1e-12 * bias.amax().max(1.0),
            "{residual}"
        );
    }
}
