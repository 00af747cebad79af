//! The runtime's errors, as values: what went wrong and where.

use core::fmt;

/// Why the equations of motion could not be evaluated at a state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DynamicsError {
    /// `M(q, t)` is not symmetric positive definite at this state (a
    /// non-positive diagonal entry, or its Cholesky factorization failed), so
    /// Gauss's principle has no minimiser.
    MassNotPositiveDefinite,
    /// The inputs (state, parameters or a derived quantity) were not
    /// finite, or the exact result is not representable in `T`.
    NonFinite,
    /// No acceleration satisfies `A q̈ = b` to working precision here: the
    /// constraints contradict each other at this state (e.g. exactly at a
    /// singular configuration), or are too ill-conditioned for `T`
    /// (`constrained::rank`).
    Unsatisfiable,
    /// The coordinates the Gibbs–Appell partition eliminates cannot be
    /// solved for at this state (their columns of `A` are dependent here,
    /// e.g. at a singular configuration): the reduced linearization does
    /// not exist in this partition (`constrained::linearize::reduced`).
    SingularPartition,
    /// `q̈` has no derivative here that `T` resolves
    /// (`acceleration_jacobian`, `linearize`; `constrained::linearize`):
    /// where `A` loses rank (Appell's particle at rest, `q̇ = 0`, where
    /// `q̈` is homogeneous of degree one in `q̇`; a linkage at its branch
    /// point) `q̈` is not differentiable, and near a branch point the rank
    /// decision `acceleration` checks makes it jump, at its tolerance, by
    /// more than `√ε` of `q̈`, so that its derivative depends on the scale
    /// it is taken at.
    NotDifferentiable,
}

impl fmt::Display for DynamicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            DynamicsError::MassNotPositiveDefinite => {
                "the mass matrix is not positive definite at this state"
            }
            DynamicsError::NonFinite => "the state or a derived quantity is not finite",
            DynamicsError::Unsatisfiable => {
                "no acceleration satisfies the constraints to working precision at this state"
            }
            DynamicsError::SingularPartition => {
                "the eliminated coordinates cannot be solved for at this state"
            }
            DynamicsError::NotDifferentiable => {
                "the acceleration is not differentiable at this state to working precision \
                 (the constraints lose rank here, or nearly: a branch point)"
            }
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for DynamicsError {}

/// Why the Gibbs–Appell system could not be formed at a state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GibbsAppellError {
    /// `A` has rank below the generic rank `r` here: no `r` independent
    /// columns (or rows) exist, so no coordinates can be eliminated.
    RankDeficient,
    /// The reduced mass matrix `B` is not positive definite, because `M` is
    /// not (or the inputs are not finite).
    MassNotPositiveDefinite,
    /// The result is not finite: the inputs were not, or the exact result
    /// is not representable in `T`.
    NonFinite,
    /// The form is too ill-conditioned here to give `q̈` to `√ε`: the
    /// reduced mass matrix `B` has condition beyond `1/√ε`, or the result
    /// violates its rows of `A q̈ = b` by more than `√ε` (relative). The
    /// generalized-inverse form is better conditioned.
    IllConditioned,
    /// The result violates a row of `A q̈ = b` that the partition left out
    /// by more than `√ε` (relative): the form enforces `r` rows and answers
    /// only where the others follow from them, i.e. on the surface where a
    /// redundant model's extra rows depend on the rest. Off it (a redundant
    /// row independent, `A` of rank above `r`), no `q̈` of the form satisfies
    /// every row; the generalized-inverse form says what does.
    Inconsistent,
    /// A row of `A` lies wholly below `T`'s normal range at this state (a
    /// state scaled toward the smallest subnormal number): its entries and
    /// its `b`, products of subnormal numbers, have lost their relative
    /// precision (`f32` at 1e-45 keeps one bit), so `q̈` and its check
    /// against `A q̈ = b` cannot be trusted to `√ε`. Rescale the model.
    Underflow,
}

impl fmt::Display for GibbsAppellError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            GibbsAppellError::RankDeficient => {
                "A has dropped below its generic rank at this state: the Gibbs–Appell \
                 partition is undefined (use the generalized-inverse form)"
            }
            GibbsAppellError::MassNotPositiveDefinite => {
                "the reduced mass matrix of the Gibbs–Appell form is not positive definite"
            }
            GibbsAppellError::IllConditioned => {
                "the Gibbs–Appell form is too ill-conditioned at this state to give q̈ to \
                 working precision (use the generalized-inverse form)"
            }
            GibbsAppellError::Inconsistent => {
                "the Gibbs–Appell acceleration violates a row of A q̈ = b outside its partition \
                 (off the surface where the redundant rows depend on the others; use the \
                 generalized-inverse form)"
            }
            GibbsAppellError::Underflow => {
                "a row of A is subnormal at this state: its digits are lost to underflow, so the \
                 Gibbs–Appell acceleration cannot be trusted (rescale the model)"
            }
            GibbsAppellError::NonFinite => {
                "the Gibbs–Appell acceleration is not finite (non-finite input, or a result \
                 beyond the range of the scalar type)"
            }
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for GibbsAppellError {}

/// Why an integration stopped early. Each carries the time it stopped at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegrationError<T> {
    /// The state became NaN or infinite.
    NonFiniteState {
        /// Time of the last finite state.
        t: T,
    },
    /// The adaptive step size fell below what the time's precision resolves.
    StepSizeUnderflow {
        /// Time reached.
        t: T,
        /// The step size that was too small.
        step: T,
    },
    /// The step budget ran out before the end time.
    TooManySteps {
        /// Time reached.
        t: T,
        /// The budget.
        steps: usize,
    },
    /// The equations of motion could not be evaluated.
    Dynamics {
        /// Time of the failing evaluation.
        t: T,
        /// Why.
        error: DynamicsError,
    },
    /// Projection onto the constraints did not converge.
    ProjectionFailed {
        /// Time of the step.
        t: T,
        /// The largest constraint residual left.
        residual: T,
    },
    /// The end time lies before the current time.
    EndBeforeStart {
        /// Current time.
        t: T,
        /// Requested end time.
        t_end: T,
    },
    /// Time stopped advancing: `t + h == t` in `T`'s precision (a step
    /// below the resolution of `t`, e.g. `h = 1e-3` at `t = 32768` in `f32`).
    TimeStalled {
        /// The time that did not advance.
        t: T,
        /// The step that was lost in rounding.
        step: T,
    },
    /// A setting that cannot work, found before any step: a step size,
    /// tolerance, rate or sample time that is not positive and finite (or
    /// out of order), a zero step budget, a non-finite end time, or a
    /// starting state whose `t`, `q` or `q̇` is not finite.
    InvalidParameter,
    /// An event function's value was NaN or infinite (it could not change
    /// sign, so a crossing would have been missed).
    EventNotFinite {
        /// Time of the evaluation.
        t: T,
        /// The function's index.
        event: usize,
    },
    /// Event function `event` crossed again, in the same direction, within
    /// the time tolerance of the state set at its crossing at `t`: the
    /// state change did not take the trajectory off the surface (an impact
    /// with restitution 0 under a force into it, or the end of a Zeno
    /// sequence of impacts). The contact persists: switch the model to it
    /// (a constraint, a support force) and restart.
    EventRepeats {
        /// Time of the crossing whose state change did not separate.
        t: T,
        /// The function's index.
        event: usize,
    },
}

impl<T: fmt::Display> fmt::Display for IntegrationError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IntegrationError::NonFiniteState { t } => {
                write!(f, "the state became non-finite after t = {t}")
            }
            IntegrationError::StepSizeUnderflow { t, step } => write!(
                f,
                "the step size {step} underflowed at t = {t}: the problem is too stiff \
                 or singular for the tolerances"
            ),
            IntegrationError::TooManySteps { t, steps } => {
                write!(f, "{steps} steps were not enough: stopped at t = {t}")
            }
            IntegrationError::Dynamics { t, error } => write!(f, "at t = {t}: {error}"),
            IntegrationError::ProjectionFailed { t, residual } => write!(
                f,
                "projection onto the constraints did not converge at t = {t} \
                 (residual {residual})"
            ),
            IntegrationError::EndBeforeStart { t, t_end } => {
                write!(f, "the end time {t_end} lies before the current time {t}")
            }
            IntegrationError::TimeStalled { t, step } => write!(
                f,
                "time stopped advancing at t = {t}: the step {step} is below its resolution \
                 (use a larger step, or f64)"
            ),
            IntegrationError::InvalidParameter => f.write_str(
                "invalid setting: step sizes, tolerances and stabilization parameters must be \
                 positive and finite, sample times ordered, the starting state and end time \
                 finite",
            ),
            IntegrationError::EventNotFinite { t, event } => {
                write!(f, "event function {event} is not finite at t = {t}")
            }
            IntegrationError::EventRepeats { t, event } => write!(
                f,
                "event function {event} crosses again right after the state set at its \
                 crossing at t = {t}: the contact persists (restitution 0, or a Zeno \
                 sequence); switch to the persistent contact"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for IntegrationError<T> {}
