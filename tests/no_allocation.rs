//! 10⁵ steps of each integrator (and each stabilization) on the double
//! pendulum allocate nothing, nor do 10⁵ Jacobians and linearizations and
//! an LQR design: a counting global allocator proves it. So does a 10 s
//! run of the standing quadruped (`examples/support/quadruped.rs`: a
//! floating base, four feet on the ground) under a joint-space PD
//! controller, with projection (tolerance 1e-12) keeping its feet within
//! 1e-9 m of their places. So do 2.2 × 10⁵ calls of a named frame's
//! kinematics and the centroidal momentum (`frames: [..]`) and of the
//! derivatives of inverse dynamics, returned and into a kept pair.
//! Runs without the test harness so that no other thread allocates
//! meanwhile; prints a summary line the test runners understand.

use constrained::control::{discretize, lqr_gain};
use constrained::integrate::{Direction, Event, Events, StepOutcome};
use constrained::models::{CartPole, DoublePendulum};
use constrained::nalgebra::{Matrix1, Matrix2, Matrix4, Vector2, Vector4};
use constrained::{DormandPrince45, Rk4, SemiImplicitEuler, Stabilization, State};
use std::alloc::{GlobalAlloc, Layout, System};

#[path = "../examples/support/quadruped.rs"]
#[allow(dead_code)]
#[macro_use]
mod model;

use std::sync::atomic::{AtomicUsize, Ordering};

constrained::constrained_system! {
    /// A two-link arm with a frame at its tip, for the kinematics' calls,
    /// and the derivatives of its inverse dynamics.
    pub struct FramedArm {
        bodies: [
            upper { joint: revolute(q1, [0.0, 1.0, 0.0]), mass: 2.0, com: [0.25, 0.0, 0.0] },
            fore {
                parent: upper,
                joint: revolute(q2, [0.0, 1.0, 0.0]),
                xyz: [0.5, 0.0, 0.0],
                mass: 1.0,
                com: [0.2, 0.0, 0.0],
            },
        ],
        frames: [tip { body: fore, xyz: [0.4, 0.0, 0.1], rpy: [0.1, 0.2, 0.3] }],
        derivatives: [inverse_dynamics],
    }
}

/// 2.2 × 10⁵ calls of the tip's placement, Jacobian, velocity and bias, of
/// the centre of mass's Jacobian and velocity, of the centroidal map and
/// its bias, and of the derivatives of inverse dynamics (returned, and into
/// a pair kept across the calls): their allocations
/// and the call count.
fn frame_calls() -> (usize, usize) {
    let arm = FramedArm::<f64>::new();
    let mut pair = (Matrix2::zeros(), Matrix2::zeros());
    count(|| {
        let mut calls = 0;
        for i in 0..20_000 {
            let q = Vector2::new(0.3 + 1e-5 * f64::from(i), -0.6);
            let qd = Vector2::new(1.0, 0.5);
            let placed = arm.tip_placement(&q, 0.0);
            let j = arm.tip_jacobian(&q, 0.0);
            let v = arm.tip_velocity(&q, &qd, 0.0);
            let b = arm.tip_acceleration_bias(&q, &qd, 0.0);
            let c = arm.center_of_mass_jacobian(&q, 0.0);
            let cd = arm.center_of_mass_velocity(&q, &qd, 0.0);
            let ag = arm.centroidal_map(&q, 0.0);
            let dag = arm.centroidal_map_bias(&q, &qd, 0.0);
            let dtau = arm.inverse_dynamics_jacobian(&q, &qd, &qd, 0.0);
            let both = arm.center_of_mass_and_jacobian(&q, 0.0);
            let kept = arm.inverse_dynamics_jacobian_to(&q, &qd, &qd, 0.0, &mut pair);
            std::hint::black_box((&placed, &j, &v, &b, &c, &cd, &ag, &dag, &dtau, &both, &kept));
            std::hint::black_box(&pair);
            calls += 11;
        }
        calls
    })
}

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn start() -> (DoublePendulum<f64>, State<f64, 4>) {
    let (l1, l2) = (1.2, 0.8);
    let state = constrained::models::double_pendulum_state(l1, l2, 0.0, [2.0, -1.0], [0.5, 1.5]);
    (DoublePendulum::new(1.0, 1.5, l1, l2, 9.81), state)
}

/// Allocations made by `run`, and the number of steps it reports.
fn count(run: impl FnOnce() -> usize) -> (usize, usize) {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    let steps = run();
    (ALLOCATIONS.load(Ordering::SeqCst) - before, steps)
}

fn main() {
    // The counter itself works: a vector allocates once.
    let (allocs, _) = count(|| std::hint::black_box(vec![1u8; 16]).len());
    assert_eq!(
        allocs, 1,
        "the counting allocator must see a Vec's allocation"
    );
    let (system, initial) = start();
    let stabilizations = [
        ("none", Stabilization::None),
        ("Baumgarte", Stabilization::baumgarte(10.0)),
        ("projection", Stabilization::projection(1e-12)),
    ];
    let mut results: Vec<(String, usize, usize)> = Vec::new();
    for (name, stabilization) in stabilizations {
        let mut s = initial;
        let rk4 = Rk4::new(1e-3).with_stabilization(stabilization);
        let (allocs, steps) = count(|| rk4.advance(&system, &mut s, 100.0).expect("rk4").steps);
        results.push((format!("Rk4, {name}"), allocs, steps));

        let mut s = initial;
        // The first-order method at a tenth of the step over a tenth of the
        // time: 10⁵ steps as well. At 1e-3 this chaotic state gains energy
        // until, near t = 25, the velocities reach ~10³ and a projection
        // fails (an honest `Err`, but not what this test is about).
        let euler = SemiImplicitEuler::new(1e-4).with_stabilization(stabilization);
        let (allocs, steps) = count(|| euler.advance(&system, &mut s, 10.0).expect("euler").steps);
        results.push((format!("SemiImplicitEuler, {name}"), allocs, steps));

        let mut s = initial;
        // A step bound makes the adaptive method take at least 10⁵ steps
        // too (its first steps are shorter, hence the extra 0.1 s).
        let dopri = DormandPrince45::new(1e-8, 1e-10)
            .with_max_step(1e-3)
            .with_stabilization(stabilization);
        let (allocs, steps) = count(|| dopri.advance(&system, &mut s, 100.1).expect("dopri").steps);
        results.push((format!("DormandPrince45, {name}"), allocs, steps));
    }
    // Event location: the bobs' horizontal positions crossing zero (both
    // directions, recorded), by the driver and by the single step with a
    // state change at every crossing (the velocities reversed).
    let events = Events::new(
        |s: &State<f64, 4>| [s.q[0], s.q[2]],
        [
            Event::record(Direction::Either),
            Event::record(Direction::Either),
        ],
    );
    let dopri = DormandPrince45::new(1e-8, 1e-10).with_max_step(1e-3);
    let mut s = initial;
    let (allocs, steps) = count(|| {
        let run = dopri
            .advance_events(&system, &mut s, 100.1, &events, |_, _| {})
            .expect("events");
        assert!(run.event_stats.crossings > 100, "{run:?}");
        run.stats.steps
    });
    results.push(("DormandPrince45, advance_events".to_string(), allocs, steps));
    let (allocs, steps) = count(|| {
        let mut stepper = Rk4::new(1e-3).stepper(initial, 100.0).expect("stepper");
        let mut crossings = 0;
        loop {
            match stepper.step(&system, &events).expect("step") {
                StepOutcome::Event(c) => {
                    crossings += 1;
                    let mut reversed = c.state;
                    reversed.qd = -reversed.qd;
                    stepper.set_state(reversed).expect("set");
                }
                StepOutcome::Step => {}
                StepOutcome::Finished => break,
            }
        }
        assert!(crossings > 50, "{crossings}"); // measured: 80
        stepper.stats().steps
    });
    results.push(("Rk4, Stepper with state changes".to_string(), allocs, steps));
    // Linearization and control: 10⁵ Jacobians through the generated
    // structured solve (constant M) and through the runtime's dense one
    // (the cart-pole's M(q)), the multipliers' Jacobians, reduced
    // linearizations, and the LQR design.
    let (allocs, calls) = count(|| {
        let mut calls = 0;
        for i in 0..25_000 {
            let mut s = initial;
            s.q[0] += 1e-6 * f64::from(i % 7);
            let j = system
                .acceleration_jacobian(&s.q, &s.qd, s.t)
                .expect("jacobian");
            let r = system.linearize_reduced(&s.q, &s.qd, s.t).expect("reduced");
            let dl = system
                .multiplier_jacobian(&s.q, &s.qd, s.t)
                .expect("multiplier jacobian");
            std::hint::black_box((&j, &r, &dl));
            let cart_pole = CartPole::new(1.0, 0.3, 0.8, 9.81, 0.1 * f64::from(i % 5));
            let q = Vector2::new(0.1, 2.9);
            let mut j = cart_pole
                .acceleration_jacobian(&q, &q, 0.0)
                .expect("jacobian");
            cart_pole
                .acceleration_jacobian_to(&q, &q, 0.0, &mut j)
                .expect("jacobian, in place");
            let (a, b) = cart_pole.linearize(&q, &q, 0.0).expect("linearize");
            std::hint::black_box((&j, &a, &b));
            calls += 4;
        }
        let cart_pole = CartPole::new(1.0, 0.3, 0.8, 9.81, 0.0);
        let upright = Vector2::new(0.0, std::f64::consts::PI);
        let (a, b) = cart_pole
            .linearize(&upright, &Vector2::zeros(), 0.0)
            .expect("linearize");
        let (ad, bd) = discretize(&a, &b, 0.01).expect("discretize");
        let q_weight = Matrix4::from_diagonal(&Vector4::new(1.0, 10.0, 0.1, 0.1));
        let k = lqr_gain(&ad, &bd, &q_weight, &Matrix1::new(0.1), 1e-12, 10_000).expect("lqr");
        std::hint::black_box(&k);
        calls + 1
    });
    results.push(("Jacobians, linearizations, LQR".to_string(), allocs, calls));
    let (allocs, calls) = frame_calls();
    results.push((
        "frame kinematics, centroidal map, ∂τ".to_string(),
        allocs,
        calls,
    ));
    let mut failed = usize::from(!quadruped_checked());
    for (name, allocs, steps) in &results {
        let ok = *allocs == 0 && *steps >= 100_000;
        // (For the linearization row, `steps` counts the calls.)
        println!(
            "{}: {name}: {steps} steps, {allocs} allocations",
            if ok { "ok" } else { "FAILED" }
        );
        failed += usize::from(!ok);
    }
    println!("{} passed, {failed} failed", results.len() + 1 - failed);
    if failed > 0 {
        std::process::exit(1);
    }
}

/// Runs [`quadruped_standing`] and prints its line: no allocation, at least
/// one step per millisecond, the feet within 1e-9 m.
fn quadruped_checked() -> bool {
    let (allocs, steps, feet) = quadruped_standing();
    println!("quadruped standing 10 s: feet within {feet:.1e} m of their places");
    let ok = allocs == 0 && steps >= 10_000 && feet < 1e-9;
    println!(
        "{}: quadruped, 10 s standing, DormandPrince45 with projection: {steps} steps, {allocs} allocations",
        if ok { "ok" } else { "FAILED" }
    );
    ok
}

/// The standing quadruped of `tests/quadruped.rs`: released at rest with
/// hip flexion 0.8 and knee −1.6 (each foot under its hip), held by
/// `τ = K_p (q_ref − q) − K_d q̇` over each millisecond for 10 s, projected
/// onto the feet's rows (tolerance 1e-12) after every step, the Jacobians
/// of `q̈` and `λ` taken every 0.1 s (through the legs' solve). The
/// allocations of the run, its steps, and the feet's largest distance from
/// their places.
fn quadruped_standing() -> (usize, usize, f64) {
    use constrained::floating::FreeMotion;
    use constrained::nalgebra::{SVector, UnitQuaternion, Vector3};
    use constrained::ConstrainedSystem;
    use model::{Quadruped, FOOT_OFFSET, HIPS, N, SEGMENT};
    let theta: f64 = 0.8;
    let mut feet = [0.0; 8];
    for (k, h) in HIPS.iter().enumerate() {
        feet[2 * k] = h[0];
        feet[2 * k + 1] = h[1] + h[1].signum() * FOOT_OFFSET;
    }
    let base = FreeMotion::at_rest(
        Vector3::new(0.0, 0.0, 2.0 * SEGMENT * theta.cos()),
        UnitQuaternion::identity(),
    );
    let (mut q, mut qd) = (SVector::<f64, N>::zeros(), SVector::<f64, N>::zeros());
    base.write(0, &mut q, &mut qd)
        .expect("seven coordinates fit");
    for leg in 0..4 {
        q[7 + 3 * leg + 1] = theta;
        q[7 + 3 * leg + 2] = -2.0 * theta;
    }
    let mut s = State::new(0.0, q, qd);
    let [a, b, c, d, e, f, g, h] = feet;
    let zero = 0.0;
    let mut sys = Quadruped::new(
        a, b, c, d, e, f, g, h, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero,
        zero,
    );
    let integrator =
        DormandPrince45::new(1e-10, 1e-12).with_stabilization(Stabilization::projection(1e-12));
    let (kp, kd) = (6.0, 0.15);
    let mut worst: f64 = 0.0;
    let (allocs, steps) = count(|| {
        let mut steps = 0;
        for step in 1..=10_000 {
            let tau: [f64; 12] =
                core::array::from_fn(|j| kp * (q[7 + j] - s.q[7 + j]) - kd * s.qd[7 + j]);
            [sys.t_fl_haa, sys.t_fl_hfe, sys.t_fl_kfe] = [tau[0], tau[1], tau[2]];
            [sys.t_fr_haa, sys.t_fr_hfe, sys.t_fr_kfe] = [tau[3], tau[4], tau[5]];
            [sys.t_hl_haa, sys.t_hl_hfe, sys.t_hl_kfe] = [tau[6], tau[7], tau[8]];
            [sys.t_hr_haa, sys.t_hr_hfe, sys.t_hr_kfe] = [tau[9], tau[10], tau[11]];
            let run = integrator
                .advance(&sys, &mut s, f64::from(step) * 1e-3)
                .expect("the quadruped integrates");
            steps += run.steps;
            worst = worst.max(ConstrainedSystem::constraint_residual(&sys, &s).amax());
            if step % 100 == 0 {
                // The Jacobians an MPC asks for, through the legs' solve.
                let both = sys
                    .acceleration_and_multiplier_jacobians(&s.q, &s.qd, s.t)
                    .expect("the quadruped's Jacobians");
                std::hint::black_box(&both);
                // And into the outputs the controller keeps.
                let (mut jac, mut lambdas) = both;
                sys.acceleration_and_multiplier_jacobians_to(
                    &s.q,
                    &s.qd,
                    s.t,
                    &mut jac,
                    &mut lambdas,
                )
                .expect("the quadruped's Jacobians, in place");
                std::hint::black_box((&jac, &lambdas));
            }
        }
        steps
    });
    (allocs, steps, worst)
}
