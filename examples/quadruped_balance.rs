//! The quadruped of `quadruped.rs` (Solo-12's structure: a floating base on
//! a free joint, twelve joints, the four feet held on the ground by the
//! model's rows) under a whole-body balance controller
//! (`support/balance.rs`) at 1 kHz: its centre of mass circles over the
//! support polygon — 3 cm forward and back, 4 cm to the left and back,
//! sinking 2 cm on the way, once every 4 s — while the trunk stays level
//! and the feet stay put. From the generated kinematics (`centroidal_map`
//! and its bias for the centre of mass, the trunk's and the feet's frame
//! Jacobians and biases) the controller finds `q̈`; the floating base's
//! inverse dynamics (`inverse_dynamics`, the base's rows for the feet's
//! least-squares forces, the joints' rows for the torques) then gives the
//! torques, set as the model's inputs and held over each millisecond, and
//! `DormandPrince45` with projection (tolerance 1e-12) integrates it.
//!
//! It fails unless the centre of mass's error follows the gains'
//! prediction, the trunk stays level, every foot pushes inside its
//! friction cone, the feet do not drift, and the ground's forces (the
//! model's multipliers, `constrained::multipliers`) are the ones the
//! controller planned.
//!
//! `cargo run --release --example quadruped_balance [-- --duration 4 --progress]`

#[path = "support/quadruped.rs"]
#[allow(dead_code)] // the plain `Quadruped` is the other examples'
#[macro_use]
mod quadruped;

#[path = "support/balance.rs"]
mod balance;
#[path = "support/mod.rs"]
mod support;

use balance::{attitude_error, balance, Balancing, Gains, Target};
use constrained::floating::FreeMotion;
use constrained::multipliers::Multipliers;
use constrained::nalgebra::{Matrix3, SVector, UnitQuaternion, Vector3};
use constrained::{ConstrainedSystem, DormandPrince45, Stabilization, State};
use quadruped::{FOOT_OFFSET, HIPS, N, SEGMENT};
use std::f64::consts::PI;
use support::{plot, Options, Panel, Progress, Series};

/// Hip flexion when standing; the knee is at `−2θ`, each foot under its hip.
const THETA: f64 = 0.8;
/// The friction coefficient the feet's forces must respect: `|f_t| ≤ μ f_n`,
/// a cautious figure for a rubber foot on a floor.
const MU: f64 = 0.5;
/// The circle's period, s, and its half-axes: forward, left, down.
const PERIOD: f64 = 4.0;
const AXES: [f64; 3] = [0.03, 0.02, 0.01];

/// The centre of mass's target: from `start`, `a sin ωt` forward,
/// `b (1 − cos ωt)` to the left and `d (1 − cos ωt)` down.
fn circle(start: &Vector3<f64>, t: f64) -> Target {
    let w = 2.0 * PI / PERIOD;
    let (s, c) = (w * t).sin_cos();
    let [a, b, d] = AXES;
    (
        start + Vector3::new(a * s, b * (1.0 - c), -d * (1.0 - c)),
        w * Vector3::new(a * c, b * s, -d * s),
        w * w * Vector3::new(-a * s, b * c, -d * c),
    )
}

fn set_torques(robot: &mut Balancing<f64>, tau: &SVector<f64, 12>) {
    [robot.t_fl_haa, robot.t_fl_hfe, robot.t_fl_kfe] = [tau[0], tau[1], tau[2]];
    [robot.t_fr_haa, robot.t_fr_hfe, robot.t_fr_kfe] = [tau[3], tau[4], tau[5]];
    [robot.t_hl_haa, robot.t_hl_hfe, robot.t_hl_kfe] = [tau[6], tau[7], tau[8]];
    [robot.t_hr_haa, robot.t_hr_hfe, robot.t_hr_kfe] = [tau[9], tau[10], tau[11]];
}

/// The feet's places, `(x, y)`: each under its hip.
fn feet() -> [[f64; 2]; 4] {
    HIPS.map(|h| [h[0], h[1] + h[1].signum() * FOOT_OFFSET])
}

/// The robot with its feet in their places, and its state standing there
/// at rest.
fn standing() -> Result<(Balancing<f64>, State<f64, N>), Box<dyn std::error::Error>> {
    let [[a, b], [c, d], [e, f], [g, h]] = feet();
    let zero = 0.0;
    let robot = Balancing::new(
        a, b, c, d, e, f, g, h, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero,
        zero,
    );
    let base = FreeMotion::at_rest(
        Vector3::new(0.0, 0.0, 2.0 * SEGMENT * THETA.cos()),
        UnitQuaternion::identity(),
    );
    let (mut q, mut qd) = (SVector::<f64, N>::zeros(), SVector::<f64, N>::zeros());
    base.write(0, &mut q, &mut qd)?;
    for leg in 0..4 {
        q[7 + 3 * leg + 1] = THETA;
        q[7 + 3 * leg + 2] = -2.0 * THETA;
    }
    Ok((robot, State::new(0.0, q, qd)))
}

/// One sample of the run, every 5 ms.
struct Sample {
    t: f64,
    com: Vector3<f64>,
    target: Vector3<f64>,
    com_error: f64,
    attitude: f64,
    normal: [f64; 4],
    slip: f64,
    drift: f64,
}

/// What the run measured, over every millisecond.
#[derive(Default)]
struct Worst {
    /// The largest `|f_t| / f_n` over the feet.
    slip: f64,
    /// The smallest normal force, N.
    push: f64,
    /// The trunk's largest rotation from level, rad.
    attitude: f64,
    /// The feet's largest distance from their places, m.
    drift: f64,
    /// The largest difference between the controller's forces and the
    /// model's multipliers, N.
    planned: f64,
    /// The largest difference between the controller's `q̈` and the
    /// model's.
    moved: f64,
    /// The largest departure of the centre of mass's error from the
    /// prediction, m.
    off_prediction: f64,
}

/// The gains: both errors obey `ë + 20 ė + 100 e = 0`, a double pole at
/// −10 /s.
const GAINS: Gains = Gains {
    com_kp: 100.0,
    com_kd: 20.0,
    trunk_kp: 100.0,
    trunk_kd: 20.0,
};
/// The double pole's rate, 1/s: `√kp`.
const RATE: f64 = 10.0;

/// The centre of mass's error the gains predict: the robot starts at rest
/// where the target moves forward at `v₀ = a ω`, so `e(0) = 0`, `ė(0) = v₀`,
/// and `ë + 2 r ė + r² e = 0` gives `e = v₀ t e^(−r t)`.
fn predicted(t: f64) -> f64 {
    AXES[0] * 2.0 * PI / PERIOD * t * (-RATE * t).exp()
}

/// Runs the controller for `duration` seconds, its torques set every
/// `period` seconds and held in between.
fn run(
    duration: f64,
    period: f64,
    mut progress: Option<&mut Progress>,
) -> Result<(Vec<Sample>, Worst), Box<dyn std::error::Error>> {
    let (mut robot, mut state) = standing()?;
    let start = robot.center_of_mass(&state.q, 0.0);
    let integrator =
        DormandPrince45::new(1e-10, 1e-12).with_stabilization(Stabilization::projection(1e-12));
    let mut worst = Worst {
        push: f64::INFINITY,
        ..Worst::default()
    };
    let mut samples = Vec::new();
    let every = (5e-3 / period).round() as usize; // a sample every 5 ms
    for step in 0..(duration / period).round() as usize {
        let t = state.t;
        let target = circle(&start, t);
        let command = balance(&robot, &state, &target, &GAINS)
            .map_err(|e| format!("the balance controller at t = {t}: {e:?}"))?;
        set_torques(&mut robot, &command.tau);
        // The ground's forces in the simulation: the model's multipliers.
        let (qdd, lambda) = robot.acceleration_and_multipliers(&state)?;
        worst.moved = worst.moved.max((qdd - command.qdd).amax());
        let (mut normal, mut slip) = ([0.0; 4], 0.0f64);
        for (k, planned) in command.feet.iter().enumerate() {
            let ground = Vector3::new(lambda[3 * k], lambda[3 * k + 1], lambda[3 * k + 2]);
            worst.planned = worst.planned.max((ground - planned).amax());
            normal[k] = ground.z;
            slip = slip.max(ground.xy().norm() / ground.z);
        }
        let com = robot.center_of_mass(&state.q, t);
        let com_error = (target.0 - com).norm();
        let trunk = robot.trunk_placement(&state.q, t).0;
        let attitude = attitude_error(&trunk, &Matrix3::identity()).norm();
        worst.slip = worst.slip.max(slip);
        worst.push = normal.iter().fold(worst.push, |a, &b| a.min(b));
        worst.attitude = worst.attitude.max(attitude);
        worst.off_prediction = worst.off_prediction.max((com_error - predicted(t)).abs());
        integrator.advance(&robot, &mut state, t + period)?;
        let drift = ConstrainedSystem::constraint_residual(&robot, &state).amax();
        worst.drift = worst.drift.max(drift);
        if step % every == 0 {
            samples.push(Sample {
                t,
                com,
                target: target.0,
                com_error,
                attitude,
                normal,
                slip,
                drift,
            });
        }
        if let Some(progress) = progress.as_mut() {
            progress.tick(state.t);
        }
    }
    Ok((samples, worst))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = Options::parse(PERIOD);
    let mut progress = options.progress();
    let (samples, worst) = run(options.duration, 1e-3, Some(&mut progress))?;
    // The same at 2 kHz: what the held torques leave halves.
    let (_, finer) = run(options.duration, 5e-4, None)?;
    let peak = predicted(1.0 / RATE);
    let last = samples.last().map_or(0.0, |s| s.com_error);
    println!(
        "quadruped balance, {} s at 1 kHz: centre of mass error peaks at {:.3e} m \
         (predicted v₀/(10 e) = {peak:.3e} m), departs from v₀ t e^(−10 t) by at most \
         {:.1e} m, ends at {last:.1e} m; trunk within {:.1e} rad of level; \
         feet push ≥ {:.2} N with |f_t|/f_n ≤ {:.3} (μ = {MU}); feet within {:.1e} m; \
         ground forces within {:.1e} N and q̈ within {:.1e} of the planned; \
         at 2 kHz the departure is {:.1e} m ({:.2} times less)",
        options.duration,
        samples.iter().map(|s| s.com_error).fold(0.0, f64::max),
        worst.off_prediction,
        worst.attitude,
        worst.push,
        worst.slip,
        worst.drift,
        worst.planned,
        worst.moved,
        finer.off_prediction,
        worst.off_prediction / finer.off_prediction,
    );
    // The torques are held over each period h while the exact law would
    // change them. Their lag of h/2 alone forces the error equation with
    // −(h/2)(k_d ë + k_p ė) along e = v₀ t e^(−r t), which moves it by
    // (h/2) v₀ r² (3t²/2 − r t³/6) e^(−r t): at most 0.9 % of the peak at
    // 1 kHz; the robot's own motion under held torques adds about as much
    // again. Both are first order in h: 2 % of the peak at 1 kHz is the
    // bound, and halving h must halve the departure.
    let ratio = worst.off_prediction / finer.off_prediction;
    let checks = [
        (
            worst.off_prediction <= 0.02 * peak,
            "the centre of mass left its prediction",
        ),
        (
            (1.8..=2.2).contains(&ratio),
            "the departure from the prediction is not the held torques' (first order in h)",
        ),
        (
            worst.attitude <= 1e-3,
            "the trunk tilted by more than 1 mrad",
        ),
        (worst.push > 0.0, "a foot pulled on the ground"),
        (worst.slip <= MU, "a foot's force left the friction cone"),
        (worst.drift <= 1e-9, "the feet drifted by more than 1e-9 m"),
        (
            worst.planned <= 1e-6 && worst.moved <= 1e-6,
            "the ground's forces or the accelerations are not the planned ones",
        ),
    ];
    let failed: Vec<&str> = checks.iter().filter(|c| !c.0).map(|c| c.1).collect();
    if !failed.is_empty() {
        return Err(failed.join("; ").into());
    }
    draw(&options, &samples)
}

fn draw(options: &Options, samples: &[Sample]) -> Result<(), Box<dyn std::error::Error>> {
    let out = options.plot_path("quadruped_balance");
    let [top, path] = motion(samples);
    let [errors, normal, friction] = checks(samples);
    plot(
        &out,
        "Quadruped (Solo-12's structure, 4 feet held): whole-body balance control",
        &[top, path, errors, normal, friction],
    )?;
    println!("  plot: {}", out.display());
    Ok(())
}

/// One value of every sample against time.
fn series(samples: &[Sample], label: &str, f: &dyn Fn(&Sample) -> f64) -> Series {
    Series::new(label, samples.iter().map(|s| (s.t, f(s))).collect())
}

/// The motion: the centre of mass seen from above, over the feet, and its
/// coordinates from where it started.
fn motion(samples: &[Sample]) -> [Panel; 2] {
    // The support polygon, front-left → front-right → hind-right → hind-left.
    let polygon = [0, 1, 3, 2, 0].map(|k| (feet()[k][0], feet()[k][1]));
    let top =
        |f: &dyn Fn(&Sample) -> Vector3<f64>| samples.iter().map(|s| (f(s).x, f(s).y)).collect();
    let start = samples.first().map_or(Vector3::zeros(), |s| s.target);
    [
        Panel::new(
            "top view: the centre of mass over the support polygon",
            "x [m]",
            "y [m]",
            vec![
                Series::new("feet", polygon.to_vec()),
                Series::new("centre of mass", top(&|s| s.com)),
                Series::new("target", top(&|s| s.target)),
            ],
        )
        .equal(),
        Panel::new(
            "the centre of mass from where it started",
            "t [s]",
            "[m]",
            vec![
                series(samples, "forward", &|s| s.com.x - start.x),
                series(samples, "left", &|s| s.com.y - start.y),
                series(samples, "up", &|s| s.com.z - start.z),
            ],
        ),
    ]
}

/// What the example checks: the errors against the prediction, the feet's
/// normal forces, the friction they use and their drift.
fn checks(samples: &[Sample]) -> [Panel; 3] {
    // On the log scale: after the start (both errors start at 0) and above
    // rounding, the prediction until it falls below the held torques' floor.
    let after = |f: &dyn Fn(&Sample) -> f64| -> Vec<(f64, f64)> {
        let points = samples.iter().map(|s| (s.t, f(s)));
        points.filter(|p| p.0 > 0.0 && p.1 > 1e-12).collect()
    };
    let prediction = after(&|s| predicted(s.t))
        .into_iter()
        .filter(|p| p.1 > 1e-7);
    let foot = |label: &str, k: usize| series(samples, label, &move |s| s.normal[k]);
    [
        Panel::new(
            "errors: the centre of mass against the gains' prediction, the trunk's tilt",
            "t [s]",
            "[m], [rad]",
            vec![
                Series::new("|c_d − c| [m]", after(&|s| s.com_error)),
                Series::new("predicted v₀ t e^(−10 t) [m]", prediction.collect()),
                Series::new("trunk from level [rad]", after(&|s| s.attitude)),
            ],
        )
        .log(),
        Panel::new(
            "normal forces on the feet, λ_z",
            "t [s]",
            "[N]",
            vec![
                foot("front left", 0),
                foot("front right", 1),
                foot("hind left", 2),
                foot("hind right", 3),
            ],
        ),
        Panel::new(
            "friction used and the feet's drift",
            "t [s]",
            "[–], [m]",
            vec![
                series(samples, &format!("max |f_t| / f_n (μ = {MU})"), &|s| {
                    s.slip
                }),
                series(samples, "max |φ| [m]", &|s| s.drift),
            ],
        )
        .log(),
    ]
}
