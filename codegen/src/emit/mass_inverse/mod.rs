//! One module per way of applying `M⁻¹` (`crate::motion::MassInverse`).

pub(super) mod factored;
pub(super) mod step;
pub(super) mod symbolic;
