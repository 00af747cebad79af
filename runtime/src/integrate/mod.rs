//! Integrators that advance a [`State`] with no heap allocation.
//!
//! One explicit Runge–Kutta engine steps every method; a method is data, a
//! Butcher [`Tableau`] named by a marker type ([`tableau`]):
//! - [`Rk4`]: classical fourth-order Runge–Kutta, fixed step;
//!   [`ThreeEighthsRule`]: Kutta's 3/8 rule, the same with smaller error
//!   constants. Both are [`ExplicitRungeKutta`] with another tableau.
//! - [`DormandPrince45`]: adaptive 5(4) pair with error control, step
//!   rejection and first-same-as-last; [`BogackiShampine32`]: the 3(2) pair
//!   for loose tolerances. Both are [`EmbeddedRungeKutta`], whose step size
//!   follows a [`PiController`].
//! - [`SemiImplicitEuler`]: first order, one evaluation a step, for hard
//!   real-time loops (its own update, on the same driver).
//!
//! Every entry point (`advance`, `advance_with`, `advance_sampled`,
//! `advance_events`) runs one loop of [`Stepper`] steps, and every
//! Runge–Kutta step is one routine, whatever the tableau.
//!
//! Each takes an opt-in [`Stabilization`] against constraint drift, and
//! reports failures as [`IntegrationError`] values, never panics: a
//! non-finite state, a step size that underflows, too many steps, a mass
//! matrix that is not positive definite, a projection that does not converge.

/// What every integrator shares: its settings (`with_stabilization`,
/// `with_max_steps`, and for the stepper `Configured`), its entry points
/// on the one driver loop (`advance_with`, `advance`, which is
/// `advance_with` without an observer, `advance_events`) and the
/// single-step API (`stepper`).
/// Arguments: the type with its generic parameters, its number of stages,
/// then the bounds of its parameters besides `T`.
macro_rules! shared_settings {
    ($integrator:ident < T $(, $param:ident)* >, $stages:tt $(, $($bounds:tt)*)?) => {
        impl<T: RealField + Copy $(, $($bounds)*)?> $crate::integrate::stepper::Configured<T>
            for $integrator<T $(, $param)*>
        {
            fn duplicate(&self) -> Self {
                // Field by field: each is `Copy` (a marker's `PhantomData`
                // too), where the derived `Clone` asks it of the marker.
                Self { ..*self }
            }

            #[allow(private_interfaces)]
            fn settings(&self) -> &$crate::integrate::Settings<T> {
                &self.settings
            }
        }

        impl<T: RealField + Copy $(, $($bounds)*)?> $integrator<T $(, $param)*> {
            /// The same with a stabilization against constraint drift.
            pub fn with_stabilization(
                mut self,
                stabilization: $crate::stabilize::Stabilization<T>,
            ) -> Self {
                self.settings.stabilization = stabilization;
                self
            }

            /// The same with at most `max_steps` steps per call (rejected
            /// steps of an adaptive method count).
            pub fn with_max_steps(mut self, max_steps: usize) -> Self {
                self.settings.max_steps = max_steps;
                self
            }

            /// Advances `state` to `t_end`, calling `observer` after every
            /// accepted step.
            pub fn advance_with<Sys, const N: usize, const K: usize>(
                &self,
                system: &Sys,
                state: &mut State<T, N>,
                t_end: T,
                mut observer: impl FnMut(&State<T, N>),
            ) -> Result<Stats, IntegrationError<T>>
            where
                Sys: ConstrainedSystem<T, N, K>,
            {
                let method = $crate::integrate::stepper::Configured::duplicate(self);
                // The observer sees no step's inside: a fixed-step run
                // leaves each end's derivative to the next step; an
                // adaptive one evaluates it with its step, as its stepper
                // does, so that a run counts the same evaluations with
                // events as without.
                let extension = $crate::integrate::stepper::StepMethod::fixed_step(&method).is_none();
                $crate::integrate::stepper::advance(method, system, state, t_end, extension, |_, end| {
                    observer(end)
                })
            }

            /// Advances `state` to `t_end`.
            pub fn advance<Sys, const N: usize, const K: usize>(
                &self,
                system: &Sys,
                state: &mut State<T, N>,
                t_end: T,
            ) -> Result<Stats, IntegrationError<T>>
            where
                Sys: ConstrainedSystem<T, N, K>,
            {
                self.advance_with(system, state, t_end, |_| {})
            }

            /// A [`Stepper`](crate::integrate::Stepper): this integration one accepted step at a time,
            /// from `state` to `t_end`, with `E` event functions (`Err` as
            /// for `advance`, before any step).
            pub fn stepper<const N: usize, const E: usize>(
                &self,
                state: State<T, N>,
                t_end: T,
            ) -> Result<$crate::integrate::Stepper<T, Self, N, $stages, E>, IntegrationError<T>> {
                $crate::integrate::Stepper::new(
                    $crate::integrate::stepper::Configured::duplicate(self),
                    state,
                    t_end,
                )
            }

            /// Advances `state` to `t_end` locating the crossings of
            /// `events` ([`events`](crate::integrate::events)):
            /// `handler(&crossing, &mut state)` runs at each, in time
            /// order, with the state there; a state it changes is the one
            /// the integration restarts from. Returns at `t_end` or at the
            /// first crossing whose action is [`Action::Stop`](crate::integrate::Action::Stop) (in
            /// [`EventRun::stopped`](crate::integrate::EventRun::stopped)), with `state` where it stopped.
            pub fn advance_events<Sys, F, D, const N: usize, const K: usize, const E: usize>(
                &self,
                system: &Sys,
                state: &mut State<T, N>,
                t_end: T,
                events: &$crate::integrate::Events<T, F, E, D>,
                handler: impl FnMut(&$crate::integrate::Crossing<T, N>, &mut State<T, N>),
            ) -> Result<$crate::integrate::EventRun<T, N>, IntegrationError<T>>
            where
                Sys: ConstrainedSystem<T, N, K>,
                F: Fn(&State<T, N>) -> [T; E],
                D: $crate::integrate::events::Rates<T, N, E>,
            {
                let mut stepper = self.stepper(*state, t_end)?;
                $crate::integrate::stepper::drive(&mut stepper, system, state, events, |_, _| {}, handler)
            }
        }
    };
}

mod accepted;
mod controller;
mod dense_output;
mod embedded;
mod euler;
pub mod events;
mod explicit;
mod method;
mod screening;
mod search;
mod stepper;
mod stick_slip;
pub mod tableau;

pub use controller::PiController;
pub use embedded::EmbeddedRungeKutta;
pub use euler::SemiImplicitEuler;
pub use events::{
    Action, Crossing, Direction, Event, EventStats, Events, NoRates, Rates, WithRates,
};
pub use explicit::ExplicitRungeKutta;
pub use stepper::{EventRun, StepOutcome, Stepper};
pub use stick_slip::{StickSlip, StickSlipOutcome};
pub use tableau::Tableau;

use crate::stabilize::{baumgarte_correction, project, Stabilization};
use crate::{ConstrainedSystem, DynamicsError, IntegrationError, State};
use nalgebra::{RealField, SVector};

/// Classical fourth-order Runge–Kutta with a fixed step: four evaluations a
/// step; the last step is shortened to land on the end time.
pub type Rk4<T> = ExplicitRungeKutta<T, tableau::Classic4, 4>;

/// Kutta's 3/8 rule with a fixed step (fourth order, four evaluations).
pub type ThreeEighthsRule<T> = ExplicitRungeKutta<T, tableau::ThreeEighths, 4>;

/// The Dormand–Prince 5(4) method with adaptive steps (see
/// [`EmbeddedRungeKutta`]): six evaluations per accepted step.
pub type DormandPrince45<T> = EmbeddedRungeKutta<T, tableau::DormandPrince, 7>;

/// The Bogacki–Shampine 3(2) method with adaptive steps (see
/// [`EmbeddedRungeKutta`]): three evaluations per accepted step.
pub type BogackiShampine32<T> = EmbeddedRungeKutta<T, tableau::BogackiShampine, 4>;

/// What an integration did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps (adaptive methods).
    pub rejected: usize,
    /// Evaluations of the acceleration.
    pub evaluations: usize,
}

/// `(q̇, q̈)`: the derivative of the state `(q, q̇)`.
type Derivative<T, const N: usize> = (SVector<T, N>, SVector<T, N>);

/// What every integrator is configured with.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Settings<T> {
    stabilization: Stabilization<T>,
    /// Steps allowed per call (accepted and rejected).
    max_steps: usize,
}

impl<T> Settings<T> {
    fn new(max_steps: usize) -> Self {
        Settings {
            stabilization: Stabilization::None,
            max_steps,
        }
    }
}

impl<T: RealField + Copy> Settings<T> {
    /// `Err(InvalidParameter)` for a setting that cannot work, before any
    /// step is taken: a zero budget, a Baumgarte rate that is negative or
    /// not finite, a projection tolerance that is not positive and finite.
    fn validate(&self) -> Result<(), IntegrationError<T>> {
        let rate = |x: T| x >= T::zero() && x.is_finite();
        let valid = self.max_steps > 0
            && match self.stabilization {
                Stabilization::None => true,
                Stabilization::Baumgarte { alpha, beta, gamma } => {
                    rate(alpha) && rate(beta) && rate(gamma)
                }
                Stabilization::Projection {
                    tolerance,
                    max_iterations,
                } => tolerance > T::zero() && tolerance.is_finite() && max_iterations > 0,
            };
        if valid {
            Ok(())
        } else {
            Err(IntegrationError::InvalidParameter)
        }
    }
}

/// Fixed-step integrators' default budget per call: ten million steps
/// (`with_max_steps` raises it), so that no setting can loop for ever.
const FIXED_STEP_BUDGET: usize = 10_000_000;

/// `(q̇, q̈)` at a state, with the stabilization's correction of `b`,
/// written to `out`: the stepper's buffers, where the value is needed, so
/// that it is not returned through memory and moved there (per evaluation of a cheap system that move cost a fifth of the
/// evaluation). `out` is unchanged on `Err`.
#[inline]
fn derivative_into<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &State<T, N>,
    settings: &Settings<T>,
    stats: &mut Stats,
    out: &mut Derivative<T, N>,
) -> Result<(), IntegrationError<T>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    stats.evaluations += 1;
    out.1 = stabilized_acceleration(system, state, settings)?;
    out.0 = state.qd;
    Ok(())
}

/// `q̈` at a state, with the stabilization's correction of `b`.
#[inline(always)]
fn stabilized_acceleration<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &State<T, N>,
    settings: &Settings<T>,
) -> Result<SVector<T, N>, IntegrationError<T>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    match baumgarte_correction(system, state, &settings.stabilization) {
        Some(db) => system.acceleration_corrected(state, &db),
        None => system.acceleration(state),
    }
    .map_err(|error| match error {
        // The acceleration of a stage blew up: the state is on its way to
        // non-finite values, which is what the caller is told.
        DynamicsError::NonFinite => IntegrationError::NonFiniteState { t: state.t },
        error => IntegrationError::Dynamics { t: state.t, error },
    })
}

/// After an accepted step: finite check, then projection if asked for.
/// Returns whether the state was changed by the projection.
#[inline]
fn accept<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &mut State<T, N>,
    settings: &Settings<T>,
) -> Result<bool, IntegrationError<T>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    if !state.is_finite() {
        return Err(IntegrationError::NonFiniteState { t: state.t });
    }
    match settings.stabilization {
        Stabilization::Projection {
            tolerance,
            max_iterations,
        } => {
            project(system, state, tolerance, max_iterations)?;
            Ok(true)
        }
        _ => Ok(false),
    }
}

/// Validates the starting state and the end time and returns the span to
/// cover. A non-finite `t`, `q` or `q̇` is refused up front: from
/// `t = NaN` every comparison is false, and the loops returned `Ok` after
/// no step with `t` still NaN.
fn span<T: RealField + Copy, const N: usize>(
    state: &State<T, N>,
    t_end: T,
) -> Result<T, IntegrationError<T>> {
    if !(t_end.is_finite() && state.is_finite()) {
        return Err(IntegrationError::InvalidParameter);
    }
    if t_end < state.t {
        return Err(IntegrationError::EndBeforeStart { t: state.t, t_end });
    }
    Ok(t_end - state.t)
}

/// `x` as `T`.
fn c<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert::<f64, T>(x)
}
