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
//! `Aᵀ λ = Q_c` has a unique solution when the rows are independent, found
//! from orthogonal factors of `Aᵀ` (Gram–Schmidt, twice). For a
//! redundant set (the rank rule of the solve: four feet on the ground, a
//! dependent closure) only `Aᵀ λ` is physical, and the minimum-norm `λ` is
//! returned: the pseudo-inverse, with singular values of `Aᵀ` at or below
//! `(N + K) · 64 ε` of the largest counted as zero (exact dependencies sit
//! at rounding level; genuine directions far above).
//!
//! Every generated system has `constraint_multipliers(&state)` and
//! `acceleration_and_multipliers(&state)` ([`Multipliers`]). Where the
//! generated solve kept every row (independent rows: the usual case), its
//! own `λ` — the multipliers of `S λ = r` it solved for `q̈` — is
//! returned as it is. For a redundant set whose solve factors
//! `S = A M⁻¹ Aᵀ` (`M⁻¹` known, or `M(q)` factored) and whose rank decision
//! stands, the generated solve returns the minimum-norm `λ` too, from the
//! factors of `S` (the solve's `λ` less its part in the null space of `S`,
//! which is that of `Aᵀ`). Otherwise (a saddle-point solve, a suspect rank
//! decision, the runtime's dense solve) `Aᵀ λ = Q_c` is solved by
//! [`multipliers`].
//! Two copies of the same row share the force equally:
//!
//! ```
//! use constrained_runtime::multipliers::multipliers;
//! use nalgebra::{Matrix2, Vector2};
//!
//! let a = Matrix2::new(1.0, 0.0, 1.0, 0.0); // the row x = 0, twice
//! let lambda = multipliers(&a, &Vector2::new(2.0, 0.0)).unwrap();
//! assert!((lambda - Vector2::new(1.0, 1.0)).norm() < 1e-15);
//! ```

use crate::generated::all_finite;
use crate::generated::{Generated, Reaction};
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
        let (qdd, lambda) = match Generated::gauss_multipliers(self, &s.q, &s.qd, s.t)? {
            // Every row kept by the generated solve: its λ is the one.
            (qdd, Reaction::Multipliers(lambda)) => (qdd, lambda),
            (qdd, Reaction::Force(force)) => {
                let (a, _) = Generated::constraint_matrices(self, &s.q, &s.qd, s.t);
                (qdd, multipliers(&a, &force)?)
            }
        };
        if all_finite(lambda.as_slice()) & all_finite(qdd.as_slice()) {
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
    if !a.iter().all(|x| x.is_finite()) {
        return Err(DynamicsError::NonFinite);
    }
    let count = nalgebra::convert::<f64, T>((N + K) as f64 * 64.0);
    // Independent rows, the usual case: the one solution, by orthogonal
    // factors of Aᵀ (no SVD, which costs the quadruped's 13 rows several
    // times what its q̈ costs).
    if let Some(lambda) = independent(a, force, count) {
        return Ok(lambda);
    }
    // A itself is decomposed (K columns of length N to orthogonalize, not
    // N of length K, N − K of which must be rotated down to zero): for the
    // quadruped (13 rows, 19 coordinates) an order of magnitude less work
    // than decomposing Aᵀ, with the same singular values and the same cut.
    let svd = JacobiSvd::new(a).ok_or(DynamicsError::NonFinite)?;
    let largest = svd.singular_values().amax();
    let cut = largest * T::default_epsilon() * count;
    svd.solve_transpose(force, cut)
        .ok_or(DynamicsError::NonFinite)
}

/// `λ` of `Aᵀ λ = force` when the rows of `A` are independent: `Aᵀ = Q R`
/// by Gram–Schmidt applied twice to each row (as accurate as Householder),
/// then `R λ = Qᵀ force`. `None` when a row's part independent of the rows
/// before it is at or below `count · ε · ‖A‖_F` (the SVD's cut, for which
/// `‖A‖_F ≥ σ_max`): the rows are dependent, and the minimum-norm `λ` is
/// the SVD's. A row of zeros counts as dependent.
fn independent<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    force: &SVector<T, N>,
    count: T,
) -> Option<SVector<T, K>> {
    if K > N {
        return None; // more rows than coordinates: dependent
    }
    let cut = a.norm() * T::default_epsilon() * count;
    let mut q: SMatrix<T, N, K> = a.transpose();
    let mut r = SMatrix::<T, K, K>::zeros();
    for j in 0..K {
        for _ in 0..2 {
            for i in 0..j {
                let d = q.column(i).dot(&q.column(j));
                r[(i, j)] += d;
                let qi = q.column(i).into_owned();
                q.column_mut(j).axpy(-d, &qi, T::one());
            }
        }
        let norm = q.column(j).norm();
        // Not `norm <= cut`: a NaN norm must not pass either.
        if norm.partial_cmp(&cut) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        r[(j, j)] = norm;
        q.column_mut(j).unscale_mut(norm);
    }
    let rhs = q.transpose() * force;
    let lambda = r.solve_upper_triangular(&rhs)?;
    lambda.iter().all(|x| x.is_finite()).then_some(lambda)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2x3, Vector2, Vector3};

    /// Independent rows: the Gram–Schmidt solution is the SVD's (the only
    /// one), to rounding; dependent rows fall to the SVD's minimum norm.
    #[test]
    fn independent_rows_match_the_svd_and_dependent_ones_use_it() {
        let a = Matrix2x3::new(1.0, 2.0, -0.5, 0.3, -1.0, 4.0);
        let lambda = Vector2::new(0.7, -2.5);
        let force = a.transpose() * lambda;
        let fast = independent(&a, &force, 320.0).unwrap();
        let svd = JacobiSvd::new(&a)
            .unwrap()
            .solve_transpose(&force, 1e-13)
            .unwrap();
        assert!((fast - lambda).amax() < 1e-14, "{fast}");
        assert!((fast - svd).amax() < 1e-14, "{fast} vs {svd}");
        assert_eq!(multipliers(&a, &force).unwrap(), fast);
        // The second row twice the first: dependent, shared by the SVD as
        // the minimum norm (λ₁ + 2 λ₂ = 5 at least norm: (1, 2)).
        let twice = Matrix2x3::new(1.0, 2.0, -0.5, 2.0, 4.0, -1.0);
        let f = Vector3::new(5.0, 10.0, -2.5);
        assert!(independent(&twice, &f, 320.0).is_none());
        let shared = multipliers(&twice, &f).unwrap();
        assert!((shared - Vector2::new(1.0, 2.0)).amax() < 1e-13, "{shared}");
    }
}
