//! The search of one step for crossings (the [events](super::events)
//! module docs say what is found and in which order): the grid, the probe
//! of a function sitting at zero, the dip between grid points of a function
//! with known rates, and the Illinois refinement of a bracket.

use super::c;
use super::events::{values, Direction, Event, EventStats, Events, Rates, Span};
use crate::{IntegrationError, State};
use nalgebra::RealField;

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
    let mut rates = RateCache::new();
    let grid = Grid {
        events,
        span,
        tolerance,
    };
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
        if let Some(found) = grid.earliest(refs, (s, &g), &mut rates, stats)? {
            return Ok(Some(found));
        }
        for (r, &gi) in refs.iter_mut().zip(g.iter()) {
            if r.0 < s {
                *r = (s, gi);
            }
        }
    }
    Ok(None)
}

/// What the search of one step reads at each grid point: the functions,
/// the step's extension and the time tolerance.
struct Grid<'g, 'a, T, F, D, const N: usize, const S: usize, const E: usize> {
    events: &'g Events<T, F, E, D>,
    span: &'g Span<'a, T, N, S>,
    tolerance: T,
}

impl<T, F, D, const N: usize, const S: usize, const E: usize> Grid<'_, '_, T, F, D, N, S, E>
where
    T: RealField + Copy,
    F: Fn(&State<T, N>) -> [T; E],
    D: Rates<T, N, E>,
{
    /// The earliest crossing of any function between its reference and
    /// the grid point `s`, where the functions' values are `g`: a sign
    /// change, or with known rates a dip between them ([`dip`]), from a
    /// reference moved off an exact zero ([`leave_zero`]), each bracket
    /// refined to the tolerance; with the functions whose crossings there
    /// lie within the tolerance after it (`together`).
    fn earliest(
        &self,
        refs: &mut [(T, T); E],
        (s, g): (T, &[T; E]),
        rates: &mut RateCache<T, E>,
        stats: &mut EventStats,
    ) -> Result<Option<Found<T, E>>, IntegrationError<T>> {
        let (events, span, tolerance) = (self.events, self.span, self.tolerance);
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
                None if D::KNOWN => dip(events, span, i, ((tl, gl), (s, gs)), kind, rates, stats)?,
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
        // Simultaneous: within the tolerance after the earliest (ties went to
        // the lowest index, which is reported first).
        Ok(best.map(|mut best| {
            best.together =
                core::array::from_fn(|j| lefts[j].is_some_and(|l| l - best.left <= tolerance));
            best
        }))
    }
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

/// The rates at the last two times asked for, all functions' at once: a
/// grid interval's ends are shared by every function searched there and
/// by the next interval, so each is evaluated once.
struct RateCache<T, const E: usize> {
    slots: [Option<(T, [T; E])>; 2],
    next: usize,
}

impl<T: RealField + Copy, const E: usize> RateCache<T, E> {
    fn new() -> Self {
        RateCache {
            slots: [None, None],
            next: 0,
        }
    }

    /// The rates at `t` (`None` where not known), or an error if one is
    /// not finite.
    fn at<F, D, const N: usize, const S: usize>(
        &mut self,
        events: &Events<T, F, E, D>,
        span: &Span<'_, T, N, S>,
        t: T,
    ) -> Result<Option<[T; E]>, IntegrationError<T>>
    where
        D: Rates<T, N, E>,
    {
        if let Some((_, r)) = self.slots.iter().flatten().find(|(at, _)| *at == t) {
            return Ok(Some(*r));
        }
        let Some(r) = events.rates.rates(&span.at(t)) else {
            return Ok(None);
        };
        if let Some(event) = r.iter().position(|x| !x.is_finite()) {
            return Err(IntegrationError::EventNotFinite { t, event });
        }
        if let Some(slot) = self.slots.get_mut(self.next) {
            *slot = Some((t, r));
        }
        self.next = 1 - self.next;
        Ok(Some(r))
    }
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
    rates: &mut RateCache<T, E>,
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
    let mut rate = |t: T| -> Result<Option<T>, IntegrationError<T>> {
        Ok(rates.at(events, span, t)?.and_then(|r| r.get(i).copied()))
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
    use super::super::dense_output::Interpolant;
    use super::super::events::DEFAULT_SAMPLES;
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
