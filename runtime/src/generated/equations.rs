//! The trait a generated system implements: its equations at a state,
//! from which every [`ConstrainedSystem`](crate::ConstrainedSystem) method
//! follows, and what its solves hand back.

use crate::{ConstraintLevel, DynamicsError, GibbsAppellError};
use nalgebra::{RealField, SMatrix, SVector};

/// `(q̈, Fᶜ)`: the acceleration and the constraint force `Aᵀλ`.
pub type Motion<T, const N: usize> = (SVector<T, N>, SVector<T, N>);

/// The equations a generated system provides at `(q, q̇, t)`: its inherent
/// methods, forwarded (the rows of `methods.rs`, and the solver `gauss`).
/// [`ConstrainedSystem`](crate::ConstrainedSystem) is implemented for every
/// `Generated` type by the blanket impl in `system.rs`.
pub trait Generated<T: RealField + Copy, const N: usize, const K: usize> {
    /// Position or velocity level of each constraint.
    const CONSTRAINT_LEVELS: [ConstraintLevel; K];
    /// Whether `M` is only positive semi-definite, so that Gauss's
    /// principle is solved for the auxiliary system `M + s AᵀA`,
    /// `F + s Aᵀb` (Udwadia & Schutte 2010; see `effective_mass`): here
    /// with every row, in the generated solve with the rows that complete
    /// `M`'s rank.
    const SEMIDEFINITE_MASS: bool = false;
    /// The rank of `A` at consistent states, measured at compile time: `K`
    /// less the model's redundancy. A rank decision that keeps this many
    /// rows is accepted unchecked ([`crate::rank`]).
    const GENERIC_RANK: usize = K;
    forwarded_methods!(generated_declarations);
    /// `(q̈, Aᵀλ)` of Gauss's principle with `b + correction`.
    fn gauss(
        &self,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        correction: Option<&SVector<T, K>>,
    ) -> Result<Motion<T, N>, DynamicsError>;
    /// `q̈` of [`gauss`](Self::gauss) alone (this default: its first half);
    /// the generated systems' never make the constraint force.
    fn gauss_acceleration(
        &self,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        correction: Option<&SVector<T, K>>,
    ) -> Result<SVector<T, N>, DynamicsError> {
        self.gauss(q, qd, t, correction).map(|m| m.0)
    }
    /// `q̈` and, where the generated solve kept every row, each row's
    /// multiplier `λ` from that solve; else the constraint force `Aᵀλ`
    /// (this default: always), from which the runtime finds `λ`.
    fn gauss_multipliers(
        &self,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
    ) -> Result<(SVector<T, N>, Reaction<T, N, K>), DynamicsError> {
        self.gauss(q, qd, t, None)
            .map(|(qdd, force)| (qdd, Reaction::Force(force)))
    }
    /// The constraint-space step of the projections, `W S⁺ r` with
    /// `W = M⁻¹ Aᵀ`, `S = A W`, by the generated factorizations at this
    /// state, and which rows the rank rule kept. `None` where the generated
    /// solve does not answer (a singular `M`, `M` not positive definite, a
    /// suspect rank decision): then the runtime solves densely.
    #[allow(clippy::type_complexity)]
    fn constraint_step(
        &self,
        _q: &SVector<T, N>,
        _qd: &SVector<T, N>,
        _t: T,
        _r: &SVector<T, K>,
    ) -> Option<(SVector<T, N>, [bool; K])> {
        None
    }
}
/// What [`Generated::gauss_multipliers`] gives beside `q̈` (the runtime's
/// `Multiplied` finisher makes it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reaction<T: RealField + Copy, const N: usize, const K: usize> {
    /// Every row's multiplier, from the generated solve: the unique `λ` of
    /// `Aᵀλ = Fᶜ` where every row was kept, the minimum-norm one for a
    /// redundant set whose solve writes it.
    Multipliers(SVector<T, K>),
    /// The constraint force `Fᶜ = Aᵀλ` only (a row dropped, the dense
    /// solve, a recomputation, or a solve without `λ`): the runtime finds
    /// `λ` from it (`constrained::multipliers`).
    Force(SVector<T, N>),
}
