//! The data of an accepted step that event location needs, kept where the
//! step is computed: the [`Stepper`](super::Stepper)'s buffers, which each
//! step overwrites in place, and their continuous extension.

use super::dense_output::Interpolant;
use super::Derivative;
use crate::State;
use nalgebra::{RealField, SVector};

/// The last step, written in place by the method and the stepper: a step
/// that nothing crosses in moves nothing of the size of the state but
/// its end into the stepper's state (as a step of the run without events
/// does), and a kept one adds its start.
#[derive(Clone, Copy, Debug)]
pub(super) struct Work<T, const N: usize, const S: usize> {
    /// The step's start, once kept (the stepper's state has moved on to a
    /// crossing or the step's end); before, the stepper's state is it.
    pub start: State<T, N>,
    /// The Runge–Kutta solution at its end (before any projection), its
    /// time the step's end.
    pub solution: State<T, N>,
    /// The accepted state at its end when projection moved it
    /// (`projected`); otherwise `solution` is the accepted state.
    pub projected_end: State<T, N>,
    pub projected: bool,
    pub h: T,
    pub stages: [Derivative<T, N>; S],
}

impl<T: RealField + Copy, const N: usize, const S: usize> Work<T, N, S> {
    /// Buffers for steps from `state` (no step in them yet).
    pub(super) fn new(state: &State<T, N>) -> Self {
        let zero = SVector::zeros();
        Work {
            start: *state,
            solution: *state,
            projected_end: *state,
            projected: false,
            h: T::zero(),
            stages: [(zero, zero); S],
        }
    }

    /// The accepted state at the step's end.
    #[inline(always)]
    pub(super) fn end(&self) -> &State<T, N> {
        if self.projected {
            &self.projected_end
        } else {
            &self.solution
        }
    }

    /// The step's continuous extension from `start` (the stepper's state
    /// while the step is fresh, `self.start` once kept), with the slope
    /// `end_slope` at its end and the method's weights `dense`.
    #[inline(always)]
    pub(super) fn interpolant<'a>(
        &'a self,
        start: &'a State<T, N>,
        end_slope: &'a Derivative<T, N>,
        dense: &'a [f64; S],
    ) -> Interpolant<'a, T, N, S> {
        Interpolant {
            start,
            end: &self.solution,
            h: self.h,
            stages: &self.stages,
            end_slope,
            dense,
        }
    }

    /// The slope at the step's end for its extension: the last stage of a
    /// first-same-as-last method (evaluated at the solution), else `k_end`,
    /// the derivative at the accepted end (the next step's first stage).
    #[inline(always)]
    pub(super) fn end_slope<'a>(
        &'a self,
        fsal: bool,
        k_end: &'a Derivative<T, N>,
    ) -> &'a Derivative<T, N> {
        match self.stages.last() {
            Some(last) if fsal => last,
            _ => k_end,
        }
    }
}
