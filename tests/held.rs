//! A body held at three or more of its points under a floating base
//! (`equations/held.rs`): its rows are solved as the body's own six. The
//! oracles are the runtime's dense Moore–Penrose solve and its SVD on the
//! constraint surface, and off it (a foot turning, where no acceleration
//! satisfies all of its points' rows) the least-squares problem the
//! solve is defined by, solved densely here.

use constrained::multipliers::{multipliers, Multipliers};
use constrained::nalgebra::{SMatrix, SVector, UnitQuaternion, Vector3};
use constrained::rank::relative_residual;
use constrained::{ConstrainedSystem, State};

constrained::constrained_system! {
    /// A biped's legs on a floating pelvis, its left foot held at four points of its sole, its right at three.
    pub struct BipedOnSevenPoints {
        parameters: [l0x, l0y, l0z, l1x, l1y, l1z, l2x, l2y, l2z, l3x, l3y, l3z, r0x, r0y, r0z, r1x, r1y, r1z, r2x, r2y, r2z],
        bodies: [
            pelvis {
                joint: free(x, y, z, qw, qx, qy, qz),
                mass: 4.0,
                com: [0.0, 0.0, 0.05],
                inertia: [[0.04, 0.0, 0.001], [0.0, 0.03, 0.0], [0.001, 0.0, 0.035]],
            },
            l_hip_yaw { parent: pelvis, joint: revolute(lhy, [0.0, 0.0, 1.0]), xyz: [0.0, 0.1, -0.05], mass: 0.5, com: [0.0, 0.0, -0.02], inertia: [[5.0e-4, 0.0, 0.0], [0.0, 5.0e-4, 0.0], [0.0, 0.0, 4.0e-4]] },
            l_hip_roll { parent: l_hip_yaw, joint: revolute(lhr, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, -0.05], mass: 0.6, com: [0.0, 0.01, 0.0], inertia: [[6.0e-4, 0.0, 0.0], [0.0, 5.0e-4, 0.0], [0.0, 0.0, 5.0e-4]] },
            l_thigh { parent: l_hip_roll, joint: revolute(lhp, [0.0, 1.0, 0.0]), mass: 2.0, com: [0.01, 0.0, -0.15], inertia: [[0.02, 0.0, 0.001], [0.0, 0.02, 0.0], [0.001, 0.0, 0.003]] },
            l_shin { parent: l_thigh, joint: revolute(lk, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, -0.3], mass: 1.2, com: [0.0, 0.0, -0.14], inertia: [[0.012, 0.0, 0.0], [0.0, 0.012, 0.0], [0.0, 0.0, 0.001]] },
            l_ankle { parent: l_shin, joint: revolute(lap, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, -0.3], mass: 0.1, com: [0.0, 0.0, 0.0], inertia: [[1.0e-5, 0.0, 0.0], [0.0, 1.0e-5, 0.0], [0.0, 0.0, 1.0e-5]] },
            l_foot { parent: l_ankle, joint: revolute(lar, [1.0, 0.0, 0.0]), mass: 0.5, com: [0.03, 0.0, -0.03], inertia: [[3.0e-4, 0.0, 0.0], [0.0, 9.0e-4, 0.0], [0.0, 0.0, 1.0e-3]] },
            r_hip_yaw { parent: pelvis, joint: revolute(rhy, [0.0, 0.0, 1.0]), xyz: [0.0, -0.1, -0.05], mass: 0.5, com: [0.0, 0.0, -0.02], inertia: [[5.0e-4, 0.0, 0.0], [0.0, 5.0e-4, 0.0], [0.0, 0.0, 4.0e-4]] },
            r_hip_roll { parent: r_hip_yaw, joint: revolute(rhr, [1.0, 0.0, 0.0]), xyz: [0.0, 0.0, -0.05], mass: 0.6, com: [0.0, -0.01, 0.0], inertia: [[6.0e-4, 0.0, 0.0], [0.0, 5.0e-4, 0.0], [0.0, 0.0, 5.0e-4]] },
            r_thigh { parent: r_hip_roll, joint: revolute(rhp, [0.0, 1.0, 0.0]), mass: 2.0, com: [0.01, 0.0, -0.15], inertia: [[0.02, 0.0, 0.001], [0.0, 0.02, 0.0], [0.001, 0.0, 0.003]] },
            r_shin { parent: r_thigh, joint: revolute(rk, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, -0.3], mass: 1.2, com: [0.0, 0.0, -0.14], inertia: [[0.012, 0.0, 0.0], [0.0, 0.012, 0.0], [0.0, 0.0, 0.001]] },
            r_ankle { parent: r_shin, joint: revolute(rap, [0.0, 1.0, 0.0]), xyz: [0.0, 0.0, -0.3], mass: 0.1, com: [0.0, 0.0, 0.0], inertia: [[1.0e-5, 0.0, 0.0], [0.0, 1.0e-5, 0.0], [0.0, 0.0, 1.0e-5]] },
            r_foot { parent: r_ankle, joint: revolute(rar, [1.0, 0.0, 0.0]), mass: 0.5, com: [0.03, 0.0, -0.03], inertia: [[3.0e-4, 0.0, 0.0], [0.0, 9.0e-4, 0.0], [0.0, 0.0, 1.0e-3]] },
        ],
        constraints: [
            position(l_foot, [-0.05, 0.025, -0.04]) == [l0x, l0y, l0z],
            position(l_foot, [-0.05, -0.025, -0.04]) == [l1x, l1y, l1z],
            position(l_foot, [0.12, 0.0, -0.04]) == [l2x, l2y, l2z],
            position(l_foot, [0.1, 0.04, -0.04]) == [l3x, l3y, l3z],
            position(r_foot, [-0.05, 0.025, -0.04]) == [r0x, r0y, r0z],
            position(r_foot, [-0.05, -0.025, -0.04]) == [r1x, r1y, r1z],
            position(r_foot, [0.12, 0.0, -0.04]) == [r2x, r2y, r2z],
        ],
    }
}

const N: usize = 19;
const K: usize = 22;

/// Each foot's points' rows, `x, y, z` of each point: its first row and
/// its number of points.
const FEET: [(usize, usize); 2] = [(0, 4), (12, 3)];

/// The quaternion's norm's row.
const NORM: usize = 21;

/// A deterministic number in `[-1, 1)` for index `i` of stream `k`.
fn wiggle(k: usize, i: usize) -> f64 {
    (((i * 7919 + k * 104_729) % 2003) as f64 / 1001.5) - 1.0
}

/// The biped at state `k`: the pelvis leaning, every joint within
/// ±0.3 rad (the knees of state 0 straight), the feet's points held where
/// they are; `q̇` arbitrary (off the constraint surface).
fn biped(k: usize) -> (BipedOnSevenPoints<f64>, State<f64, N>) {
    let pelvis =
        UnitQuaternion::from_euler_angles(0.1 * wiggle(k, 1), 0.1 * wiggle(k, 2), wiggle(k, 3));
    let mut q = SVector::<f64, N>::zeros();
    q[2] = 0.7;
    q[3] = pelvis.w;
    q[4] = pelvis.i;
    q[5] = pelvis.j;
    q[6] = pelvis.k;
    for j in 7..N {
        q[j] = 0.3 * wiggle(k, j);
    }
    if k == 0 {
        q[10] = 0.0;
        q[16] = 0.0;
    }
    let qd = SVector::<f64, N>::from_fn(|i, _| wiggle(k + 10, i));
    let free = BipedOnSevenPoints::new(
        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0,
    );
    let s = State::new(0.0, q, qd);
    let p = ConstrainedSystem::constraint_residual(&free, &s);
    let system = BipedOnSevenPoints::new(
        p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12], p[13],
        p[14], p[15], p[16], p[17], p[18], p[19], p[20],
    );
    (system, s)
}

/// `q̇` moved onto `A q̇ = 0` (twice, by the pseudo-inverse of `A`).
fn on_the_surface(system: &BipedOnSevenPoints<f64>, s: &State<f64, N>) -> State<f64, N> {
    let mut qd = s.qd;
    for _ in 0..2 {
        let at = State::new(s.t, s.q, qd);
        let (a, _) = ConstrainedSystem::constraint_matrices(system, &at);
        let pinv = a.pseudo_inverse(1e-12).expect("a pseudo-inverse");
        qd -= pinv * (a * qd);
    }
    State::new(s.t, s.q, qd)
}

/// The points' rows' residual `r = A q̈ − (b + db)` must exert no force
/// and no moment on each foot (`Σ rᵢ = 0`, `Σ (pᵢ − p₀) × rᵢ = 0`: six
/// rows a foot), the quaternion's norm holds, and `M q̈ − F` is a force of
/// those 13 rows: Gauss's principle under them, solved densely.
fn least_squares(
    system: &BipedOnSevenPoints<f64>,
    s: &State<f64, N>,
    db: &SVector<f64, K>,
) -> SVector<f64, N> {
    let (a, b) = ConstrainedSystem::constraint_matrices(system, s);
    let b = b + db;
    let phi = ConstrainedSystem::constraint_residual(system, s);
    let places = [
        system.l0x, system.l0y, system.l0z, system.l1x, system.l1y, system.l1z, system.l2x,
        system.l2y, system.l2z, system.l3x, system.l3y, system.l3z, system.r0x, system.r0y,
        system.r0z, system.r1x, system.r1y, system.r1z, system.r2x, system.r2y, system.r2z,
    ];
    let point = |r: usize| Vector3::from_fn(|c, _| phi[r + c] + places[r + c]);
    let mut rows = SMatrix::<f64, 13, N>::zeros();
    let mut rhs = SVector::<f64, 13>::zeros();
    for (foot, &(first, points)) in FEET.iter().enumerate() {
        for i in 0..points {
            let r = first + 3 * i;
            let arm = point(r) - point(first);
            for c in 0..3 {
                let sum = rows.row(6 * foot + c) + a.row(r + c);
                rows.set_row(6 * foot + c, &sum);
                rhs[6 * foot + c] += b[r + c];
            }
            for j in 0..N {
                let moment = arm.cross(&Vector3::from_fn(|c, _| a[(r + c, j)]));
                for c in 0..3 {
                    rows[(6 * foot + 3 + c, j)] += moment[c];
                }
            }
            let moment = arm.cross(&Vector3::from_fn(|c, _| b[r + c]));
            for c in 0..3 {
                rhs[6 * foot + 3 + c] += moment[c];
            }
        }
    }
    rows.set_row(12, &a.row(NORM));
    rhs[12] = b[NORM];
    let (m, f) = (
        ConstrainedSystem::mass_matrix(system, s),
        ConstrainedSystem::forces(system, s),
    );
    // M is singular (the quaternion), [M Eᵀ; E 0] is not.
    let mut kkt = SMatrix::<f64, 32, 32>::zeros();
    kkt.view_mut((0, 0), (N, N)).copy_from(&m);
    kkt.view_mut((N, 0), (13, N)).copy_from(&rows);
    kkt.view_mut((0, N), (N, 13)).copy_from(&rows.transpose());
    let mut right = SVector::<f64, 32>::zeros();
    right.rows_mut(0, N).copy_from(&f);
    right.rows_mut(N, 13).copy_from(&rhs);
    let solution = kkt
        .full_piv_lu()
        .solve(&right)
        .expect("a regular KKT matrix");
    solution.fixed_rows::<N>(0).into_owned()
}

/// `λ` is the least of the constraint force's: against the runtime's SVD.
fn lambda_gap(system: &BipedOnSevenPoints<f64>, s: &State<f64, N>) -> f64 {
    let (qdd, lambda) = system.acceleration_and_multipliers(s).expect("q̈ and λ");
    let (a, _) = ConstrainedSystem::constraint_matrices(system, s);
    let (m, f) = (
        ConstrainedSystem::mass_matrix(system, s),
        ConstrainedSystem::forces(system, s),
    );
    let least = multipliers(&a, &(m * qdd - f)).expect("λ of Aᵀλ = Fᶜ");
    (lambda - least).amax() / least.amax()
}

/// On the constraint surface (`q̇` projected onto `A q̇ = 0`), the feet's
/// rows are consistent: `A q̈ = b` to 1e-12 (worst 4.7e-15), `q̈` within
/// 1e-10 of the runtime's dense Moore–Penrose solve (5.5e-14) and `λ` of
/// its SVD (2.5e-13), the knees straight in the first state.
#[test]
fn on_the_surface_the_feet_hold_and_lambda_is_the_least() {
    let mut worst = [0.0f64; 3];
    for k in 0..6 {
        let (system, moving) = biped(k);
        let s = on_the_surface(&system, &moving);
        let qdd = ConstrainedSystem::acceleration(&system, &s).expect("a solve");
        let (a, b) = ConstrainedSystem::constraint_matrices(&system, &s);
        let residual = relative_residual(&a, &b, &qdd);
        let dense = ConstrainedSystem::acceleration_moore_penrose(&system, &s).expect("a solve");
        let error = (qdd - dense).amax() / dense.amax();
        let gap = lambda_gap(&system, &s);
        assert!(
            residual <= 1e-12 && error <= 1e-10 && gap <= 1e-10,
            "state {k}: rows to {residual:e}, q̈ {error:e} from the dense solve, λ {gap:e} from the SVD's"
        );
        worst = [
            worst[0].max(residual),
            worst[1].max(error),
            worst[2].max(gap),
        ];
    }
    println!(
        "worst: rows {:e}, q̈ {:e}, λ {:e}",
        worst[0], worst[1], worst[2]
    );
}

/// Off the surface the feet's rows are inconsistent (a turning
/// foot's points accelerate towards its axis, which no rigid acceleration
/// of its held points matches), and the solve reads them in the
/// least-squares sense of the points' accelerations: `q̈` within 1e-10 of
/// that problem solved densely (worst 1.2e-13), `λ` the least of its force
/// (to 1e-10), and a correction `db` of `b` through the same six rows a
/// foot (1e-10). Without the part of the points' rates that no rigid
/// motion gives (`cᴸ`), `q̈` is 0.18 from it.
#[test]
fn off_the_surface_the_points_hold_in_the_least_squares_sense() {
    let mut worst: f64 = 0.0;
    for k in 0..6 {
        let (system, s) = biped(k);
        let qdd = ConstrainedSystem::acceleration(&system, &s).expect("a solve");
        let zero = SVector::<f64, K>::zeros();
        let reference = least_squares(&system, &s, &zero);
        let (a, b) = ConstrainedSystem::constraint_matrices(&system, &s);
        let inconsistency = (a * reference - b).amax() / b.amax();
        assert!(
            inconsistency > 1e-3,
            "state {k}: the rows hold to {inconsistency:e}, which tests no sense"
        );
        let error = (qdd - reference).amax() / reference.amax();
        let gap = lambda_gap(&system, &s);
        let db = SVector::<f64, K>::from_fn(|i, _| wiggle(k + 20, i));
        let corrected = ConstrainedSystem::acceleration_corrected(&system, &s, &db).expect("q̈");
        let expected = least_squares(&system, &s, &db);
        let shifted = (corrected - expected).amax() / expected.amax();
        assert!(
            error <= 1e-10 && gap <= 1e-10 && shifted <= 1e-10,
            "state {k}: q̈ {error:e}, λ {gap:e}, corrected q̈ {shifted:e}"
        );
        worst = worst.max(error).max(shifted);
    }
    println!("worst relative difference from the dense least-squares solve: {worst:e}");
}
