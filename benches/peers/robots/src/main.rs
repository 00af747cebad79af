//! The Robots rows of BENCHMARKS.md: robots read from `example-robot-data`'s
//! URDFs as written by `constrained_system!` (build.rs's table: the Panda
//! with its fingers locked, the UR5, TALOS, the xArm7, the Kinova Jaco 2,
//! the Unitree G1 with its arms locked and whole, and the Panda with its
//! finger `<mimic>`), against Pinocchio's `aba`, `crba` and `rnea` on the
//! same files (`benches/peers/robots.cpp`).
//!
//! ```text
//! constrained-robots write REFERENCE_FILE
//! constrained-robots time ROUND
//! ```
//!
//! `write` writes, per robot, a header (`robot NAME N MIMIC`, then `urdf`
//! with the file under example-robot-data's `robots` directory, `locked`
//! with the joints held at zero and `names` with `COORDINATES`, the order of
//! every vector below) and 20 pseudo-random states, each `state` followed
//! by the lines `q`, `v`, `tau` (the joint torques, the system's inputs),
//! `qdd` (`acceleration`), `M` (`mass_matrix`, row by row), `a` (an
//! acceleration) and `tau_id` (`inverse_dynamics(q, v, a)`). `time` times
//! `acceleration`, `mass_matrix` and `inverse_dynamics` over the same
//! states with `common.h`'s statistic on the thread's CPU clock (the median
//! of 31 batches of about 5 ms, per state) and prints one JSON line per
//! result, tagged with its round; a robot with mimic joints is not timed
//! (Pinocchio's `aba` refuses it, so there is nothing to set against ours).
//! `benches/peers/run.sh` runs three rounds, each followed by Pinocchio's,
//! pinned to the core the peers use.

use constrained::nalgebra::{SMatrix, SVector};
use std::fmt::Write as _;
use std::hint::black_box;

mod clock;

use clock::median_ns;

type Vector<const N: usize> = SVector<f64, N>;
type Matrix<const N: usize> = SMatrix<f64, N, N>;

/// A robot read from URDF: build.rs writes the implementation of each,
/// from its table, next to its `constrained_system!`.
trait Urdf<const N: usize>: Sized {
    /// The reference file's name of the robot.
    const NAME: &'static str;
    /// Its file under example-robot-data's `robots` directory.
    const FILE: &'static str;
    /// The joints held at zero (`locked:`).
    const LOCKED: &'static [&'static str];
    /// Whether the model has mimic joints (read as Pinocchio's
    /// `buildModel(.., mimic=True)`).
    const MIMIC: bool;
    /// `COORDINATES`: the joints' names, in the order of `q`.
    fn names() -> [&'static str; N];
    /// The system with one torque per joint.
    fn with_torques(tau: &Vector<N>) -> Self;
    fn qdd(&self, q: &Vector<N>, v: &Vector<N>) -> Vector<N>;
    fn mass(&self, q: &Vector<N>) -> Matrix<N>;
    fn tau(&self, q: &Vector<N>, v: &Vector<N>, a: &Vector<N>) -> Vector<N>;
    /// `F(q, q̇)` with the torques `with_torques` gave: `forces`, which
    /// Pinocchio's peers do not time (`spin` only).
    fn forces_of(&self, q: &Vector<N>, v: &Vector<N>) -> Vector<N>;
}

/// Something done to every robot (`robots`, which build.rs writes).
trait Visit {
    fn robot<R: Urdf<N>, const N: usize>(&mut self);
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

include!(concat!(env!("OUT_DIR"), "/robots.rs"));

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

/// One state: joint angles, rates, torques and an acceleration.
struct Sample<const N: usize> {
    q: Vector<N>,
    v: Vector<N>,
    tau: Vector<N>,
    a: Vector<N>,
}

/// Angles and rates within ±1 (rad, rad/s; m and m/s for a prismatic
/// joint), torques within ±10 N m, accelerations within ±2 rad/s².
fn samples<const N: usize>(rng: &mut Rng) -> Vec<Sample<N>> {
    (0..STATES)
        .map(|_| Sample {
            q: rng.vector(1.0),
            v: rng.vector(1.0),
            tau: rng.vector(10.0),
            a: rng.vector(2.0),
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

/// `write`: the records of every robot, its answers checked against each
/// other first: `inverse_dynamics` at the generated `q̈` gives back `τ`,
/// and `M a + c = τ_id` with `c = inverse_dynamics(q, v, 0)`.
struct Write {
    rng: Rng,
    out: String,
}

impl Visit for Write {
    fn robot<R: Urdf<N>, const N: usize>(&mut self) {
        let samples = samples::<N>(&mut self.rng);
        let out = &mut self.out;
        let _ = writeln!(out, "robot {} {N} {}", R::NAME, u8::from(R::MIMIC));
        let _ = writeln!(out, "urdf {}", R::FILE);
        let _ = writeln!(out, "locked {}", R::LOCKED.join(" "));
        let _ = writeln!(out, "names {}", R::names().join(" "));
        for s in &samples {
            let system = R::with_torques(&s.tau);
            let qdd = system.qdd(&s.q, &s.v);
            let m = system.mass(&s.q);
            let tau_id = system.tau(&s.q, &s.v, &s.a);
            let back = system.tau(&s.q, &s.v, &qdd);
            let c = system.tau(&s.q, &s.v, &Vector::<N>::zeros());
            let worst = ((back - s.tau).amax() / s.tau.amax())
                .max((m * s.a + c - tau_id).amax() / tau_id.amax());
            assert!(
                worst < 1e-10,
                "{}: the generated answers disagree by {worst:e}",
                R::NAME
            );
            out.push_str("state\n");
            line(out, "q", s.q.iter());
            line(out, "v", s.v.iter());
            line(out, "tau", s.tau.iter());
            line(out, "qdd", qdd.iter());
            line(out, "M", m.transpose().iter());
            line(out, "a", s.a.iter());
            line(out, "tau_id", tau_id.iter());
        }
    }
}

/// `time`: the three methods over each robot's states; one JSON line each,
/// of round `round`.
struct Time {
    rng: Rng,
    round: String,
}

impl Visit for Time {
    fn robot<R: Urdf<N>, const N: usize>(&mut self) {
        // Drawn whether timed or not: every robot keeps its states.
        let samples = samples::<N>(&mut self.rng);
        if R::MIMIC {
            return;
        }
        let systems: Vec<R> = samples.iter().map(|s| R::with_torques(&s.tau)).collect();
        let per_state = |ns: f64| ns / samples.len() as f64;
        // Each answer is kept by reference where the call wrote it: moving
        // it into `black_box` copies it, and a large one (TALOS's `M`, 8 KB)
        // is copied by the libc's `memcpy`, whose `rep movsb` on an AMD EPYC
        // took three times as long as the call itself when the two stack
        // slots fell on nearby offsets of their 4 KB pages (perf: 73 % of
        // the time in `__memmove_avx512_unaligned_erms`). Pinocchio's side
        // leaves its answers in its `Data`, uncopied.
        let acceleration = median_ns(|| {
            for (system, s) in systems.iter().zip(&samples) {
                black_box(&black_box(system).qdd(black_box(&s.q), black_box(&s.v)));
            }
        });
        let mass_matrix = median_ns(|| {
            for (system, s) in systems.iter().zip(&samples) {
                black_box(&black_box(system).mass(black_box(&s.q)));
            }
        });
        let inverse_dynamics = median_ns(|| {
            for (system, s) in systems.iter().zip(&samples) {
                black_box(&black_box(system).tau(
                    black_box(&s.q),
                    black_box(&s.v),
                    black_box(&s.a),
                ));
            }
        });
        for (what, ns) in [
            ("acceleration", acceleration),
            ("mass_matrix", mass_matrix),
            ("inverse_dynamics", inverse_dynamics),
        ] {
            println!(
                "{{\"peer\": \"constrained\", \"what\": \"{what}\", \"system\": \"{}\", \"n\": {N}, \
                 \"ns\": {:.3}, \"states\": {}, \"round\": {}, \"ok\": true}}",
                R::NAME,
                per_state(ns),
                samples.len(),
                self.round
            );
        }
    }
}

/// `constrained-robots spin ROBOT WHAT PASSES`: `PASSES` passes of `WHAT`
/// (`acceleration`, `mass_matrix`, `inverse_dynamics` or `forces`) over
/// the robot's states and nothing else, for cachegrind
/// (`benches/peers/icache.sh`) and for timing two builds against each other.
struct Spin {
    rng: Rng,
    robot: String,
    what: String,
    passes: usize,
}

impl Visit for Spin {
    fn robot<R: Urdf<N>, const N: usize>(&mut self) {
        // Drawn for every robot, as `Time` draws them: the same states.
        let samples = samples::<N>(&mut self.rng);
        if R::NAME != self.robot {
            return;
        }
        let systems: Vec<R> = samples.iter().map(|s| R::with_torques(&s.tau)).collect();
        for _ in 0..self.passes {
            for (system, s) in systems.iter().zip(&samples) {
                match self.what.as_str() {
                    "mass_matrix" => {
                        black_box(&black_box(system).mass(black_box(&s.q)));
                    }
                    "forces" => {
                        black_box(&black_box(system).forces_of(black_box(&s.q), black_box(&s.v)));
                    }
                    "inverse_dynamics" => {
                        black_box(&black_box(system).tau(
                            black_box(&s.q),
                            black_box(&s.v),
                            black_box(&s.a),
                        ));
                    }
                    _ => {
                        black_box(&black_box(system).qdd(black_box(&s.q), black_box(&s.v)));
                    }
                }
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seed = 26;
    match (args.get(1).map(String::as_str), args.get(2)) {
        (Some("write"), Some(path)) => {
            let mut write = Write {
                rng: Rng(seed),
                out: String::new(),
            };
            robots(&mut write);
            std::fs::write(path, write.out).expect("writes the reference file");
        }
        (Some("time"), Some(round)) => robots(&mut Time {
            rng: Rng(seed),
            round: round.clone(),
        }),
        (Some("spin"), Some(robot)) => {
            let (Some(what), Some(Ok(passes))) = (args.get(3), args.get(4).map(|p| p.parse()))
            else {
                eprintln!("usage: constrained-robots spin ROBOT WHAT PASSES");
                std::process::exit(2);
            };
            robots(&mut Spin {
                rng: Rng(seed),
                robot: robot.clone(),
                what: what.clone(),
                passes,
            });
        }
        _ => {
            eprintln!(
                "usage: constrained-robots write REFERENCE_FILE | constrained-robots time ROUND | constrained-robots spin ROBOT WHAT PASSES"
            );
            std::process::exit(2);
        }
    }
}
