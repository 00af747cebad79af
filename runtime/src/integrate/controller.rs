//! The step-size controller of the adaptive methods.

use super::c;
use nalgebra::RealField;

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
