//! The generated `generalized_momentum` (`p = M q̇`), against the momenta
//! written by hand, against `mass_matrix · q̇`, and against `∂T/∂q̇` by a
//! central difference of the generated `kinetic_energy` (exact for a `T`
//! quadratic in `q̇`, up to rounding).

use constrained::constrained_system;
use constrained::models::{CartPole, DoublePendulumAngles};
use constrained::nalgebra::{SVector, Vector2};
use constrained::DynamicsError;

constrained_system! {
    /// Two free masses of constant mass: `M` is a positive-definite
    /// constant, so the methods return plain values.
    pub struct TwoMasses {
        coordinates: [x, y],
        mass: diag[2.0, 3.0],
        forces: [0.0, 0.0],
    }
}

struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

fn close(a: f64, b: f64, scale: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + scale)
}

/// `∂T/∂q̇ᵢ` by a central difference of the generated kinetic energy.
fn kinetic_gradient<F: Fn(&Vector2<f64>) -> f64>(kinetic: F, qd: &Vector2<f64>) -> Vector2<f64> {
    let h = 1e-3;
    Vector2::from_fn(|i, _| {
        let mut up = *qd;
        let mut down = *qd;
        up[i] += h;
        down[i] -= h;
        (kinetic(&up) - kinetic(&down)) / (2.0 * h)
    })
}

#[test]
fn cart_pole_momentum_is_the_textbook_one() {
    let mut rng = Rng(11);
    for _ in 0..200 {
        let (mc, mp, l, g) = (
            rng.uniform(0.5, 3.0),
            rng.uniform(0.1, 2.0),
            rng.uniform(0.2, 2.0),
            9.81,
        );
        let system = CartPole::new(mc, mp, l, g, rng.uniform(-1.0, 1.0));
        let q = Vector2::new(rng.uniform(-2.0, 2.0), rng.uniform(-4.0, 4.0));
        let qd = Vector2::new(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
        let c = q[1].cos();
        let hand = [
            (mc + mp) * qd[0] + mp * l * c * qd[1],
            mp * l * c * qd[0] + mp * l * l * qd[1],
        ];
        let p = system.generalized_momentum(&q, &qd, 0.0).unwrap();
        let mqd = system.mass_matrix(&q, 0.0) * qd;
        let dt = kinetic_gradient(|v| system.kinetic_energy(&q, v, 0.0).unwrap(), &qd);
        for i in 0..2 {
            assert!(
                close(p[i], hand[i], hand[i].abs(), 1e-12),
                "p{i}: {} vs {}",
                p[i],
                hand[i]
            );
            assert!(close(p[i], mqd[i], mqd[i].abs(), 1e-12), "p{i} vs M q̇");
            assert!(
                close(p[i], dt[i], dt[i].abs(), 1e-7),
                "p{i}: {} vs ∂T/∂q̇ {}",
                p[i],
                dt[i]
            );
        }
    }
}

#[test]
fn double_pendulum_momentum_is_the_textbook_one() {
    let mut rng = Rng(12);
    for _ in 0..200 {
        let (m1, m2, l1, l2) = (
            rng.uniform(0.1, 3.0),
            rng.uniform(0.1, 3.0),
            rng.uniform(0.2, 2.0),
            rng.uniform(0.2, 2.0),
        );
        let system = DoublePendulumAngles::new(m1, m2, l1, l2, 9.81);
        let q = Vector2::new(rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0));
        let qd = Vector2::new(rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0));
        let c = (q[0] - q[1]).cos();
        let hand = [
            (m1 + m2) * l1 * l1 * qd[0] + m2 * l1 * l2 * c * qd[1],
            m2 * l1 * l2 * c * qd[0] + m2 * l2 * l2 * qd[1],
        ];
        let p = system.generalized_momentum(&q, &qd, 0.0).unwrap();
        let mqd = system.mass_matrix(&q, 0.0) * qd;
        let dt = kinetic_gradient(|v| system.kinetic_energy(&q, v, 0.0).unwrap(), &qd);
        for i in 0..2 {
            let scale = hand[0].abs() + hand[1].abs();
            assert!(
                close(p[i], hand[i], scale, 1e-12),
                "p{i}: {} vs {}",
                p[i],
                hand[i]
            );
            assert!(close(p[i], mqd[i], scale, 1e-12), "p{i} vs M q̇");
            assert!(
                close(p[i], dt[i], scale, 1e-7),
                "p{i}: {} vs ∂T/∂q̇ {}",
                p[i],
                dt[i]
            );
        }
    }
}

/// A constant positive-definite `M`: a plain vector, `diag(2, 3) q̇`.
#[test]
fn constant_mass_momentum_is_plain() {
    let system = TwoMasses::new();
    let qd = Vector2::new(1.5, -0.25);
    let p: SVector<f64, 2> = system.generalized_momentum(&Vector2::zeros(), &qd, 0.0);
    assert_eq!(p, Vector2::new(3.0, -0.75));
}

/// Where `M q̇` overflows, `Err(NonFinite)`, not an infinite momentum.
#[test]
fn overflowing_momentum_is_an_error() {
    let system = CartPole::new(1e300, 1.0, 1.0, 9.81, 0.0);
    let q = Vector2::new(0.0, 0.3);
    let qd = Vector2::new(1e10, 0.0);
    assert_eq!(
        system.generalized_momentum(&q, &qd, 0.0),
        Err(DynamicsError::NonFinite)
    );
}
