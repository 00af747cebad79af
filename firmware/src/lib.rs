//! The simulation the firmware runs, `no_std` and in `f32`, shared by the
//! bare-metal binary and its host run so that both execute the same code.

#![no_std]

use constrained::control::{discretize, lqr_gain, ControlError};
use constrained::models::{Appell, CartPole, DoublePendulum};
// nalgebra's functions (libm) rather than f32's inherent ones: available
// without std, and the same code on the host and the target.
use constrained::integrate::{Direction, Event, Events, StepOutcome};
use constrained::nalgebra::Vector1;
use constrained::nalgebra::{
    convert, ComplexField, Matrix1, Matrix4, RealField, SMatrix, Vector2, Vector3, Vector4,
};
use constrained::{
    constrained_system, DormandPrince45, DynamicsError, IntegrationError, Rk4, Stabilization, State,
};

/// Simulated time, s.
pub const DURATION: f32 = 5.0;
/// RK4 step, s.
pub const STEP: f32 = 1e-3;

/// The cart-pole's masses (cart, pole), pole length and gravity.
const CART_POLE: [f32; 4] = [1.0, 0.3, 0.8, 9.81];
/// The control period of the cart-pole's loop (zero-order hold), s.
pub const PERIOD: f32 = 0.01;
/// The pole's initial offset from upright, rad.
pub const OFFSET: f32 = 0.3;
/// Simulated time of the closed loop, s.
pub const LOOP_DURATION: f32 = 6.0;

#[path = "../../examples/support/panda.rs"]
mod panda;
mod tool;
pub use tool::{tool_controller_step, track_circle, ToolTrack, TOOL_DURATION};

#[path = "../../examples/support/rimless_wheel.rs"]
mod rimless_wheel;
pub use rimless_wheel::RimlessWheel;

/// Heel strikes of the rimless wheel located on the device.
pub const STRIKES: usize = 4;

/// Bounces of the ball located on the device.
pub const BOUNCES: usize = 10;
/// The ball's restitution.
pub const RESTITUTION: f32 = 0.8;

constrained_system! {
    /// A ball of unit mass under gravity `g`, over the ground `y = 0`.
    pub struct Ball {
        coordinates: [y],
        parameters: [g],
        mass: diag[1.0],
        forces: [-g],
    }
}

/// Why the firmware's run stopped.
#[derive(Debug)]
pub enum Failure<T = f32> {
    /// An integrator failed.
    Integration(IntegrationError<T>),
    /// The linearization failed.
    Dynamics(DynamicsError),
    /// The LQR design failed.
    Control(ControlError),
    /// The Panda's tool Jacobian lost rank.
    Singular,
}

impl<T> From<IntegrationError<T>> for Failure<T> {
    fn from(e: IntegrationError<T>) -> Self {
        Failure::Integration(e)
    }
}

impl<T> From<DynamicsError> for Failure<T> {
    fn from(e: DynamicsError) -> Self {
        Failure::Dynamics(e)
    }
}

impl<T> From<ControlError> for Failure<T> {
    fn from(e: ControlError) -> Self {
        Failure::Control(e)
    }
}

/// The final states of the simulations, the largest constraint residual
/// seen along each, and the cart-pole's gain and closed loop.
pub struct Report {
    /// Appell's particle at `DURATION`.
    pub appell: State<f32, 3>,
    /// Largest |φ| of Appell's particle.
    pub appell_residual: f32,
    /// The double pendulum at `DURATION`.
    pub pendulum: State<f32, 4>,
    /// Largest |φ| of the double pendulum.
    pub pendulum_residual: f32,
    /// The LQR gain for `(s, θ − π, ṡ, θ̇)`, designed on the device from the
    /// generated `linearize` at the upright state.
    pub gain: SMatrix<f32, 1, 4>,
    /// The open-loop poles' scale: the upright linearization's `A[3][1]`
    /// (`∂θ̈/∂θ`, `g (m_c + m_p)/(m_c l)` in closed form).
    pub upright_stiffness: f32,
    /// The cart-pole at `LOOP_DURATION` under that gain.
    pub cart_pole: State<f32, 2>,
    /// Largest |θ − π| over the last second of the loop.
    pub cart_pole_late_offset: f32,
    /// The times of the ball's first `BOUNCES` impacts (event location).
    pub bounces: [f32; BOUNCES],
    /// How many impacts were located before the run's end (`BOUNCES`).
    pub bounce_count: usize,
    /// The rimless wheel's heel strikes (see [`roll_wheel`]).
    pub wheel: Strikes,
    /// The Panda's tool on its circle (see [`track_circle`]).
    pub tool: ToolTrack,
}

/// The rimless wheel's rate `θ̇` just before and just after each of its
/// first `STRIKES` heel strikes, and how many were located.
pub struct Strikes {
    /// `θ̇⁻` at each strike.
    pub before: [f32; STRIKES],
    /// `θ̇⁺` from the generated impact map.
    pub after: [f32; STRIKES],
    /// Strikes located (`STRIKES`).
    pub count: usize,
}

/// Appell's particle (g = 9.81, α = 0.5, h = z) from a state on its
/// constraint, and a double pendulum (Baumgarte-stabilized), each `DURATION`
/// seconds of RK4 with step `STEP`.
pub fn simulate() -> Result<Report, Failure> {
    let appell_system = Appell::<f32>::new(9.81, 0.5);
    let (xd, yd, z) = (1.2f32, 0.7f32, 1.0f32);
    // ẋ² + ẏ² − ż² = 2αz fixes ż.
    let zd = ComplexField::sqrt(xd * xd + yd * yd - 2.0 * 0.5 * z);
    let mut appell = State::new(0.0, Vector3::new(0.3, -0.4, z), Vector3::new(xd, yd, zd));
    let mut appell_residual = 0.0f32;
    Rk4::new(STEP).advance_with(&appell_system, &mut appell, DURATION, |s| {
        let phi = appell_system.constraint_residual(&s.q, &s.qd, s.t)[0].abs();
        appell_residual = appell_residual.max(phi);
    })?;

    let (l1, l2) = (1.0f32, 0.7f32);
    let pendulum_system = DoublePendulum::<f32>::new(1.0, 0.5, l1, l2, 9.81);
    let (t1, t2) = (1.2f32, -0.4f32);
    let (s1, c1) = (ComplexField::sin(t1), ComplexField::cos(t1));
    let (s2, c2) = (ComplexField::sin(t2), ComplexField::cos(t2));
    let mut pendulum = State::new(
        0.0,
        Vector4::new(l1 * s1, -l1 * c1, l1 * s1 + l2 * s2, -l1 * c1 - l2 * c2),
        Vector4::zeros(),
    );
    let mut pendulum_residual = 0.0f32;
    Rk4::new(STEP)
        .with_stabilization(Stabilization::baumgarte(20.0))
        .advance_with(&pendulum_system, &mut pendulum, DURATION, |s| {
            let phi = pendulum_system.constraint_residual(&s.q, &s.qd, s.t).amax();
            pendulum_residual = pendulum_residual.max(phi);
        })?;
    let balanced = balance::<f32>()?;
    let (bounces, bounce_count) = bounce()?;
    let wheel = roll_wheel()?;
    let tool = track_circle()?;
    Ok(Report {
        appell,
        appell_residual,
        pendulum,
        pendulum_residual,
        gain: balanced.gain,
        upright_stiffness: balanced.upright_stiffness,
        cart_pole: balanced.state,
        cart_pole_late_offset: balanced.late_offset,
        bounces,
        bounce_count,
        wheel,
        tool,
    })
}

/// A ball dropped from 1 m bouncing with restitution `RESTITUTION`, the
/// bounce being the event's state change `v → −e v`, located by
/// Dormand–Prince 4(5) in `f32` to the time `8 t₁` (between the 10th
/// impact, at ≈ 7.93 t₁, and the 11th, at ≈ 8.14 t₁; `t₁ = √(2/g)`).
pub fn bounce() -> Result<([f32; BOUNCES], usize), Failure> {
    let system = Ball::<f32>::new(9.81);
    let ground = Events::new(
        |s: &State<f32, 1>| [s.q.x],
        [Event::record(Direction::Falling)],
    );
    let t1 = ComplexField::sqrt(2.0f32 / 9.81);
    let mut ball = State::new(0.0, Vector1::new(1.0), Vector1::new(0.0));
    let mut times = [0.0f32; BOUNCES];
    let mut count = 0;
    DormandPrince45::new(1e-5, 1e-6).advance_events(
        &system,
        &mut ball,
        8.0 * t1,
        &ground,
        |crossing, state| {
            if let Some(slot) = times.get_mut(count) {
                *slot = crossing.t;
            }
            count += 1;
            state.qd = -RESTITUTION * state.qd;
        },
    )?;
    Ok((times, count))
}

/// The cart-pole balanced by an LQR, all on the device: the generated
/// `linearize` at the upright state, its zero-order-hold discretization, the
/// discrete Riccati iteration to the gain, then `LOOP_DURATION` seconds of
/// the closed loop from a pole `OFFSET` off upright, the push set every
/// `PERIOD` and held over four RK4 steps (`examples/cart_pole_lqr.rs` in
/// f32). Generic so that the host can run it in f64 as a reference.
pub fn balance<T: RealField + Copy>() -> Result<Balanced<T>, Failure<T>> {
    let c = |x: f32| -> T { convert(f64::from(x)) };
    let [mc, mp, l, g] = CART_POLE.map(c);
    let mut system = CartPole::<T>::new(mc, mp, l, g, T::zero());
    let upright = T::pi();
    let (a, b) = system.linearize(
        &Vector2::new(T::zero(), upright),
        &Vector2::zeros(),
        T::zero(),
    )?;
    let period = c(PERIOD);
    let (ad, bd) = discretize(&a, &b, period)?;
    let weights = Matrix4::from_diagonal(&Vector4::new(c(1.0), c(10.0), c(0.1), c(0.1)));
    // Ten ulps in f32; the example's 1e-12 in f64.
    let tolerance = (T::default_epsilon() * c(10.0)).max(convert(1e-12));
    let gain = lqr_gain(&ad, &bd, &weights, &Matrix1::new(c(0.1)), tolerance, 10_000)?;
    let mut state = State::new(
        T::zero(),
        Vector2::new(T::zero(), upright + c(OFFSET)),
        Vector2::zeros(),
    );
    let rk4 = Rk4::new(period / c(4.0));
    let mut late_offset = T::zero();
    // A bounded loop: the number of control periods, not a time comparison.
    let periods = (LOOP_DURATION / PERIOD) as usize;
    let late = c(LOOP_DURATION - 1.0);
    for k in 0..periods {
        let x = Vector4::new(state.q[0], state.q[1] - upright, state.qd[0], state.qd[1]);
        system.push = -(gain * x)[0];
        let t_end = c((k + 1) as f32) * period;
        rk4.advance(&system, &mut state, t_end)?;
        if t_end > late {
            late_offset = late_offset.max((state.q[1] - upright).abs());
        }
    }
    Ok(Balanced {
        gain,
        upright_stiffness: a[(3, 1)],
        state,
        late_offset,
    })
}

/// What [`balance`] reports.
pub struct Balanced<T: RealField + Copy> {
    /// The LQR gain for `(s, θ − π, ṡ, θ̇)`.
    pub gain: SMatrix<T, 1, 4>,
    /// `∂θ̈/∂θ` at upright: `g (m_c + m_p)/(m_c l)` in closed form.
    pub upright_stiffness: T,
    /// The cart-pole at `LOOP_DURATION`.
    pub state: State<T, 2>,
    /// Largest |θ − π| over the loop's last second.
    pub late_offset: T,
}

/// The rimless wheel of the example `rimless_wheel` (8 spokes, slope 0.1,
/// `I = 0.05`, `m = l = 1`) in `f32`, rolled from just after a heel strike
/// at −1.2 rad/s: each strike located as the falling zero of the next
/// foot's gap (Dormand–Prince 4(5) with projection, a [`Stepper`] driven
/// by hand), the next spoke pinned where it touched, and the post-strike
/// velocity from the generated impact map. McGeer's closed form says each
/// strike scales the rate by `(I + m l² cos a2)/(I + m l²)`; the bound
/// on the loop is on steps, not on time.
///
/// [`Stepper`]: constrained::integrate::Stepper
pub fn roll_wheel() -> Result<Strikes, Failure> {
    let w = RimlessWheel::<f32>::new(
        1.0,
        0.05,
        1.0,
        9.81,
        core::f32::consts::FRAC_PI_4,
        0.1,
        0.0,
        0.0,
        0.0,
    );
    let omega = -1.2f32;
    // Both feet on the slope, the stance foot at the origin, rotating
    // about it.
    let stance = w.a2 / 2.0 - w.gamma;
    let q = Vector3::new(
        -w.l * ComplexField::sin(stance),
        w.l * ComplexField::cos(stance),
        stance - w.phase,
    );
    let qd = Vector3::new(-omega * q[1], omega * q[0], omega);
    let mut stepper = DormandPrince45::new(1e-5, 1e-6)
        .with_stabilization(Stabilization::projection(1e-5))
        .stepper(State::new(0.0, q, qd), 100.0)?;
    let mut strikes = Strikes {
        before: [0.0; STRIKES],
        after: [0.0; STRIKES],
        count: 0,
    };
    let mut wheel = w;
    // Each stride is a few tens of steps: 10⁴ calls are far more than
    // `STRIKES` need, and the loop cannot run on unbounded.
    for _ in 0..10_000 {
        if strikes.count == STRIKES {
            break;
        }
        let current = wheel;
        let events = Events::new(
            move |s: &State<f32, 3>| [current.gaps(&s.q, s.t)[0]],
            [Event::stop(Direction::Falling)],
        );
        match stepper.step(&wheel, &events)? {
            StepOutcome::Event(crossing) => {
                let s = crossing.state;
                let next = wheel.phase + wheel.a2;
                let spoke = s.q[2] + next;
                wheel = RimlessWheel {
                    phase: next,
                    px: s.q[0] + wheel.l * ComplexField::sin(spoke),
                    py: s.q[1] - wheel.l * ComplexField::cos(spoke),
                    ..wheel
                };
                let hit = wheel.impact(&s.q, &s.qd, s.t, [false], [0.0])?;
                if let (Some(b), Some(a)) = (
                    strikes.before.get_mut(strikes.count),
                    strikes.after.get_mut(strikes.count),
                ) {
                    (*b, *a) = (s.qd[2], hit.qd[2]);
                }
                strikes.count += 1;
                stepper.set_state(State::new(s.t, s.q, hit.qd))?;
            }
            StepOutcome::Step => {}
            StepOutcome::Finished => break,
        }
    }
    Ok(strikes)
}

/// Writes the report as `name value value …` lines, values in `{:e}` (the
/// shortest form that reads back to the same f32).
pub fn write_report(out: &mut impl core::fmt::Write, report: &Report) -> core::fmt::Result {
    let mut line = |name: &str, values: &[f32]| -> core::fmt::Result {
        write!(out, "{name}")?;
        for v in values {
            write!(out, " {v:e}")?;
        }
        writeln!(out)
    };
    line("appell_t", &[report.appell.t])?;
    line("appell_q", report.appell.q.as_slice())?;
    line("appell_qd", report.appell.qd.as_slice())?;
    line("appell_max_residual", &[report.appell_residual])?;
    line("pendulum_t", &[report.pendulum.t])?;
    line("pendulum_q", report.pendulum.q.as_slice())?;
    line("pendulum_qd", report.pendulum.qd.as_slice())?;
    line("pendulum_max_residual", &[report.pendulum_residual])?;
    line("cart_pole_gain", report.gain.as_slice())?;
    line("cart_pole_upright_stiffness", &[report.upright_stiffness])?;
    line("cart_pole_t", &[report.cart_pole.t])?;
    line("cart_pole_q", report.cart_pole.q.as_slice())?;
    line("cart_pole_qd", report.cart_pole.qd.as_slice())?;
    line("cart_pole_late_offset", &[report.cart_pole_late_offset])?;
    line("ball_bounces", &report.bounces)?;
    line("ball_bounce_count", &[report.bounce_count as f32])?;
    line("wheel_rate_before", &report.wheel.before)?;
    line("wheel_rate_after", &report.wheel.after)?;
    line("wheel_strike_count", &[report.wheel.count as f32])?;
    line("tool_error_peak", &[report.tool.peak])?;
    line("tool_error_last", &[report.tool.last])
}
