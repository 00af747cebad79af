//! Shared by the integration tests.
#![allow(dead_code)] // each test binary uses its own subset

use proptest::prelude::*;

/// A random state of Appell's particle and its parameters:
/// `(q, q̇, t, g, α)`, not necessarily on the constraint.
pub fn appell_state() -> impl Strategy<Value = ([f64; 3], [f64; 3], f64, f64, f64)> {
    (
        prop::array::uniform3(-10.0..10.0f64),
        prop::array::uniform3(-10.0..10.0f64),
        -100.0..100.0f64,
        0.1..20.0f64,
        -3.0..3.0f64,
    )
}

/// A consistent state of the planar double pendulum with rods `l1`, `l2`:
/// absolute angles from the downward vertical and their rates.
pub fn double_pendulum_state(
    l1: f64,
    l2: f64,
    [t1, t2, w1, w2]: [f64; 4],
) -> constrained::State<f64, 4> {
    use constrained::nalgebra::Vector4;
    let q = Vector4::new(
        l1 * t1.sin(),
        -l1 * t1.cos(),
        l1 * t1.sin() + l2 * t2.sin(),
        -l1 * t1.cos() - l2 * t2.cos(),
    );
    let qd = Vector4::new(
        l1 * t1.cos() * w1,
        l1 * t1.sin() * w1,
        l1 * t1.cos() * w1 + l2 * t2.cos() * w2,
        l1 * t1.sin() * w1 + l2 * t2.sin() * w2,
    );
    constrained::State::new(0.0, q, qd)
}
