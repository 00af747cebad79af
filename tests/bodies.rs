//! Bodies and joints against the energy path: the same spatial arm (three
//! revolute joints, a prismatic one, a tool on a fixed joint turned by a
//! right angle, a parametric payload) written once as bodies — `M` by the
//! composite-rigid-body algorithm, the bias forces by recursive
//! Newton–Euler — and once by hand as `T` and `V` for Lagrange's
//! equations. The two derivations share nothing but the parameters.

use constrained::constrained_system;
use constrained::nalgebra::{SMatrix, SVector};

constrained_system! {
    /// The arm as bodies.
    pub struct ArmBodies {
        parameters: [payload],
        gravity: [0.0, 0.0, -9.81],
        bodies: [
            base {
                joint: revolute(q1, [0.0, 0.0, 1.0]),
                mass: 2.0,
                com: [0.0, 0.0, 0.2],
                inertia: diag[0.05, 0.06, 0.03],
            },
            upper {
                parent: base,
                joint: revolute(q2, [0.0, 1.0, 0.0]),
                xyz: [0.0, 0.0, 0.4],
                mass: 1.5,
                com: [0.25, 0.0, 0.0],
                inertia: [[0.01, 0.002, 0.0], [0.002, 0.04, 0.0], [0.0, 0.0, 0.045]],
            },
            fore {
                parent: upper,
                joint: revolute(q3, [0.0, 1.0, 0.0]),
                xyz: [0.5, 0.0, 0.0],
                mass: 1.0,
                com: [0.2, 0.0, 0.0],
                inertia: diag[0.005, 0.02, 0.021],
            },
            tool {
                parent: fore,
                joint: fixed,
                xyz: [0.0, 0.1, 0.0],
                rpy: [PI / 2.0, 0.0, 0.0],
                mass: payload,
                com: [0.0, 0.0, 0.05],
                inertia: diag[0.001, 0.002, 0.003],
            },
            slider {
                parent: fore,
                joint: prismatic(s, [1.0, 0.0, 0.0]),
                xyz: [0.3, 0.0, 0.0],
                mass: 0.5,
                inertia: diag[0.0004, 0.0005, 0.0006],
            },
        ],
    }
}

constrained_system! {
    /// The same arm by its energies.
    pub struct ArmEnergies {
        coordinates: [q1, q2, s3_angle, s],
        parameters: [payload],
        definitions: [
            c1 = q1.cos(), s1 = q1.sin(),
            q23 = q2 + s3_angle,
            // Centres of mass in the world.
            x2 = 0.25 * q2.cos(), z2 = 0.4 - 0.25 * q2.sin(),
            r3 = 0.5 * q2.cos() + 0.2 * q23.cos(), z3 = 0.4 - 0.5 * q2.sin() - 0.2 * q23.sin(),
            r4 = 0.5 * q2.cos() + (0.3 + s) * q23.cos(), z4 = 0.4 - 0.5 * q2.sin() - (0.3 + s) * q23.sin(),
            rt = 0.5 * q2.cos(), zt = 0.4 - 0.5 * q2.sin(),
            // Angular velocities in the links' frames.
            w2x = -q2.sin() * dot(q1), w2z = q2.cos() * dot(q1),
            w3x = -q23.sin() * dot(q1), w3y = dot(q2) + dot(s3_angle), w3z = q23.cos() * dot(q1),
        ],
        kinetic_energy:
            0.03 * dot(q1).powi(2) / 2.0
            + 1.5 * (dt(x2 * c1).powi(2) + dt(x2 * s1).powi(2) + dt(z2).powi(2)) / 2.0
            + (0.01 * w2x.powi(2) + 2.0 * 0.002 * w2x * dot(q2) + 0.04 * dot(q2).powi(2) + 0.045 * w2z.powi(2)) / 2.0
            + 1.0 * (dt(r3 * c1).powi(2) + dt(r3 * s1).powi(2) + dt(z3).powi(2)) / 2.0
            + (0.005 * w3x.powi(2) + 0.02 * w3y.powi(2) + 0.021 * w3z.powi(2)) / 2.0
            + payload * (dt(rt * c1 - 0.05 * s1).powi(2) + dt(rt * s1 + 0.05 * c1).powi(2) + dt(zt).powi(2)) / 2.0
            + (0.001 * w3x.powi(2) + 0.003 * w3y.powi(2) + 0.002 * w3z.powi(2)) / 2.0
            + 0.5 * (dt(r4 * c1).powi(2) + dt(r4 * s1).powi(2) + dt(z4).powi(2)) / 2.0
            + (0.0004 * w3x.powi(2) + 0.0005 * w3y.powi(2) + 0.0006 * w3z.powi(2)) / 2.0,
        potential_energy: 9.81 * (2.0 * 0.2 + 1.5 * z2 + 1.0 * z3 + payload * zt + 0.5 * z4),
    }
}

const STATES: [([f64; 4], [f64; 4]); 4] = [
    ([0.3, -0.7, 1.1, 0.05], [0.4, -1.2, 0.9, 0.3]),
    ([-2.0, 0.4, -0.3, -0.1], [1.5, 0.2, -2.0, -0.4]),
    ([0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]),
    ([1.0, 2.5, -1.7, 0.2], [-0.3, 0.8, 0.1, 1.0]),
];

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
}

#[test]
fn bodies_give_the_energy_paths_mass_matrix_forces_and_energies() {
    let (bodies, energies) = (ArmBodies::new(0.3), ArmEnergies::new(0.3));
    for (q, qd) in STATES {
        let (q, qd) = (SVector::from(q), SVector::from(qd));
        let (mb, me) = (bodies.mass_matrix(&q, 0.0), energies.mass_matrix(&q, 0.0));
        let (fb, fe) = (bodies.forces(&q, &qd, 0.0), energies.forces(&q, &qd, 0.0));
        for (a, b) in mb.iter().zip(me.iter()).chain(fb.iter().zip(fe.iter())) {
            assert!(close(*a, *b), "bodies\n{mb}{fb}\nenergies\n{me}{fe}");
        }
        let tb = bodies.kinetic_energy(&q, &qd, 0.0).unwrap();
        let te = energies.kinetic_energy(&q, &qd, 0.0).unwrap();
        let vb = bodies.potential_energy(&q, 0.0).unwrap();
        let ve = energies.potential_energy(&q, 0.0).unwrap();
        assert!(
            close(tb, te) && close(vb, ve),
            "T {tb} vs {te}, V {vb} vs {ve}"
        );
        assert!(close(bodies.energy(&q, &qd, 0.0).unwrap(), te + ve));
    }
}

#[test]
fn inverse_dynamics_is_m_qdd_plus_bias_and_gravity_forces_hold_still() {
    let arm = ArmBodies::new(0.7);
    for (q, qd) in STATES {
        let (q, qd) = (SVector::from(q), SVector::from(qd));
        let qdd = SVector::<f64, 4>::new(0.3, -1.1, 2.0, -0.5);
        let tau = arm.inverse_dynamics(&q, &qd, &qdd, 0.0).unwrap();
        let m: SMatrix<f64, 4, 4> = arm.mass_matrix(&q, 0.0);
        let expected = m * qdd - arm.forces(&q, &qd, 0.0);
        for (a, b) in tau.iter().zip(expected.iter()) {
            assert!(close(*a, *b), "{tau} vs {expected}");
        }
        let gravity = arm.gravity_forces(&q, 0.0).unwrap();
        let still = -arm.forces(&q, &SVector::zeros(), 0.0);
        for (a, b) in gravity.iter().zip(still.iter()) {
            assert!(close(*a, *b), "{gravity} vs {still}");
        }
        // Round trip: the acceleration of τ = inverse_dynamics(q̈) is q̈.
        let back = m
            .cholesky()
            .unwrap()
            .solve(&(tau + arm.forces(&q, &qd, 0.0)));
        assert!((back - qdd).norm() <= 1e-12 * (1.0 + qdd.norm()));
    }
}

/// An independent numeric model of the Panda from the same published
/// table: forward kinematics by 3×3 rotations, each centre of mass's
/// geometric Jacobian, `M = Σ mᵢ Jᵥᵀ Jᵥ + J_ωᵀ Rᵢ Iᵢ Rᵢᵀ J_ω` and
/// `g(q) = −Σ mᵢ Jᵥᵀ g` — no recursion, nothing shared with the macro.
mod reference {
    use constrained::nalgebra::{Matrix3, SMatrix, SVector, Vector3};
    use constrained_codegen::tools::fixtures::PANDA;

    fn num(s: &str) -> f64 {
        s.parse().expect("the table holds decimals")
    }

    pub fn mass_and_gravity(q: &SVector<f64, 7>) -> (SMatrix<f64, 7, 7>, SVector<f64, 7>) {
        let (mut r, mut p) = (Matrix3::identity(), Vector3::zeros());
        let (mut axes, mut origins) = (Vec::new(), Vec::new());
        let mut m = SMatrix::<f64, 7, 7>::zeros();
        let mut gravity = SVector::<f64, 7>::zeros();
        for (i, (xyz, roll, mass, first, inertia)) in PANDA.iter().enumerate() {
            let angle = f64::from(*roll) * std::f64::consts::FRAC_PI_2;
            let (s, c) = (angle.sin().round(), angle.cos().round());
            let placement = Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c);
            p += r * Vector3::new(num(xyz[0]), num(xyz[1]), num(xyz[2]));
            let (sq, cq) = q[i].sin_cos();
            r = r * placement * Matrix3::new(cq, -sq, 0.0, sq, cq, 0.0, 0.0, 0.0, 1.0);
            axes.push(r.column(2).into_owned());
            origins.push(p);
            let mi = num(mass);
            let com = p + r * Vector3::new(num(first[0]), num(first[1]), num(first[2])) / mi;
            let [xx, xy, xz, yy, yz, zz] = inertia.map(num);
            let ic = r * Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz) * r.transpose();
            let (mut jv, mut jw) = (SMatrix::<f64, 3, 7>::zeros(), SMatrix::<f64, 3, 7>::zeros());
            for j in 0..=i {
                jv.set_column(j, &axes[j].cross(&(com - origins[j])));
                jw.set_column(j, &axes[j]);
            }
            m += mi * jv.transpose() * jv + jw.transpose() * ic * jw;
            gravity += mi * jv.transpose() * Vector3::new(0.0, 0.0, 9.81);
        }
        (m, gravity)
    }

    /// `C(q, q̇) q̇ = Ṁ q̇ − ½ ∂(q̇ᵀ M q̇)/∂q`, by central differences of `M`.
    pub fn coriolis(q: &SVector<f64, 7>, qd: &SVector<f64, 7>) -> SVector<f64, 7> {
        let h = 1e-5;
        let mass = |q: SVector<f64, 7>| mass_and_gravity(&q).0;
        let mdot = (mass(q + h * qd) - mass(q - h * qd)) / (2.0 * h);
        let mut gradient = SVector::<f64, 7>::zeros();
        for k in 0..7 {
            let e = SVector::<f64, 7>::from_fn(|i, _| if i == k { h } else { 0.0 });
            let (plus, minus) = (mass(q + e), mass(q - e));
            gradient[k] = (qd.dot(&(plus * qd)) - qd.dot(&(minus * qd))) / (2.0 * h);
        }
        mdot * qd - 0.5 * gradient
    }
}

fn panda_states() -> Vec<(SVector<f64, 7>, SVector<f64, 7>, SVector<f64, 7>)> {
    // Fixed pseudo-random states (a linear congruential sequence).
    let mut x = 12345u64;
    let mut next = move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((x >> 11) as f64 / (1u64 << 53) as f64) * 4.0 - 2.0
    };
    (0..20)
        .map(|_| {
            (
                SVector::from_fn(|_, _| next()),
                SVector::from_fn(|_, _| next()),
                SVector::from_fn(|_, _| next()),
            )
        })
        .collect()
}

#[test]
fn panda_mass_matrix_and_gravity_equal_the_jacobian_reference_to_1e12() {
    let panda = constrained_chains::Panda::<f64>::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (q, _, _) in panda_states() {
        let (m, g) = reference::mass_and_gravity(&q);
        let generated = panda.mass_matrix(&q, 0.0);
        assert!((generated - m).norm() <= 1e-12 * m.norm(), "{generated}{m}");
        let gravity = panda.gravity_forces(&q, 0.0).unwrap();
        assert!((gravity - g).norm() <= 1e-12 * g.norm(), "{gravity}{g}");
    }
}

#[test]
fn panda_inverse_dynamics_and_acceleration_equal_the_reference() {
    let panda = constrained_chains::Panda::<f64>::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (q, qd, qdd) in panda_states() {
        let (m, g) = reference::mass_and_gravity(&q);
        let expected = m * qdd + reference::coriolis(&q, &qd) + g;
        let tau = panda.inverse_dynamics(&q, &qd, &qdd, 0.0).unwrap();
        // The reference's Coriolis terms are central differences (h = 1e-5).
        assert!(
            (tau - expected).norm() <= 1e-7 * expected.norm(),
            "{tau}{expected}"
        );
        // Driven by τ, the arm accelerates by qdd (the library's own solve).
        let driven = constrained_chains::Panda::<f64>::new(
            tau[0], tau[1], tau[2], tau[3], tau[4], tau[5], tau[6],
        );
        let back = driven.acceleration(&q, &qd, 0.0).unwrap();
        assert!(
            (back - qdd).norm() <= 1e-10 * (1.0 + qdd.norm()),
            "{back}{qdd}"
        );
    }
}

constrained_system! {
    /// The same Panda from a URDF file written from the same table, its
    /// gripper's fingers locked and a massless fixed flange.
    pub struct PandaUrdf {
        urdf: "data/panda_published.urdf",
        locked: [finger_joint1, finger_joint2],
    }
}

#[test]
fn urdf_section_reads_the_same_panda_as_the_bodies_section() {
    assert_eq!(PandaUrdf::<f64>::DOF, 7);
    let (urdf, bodies) = (
        PandaUrdf::<f64>::new(),
        constrained_chains::Panda::<f64>::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    );
    for (q, qd, qdd) in panda_states() {
        let (a, b) = (urdf.mass_matrix(&q, 0.0), bodies.mass_matrix(&q, 0.0));
        assert!((a - b).norm() <= 1e-12 * b.norm(), "{a}{b}");
        let (a, b) = (
            urdf.acceleration(&q, &qd, 0.0).unwrap(),
            bodies.acceleration(&q, &qd, 0.0).unwrap(),
        );
        assert!((a - b).norm() <= 1e-12 * b.norm(), "{a}{b}");
        let (a, b) = (
            urdf.inverse_dynamics(&q, &qd, &qdd, 0.0).unwrap(),
            bodies.inverse_dynamics(&q, &qd, &qdd, 0.0).unwrap(),
        );
        assert!((a - b).norm() <= 1e-12 * b.norm(), "{a}{b}");
    }
}

#[test]
fn energy_of_the_panda_is_conserved_along_an_unforced_run() {
    use constrained::{DormandPrince45, State};
    let panda = PandaUrdf::<f64>::new();
    let (q, qd, _) = panda_states()[3];
    let mut state = State::new(0.0, q, qd);
    let before = panda.energy(&state.q, &state.qd, 0.0).unwrap();
    DormandPrince45::new(1e-11, 1e-12)
        .advance(&panda, &mut state, 1.0)
        .unwrap();
    let after = panda.energy(&state.q, &state.qd, state.t).unwrap();
    assert!(
        (after - before).abs() <= 1e-8 * before.abs().max(1.0),
        "{before} -> {after}"
    );
    assert!((state.q - q).norm() > 0.1, "it moved");
}

constrained_system! {
    /// `TwoLinkArmOnLine` as bodies: point masses at the ends of the links,
    /// the tip held on `y = height` through `position(..)`.
    pub struct TwoLinkArmBodies {
        parameters: [m1, m2, l1, l2, g, height],
        gravity: [0.0, -g, 0.0],
        bodies: [
            upper { joint: revolute(th1, [0.0, 0.0, 1.0]), mass: m1, com: [l1, 0.0, 0.0] },
            fore {
                parent: upper,
                joint: revolute(th2, [0.0, 0.0, 1.0]),
                xyz: [l1, 0.0, 0.0],
                mass: m2,
                com: [l2, 0.0, 0.0],
            },
        ],
        constraints: [position(fore, [l2, 0.0, 0.0]).y == height],
    }
}

#[test]
fn a_point_of_a_body_in_a_constraint_gives_the_hand_written_arm() {
    use constrained::models::TwoLinkArmOnLine;
    use constrained::nalgebra::Vector2;
    let p = (1.0, 0.8, 1.0, 0.8, 9.81);
    for (th1, th2, w1) in [(1.2, -1.6, 0.4), (0.3, 0.9, -1.0), (2.0, -2.5, 0.7)] {
        let height = p.2 * f64::sin(th1) + p.3 * f64::sin(th1 + th2);
        let bodies = TwoLinkArmBodies::new(p.0, p.1, p.2, p.3, p.4, height);
        let hand = TwoLinkArmOnLine::new(p.0, p.1, p.2, p.3, p.4, height);
        // A velocity along the line: the tip's ẏ = 0.
        let (c1, c12) = (p.2 * f64::cos(th1), p.3 * f64::cos(th1 + th2));
        let w2 = -w1 * (c1 + c12) / c12;
        let (q, qd) = (Vector2::new(th1, th2), Vector2::new(w1, w2));
        assert!(bodies.constraint_residual(&q, &qd, 0.0)[0].abs() < 1e-14);
        let (a, b) = (
            bodies.acceleration(&q, &qd, 0.0).unwrap(),
            hand.acceleration(&q, &qd, 0.0).unwrap(),
        );
        assert!((a - b).norm() <= 1e-12 * b.norm(), "{a} vs {b}");
        let ga = bodies.acceleration_gibbs_appell(&q, &qd, 0.0).unwrap();
        assert!((ga - b).norm() <= 1e-12 * b.norm(), "{ga} vs {b}");
    }
}

constrained_system! {
    /// A rod turning about z; its tip's position and velocity as forces,
    /// to read them back.
    pub struct RodPoints {
        bodies: [rod { joint: revolute(th, [0.0, 0.0, 1.0]), mass: 1.0, com: [0.5, 0.0, 0.0] }],
        gravity: [0.0, 0.0, 0.0],
        forces: [position(rod, [2.0, 0.0, 0.5]).x + velocity(rod, [2.0, 0.0, 0.5]).y],
    }
}

#[test]
fn position_and_velocity_of_a_point_are_the_closed_forms() {
    let rod = RodPoints::new();
    for (th, w) in [(0.3f64, 1.7f64), (-2.0, 0.4)] {
        let f = rod.forces(&SVector::from([th]), &SVector::from([w]), 0.0)[0];
        let expected = 2.0 * th.cos() + 2.0 * th.cos() * w;
        assert!((f - expected).abs() < 1e-14, "{f} vs {expected}");
    }
}

constrained_system! {
    /// The spatial arm with the slider's tip held at a point of the world:
    /// three rows from one line, leaving one degree of freedom.
    pub struct ArmTipHeld {
        gravity: [0.0, 0.0, -9.81],
        parameters: [px, py, pz],
        bodies: [
            base { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 2.0, com: [0.0, 0.0, 0.2], inertia: diag[0.05, 0.06, 0.03] },
            upper {
                parent: base, joint: revolute(q2, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.4],
                mass: 1.5, com: [0.25, 0.0, 0.0], inertia: diag[0.01, 0.04, 0.045],
            },
            fore {
                parent: upper, joint: revolute(q3, [0.0, 1.0, 0.0]), xyz: [0.5, 0.0, 0.0],
                mass: 1.0, com: [0.2, 0.0, 0.0], inertia: diag[0.005, 0.02, 0.021],
            },
            slider {
                parent: fore, joint: prismatic(s, [1.0, 0.0, 0.0]), xyz: [0.3, 0.0, 0.0],
                mass: 0.5, inertia: diag[0.0004, 0.0005, 0.0006],
            },
        ],
        constraints: [position(slider, [0.0, 0.0, 0.0]) == [px, py, pz]],
    }
}

#[test]
fn a_point_held_in_space_is_three_rows_that_both_forms_satisfy() {
    assert_eq!(ArmTipHeld::<f64>::CONSTRAINTS, 3);
    // The tip where the arm puts it at q = (0.4, −0.3, 0.8, 0.1); a velocity
    // in the null space of A (the one free direction).
    let q = SVector::<f64, 4>::new(0.4, -0.3, 0.8, 0.1);
    let free = ArmTipHeld::new(0.0, 0.0, 0.0);
    let tip = free.constraint_residual(&q, &SVector::zeros(), 0.0);
    let arm = ArmTipHeld::new(tip[0], tip[1], tip[2]);
    assert!(arm.constraint_residual(&q, &SVector::zeros(), 0.0).norm() < 1e-14);
    let (a, _) = arm.constraint_matrices(&q, &SVector::zeros(), 0.0);
    let eigen = (a.transpose() * a).symmetric_eigen();
    let smallest = eigen.eigenvalues.imin();
    let null = eigen.eigenvectors.column(smallest).into_owned();
    let qd = 0.7 * null;
    assert!(arm.constraint_velocity_residual(&q, &qd, 0.0).norm() < 1e-14);
    let qdd = arm.acceleration(&q, &qd, 0.0).unwrap();
    let (a, b) = arm.constraint_matrices(&q, &qd, 0.0);
    assert!((a * qdd - b).norm() < 1e-12 * (1.0 + b.norm()));
    let ga = arm.acceleration_gibbs_appell(&q, &qd, 0.0).unwrap();
    assert!(
        (ga - qdd).norm() < 1e-12 * (1.0 + qdd.norm()),
        "{ga} vs {qdd}"
    );
}
