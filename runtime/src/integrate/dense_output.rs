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

/// An [`Interpolant`]'s polynomial with its coefficients computed once:
/// `y(θ) = y₀ + θ (Δ + (1 − θ)(a + θ (b + (1 − θ) d)))`, so that each
/// evaluation is four vector operations per part, which is what event
/// location pays per grid point and per root-finder iteration.
#[derive(Clone, Copy, Debug)]
pub(super) struct Polynomial<T, const N: usize> {
    t0: T,
    h: T,
    y0: (SVector<T, N>, SVector<T, N>),
    /// `(Δ, a, b, d)` for `q` and for `q̇`.
    coefficients: [(SVector<T, N>, SVector<T, N>); 4],
}

impl<T: RealField + Copy, const N: usize, const S: usize> Interpolant<'_, T, N, S> {
    /// The polynomial of [`at`](Self::at), its coefficients computed
    /// (both parts, one pass over the components per coefficient and no
    /// temporary vectors: this runs once per step with events, and for the
    /// 32-link chain each temporary would be a 512-byte copy).
    #[inline]
    pub fn polynomial(&self) -> Polynomial<T, N> {
        let h = self.h;
        let zero = SVector::<T, N>::zeros();
        let k1 = self.stages.first().copied().unwrap_or((zero, zero));
        let part = |y0: &SVector<T, N>,
                    y1: &SVector<T, N>,
                    k1: &SVector<T, N>,
                    k_end: &SVector<T, N>,
                    stage: fn(&Derivative<T, N>) -> &SVector<T, N>| {
            let mut coefficients = [zero; 4];
            let [delta, spline, fourth, fifth] = &mut coefficients;
            for (d, k) in self.dense.iter().zip(self.stages) {
                if *d != 0.0 {
                    fifth.axpy(c::<T>(*d) * h, stage(k), T::one());
                }
            }
            // Slices, not nalgebra's strided iterators: these loops vectorize.
            let columns = (y0.as_slice().iter().zip(y1.as_slice()))
                .zip(k1.as_slice().iter().zip(k_end.as_slice()));
            let targets = (delta.as_mut_slice().iter_mut())
                .zip(spline.as_mut_slice().iter_mut())
                .zip(fourth.as_mut_slice().iter_mut());
            for (((dl, sp), fo), ((a, b), (ka, kb))) in targets.zip(columns) {
                *dl = *b - *a;
                *sp = *ka * h - *dl;
                *fo = *dl - *kb * h - *sp;
            }
            coefficients
        };
        let q = part(&self.start.q, &self.end.q, &k1.0, &self.end_slope.0, |k| {
            &k.0
        });
        let qd = part(
            &self.start.qd,
            &self.end.qd,
            &k1.1,
            &self.end_slope.1,
            |k| &k.1,
        );
        Polynomial {
            t0: self.start.t,
            h,
            y0: (self.start.q, self.start.qd),
            coefficients: [(q[0], qd[0]), (q[1], qd[1]), (q[2], qd[2]), (q[3], qd[3])],
        }
    }
}

impl<T: RealField + Copy, const N: usize> Polynomial<T, N> {
    /// The state at time `t` (equal to [`Interpolant::at`] but for rounding):
    /// one pass over the components, no temporary vectors.
    #[inline]
    pub fn at(&self, t: T) -> State<T, N> {
        let theta = (t - self.t0) / self.h;
        let one_minus = T::one() - theta;
        let [(dq, dqd), (aq, aqd), (bq, bqd), (eq, eqd)] = &self.coefficients;
        let mut state = State {
            t,
            q: self.y0.0,
            qd: self.y0.1,
        };
        let eval = |y: &mut SVector<T, N>,
                    delta: &SVector<T, N>,
                    a: &SVector<T, N>,
                    b: &SVector<T, N>,
                    d: &SVector<T, N>| {
            // Slices, not nalgebra's strided iterators: this loop vectorizes.
            let coefficients = (delta.as_slice().iter().zip(a.as_slice()))
                .zip(b.as_slice().iter().zip(d.as_slice()));
            for (y, ((delta, a), (b, d))) in y.as_mut_slice().iter_mut().zip(coefficients) {
                let inner = (*b + *d * one_minus) * theta + *a;
                *y += (inner * one_minus + *delta) * theta;
            }
        };
        eval(&mut state.q, dq, aq, bq, eq);
        eval(&mut state.qd, dqd, aqd, bqd, eqd);
        state
    }
}
