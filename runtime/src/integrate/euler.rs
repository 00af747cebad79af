use super::stepper::StepMethod;
use super::tableau::Tableau;
use super::{Derivative, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use nalgebra::RealField;

/// Semi-implicit (symplectic) Euler with a fixed step:
/// `q̇ₙ₊₁ = q̇ₙ + h q̈(qₙ, q̇ₙ)`, `qₙ₊₁ = qₙ + h q̇ₙ₊₁`. First order, one
/// evaluation a step and bounded energy error for conservative systems:
/// the choice for hard real-time loops where the step is fixed by the loop.
/// Not a Runge–Kutta method of the state `(q, q̇)` (it uses the new `q̇`),
/// so it has its own update (its stepper `attempt`) on the one driver.
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
}

impl<T: RealField + Copy> StepMethod<T, 1> for SemiImplicitEuler<T> {
    const TABLEAU: Tableau<1> = STAGE;

    fn fixed_step(&self) -> Option<T> {
        Some(self.step)
    }

    /// The semi-implicit update, not the tableau's: `q` moves with the new
    /// `q̇`.
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

/// Semi-implicit Euler's one stage, the derivative at the step's start:
/// first order, no error estimate, not first-same-as-last (what the
/// stepper asks of the tableau; `b` is explicit Euler's, never combined).
const STAGE: Tableau<1> = Tableau {
    c: [0.0],
    a: [[0.0]],
    b: [1.0],
    e: [0.0],
    order: 1,
    error_order: 0,
};

shared_settings!(SemiImplicitEuler<T>, 1);
