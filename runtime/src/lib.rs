//! The `no_std` runtime of `constrained` (the facade crate users depend on).
//!
//! Generated code from `constrained_system!` is straight-line arithmetic; what
//! it cannot specialise at compile time lives here: the [`State`] and
//! [`ConstrainedSystem`] abstractions, the rank-revealing generalized inverse
//! ([`inverse`]), errors as values, and the machine-readable
//! [`SymbolicSystem`] description. Nothing here allocates or panics on user
//! data.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(missing_docs)]

#[macro_use]
mod methods;
pub mod control;
#[cfg(target_arch = "x86_64")]
mod cpu;
mod error;
mod finish;
pub mod floating;
pub mod friction;
mod gauss_dense;
mod generated;
pub mod gibbs_appell;
pub mod impact;
pub mod integrate;
pub mod inverse;
mod level;
pub mod linearize;
pub mod multipliers;
mod pow2;
pub mod rank;
pub mod stabilize;
mod state;
pub mod svd;
mod symbolic;
mod system;
mod trig;

pub use control::ControlError;
pub use error::{DynamicsError, GibbsAppellError, IntegrationError};
pub use impact::Impact;
pub use integrate::{
    BogackiShampine32, DormandPrince45, EmbeddedRungeKutta, ExplicitRungeKutta, Rk4,
    SemiImplicitEuler, Stats, ThreeEighthsRule,
};
pub use level::ConstraintLevel;
pub use linearize::Jacobians;
pub use stabilize::Stabilization;
pub use state::State;
pub use symbolic::{SymbolicEnergies, SymbolicGaps, SymbolicSystem};
pub use system::ConstrainedSystem;

#[doc(hidden)]
pub mod __private {
    //! Items used by generated code; not part of the public API.
    #[cfg(target_arch = "x86_64")]
    pub use crate::cpu::has_avx;
    pub use crate::finish::{
        Fallible, FallibleAcceleration, Finish, Multiplied, Total, TotalAcceleration, TotalForce,
    };
    pub use crate::gauss_dense::gauss_dense;
    pub use crate::generated::{
        all_finite, half_precision, largest, lit, signum, step, unscaled_bound, unstride,
        Generated, Motion, Reaction,
    };
    pub use crate::linearize::Tangent;
    pub use crate::rank::{
        checked, conditioning_tolerance, least_squares, moore_penrose, safe_minimum,
    };
    pub use crate::trig::sin_cos;
}
