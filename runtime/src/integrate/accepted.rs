//! The data of an accepted step that event location needs: a fresh one
//! (searched where it lies, its start the stepper's state) and a kept one
//! (for [`Stepper::at`](super::Stepper::at) and the step's later crossings),
//! and their continuous extensions.

use super::dense_output::Interpolant;
use super::events::Span;
use super::method::Attempt;
use super::Derivative;
use crate::State;
use nalgebra::RealField;

/// One accepted step, kept for the continuous extension.
#[derive(Clone, Copy, Debug)]
pub(super) struct Accepted<T, const N: usize, const S: usize> {
    pub start: State<T, N>,
    /// The Runge–Kutta solution at its end (before any projection).
    pub solution: State<T, N>,
    /// The accepted state at its end (after projection).
    pub end: State<T, N>,
    pub h: T,
    pub stages: [Derivative<T, N>; S],
    pub end_slope: Derivative<T, N>,
}

/// A step just accepted, before it is kept: its start is the stepper's
/// state, so that a step the driver searches and drops copies nothing
/// more than a step of the run without events.
pub(super) struct Fresh<T, const N: usize, const S: usize> {
    /// The Runge–Kutta solution (its time set to the step's end) and the
    /// stages.
    pub attempt: Attempt<T, N, S>,
    /// The accepted state at its end (after projection).
    pub end: State<T, N>,
    pub h: T,
    pub end_slope: Derivative<T, N>,
}

impl<T: Copy, const N: usize, const S: usize> Accepted<T, N, S> {
    /// `fresh`, which started at `start`, kept whole.
    pub(super) fn new(start: State<T, N>, fresh: Fresh<T, N, S>) -> Self {
        Accepted {
            start,
            solution: fresh.attempt.state,
            end: fresh.end,
            h: fresh.h,
            stages: fresh.attempt.stages,
            end_slope: fresh.end_slope,
        }
    }
}

/// The continuous extension of the step `fresh` from `start`.
pub(super) fn fresh_span<'a, T: RealField + Copy, const N: usize, const S: usize>(
    start: &'a State<T, N>,
    fresh: &'a Fresh<T, N, S>,
    dense: &'a [f64; S],
) -> Span<'a, T, N, S> {
    let interpolant = Interpolant {
        start,
        end: &fresh.attempt.state,
        h: fresh.h,
        stages: &fresh.attempt.stages,
        end_slope: &fresh.end_slope,
        dense,
    };
    Span::new(interpolant, &fresh.end)
}

impl<T: RealField + Copy, const N: usize, const S: usize> Accepted<T, N, S> {
    /// Its continuous extension, with the method's weights `dense`.
    pub(super) fn span<'a>(&'a self, dense: &'a [f64; S]) -> Span<'a, T, N, S> {
        let interpolant = Interpolant {
            start: &self.start,
            end: &self.solution,
            h: self.h,
            stages: &self.stages,
            end_slope: &self.end_slope,
            dense,
        };
        Span::new(interpolant, &self.end)
    }
}
