//! How the [`Stepper`] takes an accepted step: the method's attempts with
//! the step-size controller, retried until one is accepted, then the
//! accepted state (projected where the system asks for it) checked finite.

use super::super::{accept, c, derivative_into};
use super::{StepMethod, Stepper};
use crate::stabilize::Stabilization;
use crate::{ConstrainedSystem, IntegrationError, State};
use nalgebra::RealField;

impl<T, I, const N: usize, const S: usize, const E: usize> Stepper<T, I, N, S, E>
where
    T: RealField + Copy,
    I: StepMethod<T, S>,
{
    /// Takes one accepted step from `state` (retrying rejected ones) into
    /// `work`, `state` still its start. Always inlined, as `accepted`: the
    /// method writes the step into the stepper's buffers where the driver
    /// searches it (for the 32-link chain its stages are 4 KB).
    #[inline(always)]
    pub(super) fn take_step<Sys, const K: usize>(
        &mut self,
        system: &Sys,
    ) -> Result<(), IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        let max_steps = self.integrator.settings().max_steps;
        loop {
            if self.stats.steps + self.stats.rejected >= max_steps {
                return Err(IntegrationError::TooManySteps {
                    t: self.state.t,
                    steps: max_steps,
                });
            }
            if !self.carried {
                derivative_into(
                    system,
                    &self.state,
                    self.integrator.settings(),
                    &mut self.stats,
                    &mut self.k1,
                )?;
                self.carried = true;
            }
            let (h, next_t, last) = self.next_step(system)?;
            let error = self.integrator.attempt(
                system,
                &self.state,
                &self.k1,
                h,
                &mut self.work.stages,
                &mut self.work.solution,
                &mut self.stats,
            )?;
            if error <= T::one() {
                return self.accepted(system, error, h, next_t, last);
            }
            // Rejected (the error is NaN-safe: `<=` failed, so retried smaller).
            self.stats.rejected += 1;
            self.h = Some(self.controller.rejected(h, error));
        }
    }

    /// The size of the next step, the time it ends at, and whether it is
    /// the last (shortened to land on `t_end`).
    fn next_step<Sys, const K: usize>(
        &mut self,
        system: &Sys,
    ) -> Result<(T, T, bool), IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        let t = self.state.t;
        let remaining = self.t_end - t;
        if let Some(step) = self.integrator.fixed_step() {
            let slack = T::one() + c::<T>(64.0) * T::default_epsilon();
            let last = remaining <= step * slack;
            let next = if last {
                self.t_end
            } else {
                self.anchor.0 + step * c::<T>((self.anchor.1 + 1) as f64)
            };
            if next <= t {
                return Err(IntegrationError::TimeStalled { t, step });
            }
            // The step itself, not `next − t`: every step of a fixed-step
            // run is the same size but the last, the time alone anchored.
            return Ok((if last { remaining } else { step }, next, last));
        }
        let h = match self.h {
            Some(h) => h,
            None => {
                let integrator = &self.integrator;
                let h = match integrator.tolerances() {
                    Some(tolerances) => tolerances.initial_step(
                        I::TABLEAU.order,
                        system,
                        (&self.state, &self.k1),
                        remaining,
                        integrator.settings(),
                        &mut self.stats,
                    )?,
                    None => remaining, // an adaptive method has tolerances
                };
                integrator.max_step().map_or(h, |max| h.min(max))
            }
        };
        let resolution = c::<T>(16.0) * T::default_epsilon() * t.abs().max(self.t_end.abs());
        if h <= resolution {
            return Err(IntegrationError::StepSizeUnderflow { t, step: h });
        }
        if h >= remaining {
            Ok((remaining, self.t_end, true))
        } else {
            Ok((h, t + h, false))
        }
    }

    /// An accepted attempt as a step, in place: its end time, finite check
    /// and projection, the derivative carried to the next step, the
    /// controller's next size.
    #[inline(always)]
    fn accepted<Sys, const K: usize>(
        &mut self,
        system: &Sys,
        error: T,
        h: T,
        next_t: T,
        last: bool,
    ) -> Result<(), IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        let settings = self.integrator.settings();
        let work = &mut self.work;
        work.solution.t = if last { self.t_end } else { next_t };
        work.h = h;
        self.stats.steps += 1;
        self.anchor.1 += 1;
        // The solution is the accepted end unless projection moves it (its
        // copy then keeps the solution for the extension).
        work.projected = if let Stabilization::Projection { .. } = settings.stabilization {
            work.projected_end = work.solution;
            accept(system, &mut work.projected_end, settings)?
        } else if all_finite(&work.solution) {
            false
        } else {
            return Err(IntegrationError::NonFiniteState { t: work.solution.t });
        };
        let fsal = self.integrator.fsal();
        self.carried = match work.stages.last() {
            Some(k) if fsal && !work.projected => {
                self.k1 = *k;
                true
            }
            // Projection moved the state, or the method is not FSAL: the
            // next step's derivative, and the Hermite end slope.
            _ if self.extension => {
                derivative_into(system, work.end(), settings, &mut self.stats, &mut self.k1)?;
                true
            }
            _ => false,
        };
        if self.integrator.fixed_step().is_none() {
            let proposed = self.controller.accepted(h, error);
            self.h = Some(
                self.integrator
                    .max_step()
                    .map_or(proposed, |m| proposed.min(m)),
            );
        } else {
            self.h = Some(h);
        }
        Ok(())
    }
}

/// Whether every component of `state` is finite (`State::is_finite`
/// without its early exits, which kept the check scalar and branchy: it
/// runs once a step).
#[inline(always)]
fn all_finite<T: RealField + Copy, const N: usize>(state: &State<T, N>) -> bool {
    let finite = |all: bool, x: &T| all & x.is_finite();
    let q = state.q.as_slice().iter().fold(state.t.is_finite(), finite);
    state.qd.as_slice().iter().fold(q, finite)
}
