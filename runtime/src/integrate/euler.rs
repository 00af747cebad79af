use super::{accept, c, derivative, span, IntegrationError, Stats};
use crate::stabilize::Stabilization;
use crate::{ConstrainedSystem, State};
use nalgebra::RealField;

/// Semi-implicit (symplectic) Euler with a fixed step:
/// `q̇ₙ₊₁ = q̇ₙ + h q̈(qₙ, q̇ₙ)`, `qₙ₊₁ = qₙ + h q̇ₙ₊₁`. First order, one
/// evaluation a step and bounded energy error for conservative systems:
/// the choice for hard real-time loops where the step is fixed by the loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SemiImplicitEuler<T> {
    step: T,
    stabilization: Stabilization<T>,
    max_steps: usize,
}

impl<T: RealField + Copy> SemiImplicitEuler<T> {
    /// Steps of size `step`, no stabilization, no step budget.
    pub fn new(step: T) -> Self {
        SemiImplicitEuler {
            step,
            stabilization: Stabilization::None,
            max_steps: usize::MAX,
        }
    }

    /// The same with a stabilization against constraint drift.
    pub fn with_stabilization(mut self, stabilization: Stabilization<T>) -> Self {
        self.stabilization = stabilization;
        self
    }

    /// The same with at most `max_steps` steps per call.
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

    /// Advances `state` to `t_end`, calling `observer` after every step.
    pub fn advance_with<S, const N: usize, const K: usize>(
        &self,
        system: &S,
        state: &mut State<T, N>,
        t_end: T,
        mut observer: impl FnMut(&State<T, N>),
    ) -> Result<Stats, IntegrationError<T>>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        if !(self.step > T::zero() && self.step.is_finite()) {
            return Err(IntegrationError::InvalidParameter);
        }
        let mut remaining = span(state, t_end)?;
        let mut stats = Stats::default();
        let slack = T::one() + c::<T>(64.0) * T::default_epsilon();
        while remaining > T::zero() {
            if stats.steps == self.max_steps {
                return Err(IntegrationError::TooManySteps {
                    t: state.t,
                    steps: stats.steps,
                });
            }
            let last = remaining <= self.step * slack;
            let h = if last { remaining } else { self.step };
            let (_, qdd) = derivative(system, state, &self.stabilization, &mut stats)?;
            state.qd += qdd * h;
            state.q += state.qd * h;
            state.t = if last { t_end } else { state.t + h };
            remaining = if last { T::zero() } else { t_end - state.t };
            stats.steps += 1;
            accept(system, state, &self.stabilization)?;
            observer(state);
        }
        Ok(stats)
    }
}
