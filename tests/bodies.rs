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
