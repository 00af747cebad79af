//! Dense output: the continuous extension of an accepted step, so that a
//! solution can be observed at any time inside it without shortening the
//! steps (which would restart the step-size control and cost evaluations).

use super::{c, Derivative};
use crate::State;
use nalgebra::{RealField, SVector};

/// One accepted step of an embedded pair with `S` stages, able to evaluate
/// the method's continuous extension (see
/// [`Embedded`](super::tableau::Embedded)) anywhere in it. Holds references
/// to the step's data: building one costs nothing, each [`at`](Self::at)
/// a few vector operations and no evaluation of the system.
pub(super) struct Interpolant<'a, T, const N: usize, const S: usize> {
    /// The state the step started from.
    pub start: &'a State<T, N>,
    /// The Runge–Kutta solution at its end (before any projection).
    pub end: &'a State<T, N>,
    /// The step size.
    pub h: T,
    /// The stages' derivatives.
    pub stages: &'a [Derivative<T, N>; S],
    /// The derivative at `end`.
    pub end_slope: &'a Derivative<T, N>,
    /// The method's weights `dⱼ`.
    pub dense: &'a [f64; S],
}

impl<T: RealField + Copy, const N: usize, const S: usize> Interpolant<'_, T, N, S> {
    /// The interpolated state at time `t`, `start.t ≤ t ≤ start.t + h`.
    pub fn at(&self, t: T) -> State<T, N> {
        let theta = (t - self.start.t) / self.h;
        let one_minus = T::one() - theta;
        let h = self.h;
        let part = |y0: &SVector<T, N>,
                    y1: &SVector<T, N>,
                    slope: &dyn Fn(&Derivative<T, N>) -> SVector<T, N>| {
            let delta = y1 - y0;
            let k1 = self.stages.first().map_or(delta * T::zero(), slope);
            let spline = k1 * h - delta;
            let fourth = delta - slope(self.end_slope) * h - spline;
            let mut fifth = SVector::<T, N>::zeros();
            for (d, k) in self.dense.iter().zip(self.stages) {
                if *d != 0.0 {
                    fifth += slope(k) * (c::<T>(*d) * h);
                }
            }
            y0 + (delta + (spline + (fourth + fifth * one_minus) * theta) * one_minus) * theta
        };
        State {
            t,
            q: part(&self.start.q, &self.end.q, &|k| k.0),
            qd: part(&self.start.qd, &self.end.qd, &|k| k.1),
        }
    }
}
