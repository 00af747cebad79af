//! For every reference model, `A` and `b` agree with central finite
//! differences of `φ` along smooth trajectories.
//!
//! Along any trajectory `q(t)` (consistent with the constraints or not),
//! `d φ/dt = A q̈ − b` for a velocity-level constraint and `d²φ/dt² = A q̈ − b`
//! for a position-level one. The trajectory is a random cubic, so `q`, `q̇`
//! and `q̈` are known exactly at every time; `φ` is the generated
//! `constraint_residual`, and the differences are Richardson-extrapolated.

use constrained::models::*;
use constrained::nalgebra::SVector;
use constrained::ConstraintLevel;
use proptest::prelude::*;

/// `q(t) = q0 + v·s + a·s²/2 + j·s³/6` with `s = t − t0`.
#[derive(Clone, Debug)]
struct Cubic<const N: usize> {
    t0: f64,
    q0: [f64; N],
    v: [f64; N],
    a: [f64; N],
    j: [f64; N],
}

impl<const N: usize> Cubic<N> {
    fn at(&self, t: f64) -> (SVector<f64, N>, SVector<f64, N>) {
        let s = t - self.t0;
        let q = SVector::from_fn(|i, _| {
            self.q0[i] + self.v[i] * s + self.a[i] * s * s / 2.0 + self.j[i] * s * s * s / 6.0
        });
        let qd = SVector::from_fn(|i, _| self.v[i] + self.a[i] * s + self.j[i] * s * s / 2.0);
        (q, qd)
    }
}

fn cubic<const N: usize>() -> impl Strategy<Value = Cubic<N>> {
    let coordinate = || prop::array::uniform::<_, N>(-2.0..2.0f64);
    (
        -5.0..5.0f64,
        coordinate(),
        coordinate(),
        coordinate(),
        coordinate(),
    )
        .prop_map(|(t0, q0, v, a, j)| Cubic { t0, q0, v, a, j })
}

/// Richardson-extrapolated central differences, first and second derivative.
fn derivatives(f: &dyn Fn(f64) -> f64, t: f64) -> (f64, f64) {
    let first = |h: f64| (f(t + h) - f(t - h)) / (2.0 * h);
    let second = |h: f64| (f(t + h) - 2.0 * f(t) + f(t - h)) / (h * h);
    let h = 1e-3;
    (
        (4.0 * first(h / 2.0) - first(h)) / 3.0,
        (4.0 * second(h / 2.0) - second(h)) / 3.0,
    )
}

/// How far from a kink a trajectory must stay (over the differences' span).
const KINK_MARGIN: f64 = 0.05;

/// Checks every constraint of a model along one trajectory.
/// A model with kinks (`abs`, `min`, `max`) names where they are, so that
/// trajectories passing within `KINK_MARGIN` of one are left out: a
/// difference straddling a kink measures the jump, not the derivative.
macro_rules! agrees_with_finite_differences {
    ($test:ident, $model:ty, $n:literal, |$p:ident| $make:expr) => {
        agrees_with_finite_differences!($test, $model, $n, |$p| $make, kinks: |_q| []);
    };
    ($test:ident, $model:ty, $n:literal, |$p:ident| $make:expr, kinks: |$kq:ident| $kinks:expr) => {
        proptest! {
            #![proptest_config(ProptestConfig::with_cases(300))]
            #[test]
            fn $test(path in cubic::<$n>(), $p in prop::array::uniform8(0.5..2.0f64)) {
                let system: $model = $make;
                let (q, qd) = path.at(path.t0);
                for t in [path.t0 - 2e-3, path.t0, path.t0 + 2e-3] {
                    let $kq = path.at(t).0;
                    let distances: Vec<f64> = Vec::from($kinks);
                    prop_assume!(distances.iter().all(|d: &f64| d.abs() > KINK_MARGIN));
                }
                let qdd = SVector::<f64, $n>::from(path.a);
                let (a, b) = system.constraint_matrices(&q, &qd, path.t0);
                let ab = a * qdd - b;
                for (i, level) in <$model>::CONSTRAINT_LEVELS.into_iter().enumerate() {
                    let phi = |t: f64| {
                        let (q, qd) = path.at(t);
                        system.constraint_residual(&q, &qd, t)[i]
                    };
                    let (d1, d2) = derivatives(&phi, path.t0);
                    let fd = match level {
                        ConstraintLevel::Velocity => d1,
                        ConstraintLevel::Position => d2,
                    };
                    let scale = (a.row(i).abs() * qdd.abs())[0] + b[i].abs() + 1.0;
                    prop_assert!(
                        (fd - ab[i]).abs() < 1e-6 * scale,
                        "constraint {}: finite difference {} vs A q̈ − b = {}", i + 1, fd, ab[i]
                    );
                }
            }
        }
    };
}

agrees_with_finite_differences!(appell, Appell, 3, |p| Appell::new(p[0], p[1]));
agrees_with_finite_differences!(appell_time_dependent, AppellTimeDependent, 3, |p| {
    AppellTimeDependent::new(p[0], p[1])
});
agrees_with_finite_differences!(spherical_pendulum, SphericalPendulum, 3, |p| {
    SphericalPendulum::new(p[0], p[1], p[2])
});
agrees_with_finite_differences!(double_pendulum, DoublePendulum, 4, |p| {
    DoublePendulum::new(p[0], p[1], p[2], p[3], p[4])
});
agrees_with_finite_differences!(redundant_double_pendulum, RedundantDoublePendulum, 4, |p| {
    RedundantDoublePendulum::new(p[0], p[1], p[2], p[3], p[4])
});
agrees_with_finite_differences!(bead_on_rotating_hoop, BeadOnRotatingHoop, 3, |p| {
    BeadOnRotatingHoop::new(p[0], p[1], p[2], p[3])
});
agrees_with_finite_differences!(chaplygin_sleigh, ChaplyginSleigh, 3, |p| {
    ChaplyginSleigh::new(p[0], p[1], p[2], p[3])
});
agrees_with_finite_differences!(two_link_arm_on_line, TwoLinkArmOnLine, 2, |p| {
    TwoLinkArmOnLine::new(p[0], p[1], p[2], p[3], p[4], p[5])
});
agrees_with_finite_differences!(slider_crank, SliderCrank, 4, |p| {
    SliderCrank::new(p[0], p[1], p[2], p[3], p[4], p[5])
});
agrees_with_finite_differences!(parallelogram_four_bar, ParallelogramFourBar, 9, |p| {
    ParallelogramFourBar::new(p[0], p[1], p[2], p[3], p[4])
});
agrees_with_finite_differences!(crane, Crane, 3, |p| {
    Crane::new(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], 1.0)
});

constrained::constrained_system! {
    /// Kinks in a velocity-level constraint (differentiated once: allowed)
    /// and `hypot` in a position-level one (smooth away from the origin).
    pub struct Kinked {
        coordinates: [x, y, z],
        parameters: [c],
        mass: diag[1.0, 2.0, 3.0],
        constraints: [
            dot(x) == y.abs() * dot(z) + max(x, c * z) - min(y, z).powi(2) + clamp(x, -0.5, c),
            hypot(x, y) == 3.0 + (PI * z).sin() / E,
        ],
    }
}

agrees_with_finite_differences!(
    kinked,
    Kinked,
    3,
    |p| Kinked::new(p[0]),
    kinks: |q| [q[1], q[0] - p[0] * q[2], q[1] - q[2], q[0] + 0.5, q[0] - p[0]]
);
