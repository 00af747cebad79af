//! What a generated solve hands back, chosen by the method that calls it.
//!
//! Every generated system has one private solver, `gauss`, shared by
//! `acceleration`, `constraint_force`, `acceleration_corrected`, the
//! Jacobian and the [`Generated`] trait. It is generic over a [`Finish`]:
//! the caller's type says what the solve returns on its exits, so that the
//! total `acceleration` returns `q̈` itself and never makes the constraint
//! force, and no caller post-processes a `Result` built for it:
//!
//! - the fast path, or a suspect rank decision that [`checked`] let stand
//!   ([`Finish::stands`]; [`Finish::stands_with`] where the fast path also
//!   has every row's multiplier, which [`Multiplied`] keeps);
//! - an error found before the solve (`M` not positive definite), the
//!   dense solve's outcome, or the checked recomputation
//!   ([`Finish::settle`]): for the total methods, the least-squares answer
//!   where the solve failed.
//!
//! [`checked`]: crate::rank::checked

use crate::generated::{Generated, Motion, Reaction};
use crate::rank::least_squares;
use crate::DynamicsError;
use nalgebra::{RealField, SVector};

/// The value of a generated solve for one kind of caller (module docs).
pub trait Finish<T: RealField + Copy, const N: usize> {
    /// What the solve returns.
    type Output;

    /// The fast solve's `q̈` stands; `force` makes the constraint force
    /// `Aᵀλ`, called only by a caller that wants it.
    fn stands(acceleration: SVector<T, N>, force: impl FnOnce() -> SVector<T, N>) -> Self::Output;

    /// `motion` as this caller returns it; `least_squares` makes the
    /// least-squares motion, for a caller that answers with it where the
    /// solve failed.
    fn decided(
        motion: Result<Motion<T, N>, DynamicsError>,
        least_squares: impl FnOnce() -> Motion<T, N>,
    ) -> Self::Output;

    /// [`stands`](Finish::stands), where the solve also has `λ`:
    /// `multipliers` makes every row's multiplier, `None` where the fast
    /// path dropped a row (a suspect rank decision let stand), so that they
    /// are not the unique `λ`. Only [`Multiplied`] reads it.
    #[inline(always)]
    fn stands_with<const K: usize>(
        acceleration: SVector<T, N>,
        force: impl FnOnce() -> SVector<T, N>,
        _multipliers: impl FnOnce() -> Option<[T; K]>,
    ) -> Self::Output {
        Self::stands(acceleration, force)
    }

    /// The solve's outcome where it was decided outside the fast path: an
    /// error before the solve, a checked recomputation, the dense solve.
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
        outside_fast_path();
        Self::decided(motion, || least_squares(system, q, qd, t, correction))
    }
}

/// Marks the path that calls it as rarely taken: every exit through
/// [`Finish::settle`] leaves the generated fast path, so the compiler lays
/// those blocks out of its way and keeps the fast path's values in
/// registers across them (a call to a `#[cold]` function is its only
/// stable hint).
#[cold]
#[inline(never)]
fn outside_fast_path() {}

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
    fn decided(motion: Self::Output, _: impl FnOnce() -> Motion<T, N>) -> Self::Output {
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
    fn decided(
        motion: Result<Motion<T, N>, DynamicsError>,
        least_squares: impl FnOnce() -> Motion<T, N>,
    ) -> Self::Output {
        motion.unwrap_or_else(|_| least_squares())
    }
}

/// `Result<q̈, DynamicsError>`: [`Fallible`]'s acceleration alone; the
/// constraint force is never made (so that `acceleration` does not pay for
/// `Aᵀλ` where the generated `gauss` is not inlined into it).
pub struct FallibleAcceleration;

impl<T: RealField + Copy, const N: usize> Finish<T, N> for FallibleAcceleration {
    type Output = Result<SVector<T, N>, DynamicsError>;

    #[inline(always)]
    fn stands(acceleration: SVector<T, N>, _: impl FnOnce() -> SVector<T, N>) -> Self::Output {
        Ok(acceleration)
    }

    #[inline(always)]
    fn decided(
        motion: Result<Motion<T, N>, DynamicsError>,
        _: impl FnOnce() -> Motion<T, N>,
    ) -> Self::Output {
        motion.map(|(acceleration, _)| acceleration)
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
    fn decided(
        motion: Result<Motion<T, N>, DynamicsError>,
        least_squares: impl FnOnce() -> Motion<T, N>,
    ) -> Self::Output {
        <Total as Finish<T, N>>::decided(motion, least_squares).0
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
    fn decided(
        motion: Result<Motion<T, N>, DynamicsError>,
        least_squares: impl FnOnce() -> Motion<T, N>,
    ) -> Self::Output {
        <Total as Finish<T, N>>::decided(motion, least_squares).1
    }
}

/// `Result<(q̈, Reaction), DynamicsError>`: `q̈` with the generated `λ`
/// where the fast path has all of it, else with `Aᵀλ`
/// (`Multipliers::acceleration_and_multipliers`).
pub struct Multiplied<const K: usize>;

impl<T: RealField + Copy, const N: usize, const K: usize> Finish<T, N> for Multiplied<K> {
    type Output = Result<(SVector<T, N>, Reaction<T, N, K>), DynamicsError>;

    #[inline(always)]
    fn stands(acceleration: SVector<T, N>, force: impl FnOnce() -> SVector<T, N>) -> Self::Output {
        Ok((acceleration, Reaction::Force(force())))
    }

    #[inline(always)]
    fn stands_with<const R: usize>(
        acceleration: SVector<T, N>,
        force: impl FnOnce() -> SVector<T, N>,
        multipliers: impl FnOnce() -> Option<[T; R]>,
    ) -> Self::Output {
        // R is the system's K (the generated code passes its own rows);
        // a mismatch, which no generated code makes, takes the force.
        match multipliers() {
            Some(lambda) if R == K => {
                let mut out = SVector::<T, K>::zeros();
                out.iter_mut().zip(lambda).for_each(|(o, l)| *o = l);
                Ok((acceleration, Reaction::Multipliers(out)))
            }
            _ => Ok((acceleration, Reaction::Force(force()))),
        }
    }

    #[inline(always)]
    fn decided(
        motion: Result<Motion<T, N>, DynamicsError>,
        _: impl FnOnce() -> Motion<T, N>,
    ) -> Self::Output {
        motion.map(|(acceleration, force)| (acceleration, Reaction::Force(force)))
    }
}
