//! Integrators that advance a [`State`] with no heap allocation.
//!
//! - [`Rk4`]: classical fourth-order Runge–Kutta, fixed step.
//! - [`DormandPrince45`]: adaptive 5(4) pair with error control, step
//!   rejection and first-same-as-last.
//! - [`SemiImplicitEuler`]: first order, one evaluation a step, for hard
//!   real-time loops.
//!
//! Each takes an opt-in [`Stabilization`] against constraint drift, and
//! reports failures as [`IntegrationError`] values, never panics: a
//! non-finite state, a step size that underflows, too many steps, a mass
//! matrix that is not positive definite, a projection that does not converge.

/// The methods every integrator has: the two settings it shares
/// (`stabilization`, `max_steps`) and `advance`, which is `advance_with`
/// without an observer.
macro_rules! common_methods {
    ($integrator:ident) => {
        impl<T: RealField + Copy> $integrator<T> {
            /// The same with a stabilization against constraint drift.
            pub fn with_stabilization(mut self, stabilization: Stabilization<T>) -> Self {
                self.stabilization = stabilization;
                self
            }

            /// The same with at most `max_steps` steps per call (rejected
            /// steps of an adaptive method count).
            pub fn with_max_steps(mut self, max_steps: usize) -> Self {
                self.max_steps = max_steps;
                self
            }

            /// Advances `state` to `t_end`.
            pub fn advance<S, const N: usize, const K: usize>(
                &self,
                system: &S,
                state: &mut State<T, N>,
                t_end: T,
            ) -> Result<Stats, IntegrationError<T>>
            where
                S: ConstrainedSystem<T, N, K>,
            {
                self.advance_with(system, state, t_end, |_| {})
            }
        }
    };
}

mod dopri45;
mod euler;
mod rk4;

pub use dopri45::DormandPrince45;
pub use euler::SemiImplicitEuler;
pub use rk4::Rk4;

use crate::stabilize::{baumgarte_correction, project, Stabilization};
use crate::{ConstrainedSystem, DynamicsError, State};
use core::fmt;
use nalgebra::{RealField, SVector};

/// Why an integration stopped early. Each carries the time it stopped at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegrationError<T> {
    /// The state became NaN or infinite.
    NonFiniteState {
        /// Time of the last finite state.
        t: T,
    },
    /// The adaptive step size fell below what the time's precision resolves.
    StepSizeUnderflow {
        /// Time reached.
        t: T,
        /// The step size that was too small.
        step: T,
    },
    /// The step budget ran out before the end time.
    TooManySteps {
        /// Time reached.
        t: T,
        /// The budget.
        steps: usize,
    },
    /// The equations of motion could not be evaluated.
    Dynamics {
        /// Time of the failing evaluation.
        t: T,
        /// Why.
        error: DynamicsError,
    },
    /// Projection onto the constraints did not converge.
    ProjectionFailed {
        /// Time of the step.
        t: T,
        /// The largest constraint residual left.
        residual: T,
    },
    /// The end time lies before the current time.
    EndBeforeStart {
        /// Current time.
        t: T,
        /// Requested end time.
        t_end: T,
    },
    /// A step size or tolerance that is not positive and finite.
    InvalidParameter,
}

impl<T: fmt::Display> fmt::Display for IntegrationError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IntegrationError::NonFiniteState { t } => {
                write!(f, "the state became non-finite after t = {t}")
            }
            IntegrationError::StepSizeUnderflow { t, step } => write!(
                f,
                "the step size {step} underflowed at t = {t}: the problem is too stiff \
                 or singular for the tolerances"
            ),
            IntegrationError::TooManySteps { t, steps } => {
                write!(f, "{steps} steps were not enough: stopped at t = {t}")
            }
            IntegrationError::Dynamics { t, error } => write!(f, "at t = {t}: {error}"),
            IntegrationError::ProjectionFailed { t, residual } => write!(
                f,
                "projection onto the constraints did not converge at t = {t} \
                 (residual {residual})"
            ),
            IntegrationError::EndBeforeStart { t, t_end } => {
                write!(f, "the end time {t_end} lies before the current time {t}")
            }
            IntegrationError::InvalidParameter => {
                f.write_str("a step size or tolerance must be positive and finite")
            }
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for IntegrationError<T> {}

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

/// `(q̇, q̈)` at a state, with the stabilization's correction of `b`.
fn derivative<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &State<T, N>,
    stabilization: &Stabilization<T>,
    stats: &mut Stats,
) -> Result<(SVector<T, N>, SVector<T, N>), IntegrationError<T>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    stats.evaluations += 1;
    let qdd = match baumgarte_correction(system, state, stabilization) {
        Some(db) => system.acceleration_corrected(state, &db),
        None => system.acceleration(state),
    }
    .map_err(|error| IntegrationError::Dynamics { t: state.t, error })?;
    if qdd.iter().all(|x| x.is_finite()) {
        Ok((state.qd, qdd))
    } else {
        Err(IntegrationError::NonFiniteState { t: state.t })
    }
}

/// After an accepted step: finite check, then projection if asked for.
/// Returns whether the state was changed by the projection.
fn accept<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &mut State<T, N>,
    stabilization: &Stabilization<T>,
) -> Result<bool, IntegrationError<T>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    if !state.is_finite() {
        return Err(IntegrationError::NonFiniteState { t: state.t });
    }
    match *stabilization {
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

/// The loop shared by the fixed-step methods: steps of `step` (the last one
/// shortened to land on `t_end`), each made by `advance_one(state, h,
/// stats)`, then checked, stabilized and observed.
#[allow(clippy::too_many_arguments)]
fn fixed_steps<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &mut State<T, N>,
    t_end: T,
    step: T,
    max_steps: usize,
    stabilization: &Stabilization<T>,
    mut advance_one: impl FnMut(&mut State<T, N>, T, &mut Stats) -> Result<(), IntegrationError<T>>,
    mut observer: impl FnMut(&State<T, N>),
) -> Result<Stats, IntegrationError<T>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    if !(step > T::zero() && step.is_finite()) {
        return Err(IntegrationError::InvalidParameter);
    }
    let mut remaining = span(state, t_end)?;
    let mut stats = Stats::default();
    let slack = T::one() + c::<T>(64.0) * T::default_epsilon();
    while remaining > T::zero() {
        if stats.steps == max_steps {
            return Err(IntegrationError::TooManySteps {
                t: state.t,
                steps: stats.steps,
            });
        }
        let last = remaining <= step * slack;
        let h = if last { remaining } else { step };
        let t = state.t;
        advance_one(state, h, &mut stats)?;
        state.t = if last { t_end } else { t + h };
        remaining = if last { T::zero() } else { t_end - state.t };
        stats.steps += 1;
        accept(system, state, stabilization)?;
        observer(state);
    }
    Ok(stats)
}

/// Validates the end time and returns the span to cover.
fn span<T: RealField + Copy, const N: usize>(
    state: &State<T, N>,
    t_end: T,
) -> Result<T, IntegrationError<T>> {
    if !t_end.is_finite() {
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
