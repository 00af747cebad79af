//! The one explicit Runge–Kutta engine: [`step`] advances a state by one
//! step of any [`Tableau`] (every Runge–Kutta method's step, through
//! [`StepMethod::attempt`]), and [`ExplicitRungeKutta`] is a tableau with a
//! fixed step size.

use super::stepper::StepMethod;
use super::tableau::{Method, Tableau};
use super::{c, derivative_into, Derivative, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use core::marker::PhantomData;
use nalgebra::{RealField, SVector};

/// One step of size `h` of the method `tableau` from `state`, whose
/// derivative `k1` is given (the previous step's last stage for a
/// first-same-as-last method), written where the caller keeps the step
/// (the [`Stepper`](super::Stepper)'s buffers), so that nothing of the size
/// of the state is moved after it: the stages to `k` (the first is `k1`),
/// and the propagated solution, at `state.t + h`, to `new` (which holds
/// each stage's state on the way).
/// Always inlined: there the tableau is a constant, so the stage loops
/// unroll and the zero weights vanish.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn step<T, Sys, const N: usize, const K: usize, const S: usize>(
    tableau: &Tableau<S>,
    system: &Sys,
    state: &State<T, N>,
    k1: &Derivative<T, N>,
    h: T,
    settings: &Settings<T>,
    stats: &mut Stats,
    k: &mut [Derivative<T, N>; S],
    new: &mut State<T, N>,
) -> Result<(), IntegrationError<T>>
where
    T: RealField + Copy,
    Sys: ConstrainedSystem<T, N, K>,
{
    if let Some(first) = k.first_mut() {
        *first = *k1;
    }
    for i in 1..S {
        *new = combine(&tableau.a[i], k, i, state, h, c::<T>(tableau.c[i]) * h);
        derivative_into(system, new, settings, stats, &mut k[i])?;
    }
    if tableau.is_fsal() {
        // The last stage was evaluated at the new solution itself.
        new.t = state.t + h;
    } else {
        *new = combine(&tableau.b, k, S, state, h, h);
    }
    Ok(())
}

/// `y + h Σⱼ wⱼ kⱼ` over the first `stages` stages, at time `y.t + dt`
/// (zero weights skipped: the tableau is a constant, so this unrolls to
/// the method's own sums).
#[inline(always)]
fn combine<T: RealField + Copy, const N: usize, const S: usize>(
    weights: &[f64; S],
    k: &[Derivative<T, N>; S],
    stages: usize,
    y: &State<T, N>,
    h: T,
    dt: T,
) -> State<T, N> {
    let (mut q, mut qd) = (y.q, y.qd);
    for (w, kj) in weights.iter().zip(k).take(stages) {
        if *w != 0.0 {
            let f = c::<T>(*w) * h;
            q += kj.0 * f;
            qd += kj.1 * f;
        }
    }
    State { t: y.t + dt, q, qd }
}

/// The local error estimate `h Σ eⱼ kⱼ` of the stages `k`, unscaled (zero
/// without an embedded pair).
#[inline(always)]
pub(super) fn error_estimate<T: RealField + Copy, const N: usize, const S: usize>(
    tableau: &Tableau<S>,
    k: &[Derivative<T, N>; S],
    h: T,
) -> Derivative<T, N> {
    let mut error = (SVector::zeros(), SVector::zeros());
    if tableau.error_order > 0 {
        for (e, kj) in tableau.e.iter().zip(k) {
            if *e != 0.0 {
                let f = c::<T>(*e) * h;
                error.0 += kj.0 * f;
                error.1 += kj.1 * f;
            }
        }
    }
    error
}

/// An explicit Runge–Kutta method `M` with `S` stages and a fixed step; the
/// last step is shortened to land on the end time. [`Rk4`](super::Rk4) and
/// [`ThreeEighthsRule`](super::ThreeEighthsRule) are instances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExplicitRungeKutta<T, M, const S: usize> {
    step: T,
    settings: Settings<T>,
    method: PhantomData<M>,
}

impl<T: RealField + Copy, M: Method<S>, const S: usize> ExplicitRungeKutta<T, M, S> {
    /// Steps of size `step`, no stabilization, a budget of 10⁷ steps per
    /// call.
    pub fn new(step: T) -> Self {
        Self::with_settings(step, Settings::new(super::FIXED_STEP_BUDGET))
    }

    /// Steps of size `step` with `settings` (an embedded pair's fixed-step
    /// run keeps its own).
    pub(super) fn with_settings(step: T, settings: Settings<T>) -> Self {
        ExplicitRungeKutta {
            step,
            settings,
            method: PhantomData,
        }
    }
}

impl<T: RealField + Copy, M: Method<S>, const S: usize> StepMethod<T, S>
    for ExplicitRungeKutta<T, M, S>
{
    const TABLEAU: Tableau<S> = M::TABLEAU;

    fn fixed_step(&self) -> Option<T> {
        Some(self.step)
    }
}

shared_settings!(ExplicitRungeKutta<T, M, S>, S, M: Method<S>, const S: usize);
