//! The `no_std` runtime of [`constrained`](https://docs.rs/constrained).
//!
//! Generated code from `constrained_system!` is straight-line arithmetic; what it
//! cannot specialise at compile time lives here: the machine-readable
//! [`SymbolicSystem`] description and the conversion of literals into the
//! user's scalar type.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(missing_docs)]

mod level;
mod symbolic;

pub use level::ConstraintLevel;
pub use symbolic::SymbolicSystem;

/// Converts a compile-time `f64` literal of generated code into the scalar `T`.
///
/// Generated code writes every literal through this function so that the same
/// code serves `f32` and `f64`; the conversion is a constant the optimiser folds.
#[inline(always)]
pub fn lit<T: nalgebra::RealField + Copy>(value: f64) -> T {
    nalgebra::convert::<f64, T>(value)
}
