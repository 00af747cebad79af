//! The one explicit Runge–Kutta engine: [`step`] advances a state by one
//! step of any [`Tableau`], and [`ExplicitRungeKutta`] drives it with a
//! fixed step size.

use super::stepper::StepMethod;
use super::tableau::{Method, Tableau};
use super::{c, derivative, derivative_into, fixed_steps, Derivative, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use core::marker::PhantomData;
use nalgebra::{RealField, SVector};

/// The outcome of one step.
pub(super) struct Step<T, const N: usize, const S: usize> {
    /// The propagated solution.
    pub state: State<T, N>,
    /// `(q̇, q̈)` at the new state when the method is first-same-as-last:
    /// the next step's first stage.
    pub last: Option<Derivative<T, N>>,
    /// The local error estimate `h Σ eⱼ kⱼ`, unscaled (zero without an
    /// embedded pair).
    pub error: Derivative<T, N>,
    /// Every stage's derivative, for the continuous extension.
    pub stages: [Derivative<T, N>; S],
}

/// One step of size `h` of the method `tableau` from `state`, whose
/// derivative `k1` is given (it is the previous step's last stage for a
/// first-same-as-last method). Always inlined: there the tableau is a
/// constant, so the stage loops unroll and the zero weights vanish.
#[inline(always)]
pub(super) fn step<T, Sys, const N: usize, const K: usize, const S: usize>(
    tableau: &Tableau<S>,
    system: &Sys,
    state: &State<T, N>,
    k1: &Derivative<T, N>,
    h: T,
    settings: &Settings<T>,
    stats: &mut Stats,
) -> Result<Step<T, N, S>, IntegrationError<T>>
where
    T: RealField + Copy,
    Sys: ConstrainedSystem<T, N, K>,
{
    let mut k: [Derivative<T, N>; S] = [*k1; S];
    let mut stage = *state;
    for i in 1..S {
        stage = combine(&tableau.a[i], &k, i, state, h, c::<T>(tableau.c[i]) * h);
        k[i] = derivative(system, &stage, settings, stats)?;
    }
    let (new, last) = if tableau.is_fsal() {
        // The last stage was evaluated at the new solution itself.
        (
            State {
                t: state.t + h,
                ..stage
            },
            Some(k[S - 1]),
        )
    } else {
        (combine(&tableau.b, &k, S, state, h, h), None)
    };
    let error = error_estimate(tableau, &k, h);
    Ok(Step {
        state: new,
        last,
        error,
        stages: k,
    })
}

/// [`step`] writing where the [`Stepper`](super::Stepper) keeps the step,
/// so that nothing of the size of the state is moved after it: the stages
/// to `k` (the first is `k1`), and the propagated solution, at
/// `state.t + h`, to `new` (which holds each stage's state on the way).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn step_into<T, Sys, const N: usize, const K: usize, const S: usize>(
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
        ExplicitRungeKutta {
            step,
            settings: Settings::new(super::FIXED_STEP_BUDGET),
            method: PhantomData,
        }
    }

    /// Advances `state` to `t_end`, calling `observer` after every step.
    pub fn advance_with<Sys, const N: usize, const K: usize>(
        &self,
        system: &Sys,
        state: &mut State<T, N>,
        t_end: T,
        observer: impl FnMut(&State<T, N>),
    ) -> Result<Stats, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        fixed_tableau_steps(
            &M::TABLEAU,
            system,
            state,
            t_end,
            self.step,
            &self.settings,
            observer,
        )
    }
}

/// Steps of size `h` of the method `tableau` to `t_end` (no error control),
/// carrying the last stage of a first-same-as-last method into the next
/// step: the fixed-step methods, and embedded pairs run at a fixed step.
#[inline]
pub(super) fn fixed_tableau_steps<T, Sys, const N: usize, const K: usize, const S: usize>(
    tableau: &Tableau<S>,
    system: &Sys,
    state: &mut State<T, N>,
    t_end: T,
    h: T,
    settings: &Settings<T>,
    observer: impl FnMut(&State<T, N>),
) -> Result<Stats, IntegrationError<T>>
where
    T: RealField + Copy,
    Sys: ConstrainedSystem<T, N, K>,
{
    let one_step = |state: &mut State<T, N>, h: T, k1: &Derivative<T, N>, stats: &mut Stats| {
        let next = step(tableau, system, state, k1, h, settings, stats)?;
        *state = next.state;
        Ok(next.last)
    };
    fixed_steps(system, state, t_end, h, settings, one_step, observer)
}

impl<T: RealField + Copy, M: Method<S>, const S: usize> StepMethod<T, S>
    for ExplicitRungeKutta<T, M, S>
{
    /// Cubic Hermite.
    const DENSE: [f64; S] = [0.0; S];

    fn duplicate(&self) -> Self {
        ExplicitRungeKutta {
            method: PhantomData,
            ..*self
        }
    }

    // The trait is sealed (a private module): `Settings` stays private.
    #[allow(private_interfaces)]
    fn settings(&self) -> &Settings<T> {
        &self.settings
    }

    fn validate(&self) -> Result<(), IntegrationError<T>> {
        fixed_step_valid(self.step)?;
        self.settings.validate()
    }

    fn fixed_step(&self) -> Option<T> {
        Some(self.step)
    }

    fn error_order(&self) -> u32 {
        M::TABLEAU.error_order
    }

    fn fsal(&self) -> bool {
        M::TABLEAU.is_fsal()
    }

    // Always inlined: the stages are then built in the stepper's buffers.
    #[inline(always)]
    fn attempt<Sys, const N: usize, const K: usize>(
        &self,
        system: &Sys,
        state: &State<T, N>,
        k1: &Derivative<T, N>,
        h: T,
        stages: &mut [Derivative<T, N>; S],
        solution: &mut State<T, N>,
        stats: &mut Stats,
    ) -> Result<T, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        let tableau = &M::TABLEAU;
        step_into(
            tableau,
            system,
            state,
            k1,
            h,
            &self.settings,
            stats,
            stages,
            solution,
        )?;
        Ok(T::zero())
    }
}

/// `Err(InvalidParameter)` unless the fixed step is positive and finite.
pub(super) fn fixed_step_valid<T: RealField + Copy>(step: T) -> Result<(), IntegrationError<T>> {
    if step > T::zero() && step.is_finite() {
        Ok(())
    } else {
        Err(IntegrationError::InvalidParameter)
    }
}

shared_settings!(ExplicitRungeKutta<T, M, S>, S, M: Method<S>, const S: usize);
