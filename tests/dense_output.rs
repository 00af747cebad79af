//! Dense output against stepping (issue 30): the solution interpolated at
//! a time inside a step — `advance_sampled`'s samples, `Stepper::at` — is
//! the solution reached by integrating to that time, to the method's
//! accuracy, from random states of the double pendulum.

use constrained::integrate::{Events, StepOutcome};
use constrained::models::{double_pendulum_state, DoublePendulum};
use constrained::{BogackiShampine32, DormandPrince45, Rk4, State};
use proptest::prelude::*;

const SPAN: f64 = 2.0;

fn system() -> DoublePendulum<f64> {
    DoublePendulum::new(1.0, 1.5, 1.2, 0.8, 9.81)
}

fn distance(a: &State<f64, 4>, b: &State<f64, 4>) -> f64 {
    assert_eq!(a.t, b.t);
    (a.q - b.q).amax().max((a.qd - b.qd).amax())
}

/// Sorted sample times in `(0, SPAN)`.
fn times(fractions: &[f64]) -> Vec<f64> {
    let mut times: Vec<f64> = fractions.iter().map(|f| f * SPAN).collect();
    times.sort_by(f64::total_cmp);
    times
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn dense_output_agrees_with_advance(
        angles in prop::array::uniform2(-2.5..2.5f64),
        rates in prop::array::uniform2(-2.0..2.0f64),
        fractions in prop::collection::vec(0.001..0.999f64, 1..6),
    ) {
        let system = system();
        let start = double_pendulum_state(1.2, 0.8, 0.0, angles, rates);
        let times = times(&fractions);
        // The adaptive pairs, through advance_sampled: (method, bound).
        let dp = DormandPrince45::new(1e-10, 1e-12);
        let bs = BogackiShampine32::new(1e-9, 1e-11);
        let mut worst = [0.0f64; 2];
        let mut sampled = Vec::new();
        let mut s = start;
        dp.advance_sampled(&system, &mut s, SPAN, &times, |x| sampled.push(*x)).unwrap();
        for (x, &t) in sampled.iter().zip(&times) {
            let mut reference = start;
            dp.advance(&system, &mut reference, t).unwrap();
            worst[0] = worst[0].max(distance(x, &reference));
        }
        sampled.clear();
        let mut s = start;
        bs.advance_sampled(&system, &mut s, SPAN, &times, |x| sampled.push(*x)).unwrap();
        for (x, &t) in sampled.iter().zip(&times) {
            let mut reference = start;
            bs.advance(&system, &mut reference, t).unwrap();
            worst[1] = worst[1].max(distance(x, &reference));
        }
        prop_assert_eq!(sampled.len(), times.len());
        // Both are within the global error of the two runs.
        prop_assert!(worst[0] < 1e-6, "Dormand–Prince: {:e}", worst[0]);
        prop_assert!(worst[1] < 1e-5, "Bogacki–Shampine: {:e}", worst[1]);

        // The stepper's extension of RK4 (cubic Hermite) inside its steps,
        // from gentler states (half the angles and rates), against the exact
        // solution through the step's start (a Dormand–Prince run at 1e-13
        // from that state): the interpolation error alone. It scales as h⁴
        // and reached 8e-6 at h = 0.005 over the test command's seed, so the
        // step is 0.002 (8e-6 · 0.4⁴ ≈ 2e-7, bound 1e-6), where a linear
        // interpolant, scaling as h², would leave ~5e-6.
        let start = double_pendulum_state(1.2, 0.8, 0.0, angles.map(|a| a / 2.0), rates.map(|r| r / 2.0));
        let rk4 = Rk4::new(0.002);
        let exact = DormandPrince45::new(1e-13, 1e-15);
        let mut stepper = rk4.stepper(start, SPAN).unwrap();
        let mut next = 0;
        let mut worst_rk4 = 0.0f64;
        let mut step_start = start;
        while let Ok(StepOutcome::Step | StepOutcome::Finished) = stepper.step(&system, &Events::none()) {
            while let Some(&t) = times.get(next) {
                let Some(x) = stepper.at(t) else { break };
                let mut reference = step_start;
                exact.advance(&system, &mut reference, t).unwrap();
                worst_rk4 = worst_rk4.max(distance(&x, &reference));
                next += 1;
            }
            step_start = *stepper.state();
            if stepper.state().t == SPAN {
                break;
            }
        }
        prop_assert_eq!(next, times.len());
        prop_assert!(worst_rk4 < 1e-6, "RK4 + Hermite: {:e}", worst_rk4);
    }
}
