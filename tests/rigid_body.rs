//! Rigid bodies in unit quaternions: a positive semi-definite mass matrix
//! (`M = 4 GᵀJG`, rank 3) completed by the unit-norm constraint, solved
//! through Udwadia & Schutte's auxiliary mass. Checked against Euler's
//! equations, conservation laws and the heavy top's steady precession.

use constrained::models::{
    quaternion_rate_matrix as g_matrix, quaternion_state, HeavyTop, RigidBodyQuaternion,
};
use constrained::nalgebra::{Matrix3, Vector3, Vector4};
use constrained::{DormandPrince45, DynamicsError, Stabilization, State};

/// Body → world rotation of a unit quaternion (Hamilton).
fn rotation(e: &Vector4<f64>) -> Matrix3<f64> {
    let (w, x, y, z) = (e[0], e[1], e[2], e[3]);
    Matrix3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// A consistent state from a quaternion and a body angular velocity.
fn state(e: Vector4<f64>, omega: Vector3<f64>) -> State<f64, 4> {
    quaternion_state(0.0, e, omega)
}

struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// At 200 random consistent states, `q̈` of all three forms maps to the
/// `ω̇ = 2 (G ë + G(ė) ė)` that Euler's equations `J ω̇ = −ω × Jω` give.
#[test]
fn quaternion_accelerations_satisfy_eulers_equations() {
    let mut rng = Rng(3);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let j = Vector3::new(
            rng.uniform(0.5, 2.0),
            rng.uniform(0.5, 2.0),
            rng.uniform(0.5, 2.0),
        );
        let body = RigidBodyQuaternion::new(j[0], j[1], j[2]);
        let e = Vector4::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        let omega = Vector3::new(
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
        );
        let s = state(e, omega);
        let inertia = Matrix3::from_diagonal(&j);
        let euler = inertia.try_inverse().unwrap() * (-omega.cross(&(inertia * omega)));
        let forms = [
            s.acceleration(&body).expect("generalized inverse"),
            s.acceleration_gibbs_appell(&body).expect("Gibbs–Appell"),
            s.acceleration_moore_penrose(&body).expect("Moore–Penrose"),
        ];
        for qdd in forms {
            let omega_dot = 2.0 * (g_matrix(&s.q) * qdd + g_matrix(&s.qd) * s.qd);
            let error = (omega_dot - euler).amax() / (1.0 + euler.amax());
            worst = worst.max(error);
            // The norm constraint at acceleration level: eᵀë + ėᵀė = 0.
            assert!((s.q.dot(&qdd) + s.qd.dot(&s.qd)).abs() < 1e-12);
        }
    }
    println!("Euler's equations vs the three forms, 200 states: {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// Torque-free over 100 s: energy and the angular momentum in the world
/// frame are conserved.
#[test]
fn torque_free_body_conserves_energy_and_angular_momentum() {
    let j = Vector3::new(1.0, 2.0, 3.0);
    let body = RigidBodyQuaternion::new(j[0], j[1], j[2]);
    // Near the unstable middle axis: the body tumbles.
    let mut s = state(
        Vector4::new(1.0, 0.2, -0.1, 0.3),
        Vector3::new(0.05, 2.0, 0.05),
    );
    let measure = |s: &State<f64, 4>| {
        let omega = 2.0 * g_matrix(&s.q) * s.qd;
        let jw = Matrix3::from_diagonal(&j) * omega;
        (0.5 * omega.dot(&jw), rotation(&s.q) * jw)
    };
    let (e0, l0) = measure(&s);
    DormandPrince45::new(1e-12, 1e-12)
        .with_stabilization(Stabilization::projection(1e-13))
        .advance(&body, &mut s, 100.0)
        .expect("integrates");
    let (e1, l1) = measure(&s);
    let (de, dl) = ((e1 - e0).abs() / e0, (l1 - l0).norm() / l0.norm());
    println!("torque-free body over 100 s: energy {de:.1e}, angular momentum {dl:.1e} (relative)");
    assert!(de < 1e-10 && dl < 1e-10, "{de:e} {dl:e}");
}

/// A heavy symmetric top started in steady precession keeps its tilt and
/// precesses at the classical rate, the slow root of
/// `A Ω² cos θ − C ω₃ Ω + m g l = 0`.
#[test]
fn heavy_top_precesses_at_the_classical_rate() {
    let (a, c, m, g, l) = (0.5, 0.2, 1.0, 9.81, 0.3);
    let top = HeavyTop::new(a, c, m, g, l);
    let (theta, spin): (f64, f64) = (0.5, 40.0);
    let (p, q) = (a * theta.cos(), c * spin);
    let omega_p = (q - (q * q - 4.0 * p * m * g * l).sqrt()) / (2.0 * p);
    // Euler angles (z-x-z) φ = 0, θ, ψ = 0: e = (cos θ/2, sin θ/2, 0, 0);
    // body angular velocity (0, Ω sin θ, ω₃).
    let e = Vector4::new((theta / 2.0).cos(), (theta / 2.0).sin(), 0.0, 0.0);
    let mut s = state(e, Vector3::new(0.0, omega_p * theta.sin(), spin));
    let t_end = 2.0;
    let mut worst_tilt: f64 = 0.0;
    DormandPrince45::new(1e-12, 1e-12)
        .with_stabilization(Stabilization::projection(1e-13))
        .advance_with(&top, &mut s, t_end, |s| {
            let axis = rotation(&s.q).column(2).into_owned();
            worst_tilt = worst_tilt.max((axis.z.acos() - theta).abs());
        })
        .expect("integrates");
    let axis = rotation(&s.q).column(2).into_owned();
    // The axis is (sin θ sin φ, −sin θ cos φ, cos θ).
    let phi = axis.x.atan2(-axis.y);
    let expected = omega_p * t_end;
    println!(
        "heavy top: Ω = {omega_p:.6} rad/s; φ({t_end} s) = {phi:.9} vs Ω t = {expected:.9}; tilt kept to {worst_tilt:.1e} rad"
    );
    assert!(worst_tilt < 1e-8, "{worst_tilt:e}");
    assert!(
        (phi - expected).abs() < 1e-8 * expected.abs().max(1.0),
        "{phi} vs {expected}"
    );
}

/// Where `[M; A]` loses rank (`e = 0`: `M = 0` and `A = 2eᵀ = 0`) the
/// acceleration is an error, not NaN.
#[test]
fn rank_deficient_mass_and_constraints_is_an_error() {
    let body = RigidBodyQuaternion::new(1.0, 2.0, 3.0);
    let s = State::new(0.0, Vector4::zeros(), Vector4::new(0.1, 0.2, 0.3, 0.4));
    assert_eq!(
        s.acceleration(&body),
        Err(DynamicsError::MassNotPositiveDefinite)
    );
    assert!(s.acceleration_moore_penrose(&body).is_err());
}

/// A coin rolling in steady motion — constant tilt θ, heading rate Ω, spin
/// `ω₃ = ψ̇ + Ω cos θ` — satisfies the classical condition
/// `(C + m r²) ω₃ Ω sin θ − A Ω² sin θ cos θ + m g r cos θ = 0`
/// (Newton–Euler about the centre in the frame of the disk without spin).
/// Started on it, the macro's disk keeps θ and Ω; started slightly off it
/// (ω₃ 1 % too small), θ moves by far more.
#[test]
fn rolling_disk_keeps_its_steady_motion() {
    use constrained::models::RollingDisk;
    use constrained::nalgebra::SVector;
    let (m, r, g) = (0.2, 0.1, 9.81);
    let (a, c) = (m * r * r / 4.0, m * r * r / 2.0);
    let disk = RollingDisk::new(m, r, a, c, g);
    let (theta, omega): (f64, f64) = (1.3, 3.0);
    let steady_w3 = (a * omega * omega * theta.sin() * theta.cos() - m * g * r * theta.cos())
        / ((c + m * r * r) * omega * theta.sin());
    let run = |w3: f64| {
        let psid = w3 - omega * theta.cos();
        let phi: f64 = 0.4;
        // ω and u at this state; the centre velocity from v = r ω × u.
        let w = Vector3::new(
            psid * theta.sin() * phi.sin(),
            -psid * theta.sin() * phi.cos(),
            omega + psid * theta.cos(),
        );
        let u = Vector3::new(
            -theta.cos() * phi.sin(),
            theta.cos() * phi.cos(),
            theta.sin(),
        );
        let v = r * w.cross(&u);
        let q = SVector::<f64, 5>::from([0.0, 0.0, theta, phi, 0.0]);
        let qd = SVector::<f64, 5>::from([v.x, v.y, 0.0, omega, psid]);
        let mut s = State::new(0.0, q, qd);
        let mut worst: f64 = 0.0;
        DormandPrince45::new(1e-12, 1e-13)
            .advance_with(&disk, &mut s, 3.0, |s| {
                worst = worst.max((s.q[2] - theta).abs())
            })
            .expect("integrates");
        (worst, (s.qd[3] - omega).abs())
    };
    let (tilt, rate) = run(steady_w3);
    let (off_tilt, _) = run(0.99 * steady_w3);
    println!(
        "rolling disk, ω₃ = {steady_w3:.6} rad/s: tilt kept to {tilt:.1e} rad, heading rate to {rate:.1e} rad/s \
         over 3 s (1 % off the condition: tilt moves {off_tilt:.1e} rad)"
    );
    assert!(tilt < 1e-8 && rate < 1e-8, "{tilt:e} {rate:e}");
    assert!(off_tilt > 1e3 * tilt.max(1e-12), "{off_tilt:e}");
}
