//! What the integrators implement for the [`Stepper`](super::Stepper): a
//! sealed trait (this module is private), so only this crate's
//! integrators step. A Runge–Kutta method is its tableau: the step, the
//! error order and first-same-as-last follow from it here, so the impls
//! say only what differs (their settings, step-size rule and error norm).

use super::controller::Tolerances;
use super::explicit::{error_estimate, step};
use super::tableau::Tableau;
use super::{Derivative, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use nalgebra::RealField;

/// What every integrator holds, written once for all of them by the
/// `shared_settings!` macro.
pub trait Configured<T> {
    /// A copy: a method marker need not be `Clone`, so the derived
    /// `Clone` of an integrator may not exist, but every field is `Copy`.
    fn duplicate(&self) -> Self;
    /// Stabilization and budget.
    #[allow(private_interfaces)]
    fn settings(&self) -> &Settings<T>;
}

/// A method the [`Stepper`](super::Stepper) can drive.
pub trait StepMethod<T: RealField + Copy, const S: usize>: Configured<T> {
    /// The method's stages: for a Runge–Kutta method its Butcher tableau,
    /// which [`attempt`](Self::attempt) steps; a method that combines its
    /// stages otherwise (semi-implicit Euler) overrides `attempt` and
    /// states here only its order, stages and lack of an error estimate.
    const TABLEAU: Tableau<S>;
    /// The continuous extension's weights (zero: cubic Hermite).
    const DENSE: [f64; S] = [0.0; S];
    /// `Some(h)` for a fixed-step method.
    fn fixed_step(&self) -> Option<T>;
    /// `Err(InvalidParameter)` for settings that cannot work: by default a
    /// fixed step that is not positive and finite, or invalid settings.
    fn validate(&self) -> Result<(), IntegrationError<T>> {
        match self.fixed_step() {
            Some(step) if !(step > T::zero() && step.is_finite()) => {
                Err(IntegrationError::InvalidParameter)
            }
            _ => self.settings().validate(),
        }
    }
    /// The adaptive methods' longest step (none by default).
    fn max_step(&self) -> Option<T> {
        None
    }
    /// The order of the error estimate (for the controller; 0 without).
    fn error_order(&self) -> u32 {
        Self::TABLEAU.error_order
    }
    /// Whether the last stage is evaluated at the new solution (first
    /// same as last): then it is the derivative at the step's end.
    fn fsal(&self) -> bool {
        Self::TABLEAU.is_fsal()
    }
    /// An adaptive method's tolerances, which scale its error estimate
    /// and its starting step (none by default: no error control).
    #[allow(private_interfaces)]
    fn tolerances(&self) -> Option<Tolerances<T>> {
        None
    }
    /// One step of size `h` from `state`, whose derivative is `k1`, written
    /// where the stepper keeps it: the stages to `stages` (the first is
    /// `k1`), the new state to `solution` (its time `state.t + h`).
    /// Returns the scaled error (zero for a fixed-step method; a NaN fails
    /// `error <= 1` and is rejected). On `Err` both are partly written.
    /// By default the Runge–Kutta step of [`TABLEAU`](Self::TABLEAU) and
    /// its error estimate in the norm of the [`tolerances`](Self::tolerances);
    /// always inlined, so that the stages are built in the stepper's
    /// buffers and the constant tableau unrolls.
    #[allow(clippy::too_many_arguments)]
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
        let tableau = &Self::TABLEAU;
        let settings = self.settings();
        step(
            tableau, system, state, k1, h, settings, stats, stages, solution,
        )?;
        match self.tolerances() {
            Some(tolerances) if tableau.error_order > 0 => {
                let error = error_estimate(tableau, stages, h);
                // A NaN error fails `error <= 1`: rejected and shrunk.
                let (start, end) = ((state.q, state.qd), (solution.q, solution.qd));
                Ok(tolerances.norm(&error, &start, &end))
            }
            _ => Ok(T::zero()),
        }
    }
}
