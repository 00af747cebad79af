//! The `no_std` runtime of [`constrained`](https://docs.rs/constrained).
//!
//! Generated code from `constrained_system!` is straight-line arithmetic; what
//! it cannot specialise at compile time lives here: the [`State`] and
//! [`ConstrainedSystem`] abstractions, the rank-revealing generalized inverse
//! ([`inverse`]), errors as values, and the machine-readable
//! [`SymbolicSystem`] description. Nothing here allocates or panics on user
//! data.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(missing_docs)]

mod error;
pub mod gibbs_appell;
pub mod integrate;
pub mod inverse;
mod level;
pub mod stabilize;
mod state;
pub mod svd;
mod symbolic;
mod system;

pub use error::DynamicsError;
pub use gibbs_appell::GibbsAppellError;
pub use integrate::{DormandPrince45, IntegrationError, Rk4, SemiImplicitEuler, Stats};
pub use level::ConstraintLevel;
pub use stabilize::Stabilization;
pub use state::State;
pub use symbolic::SymbolicSystem;
pub use system::ConstrainedSystem;

/// Converts a compile-time `f64` literal of generated code into the scalar `T`.
///
/// Generated code writes every literal through this function so that the same
/// code serves `f32` and `f64`; the conversion is a constant the optimiser folds.
#[inline(always)]
pub fn lit<T: nalgebra::RealField + Copy>(value: f64) -> T {
    nalgebra::convert::<f64, T>(value)
}
