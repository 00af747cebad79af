use crate::{ConstraintLevel, DynamicsError, GibbsAppellError, State};
use nalgebra::{RealField, SMatrix, SVector};

/// A constrained mechanical system with `N` coordinates and `K` constraints,
/// implemented by every struct that `constrained_system!` generates. The
/// methods are the generated ones, taking a [`State`].
pub trait ConstrainedSystem<T: RealField + Copy, const N: usize, const K: usize> {
    /// Whether each constraint is position level (differentiated twice) or
    /// velocity level (once).
    const CONSTRAINT_LEVELS: [ConstraintLevel; K];

    /// `M(q, t)`.
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N>;
    /// `F(q, q̇, t)`.
    fn forces(&self, state: &State<T, N>) -> SVector<T, N>;
    /// `φ(q, q̇, t)`.
    fn constraint_residual(&self, state: &State<T, N>) -> SVector<T, K>;
    /// The constraints at velocity level: `φ̇` for position-level rows, `φ`
    /// for velocity-level ones. Its Jacobian in `q̇` is `A`.
    fn constraint_velocity_residual(&self, state: &State<T, N>) -> SVector<T, K>;
    /// `(A, b)` of `A q̈ = b`.
    fn constraint_matrices(&self, state: &State<T, N>) -> (SMatrix<T, K, N>, SVector<T, K>);
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
    /// The explicit Gibbs–Appell system `(S, s)`, `S q̈ = s` (eq. 18 / 37).
    #[allow(clippy::type_complexity)]
    fn gibbs_appell_matrices(
        &self,
        state: &State<T, N>,
    ) -> Result<(SMatrix<T, N, N>, SVector<T, N>), GibbsAppellError>;
    /// `q̈` from the Gibbs–Appell system; equal to
    /// [`acceleration`](Self::acceleration) wherever both are defined.
    fn acceleration_gibbs_appell(
        &self,
        state: &State<T, N>,
    ) -> Result<SVector<T, N>, GibbsAppellError>;
}
