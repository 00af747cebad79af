//! The one driver loop: every integrator's entry point (`advance`,
//! `advance_with`, `advance_sampled`, `advance_events`, a fixed-step run of
//! an embedded pair) is this loop of [`Stepper`] steps, with or without
//! event functions, so that a step is taken, checked and stabilized in one
//! place ([`take_step`](Stepper::take_step)).

use super::super::dense_output::Interpolant;
use super::super::events::{Action, Crossing, EventStats, Events, Rates};
use super::super::Stats;
use super::{StepMethod, StepOutcome, Stepper};
use crate::{ConstrainedSystem, IntegrationError, State};
use nalgebra::RealField;

/// What [`advance_events`](crate::DormandPrince45::advance_events) did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventRun<T, const N: usize> {
    /// Steps and evaluations.
    pub stats: Stats,
    /// What event location cost.
    pub event_stats: EventStats,
    /// The crossing with [`Action::Stop`] the run stopped at, if any (the
    /// state is then the one the handler left there).
    pub stopped: Option<Crossing<T, N>>,
}

impl<T, I, const N: usize, const S: usize, const E: usize> Stepper<T, I, N, S, E>
where
    T: RealField + Copy,
    I: StepMethod<T, S>,
{
    /// The driver's step: accepted steps until one shows a crossing
    /// (reported as [`step`](Self::step) reports it) or the end, each step
    /// without a crossing shown to `observer` (its extension and its
    /// accepted end). A step without a crossing is searched where the
    /// method wrote it and its start is not kept: the run with events that
    /// never trigger copies nothing more than the run without events (`at`
    /// has no step after it).
    #[inline(always)]
    fn next_event<Sys, F, D, const K: usize>(
        &mut self,
        system: &Sys,
        events: &Events<T, F, E, D>,
        observer: &mut impl FnMut(&Interpolant<'_, T, N, S>, &State<T, N>),
    ) -> Result<StepOutcome<T, N>, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
        F: Fn(&State<T, N>) -> [T; E],
        D: Rates<T, N, E>,
    {
        // Without event functions no step is ever pending: the test is then
        // a constant, and a run without events keeps no call to `step`.
        if E > 0 && self.pending {
            return self.step(system, events);
        }
        events.validate()?;
        let mut refs = self.references(events)?;
        self.kept = false;
        loop {
            if self.state.t >= self.t_end {
                self.refs = Some(refs);
                return Ok(StepOutcome::Finished);
            }
            self.take_step(system)?;
            let start = refs;
            let before = self.before.take();
            let found = self.search_step(events, &mut refs, before.as_ref())?;
            if found.is_some() {
                self.work.start = self.state;
                self.kept = true;
                self.pending = true;
                return self.report(found, refs, events);
            }
            self.observe(observer);
            self.before = Some(start);
            self.state = *self.work.end();
            self.reported = None;
        }
    }

    /// Shows `observer` the step in `work`, the stepper's state still its
    /// start: its continuous extension (whose end slope is current where
    /// the stepper evaluates it, `extension`) and its accepted end.
    #[inline(always)]
    fn observe(&self, observer: &mut impl FnMut(&Interpolant<'_, T, N, S>, &State<T, N>)) {
        let work = &self.work;
        let end_slope = work.end_slope(self.integrator.fsal(), &self.k1);
        observer(
            &work.interpolant(&self.state, end_slope, &I::DENSE),
            work.end(),
        );
    }
}

/// The driver, on a stepper (borrowed, not moved: it is the size of a few
/// states, and a run of one step would spend on copying it): `observer`
/// sees every accepted step in which no crossing is found (every step,
/// without event functions), and `handler(&crossing, &mut state)` runs at every crossing with the state
/// there; a changed state restarts the stepper from it. `state` is left
/// where the run ended: the end time, a stopping crossing, or on `Err` the
/// last accepted state.
#[inline]
pub(in super::super) fn drive<
    T,
    I,
    Sys,
    F,
    D,
    const N: usize,
    const K: usize,
    const S: usize,
    const E: usize,
>(
    stepper: &mut Stepper<T, I, N, S, E>,
    system: &Sys,
    state: &mut State<T, N>,
    events: &Events<T, F, E, D>,
    mut observer: impl FnMut(&Interpolant<'_, T, N, S>, &State<T, N>),
    mut handler: impl FnMut(&Crossing<T, N>, &mut State<T, N>),
) -> Result<EventRun<T, N>, IntegrationError<T>>
where
    T: RealField + Copy,
    I: StepMethod<T, S>,
    Sys: ConstrainedSystem<T, N, K>,
    F: Fn(&State<T, N>) -> [T; E],
    D: Rates<T, N, E>,
{
    let result = loop {
        match stepper.next_event(system, events, &mut observer) {
            Ok(StepOutcome::Step) => {}
            Ok(StepOutcome::Finished) => break Ok(None),
            Ok(StepOutcome::Event(crossing)) => {
                let mut changed = crossing.state;
                handler(&crossing, &mut changed);
                if changed != crossing.state {
                    if let Err(error) = stepper.set_state(changed) {
                        break Err(error);
                    }
                }
                if crossing.action == Action::Stop {
                    break Ok(Some(crossing));
                }
            }
            Err(error) => break Err(error),
        }
    };
    *state = stepper.state;
    result.map(|stopped| EventRun {
        stats: stepper.stats,
        event_stats: stepper.event_stats,
        stopped,
    })
}

/// [`drive`] without event functions, from `state` to `t_end`: the run of
/// `advance_with` and `advance_sampled`. `extension`: whether `observer`
/// uses the steps' continuous extensions (else a step's end slope is left
/// to the next step, which evaluates it anyway: the last step's is never
/// evaluated).
#[inline]
pub(in super::super) fn advance<T, I, Sys, const N: usize, const K: usize, const S: usize>(
    integrator: I,
    system: &Sys,
    state: &mut State<T, N>,
    t_end: T,
    extension: bool,
    observer: impl FnMut(&Interpolant<'_, T, N, S>, &State<T, N>),
) -> Result<Stats, IntegrationError<T>>
where
    T: RealField + Copy,
    I: StepMethod<T, S>,
    Sys: ConstrainedSystem<T, N, K>,
{
    let mut stepper = Stepper::<T, I, N, S, 0>::new(integrator, *state, t_end)?;
    stepper.extension = extension;
    let none = Events::none();
    drive(&mut stepper, system, state, &none, observer, |_, _| {}).map(|run| run.stats)
}
