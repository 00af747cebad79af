use super::{derivative, fixed_steps, IntegrationError, Stats};
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

    /// Advances `state` to `t_end`, calling `observer` after every step.
    pub fn advance_with<S, const N: usize, const K: usize>(
        &self,
        system: &S,
        state: &mut State<T, N>,
        t_end: T,
        observer: impl FnMut(&State<T, N>),
    ) -> Result<Stats, IntegrationError<T>>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        let s = &self.stabilization;
        let one_step = |state: &mut State<T, N>, h: T, stats: &mut Stats| {
            let (_, qdd) = derivative(system, state, s, stats)?;
            state.qd += qdd * h;
            state.q += state.qd * h;
            Ok(())
        };
        fixed_steps(
            system,
            state,
            t_end,
            self.step,
            self.max_steps,
            s,
            one_step,
            observer,
        )
    }
}

common_methods!(SemiImplicitEuler);
