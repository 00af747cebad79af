//! What a generated solve hands back, chosen by the method that calls it.
//!
//! Every generated system has one private solver, `gauss`, shared by
//! `acceleration`, `constraint_force`, `acceleration_corrected` and the
//! [`Generated`] trait. It is generic over a [`Finish`]: the caller's type
//! says what the solve returns on each of its three exits, so that no
//! caller post-processes a `Result` that the solve built for it:
//!
//! - the fast path, whose rank decision needs no check ([`Finish::stands`]):
//!   the total `acceleration` returns `q̈` and never makes the constraint
//!   force;
//! - the suspect path ([`Finish::suspect`], out of line): the runtime's check
//!   ([`checked`]) and, for the total methods, the least-squares answer,
//!   in one call whose value is the method's own. Nothing of the fast solve
//!   is live after it, so the fast path needs no stack frame: with the
//!   `Result` matched in the caller, Appell's particle saved and restored
//!   four registers and reserved 136 bytes of stack on every call, suspect
//!   or not (its fast path was 44 instructions; it is 24 now);
//! - an error found before the solve (`M` not positive definite, the dense
//!   solve's errors: [`Finish::settle`]).

use crate::generated::{Generated, Motion};
use crate::rank::{checked, least_squares};
use crate::DynamicsError;
use nalgebra::{RealField, SVector};

/// The value of a generated solve for one kind of caller (module docs).
pub trait Finish<T: RealField + Copy, const N: usize> {
    /// What the solve returns.
    type Output;

    /// The fast solve's `q̈` stands; `force` makes the constraint force
    /// `Aᵀλ`, called only by a caller that wants it.
    fn stands(acceleration: SVector<T, N>, force: impl FnOnce() -> SVector<T, N>) -> Self::Output;

    /// The solve's outcome where it was decided outside the fast path: an
    /// error before the solve, a checked recomputation, the dense solve.
    fn settle<S, const K: usize>(
        system: &S,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        correction: Option<&SVector<T, K>>,
        motion: Result<Motion<T, N>, DynamicsError>,
    ) -> Self::Output
    where
        S: Generated<T, N, K>;

    /// The fast solve's `candidate` where its rank decision is suspect:
    /// checked by [`checked`], kept if it stands, else the recomputation.
    #[cold]
    #[inline(never)]
    fn suspect<S, F, const K: usize>(
        system: &S,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        correction: Option<&SVector<T, K>>,
        candidate: SVector<T, N>,
        force: F,
    ) -> Self::Output
    where
        S: Generated<T, N, K>,
        F: FnOnce() -> SVector<T, N>,
    {
        match checked(system, q, qd, t, correction, candidate) {
            None => Self::stands(candidate, force),
            Some(recomputed) => Self::settle(system, q, qd, t, correction, recomputed),
        }
    }
}

/// `Result<(q̈, Aᵀλ), DynamicsError>`: the fallible methods and the
/// [`Generated`] trait.
pub struct Fallible;

impl<T: RealField + Copy, const N: usize> Finish<T, N> for Fallible {
    type Output = Result<Motion<T, N>, DynamicsError>;

    #[inline(always)]
    fn stands(acceleration: SVector<T, N>, force: impl FnOnce() -> SVector<T, N>) -> Self::Output {
        Ok((acceleration, force()))
    }

    #[inline(always)]
    fn settle<S, const K: usize>(
        _: &S,
        _: &SVector<T, N>,
        _: &SVector<T, N>,
        _: T,
        _: Option<&SVector<T, K>>,
        motion: Result<Motion<T, N>, DynamicsError>,
    ) -> Self::Output
    where
        S: Generated<T, N, K>,
    {
        motion
    }
}

/// `(q̈, Aᵀλ)` of a total method (`M` constant and positive definite):
/// where the solve fails (no acceleration satisfies `A q̈ = b`), the
/// least-squares one. The Jacobian's starting point.
pub struct Total;

impl<T: RealField + Copy, const N: usize> Finish<T, N> for Total {
    type Output = Motion<T, N>;

    #[inline(always)]
    fn stands(acceleration: SVector<T, N>, force: impl FnOnce() -> SVector<T, N>) -> Self::Output {
        (acceleration, force())
    }

    #[inline(always)]
    fn settle<S, const K: usize>(
        system: &S,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        correction: Option<&SVector<T, K>>,
        motion: Result<Motion<T, N>, DynamicsError>,
    ) -> Self::Output
    where
        S: Generated<T, N, K>,
    {
        total(system, q, qd, t, correction, motion)
    }
}

/// `q̈` of a total method, as [`Total`]; the constraint force is never made.
pub struct TotalAcceleration;

impl<T: RealField + Copy, const N: usize> Finish<T, N> for TotalAcceleration {
    type Output = SVector<T, N>;

    #[inline(always)]
    fn stands(acceleration: SVector<T, N>, _: impl FnOnce() -> SVector<T, N>) -> Self::Output {
        acceleration
    }

    #[inline(always)]
    fn settle<S, const K: usize>(
        system: &S,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        correction: Option<&SVector<T, K>>,
        motion: Result<Motion<T, N>, DynamicsError>,
    ) -> Self::Output
    where
        S: Generated<T, N, K>,
    {
        total(system, q, qd, t, correction, motion).0
    }
}

/// `Aᵀλ` of a total method, as [`Total`].
pub struct TotalForce;

impl<T: RealField + Copy, const N: usize> Finish<T, N> for TotalForce {
    type Output = SVector<T, N>;

    #[inline(always)]
    fn stands(_: SVector<T, N>, force: impl FnOnce() -> SVector<T, N>) -> Self::Output {
        force()
    }

    #[inline(always)]
    fn settle<S, const K: usize>(
        system: &S,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        correction: Option<&SVector<T, K>>,
        motion: Result<Motion<T, N>, DynamicsError>,
    ) -> Self::Output
    where
        S: Generated<T, N, K>,
    {
        total(system, q, qd, t, correction, motion).1
    }
}

/// The motion, or the least-squares one where the solve failed.
#[inline(always)]
fn total<T, S, const N: usize, const K: usize>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    correction: Option<&SVector<T, K>>,
    motion: Result<Motion<T, N>, DynamicsError>,
) -> Motion<T, N>
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    match motion {
        Ok(motion) => motion,
        Err(_) => least_squares(system, q, qd, t, correction),
    }
}
