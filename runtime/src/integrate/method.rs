//! What the integrators implement for the [`Stepper`](super::Stepper): a
//! sealed trait (this module is private), so only this crate's
//! integrators step.

use super::{Derivative, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use nalgebra::RealField;

/// A method the [`Stepper`](super::Stepper) can drive.
pub trait StepMethod<T: RealField + Copy, const S: usize> {
    /// The continuous extension's weights (zero: cubic Hermite).
    const DENSE: [f64; S];
    /// A copy (the method markers are not `Copy`, so neither is the
    /// derived impl).
    fn duplicate(&self) -> Self;
    /// Stabilization and budget.
    #[allow(private_interfaces)]
    fn settings(&self) -> &Settings<T>;
    /// `Err(InvalidParameter)` for settings that cannot work.
    fn validate(&self) -> Result<(), IntegrationError<T>>;
    /// `Some(h)` for a fixed-step method.
    fn fixed_step(&self) -> Option<T>;
    /// The adaptive methods' longest step (none by default).
    fn max_step(&self) -> Option<T> {
        None
    }
    /// The order of the error estimate (for the controller; 0 without).
    fn error_order(&self) -> u32;
    /// Whether the last stage is evaluated at the new solution (first
    /// same as last): then it is the derivative at the step's end.
    fn fsal(&self) -> bool {
        false
    }
    /// The first step of an adaptive run over `total`; by default the
    /// fixed step (the stepper asks only adaptive methods).
    fn initial_step<Sys, const N: usize, const K: usize>(
        &self,
        _system: &Sys,
        _state: &State<T, N>,
        _k1: &Derivative<T, N>,
        total: T,
        _stats: &mut Stats,
    ) -> Result<T, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
    {
        Ok(self.fixed_step().unwrap_or(total))
    }
    /// One step of size `h` from `state`, whose derivative is `k1`, written
    /// where the stepper keeps it: the stages to `stages` (the first is
    /// `k1`), the new state to `solution` (its time `state.t + h`).
    /// Returns the scaled error (zero for a fixed-step method; a NaN fails
    /// `error <= 1` and is rejected). On `Err` both are partly written.
    #[allow(clippy::too_many_arguments)]
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
        Sys: ConstrainedSystem<T, N, K>;
}
