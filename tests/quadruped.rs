//! The quadruped of `examples/support/quadruped.rs` (Solo-12's structure, a
//! floating base, four feet fixed on the ground: 13 rows on 19
//! coordinates): `A q̈ = b` to 1e-12, a fifth dependent row changes no
//! `q̈`, a 10 s standing run under a joint-space PD controller with
//! projection keeps the feet within 1e-9 m, and the feet's forces `λ` carry
//! the robot's weight once it has settled.

#[path = "../examples/support/quadruped.rs"]
#[allow(dead_code)]
#[macro_use]
pub(crate) mod model;

use constrained::floating::FreeMotion;
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{SVector, UnitQuaternion, Vector3};
use constrained::{ConstrainedSystem, DormandPrince45, Stabilization, State};
use model::{Quadruped, FOOT_OFFSET, HIPS, MASS, N, SEGMENT};

quadruped_system!(
    /// The same with a fifth, dependent row: the sum of the front feet's
    /// heights, implied by their own rows (the rank rule drops it).
    QuadrupedFive,
    [position(fl_lower, [0.0, 0.008, -0.16]).z + position(fr_lower, [0.0, -0.008, -0.16]).z == 0.0,]
);

/// The feet's places when standing with hip flexion `θ` and knee `−2θ`
/// (each foot under its hip), and the state there at rest.
pub(crate) fn standing(theta: f64) -> ([f64; 8], State<f64, N>) {
    let mut feet = [0.0; 8];
    for (k, h) in HIPS.iter().enumerate() {
        feet[2 * k] = h[0];
        feet[2 * k + 1] = h[1] + h[1].signum() * FOOT_OFFSET;
    }
    let height = 2.0 * SEGMENT * theta.cos();
    let base = FreeMotion::at_rest(Vector3::new(0.0, 0.0, height), UnitQuaternion::identity());
    let (mut q, mut qd) = (SVector::zeros(), SVector::zeros());
    base.write(0, &mut q, &mut qd).unwrap();
    for leg in 0..4 {
        q[7 + 3 * leg + 1] = theta;
        q[7 + 3 * leg + 2] = -2.0 * theta;
    }
    (feet, State::new(0.0, q, qd))
}

fn robot(feet: [f64; 8]) -> Quadruped<f64> {
    let [a, b, c, d, e, f, g, h] = feet;
    Quadruped::new(
        a, b, c, d, e, f, g, h, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    )
}

/// A tumbling state near standing: joints and base moved, with velocities.
pub(crate) fn perturbed(s: &State<f64, N>, k: usize) -> State<f64, N> {
    let x = k as f64;
    let base = FreeMotion {
        position: Vector3::new(0.01 * x.sin(), -0.02, s.q[2] + 0.01 * x.cos()),
        orientation: UnitQuaternion::from_euler_angles(0.1 * x.sin(), -0.05, 0.2 * x.cos()),
        linear: Vector3::new(0.2 * x.cos(), 0.1, -0.3),
        angular: Vector3::new(0.5, -x.sin(), 0.3),
    };
    let (mut q, mut qd) = (s.q, s.qd);
    base.write(0, &mut q, &mut qd).unwrap();
    for j in 7..N {
        let y = (j as f64) * 1.7 + x;
        q[j] += 0.2 * y.sin();
        qd[j] = 1.5 * (1.3 * y).cos();
    }
    State::new(0.0, q, qd)
}

/// `maxᵢ |Aᵢ q̈ − bᵢ| / (‖Aᵢ‖₁ ‖q̈‖∞ + |bᵢ|)`.
fn residual<const K: usize>(
    a: &constrained::nalgebra::SMatrix<f64, K, N>,
    b: &SVector<f64, K>,
    qdd: &SVector<f64, N>,
) -> f64 {
    let r = a * qdd - b;
    (0..K)
        .map(|i| r[i].abs() / (a.row(i).abs().sum() * qdd.amax() + b[i].abs()))
        .fold(0.0, f64::max)
}

/// At 50 states near standing (base tumbling, joints moving), `q̈`
/// satisfies all 13 rows of `A q̈ = b` to 1e-12, and the twin with a fifth,
/// dependent row (redundancy 1 by the macro's measure) gives the same `q̈`
/// to 1e-12 and satisfies its 14 rows.
#[test]
fn quadruped_satisfies_a_qdd_b_and_a_dependent_row_changes_nothing() {
    let (feet, rest) = standing(0.8);
    let sys = robot(feet);
    let [a, b, c, d, e, f, g, h] = feet;
    let twin = QuadrupedFive::new(
        a, b, c, d, e, f, g, h, 0.3, -0.2, 0.1, 0.3, -0.2, 0.1, 0.3, -0.2, 0.1, 0.3, -0.2, 0.1,
    );
    let mut with_torques = sys;
    [
        with_torques.t_fl_haa,
        with_torques.t_fl_hfe,
        with_torques.t_fl_kfe,
    ] = [0.3, -0.2, 0.1];
    [
        with_torques.t_fr_haa,
        with_torques.t_fr_hfe,
        with_torques.t_fr_kfe,
    ] = [0.3, -0.2, 0.1];
    [
        with_torques.t_hl_haa,
        with_torques.t_hl_hfe,
        with_torques.t_hl_kfe,
    ] = [0.3, -0.2, 0.1];
    [
        with_torques.t_hr_haa,
        with_torques.t_hr_hfe,
        with_torques.t_hr_kfe,
    ] = [0.3, -0.2, 0.1];
    let (mut worst, mut twin_gap, mut twin_rows): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for k in 0..50 {
        let s = perturbed(&rest, k);
        let qdd = ConstrainedSystem::acceleration(&with_torques, &s).unwrap();
        let (am, bm) = ConstrainedSystem::constraint_matrices(&with_torques, &s);
        worst = worst.max(residual(&am, &bm, &qdd));
        let qdd5 = ConstrainedSystem::acceleration(&twin, &s).unwrap();
        twin_gap = twin_gap.max((qdd5 - qdd).amax() / qdd.amax());
        let (a5, b5) = ConstrainedSystem::constraint_matrices(&twin, &s);
        twin_rows = twin_rows.max(residual(&a5, &b5, &qdd5));
    }
    println!(
        "quadruped: A q̈ = b {worst:.1e}; five-row twin: q̈ {twin_gap:.1e}, rows {twin_rows:.1e}"
    );
    assert!(
        worst < 1e-12 && twin_gap < 1e-12 && twin_rows < 1e-12,
        "{worst:e} {twin_gap:e} {twin_rows:e}"
    );
    assert_eq!(
        <Quadruped<f64> as ConstrainedSystem<f64, N, 13>>::REDUNDANCY,
        0
    );
    assert_eq!(
        <QuadrupedFive<f64> as ConstrainedSystem<f64, N, 14>>::REDUNDANCY,
        1
    );
}

/// The generated solve (in the velocity coordinates, each leg through its
/// foot's rows; the twin's by the saddle-point `LDLᵀ`) equals the runtime's dense reference `gauss_dense` on
/// `q̈` and the feet's forces to 1e-12 at 24 states near standing, with
/// and without a correction of `b`, and so does the twin with a fifth,
/// dependent row, whose generated `LDLᵀ` drops a row in its compile-time
/// order where the dense one pivots.
#[test]
fn quadruped_generated_solve_equals_the_dense_reference() {
    let (feet, rest) = standing(0.8);
    let [a, b, c, d, e, f, g, h] = feet;
    let torques = [0.3, -0.2, 0.1];
    let [t1, t2, t3] = torques;
    let sys = Quadruped::new(
        a, b, c, d, e, f, g, h, t1, t2, t3, t1, t2, t3, t1, t2, t3, t1, t2, t3,
    );
    let twin = QuadrupedFive::new(
        a, b, c, d, e, f, g, h, t1, t2, t3, t1, t2, t3, t1, t2, t3, t1, t2, t3,
    );
    let states: Vec<State<f64, N>> = (0..24).map(|k| perturbed(&rest, k)).collect();
    use crate::auxiliary::{against_dense, assert_close};
    assert_close("Quadruped", &against_dense::<_, N, 13>(&sys, &states));
    assert_close(
        "QuadrupedFive (redundant)",
        &against_dense::<_, N, 14>(&twin, &states),
    );
    // The feet's λ from the generated solve (every row kept) against
    // Aᵀλ = Fᶜ solved by the runtime; the twin's (a row dropped) the
    // minimum norm from the solve's factors, against the runtime's.
    use crate::generated_multipliers::multipliers_gap;
    let gap = multipliers_gap::<_, N, 13>(&sys, &states, true);
    println!("Quadruped generated λ vs Aᵀλ = Fᶜ solved: {gap:.1e}");
    assert!(gap < 1e-10, "{gap:e}");
    let gap = multipliers_gap::<_, N, 14>(&twin, &states, true);
    println!("QuadrupedFive minimum-norm λ vs the runtime's: {gap:.1e}");
    assert!(gap < 1e-10, "{gap:e}");
}

/// The generated solve's two paths. Near standing with bent knees it
/// answers itself (each leg through its foot's `J⁻¹`): its `q̈` differs
/// from the dense reference's in the last bits (not bit for bit, as the
/// dense solve's own would) and agrees to 1e-12. With a leg stretched
/// straight (hip and knee flexion 0), that foot's rows no longer fix its
/// joints alone (two of its columns are parallel), its `det J` fails the
/// run-time test, and the runtime's dense solve answers: bit for bit its
/// `q̈`, which still satisfies `A q̈ = b`.
#[test]
fn a_straight_leg_hands_the_solve_to_the_dense_one() {
    let (feet, rest) = standing(0.8);
    let sys = robot(feet);
    let bent: Vec<State<f64, N>> = (0..8).map(|k| perturbed(&rest, k)).collect();
    let mut differs = false;
    for s in &bent {
        let (qdd, _) = constrained::__private::Generated::gauss(&sys, &s.q, &s.qd, s.t, None)
            .expect("answers");
        let (dense, _) =
            constrained::__private::gauss_dense(&sys, &s.q, &s.qd, s.t, None).expect("answers");
        let gap = (qdd - dense).amax() / dense.amax();
        assert!(gap < 1e-12, "{gap:e}");
        differs |= qdd != dense;
    }
    assert!(differs, "the fast path answered none of the bent states");
    // The front-left leg straight (`fl_hfe = fl_kfe = 0`); where its foot
    // is does not matter to the accelerations' solve.
    let s = &bent[0];
    let mut q = s.q;
    q[8] = 0.0;
    q[9] = 0.0;
    let s = State::new(0.0, q, s.qd);
    let (qdd, _) =
        constrained::__private::Generated::gauss(&sys, &s.q, &s.qd, s.t, None).expect("answers");
    let (dense, _) =
        constrained::__private::gauss_dense(&sys, &s.q, &s.qd, s.t, None).expect("answers");
    assert_eq!(qdd, dense, "the dense solve answers for a straight leg");
    let (a, b) = sys.constraint_matrices(&s.q, &s.qd, s.t);
    assert!(residual(&a, &b, &qdd) < 1e-12);
}

/// The generated solve writes the quaternion's `q̈ = ½ (q α + Gᵀ β)`
/// (`constrained_codegen::equations::velocity`), exact wherever `q ≠ 0`:
/// off the unit sphere (`|q|` 0.8 and 1.25, with a rate along `q` itself,
/// so that the norm's row has `b ≠ 0` from both) it still equals the
/// runtime's dense solve of the model's own `M`, `F`, `A`, `b`, with and
/// without a correction of `b` — `q̈` and `Aᵀλ` to 1e-12 — satisfies
/// `A q̈ = b` to 1e-12, and answers every state itself.
#[test]
fn the_velocity_coordinates_are_exact_off_the_unit_sphere() {
    let (feet, rest) = standing(0.8);
    let sys = robot(feet);
    let states: Vec<State<f64, N>> = [0.8, 1.25, 1.0 / 0.8, 0.9]
        .into_iter()
        .enumerate()
        .map(|(k, scale)| {
            let s = perturbed(&rest, k + 3);
            let (mut q, mut qd) = (s.q, s.qd);
            for i in 3..7 {
                qd[i] += 0.3 * q[i];
                q[i] *= scale;
            }
            State::new(0.0, q, qd)
        })
        .collect();
    use crate::auxiliary::{against_dense, assert_close};
    let gaps = against_dense::<_, N, 13>(&sys, &states);
    assert_close("Quadruped off the sphere", &gaps);
    assert_eq!(
        gaps.own, 8,
        "the generated solve answered every state itself"
    );
}

/// Joint-space PD about the standing pose, `τ = K_p (q_ref − q) − K_d q̇`,
/// held over each millisecond: over 10 s with projection (tolerance 1e-12)
/// the feet stay within 1e-9 m of their places, the base quaternion keeps
/// its norm, and once settled the feet's vertical forces carry `m g`.
#[test]
fn quadruped_stands_for_10_s_with_its_feet_in_place() {
    let theta = 0.8;
    let (feet, mut s) = standing(theta);
    let mut sys = robot(feet);
    let reference = s.q;
    // Released at rest in the pose: it sags until the PD holds it.
    let integrator =
        DormandPrince45::new(1e-10, 1e-12).with_stabilization(Stabilization::projection(1e-12));
    let (kp, kd) = (6.0, 0.15);
    let mut worst_foot: f64 = 0.0;
    for step in 1..=10_000 {
        let tau: Vec<f64> = (7..N)
            .map(|j| kp * (reference[j] - s.q[j]) - kd * s.qd[j])
            .collect();
        set_torques(&mut sys, &tau);
        integrator
            .advance(&sys, &mut s, f64::from(step) * 1e-3)
            .expect("integrates");
        worst_foot = worst_foot.max(ConstrainedSystem::constraint_residual(&sys, &s).amax());
    }
    let (_, lambda) = sys.acceleration_and_multipliers(&s).unwrap();
    let normal: f64 = (0..4).map(|k| lambda[3 * k + 2]).sum();
    let weight = MASS * 9.81;
    let norm = (s.q.fixed_rows::<4>(3).norm() - 1.0).abs();
    println!(
        "quadruped standing 10 s: feet within {worst_foot:.1e} m, |q|-1 {norm:.1e}, normal forces {normal:.6} N (m g = {weight:.6}), speed {:.1e}",
        s.qd.amax()
    );
    assert!(worst_foot < 1e-9 && norm < 1e-12, "{worst_foot:e} {norm:e}");
    assert!(s.qd.amax() < 1e-6, "not settled: {}", s.qd.amax());
    assert!((normal - weight).abs() < 1e-6 * weight, "{normal} {weight}");
}

fn set_torques(sys: &mut Quadruped<f64>, tau: &[f64]) {
    [sys.t_fl_haa, sys.t_fl_hfe, sys.t_fl_kfe] = [tau[0], tau[1], tau[2]];
    [sys.t_fr_haa, sys.t_fr_hfe, sys.t_fr_kfe] = [tau[3], tau[4], tau[5]];
    [sys.t_hl_haa, sys.t_hl_hfe, sys.t_hl_kfe] = [tau[6], tau[7], tau[8]];
    [sys.t_hr_haa, sys.t_hr_hfe, sys.t_hr_kfe] = [tau[9], tau[10], tau[11]];
}
