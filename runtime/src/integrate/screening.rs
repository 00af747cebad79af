//! Screening: whether a fresh step can skip its interior grid, decided
//! from what the stepper already has (see the [events](super::events)
//! module docs).

use super::c;
use super::events::{values, EventStats, Events, Rates};
use crate::{IntegrationError, State};
use nalgebra::RealField;

/// Safety factor of the screening on the curvature the step ends show.
const SCREEN_SAFETY: f64 = 4.0;

/// Whether screening lets a step skip its interior grid: every function
/// `i` has the same strict sign at the step's start `refs[i]` and end
/// `end[i]`, and stays away from zero by more than `SCREEN_SAFETY` times
/// what the parabola through its values at the previous step's start
/// (`before[i]`), this step's start and end can dip between them: with
/// `c` the parabola's leading coefficient, its distance from the chord is
/// at most `|c| h² / 4`. Written without divisions (the times are
/// increasing, so the denominators are positive): this runs once a step.
/// A NaN screens nothing.
#[inline(always)]
fn screened<T: RealField + Copy, const E: usize>(
    before: &[(T, T); E],
    refs: &[(T, T); E],
    (t1, end): (T, &[T; E]),
) -> bool {
    let zero = T::zero();
    let quarter = c::<T>(SCREEN_SAFETY / 4.0);
    // Without early exits (`&`, not `&&`): the functions' tests then
    // compile to straight-line arithmetic, which is what a step pays.
    before
        .iter()
        .zip(refs)
        .zip(end)
        .fold(true, |screened, ((&(ta, ga), &(tb, gb)), &g1)| {
            let (h, previous) = (t1 - tb, tb - ta);
            let ordered = (previous > zero) & (h > zero);
            let same_sign = ((gb > zero) & (g1 > zero)) | ((gb < zero) & (g1 < zero));
            // c = ((g1 − gb)/h − (gb − ga)/previous) / (h + previous)
            let bend = ((g1 - gb) * previous - (gb - ga) * h).abs();
            let dip = bend * h * quarter;
            let far = gb.abs().min(g1.abs()) * (previous * (h + previous)) > dip;
            screened & ordered & same_sign & far
        })
}

/// The first look at a fresh step: the functions' values at its end, and
/// whether screening lets it skip its grid (then nothing crosses in it, and
/// `refs` are moved to its end; never with known rates). `before`: the functions' values at the
/// previous step's start, when that step was not interrupted.
#[inline(always)]
pub(super) fn screen<T, F, D, const N: usize, const E: usize>(
    events: &Events<T, F, E, D>,
    refs: &mut [(T, T); E],
    before: Option<&[(T, T); E]>,
    end: &State<T, N>,
    stats: &mut EventStats,
) -> Result<([T; E], bool), IntegrationError<T>>
where
    T: RealField + Copy,
    F: Fn(&State<T, N>) -> [T; E],
    D: Rates<T, N, E>,
{
    let g_end = values(events, end)?;
    // Functions with known rates are searched on every step: the rates
    // see a dip between grid points only where the grid is searched.
    let skip = E > 0
        && !D::KNOWN
        && events.screening
        && events.samples > 0
        && before.is_some_and(|before| screened(before, refs, (end.t, &g_end)));
    if skip {
        stats.screened += 1;
        for (r, &g) in refs.iter_mut().zip(&g_end) {
            *r = (end.t, g);
        }
    }
    Ok((g_end, skip))
}

#[cfg(test)]
mod tests {
    use super::screened;

    /// `g(t) = (t − 1)² − δ` at step ends 0.8, 0.9 and 1.0 (the step
    /// `[0.9, 1.0]`), as the stepper sees it.
    fn parabola(delta: f64, at: [f64; 3]) -> bool {
        let g = |t: f64| (t - 1.05) * (t - 1.05) - delta;
        screened(
            &[(at[0], g(at[0]))],
            &[(at[1], g(at[1]))],
            (at[2], &[g(at[2])]),
        )
    }

    #[test]
    fn a_parabola_dipping_to_zero_inside_the_step_is_searched() {
        // The parabola's minimum is 1.05, past the step; over [0.9, 1.0]
        // its lowest value is g(1.0) = 0.0025 − δ. The three ends see the
        // exact curvature (1), so the step is screened only when both ends
        // stay above 4 · h²/4 = 0.01.
        assert!(parabola(-0.05, [0.8, 0.9, 1.0]));
        assert!(!parabola(-0.005, [0.8, 0.9, 1.0]));
        // A double crossing inside the step: g(1.05) < 0 with both ends
        // positive (the minimum moved into the step).
        let g = |t: f64| (t - 0.95) * (t - 0.95) - 0.001;
        let (ta, tb, t1) = (0.8, 0.9, 1.0);
        assert!(g(tb) > 0.0 && g(t1) > 0.0 && g(0.95) < 0.0);
        assert!(!screened(&[(ta, g(ta))], &[(tb, g(tb))], (t1, &[g(t1)])));
        // A sign change between the ends, equal or out-of-order times, or a
        // non-finite value is never screened.
        assert!(!parabola(0.0025, [0.8, 0.9, 1.0]));
        assert!(!parabola(-0.05, [0.9, 0.9, 1.0]));
        assert!(!screened(&[(0.8, f64::NAN)], &[(0.9, 1.0)], (1.0, &[1.0])));
    }

    #[test]
    fn every_function_must_be_far_from_zero() {
        let before = [(0.0, 1.0), (0.0, 1.0)];
        let start = [(0.1, 1.0), (0.1, 1.0)];
        assert!(screened(&before, &start, (0.2, &[1.0, 1.0])));
        // The second function falls almost linearly (1, 0.5, 0.001:
        // curvature 0.05, a possible dip with the safety factor of
        // 0.05 · 0.1² = 5e-4 < 1e-3): screened; falling as 1, 0.9, 0.001
        // (curvature 40, a possible dip of 0.4) it is searched.
        assert!(screened(
            &before,
            &[(0.1, 1.0), (0.1, 0.5)],
            (0.2, &[1.0, 1e-3])
        ));
        assert!(!screened(
            &before,
            &[(0.1, 1.0), (0.1, 0.9)],
            (0.2, &[1.0, 1e-3])
        ));
    }
}
