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

/// A crossing found in a step: `index` crosses in `[left, right]`.
pub(super) struct Found<T, const E: usize> {
    pub index: usize,
    pub left: T,
    pub right: T,
    /// `gᵢ(right)`, on the new side (or zero).
    pub g_right: T,
    pub rising: bool,
    /// The functions whose crossings in the same grid interval lie within
    /// the time tolerance of this one (this one included).
    pub together: [bool; E],
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

/// `Some(rising)` when `gl → gr` is a sign change counted by `direction`.
fn sign_change<T: RealField + Copy>(gl: T, gr: T, direction: Direction) -> Option<bool> {
    let zero = T::zero();
    let rising = gl < zero && gr >= zero;
    let falling = gl > zero && gr <= zero;
    match direction {
        Direction::Rising => rising.then_some(true),
        Direction::Falling => falling.then_some(false),
        Direction::Either if rising => Some(true),
        Direction::Either if falling => Some(false),
        Direction::Either => None,
    }
}

/// A bracket of a sign change, `((a, g(a)), (b, g(b)))`, and whether it
/// rises.
type Bracket<T> = (((T, T), (T, T)), bool);

/// The earliest crossing after `from` in the step, each function `i`
/// sought from `refs[i] = (time, value)`; `refs` move along the grid as
/// intervals are cleared (to the step's end when nothing is found).
/// `g_end`: the functions' values at the step's end.
pub(super) fn search<T, F, D, const N: usize, const S: usize, const E: usize>(
    events: &Events<T, F, E, D>,
    span: &Span<'_, T, N, S>,
    refs: &mut [(T, T); E],
    from: T,
    g_end: [T; E],
    stats: &mut EventStats,
) -> Result<Option<Found<T, E>>, IntegrationError<T>>
where
    T: RealField + Copy,
    F: Fn(&State<T, N>) -> [T; E],
    D: Rates<T, N, E>,
{
    if E == 0 {
        return Ok(None);
    }
    let (t0, h) = span.step();
    let end = span.end();
    let tolerance = events.time_tolerance(span);
    let intervals = events.samples.saturating_add(1);
    for k in 1..=intervals {
        let s = if k == intervals {
            end.t
        } else {
            t0 + h * (c::<T>(k as f64) / c::<T>(intervals as f64))
        };
        if s <= from {
            continue;
        }
        let g = if k == intervals {
            g_end
        } else {
            stats.samples += 1;
            values(events, &span.at(s))?
        };
        let mut best: Option<Found<T, E>> = None;
        let mut lefts: [Option<T>; E] = [None; E];
        let functions = events.kinds.iter().zip(refs.iter_mut()).zip(g.iter());
        for (i, ((kind, reference), &gs)) in functions.enumerate() {
            if reference.0 >= s {
                continue;
            }
            if reference.1 == T::zero() {
                leave_zero(events, span, i, reference, s, stats)?;
            }
            let (tl, gl) = *reference;
            let bracket = match sign_change(gl, gs, kind.direction) {
                Some(rising) => Some((((tl, gl), (s, gs)), rising)),
                None if D::KNOWN => dip(events, span, i, ((tl, gl), (s, gs)), kind, stats)?,
                None => None,
            };
            let Some((bracket, rising)) = bracket else {
                continue;
            };
            let found = refine(events, span, i, bracket, tolerance, stats)?;
            if let Some(left) = lefts.get_mut(i) {
                *left = Some(found.left);
            }
            if best.as_ref().is_none_or(|b| found.left < b.left) {
                best = Some(Found { rising, ..found });
            }
        }
        if let Some(mut best) = best {
            // Simultaneous: within the tolerance after the earliest (ties
            // went to the lowest index, which is reported first).
            best.together =
                core::array::from_fn(|j| lefts[j].is_some_and(|l| l - best.left <= tolerance));
            return Ok(Some(best));
        }
        for (r, &gi) in refs.iter_mut().zip(g.iter()) {
            if r.0 < s {
                *r = (s, gi);
            }
        }
    }
    Ok(None)
}

/// Where, as fractions of the way to the next grid point, a function
/// sitting exactly at zero is evaluated to see which side it leaves to.
/// The first is close enough that a return through zero after it is a sign
/// change the grid interval shows; the later ones are for a function that
/// stays at zero for a while (a contact at rest).
const LEAVING: [f64; 4] = [1.0 / 1_048_576.0, 1.0 / 4096.0, 1.0 / 64.0, 0.25];

/// A function exactly at zero at its reference `(t, 0)` is on neither
/// side, so no sign change can start there, and by the next grid point it
/// may already have left and come back (a ball started on the ground moving
/// up). It is evaluated a little after `t` ([`LEAVING`]), and its reference
/// moves to the first point where it is not zero: leaving zero is not a
/// crossing, coming back is.
fn leave_zero<T, F, D, const N: usize, const S: usize, const E: usize>(
    events: &Events<T, F, E, D>,
    span: &Span<'_, T, N, S>,
    i: usize,
    reference: &mut (T, T),
    s: T,
    stats: &mut EventStats,
) -> Result<(), IntegrationError<T>>
where
    T: RealField + Copy,
    F: Fn(&State<T, N>) -> [T; E],
{
    let tl = reference.0;
    for fraction in LEAVING {
        let t = tl + (s - tl) * c::<T>(fraction);
        if !(t > tl && t < s) {
            continue;
        }
        stats.probes += 1;
        let g = values(events, &span.at(t))?.get(i).copied();
        if let Some(g) = g.filter(|g| *g != T::zero()) {
            *reference = (t, g);
            return Ok(());
        }
    }
    Ok(())
}

/// For a function with known rates that keeps its strict sign from `a` to
/// `b`: a bracket of its first counted crossing inside, if it dips through
/// zero and back between them. The cubic through its values and rates at
/// `a` and `b` (Hermite's) places its extrema; the function is evaluated at
/// each in time order, and the first that lies on the other side of zero
/// brackets the dip's crossings. Exact where the function is a cubic on the
/// step's continuous extension (a gap linear in `q` under a method whose
/// extension is cubic); elsewhere as close as the cubic is to it over one
/// grid interval.
fn dip<T, F, D, const N: usize, const S: usize, const E: usize>(
    events: &Events<T, F, E, D>,
    span: &Span<'_, T, N, S>,
    i: usize,
    ((a, ga), (b, gb)): ((T, T), (T, T)),
    kind: &Event,
    stats: &mut EventStats,
) -> Result<Option<Bracket<T>>, IntegrationError<T>>
where
    T: RealField + Copy,
    F: Fn(&State<T, N>) -> [T; E],
    D: Rates<T, N, E>,
{
    let zero = T::zero();
    let positive = ga > zero && gb > zero;
    if !(positive || (ga < zero && gb < zero)) {
        return Ok(None);
    }
    let rate = |t: T| -> Result<Option<T>, IntegrationError<T>> {
        let Some(rates) = events.rates.rates(&span.at(t)) else {
            return Ok(None);
        };
        match rates.get(i).copied() {
            Some(r) if r.is_finite() => Ok(Some(r)),
            Some(_) => Err(IntegrationError::EventNotFinite { t, event: i }),
            None => Ok(None),
        }
    };
    let (Some(da), Some(db)) = (rate(a)?, rate(b)?) else {
        return Ok(None);
    };
    let mut previous = (a, ga);
    for theta in hermite_extrema((ga, da), (gb, db), b - a) {
        let t = a + (b - a) * theta;
        if !(t > previous.0 && t < b) {
            continue;
        }
        stats.probes += 1;
        let Some(gt) = values(events, &span.at(t))?.get(i).copied() else {
            return Ok(None);
        };
        if (gt > zero) == positive && gt != zero {
            previous = (t, gt);
            continue;
        }
        // Across zero: the dip's first crossing is in `[previous, t]`, its
        // return in `[t, b]`; the first the direction counts is reported.
        if let Some(rising) = sign_change(previous.1, gt, kind.direction) {
            return Ok(Some(((previous, (t, gt)), rising)));
        }
        if gt == zero {
            return Ok(None); // touching zero from the side that is not counted
        }
        let bracket = ((t, gt), (b, gb));
        return Ok(sign_change(gt, gb, kind.direction).map(|rising| (bracket, rising)));
    }
    Ok(None)
}

/// The interior extrema, as fractions `θ ∈ (0, 1)` in increasing order, of
/// the cubic with values `g` and derivatives `d` at the ends of an
/// interval of length `h`: the roots of its derivative
/// `(6(g₀ − g₁) + 3h(d₀ + d₁)) θ² + (6(g₁ − g₀) − h(4d₀ + 2d₁)) θ + h d₀`.
fn hermite_extrema<T: RealField + Copy>((g0, d0): (T, T), (g1, d1): (T, T), h: T) -> [T; 2] {
    let zero = T::zero();
    let none = -T::one(); // outside (0, 1): skipped by the caller
    let qa = c::<T>(6.0) * (g0 - g1) + c::<T>(3.0) * h * (d0 + d1);
    let qb = c::<T>(6.0) * (g1 - g0) - h * (c::<T>(4.0) * d0 + c::<T>(2.0) * d1);
    let qc = h * d0;
    let roots = if qa == zero {
        [if qb == zero { none } else { -qc / qb }, none]
    } else {
        let discriminant = qb * qb - c::<T>(4.0) * qa * qc;
        if discriminant < zero || !discriminant.is_finite() {
            [none, none]
        } else {
            // The stable pair: q = −(b + sign(b) √Δ)/2, roots q/a and c/q.
            let root = discriminant.sqrt();
            let q = -(qb + if qb < zero { -root } else { root }) * c::<T>(0.5);
            let first = q / qa;
            let second = if q == zero { first } else { qc / q };
            [first.min(second), first.max(second)]
        }
    };
    roots.map(|theta| {
        if theta > zero && theta < T::one() {
            theta
        } else {
            none
        }
    })
}

/// Root-finder iterations allowed: with a bisection at least every third
/// one, 200 shrink any bracket by 2⁻⁶⁶, below the resolution of `t`.
const MAX_REFINEMENTS: usize = 200;

/// The bracket `[a, b]` of a sign change of function `i` refined by the
/// Illinois method (regula falsi that halves the retained end's value when
/// the same end is kept twice), bisecting when the bracket has not halved
/// in three iterations, until it is within `tolerance`. A zero counts as
/// the new side, so `a` stays strictly on the old one.
fn refine<T, F, D, const N: usize, const S: usize, const E: usize>(
    events: &Events<T, F, E, D>,
    span: &Span<'_, T, N, S>,
    i: usize,
    ((mut a, mut ga), (mut b, mut gb)): ((T, T), (T, T)),
    tolerance: T,
    stats: &mut EventStats,
) -> Result<Found<T, E>, IntegrationError<T>>
where
    T: RealField + Copy,
    F: Fn(&State<T, N>) -> [T; E],
{
    let zero = T::zero();
    let half = c::<T>(0.5);
    // The secant's weights (halved by Illinois), apart from the true values.
    let (mut wa, mut wb) = (ga, gb);
    let mut kept = 0i8; // -1: a kept last time, +1: b kept
    let mut width = b - a;
    for iteration in 0..MAX_REFINEMENTS {
        if b - a <= tolerance {
            break;
        }
        let midpoint = a + (b - a) * half;
        let bisect = iteration % 3 == 2 && b - a > width * half;
        if iteration % 3 == 2 {
            width = b - a;
        }
        let secant = b - wb * (b - a) / (wb - wa);
        let t = if bisect || !(secant > a && secant < b) {
            midpoint
        } else {
            secant
        };
        if !(t > a && t < b) {
            break; // a and b are adjacent floats
        }
        stats.refinements += 1;
        let Some(g) = values(events, &span.at(t))?.get(i).copied() else {
            break;
        };
        if g != zero && (g > zero) == (ga > zero) {
            (a, ga, wa) = (t, g, g);
            if kept == 1 {
                wb *= half;
            }
            kept = 1;
        } else {
            (b, gb, wb) = (t, g, g);
            if kept == -1 {
                wa *= half;
            }
            kept = -1;
        }
    }
    Ok(Found {
        index: i,
        left: a,
        right: b,
        g_right: gb,
        rising: ga < zero,
        together: [false; E],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    /// One Hermite step (exact for a parabola) of `y = v₀ t − g t²/2` over
    /// `[0, h]`, and a search of it for `y = level` from `t = 0`.
    fn parabola_crossings(h: f64, samples: usize) -> ([Option<(f64, bool)>; 3], EventStats) {
        let (v0, g, level) = (1.0, 9.81, 0.05);
        let y = |t: f64| v0 * t - g * t * t / 2.0;
        let v = |t: f64| v0 - g * t;
        let state = |t: f64| {
            State::new(
                t,
                SVector::<f64, 1>::new(y(t)),
                SVector::<f64, 1>::new(v(t)),
            )
        };
        let (start, end) = (state(0.0), state(h));
        let slope = |t: f64| (SVector::<f64, 1>::new(v(t)), SVector::<f64, 1>::new(-g));
        let stages = [slope(0.0)];
        let end_slope = slope(h);
        let interpolant = Interpolant {
            start: &start,
            end: &end,
            h,
            stages: &stages,
            end_slope: &end_slope,
            dense: &[0.0],
        };
        let span = Span::new(interpolant, &end);
        let events = Events::new(
            move |s: &State<f64, 1>| [s.q.x - level],
            [Event::record(Direction::Either)],
        )
        .with_samples(samples);
        let mut stats = EventStats::default();
        let mut refs = [(0.0, -level)];
        let mut from = 0.0;
        let mut found = [None; 3];
        for slot in &mut found {
            let g_end = values(&events, span.end()).unwrap();
            let Ok(Some(f)) = search(&events, &span, &mut refs, from, g_end, &mut stats) else {
                break;
            };
            *slot = Some((f.left, f.rising));
            // As the stepper does: resume after the bracket.
            let g = span.at(f.left).q.x - level;
            refs = [(f.left, g)];
            refs[f.index] = (f.right, f.g_right);
            from = f.left;
        }
        (found, stats)
    }

    #[test]
    fn both_crossings_of_a_step_in_time_order_to_the_tolerance() {
        let root = (1.0f64 - 2.0 * 9.81 * 0.05).sqrt();
        let exact = [(1.0 - root) / 9.81, (1.0 + root) / 9.81];
        let (found, stats) = parabola_crossings(0.12, DEFAULT_SAMPLES);
        let [Some((t1, true)), Some((t2, false)), None] = found else {
            panic!("{found:?}");
        };
        // Left of each root, within 4 ε (|t| + h).
        let tolerance = 4.0 * f64::EPSILON * 0.24;
        assert!(
            t1 <= exact[0] && exact[0] - t1 <= tolerance,
            "{t1} vs {}",
            exact[0]
        );
        assert!(
            t2 <= exact[1] && exact[1] - t2 <= tolerance,
            "{t2} vs {}",
            exact[1]
        );
        // Illinois converges superlinearly: far fewer iterations than the
        // ~50 halvings of bisection from a 24 ms bracket to 1e-16
        // (measured: 10 per crossing).
        assert!(stats.refinements <= 2 * 12, "{stats:?}");
        assert_eq!(stats.crossings, 0); // counted by the stepper
                                        // The ends alone see no sign change.
        let (ends, _) = parabola_crossings(0.12, 0);
        assert_eq!(ends, [None; 3]);
    }

    #[test]
    fn the_cubic_through_values_and_rates_places_the_extrema() {
        // (t − 0.3)² − δ on [0, 1]: its minimum at θ = 0.3, whatever δ.
        let g = |t: f64| (t - 0.3) * (t - 0.3) - 1e-6;
        let d = |t: f64| 2.0 * (t - 0.3);
        let [first, second] = hermite_extrema((g(0.0), d(0.0)), (g(1.0), d(1.0)), 1.0);
        assert!(
            (first - 0.3).abs() < 1e-15 && second == -1.0,
            "{first} {second}"
        );
        // t³ − t on [−2, 2]: both extrema, ±1/√3, in order.
        let g = |t: f64| t * t * t - t;
        let d = |t: f64| 3.0 * t * t - 1.0;
        let [first, second] = hermite_extrema((g(-2.0), d(-2.0)), (g(2.0), d(2.0)), 4.0);
        let root = 1.0 / 3.0f64.sqrt();
        assert!((first - (2.0 - root) / 4.0).abs() < 1e-15, "{first}");
        assert!((second - (2.0 + root) / 4.0).abs() < 1e-15, "{second}");
        // A line has none; a NaN gives none.
        assert_eq!(hermite_extrema((0.0, 1.0), (1.0, 1.0), 1.0), [-1.0, -1.0]);
        assert_eq!(
            hermite_extrema((f64::NAN, 1.0), (1.0, 1.0), 1.0),
            [-1.0, -1.0]
        );
    }
}
