//! The step size of the adaptive methods: the error norm their
//! tolerances define, the starting step, and the controller of the steps
//! after it.

use super::{c, derivative_into, Derivative, Settings, Stats};
use crate::{ConstrainedSystem, IntegrationError, State};
use nalgebra::RealField;

/// An adaptive method's relative and absolute tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Tolerances<T> {
    pub rtol: T,
    pub atol: T,
}

impl<T: RealField + Copy> Tolerances<T> {
    /// RMS of `v / (atol + rtol·max(|y₀|, |y₁|))` over the 2N components.
    pub(super) fn norm<const N: usize>(
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

    /// Hairer, Nørsett & Wanner's starting step (Solving ODE I, II.4) for
    /// a method of order `order` from `state`, whose derivative is `k1`,
    /// over `total`: one evaluation, at an explicit Euler probe.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn initial_step<Sys, const N: usize, const K: usize>(
        &self,
        order: u32,
        system: &Sys,
        (state, k1): (&State<T, N>, &Derivative<T, N>),
        total: T,
        settings: &Settings<T>,
        stats: &mut Stats,
    ) -> Result<T, IntegrationError<T>>
    where
        Sys: ConstrainedSystem<T, N, K>,
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
        let mut k = *k1;
        derivative_into(system, &probe, settings, stats, &mut k)?;
        let diff = (k.0 - k1.0, k.1 - k1.1);
        let d2 = self.norm(&diff, &y, &y) / h0;
        let d = d1.max(d2);
        let order = c::<T>(f64::from(order));
        let h1 = if d <= c(1e-15) {
            (h0 * c(1e-3)).max(c(1e-6))
        } else {
            (c::<T>(0.01) / d).powf(T::one() / order)
        };
        Ok((h0 * c(100.0)).min(h1).min(total))
    }
}

/// The PI step-size controller of Hairer's DOPRI5 (Gustafsson's stabilised
/// control; Hairer & Wanner, *Solving Ordinary Differential Equations II*,
/// IV.2): after an accepted step with scaled error `err ≤ 1`,
/// `h_new = h / clamp(err^(1/(q+1) − 0.75β) / err_prev^β / safety, 1/10, 5)`
/// with `q` the order of the error estimate, β = 0.04 and safety 0.9, so
/// that a step grows at most tenfold and shrinks at most fivefold (DOPRI5's
/// `fac2`, `fac1`); it never grows right after a rejection. After a rejection, `h_new = h / min(err^(1/(q+1)) / safety, 5)`.
/// The integral term avoids the oscillation between accepted and rejected
/// steps of the plain `err^(−1/(q+1))` rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiController<T> {
    beta: T,
    safety: T,
    exponent: T,
    /// `err` of the last accepted step, floored at 1e-4 as in DOPRI5.
    err_previous: T,
    rejected_last: bool,
}

impl<T: RealField + Copy> PiController<T> {
    /// The controller for an error estimate of order `error_order`.
    pub fn new(error_order: u32) -> Self {
        let beta = c::<T>(0.04);
        PiController {
            beta,
            safety: c(0.9),
            exponent: T::one() / c::<T>(f64::from(error_order + 1)) - beta * c(0.75),
            err_previous: c(1e-4),
            rejected_last: false,
        }
    }

    /// The next step after an accepted step of size `h` with error `err`.
    pub fn accepted(&mut self, h: T, err: T) -> T {
        let factor = (self.proportional(err) / self.err_previous.powf(self.beta) / self.safety)
            .max(c(0.1))
            .min(c(5.0));
        let grown = h / factor;
        let next = if self.rejected_last {
            grown.min(h)
        } else {
            grown
        };
        self.err_previous = err.max(c(1e-4));
        self.rejected_last = false;
        next
    }

    /// The retry after a rejected step of size `h` with error `err > 1`
    /// (or not finite: then the step shrinks fivefold).
    pub fn rejected(&mut self, h: T, err: T) -> T {
        self.rejected_last = true;
        let factor = if err.is_finite() {
            (self.proportional(err) / self.safety).min(c(5.0))
        } else {
            c(5.0)
        };
        h / factor.max(T::one())
    }

    fn proportional(&self, err: T) -> T {
        if err > T::zero() {
            err.powf(self.exponent)
        } else {
            T::zero()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_at_most_tenfold_and_never_after_a_rejection() {
        let mut pi = PiController::<f64>::new(4);
        assert_eq!(pi.accepted(1.0, 0.0), 10.0);
        let shrunk = pi.rejected(1.0, 10.0);
        assert!(shrunk < 1.0 && shrunk > 0.2, "{shrunk}");
        assert_eq!(pi.accepted(0.5, 1e-8), 0.5);
        assert_eq!(pi.rejected(1.0, f64::NAN), 0.2);
    }

    #[test]
    fn exponent_follows_the_order_of_the_estimate() {
        // Dormand–Prince (q = 4) and Bogacki–Shampine (q = 2): the
        // rejection factor is err^(1/(q+1) − 0.03).
        let q4 = PiController::<f64>::new(4).rejected(1.0, 32.0);
        let q2 = PiController::<f64>::new(2).rejected(1.0, 8.0);
        assert!((q4 - 0.9 * 32f64.powf(-0.17)).abs() < 1e-12, "{q4}");
        assert!(
            (q2 - 0.9 * 8f64.powf(-(1.0 / 3.0 - 0.03))).abs() < 1e-12,
            "{q2}"
        );
    }
}
