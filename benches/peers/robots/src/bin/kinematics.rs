//! The Kinematics and derivatives rows of BENCHMARKS.md: what a robot
//! controller calls, generated from example-robot-data's URDFs as written
//! with a `frames:` section (build.rs's `FRAMED` table: the Panda with a
//! tool point on its hand, the Unitree G1 with a sole and a palm, the
//! Unitree Go1 with a frame under each foot; all fixed base), against
//! Pinocchio on the same files (`benches/peers/kinematics.cpp`).
//!
//! ```text
//! kinematics write REFERENCE_FILE
//! kinematics time ROUND
//! kinematics spin ROBOT WHAT PASSES # only calls, for a profiler
//! ```
//!
//! `write` writes, per robot, a header (`robot NAME N`, then `urdf` with
//! the file under example-robot-data's `robots` directory, `locked` with
//! the joints held at zero, `names` with `COORDINATES`, the order of every
//! vector and of every matrix's columns below, and one `frame NAME BODY x y
//! z roll pitch yaw` per frame: the frame's link and its place there, as
//! the `frames:` section writes it) and 20 pseudo-random states, each
//! `state` followed by the lines `q`, `v`, `tau` (the joint torques, the
//! system's inputs), and per frame `k` `placement:k` (`R` row by row, then
//! `p`), `jacobian:k` (6 × n, row by row), `velocity:k` and `bias:k` (the
//! classical acceleration at `q̈ = 0`); then `com`, `com_jacobian` (3 × n),
//! `dq`, `dv`, `dtau` (`acceleration_jacobian`'s `∂q̈/∂q`, `∂q̈/∂q̇`,
//! `∂q̈/∂τ`, n × n each, row by row), `com_velocity`, `centroidal_map`
//! (6 × n), `centroidal_bias` (`Ȧ_G q̇`), and `a`, `dtau_dq`, `dtau_dv`
//! (`inverse_dynamics_jacobian` at `(q, q̇, a)`, n × n each). The answers
//! are checked against each other first: `J q̇` is the velocity, `∂q̈/∂τ`
//! is `M⁻¹`, `ċ` is `J_c q̇`, `A_G`'s linear rows are `m J_c`, and `Ȧ_G q̇`
//! and `∂τ` are their central differences.
//!
//! `time` times, over the same states and with the statistic of the other
//! rows (`clock.rs`: the median of 31 batches of about 5 ms, per state, on
//! the thread's CPU clock), the first frame's placement, Jacobian and
//! acceleration bias, the centre of mass with its Jacobian, its velocity,
//! the centroidal map and its bias, `∂τ` and `∂q̈`; one JSON line each,
//! tagged with its round. A quantity is one entry of `frame_times` or
//! `whole_times` here and one of `kinematics.cpp`'s `QUANTITIES`.

#[path = "../clock.rs"]
mod clock;

use clock::median_ns;
use constrained::linearize::Jacobians;
use constrained::nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use std::fmt::Write as _;
use std::hint::black_box;

type Vector<const N: usize> = SVector<f64, N>;
type Matrix<const N: usize> = SMatrix<f64, N, N>;

/// A frame of the `frames:` section, as build.rs's table writes it.
struct Frame {
    name: &'static str,
    body: &'static str,
    xyz: [f64; 3],
    rpy: [f64; 3],
}

/// A robot read from URDF with frames: build.rs writes the implementation
/// of each, from its table, next to its `constrained_system!`.
trait Framed<const N: usize>: Sized {
    /// The reference file's name of the robot.
    const NAME: &'static str;
    /// Its file under example-robot-data's `robots` directory.
    const FILE: &'static str;
    /// The joints held at zero (`locked:`).
    const LOCKED: &'static [&'static str];
    /// The `frames:` section.
    const FRAMES: &'static [Frame];
    /// `COORDINATES`: the joints' names, in the order of `q`.
    fn names() -> [&'static str; N];
    /// The system with one torque per joint.
    fn with_torques(tau: &Vector<N>) -> Self;
    /// `{frame}_placement` of `FRAMES[frame]`, and so on.
    fn placement(&self, frame: usize, q: &Vector<N>) -> (Matrix3<f64>, Vector3<f64>);
    fn jacobian(&self, frame: usize, q: &Vector<N>) -> SMatrix<f64, 6, N>;
    fn velocity(&self, frame: usize, q: &Vector<N>, v: &Vector<N>) -> SVector<f64, 6>;
    fn bias(&self, frame: usize, q: &Vector<N>, v: &Vector<N>) -> SVector<f64, 6>;
    fn com(&self, q: &Vector<N>) -> Vector3<f64>;
    fn com_jacobian(&self, q: &Vector<N>) -> SMatrix<f64, 3, N>;
    /// Both in one call, as Pinocchio's `jacobianCenterOfMass` gives them.
    fn com_and_jacobian(&self, q: &Vector<N>) -> (Vector3<f64>, SMatrix<f64, 3, N>);
    /// `center_of_mass_velocity`, `centroidal_map`, `centroidal_map_bias`.
    fn com_velocity(&self, q: &Vector<N>, v: &Vector<N>) -> Vector3<f64>;
    fn centroidal(&self, q: &Vector<N>) -> SMatrix<f64, 6, N>;
    fn centroidal_bias(&self, q: &Vector<N>, v: &Vector<N>) -> SVector<f64, 6>;
    /// `inverse_dynamics` and `inverse_dynamics_jacobian`.
    fn tau(&self, q: &Vector<N>, v: &Vector<N>, a: &Vector<N>) -> Vector<N>;
    fn tau_jacobian(&self, q: &Vector<N>, v: &Vector<N>, a: &Vector<N>) -> (Matrix<N>, Matrix<N>);
    /// `inverse_dynamics_jacobian_to`: the same into `out`.
    fn tau_jacobian_to(
        &self,
        q: &Vector<N>,
        v: &Vector<N>,
        a: &Vector<N>,
        out: &mut (Matrix<N>, Matrix<N>),
    );
    fn mass(&self, q: &Vector<N>) -> Matrix<N>;
    /// `acceleration_jacobian`, `∂q̈/∂u` being `∂q̈/∂τ`.
    fn derivatives(&self, q: &Vector<N>, v: &Vector<N>) -> Jacobians<f64, N, N>;
    /// `acceleration_jacobian_to`: the same into `out`.
    fn derivatives_to(&self, q: &Vector<N>, v: &Vector<N>, out: &mut Jacobians<f64, N, N>);
}

/// Something done to every robot (`framed`, which build.rs writes).
trait Visit {
    fn robot<R: Framed<N>, const N: usize>(&mut self);
}

/// A generated method's answer, plain or `Result`.
trait Value<T> {
    fn value(self) -> T;
}

impl<T, E: std::fmt::Debug> Value<T> for Result<T, E> {
    #[inline(always)]
    fn value(self) -> T {
        self.expect("the generated answer")
    }
}

impl<const R: usize, const C: usize> Value<SMatrix<f64, R, C>> for SMatrix<f64, R, C> {
    #[inline(always)]
    fn value(self) -> Self {
        self
    }
}

impl<const N: usize> Value<Jacobians<f64, N, N>> for Jacobians<f64, N, N> {
    #[inline(always)]
    fn value(self) -> Self {
        self
    }
}

include!(concat!(env!("OUT_DIR"), "/kinematics.rs"));

/// States per robot.
const STATES: usize = 20;

/// splitmix64: reproducible states without a dependency.
struct Rng(u64);

impl Rng {
    /// Uniform in `[-scale, scale)`.
    fn uniform(&mut self, scale: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        scale * (2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0)
    }

    fn vector<const N: usize>(&mut self, scale: f64) -> SVector<f64, N> {
        SVector::from_fn(|_, _| self.uniform(scale))
    }
}

/// One state: joint angles, rates, torques and the accelerations at
/// which inverse dynamics is differentiated.
struct Sample<const N: usize> {
    q: Vector<N>,
    v: Vector<N>,
    tau: Vector<N>,
    a: Vector<N>,
}

/// Angles, rates and accelerations within ±1 (rad, rad/s, rad/s²),
/// torques within ±10 N m.
fn samples<const N: usize>(rng: &mut Rng) -> Vec<Sample<N>> {
    (0..STATES)
        .map(|_| Sample {
            q: rng.vector(1.0),
            v: rng.vector(1.0),
            tau: rng.vector(10.0),
            a: rng.vector(1.0),
        })
        .collect()
}

fn line<'a>(out: &mut String, name: &str, values: impl Iterator<Item = &'a f64>) {
    let _ = write!(out, "{name}");
    for v in values {
        let _ = write!(out, " {v:.17e}");
    }
    out.push('\n');
}

/// A matrix row by row (nalgebra iterates column by column).
fn rows<const R: usize, const C: usize>(out: &mut String, name: &str, m: &SMatrix<f64, R, C>) {
    line(out, name, m.transpose().iter());
}

/// `write`: the records of every robot, its answers checked against each
/// other first.
struct Write {
    rng: Rng,
    out: String,
}

impl Write {
    /// The lines of one state.
    fn state<R: Framed<N>, const N: usize>(&mut self, s: &Sample<N>) {
        let system = R::with_torques(&s.tau);
        let out = &mut self.out;
        out.push_str("state\n");
        line(out, "q", s.q.iter());
        line(out, "v", s.v.iter());
        line(out, "tau", s.tau.iter());
        for k in 0..R::FRAMES.len() {
            let (r, p) = system.placement(k, &s.q);
            let j = system.jacobian(k, &s.q);
            let twist = system.velocity(k, &s.q, &s.v);
            let worst = (j * s.v - twist).amax() / twist.amax();
            assert!(
                worst < 1e-12,
                "{}: J q̇ is not the velocity ({worst:e})",
                R::NAME
            );
            line(
                out,
                &format!("placement:{k}"),
                r.transpose().iter().chain(p.iter()),
            );
            rows(out, &format!("jacobian:{k}"), &j);
            line(out, &format!("velocity:{k}"), twist.iter());
            line(out, &format!("bias:{k}"), system.bias(k, &s.q, &s.v).iter());
        }
        // The answers Pinocchio checks are the one-pass method's, which the
        // row times; each alone must give the same.
        let (com, jc) = system.com_and_jacobian(&s.q);
        let apart =
            relative(&system.com(&s.q), &com).max(relative(&system.com_jacobian(&s.q), &jc));
        assert!(
            apart < 1e-14,
            "{}: (c, J_c) at once differ from each alone ({apart:e})",
            R::NAME
        );
        line(out, "com", com.iter());
        rows(out, "com_jacobian", &jc);
        let d = system.derivatives(&s.q, &s.v);
        let worst = (d.du * system.mass(&s.q) - Matrix::<N>::identity()).amax();
        assert!(worst < 1e-10, "{}: ∂q̈/∂τ is not M⁻¹ ({worst:e})", R::NAME);
        rows(out, "dq", &d.dq);
        rows(out, "dv", &d.dqd);
        rows(out, "dtau", &d.du);
        centroidal(out, &system, s);
        inverse(out, &system, s);
    }
}

/// The relative difference of `a` from `b`, by their largest entries.
fn relative<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>, b: &SMatrix<f64, R, C>) -> f64 {
    (a - b).amax() / b.amax()
}

/// The centre of mass's velocity and the centroidal momentum of one state
/// (`com_velocity`, `centroidal_map` 6 × n, `centroidal_bias`), checked
/// first: `ċ = J_c q̇`; the linear rows of `A_G` are `m J_c`, `m` the
/// total mass (fitted); `Ȧ_G q̇` is `A_G`'s central difference along `q̇`
/// times `q̇`.
fn centroidal<R: Framed<N>, const N: usize>(out: &mut String, system: &R, s: &Sample<N>) {
    let (q, v) = (&s.q, &s.v);
    let jc = system.com_jacobian(q);
    let cd = system.com_velocity(q, v);
    let worst = relative(&(jc * v), &cd);
    assert!(worst < 1e-12, "{}: ċ is not J_c q̇ ({worst:e})", R::NAME);
    let ag = system.centroidal(q);
    let linear: SMatrix<f64, 3, N> = ag.fixed_rows::<3>(0).into_owned();
    let mass = linear.dot(&jc) / jc.dot(&jc);
    let worst = relative(&linear, &(jc * mass));
    assert!(
        worst < 1e-12,
        "{}: A_G's linear rows are not m J_c ({worst:e})",
        R::NAME
    );
    let bias = system.centroidal_bias(q, v);
    let h = 1e-6;
    let rate = (system.centroidal(&(q + v * h)) - system.centroidal(&(q - v * h))) / (2.0 * h);
    let worst = relative(&(rate * v), &bias);
    assert!(
        worst < 1e-6,
        "{}: Ȧ_G q̇ is not Ȧ_G's difference ({worst:e})",
        R::NAME
    );
    line(out, "com_velocity", cd.iter());
    rows(out, "centroidal_map", &ag);
    line(out, "centroidal_bias", bias.iter());
}

/// `inverse_dynamics_jacobian` at one state's `(q, q̇, a)` (`a`,
/// `dtau_dq`, `dtau_dv`: n × n), checked first against central
/// differences of `inverse_dynamics`.
fn inverse<R: Framed<N>, const N: usize>(out: &mut String, system: &R, s: &Sample<N>) {
    let (q, v, a) = (&s.q, &s.v, &s.a);
    let (dq, dv) = system.tau_jacobian(q, v, a);
    let h = 1e-6;
    let step = |k: usize| Vector::<N>::from_fn(|i, _| if i == k { h } else { 0.0 });
    let fq = Matrix::<N>::from_fn(|i, k| {
        (system.tau(&(q + step(k)), v, a) - system.tau(&(q - step(k)), v, a))[i] / (2.0 * h)
    });
    let fv = Matrix::<N>::from_fn(|i, k| {
        (system.tau(q, &(v + step(k)), a) - system.tau(q, &(v - step(k)), a))[i] / (2.0 * h)
    });
    let worst = relative(&fq, &dq).max(relative(&fv, &dv));
    assert!(
        worst < 1e-6,
        "{}: ∂τ is not τ's difference ({worst:e})",
        R::NAME
    );
    line(out, "a", a.iter());
    rows(out, "dtau_dq", &dq);
    rows(out, "dtau_dv", &dv);
}

impl Visit for Write {
    fn robot<R: Framed<N>, const N: usize>(&mut self) {
        let samples = samples::<N>(&mut self.rng);
        let out = &mut self.out;
        let _ = writeln!(out, "robot {} {N}", R::NAME);
        let _ = writeln!(out, "urdf {}", R::FILE);
        let _ = writeln!(out, "locked {}", R::LOCKED.join(" "));
        let _ = writeln!(out, "names {}", R::names().join(" "));
        for f in R::FRAMES {
            let _ = write!(out, "frame {} {}", f.name, f.body);
            for x in f.xyz.iter().chain(&f.rpy) {
                let _ = write!(out, " {x:.17e}");
            }
            out.push('\n');
        }
        for s in &samples {
            self.state::<R, N>(s);
        }
    }
}

/// The time of `call` per state over `samples` (its system each).
fn per_state<R, const N: usize>(
    systems: &[R],
    samples: &[Sample<N>],
    mut call: impl FnMut(&R, &Sample<N>),
) -> f64 {
    median_ns(|| {
        for (system, s) in systems.iter().zip(samples) {
            call(black_box(system), s);
        }
    }) / samples.len() as f64
}

/// `time`: each quantity over each robot's states; one JSON line each, of
/// round `round`.
struct Time {
    rng: Rng,
    round: String,
}

/// The times of the first frame's methods and the centre of mass's: one
/// entry per row, `kinematics.cpp`'s QUANTITIES holding Pinocchio's
/// counterpart of each under the same name.
fn frame_times<R: Framed<N>, const N: usize>(
    systems: &[R],
    samples: &[Sample<N>],
) -> [(&'static str, f64); 4] {
    [
        (
            "frame_placement",
            per_state(systems, samples, |r, s| {
                black_box(&r.placement(0, black_box(&s.q)));
            }),
        ),
        (
            "frame_jacobian",
            per_state(systems, samples, |r, s| {
                black_box(&r.jacobian(0, black_box(&s.q)));
            }),
        ),
        (
            "frame_acceleration_bias",
            per_state(systems, samples, |r, s| {
                black_box(&r.bias(0, black_box(&s.q), black_box(&s.v)));
            }),
        ),
        (
            "center_of_mass_and_jacobian",
            per_state(systems, samples, |r, s| {
                black_box(&r.com_and_jacobian(black_box(&s.q)));
            }),
        ),
    ]
}

/// The times of the whole robot's quantities, as `frame_times`.
fn whole_times<R: Framed<N>, const N: usize>(
    systems: &[R],
    samples: &[Sample<N>],
) -> [(&'static str, f64); 5] {
    let mut pair = (Matrix::<N>::zeros(), Matrix::<N>::zeros());
    let mut jacobians = Jacobians::<f64, N, N>::zeros();
    [
        (
            "center_of_mass_velocity",
            per_state(systems, samples, |r, s| {
                black_box(&r.com_velocity(black_box(&s.q), black_box(&s.v)));
            }),
        ),
        (
            "centroidal_map",
            per_state(systems, samples, |r, s| {
                black_box(&r.centroidal(black_box(&s.q)));
            }),
        ),
        (
            "centroidal_map_bias",
            per_state(systems, samples, |r, s| {
                black_box(&r.centroidal_bias(black_box(&s.q), black_box(&s.v)));
            }),
        ),
        (
            "inverse_dynamics_jacobian",
            // Into one pair kept from call to call, as Pinocchio's
            // `computeRNEADerivatives` writes into its `Data`: returned by
            // value, the 2n² entries would be copied out of the `Result`.
            per_state(systems, samples, |r, s| {
                r.tau_jacobian_to(black_box(&s.q), black_box(&s.v), black_box(&s.a), &mut pair);
                black_box(&pair);
            }),
        ),
        (
            "acceleration_jacobian",
            // Into Jacobians kept from call to call, as `_to` above.
            per_state(systems, samples, |r, s| {
                r.derivatives_to(black_box(&s.q), black_box(&s.v), &mut jacobians);
                black_box(&jacobians);
            }),
        ),
    ]
}

impl Visit for Time {
    fn robot<R: Framed<N>, const N: usize>(&mut self) {
        let samples = samples::<N>(&mut self.rng);
        let systems: Vec<R> = samples.iter().map(|s| R::with_torques(&s.tau)).collect();
        let times = frame_times(&systems, &samples)
            .into_iter()
            .chain(whole_times(&systems, &samples));
        for (what, ns) in times {
            println!(
                "{{\"peer\": \"constrained\", \"what\": \"{what}\", \"system\": \"{}\", \"n\": {N}, \
                 \"frame\": \"{}\", \"ns\": {ns:.3}, \"states\": {}, \"round\": {}, \"ok\": true}}",
                R::NAME,
                R::FRAMES[0].name,
                samples.len(),
                self.round
            );
        }
    }
}

/// `kinematics spin ROBOT WHAT PASSES`: `PASSES` passes of `WHAT`
/// (`centroidal_map`, `centroidal_map_bias`, `inverse_dynamics_jacobian`,
/// `acceleration_jacobian`, `inverse_dynamics`, `mass_matrix`; anything
/// else: the centre of mass and its Jacobian) over the robot's states and
/// nothing else, for a profiler, as `constrained-robots spin` does for `q̈`,
/// `M` and `τ`.
struct Spin {
    rng: Rng,
    robot: String,
    what: String,
    passes: usize,
}

impl Visit for Spin {
    fn robot<R: Framed<N>, const N: usize>(&mut self) {
        // Drawn for every robot, as `Time` draws them: the same states.
        let samples = samples::<N>(&mut self.rng);
        if R::NAME != self.robot {
            return;
        }
        let systems: Vec<R> = samples.iter().map(|s| R::with_torques(&s.tau)).collect();
        let mut pair = (Matrix::<N>::zeros(), Matrix::<N>::zeros());
        let mut jacobians = Jacobians::<f64, N, N>::zeros();
        for _ in 0..self.passes {
            for (r, s) in systems.iter().zip(&samples) {
                let (r, q, v) = (black_box(r), black_box(&s.q), black_box(&s.v));
                match self.what.as_str() {
                    "centroidal_map" => {
                        black_box(&r.centroidal(q));
                    }
                    "centroidal_map_bias" => {
                        black_box(&r.centroidal_bias(q, v));
                    }
                    "inverse_dynamics_jacobian" => {
                        r.tau_jacobian_to(q, v, black_box(&s.a), &mut pair);
                        black_box(&pair);
                    }
                    "acceleration_jacobian" => {
                        r.derivatives_to(q, v, &mut jacobians);
                        black_box(&jacobians);
                    }
                    "inverse_dynamics" => {
                        black_box(&r.tau(q, v, black_box(&s.a)));
                    }
                    "mass_matrix" => {
                        black_box(&r.mass(q));
                    }
                    _ => {
                        black_box(&r.com_and_jacobian(q));
                    }
                }
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seed = 49;
    match (args.get(1).map(String::as_str), args.get(2)) {
        (Some("write"), Some(path)) => {
            let mut write = Write {
                rng: Rng(seed),
                out: String::new(),
            };
            framed(&mut write);
            std::fs::write(path, write.out).expect("writes the reference file");
        }
        (Some("time"), Some(round)) => framed(&mut Time {
            rng: Rng(seed),
            round: round.clone(),
        }),
        (Some("spin"), Some(robot)) => framed(&mut Spin {
            rng: Rng(seed),
            robot: robot.clone(),
            what: args.get(3).cloned().unwrap_or_default(),
            passes: args.get(4).and_then(|p| p.parse().ok()).unwrap_or(1000),
        }),
        _ => {
            eprintln!(
                "usage: kinematics write REFERENCE_FILE | kinematics time ROUND | \
                 kinematics spin ROBOT WHAT PASSES"
            );
            std::process::exit(2);
        }
    }
}
