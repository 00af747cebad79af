//! A symbolic `M⁻¹` (constant or diagonal `M`).

pub(in crate::emit) mod jacobian;
