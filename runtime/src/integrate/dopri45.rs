use super::{accept, c, derivative, span, IntegrationError, Stats};
use crate::stabilize::Stabilization;
use crate::{ConstrainedSystem, State};
use nalgebra::{RealField, SVector};

// The Dormand–Prince 5(4) pair: J. R. Dormand and P. J. Prince, "A family of
// embedded Runge-Kutta formulae", J. Comput. Appl. Math. 6 (1980) 19–26;
// tableau as in Hairer, Nørsett & Wanner, *Solving Ordinary Differential
// Equations I*, Table II.5.2. The 5th-order solution propagates (local
// extrapolation); the 7th stage is the derivative at the new point (FSAL).
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// `b − b̂`: 5th-order weights (the last row of A, then 0) minus 4th-order ones.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

type Derivative<T, const N: usize> = (SVector<T, N>, SVector<T, N>);

/// The outcome of one step: the new state, `f` there (the next step's first
/// stage), and the local error estimate, unscaled.
struct Step<T, const N: usize> {
    state: State<T, N>,
    derivative: Derivative<T, N>,
    error: Derivative<T, N>,
}

/// The Dormand–Prince 5(4) method with adaptive steps: the local error
/// estimate, scaled by `atol + rtol·|y|` per component of `(q, q̇)` and
/// measured in the RMS norm, is kept below one; steps that exceed it are
/// rejected and retried smaller. The step size follows the PI controller of
/// Hairer's DOPRI5 (Gustafsson's stabilised control, β = 0.04):
/// `h_new = h / clamp(err^(1/5 − 0.75β) / err_prev^β / 0.9, 1/10, 5)`,
/// which avoids the oscillation between accepted and rejected steps of the
/// plain `err^(−1/5)` rule, and never grows right after a rejection. Six
/// evaluations per accepted step (first same as last).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DormandPrince45<T> {
    rtol: T,
    atol: T,
    stabilization: Stabilization<T>,
    max_steps: usize,
    max_step: Option<T>,
}

impl<T: RealField + Copy> DormandPrince45<T> {
    /// Relative and absolute tolerances; a budget of 10⁶ steps per call.
    pub fn new(rtol: T, atol: T) -> Self {
        DormandPrince45 {
            rtol,
            atol,
            stabilization: Stabilization::None,
            max_steps: 1_000_000,
            max_step: None,
        }
    }

    /// The same with steps no longer than `max_step` (e.g. to sample output).
    pub fn with_max_step(mut self, max_step: T) -> Self {
        self.max_step = Some(max_step);
        self
    }

    /// Advances `state` to `t_end`, calling `observer` after every accepted step.
    pub fn advance_with<S, const N: usize, const K: usize>(
        &self,
        system: &S,
        state: &mut State<T, N>,
        t_end: T,
        mut observer: impl FnMut(&State<T, N>),
    ) -> Result<Stats, IntegrationError<T>>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        let positive = |x: T| x > T::zero() && x.is_finite();
        if !(positive(self.rtol) && (positive(self.atol) || self.atol == T::zero())) {
            return Err(IntegrationError::InvalidParameter);
        }
        let total = span(state, t_end)?;
        let mut stats = Stats::default();
        if total == T::zero() {
            return Ok(stats);
        }
        let s = &self.stabilization;
        let mut k1 = derivative(system, state, s, &mut stats)?;
        let mut h = self.initial_step(system, state, &k1, total, &mut stats)?;
        let mut rejected_last = false;
        // err of the last accepted step (PI control), floored as in DOPRI5.
        let mut err_previous = c::<T>(1e-4);
        let (beta, safety) = (c::<T>(0.04), c::<T>(0.9));
        let exponent = c::<T>(0.2) - beta * c(0.75);
        while state.t < t_end {
            if stats.steps + stats.rejected >= self.max_steps {
                return Err(IntegrationError::TooManySteps {
                    t: state.t,
                    steps: self.max_steps,
                });
            }
            let resolution = c::<T>(16.0) * T::default_epsilon() * state.t.abs().max(t_end.abs());
            if h <= resolution {
                return Err(IntegrationError::StepSizeUnderflow {
                    t: state.t,
                    step: h,
                });
            }
            let last = h >= t_end - state.t;
            if last {
                h = t_end - state.t;
            }
            let Step {
                state: new,
                derivative: k7,
                error,
            } = step(system, state, &k1, h, s, &mut stats)?;
            let err = self.norm(&error, &(state.q, state.qd), &(new.q, new.qd));
            // h_new = h / factor, factor in [1/10, 5] (DOPRI5's fac1, fac2).
            let proportional = if err > T::zero() {
                err.powf(exponent)
            } else {
                T::zero()
            };
            if err <= T::one() {
                *state = new;
                if last {
                    state.t = t_end;
                }
                stats.steps += 1;
                k1 = if accept(system, state, s)? {
                    // Projection moved the state: its derivative is new.
                    derivative(system, state, s, &mut stats)?
                } else {
                    k7
                };
                observer(state);
                let factor = (proportional / err_previous.powf(beta) / safety)
                    .max(c(0.1))
                    .min(c(5.0));
                let grown = h / factor;
                h = if rejected_last { grown.min(h) } else { grown };
                err_previous = err.max(c(1e-4));
                rejected_last = false;
            } else {
                stats.rejected += 1;
                let factor = if err.is_finite() {
                    (proportional / safety).min(c(5.0))
                } else {
                    c(5.0)
                };
                h /= factor.max(T::one());
                rejected_last = true;
            }
            if let Some(max) = self.max_step {
                h = h.min(max);
            }
        }
        Ok(stats)
    }

    /// Advances `state` to `t_end` in steps of `h` without error control:
    /// the fifth-order formula alone, for convergence studies and loops
    /// that need a fixed cost per step.
    pub fn advance_fixed<S, const N: usize, const K: usize>(
        &self,
        system: &S,
        state: &mut State<T, N>,
        t_end: T,
        h: T,
    ) -> Result<Stats, IntegrationError<T>>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        if !(h > T::zero() && h.is_finite()) {
            return Err(IntegrationError::InvalidParameter);
        }
        let mut remaining = span(state, t_end)?;
        let mut stats = Stats::default();
        let s = &self.stabilization;
        let mut k1 = derivative(system, state, s, &mut stats)?;
        let slack = T::one() + c::<T>(64.0) * T::default_epsilon();
        while remaining > T::zero() {
            if stats.steps == self.max_steps {
                return Err(IntegrationError::TooManySteps {
                    t: state.t,
                    steps: stats.steps,
                });
            }
            let last = remaining <= h * slack;
            let dt = if last { remaining } else { h };
            let Step {
                state: new,
                derivative: k7,
                ..
            } = step(system, state, &k1, dt, s, &mut stats)?;
            *state = new;
            if last {
                state.t = t_end;
            }
            remaining = if last { T::zero() } else { t_end - state.t };
            stats.steps += 1;
            k1 = if accept(system, state, s)? {
                derivative(system, state, s, &mut stats)?
            } else {
                k7
            };
        }
        Ok(stats)
    }

    /// Hairer, Nørsett & Wanner's starting step (Solving ODE I, II.4).
    fn initial_step<S, const N: usize, const K: usize>(
        &self,
        system: &S,
        state: &State<T, N>,
        k1: &Derivative<T, N>,
        total: T,
        stats: &mut Stats,
    ) -> Result<T, IntegrationError<T>>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        let y = (state.q, state.qd);
        let d0 = self.norm(&y, &y, &y);
        let d1 = self.norm(k1, &y, &y);
        let tiny = c::<T>(1e-5);
        let h0 = if d0 < tiny || d1 < tiny {
            c(1e-6)
        } else {
            d0 / d1 * c(0.01)
        };
        let h0 = h0.min(total);
        let probe = State {
            t: state.t + h0,
            q: state.q + k1.0 * h0,
            qd: state.qd + k1.1 * h0,
        };
        let k = derivative(system, &probe, &self.stabilization, stats)?;
        let diff = (k.0 - k1.0, k.1 - k1.1);
        let d2 = self.norm(&diff, &y, &y) / h0;
        let d = d1.max(d2);
        let h1 = if d <= c(1e-15) {
            (h0 * c(1e-3)).max(c(1e-6))
        } else {
            (c::<T>(0.01) / d).powf(c(0.2))
        };
        Ok((h0 * c(100.0)).min(h1).min(total))
    }

    /// RMS of `v / (atol + rtol·max(|y₀|, |y₁|))` over the 2N components.
    fn norm<const N: usize>(
        &self,
        v: &Derivative<T, N>,
        y0: &Derivative<T, N>,
        y1: &Derivative<T, N>,
    ) -> T {
        let mut sum = T::zero();
        let parts = [(&v.0, &y0.0, &y1.0), (&v.1, &y0.1, &y1.1)];
        for (vi, a, b) in parts {
            for i in 0..N {
                let sc = self.atol + self.rtol * a[i].abs().max(b[i].abs());
                let x = vi[i] / sc;
                sum += x * x;
            }
        }
        (sum / c::<T>(2.0 * N as f64)).sqrt()
    }
}

/// One Dormand–Prince step of size `h` from `state` with `k1 = f(state)`:
/// the new state, `f(new)` and the local error estimate (unscaled; the
/// integrator scales it by its tolerances).
fn step<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &State<T, N>,
    k1: &Derivative<T, N>,
    h: T,
    stabilization: &Stabilization<T>,
    stats: &mut Stats,
) -> Result<Step<T, N>, IntegrationError<T>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    let mut k: [Derivative<T, N>; 7] = [*k1; 7];
    for i in 1..7 {
        let mut q = state.q;
        let mut qd = state.qd;
        for j in 0..i {
            let a = c::<T>(A[i][j]) * h;
            if A[i][j] != 0.0 {
                q += k[j].0 * a;
                qd += k[j].1 * a;
            }
        }
        let stage = State {
            t: state.t + c::<T>(C[i]) * h,
            q,
            qd,
        };
        k[i] = derivative(system, &stage, stabilization, stats)?;
    }
    // The 7th stage was evaluated at the 5th-order solution (A's last row).
    let new = State {
        t: state.t + h,
        q: state.q
            + (0..6).fold(SVector::zeros(), |acc, j| {
                acc + k[j].0 * (c::<T>(A[6][j]) * h)
            }),
        qd: state.qd
            + (0..6).fold(SVector::zeros(), |acc, j| {
                acc + k[j].1 * (c::<T>(A[6][j]) * h)
            }),
    };
    let error = (
        (0..7).fold(SVector::<T, N>::zeros(), |acc, j| {
            acc + k[j].0 * (c::<T>(E[j]) * h)
        }),
        (0..7).fold(SVector::<T, N>::zeros(), |acc, j| {
            acc + k[j].1 * (c::<T>(E[j]) * h)
        }),
    );
    Ok(Step {
        state: new,
        derivative: k[6],
        error,
    })
}

common_methods!(DormandPrince45);
