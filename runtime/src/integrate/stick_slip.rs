//! The stick–slip driver: a [`Stepper`] whose event functions are the
//! friction entries' switches (`crate::friction`, the module docs there say
//! how a switch is decided and why each is handled once).

use super::events::{Direction, Event, Events};
use super::stepper::StepMethod;
use super::{StepOutcome, Stepper};
use crate::friction::{check_coefficients, stick_or_slip, Friction, FrictionError, Mode};
use crate::impact::impact_with_gaps;
use crate::{DynamicsError, State};
use nalgebra::{RealField, SMatrix};

/// What one call of [`StickSlip::step`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StickSlipOutcome<T, const N: usize> {
    /// An accepted step ended.
    Step,
    /// Entry `entry` switched to `mode` at `state` (the state after the
    /// switch: a stop sets the entry's velocity to zero).
    Switch {
        /// The friction entry, in the order written.
        entry: usize,
        /// Its new mode.
        mode: Mode,
        /// The state the integration goes on from.
        state: State<T, N>,
    },
    /// The end time is reached.
    Finished,
}

/// An integration with Coulomb friction switched between stick and slip:
/// the system (its modes change at the switches) and the stepper, driven
/// one accepted step or one switch per [`step`](Self::step). No
/// allocation; every loop is bounded (the stepper's step budget, and at
/// most `2F + 1` switches at one instant, else [`FrictionError::Zeno`]).
#[derive(Clone, Copy, Debug)]
pub struct StickSlip<T, S, I, const N: usize, const ST: usize, const F: usize> {
    system: S,
    stepper: Stepper<T, I, N, ST, F>,
    switches: usize,
    /// The instant of the last switch and how many were made there.
    instant: Option<(T, usize)>,
}

impl<T, S, I, const N: usize, const ST: usize, const F: usize> StickSlip<T, S, I, N, ST, F>
where
    T: RealField + Copy,
    I: StepMethod<T, ST>,
{
    /// The driver from `stepper`'s state: each entry slips in the sense of
    /// its velocity, or, at `v = 0`, sticks if the force needed is within
    /// `μs N` (else slips against it). `Err` for coefficients that are not
    /// `μs ≥ μk ≥ 0`, a negative normal force, or a failing evaluation.
    pub fn new<const K: usize>(
        mut system: S,
        mut stepper: Stepper<T, I, N, ST, F>,
    ) -> Result<Self, FrictionError<T>>
    where
        S: Friction<T, N, K, F>,
    {
        check_coefficients(&system.friction_coefficients())?;
        let state = *stepper.state();
        let v = system.friction_velocities(&state.q, &state.qd, state.t);
        let moving: [Mode; F] = core::array::from_fn(|i| Mode::slip(v[i]));
        system.set_friction_modes(moving);
        let lambda = stick_forces(&system, &state)?;
        let normal = normals(&system, &state)?;
        let coefficients = system.friction_coefficients();
        let modes = core::array::from_fn(|i| match moving[i] {
            Mode::Stick => stick_or_slip(lambda[i], coefficients[i].0, normal[i]),
            slip => slip,
        });
        system.set_friction_modes(modes);
        stepper.set_state(state)?;
        Ok(StickSlip {
            system,
            stepper,
            switches: 0,
            instant: None,
        })
    }

    /// The system in its current modes.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// The stepper (its state, statistics, step size).
    pub fn stepper(&self) -> &Stepper<T, I, N, ST, F> {
        &self.stepper
    }

    /// The current state.
    pub fn state(&self) -> &State<T, N> {
        self.stepper.state()
    }

    /// The switches made so far.
    pub fn switches(&self) -> usize {
        self.switches
    }

    /// One accepted step, or one switch inside it.
    pub fn step<const K: usize>(&mut self) -> Result<StickSlipOutcome<T, N>, FrictionError<T>>
    where
        S: Friction<T, N, K, F>,
    {
        let system = &self.system;
        let modes = system.friction_modes();
        let coefficients = system.friction_coefficients();
        let g = |s: &State<T, N>| -> [T; F] { event_values(system, &modes, &coefficients, s) };
        // A slip's velocity crosses zero against its sense; a stick's
        // margin μs N − |λ| falls through zero. A new phase's function
        // starts at zero moving away from its crossing direction, so the
        // switch that started it is not reported again.
        let kinds: [Event; F] = core::array::from_fn(|i| match modes[i] {
            Mode::Stick | Mode::SlipPositive => Event::stop(Direction::Falling),
            Mode::SlipNegative => Event::stop(Direction::Rising),
        });
        let events = Events::new(g, kinds);
        match self.stepper.step(&self.system, &events)? {
            StepOutcome::Step => Ok(StickSlipOutcome::Step),
            StepOutcome::Finished => Ok(StickSlipOutcome::Finished),
            StepOutcome::Event(crossing) => self.switch(crossing.index, crossing.state),
        }
    }

    /// Steps to the end time; `observe` sees every outcome. At most
    /// `max_calls` calls of [`step`](Self::step) (the stepper's own budget
    /// bounds them too); `Ok(false)` if they ran out first.
    pub fn finish<const K: usize>(
        &mut self,
        max_calls: usize,
        mut observe: impl FnMut(&Self, &StickSlipOutcome<T, N>),
    ) -> Result<bool, FrictionError<T>>
    where
        S: Friction<T, N, K, F>,
    {
        for _ in 0..max_calls {
            let outcome = self.step()?;
            observe(self, &outcome);
            if outcome == StickSlipOutcome::Finished {
                return Ok(true);
            }
        }
        Ok(false)
    }

    fn switch<const K: usize>(
        &mut self,
        entry: usize,
        at: State<T, N>,
    ) -> Result<StickSlipOutcome<T, N>, FrictionError<T>>
    where
        S: Friction<T, N, K, F>,
    {
        let count = match self.instant {
            Some((t, count)) if t == at.t => count + 1,
            _ => 1,
        };
        if count > 2 * F + 1 {
            return Err(FrictionError::Zeno { t: at.t });
        }
        self.instant = Some((at.t, count));
        let mut modes = self.system.friction_modes();
        let Some(&old) = modes.get(entry) else {
            return Err(FrictionError::Zeno { t: at.t });
        };
        let dynamics = |error| FrictionError::Dynamics { t: at.t, error };
        let state = match old {
            // A slip stopped: v = 0 by the impulsive Gauss principle.
            Mode::SlipPositive | Mode::SlipNegative => {
                if let Some(m) = modes.get_mut(entry) {
                    *m = Mode::Stick;
                }
                self.system.set_friction_modes(modes);
                stop(&self.system, &at).map_err(dynamics)?
            }
            Mode::Stick => at,
        };
        let lambda = stick_forces(&self.system, &state)?;
        let normal = normals(&self.system, &state)?;
        let coefficients = self.system.friction_coefficients();
        let (l, n, mu) = match (
            lambda.get(entry),
            normal.get(entry),
            coefficients.get(entry),
        ) {
            (Some(&l), Some(&n), Some(&(mu, _))) => (l, n, mu),
            _ => return Err(FrictionError::Zeno { t: at.t }),
        };
        let mode = match old {
            Mode::Stick => Mode::slip(-l),
            _ => stick_or_slip(l, mu, n),
        };
        if let Some(m) = modes.get_mut(entry) {
            *m = mode;
        }
        self.system.set_friction_modes(modes);
        self.stepper.set_state(state)?;
        self.switches += 1;
        Ok(StickSlipOutcome::Switch { entry, mode, state })
    }
}

/// The event functions: a slipping entry's velocity, a sticking one's
/// margin `μs N − |λ|` (NaN where the dynamics fail: the stepper reports
/// it as a non-finite event value).
fn event_values<T, S, const N: usize, const K: usize, const F: usize>(
    system: &S,
    modes: &[Mode; F],
    coefficients: &[(T, T); F],
    s: &State<T, N>,
) -> [T; F]
where
    T: RealField + Copy,
    S: Friction<T, N, K, F>,
{
    let v = system.friction_velocities(&s.q, &s.qd, s.t);
    let sticking = modes.contains(&Mode::Stick);
    let margin = if sticking {
        let normal = system.friction_normals(&s.q, &s.qd, s.t);
        system.stick_forces(s).map_or_else(
            |_| SMatrix::<T, F, 1>::repeat(T::zero() / T::zero()),
            |lambda| SMatrix::from_fn(|i, _| coefficients[i].0 * normal[i] - lambda[i].abs()),
        )
    } else {
        SMatrix::<T, F, 1>::zeros()
    };
    core::array::from_fn(|i| match modes[i] {
        Mode::Stick => margin[i],
        _ => v[i],
    })
}

/// The stick rows' multipliers at a switch.
fn stick_forces<T, S, const N: usize, const K: usize, const F: usize>(
    system: &S,
    state: &State<T, N>,
) -> Result<SMatrix<T, F, 1>, FrictionError<T>>
where
    T: RealField + Copy,
    S: Friction<T, N, K, F>,
{
    system
        .stick_forces(state)
        .map_err(|error| FrictionError::Dynamics { t: state.t, error })
}

/// The normal forces at a switch, checked non-negative and finite.
fn normals<T, S, const N: usize, const K: usize, const F: usize>(
    system: &S,
    state: &State<T, N>,
) -> Result<SMatrix<T, F, 1>, FrictionError<T>>
where
    T: RealField + Copy,
    S: Friction<T, N, K, F>,
{
    let normal = system.friction_normals(&state.q, &state.qd, state.t);
    match normal
        .iter()
        .position(|n| !(n.is_finite() && *n >= T::zero()))
    {
        Some(entry) => Err(FrictionError::Normal { entry, t: state.t }),
        None => Ok(normal),
    }
}

/// The state with every sticking entry's velocity at zero and every
/// constraint kept: the velocity closest to `s.qd` in the metric of `M`
/// (the impulsive Gauss principle, no gaps).
fn stop<T, S, const N: usize, const K: usize, const F: usize>(
    system: &S,
    s: &State<T, N>,
) -> Result<State<T, N>, DynamicsError>
where
    T: RealField + Copy,
    S: Friction<T, N, K, F>,
{
    let (a, _) = system.constraint_matrices(s);
    let residual = system.constraint_velocity_residual(s);
    let m = system.mass_matrix(s);
    let none = SMatrix::<T, 0, N>::zeros();
    let hit = impact_with_gaps::<T, N, K, 0, K>(&m, &a, &residual, &none, &[], &[], &s.qd)?;
    Ok(State::new(s.t, s.q, hit.qd))
}
