use super::{c, derivative, fixed_steps, IntegrationError, Stats};
use crate::stabilize::Stabilization;
use crate::{ConstrainedSystem, State};
use nalgebra::RealField;

/// The classical fourth-order Runge–Kutta method with a fixed step
/// (Kutta 1901; tableau as in Hairer, Nørsett & Wanner, *Solving Ordinary
/// Differential Equations I*, Table II.1.2). Four evaluations a step; the
/// last step is shortened to land on the end time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rk4<T> {
    step: T,
    stabilization: Stabilization<T>,
    max_steps: usize,
}

impl<T: RealField + Copy> Rk4<T> {
    /// Steps of size `step`, no stabilization, no step budget.
    pub fn new(step: T) -> Self {
        Rk4 {
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
            let (half, sixth, two) = (h * c(0.5), h / c(6.0), c::<T>(2.0));
            let k1 = derivative(system, state, s, stats)?;
            let at = |k: &(nalgebra::SVector<T, N>, nalgebra::SVector<T, N>), dt: T| State {
                t: state.t + dt,
                q: state.q + k.0 * dt,
                qd: state.qd + k.1 * dt,
            };
            let k2 = derivative(system, &at(&k1, half), s, stats)?;
            let k3 = derivative(system, &at(&k2, half), s, stats)?;
            let k4 = derivative(system, &at(&k3, h), s, stats)?;
            state.q += (k1.0 + k2.0 * two + k3.0 * two + k4.0) * sixth;
            state.qd += (k1.1 + k2.1 * two + k3.1 * two + k4.1) * sixth;
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

common_methods!(Rk4);
