use crate::generated::all_finite;
use crate::generated::Generated;
use crate::rank::moore_penrose;
use crate::{ConstraintLevel, DynamicsError, GibbsAppellError, State};
use nalgebra::{RealField, SMatrix, SVector};

/// A constrained mechanical system with `N` coordinates and `K` constraints,
/// implemented by every struct that `constrained_system!` generates. The
/// methods are the generated ones, taking a [`State`].
///
/// Call them fully qualified, `ConstrainedSystem::forces(&system, &state)`,
/// or (the accelerations) on the state, `state.acceleration(&system)` (see
/// the methods of [`State`]): a generated system's
/// inherent `acceleration(q, qd, t)` has the same name and wins method
/// resolution, so `system.acceleration(&state)` does not compile (E0061).
pub trait ConstrainedSystem<T: RealField + Copy, const N: usize, const K: usize> {
    /// Whether each constraint is position level (differentiated twice) or
    /// velocity level (once).
    const CONSTRAINT_LEVELS: [ConstraintLevel; K];
    /// The model's redundancy: `K` less the rank of `A` at consistent
    /// states (measured by the macro); 0 unless some rows depend on the
    /// others on the constraint surface.
    const REDUNDANCY: usize = 0;
    /// Whether `M` is only positive semi-definite (singular everywhere, a
    /// body in unit quaternions), so that the projections' metric is the
    /// auxiliary mass `M + s AᵀA` (as the accelerations' solve): a
    /// Cholesky factorization of `M` itself may succeed by rounding, with a
    /// pivot at rounding level, and its steps are then noise along the
    /// singular direction.
    const SEMIDEFINITE_MASS: bool = false;

    forwarded_methods!(system_declarations);
    /// `q̈` by the generalized-inverse equation (eq. 24–26). `Err` only when
    /// `M` is not positive definite at this state.
    fn acceleration(&self, state: &State<T, N>) -> Result<SVector<T, N>, DynamicsError>;
    /// `q̈` by the Moore–Penrose form of eq. 24 (SVD at run time): the same
    /// as [`acceleration`](Self::acceleration) wherever the constraints are
    /// consistent, slower.
    fn acceleration_moore_penrose(
        &self,
        state: &State<T, N>,
    ) -> Result<SVector<T, N>, DynamicsError>;
    /// `q̈` with `b` replaced by `b + db` (constraint stabilization).
    fn acceleration_corrected(
        &self,
        state: &State<T, N>,
        db: &SVector<T, K>,
    ) -> Result<SVector<T, N>, DynamicsError>;
    /// The constraint force `M q̈ − F`, with the same error as
    /// [`acceleration`](Self::acceleration).
    fn constraint_force(&self, state: &State<T, N>) -> Result<SVector<T, N>, DynamicsError>;
    /// The projections' step `M⁻¹Aᵀ (A M⁻¹ Aᵀ)⁺ r` through the generated
    /// factorizations, and the rows kept; `None` makes
    /// [`stabilize::project`](crate::stabilize::project) solve densely (the
    /// default, for systems without a generated solve).
    #[doc(hidden)]
    #[allow(clippy::type_complexity)]
    fn constraint_step(
        &self,
        _state: &State<T, N>,
        _r: &SVector<T, K>,
    ) -> Option<(SVector<T, N>, [bool; K])> {
        None
    }
}

/// The accelerations of [`ConstrainedSystem`], called on the state:
/// `state.acceleration(&system)`.
///
/// A generated system has inherent methods of the same names that take
/// `(q, q̇, t)`, and Rust picks the inherent one for `system.acceleration(..)`
/// (so `system.acceleration(&state)` is error E0061, "takes 3 arguments").
/// These methods are the one spelling that needs neither the trait in scope
/// nor a qualified path, for the three forms of `q̈` users compare. `K` is
/// inferred from the system. The trait's other methods are called fully
/// qualified, `ConstrainedSystem::forces(&system, &state)`, or inherent,
/// `system.forces(&state.q, &state.qd, state.t)`.
impl<T: RealField + Copy, const N: usize> State<T, N> {
    /// `q̈` by the generalized-inverse equation (eq. 24–26).
    pub fn acceleration<const K: usize, S>(
        &self,
        system: &S,
    ) -> Result<SVector<T, N>, DynamicsError>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        system.acceleration(self)
    }

    /// `q̈` by the Moore–Penrose form of eq. 24.
    pub fn acceleration_moore_penrose<const K: usize, S>(
        &self,
        system: &S,
    ) -> Result<SVector<T, N>, DynamicsError>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        system.acceleration_moore_penrose(self)
    }

    /// `q̈` from the explicit Gibbs–Appell system.
    pub fn acceleration_gibbs_appell<const K: usize, S>(
        &self,
        system: &S,
    ) -> Result<SVector<T, N>, GibbsAppellError>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        system.acceleration_gibbs_appell(self)
    }
}

/// Every generated system is a [`ConstrainedSystem`]: its inherent methods,
/// taking a [`State`], with non-finite values turned into `Err`.
impl<T, S, const N: usize, const K: usize> ConstrainedSystem<T, N, K> for S
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    const CONSTRAINT_LEVELS: [ConstraintLevel; K] = <S as Generated<T, N, K>>::CONSTRAINT_LEVELS;
    const REDUNDANCY: usize = K - <S as Generated<T, N, K>>::GENERIC_RANK;
    const SEMIDEFINITE_MASS: bool = <S as Generated<T, N, K>>::SEMIDEFINITE_MASS;

    forwarded_methods!(system_definitions);
    #[inline]
    fn acceleration(&self, s: &State<T, N>) -> Result<SVector<T, N>, DynamicsError> {
        finite(Generated::gauss_acceleration(self, &s.q, &s.qd, s.t, None))
    }
    #[inline]
    fn acceleration_moore_penrose(&self, s: &State<T, N>) -> Result<SVector<T, N>, DynamicsError> {
        finite(moore_penrose(self, &s.q, &s.qd, s.t))
    }
    #[inline]
    fn acceleration_corrected(
        &self,
        s: &State<T, N>,
        db: &SVector<T, K>,
    ) -> Result<SVector<T, N>, DynamicsError> {
        finite(Generated::gauss_acceleration(
            self,
            &s.q,
            &s.qd,
            s.t,
            Some(db),
        ))
    }
    #[inline]
    fn constraint_force(&self, s: &State<T, N>) -> Result<SVector<T, N>, DynamicsError> {
        finite(Generated::gauss(self, &s.q, &s.qd, s.t, None).map(|m| m.1))
    }
    #[inline]
    fn constraint_step(
        &self,
        s: &State<T, N>,
        r: &SVector<T, K>,
    ) -> Option<(SVector<T, N>, [bool; K])> {
        Generated::constraint_step(self, &s.q, &s.qd, s.t, r)
            .filter(|(step, _)| all_finite(step.as_slice()))
    }
}

/// The contract of the `Result` methods: a non-finite value is an `Err`
/// (the input was not finite, or the exact result is not representable).
#[inline]
fn finite<T: RealField + Copy, const N: usize>(
    value: Result<SVector<T, N>, DynamicsError>,
) -> Result<SVector<T, N>, DynamicsError> {
    match value {
        Ok(v) if !all_finite(v.as_slice()) => Err(DynamicsError::NonFinite),
        other => other,
    }
}

/// The finish of a row of `methods.rs` whose generated value is the trait's.
#[inline]
fn same<V>(value: V) -> V {
    value
}

/// `acceleration_gibbs_appell`'s finish: a non-finite `q̈` is
/// `Err(NonFinite)`.
#[inline]
fn finite_gibbs_appell<T: RealField + Copy, const N: usize>(
    value: Result<SVector<T, N>, GibbsAppellError>,
) -> Result<SVector<T, N>, GibbsAppellError> {
    match value {
        Ok(v) if !all_finite(v.as_slice()) => Err(GibbsAppellError::NonFinite),
        other => other,
    }
}

/// The finish of an optional vector (`gravity_forces`): a non-finite
/// entry is `Err(NonFinite)`.
#[inline]
fn finite_vector<T: RealField + Copy, const N: usize>(
    value: Option<Result<SVector<T, N>, DynamicsError>>,
) -> Option<Result<SVector<T, N>, DynamicsError>> {
    value.map(finite)
}

/// The finish of an optional scalar (the energies): a non-finite value is
/// `Err(NonFinite)`.
#[inline]
fn finite_scalar<T: RealField + Copy>(
    value: Option<Result<T, DynamicsError>>,
) -> Option<Result<T, DynamicsError>> {
    value.map(|v| match v {
        Ok(x) if !x.is_finite() => Err(DynamicsError::NonFinite),
        other => other,
    })
}
