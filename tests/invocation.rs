//! `constrained_system!` where users call it: from a `macro_rules!` macro
//! that stamps out a family of systems, and inside a function body.
//!
//! A fragment such as `$k:expr` reaches the DSL as an invisible group: it
//! must keep its grouping, so that `$k * x` with `$k = 1.0 + 3.0` is `4 x`,
//! not `1 + 3 x` (the expansion takes the compiler's tokens for such input
//! instead of reading its text). Identifiers passed in (`$name:ident`) name
//! the generated struct. Inside a function, a large system's `M`, `F` and
//! `(A, b)` forward to functions in a module declared beside it.

use constrained::nalgebra::{SMatrix, SVector};
use constrained::{constrained_system, ConstrainedSystem, State};

macro_rules! spring {
    ($name:ident, $stiffness:expr) => {
        constrained_system! {
            /// A unit mass on a spring whose stiffness is a fragment.
            pub struct $name {
                coordinates: [x],
                kinetic_energy: dot(x).powi(2) / 2.0,
                potential_energy: $stiffness * x.powi(2) / 2.0,
            }
        }
    };
}

spring!(GroupedSpring, 1.0 + 3.0);
spring!(PlainSpring, 4.0);

constrained_system! {
    /// The same spring written out: `V = 2 x²`.
    pub struct WrittenSpring {
        coordinates: [x],
        kinetic_energy: dot(x).powi(2) / 2.0,
        potential_energy: 2.0 * x.powi(2),
    }
}

/// `ẍ` of each at `x = 0.5`: `−k x = −2` with `k = 4` for all three (a
/// lost grouping gives `V = 1 + 1.5 x²`, `ẍ = −1.5`).
#[test]
fn a_fragment_keeps_its_grouping() {
    let state = State::new(0.0, SVector::<f64, 1>::new(0.5), SVector::zeros());
    let accelerations = [
        ConstrainedSystem::acceleration(&GroupedSpring::new(), &state),
        ConstrainedSystem::acceleration(&PlainSpring::new(), &state),
        ConstrainedSystem::acceleration(&WrittenSpring::new(), &state),
    ];
    for a in accelerations {
        let a = a.expect("a spring's acceleration is finite");
        assert!((a[0] + 2.0).abs() < 1e-15, "ẍ = {}", a[0]);
    }
}

/// A system defined inside a function body, with a parameter its `M`,
/// `F` and `A` read: the functions those methods forward to live in a
/// module declared beside it, in the same block.
#[test]
fn a_system_defined_in_a_function_body() {
    constrained_system! {
        /// A mass `m` on a circle of radius `r` in the plane, under gravity.
        pub struct Bead {
            coordinates: [x, y],
            parameters: [m, r],
            mass: diag[m, m],
            forces: [0.0, -9.81 * m],
            constraints: [x.powi(2) + y.powi(2) == r.powi(2)],
        }
    }
    let bead = Bead::new(2.0, 0.5);
    // At the bottom, at rest: no acceleration; the normal force holds the
    // weight (λ along the gradient).
    let bottom = State::new(0.0, SVector::<f64, 2>::new(0.0, -0.5), SVector::zeros());
    let a = ConstrainedSystem::acceleration(&bead, &bottom).expect("finite");
    assert!(a.norm() < 1e-14, "q̈ = {a}");
    let m = bead.mass_matrix(&bottom.q, 0.0);
    assert_eq!(m[(0, 0)], 2.0);
    assert_eq!(m[(1, 1)], 2.0);
    let f = bead.forces(&bottom.q, &bottom.qd, 0.0);
    assert!((f[1] + 19.62).abs() < 1e-14, "F = {f}");
    let (a_matrix, b) = bead.constraint_matrices(&bottom.q, &bottom.qd, 0.0);
    assert!((a_matrix[(0, 1)] + 1.0).abs() < 1e-14, "A = {a_matrix}");
    assert!(b[0].abs() < 1e-14, "b = {b}");
    // Moving at speed v on the side (x = r): the centripetal acceleration
    // v²/r points to the centre.
    let side = State::new(
        0.0,
        SVector::<f64, 2>::new(0.5, 0.0),
        SVector::<f64, 2>::new(0.0, 1.0),
    );
    let a = ConstrainedSystem::acceleration(&bead, &side).expect("finite");
    assert!((a[0] + 2.0).abs() < 1e-13, "q̈ = {a}");
    assert!((a[1] + 9.81).abs() < 1e-13, "q̈ = {a}");
}

/// A six-joint arm defined inside a function body, large enough that its
/// `M` and `F` are computed in the module beside it, which reads the
/// payload parameter from its argument: `M eⱼ` is inverse dynamics'
/// `τ(q, 0, eⱼ) − τ(q, 0, 0)` and `F` is `−τ(q, q̇, 0)` (inverse dynamics
/// is a method of its own, reading the payload from the struct), at two
/// payloads; `acceleration` solves `M q̈ = F`.
#[test]
fn a_large_system_defined_in_a_function_body() {
    constrained_system! {
        /// Six revolute joints, the last link carrying `payload`.
        pub struct Arm {
            parameters: [payload],
            gravity: [0.0, 0.0, -9.81],
            bodies: [
                l1 { joint: revolute(q1, [0.0, 0.0, 1.0]), mass: 2.0, com: [0.0, 0.0, 0.2],
                     inertia: diag[0.05, 0.06, 0.03] },
                l2 { parent: l1, joint: revolute(q2, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, 0.4],
                     mass: 1.5, com: [0.25, 0.0, 0.01],
                     inertia: [[0.01, 0.002, 0.0], [0.002, 0.04, 0.0], [0.0, 0.0, 0.045]] },
                l3 { parent: l2, joint: revolute(q3, [0.0, 1.0, 0.0]), xyz: [0.5, 0.0, 0.0],
                     mass: 1.0, com: [0.2, 0.0, 0.0], inertia: diag[0.005, 0.02, 0.021] },
                l4 { parent: l3, joint: revolute(q4, [1.0, 0.0, 0.0]), xyz: [0.4, 0.0, 0.05],
                     mass: 0.7, com: [0.1, 0.01, 0.0], inertia: diag[0.003, 0.004, 0.005] },
                l5 { parent: l4, joint: revolute(q5, [0.0, 1.0, 0.0]), xyz: [0.2, 0.0, 0.0],
                     mass: 0.5, com: [0.05, 0.0, 0.02], inertia: diag[0.002, 0.002, 0.001] },
                l6 { parent: l5, joint: revolute(q6, [0.0, 0.0, 1.0]), xyz: [0.1, 0.0, 0.0],
                     mass: payload, com: [0.0, 0.0, 0.05], inertia: diag[0.001, 0.001, 0.002] },
            ],
        }
    }
    let q = SVector::<f64, 6>::from([0.3, -0.7, 1.1, 0.4, -0.2, 0.9]);
    let qd = SVector::<f64, 6>::from([0.5, 0.1, -0.3, 0.8, -0.6, 0.2]);
    let mut masses = Vec::new();
    for payload in [0.25, 3.0] {
        let arm = Arm::new(payload);
        let m = arm.mass_matrix(&q, 0.0);
        let zero = SVector::<f64, 6>::zeros();
        let tau = |qd: &SVector<f64, 6>, qdd: &SVector<f64, 6>| {
            arm.inverse_dynamics(&q, qd, qdd, 0.0).expect("finite")
        };
        let bias = tau(&zero, &zero);
        let mut by_columns = SMatrix::<f64, 6, 6>::zeros();
        for j in 0..6 {
            let e = SVector::<f64, 6>::from_fn(|i, _| f64::from(u8::from(i == j)));
            by_columns.set_column(j, &(tau(&zero, &e) - bias));
        }
        assert!(
            (m - by_columns).norm() < 1e-13 * m.norm(),
            "M = {m}, by τ {by_columns}"
        );
        let f = arm.forces(&q, &qd, 0.0);
        let c = tau(&qd, &zero);
        assert!((f + c).norm() < 1e-13 * c.norm(), "F = {f}, τ = {c}");
        let state = State::new(0.0, q, qd);
        let qdd = ConstrainedSystem::acceleration(&arm, &state).expect("finite");
        assert!(
            (m * qdd - f).norm() < 1e-12 * f.norm(),
            "M q̈ − F = {}",
            m * qdd - f
        );
        masses.push(m);
    }
    // The payload reached the detached `M`: its inertia about the first
    // axis grew with it.
    assert!(
        masses[1][(0, 0)] > masses[0][(0, 0)] + 0.01,
        "{} {}",
        masses[0],
        masses[1]
    );
}
