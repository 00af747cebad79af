//! The Robots rows of BENCHMARKS.md: the Franka Emika Panda (fingers
//! locked) and the UR5, read from `example-robot-data`'s URDFs by
//! `constrained_system!` (build.rs finds the files in the peers' virtual
//! environment), against Pinocchio's `aba`, `crba` and `rnea` on the same
//! files (`benches/peers/robots.cpp`).
//!
//! ```text
//! constrained-robots write REFERENCE_FILE
//! constrained-robots time ROUND
//! ```
//!
//! `write` writes 20 pseudo-random states per robot and the generated
//! answers in the format of `benches/peers/common.h`, one record per state:
//! a header `panda 7` or `ur5 6`, then the lines `q`, `v`, `tau` (the joint
//! torques, the system's inputs), `qdd` (`acceleration`), `M`
//! (`mass_matrix`, row by row), `a` (an acceleration) and `tau_id`
//! (`inverse_dynamics(q, v, a)`). `time` times `acceleration`,
//! `mass_matrix` and `inverse_dynamics` over the same states with
//! `common.h`'s statistic on the thread's CPU clock (the median of 31
//! batches of about 5 ms, per state) and prints one JSON line per result,
//! tagged with its round. `benches/peers/run.sh` runs three rounds, each
//! followed by Pinocchio's, pinned to the core the peers use.

use constrained::nalgebra::{SMatrix, SVector};
use std::fmt::Write as _;
use std::hint::black_box;

mod clock;

use clock::median_ns;

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
    q: SVector<f64, N>,
    v: SVector<f64, N>,
    tau: SVector<f64, N>,
    a: SVector<f64, N>,
}

/// A robot's generated methods, as closures over its struct (whose `new`
/// takes one torque per joint).
struct Robot<S, const N: usize, New, Acc, Mass, Inv> {
    name: &'static str,
    new: New,
    acceleration: Acc,
    mass_matrix: Mass,
    inverse_dynamics: Inv,
    _system: std::marker::PhantomData<S>,
}

type Vector<const N: usize> = SVector<f64, N>;

impl<S, const N: usize, New, Acc, Mass, Inv> Robot<S, N, New, Acc, Mass, Inv>
where
    New: Fn(&Vector<N>) -> S,
    Acc: Fn(&S, &Vector<N>, &Vector<N>) -> Vector<N>,
    Mass: Fn(&S, &Vector<N>) -> SMatrix<f64, N, N>,
    Inv: Fn(&S, &Vector<N>, &Vector<N>, &Vector<N>) -> Vector<N>,
{
    /// Writes the records of `samples` and checks the answers against each
    /// other: `inverse_dynamics` at the generated `q̈` gives back `τ`, and
    /// `M a + c = τ_id` with `c = inverse_dynamics(q, v, 0)`.
    fn reference(&self, out: &mut String, samples: &[Sample<N>]) {
        for s in samples {
            let system = (self.new)(&s.tau);
            let qdd = (self.acceleration)(&system, &s.q, &s.v);
            let m = (self.mass_matrix)(&system, &s.q);
            let tau_id = (self.inverse_dynamics)(&system, &s.q, &s.v, &s.a);
            let back = (self.inverse_dynamics)(&system, &s.q, &s.v, &qdd);
            let c = (self.inverse_dynamics)(&system, &s.q, &s.v, &Vector::<N>::zeros());
            let worst = ((back - s.tau).amax() / s.tau.amax())
                .max((m * s.a + c - tau_id).amax() / tau_id.amax());
            assert!(
                worst < 1e-10,
                "{}: the generated answers disagree by {worst:e}",
                self.name
            );
            let _ = writeln!(out, "{} {N}", self.name);
            line(out, "q", s.q.iter());
            line(out, "v", s.v.iter());
            line(out, "tau", s.tau.iter());
            line(out, "qdd", qdd.iter());
            line(out, "M", m.transpose().iter());
            line(out, "a", s.a.iter());
            line(out, "tau_id", tau_id.iter());
        }
    }

    /// Times the three methods over `samples`; one JSON line each, of
    /// round `round`.
    fn time(&self, samples: &[Sample<N>], round: &str) {
        let systems: Vec<S> = samples.iter().map(|s| (self.new)(&s.tau)).collect();
        let per_state = |ns: f64| ns / samples.len() as f64;
        let acceleration = median_ns(|| {
            for (system, s) in systems.iter().zip(samples) {
                black_box((self.acceleration)(
                    black_box(system),
                    black_box(&s.q),
                    black_box(&s.v),
                ));
            }
        });
        let mass_matrix = median_ns(|| {
            for (system, s) in systems.iter().zip(samples) {
                black_box((self.mass_matrix)(black_box(system), black_box(&s.q)));
            }
        });
        let inverse_dynamics = median_ns(|| {
            for (system, s) in systems.iter().zip(samples) {
                black_box((self.inverse_dynamics)(
                    black_box(system),
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
                 \"ns\": {:.3}, \"states\": {}, \"round\": {round}, \"ok\": true}}",
                self.name,
                per_state(ns),
                samples.len()
            );
        }
    }
}

fn line<'a>(out: &mut String, name: &str, values: impl Iterator<Item = &'a f64>) {
    let _ = write!(out, "{name}");
    for v in values {
        let _ = write!(out, " {v:.17e}");
    }
    out.push('\n');
}

/// Angles and rates within ±1 (rad, rad/s), torques within ±10 N m,
/// accelerations within ±2 rad/s².
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

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let panda = Robot {
        name: "panda",
        new: |t: &Vector<7>| PandaUrdf::new(t[0], t[1], t[2], t[3], t[4], t[5], t[6]),
        acceleration: |s: &PandaUrdf, q: &Vector<7>, v: &Vector<7>| {
            s.acceleration(q, v, 0.0).expect("the Panda's q̈")
        },
        mass_matrix: |s: &PandaUrdf, q: &Vector<7>| s.mass_matrix(q, 0.0),
        inverse_dynamics: |s: &PandaUrdf, q: &Vector<7>, v: &Vector<7>, a: &Vector<7>| {
            s.inverse_dynamics(q, v, a, 0.0).expect("the Panda's τ")
        },
        _system: std::marker::PhantomData,
    };
    let ur5 = Robot {
        name: "ur5",
        new: |t: &Vector<6>| Ur5Urdf::new(t[0], t[1], t[2], t[3], t[4], t[5]),
        acceleration: |s: &Ur5Urdf, q: &Vector<6>, v: &Vector<6>| {
            s.acceleration(q, v, 0.0).expect("the UR5's q̈")
        },
        mass_matrix: |s: &Ur5Urdf, q: &Vector<6>| s.mass_matrix(q, 0.0),
        inverse_dynamics: |s: &Ur5Urdf, q: &Vector<6>, v: &Vector<6>, a: &Vector<6>| {
            s.inverse_dynamics(q, v, a, 0.0).expect("the UR5's τ")
        },
        _system: std::marker::PhantomData,
    };
    let mut rng = Rng(26);
    let (panda_states, ur5_states) = (samples::<7>(&mut rng), samples::<6>(&mut rng));
    match (args.get(1).map(String::as_str), args.get(2)) {
        (Some("write"), Some(path)) => {
            let mut out = String::new();
            panda.reference(&mut out, &panda_states);
            ur5.reference(&mut out, &ur5_states);
            std::fs::write(path, out).expect("writes the reference file");
        }
        (Some("time"), Some(round)) => {
            panda.time(&panda_states, round);
            ur5.time(&ur5_states, round);
        }
        _ => {
            eprintln!(
                "usage: constrained-robots write REFERENCE_FILE | constrained-robots time ROUND"
            );
            std::process::exit(2);
        }
    }
}
