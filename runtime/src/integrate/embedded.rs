//! Adaptive steps for embedded Runge–Kutta pairs.

use super::controller::Tolerances;
use super::dense_output::Interpolant;
use super::explicit::ExplicitRungeKutta;
use super::stepper::{advance, Configured, StepMethod};
use super::tableau::{Embedded, Tableau};
use super::{span, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use core::marker::PhantomData;
use nalgebra::RealField;

/// An embedded Runge–Kutta pair `M` with `S` stages and adaptive steps: the
/// local error estimate, scaled by `atol + rtol·|y|` per component of
/// `(q, q̇)` and measured in the RMS norm, is kept below one; steps that
/// exceed it are rejected and retried smaller; the step size follows a
/// [`PiController`](super::PiController). [`DormandPrince45`](super::DormandPrince45) and
/// [`BogackiShampine32`](super::BogackiShampine32) are instances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmbeddedRungeKutta<T, M, const S: usize> {
    rtol: T,
    atol: T,
    settings: Settings<T>,
    max_step: Option<T>,
    method: PhantomData<M>,
}

impl<T: RealField + Copy, M: Embedded<S>, const S: usize> EmbeddedRungeKutta<T, M, S> {
    /// Relative and absolute tolerances, both positive and finite (else
    /// `InvalidParameter` when advancing); a budget of 10⁶ steps per call.
    pub fn new(rtol: T, atol: T) -> Self {
        EmbeddedRungeKutta {
            rtol,
            atol,
            settings: Settings::new(1_000_000),
            max_step: None,
            method: PhantomData,
        }
    }

    /// The same with steps no longer than `max_step` (e.g. to sample output).
    pub fn with_max_step(mut self, max_step: T) -> Self {
        self.max_step = Some(max_step);
        self
    }

    /// Advances `state` to `t_end`, calling `observer` with the solution at
    /// each of `times` (nondecreasing, within `[state.t, t_end]`, else
    /// `InvalidParameter` before any step): dense output. The samples come
    /// from the method's continuous extension inside each accepted step
    /// (Dormand–Prince's fourth-order one for [`DormandPrince45`](super::DormandPrince45),
    /// the cubic Hermite interpolant otherwise), so the steps, and the
    /// number of evaluations, are those of the same call without samples.
    /// A sample at a step's end (or at `t_end`) is the accepted state itself.
    pub fn advance_sampled<Sys, const N: usize, const K: usize>(
        &self,
        system: &Sys,
        state: &mut State<T, N>,
        t_end: T,
        times: &[T],
        mut observer: impl FnMut(&State<T, N>),
    ) -> Result<Stats, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        self.validate()?;
        span(state, t_end)?;
        let mut previous = state.t;
        for &t in times {
            if !(t.is_finite() && t >= previous && t <= t_end) {
                return Err(IntegrationError::InvalidParameter);
            }
            previous = t;
        }
        let mut next = 0;
        while times.get(next).is_some_and(|&t| t <= state.t) {
            observer(state);
            next += 1;
        }
        let run = |step: &Interpolant<'_, T, N, S>, accepted: &State<T, N>| {
            while let Some(&t) = times.get(next) {
                if t > accepted.t {
                    break;
                }
                if t == accepted.t {
                    observer(accepted);
                } else {
                    observer(&step.at(t));
                }
                next += 1;
            }
        };
        advance(self.duplicate(), system, state, t_end, true, run)
    }

    /// Advances `state` to `t_end` in steps of `h` without error control:
    /// the higher-order formula alone, for convergence studies and loops
    /// that need a fixed cost per step.
    pub fn advance_fixed<Sys, const N: usize, const K: usize>(
        &self,
        system: &Sys,
        state: &mut State<T, N>,
        t_end: T,
        h: T,
    ) -> Result<Stats, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        let fixed = ExplicitRungeKutta::<T, M, S>::with_settings(h, self.settings);
        fixed.advance(system, state, t_end)
    }
}

impl<T: RealField + Copy, M: Embedded<S>, const S: usize> StepMethod<T, S>
    for EmbeddedRungeKutta<T, M, S>
{
    const TABLEAU: Tableau<S> = M::TABLEAU;
    const DENSE: [f64; S] = M::DENSE;

    fn fixed_step(&self) -> Option<T> {
        None
    }

    /// `Err(InvalidParameter)` for settings that cannot work. `atol > 0`:
    /// with a zero one, a component passing through zero has a zero error
    /// scale and the step size underflows.
    fn validate(&self) -> Result<(), IntegrationError<T>> {
        let positive = |x: T| x > T::zero() && x.is_finite();
        let max_step_valid = self.max_step.is_none_or(positive);
        if !(positive(self.rtol) && positive(self.atol) && max_step_valid) {
            return Err(IntegrationError::InvalidParameter);
        }
        self.settings.validate()
    }

    fn max_step(&self) -> Option<T> {
        self.max_step
    }

    // The trait is sealed (a private module): `Tolerances` stays private.
    #[allow(private_interfaces)]
    fn tolerances(&self) -> Option<Tolerances<T>> {
        Some(Tolerances {
            rtol: self.rtol,
            atol: self.atol,
        })
    }
}

shared_settings!(EmbeddedRungeKutta<T, M, S>, S, M: Embedded<S>, const S: usize);
