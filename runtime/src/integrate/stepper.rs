//! The single-step API: a [`Stepper`] takes one accepted step per call,
//! reports the event crossings inside it in time order, and restarts from
//! a state changed at an event. The drivers with events are built on it.

use super::accepted::Work;
use super::controller::PiController;
use super::events::{self, Action, Crossing, Direction, EventStats, Events, Rates, Span};
use super::screening;
use super::search::{self, Found};
use super::{Derivative, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use nalgebra::{RealField, SVector};

pub(super) use super::method::{Configured, StepMethod};

mod drive;
mod take;

pub use drive::EventRun;
pub(super) use drive::{advance, drive};

/// What one call of [`Stepper::step`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepOutcome<T, const N: usize> {
    /// An accepted step ended (its crossings, if any, were reported before):
    /// the stepper's state is the step's end.
    Step,
    /// A crossing: the stepper's state is the state at the crossing. The
    /// next call reports the step's next crossing or its end, unless
    /// [`Stepper::set_state`] changed the state (then it steps from there).
    Event(Crossing<T, N>),
    /// The end time is reached and every crossing before it reported.
    Finished,
}

/// The last reported crossing's state, for `set_state` to tell a restart
/// at it.
#[derive(Clone, Copy, Debug)]
struct Reported<T, const N: usize> {
    state: State<T, N>,
}

/// The crossings reported at one instant (within the time tolerance of its
/// first), across the state changes made there: what makes each function's
/// crossing there reported once, and a crossing that a state change did not
/// end an error instead of a loop.
#[derive(Clone, Copy, Debug)]
struct Instant<T, const E: usize> {
    t: T,
    /// Per function, `Some(rising)` once reported at this instant.
    reported: [Option<bool>; E],
    /// The functions found crossing together with the last one reported.
    together: [bool; E],
}

/// An integration in progress, one accepted step per [`step`](Self::step)
/// (as diffsol's `step()`): made by an integrator's `stepper(state,
/// t_end)`, driven by the caller, who may inspect the state, change it at
/// an event ([`set_state`](Self::set_state)) or change the system's inputs
/// and parameters between calls (the system is passed to each call; after
/// changing it, call `set_state(*stepper.state())` so that no derivative
/// of the old system is carried over). `E` is the number of event
/// functions; no allocation, errors as values.
///
/// The guide `constrained::guide::runtime` (section "Events and the
/// single step") has a bouncing ball driven by hand with this API and by
/// `advance_events`, doc-tested against the closed-form bounce times.
#[derive(Clone, Copy, Debug)]
pub struct Stepper<T, I, const N: usize, const S: usize, const E: usize> {
    integrator: I,
    t_end: T,
    state: State<T, N>,
    /// The derivative at the last step's end, when `carried`: the next
    /// step's first stage (and the end slope of the step's extension).
    /// Not carried before the first step and after a state change.
    k1: Derivative<T, N>,
    carried: bool,
    /// The next step size (`None` before the first).
    h: Option<T>,
    controller: PiController<T>,
    stats: Stats,
    event_stats: EventStats,
    /// The last step, written in place by each step.
    work: Work<T, N, S>,
    /// Whether `work` is a whole accepted step, its start kept (for `at`
    /// and the step's later crossings).
    kept: bool,
    /// Whether `step` still has crossings to search after `state.t`.
    pending: bool,
    /// Whether an accepted step whose last stage is not the derivative at
    /// its end evaluates that derivative at once, for the step's continuous
    /// extension (the stepper's API, events, sampled output); otherwise
    /// the next step evaluates it, and a run that never looks inside its
    /// steps does not pay for the last one.
    extension: bool,
    /// Per event function, the time and value its next crossing is sought
    /// from (`None`: evaluate at `state`).
    refs: Option<[(T, T); E]>,
    /// Per event function, its time and value at the start of the last
    /// step, when that step ended without a crossing or a state change
    /// (the screening's third point).
    before: Option<[(T, T); E]>,
    /// Fixed steps: the time steps are counted from, and their count (time
    /// is `anchor + n h`, not a running sum).
    anchor: (T, usize),
    /// The last crossing reported in the current step.
    reported: Option<Reported<T, N>>,
    /// The instant of the last crossings reported.
    instant: Option<Instant<T, E>>,
}

impl<T, I, const N: usize, const S: usize, const E: usize> Stepper<T, I, N, S, E>
where
    T: RealField + Copy,
    I: StepMethod<T, S>,
{
    /// A stepper from `state` to `t_end`; `Err(InvalidParameter)` for
    /// settings that cannot work or a non-finite state or end time,
    /// `EndBeforeStart` for an end before the state's time. Inlined: it
    /// builds the stepper where the driver keeps it.
    #[inline]
    pub(super) fn new(
        integrator: I,
        state: State<T, N>,
        t_end: T,
    ) -> Result<Self, IntegrationError<T>> {
        integrator.validate()?;
        super::span(&state, t_end)?;
        let controller = PiController::new(integrator.error_order());
        let zero = SVector::zeros();
        Ok(Stepper {
            integrator,
            t_end,
            state,
            k1: (zero, zero),
            carried: false,
            h: None,
            controller,
            stats: Stats::default(),
            event_stats: EventStats::default(),
            work: Work::new(&state),
            kept: false,
            pending: false,
            extension: true,
            refs: None,
            before: None,
            anchor: (state.t, 0),
            reported: None,
            instant: None,
        })
    }

    /// The current state: a step's end, or a crossing's state.
    pub fn state(&self) -> &State<T, N> {
        &self.state
    }

    /// The end time.
    pub fn t_end(&self) -> T {
        self.t_end
    }

    /// Steps and evaluations so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// What event location has cost so far.
    pub fn event_stats(&self) -> EventStats {
        self.event_stats
    }

    /// The next step size the stepper will try (`None` before the first).
    pub fn step_size(&self) -> Option<T> {
        self.h
    }

    /// The last accepted step's continuous extension at `t`, or `None`
    /// outside it (or before the first step, after a state change, or
    /// after a step that failed).
    pub fn at(&self, t: T) -> Option<State<T, N>> {
        if !self.kept {
            return None;
        }
        let work = &self.work;
        let end_slope = work.end_slope(self.integrator.fsal(), &self.k1);
        let span = Span::new(
            work.interpolant(&work.start, end_slope, &I::DENSE),
            work.end(),
        );
        (t >= work.start.t && t <= work.end().t).then(|| span.at(t))
    }

    /// Replaces the state (at an event: the impact law, a reset) and
    /// restarts from it: the rest of the current step is dropped, the
    /// derivative is evaluated anew, and the step-size controller keeps its
    /// history (the next step tries the size it had proposed; if the jump
    /// made that too long, the error control rejects and shrinks it).
    /// `Err(InvalidParameter)` for a non-finite state, `EndBeforeStart`
    /// for a time after the end.
    ///
    /// At a crossing, with the crossing's own state (to restart after
    /// changing the system, e.g. a controller's mode), the crossing counts
    /// as done: the function is sought from its new side, and the other
    /// functions crossing at the same instant are still reported. With a
    /// changed state (an impact) every function is sought from the new
    /// state (one that crossed here and is left exactly at zero counts as
    /// on its old side); if one that crossed here crosses again in the same
    /// direction within the time tolerance, the change did not take the
    /// trajectory off its surface: the next [`step`](Self::step) is
    /// `Err(EventRepeats)` (the stepper stays usable: switch the model to
    /// the persistent contact and set the state again).
    pub fn set_state(&mut self, state: State<T, N>) -> Result<(), IntegrationError<T>> {
        super::span(&state, self.t_end)?;
        let reported = self.reported.take();
        if reported.is_none_or(|r| r.state.t != state.t) {
            self.instant = None;
        }
        // The crossing's own state (the system changed, not the state): the
        // search goes on from the references the report left, each function
        // already reported at this instant past its crossing.
        self.refs = match (reported, self.refs) {
            (Some(r), Some(refs)) if r.state == state => Some(refs.map(|(_, g)| (state.t, g))),
            _ => None,
        };
        self.state = state;
        self.carried = false;
        self.kept = false;
        self.pending = false;
        self.before = None;
        self.anchor = (state.t, 0);
        Ok(())
    }

    /// Moves the end time (e.g. to go on after [`StepOutcome::Finished`]);
    /// `Err` as for a new stepper.
    pub fn set_t_end(&mut self, t_end: T) -> Result<(), IntegrationError<T>> {
        super::span(&self.state, t_end)?;
        self.t_end = t_end;
        Ok(())
    }

    /// Advances by one accepted step, or to the next crossing inside the
    /// current one (see [`StepOutcome`]).
    pub fn step<Sys, F, D, const K: usize>(
        &mut self,
        system: &Sys,
        events: &Events<T, F, E, D>,
    ) -> Result<StepOutcome<T, N>, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
        F: Fn(&State<T, N>) -> [T; E],
        D: Rates<T, N, E>,
    {
        events.validate()?;
        let mut refs = self.references(events)?;
        let start = refs;
        let fresh = !self.pending;
        if fresh {
            if self.state.t >= self.t_end {
                self.refs = Some(refs);
                return Ok(StepOutcome::Finished);
            }
            // Kept whole, for `at` and the step's later crossings.
            self.kept = false;
            self.take_step(system)?;
            self.work.start = self.state;
            self.kept = true;
            self.pending = true;
        }
        let before = if fresh { self.before.take() } else { None };
        self.before = None;
        let found = if self.kept {
            self.search_step(events, &mut refs, before.as_ref())?
        } else {
            None
        };
        if fresh && found.is_none() {
            self.before = Some(start);
        }
        self.report(found, refs, events)
    }

    /// The step in `work` screened, then, unless screening cleared it,
    /// searched for its first crossing after the stepper's time (with its
    /// extension from `work.start` once kept, else from the stepper's
    /// state, still the step's start). Without event functions, nothing is
    /// evaluated and no extension is formed.
    #[inline(always)]
    fn search_step<F, D>(
        &mut self,
        events: &Events<T, F, E, D>,
        refs: &mut [(T, T); E],
        before: Option<&[(T, T); E]>,
    ) -> Result<Option<Found<T, E>>, IntegrationError<T>>
    where
        F: Fn(&State<T, N>) -> [T; E],
        D: Rates<T, N, E>,
    {
        if E == 0 {
            return Ok(None);
        }
        let work = &self.work;
        let stats = &mut self.event_stats;
        let (g_end, screened) = screening::screen(events, refs, before, work.end(), stats)?;
        if screened {
            return Ok(None);
        }
        let start = if self.kept { &work.start } else { &self.state };
        let end_slope = work.end_slope(self.integrator.fsal(), &self.k1);
        let span = Span::new(work.interpolant(start, end_slope, &I::DENSE), work.end());
        search::search(events, &span, refs, self.state.t, g_end, stats)
    }

    /// Per event function, the time and value its next crossing is sought
    /// from: kept from the last search, else evaluated at the state. After
    /// a state change at a crossing, a function reported there that the new
    /// state leaves exactly at zero (a handler that puts the ball back on
    /// the ground) counts as on its old side: its next crossing in the same
    /// direction is found, and is `EventRepeats` if it comes at once.
    fn references<F, D>(
        &mut self,
        events: &Events<T, F, E, D>,
    ) -> Result<[(T, T); E], IntegrationError<T>>
    where
        F: Fn(&State<T, N>) -> [T; E],
    {
        if let Some(refs) = self.refs {
            return Ok(refs);
        }
        let g = events::values(events, &self.state)?;
        let mut refs = core::array::from_fn(|i| (self.state.t, g[i]));
        if let Some(instant) = &self.instant {
            // Far below any value the functions take, a sign and no weight.
            let tiny = T::default_epsilon() * T::default_epsilon();
            for (r, reported) in refs.iter_mut().zip(&instant.reported) {
                match reported {
                    Some(rising) if r.1 == T::zero() => r.1 = if *rising { -tiny } else { tiny },
                    _ => {}
                }
            }
        }
        Ok(refs)
    }

    /// What the search of the kept step found, reported: its end when
    /// nothing (the step is done), else the crossing, whose state becomes
    /// the stepper's. The references only move forward: a function already
    /// past the crossing (reported at the same instant) keeps its own, the
    /// others restart at the crossing.
    fn report<F, D>(
        &mut self,
        found: Option<Found<T, E>>,
        mut refs: [(T, T); E],
        events: &Events<T, F, E, D>,
    ) -> Result<StepOutcome<T, N>, IntegrationError<T>>
    where
        F: Fn(&State<T, N>) -> [T; E],
    {
        if !self.kept {
            return Err(IntegrationError::InvalidParameter); // unreachable: a step was just taken
        }
        let work = &self.work;
        let Some(found) = found else {
            self.state = *work.end();
            self.refs = Some(refs);
            self.pending = false;
            self.reported = None;
            return Ok(if self.state.t >= self.t_end {
                StepOutcome::Finished
            } else {
                StepOutcome::Step
            });
        };
        let end_slope = work.end_slope(self.integrator.fsal(), &self.k1);
        let span = Span::new(
            work.interpolant(&work.start, end_slope, &I::DENSE),
            work.end(),
        );
        let instant = self.at_instant(&found, events.time_tolerance(&span))?;
        let state = span.at(found.left);
        let g = events::values(events, &state)?;
        for (j, (r, gj)) in refs.iter_mut().zip(g).enumerate() {
            if j == found.index {
                *r = (found.right, found.g_right);
            } else if r.0 < found.left {
                *r = (found.left, gj);
            }
        }
        self.refs = Some(refs);
        self.state = state;
        self.event_stats.crossings += 1;
        self.reported = Some(Reported { state });
        self.instant = Some(instant);
        let action = events
            .kinds
            .get(found.index)
            .map_or(Action::Stop, |kind| kind.action);
        Ok(StepOutcome::Event(Crossing {
            index: found.index,
            t: found.left,
            state,
            direction: if found.rising {
                Direction::Rising
            } else {
                Direction::Falling
            },
            action,
        }))
    }

    /// The instant `found` belongs to, with it recorded: the current one if
    /// `found` is within `tolerance` of it, else a new one. A function
    /// reported at this instant in the same direction before has crossed
    /// again at once: whatever the state changes there did, they did not
    /// take the trajectory off its surface, so it is
    /// `Err(EventRepeats)`, never a loop of events at one time (each
    /// function can be reported at most once a direction at one instant).
    fn at_instant(
        &self,
        found: &Found<T, E>,
        tolerance: T,
    ) -> Result<Instant<T, E>, IntegrationError<T>> {
        let mut instant = match self.instant {
            Some(instant) if found.left - instant.t <= tolerance => instant,
            _ => Instant {
                t: found.left,
                reported: [None; E],
                together: [false; E],
            },
        };
        let Some(reported) = instant.reported.get_mut(found.index) else {
            return Err(IntegrationError::InvalidParameter); // unreachable: index < E
        };
        if *reported == Some(found.rising) {
            return Err(IntegrationError::EventRepeats {
                t: instant.t,
                event: found.index,
            });
        }
        *reported = Some(found.rising);
        for (all, &this) in instant.together.iter_mut().zip(&found.together) {
            *all |= this;
        }
        Ok(instant)
    }

    /// At a crossing ([`StepOutcome::Event`]): which event functions cross
    /// at its instant, within the time tolerance (the reported one
    /// included; `[false; E]` elsewhere). Those after it are reported next,
    /// one a call at the same state, in time order and, at the same time,
    /// in index order, each once; a state change ([`set_state`](Self::set_state))
    /// ends the group: the search starts anew from the new state, where
    /// the ones still crossing are reported. To apply simultaneous impacts
    /// as one (a bar landing flat on both ends), mark every gap this
    /// returns as active in one `impact`.
    pub fn simultaneous(&self) -> [bool; E] {
        match (&self.reported, &self.instant) {
            (Some(_), Some(instant)) => instant.together,
            _ => [false; E],
        }
    }
}
