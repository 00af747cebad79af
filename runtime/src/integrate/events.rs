//! Event location: the times at which user functions `g(t, q, q̇)` cross
//! zero, found on the continuous extension of each accepted step.
//!
//! A step `[t₀, t₁]` is searched on a grid of `samples` interior points of
//! its continuous extension (Dormand–Prince's own for
//! [`DormandPrince45`](super::DormandPrince45), the cubic Hermite
//! interpolant otherwise) plus its end, so that a function changing sign
//! twice inside one step is seen when the grid separates the two crossings
//! (checking the ends alone, as scipy's `solve_ivp` does, misses both). The
//! first grid interval with a sign change of some function in its direction
//! is refined by the Illinois variant of regula falsi, with a bisection
//! whenever it stalls, to the time tolerance; of the functions crossing in
//! that interval the earliest is reported, and the search resumes after it,
//! so the crossings of one step come out in time order. A refinement costs
//! one evaluation of the interpolant and of the event functions per
//! iteration, never an evaluation of the system.
//!
//! **Screening.** The grid costs `samples` evaluations of the extension
//! and of the functions per step, which on a cheap system is more than the
//! step (a double pendulum's RK4 step is four evaluations of `q̈`, ~90 ns
//! each). So a step after an uninterrupted one first looks at what it
//! already has: each function's values at the previous step's start, this
//! step's start and its end. The parabola through them has a curvature
//! `c`; a smooth function that is at least `4 |c| h² / 4` away from zero at
//! both ends of the step, with the same sign, does not reach zero inside it
//! unless its curvature grows fourfold within two steps (the safety
//! factor 4). Such a step skips its grid ([`EventStats::screened`]); any
//! other — a function near zero, or curving towards it, or the first step
//! after a start, a crossing or a state change — is searched on the whole
//! grid. What screening can miss is a dip the step ends do not show (a
//! function with a narrow bump, a kink): for those, turn it off
//! ([`Events::with_screening`]) and every step's grid is searched.
//!
//! **Exactly once, in order.** A crossing is reported at the left end of
//! its final bracket, where the function still has its old sign (strictly:
//! a zero counts as the new side), and the search for that function
//! resumes from the bracket's right end, where the sign has changed: the
//! same crossing cannot be found again. The other functions' references
//! move to the crossing, except those already past it, so the references
//! only ever move forward. Crossings come out in time order; functions
//! crossing at the same instant (identical, proportional or opposite
//! functions, or crossings within the time tolerance of each other) come
//! one after another at the same state, the lowest index first, each
//! once; `Stepper::simultaneous` names the whole group at the first, so
//! that a handler can treat them as one (a bar landing flat on both ends:
//! one impact with both gaps active).
//!
//! **On the surface.** A function exactly at zero is on neither side. It
//! is evaluated a little after (2⁻²⁰ of the way to the next grid point,
//! then farther while it stays at zero), and searched from where it has
//! left zero, so a ball started on the ground moving up is found landing
//! even when it lands before the next grid point. Leaving zero is not a
//! crossing; coming back is.
//!
//! **At a state change.** After a state change at a crossing (a bounce
//! `v → −e v`) every function is evaluated anew at the new state, where
//! the ones that crossed are still on their old side, or exactly at zero,
//! which then counts as their old side (a handler that puts the ball back
//! on the ground): their next crossings are those of the new trajectory.
//! If one of them crosses again in the same direction within the time
//! tolerance of the instant, the changes did not separate the trajectory
//! from the surface (restitution 0 under a force into it, the end of a
//! Zeno sequence of bounces, impacts applied one end at a time to a bar
//! landing flat): that is the error
//! [`EventRepeats`](crate::IntegrationError::EventRepeats), never a loop of
//! events at one time nor a silent pass through the surface. Each function
//! is reported at most once a direction at one instant, so every loop of a
//! driver ends.
//!
//! **Known rates.** The grid separates two crossings of one function only
//! when a grid point falls between them: a foot that touches the ground and
//! leaves it within one grid interval has passed through it unseen. Where
//! the functions' time derivatives `ġ` are known ([`Events::with_rates`]:
//! for a gap `g(q)`, `ġ = ∇g · q̇`, the generated `gap_rates`), each
//! grid interval in which a function keeps its sign is checked for a dip:
//! the cubic through its values and rates at the interval's ends places its
//! extrema, the function is evaluated there, and an extremum on the other
//! side of zero brackets both crossings. That is exact when the function is
//! a cubic on the continuous extension (a gap linear in `q` under a method
//! with a cubic extension), and otherwise as close as the cubic is to the
//! function over a grid interval. Steps of functions with rates are never
//! screened. Closures without rates keep the grid alone.

use super::c;
use super::dense_output::{Interpolant, Polynomial};
use crate::{IntegrationError, State};
use core::cell::OnceCell;
use nalgebra::RealField;

/// Which sign changes of an event function count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// From negative to zero or positive.
    Rising,
    /// From positive to zero or negative.
    Falling,
    /// Either.
    Either,
}

/// What a driver does at a crossing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Return from the driver at the crossing (after the handler ran).
    Stop,
    /// Record it (the handler runs, and may change the state) and go on.
    Continue,
}

/// The kind of one event function: its direction and action.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Event {
    /// Which sign changes count.
    pub direction: Direction,
    /// What to do at one.
    pub action: Action,
}

impl Event {
    /// An event of this direction and action.
    pub const fn new(direction: Direction, action: Action) -> Self {
        Event { direction, action }
    }

    /// An event that stops the run.
    pub const fn stop(direction: Direction) -> Self {
        Event::new(direction, Action::Stop)
    }

    /// An event that is recorded and the run goes on.
    pub const fn record(direction: Direction) -> Self {
        Event::new(direction, Action::Continue)
    }
}

/// Default interior points of a step searched for sign changes.
pub const DEFAULT_SAMPLES: usize = 4;

/// `E` event functions, computed together by one closure
/// `g(&state) -> [T; E]` (so that they can share work, e.g. the kinematics
/// of several contact points), with each one's [`Event`] kind.
///
/// The functions see the whole [`State`] (`t`, `q`, `q̇`) and whatever the
/// closure captures (inputs, a target, a model's parameters), which is why
/// they are closures and not expressions of the model's DSL: a contact gap
/// generated by the model is one closure calling it.
///
/// `D` holds the functions' time derivatives `ġ` when they are known
/// ([`with_rates`](Self::with_rates)): then no pair of crossings inside a
/// step is missed (see the [module](self) docs).
#[derive(Clone, Copy, Debug)]
pub struct Events<T, F, const E: usize, D = NoRates> {
    pub(super) g: F,
    pub(super) kinds: [Event; E],
    pub(super) tolerance: Option<T>,
    pub(super) samples: usize,
    pub(super) screening: bool,
    pub(super) rates: D,
}

/// The time derivatives `ġ` of event functions, where known.
pub trait Rates<T, const N: usize, const E: usize> {
    /// Whether [`rates`](Self::rates) gives them: decided by the type, so
    /// that a search without them compiles to the plain grid search.
    const KNOWN: bool;
    /// `ġ` at `state` (`None` where not known).
    fn rates(&self, state: &State<T, N>) -> Option<[T; E]>;
}

/// No known rates: the functions are searched on the grid alone (the
/// default of [`Events::new`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoRates;

impl<T, const N: usize, const E: usize> Rates<T, N, E> for NoRates {
    const KNOWN: bool = false;
    #[inline(always)]
    fn rates(&self, _: &State<T, N>) -> Option<[T; E]> {
        None
    }
}

/// Rates computed by a closure `ġ(&state) -> [T; E]`
/// ([`Events::with_rates`]).
#[derive(Clone, Copy, Debug)]
pub struct WithRates<D>(pub D);

impl<T, D, const N: usize, const E: usize> Rates<T, N, E> for WithRates<D>
where
    D: Fn(&State<T, N>) -> [T; E],
{
    const KNOWN: bool = true;
    #[inline]
    fn rates(&self, state: &State<T, N>) -> Option<[T; E]> {
        Some((self.0)(state))
    }
}

impl<T: RealField + Copy, F, const E: usize> Events<T, F, E> {
    /// The functions `g` with their kinds; a time tolerance of
    /// `4 ε (|t| + h)` (the step's time resolution),
    /// [`DEFAULT_SAMPLES`] interior points per step, and the grid of a
    /// step skipped where every function stays far from zero for the
    /// curvature its values at the ends of steps show (screening: see the
    /// [module](self) docs and [`with_screening`](Self::with_screening)).
    pub fn new(g: F, kinds: [Event; E]) -> Self {
        Events {
            g,
            kinds,
            tolerance: None,
            samples: DEFAULT_SAMPLES,
            screening: true,
            rates: NoRates,
        }
    }

    /// The same with the functions' time derivatives `ġ(&state) -> [T; E]`
    /// (for a gap `g(q)`, `ġ = ∇g · q̇`: the generated `gap_rates`). With
    /// them, each grid interval where a function keeps its sign is checked
    /// for a dip through zero between its ends: the cubic through the
    /// values and rates at the ends locates the extrema, where the function
    /// itself is evaluated, so two crossings closer than the grid are both
    /// found (the [module](self) docs). Such functions are searched on every
    /// step (screening cannot see a dip between the grid's points).
    pub fn with_rates<D>(self, rates: D) -> Events<T, F, E, WithRates<D>> {
        Events {
            g: self.g,
            kinds: self.kinds,
            tolerance: self.tolerance,
            samples: self.samples,
            screening: self.screening,
            rates: WithRates(rates),
        }
    }
}

impl<T: RealField + Copy, F, const E: usize, D> Events<T, F, E, D> {
    /// The same with the screening of steps on (the default) or off (every
    /// step's grid searched: `samples` calls of the closure per step
    /// whatever the functions' values).
    pub fn with_screening(mut self, screening: bool) -> Self {
        self.screening = screening;
        self
    }

    /// The same with crossings located to `tolerance` in time (finite and
    /// not negative, else `InvalidParameter`; zero: to the last bit).
    pub fn with_tolerance(mut self, tolerance: T) -> Self {
        self.tolerance = Some(tolerance);
        self
    }

    /// The same with `samples` interior points of each step searched for
    /// sign changes (0: the step's ends only). Two crossings closer than a
    /// grid interval (`h / (samples + 1)`) can hide each other.
    pub fn with_samples(mut self, samples: usize) -> Self {
        self.samples = samples;
        self
    }

    /// The kinds, as given.
    pub fn kinds(&self) -> &[Event; E] {
        &self.kinds
    }

    /// The time tolerance in a step: the one given, else `4 ε (|t| + h)`.
    pub(super) fn time_tolerance<const N: usize, const S: usize>(
        &self,
        span: &Span<'_, T, N, S>,
    ) -> T {
        let (t0, h) = span.step();
        self.tolerance.unwrap_or_else(|| {
            c::<T>(4.0) * T::default_epsilon() * (span.end().t.abs().max(t0.abs()) + h)
        })
    }

    pub(super) fn validate(&self) -> Result<(), IntegrationError<T>> {
        match self.tolerance {
            Some(tol) if !(tol >= T::zero() && tol.is_finite()) => {
                Err(IntegrationError::InvalidParameter)
            }
            _ => Ok(()),
        }
    }
}

/// The type of [`Events::none`]'s functions.
pub type NoEvents<T, const N: usize> = fn(&State<T, N>) -> [T; 0];

impl<T: RealField + Copy, const N: usize> Events<T, NoEvents<T, N>, 0> {
    /// No event functions: stepping alone.
    pub fn none() -> Self {
        Events::new(|_| [], [])
    }
}

/// A located zero crossing of event function `index`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing<T, const N: usize> {
    /// Which function crossed (its index in the closure's array).
    pub index: usize,
    /// The crossing's time: within the tolerance before the exact one, the
    /// function still strictly on its old side.
    pub t: T,
    /// The state there, from the step's continuous extension.
    pub state: State<T, N>,
    /// [`Direction::Rising`] or [`Direction::Falling`]: how it crossed.
    pub direction: Direction,
    /// Its kind's action.
    pub action: Action,
}

/// What event location cost: every figure is one evaluation of the step's
/// continuous extension and one call of the event closure.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EventStats {
    /// Crossings reported.
    pub crossings: usize,
    /// Interior grid points evaluated to detect sign changes.
    pub samples: usize,
    /// Steps whose interior grid screening skipped (every function far
    /// from zero at both ends for its curvature).
    pub screened: usize,
    /// Root-finder iterations, over all crossings.
    pub refinements: usize,
    /// Extra points evaluated: to see where a function sitting exactly at
    /// zero goes, and, for functions with known rates, at their extrema
    /// between grid points.
    pub probes: usize,
}

/// Where the continuous extension ends (the accepted state) and how to
/// evaluate it inside.
pub(super) struct Span<'a, T, const N: usize, const S: usize> {
    interpolant: Interpolant<'a, T, N, S>,
    /// Its polynomial, formed at the first evaluation inside the step (a
    /// step whose grid is its ends alone and has no sign change needs none).
    polynomial: OnceCell<Polynomial<T, N>>,
    end: &'a State<T, N>,
}

impl<'a, T: RealField + Copy, const N: usize, const S: usize> Span<'a, T, N, S> {
    pub fn new(interpolant: Interpolant<'a, T, N, S>, end: &'a State<T, N>) -> Self {
        Span {
            interpolant,
            polynomial: OnceCell::new(),
            end,
        }
    }

    /// The step's start time and size.
    pub fn step(&self) -> (T, T) {
        (self.interpolant.start.t, self.interpolant.h)
    }

    /// The accepted state at the end.
    pub fn end(&self) -> &State<T, N> {
        self.end
    }

    /// The state at `t`: the accepted one at the end, else the polynomial.
    pub fn at(&self, t: T) -> State<T, N> {
        if t >= self.end.t {
            *self.end
        } else {
            self.polynomial
                .get_or_init(|| self.interpolant.polynomial())
                .at(t)
        }
    }
}

/// The values of the functions at `state`, or an error if one is not
/// finite (a NaN never changes sign, so it would hide a crossing).
pub(super) fn values<T, F, D, const N: usize, const E: usize>(
    events: &Events<T, F, E, D>,
    state: &State<T, N>,
) -> Result<[T; E], IntegrationError<T>>
where
    T: RealField + Copy,
    F: Fn(&State<T, N>) -> [T; E],
{
    let g = (events.g)(state);
    match g.iter().position(|x| !x.is_finite()) {
        Some(event) => Err(IntegrationError::EventNotFinite { t: state.t, event }),
        None => Ok(g),
    }
}
