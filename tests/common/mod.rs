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
