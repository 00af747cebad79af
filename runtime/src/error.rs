use core::fmt;

/// Why the equations of motion could not be evaluated at a state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DynamicsError {
    /// `M(q, t)` is not symmetric positive definite at this state (a
    /// non-positive diagonal entry, or its Cholesky factorization failed), so
    /// Gauss's principle has no minimiser.
    MassNotPositiveDefinite,
    /// The inputs were not finite: the singular value decomposition of the
    /// Moore–Penrose variant did not converge on them.
    NonFinite,
}

impl fmt::Display for DynamicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            DynamicsError::MassNotPositiveDefinite => {
                "the mass matrix is not positive definite at this state"
            }
            DynamicsError::NonFinite => "the state or a derived quantity is not finite",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for DynamicsError {}
