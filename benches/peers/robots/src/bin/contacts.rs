//! The Contacts rows of BENCHMARKS.md: the quadruped of
//! `examples/support/quadruped.rs` standing on its four feet (19
//! coordinates, 13 rows), the Unitree Go1 read from example-robot-data's
//! URDF with a floating root joint standing on its four feet (19
//! coordinates, 13 rows; `build.rs` writes it), a planar five-bar closed
//! by one loop (4 joints, 2 rows) and the Unitree G1 on a floating root on
//! three points of each foot (`g1_standing.rs`) and on two flat feet
//! (`g1_flat.rs`), against Pinocchio's `constraintDynamics`
//! (and `lcaba`) on the same models and states
//! (`benches/peers/contacts.cpp`).
//!
//! ```text
//! contacts write REFERENCE_FILE   # the states and the generated answers
//! contacts time ROUND             # the generated code's times, JSON lines
//! contacts spin SYSTEM WHAT PASSES # only calls, for cachegrind (benches/peers/icache.sh)
//! ```
//!
//! The states are consistent (the quadruped's legs placed by inverse
//! kinematics, the Go1's by Newton's method on its feet's rows, the
//! five-bar's by `project`, all on the constraints at position and
//! velocity level to 1e-13), so that both sides solve the same problem
//! whatever their formulation of the contact acceleration. The record gives
//! them in Pinocchio's coordinates: the base's configuration
//! `(x, y, z, qx, qy, qz, qw)` and its twist in the base's own axes; our
//! `q̈` is turned into Pinocchio's `a` (the base's spatial acceleration in
//! its own axes: `Rᵀ p̈ − ω × v` and `2 (q̄ ⊗ q̈)_vec`), and the feet's `λ`
//! (world axes, the force on the foot: `Q_c = Aᵀ λ`) are written as they
//! are. The Go1's joints follow the base in our order, and the file's first
//! line (`names go1 …`) names them, for Pinocchio's side to place each by
//! its name. Every state's `q̈` is checked against `A q̈ = b` (1e-12) first.
//!
//! For the Go1, `REFERENCE_FILE.derivatives` holds our Jacobians of `q̈` and
//! `λ` (`acceleration_and_multiplier_jacobians`) turned into Pinocchio's conventions
//! (`go1_derivatives.rs`), one matrix a line, after they are checked against
//! central differences of our `q̈` and `λ` turned the same way (to 1e-6), for
//! Pinocchio's side to compare with `computeConstraintDynamicsDerivatives`.

#[path = "../clock.rs"]
mod clock;
#[path = "../g1_flat.rs"]
mod g1_flat;
#[path = "../g1_standing.rs"]
mod g1_standing;
#[path = "../go1_derivatives.rs"]
mod go1_derivatives;
#[path = "../../../../../examples/support/quadruped.rs"]
#[allow(dead_code)]
#[macro_use]
mod model;

use clock::median_ns;
use constrained::floating::FreeMotion;
use constrained::linearize::MultiplierJacobians;
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{Quaternion, SMatrix, SVector, UnitQuaternion, Vector3};
use constrained::stabilize::project;
use constrained::{ConstrainedSystem, Jacobians, State};
use model::{Quadruped, FOOT_OFFSET, HIPS, N};

include!(concat!(env!("OUT_DIR"), "/go1.rs"));
use std::fmt::Write as _;
use std::hint::black_box;

constrained::constrained_system! {
    /// The planar five-bar of `examples/five_bar.rs` (the same bodies),
    /// closed by its loop only and driven by a torque at each joint: the
    /// peers' constraint solvers take loop closures, not driving rows.
    pub struct FiveBarLoop {
        inputs: [tau1, tau2, tau3, tau4],
        bodies: [
            left_proximal {
                joint: revolute(q1, [0.0, 1.0, 0.0]),
                xyz: [-0.1, 0.0, 0.0],
                mass: 0.2,
                com: [0.075, 0.0, 0.0],
                inertia: diag[1.0e-5, 4.0e-4, 4.0e-4],
            },
            left_distal {
                parent: left_proximal,
                joint: revolute(q2, [0.0, 1.0, 0.0]),
                xyz: [0.15, 0.0, 0.0],
                mass: 0.15,
                com: [0.125, 0.0, 0.0],
                inertia: diag[1.0e-5, 8.0e-4, 8.0e-4],
            },
            right_proximal {
                joint: revolute(q3, [0.0, 1.0, 0.0]),
                xyz: [0.1, 0.0, 0.0],
                mass: 0.2,
                com: [0.075, 0.0, 0.0],
                inertia: diag[1.0e-5, 4.0e-4, 4.0e-4],
            },
            right_distal {
                parent: right_proximal,
                joint: revolute(q4, [0.0, 1.0, 0.0]),
                xyz: [0.15, 0.0, 0.0],
                mass: 0.15,
                com: [0.125, 0.0, 0.0],
                inertia: diag[1.0e-5, 8.0e-4, 8.0e-4],
            },
        ],
        forces: [tau1, tau2, tau3, tau4],
        constraints: [
            position(left_distal, [0.25, 0.0, 0.0]).x == position(right_distal, [0.25, 0.0, 0.0]).x,
            position(left_distal, [0.25, 0.0, 0.0]).z == position(right_distal, [0.25, 0.0, 0.0]).z,
        ],
    }
}

/// States per system.
const STATES: usize = 20;

/// splitmix64: reproducible states without a dependency.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    /// Uniform in `[-scale, scale)`.
    pub(crate) fn uniform(&mut self, scale: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        scale * (2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0)
    }
}

/// A floating base about `height` up (within 0.02 m each way), rolled and
/// pitched within `tilt` and turned within `yaw` (radians), moving: the
/// start of every floating system's states.
pub(crate) fn moving_base(rng: &mut Rng, height: f64, (tilt, yaw): (f64, f64)) -> FreeMotion<f64> {
    FreeMotion {
        position: Vector3::new(
            rng.uniform(0.02),
            rng.uniform(0.02),
            height + rng.uniform(0.02),
        ),
        orientation: UnitQuaternion::from_euler_angles(
            rng.uniform(tilt),
            rng.uniform(tilt),
            rng.uniform(yaw),
        ),
        linear: Vector3::new(rng.uniform(0.3), rng.uniform(0.3), rng.uniform(0.3)),
        angular: Vector3::new(rng.uniform(1.0), rng.uniform(1.0), rng.uniform(1.0)),
    }
}

/// The feet's places: each foot under its hip (`tests/quadruped.rs`).
fn feet() -> [f64; 8] {
    let mut feet = [0.0; 8];
    for (k, h) in HIPS.iter().enumerate() {
        feet[2 * k] = h[0];
        feet[2 * k + 1] = h[1] + h[1].signum() * FOOT_OFFSET;
    }
    feet
}

/// The quadruped with joint torques `tau`.
fn quadruped(tau: &[f64; 12]) -> Quadruped<f64> {
    let [a, b, c, d, e, f, g, h] = feet();
    let t = tau;
    Quadruped::new(
        a, b, c, d, e, f, g, h, t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7], t[8], t[9], t[10],
        t[11],
    )
}

/// A standing G1's pose, as both of its rows draw theirs: the pelvis about
/// 0.75 m up, turned and moving, every joint within ±0.3 rad of zero and
/// its rate within ±1 rad/s.
pub(crate) fn g1_pose<const M: usize>(rng: &mut Rng) -> (SVector<f64, M>, SVector<f64, M>) {
    let base = moving_base(rng, 0.75, (0.1, 0.3));
    let (mut q, mut qd) = (SVector::<f64, M>::zeros(), SVector::<f64, M>::zeros());
    base.write(0, &mut q, &mut qd)
        .expect("seven coordinates fit");
    for j in 7..M {
        q[j] = rng.uniform(0.3);
        qd[j] = rng.uniform(1.0);
    }
    (q, qd)
}

/// The state `(q, q̇)` with `q̇` projected onto the null space of the rows of
/// `system` (`A q̇ = 0`, by `pseudo_inverse` of `A`, which the caller
/// writes at its sizes: nalgebra's SVD asks for bounds on the dimensions
/// that `M` and `K` alone do not carry; twice, the second taking what
/// rounding left of the first), checked on them: positions to
/// 1e-14 (where `system` holds the places `q` puts its points), velocities
/// to 1e-12.
pub(crate) fn on_the_rows<S, const M: usize, const K: usize>(
    system: &S,
    (q, mut qd): (SVector<f64, M>, SVector<f64, M>),
    pseudo_inverse: fn(&SMatrix<f64, K, M>) -> SMatrix<f64, M, K>,
) -> State<f64, M>
where
    S: ConstrainedSystem<f64, M, K>,
{
    let at_rest = State::new(0.0, q, SVector::zeros());
    let (a, _) = ConstrainedSystem::constraint_matrices(system, &at_rest);
    let pinv = pseudo_inverse(&a);
    for _ in 0..2 {
        qd -= pinv * (a * qd);
    }
    let s = State::new(0.0, q, qd);
    let position = ConstrainedSystem::constraint_residual(system, &s).amax();
    let velocity = ConstrainedSystem::constraint_velocity_residual(system, &s).amax();
    assert!(
        position < 1e-14 && velocity < 1e-12,
        "{position:e} {velocity:e}"
    );
    s
}

/// `maxᵢ |Aᵢ q̈ − bᵢ| / (‖Aᵢ‖₁ ‖q̈‖∞ + |bᵢ|)`.
pub(crate) fn residual<const K: usize, const M: usize>(
    a: &SMatrix<f64, K, M>,
    b: &SVector<f64, K>,
    qdd: &SVector<f64, M>,
) -> f64 {
    let r = a * qdd - b;
    (0..K)
        .map(|i| r[i].abs() / (a.row(i).abs().sum() * qdd.amax() + b[i].abs()))
        .fold(0.0, f64::max)
}

/// The joints `(haa, hfe, kfe)` of leg `k` that put its foot at `target`
/// (world) with the base at `position`, `attitude`: the leg's closed-form
/// inverse kinematics (knee bent backwards, as standing).
fn leg(
    k: usize,
    position: &Vector3<f64>,
    attitude: &UnitQuaternion<f64>,
    target: &Vector3<f64>,
) -> [f64; 3] {
    let side = HIPS[k][1].signum();
    let hip = Vector3::new(HIPS[k][0], HIPS[k][1], 0.0);
    let d = attitude.inverse() * (target - position) - hip;
    let (y, l) = (side * FOOT_OFFSET, model::SEGMENT);
    let z = -(d.y * d.y + d.z * d.z - y * y).sqrt();
    let haa = d.z.atan2(d.y) - z.atan2(y);
    let cos_knee = (d.x * d.x + z * z - 2.0 * l * l) / (2.0 * l * l);
    let kfe = -cos_knee.clamp(-1.0, 1.0).acos();
    let (u, w) = (-d.x / l, -z / l);
    let hfe = u.atan2(w) - kfe.sin().atan2(1.0 + kfe.cos());
    [haa, hfe, kfe]
}

/// A quadruped state near standing (hip flexion 0.8, knee −1.6): the base
/// moved, turned and moving, the legs placed by inverse kinematics with the
/// feet at their places, the joints' rates from the feet's velocity rows
/// (`A q̇ = 0` solved for the 12 joint rates); random joint torques.
fn quadruped_state(rng: &mut Rng) -> (Quadruped<f64>, State<f64, N>) {
    let base = moving_base(rng, 0.32 * 0.8f64.cos(), (0.15, 0.3));
    let (mut q, mut qd) = (SVector::<f64, N>::zeros(), SVector::<f64, N>::zeros());
    base.write(0, &mut q, &mut qd)
        .expect("seven coordinates fit");
    let places = feet();
    for k in 0..4 {
        let target = Vector3::new(places[2 * k], places[2 * k + 1], 0.0);
        let joints = leg(k, &base.position, &base.orientation, &target);
        for (i, angle) in joints.into_iter().enumerate() {
            q[7 + 3 * k + i] = angle;
        }
    }
    let tau: [f64; 12] = std::array::from_fn(|_| rng.uniform(2.0));
    let system = quadruped(&tau);
    let state = State::new(0.0, q, qd);
    let (a, _) = ConstrainedSystem::constraint_matrices(&system, &state);
    let legs = SMatrix::<f64, 12, 12>::from_fn(|i, j| a[(i, 7 + j)]);
    let driven = -(a.fixed_view::<12, 7>(0, 0) * qd.fixed_rows::<7>(0));
    let rates = legs.lu().solve(&driven).expect("the legs are not singular");
    qd.fixed_rows_mut::<12>(7).copy_from(&rates);
    let state = State::new(0.0, q, qd);
    let position = ConstrainedSystem::constraint_residual(&system, &state).amax();
    let velocity = ConstrainedSystem::constraint_velocity_residual(&system, &state).amax();
    assert!(
        position < 1e-14 && velocity < 1e-13,
        "{position:e} {velocity:e}"
    );
    (system, state)
}

/// The Go1 with its feet at `feet` (`(x, y, z)` each: FL, FR, RL, RR) and
/// joint torques `tau`.
fn go1(feet: &[f64; 12], tau: &[f64; 12]) -> Go1<f64> {
    let (p, t) = (feet, tau);
    Go1::new(
        p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], t[0], t[1], t[2],
        t[3], t[4], t[5], t[6], t[7], t[8], t[9], t[10], t[11],
    )
}

/// The Go1's standing pose: each leg's hip, thigh and calf.
const GO1_POSE: [f64; 3] = [0.0, 0.8, -1.5];

/// Where the Go1's feet stand: under the base at `(0, 0, 0.3)`, level, its
/// legs in [`GO1_POSE`] (the rows' residual with the feet at the origin is
/// each foot's place).
fn go1_feet() -> [f64; 12] {
    let base = FreeMotion::at_rest(Vector3::new(0.0, 0.0, 0.3), UnitQuaternion::identity());
    let (mut q, mut qd) = (SVector::<f64, N>::zeros(), SVector::<f64, N>::zeros());
    base.write(0, &mut q, &mut qd)
        .expect("seven coordinates fit");
    for j in 7..N {
        q[j] = GO1_POSE[(j - 7) % 3];
    }
    let placed = ConstrainedSystem::constraint_residual(
        &go1(&[0.0; 12], &[0.0; 12]),
        &State::new(0.0, q, qd),
    );
    std::array::from_fn(|i| placed[i])
}

/// A Go1 state near standing: the base moved, turned and moving, the legs
/// placed by Newton's method on the feet's rows (from [`GO1_POSE`]) with
/// the feet at [`go1_feet`], the joints' rates from the feet's velocity
/// rows; random joint torques. Its joints are `Go1::COORDINATES[7..]`, in
/// Pinocchio's order of the same file's joints (`constrained_system!`'s
/// `urdf`).
fn go1_state(rng: &mut Rng) -> (Go1<f64>, State<f64, N>) {
    let base = moving_base(rng, 0.3, (0.1, 0.2));
    let (mut q, mut qd) = (SVector::<f64, N>::zeros(), SVector::<f64, N>::zeros());
    base.write(0, &mut q, &mut qd)
        .expect("seven coordinates fit");
    for j in 7..N {
        q[j] = GO1_POSE[(j - 7) % 3];
    }
    let tau: [f64; 12] = std::array::from_fn(|_| rng.uniform(2.0));
    let system = go1(&go1_feet(), &tau);
    for _ in 0..20 {
        let s = State::new(0.0, q, qd);
        let (a, _) = ConstrainedSystem::constraint_matrices(&system, &s);
        let r = ConstrainedSystem::constraint_residual(&system, &s);
        let legs = SMatrix::<f64, 12, 12>::from_fn(|i, j| a[(i, 7 + j)]);
        let step = legs
            .lu()
            .solve(&r.fixed_rows::<12>(0).into_owned())
            .expect("the legs are not singular");
        for j in 0..12 {
            q[7 + j] -= step[j];
        }
    }
    let (a, _) = ConstrainedSystem::constraint_matrices(&system, &State::new(0.0, q, qd));
    let legs = SMatrix::<f64, 12, 12>::from_fn(|i, j| a[(i, 7 + j)]);
    let driven = -(a.fixed_view::<12, 7>(0, 0) * qd.fixed_rows::<7>(0));
    let rates = legs.lu().solve(&driven).expect("the legs are not singular");
    qd.fixed_rows_mut::<12>(7).copy_from(&rates);
    let state = State::new(0.0, q, qd);
    let position = ConstrainedSystem::constraint_residual(&system, &state).amax();
    let velocity = ConstrainedSystem::constraint_velocity_residual(&system, &state).amax();
    assert!(
        position < 1e-14 && velocity < 1e-13,
        "{position:e} {velocity:e}"
    );
    (system, state)
}

/// A five-bar state: the motors' angles about the example's pose, the
/// passive ones by the closure, random rates projected onto it.
fn five_bar_state(rng: &mut Rng) -> (FiveBarLoop<f64>, State<f64, 4>) {
    let q = SVector::from([
        1.9 + rng.uniform(0.2),
        -1.3,
        1.25 + 0.35 * 1.2f64.sin() + rng.uniform(0.2),
        1.3,
    ]);
    let qd = SVector::from_fn(|_, _| rng.uniform(2.0));
    let system = FiveBarLoop::new(
        rng.uniform(0.5),
        rng.uniform(0.5),
        rng.uniform(0.5),
        rng.uniform(0.5),
    );
    let mut state = State::new(0.0, q, qd);
    project(&system, &mut state, 1e-13, 50).expect("the linkage assembles");
    (system, state)
}

pub(crate) fn line<'a>(out: &mut String, name: &str, values: impl Iterator<Item = &'a f64>) {
    let _ = write!(out, "{name}");
    for v in values {
        let _ = write!(out, " {v:.17e}");
    }
    out.push('\n');
}

/// Pinocchio's configuration, velocity and acceleration of a floating
/// base's state and its `q̈` (module docs), the joints in our order.
pub(crate) fn pinocchio_coordinates<const M: usize>(
    s: &State<f64, M>,
    qdd: &SVector<f64, M>,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let base = FreeMotion::read(0, &s.q, &s.qd).expect("a unit quaternion");
    let r = base.orientation;
    let (v, w) = (base.body_linear(), base.body_angular());
    let unit = Quaternion::new(s.q[3], s.q[4], s.q[5], s.q[6]);
    let unit = unit / unit.norm();
    let quat_dd = Quaternion::new(qdd[3], qdd[4], qdd[5], qdd[6]);
    let linear = r.inverse() * Vector3::new(qdd[0], qdd[1], qdd[2]) - w.cross(&v);
    let angular = (unit.conjugate() * quat_dd).imag() * 2.0;
    let quat = r.quaternion();
    let mut config = vec![0.0; M];
    config[..3].copy_from_slice(&[s.q[0], s.q[1], s.q[2]]);
    config[3..7].copy_from_slice(&[quat.i, quat.j, quat.k, quat.w]);
    let (mut velocity, mut acceleration) = (vec![0.0; M - 1], vec![0.0; M - 1]);
    for k in 0..3 {
        velocity[k] = v[k];
        velocity[3 + k] = w[k];
        acceleration[k] = linear[k];
        acceleration[3 + k] = angular[k];
    }
    for j in 7..M {
        config[j] = s.q[j];
        velocity[j - 1] = s.qd[j];
        acceleration[j - 1] = qdd[j];
    }
    (config, velocity, acceleration)
}

/// A column-major matrix's entries (`rows` to a column) row by row.
fn transposed(m: &[f64], rows: usize) -> Vec<f64> {
    let columns = m.len() / rows;
    (0..rows)
        .flat_map(|i| (0..columns).map(move |j| m[j * rows + i]))
        .collect()
}

/// The Go1's Jacobians of `q̈` and `λ` at `s` (whose `q̈` is `qdd`), from
/// `acceleration_and_multiplier_jacobians`, in Pinocchio's conventions.
fn go1_jacobians(
    system: &Go1<f64>,
    s: &State<f64, N>,
    qdd: &SVector<f64, N>,
) -> go1_derivatives::Derivatives {
    let (j, l) = system
        .acceleration_and_multiplier_jacobians(&s.q, &s.qd, s.t)
        .expect("the Go1's Jacobians of q̈ and λ");
    go1_derivatives::pinocchio_derivatives(
        (&s.q, &s.qd, qdd),
        (&j.dq, &j.dqd, &j.du),
        (&l.dq, &l.dqd, &l.du),
    )
}

/// The largest difference, relative to each matrix's largest entry, of
/// `d` from central differences of our `q̈` and `λ` turned into
/// Pinocchio's `a` and feet's forces, along each displacement of `q`, each
/// entry of `v` and each joint torque.
fn go1_differences(system: &Go1<f64>, s: &State<f64, N>, d: &go1_derivatives::Derivatives) -> f64 {
    let h = 1e-6;
    let answer = |sys: &Go1<f64>, q: SVector<f64, N>, qd: SVector<f64, N>| {
        let (qdd, lambda) = sys
            .acceleration_and_multipliers(&State::new(s.t, q, qd))
            .expect("q̈ and λ");
        (
            go1_derivatives::acceleration(&q, &qd, &qdd),
            lambda.fixed_rows::<12>(0).into_owned(),
        )
    };
    let relative = |ours: &[f64], theirs: &[f64]| {
        let scale = theirs.iter().fold(1e-300f64, |m, x| m.max(x.abs()));
        ours.iter()
            .zip(theirs)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale
    };
    let mut worst: f64 = 0.0;
    for dv in [false, true] {
        let (mut da, mut dl) = (
            SMatrix::<f64, 18, 18>::zeros(),
            SMatrix::<f64, 12, 18>::zeros(),
        );
        for c in 0..18 {
            let (qp, qdp) = go1_derivatives::displaced(&s.q, &s.qd, c, h, dv);
            let (qm, qdm) = go1_derivatives::displaced(&s.q, &s.qd, c, -h, dv);
            let (ap, lp) = answer(system, qp, qdp);
            let (am, lm) = answer(system, qm, qdm);
            da.set_column(c, &((ap - am) / (2.0 * h)));
            dl.set_column(c, &((lp - lm) / (2.0 * h)));
        }
        let (ours_a, ours_l) = if dv {
            (&d.da_dv, &d.dl_dv)
        } else {
            (&d.da_dq, &d.dl_dq)
        };
        worst = worst
            .max(relative(ours_a.as_slice(), da.as_slice()))
            .max(relative(ours_l.as_slice(), dl.as_slice()));
    }
    let (mut da, mut dl) = (
        SMatrix::<f64, 18, 12>::zeros(),
        SMatrix::<f64, 12, 12>::zeros(),
    );
    for c in 0..12 {
        let torques = |sign: f64| {
            let mut t = [
                system.t1, system.t2, system.t3, system.t4, system.t5, system.t6, system.t7,
                system.t8, system.t9, system.t10, system.t11, system.t12,
            ];
            t[c] += sign * h;
            go1(&go1_feet(), &t)
        };
        let (ap, lp) = answer(&torques(1.0), s.q, s.qd);
        let (am, lm) = answer(&torques(-1.0), s.q, s.qd);
        da.set_column(c, &((ap - am) / (2.0 * h)));
        dl.set_column(c, &((lp - lm) / (2.0 * h)));
    }
    worst
        .max(relative(d.da_dtau.as_slice(), da.as_slice()))
        .max(relative(d.dl_dtau.as_slice(), dl.as_slice()))
}

/// The records of both systems, checking `A q̈ = b` at every state.
fn write(path: &str) {
    let mut out = String::new();
    let mut rng = Rng(27);
    let mut worst: f64 = 0.0;
    let names = Go1::<f64>::COORDINATES;
    assert_eq!(names[0], "root_joint_x", "the Go1's base comes first");
    let _ = writeln!(out, "names go1 {}", names[7..].join(" "));
    let _ = writeln!(out, "names g1 {}", g1_standing::joints().join(" "));
    for _ in 0..STATES {
        let (system, s) = quadruped_state(&mut rng);
        let (qdd, lambda) = system.acceleration_and_multipliers(&s).expect("q̈ and λ");
        let (a, b) = ConstrainedSystem::constraint_matrices(&system, &s);
        worst = worst.max(residual(&a, &b, &qdd));
        let (config, velocity, acceleration) = pinocchio_coordinates(&s, &qdd);
        let tau: Vec<f64> = [0.0; 6]
            .into_iter()
            .chain([
                system.t_fl_haa,
                system.t_fl_hfe,
                system.t_fl_kfe,
                system.t_fr_haa,
                system.t_fr_hfe,
                system.t_fr_kfe,
                system.t_hl_haa,
                system.t_hl_hfe,
                system.t_hl_kfe,
                system.t_hr_haa,
                system.t_hr_hfe,
                system.t_hr_kfe,
            ])
            .collect();
        let _ = writeln!(out, "quadruped 18");
        line(&mut out, "q", config.iter());
        line(&mut out, "v", velocity.iter());
        line(&mut out, "tau", tau.iter());
        line(&mut out, "a", acceleration.iter());
        line(&mut out, "lambda", lambda.iter().take(12));
        line(&mut out, "feet", feet().iter());
    }
    // The Go1's states from a generator of their own: the others' states
    // stay those they were.
    let mut own = Rng(48);
    let mut worst_derivative: f64 = 0.0;
    // The Go1's Jacobians in Pinocchio's conventions, one matrix a line
    // (`go1 STATE NAME ROWS COLUMNS` and its entries row by row), in a file
    // of their own beside the reference.
    let mut derivatives = String::new();
    for go1_index in 0..STATES {
        let (system, s) = go1_state(&mut own);
        let (qdd, lambda) = system.acceleration_and_multipliers(&s).expect("q̈ and λ");
        let (a, b) = ConstrainedSystem::constraint_matrices(&system, &s);
        worst = worst.max(residual(&a, &b, &qdd));
        let (config, velocity, acceleration) = pinocchio_coordinates(&s, &qdd);
        let tau = [0.0; 6].into_iter().chain([
            system.t1, system.t2, system.t3, system.t4, system.t5, system.t6, system.t7, system.t8,
            system.t9, system.t10, system.t11, system.t12,
        ]);
        let feet = [
            system.fl_x,
            system.fl_y,
            system.fl_z,
            system.fr_x,
            system.fr_y,
            system.fr_z,
            system.rl_x,
            system.rl_y,
            system.rl_z,
            system.rr_x,
            system.rr_y,
            system.rr_z,
        ];
        let _ = writeln!(out, "go1 18");
        line(&mut out, "q", config.iter());
        line(&mut out, "v", velocity.iter());
        line(&mut out, "tau", tau.collect::<Vec<_>>().iter());
        line(&mut out, "a", acceleration.iter());
        line(&mut out, "lambda", lambda.iter().take(12));
        line(&mut out, "feet", feet.iter());
        let d = go1_jacobians(&system, &s, &qdd);
        worst_derivative = worst_derivative.max(go1_differences(&system, &s, &d));
        let matrices = [
            ("dadq", 18, d.da_dq.as_slice()),
            ("dadv", 18, d.da_dv.as_slice()),
            ("dadtau", 18, d.da_dtau.as_slice()),
            ("dldq", 12, d.dl_dq.as_slice()),
            ("dldv", 12, d.dl_dv.as_slice()),
            ("dldtau", 12, d.dl_dtau.as_slice()),
        ];
        for (name, rows, m) in matrices {
            let _ = write!(
                derivatives,
                "go1 {go1_index} {name} {rows} {}",
                m.len() / rows
            );
            line(&mut derivatives, "", transposed(m, rows).iter());
        }
    }
    assert!(
        worst_derivative < 1e-6,
        "the Go1's Jacobians in Pinocchio's conventions differ from central differences by {worst_derivative:e}"
    );
    eprintln!("contacts: the Go1's Jacobians within {worst_derivative:.1e} of central differences");
    for _ in 0..STATES {
        let (system, s) = five_bar_state(&mut rng);
        let (qdd, lambda) = system.acceleration_and_multipliers(&s).expect("q̈ and λ");
        let (a, b) = ConstrainedSystem::constraint_matrices(&system, &s);
        worst = worst.max(residual(&a, &b, &qdd));
        let tau = [system.tau1, system.tau2, system.tau3, system.tau4];
        let _ = writeln!(out, "five_bar 4");
        line(&mut out, "q", s.q.iter());
        line(&mut out, "v", s.qd.iter());
        line(&mut out, "tau", tau.iter());
        line(&mut out, "a", qdd.iter());
        line(&mut out, "lambda", lambda.iter());
    }
    assert!(worst < 1e-12, "A q̈ = b only to {worst:e}");
    eprintln!("contacts: A q̈ = b to {worst:.1e} at every state");
    g1_standing::write(&mut out);
    g1_flat::write(&mut out);
    std::fs::write(path, out).expect("writes the reference file");
    std::fs::write(format!("{path}.derivatives"), derivatives)
        .expect("writes the derivatives beside the reference file");
}

/// Times `acceleration` and `acceleration_and_multipliers` over `cases`
/// (per state), and the generated parts the first is made of (`M`, `F`,
/// `A` and `b`); one JSON line each.
fn time<S, const M: usize, const K: usize>(name: &str, round: &str, cases: &[(S, State<f64, M>)])
where
    S: ConstrainedSystem<f64, M, K> + Multipliers<f64, M, K>,
{
    let per_state = |ns: f64| ns / cases.len() as f64;
    let acceleration = median_ns(|| {
        for (system, s) in cases {
            let _ = black_box(ConstrainedSystem::acceleration(
                black_box(system),
                black_box(s),
            ));
        }
    });
    let both = median_ns(|| {
        for (system, s) in cases {
            let _ = black_box(black_box(system).acceleration_and_multipliers(black_box(s)));
        }
    });
    // Where the time of `acceleration` goes (the generated solve of the
    // auxiliary system takes the rest): the generated M, F and A, b.
    let mass = median_ns(|| {
        for (system, s) in cases {
            black_box(ConstrainedSystem::mass_matrix(
                black_box(system),
                black_box(s),
            ));
        }
    });
    let forces = median_ns(|| {
        for (system, s) in cases {
            black_box(ConstrainedSystem::forces(black_box(system), black_box(s)));
        }
    });
    let rows = median_ns(|| {
        for (system, s) in cases {
            black_box(ConstrainedSystem::constraint_matrices(
                black_box(system),
                black_box(s),
            ));
        }
    });
    for (what, ns) in [
        ("acceleration", acceleration),
        ("acceleration_and_multipliers", both),
        ("mass_matrix", mass),
        ("forces", forces),
        ("constraint_matrices", rows),
    ] {
        println!(
            "{{\"peer\": \"constrained\", \"what\": \"{what}\", \"system\": \"{name}\", \"n\": {M}, \
             \"rows\": {K}, \"ns\": {:.3}, \"states\": {}, \"round\": {round}, \"ok\": true}}",
            per_state(ns),
            cases.len()
        );
    }
}

/// Times the Go1's `acceleration_and_multiplier_jacobians_to` (per state;
/// in our coordinates, the conversion to Pinocchio's not included), against
/// `computeConstraintDynamicsDerivatives`; one JSON line.
fn time_go1_derivatives(round: &str, cases: &[(Go1<f64>, State<f64, N>)]) {
    // Into outputs kept from call to call, as Pinocchio keeps its `Data`
    // (and the Kinematics table's `acceleration_jacobian_to`): the 13 KB
    // pair of Jacobians is neither cleared nor copied out of a `Result`.
    let (mut jac, mut lambdas) = (Jacobians::zeros(), MultiplierJacobians::zeros());
    let both = median_ns(|| {
        for (system, s) in cases {
            let answer = black_box(system).acceleration_and_multiplier_jacobians_to(
                black_box(&s.q),
                black_box(&s.qd),
                s.t,
                &mut jac,
                &mut lambdas,
            );
            black_box((&answer, &jac, &lambdas));
        }
    });
    println!(
        "{{\"peer\": \"constrained\", \"what\": \"acceleration_and_multiplier_jacobians\", \
         \"system\": \"go1\", \"n\": {N}, \"rows\": 13, \"ns\": {:.3}, \"states\": {}, \
         \"round\": {round}, \"ok\": true}}",
        both / cases.len() as f64,
        cases.len()
    );
}

/// `passes` passes over `cases` calling `what` (`acceleration`,
/// `constraint_matrices` or `acceleration_and_multipliers`) and nothing
/// else: the loop that
/// `benches/peers/icache.sh` runs under cachegrind, once with no pass (the
/// set-up alone) and once with some, so that the difference is the calls'.
pub(crate) fn spin<S, const M: usize, const K: usize>(
    what: &str,
    passes: usize,
    cases: &[(S, State<f64, M>)],
) where
    S: ConstrainedSystem<f64, M, K> + Multipliers<f64, M, K>,
{
    for _ in 0..passes {
        for (system, s) in cases {
            if what == "acceleration" {
                let _ = black_box(ConstrainedSystem::acceleration(
                    black_box(system),
                    black_box(s),
                ));
            } else if what == "constraint_matrices" {
                black_box(ConstrainedSystem::constraint_matrices(
                    black_box(system),
                    black_box(s),
                ));
            } else {
                let _ = black_box(black_box(system).acceleration_and_multipliers(black_box(s)));
            }
        }
    }
}

/// `contacts spin SYSTEM WHAT PASSES`: the states of `SYSTEM` (as `time`
/// makes them), then [`spin`]; for the Go1, `WHAT` may also be
/// `jacobians` (`acceleration_and_multiplier_jacobians_to`) or
/// `qdd_jacobian` (`acceleration_jacobian`), for a profiler.
fn spin_system(system: &str, what: &str, passes: usize) {
    match system {
        "quadruped" => {
            let mut rng = Rng(27);
            let cases: Vec<_> = (0..STATES).map(|_| quadruped_state(&mut rng)).collect();
            spin::<_, N, 13>(what, passes, &cases);
        }
        "go1" => {
            let mut own = Rng(48);
            let cases: Vec<_> = (0..STATES).map(|_| go1_state(&mut own)).collect();
            if what == "qdd_jacobian" || what == "jacobians" {
                let (mut jac, mut lambdas) = (Jacobians::zeros(), MultiplierJacobians::zeros());
                for _ in 0..passes {
                    for (system, s) in &cases {
                        let (system, q, qd) =
                            (black_box(system), black_box(&s.q), black_box(&s.qd));
                        if what == "jacobians" {
                            let answer = system.acceleration_and_multiplier_jacobians_to(
                                q,
                                qd,
                                s.t,
                                &mut jac,
                                &mut lambdas,
                            );
                            black_box((&answer, &jac, &lambdas));
                        } else {
                            black_box(&system.acceleration_jacobian(q, qd, s.t));
                        }
                    }
                }
            } else {
                spin::<_, N, 13>(what, passes, &cases);
            }
        }
        "five_bar" => {
            // `time` draws the quadruped's states from this generator
            // first: drawn here too, the five-bar's states are the same.
            let mut rng = Rng(27);
            let _: Vec<_> = (0..STATES).map(|_| quadruped_state(&mut rng)).collect();
            let cases: Vec<_> = (0..STATES).map(|_| five_bar_state(&mut rng)).collect();
            spin::<_, 4, 2>(what, passes, &cases);
        }
        "g1_points" => g1_standing::spin(what, passes),
        "g1_flat" => spin::<_, 36, { g1_flat::K }>(what, passes, &g1_flat::states()),
        _ => {
            eprintln!("contacts spin: no system {system}");
            std::process::exit(2);
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match (args.get(1).map(String::as_str), args.get(2)) {
        (Some("write"), Some(path)) => write(path),
        (Some("time"), Some(round)) => {
            let mut rng = Rng(27);
            let quadrupeds: Vec<_> = (0..STATES).map(|_| quadruped_state(&mut rng)).collect();
            let mut own = Rng(48);
            let go1s: Vec<_> = (0..STATES).map(|_| go1_state(&mut own)).collect();
            let five_bars: Vec<_> = (0..STATES).map(|_| five_bar_state(&mut rng)).collect();
            time::<_, N, 13>("quadruped", round, &quadrupeds);
            time::<_, N, 13>("go1", round, &go1s);
            time_go1_derivatives(round, &go1s);
            time::<_, 4, 2>("five_bar", round, &five_bars);
            g1_standing::time(round);
            time::<_, 36, { g1_flat::K }>("g1_flat", round, &g1_flat::states());
        }
        (Some("spin"), Some(system)) => {
            let (Some(what), Some(Ok(passes))) = (args.get(3), args.get(4).map(|p| p.parse()))
            else {
                eprintln!("usage: contacts spin SYSTEM WHAT PASSES");
                std::process::exit(2);
            };
            spin_system(system, what, passes);
        }
        _ => {
            eprintln!(
                "usage: contacts write REFERENCE_FILE | contacts time ROUND | contacts spin SYSTEM WHAT PASSES"
            );
            std::process::exit(2);
        }
    }
}
