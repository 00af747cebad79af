//! Adaptive steps for embedded Runge–Kutta pairs.

use super::dense_output::Interpolant;
use super::explicit::ExplicitRungeKutta;
use super::stepper::{advance, StepMethod};
use super::tableau::{Embedded, Tableau};
use super::{c, derivative, span, Derivative, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use core::marker::PhantomData;
use nalgebra::RealField;

/// An embedded Runge–Kutta pair `M` with `S` stages and adaptive steps: the
/// local error estimate, scaled by `atol + rtol·|y|` per component of
/// `(q, q̇)` and measured in the RMS norm, is kept below one; steps that
/// exceed it are rejected and retried smaller; the step size follows a
/// [`PiController`]. [`DormandPrince45`](super::DormandPrince45) and
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

    /// Hairer, Nørsett & Wanner's starting step (Solving ODE I, II.4).
    fn initial_step<Sys, const N: usize, const K: usize>(
        &self,
        system: &Sys,
        state: &State<T, N>,
        k1: &Derivative<T, N>,
        total: T,
        stats: &mut Stats,
    ) -> Result<T, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        let y = (state.q, state.qd);
        let d0 = self.norm(&y, &y, &y);
        let d1 = self.norm(k1, &y, &y);
        let tiny = c::<T>(1e-5);
        let h0 = if d0 < tiny || d1 < tiny {
            c(1e-6)
        } else {
            d0 / d1 * c(0.01)
        };
        let h0 = h0.min(total);
        let probe = State {
            t: state.t + h0,
            q: state.q + k1.0 * h0,
            qd: state.qd + k1.1 * h0,
        };
        let k = derivative(system, &probe, &self.settings, stats)?;
        let diff = (k.0 - k1.0, k.1 - k1.1);
        let d2 = self.norm(&diff, &y, &y) / h0;
        let d = d1.max(d2);
        let order = c::<T>(f64::from(M::TABLEAU.order));
        let h1 = if d <= c(1e-15) {
            (h0 * c(1e-3)).max(c(1e-6))
        } else {
            (c::<T>(0.01) / d).powf(T::one() / order)
        };
        Ok((h0 * c(100.0)).min(h1).min(total))
    }

    /// RMS of `v / (atol + rtol·max(|y₀|, |y₁|))` over the 2N components.
    fn norm<const N: usize>(
        &self,
        v: &Derivative<T, N>,
        y0: &Derivative<T, N>,
        y1: &Derivative<T, N>,
    ) -> T {
        let mut sum = T::zero();
        let parts = [(&v.0, &y0.0, &y1.0), (&v.1, &y0.1, &y1.1)];
        for (vi, a, b) in parts {
            for i in 0..N {
                let sc = self.atol + self.rtol * a[i].abs().max(b[i].abs());
                let x = vi[i] / sc;
                sum += x * x;
            }
        }
        (sum / c::<T>(2.0 * N as f64)).sqrt()
    }
}

impl<T: RealField + Copy, M: Embedded<S>, const S: usize> StepMethod<T, S>
    for EmbeddedRungeKutta<T, M, S>
{
    const TABLEAU: Tableau<S> = M::TABLEAU;
    const DENSE: [f64; S] = M::DENSE;

    fn duplicate(&self) -> Self {
        EmbeddedRungeKutta {
            method: PhantomData,
            ..*self
        }
    }

    // The trait is sealed (a private module): `Settings` stays private.
    #[allow(private_interfaces)]
    fn settings(&self) -> &Settings<T> {
        &self.settings
    }

    fn fixed_step(&self) -> Option<T> {
        None
    }

    fn validate(&self) -> Result<(), IntegrationError<T>> {
        EmbeddedRungeKutta::validate(self)
    }

    fn max_step(&self) -> Option<T> {
        self.max_step
    }

    fn initial_step<Sys, const N: usize, const K: usize>(
        &self,
        system: &Sys,
        state: &State<T, N>,
        k1: &Derivative<T, N>,
        total: T,
        stats: &mut Stats,
    ) -> Result<T, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        EmbeddedRungeKutta::initial_step(self, system, state, k1, total, stats)
    }

    fn error_norm<const N: usize>(
        &self,
        error: &Derivative<T, N>,
        start: &Derivative<T, N>,
        end: &Derivative<T, N>,
    ) -> T {
        self.norm(error, start, end)
    }
}

shared_settings!(EmbeddedRungeKutta<T, M, S>, S, M: Embedded<S>, const S: usize);
