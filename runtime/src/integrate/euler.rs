use super::explicit::fixed_step_valid;
use super::stepper::StepMethod;
use super::{fixed_steps, Derivative, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use nalgebra::RealField;

/// Semi-implicit (symplectic) Euler with a fixed step:
/// `q̇ₙ₊₁ = q̇ₙ + h q̈(qₙ, q̇ₙ)`, `qₙ₊₁ = qₙ + h q̇ₙ₊₁`. First order, one
/// evaluation a step and bounded energy error for conservative systems:
/// the choice for hard real-time loops where the step is fixed by the loop.
/// Not a Runge–Kutta method of the state `(q, q̇)` (it uses the new `q̇`),
/// so it has its own one-line stepper on the shared fixed-step loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SemiImplicitEuler<T> {
    step: T,
    settings: Settings<T>,
}

impl<T: RealField + Copy> SemiImplicitEuler<T> {
    /// Steps of size `step`, no stabilization, a budget of 10⁷ steps per
    /// call.
    pub fn new(step: T) -> Self {
        SemiImplicitEuler {
            step,
            settings: Settings::new(super::FIXED_STEP_BUDGET),
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
        let one_step = |state: &mut State<T, N>, h: T, k1: &Derivative<T, N>, _: &mut Stats| {
            state.qd += k1.1 * h;
            state.q += state.qd * h;
            Ok(None)
        };
        fixed_steps(
            system,
            state,
            t_end,
            self.step,
            &self.settings,
            one_step,
            observer,
        )
    }
}

impl<T: RealField + Copy> StepMethod<T, 1> for SemiImplicitEuler<T> {
    /// Cubic Hermite.
    const DENSE: [f64; 1] = [0.0];

    fn duplicate(&self) -> Self {
        *self
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
        0
    }

    #[inline]
    fn attempt<Sys, const N: usize, const K: usize>(
        &self,
        _: &Sys,
        state: &State<T, N>,
        k1: &Derivative<T, N>,
        h: T,
        stages: &mut [Derivative<T, N>; 1],
        solution: &mut State<T, N>,
        _: &mut Stats,
    ) -> Result<T, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        *solution = *state;
        solution.qd += k1.1 * h;
        solution.q += solution.qd * h;
        solution.t = state.t + h;
        *stages = [*k1];
        Ok(T::zero())
    }
}

shared_settings!(SemiImplicitEuler<T>, 1);
