//! Coulomb friction switched between stick and slip (Leine & Nijmeijer's
//! switch model), for the entries of a system's `friction: [..]` section.
//!
//! An entry `coulomb(v, N, μs, μk)` names a velocity `v = J(q, t) q̇ + c(q, t)`
//! (a coordinate's `dot(x)`, a contact point's sliding speed, the speed
//! relative to a moving belt), the normal force `N ≥ 0` and the static and
//! kinetic coefficients `μs ≥ μk ≥ 0`. Each entry is in one [`Mode`]:
//!
//! - **slipping** in the sense `s = ±1` (the sign of `v`): the generated
//!   forces hold Coulomb's force `−μk N s Jᵀ`, its sense fixed for the
//!   phase (no `signum` of `v` to chatter on);
//! - **sticking**: the generated constraints hold the velocity-level row
//!   `v = 0`, whose multiplier `λ` ([`crate::multipliers`]) is the
//!   friction force the contact must supply.
//!
//! The switches are events of the [`StickSlip`](crate::integrate::StickSlip)
//! driver: a slip ends where `v` crosses zero against its sense (the state
//! is then stopped, `v = 0`, by the impulsive Gauss principle, the other
//! constraints kept); it sticks if the force needed to hold it is within the
//! static cone, `|λ| ≤ μs N`, and slips the other way (sense `−sign λ`)
//! otherwise; a stick ends where `μs N − |λ|` falls through zero, into a
//! slip of sense `−sign λ`. Every switch sets the mode and restarts the
//! stepper at its time; the event functions' directions are chosen so that
//! the new phase's function, which starts at zero, cannot report the same
//! switch again (each switch is handled once), and a bounded number of
//! switches at one instant is an `Err` ([`FrictionError::Zeno`]) rather
//! than a hang.

use crate::{ConstrainedSystem, DynamicsError, IntegrationError, State};
use core::fmt;
use nalgebra::{RealField, SVector};

/// The phase of one friction entry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// The velocity held at zero by a constraint row.
    #[default]
    Stick,
    /// Slipping with `v > 0`: the friction force is `−μk N Jᵀ`.
    SlipPositive,
    /// Slipping with `v < 0`: the friction force is `+μk N Jᵀ`.
    SlipNegative,
}

impl Mode {
    /// The slip's sense `s`: `1`, `−1`, or `0` when sticking. The generated
    /// equations read the mode through it: the slip force is `−μk N s Jᵀ`
    /// and the stick row is `(1 − s²) v = 0`.
    ///
    /// ```
    /// use constrained_runtime::friction::Mode;
    /// assert_eq!(Mode::SlipNegative.sign::<f64>(), -1.0);
    /// assert_eq!(Mode::Stick.sign::<f64>(), 0.0);
    /// ```
    #[must_use]
    pub fn sign<T: RealField + Copy>(self) -> T {
        match self {
            Mode::Stick => T::zero(),
            Mode::SlipPositive => T::one(),
            Mode::SlipNegative => -T::one(),
        }
    }

    /// The slip whose sense is `s`'s sign (`Stick` for zero or NaN).
    #[must_use]
    pub fn slip<T: RealField + Copy>(s: T) -> Self {
        if s > T::zero() {
            Mode::SlipPositive
        } else if s < T::zero() {
            Mode::SlipNegative
        } else {
            Mode::Stick
        }
    }
}

/// What the macro generates for a system with `friction: [..]` (`F`
/// entries): the modes, kept in the system's hidden fields, and the
/// entries' values. The stick rows are the last `F` of the `K` constraints.
pub trait Friction<T: RealField + Copy, const N: usize, const K: usize, const F: usize>:
    ConstrainedSystem<T, N, K>
{
    /// The entries' modes.
    fn friction_modes(&self) -> [Mode; F];
    /// Sets the entries' modes (between steps: restart the stepper after).
    fn set_friction_modes(&mut self, modes: [Mode; F]);
    /// The sliding velocities `v`, one per entry.
    fn friction_velocities(&self, q: &SVector<T, N>, qd: &SVector<T, N>, t: T) -> SVector<T, F>;
    /// The normal forces `N`, one per entry.
    fn friction_normals(&self, q: &SVector<T, N>, qd: &SVector<T, N>, t: T) -> SVector<T, F>;
    /// The coefficients `(μs, μk)`, one pair per entry.
    fn friction_coefficients(&self) -> [(T, T); F];
    /// The multipliers `λ` of the stick rows in the current modes (zero
    /// for a slipping entry): the friction each sticking contact supplies,
    /// along `Jᵀ`. `Err` where the acceleration is.
    fn stick_forces(&self, state: &State<T, N>) -> Result<SVector<T, F>, DynamicsError>;
}

/// Why a stick–slip integration stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrictionError<T> {
    /// The integration failed (step budget, step size, dynamics, events).
    Integration(IntegrationError<T>),
    /// The equations could not be evaluated at a switch.
    Dynamics {
        /// Time of the switch.
        t: T,
        /// Why.
        error: DynamicsError,
    },
    /// An entry's coefficients are not `μs ≥ μk ≥ 0` (finite).
    Coefficients {
        /// The entry.
        entry: usize,
    },
    /// An entry's normal force is negative or not finite at a switch.
    Normal {
        /// The entry.
        entry: usize,
        /// Time of the switch.
        t: T,
    },
    /// More switches at one instant than the entries can make (each entry
    /// sticks or slips once there): the switching does not settle.
    Zeno {
        /// The instant.
        t: T,
    },
}

impl<T> From<IntegrationError<T>> for FrictionError<T> {
    fn from(e: IntegrationError<T>) -> Self {
        FrictionError::Integration(e)
    }
}

impl<T: fmt::Display> fmt::Display for FrictionError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrictionError::Integration(e) => write!(f, "{e}"),
            FrictionError::Dynamics { t, error } => {
                write!(
                    f,
                    "the dynamics failed at a friction switch at t = {t}: {error}"
                )
            }
            FrictionError::Coefficients { entry } => write!(
                f,
                "friction entry {entry}: the coefficients must be finite with μs ≥ μk ≥ 0"
            ),
            FrictionError::Normal { entry, t } => write!(
                f,
                "friction entry {entry}: the normal force is negative or not finite at t = {t}"
            ),
            FrictionError::Zeno { t } => write!(
                f,
                "the friction switches do not settle at t = {t} (more switches than entries)"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl<T: fmt::Debug + fmt::Display> std::error::Error for FrictionError<T> {}

/// Checks every entry's coefficients: finite, `μs ≥ μk ≥ 0`.
pub(crate) fn check_coefficients<T: RealField + Copy, const F: usize>(
    coefficients: &[(T, T); F],
) -> Result<(), FrictionError<T>> {
    for (entry, &(s, k)) in coefficients.iter().enumerate() {
        if !(s.is_finite() && k.is_finite() && k >= T::zero() && s >= k) {
            return Err(FrictionError::Coefficients { entry });
        }
    }
    Ok(())
}

/// The mode an entry at `v = 0` takes: stick if the force needed to hold
/// it, `λ`, is within `μs N`, else slip against it (sense `−sign λ`).
pub(crate) fn stick_or_slip<T: RealField + Copy>(lambda: T, mu_static: T, normal: T) -> Mode {
    if lambda.abs() <= mu_static * normal {
        Mode::Stick
    } else {
        Mode::slip(-lambda)
    }
}
