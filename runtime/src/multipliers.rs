//! The constraint multipliers `λ`: the force each constraint row exerts.
//!
//! Sign convention: the generalized constraint force is `Q_c = Aᵀ λ`
//! (`M q̈ = F + Q_c`, [`constraint_force`](crate::ConstrainedSystem::constraint_force)),
//! `A` the matrix of `A q̈ = b`, whose row `i` is `∂φ̇ᵢ/∂q̇`. For a row
//! `φ = pₖ(q) − c` (a component of a point of a body, `position(foot,
//! [..]).z == 0.0`), `Aᵢ = ∂pₖ/∂q` and `λᵢ` is the `k`-th world component of
//! the force the constraint applies *to the body at that point*: a foot
//! pressed on the ground by gravity has `λ_z > 0`, and `λ_z < 0` is the
//! ground pulling (a unilateral contact about to lift off). The three rows
//! of `position(a, [..]) == position(b, [..])` give the force on `a`'s
//! point (and `−λ` on `b`'s). A row written the other way round
//! (`c − pₖ`) flips its sign. The three rows of an orientation lock,
//! `orientation(a) == orientation(b)` or `== [roll, pitch, yaw]`, give the
//! torque the lock exerts on `a` in world axes (`−λ` on `b`): their time
//! derivative on the lock is `ω_a − ω_b`. A lock written by hand on
//! quaternion or angle coordinates gives a generalized force on those
//! coordinates instead.
//!
//! `Aᵀ λ = Q_c` has a unique solution when the rows are independent. For a
//! redundant set (the rank rule of the solve: four feet on the ground, a
//! dependent closure) only `Aᵀ λ` is physical, and the minimum-norm `λ` is
//! returned: the pseudo-inverse, with singular values of `Aᵀ` at or below
//! `(N + K) · 64 ε` of the largest counted as zero (exact dependencies sit
//! at rounding level; genuine directions far above).
//!
//! Every generated system has `constraint_multipliers(&state)` and
//! `acceleration_and_multipliers(&state)` ([`Multipliers`]); the solve of
//! `Aᵀ λ = Q_c` is [`multipliers`]. Two copies of the same row share the
//! force equally:
//!
//! ```
//! use constrained_runtime::multipliers::multipliers;
//! use nalgebra::{Matrix2, Vector2};
//!
//! let a = Matrix2::new(1.0, 0.0, 1.0, 0.0); // the row x = 0, twice
//! let lambda = multipliers(&a, &Vector2::new(2.0, 0.0)).unwrap();
//! assert!((lambda - Vector2::new(1.0, 1.0)).norm() < 1e-15);
//! ```

use crate::generated::Generated;
use crate::svd::JacobiSvd;
use crate::{DynamicsError, State};
use nalgebra::{RealField, SMatrix, SVector};

/// The multipliers of every generated system (blanket implementation).
pub trait Multipliers<T: RealField + Copy, const N: usize, const K: usize> {
    /// `λ` with `Aᵀ λ = M q̈ − F` (module docs: sign convention, minimum
    /// norm for a redundant set). `Err` where the acceleration is, or when
    /// `A` is not finite.
    fn constraint_multipliers(&self, state: &State<T, N>) -> Result<SVector<T, K>, DynamicsError>;

    /// `q̈` and `λ` from one solve.
    fn acceleration_and_multipliers(
        &self,
        state: &State<T, N>,
    ) -> Result<(SVector<T, N>, SVector<T, K>), DynamicsError>;
}

impl<T, S, const N: usize, const K: usize> Multipliers<T, N, K> for S
where
    T: RealField + Copy,
    S: Generated<T, N, K>,
{
    fn constraint_multipliers(&self, state: &State<T, N>) -> Result<SVector<T, K>, DynamicsError> {
        self.acceleration_and_multipliers(state).map(|m| m.1)
    }

    fn acceleration_and_multipliers(
        &self,
        s: &State<T, N>,
    ) -> Result<(SVector<T, N>, SVector<T, K>), DynamicsError> {
        let (qdd, force) = Generated::gauss(self, &s.q, &s.qd, s.t, None)?;
        let (a, _) = Generated::constraint_matrices(self, &s.q, &s.qd, s.t);
        let lambda = multipliers(&a, &force)?;
        if qdd.iter().all(|x| x.is_finite()) {
            Ok((qdd, lambda))
        } else {
            Err(DynamicsError::NonFinite)
        }
    }
}

/// The minimum-norm `λ` of `Aᵀ λ = force` (module docs).
pub fn multipliers<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    force: &SVector<T, N>,
) -> Result<SVector<T, K>, DynamicsError> {
    // A itself is decomposed (K columns of length N to orthogonalize, not
    // N of length K, N − K of which must be rotated down to zero): the
    // quadruped's q̈ and λ (13 rows, 19 coordinates) took 934 µs before, 82
    // µs after (the first wall time, the second CPU time, on a loaded
    // machine; q̈ alone is 24 µs); the same singular values, the same cut.
    let svd = JacobiSvd::new(a).ok_or(DynamicsError::NonFinite)?;
    let largest = svd.singular_values().amax();
    let count = nalgebra::convert::<f64, T>((N + K) as f64 * 64.0);
    let cut = largest * T::default_epsilon() * count;
    svd.solve_transpose(force, cut)
        .ok_or(DynamicsError::NonFinite)
}
