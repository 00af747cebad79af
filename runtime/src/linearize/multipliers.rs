//! The Jacobians of the constraint multipliers `λ(q, q̇, u)`
//! (`constraint_multipliers`): the tangent systems of the parent module
//! give them beside those of `q̈`. Differentiating `M q̈ = F + Aᵀλ`,
//! `A q̈ = b` by one variable `v`,
//!
//! ```text
//! M q̈ᵥ = F̃ᵥ + Aᵀλᵥ,   A q̈ᵥ = b̃ᵥ,
//! ```
//!
//! so `λᵥ = S⁻¹ (b̃ᵥ − A M⁻¹ F̃ᵥ)`, `S = A M⁻¹ Aᵀ`: the tangent system's own
//! multipliers. They are `λ`'s derivative where the rows are independent,
//! and `λ` is unique (what `constraint_multipliers` returns there). For a
//! dependent set only `Aᵀλ` is physical: the minimum-norm `λ` that
//! `constraint_multipliers` returns is one choice among many, and its
//! derivative is not given (`Err(NotDifferentiable)`). A semi-definite `M`
//! is solved through its auxiliary mass `M + s AᵀA`, whose multipliers
//! are the same: `s AᵀA q̈ = s Aᵀ b` holds on both sides.

use super::batch::Projection;
use super::{Dense, Jacobians, Tangent};
use crate::generated::all_finite;
use crate::generated::{Generated, Motion};
use crate::rank::safe_minimum;
use crate::DynamicsError;
use nalgebra::{RealField, SMatrix, SVector};

/// The Jacobians of `λ(q, q̇, u)`, `K` rows each: `dq = ∂λ/∂q`,
/// `dqd = ∂λ/∂q̇`, `du = ∂λ/∂u`, column `j` the derivative by the `j`-th
/// coordinate, velocity or input (the sign convention of
/// [`crate::multipliers`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MultiplierJacobians<T, const N: usize, const K: usize, const NU: usize> {
    /// `∂λ/∂q`.
    pub dq: SMatrix<T, K, N>,
    /// `∂λ/∂q̇`.
    pub dqd: SMatrix<T, K, N>,
    /// `∂λ/∂u`.
    pub du: SMatrix<T, K, NU>,
}

impl<T: RealField + Copy, const N: usize, const K: usize, const NU: usize>
    MultiplierJacobians<T, N, K, NU>
{
    /// All three Jacobians zero.
    #[must_use]
    pub fn zeros() -> Self {
        MultiplierJacobians {
            dq: SMatrix::zeros(),
            dqd: SMatrix::zeros(),
            du: SMatrix::zeros(),
        }
    }

    /// Whether every entry is finite.
    // Always inlined: the generated Jacobians end in this check, and
    // inlined into their AVX copies it runs on four entries a vector.
    #[must_use]
    #[inline(always)]
    pub fn is_finite(&self) -> bool {
        all_finite(self.dq.as_slice())
            & all_finite(self.dqd.as_slice())
            & all_finite(self.du.as_slice())
    }
}

/// The Jacobians of `λ` at `(q, q̇, t)`, given the motion `(q̈, Fᶜ)` the
/// system's solver returned there: [`try_acceleration_and_multiplier_jacobians`]'s
/// second. Called by the generated `multiplier_jacobian`.
///
/// # Errors
///
/// As [`try_acceleration_and_multiplier_jacobians`].
pub fn try_multiplier_jacobian<
    T,
    S,
    const N: usize,
    const K: usize,
    const NU: usize,
    const D: usize,
>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    motion: Motion<T, N>,
) -> Result<MultiplierJacobians<T, N, K, NU>, DynamicsError>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    try_acceleration_and_multiplier_jacobians::<T, S, N, K, NU, D>(system, q, qd, t, motion)
        .map(|(_, multipliers)| multipliers)
}

/// The Jacobians of `q̈` and of `λ` at `(q, q̇, t)`, given the motion
/// `(q̈, Fᶜ)` the system's solver returned there, from one evaluation of
/// the tangent systems: `M` factored (Cholesky, or the rank-revealing
/// `LDLᵀ` where it is not numerically positive definite), `S = A M⁻¹ Aᵀ` by
/// the pivoted `LDLᵀ` once, then for each column both
/// `λᵥ = S⁻¹(b̃ᵥ − A M⁻¹F̃ᵥ)` and `q̈ᵥ = M⁻¹(F̃ᵥ + Aᵀλᵥ)`, regrouped as two
/// products with the column's nonzeros (`super::batch`). Called by the
/// generated `acceleration_and_multiplier_jacobians`; `D = 2N + NU`
/// columns.
///
/// # Errors
///
/// `Err(NotDifferentiable)` where the rows are not independent to the
/// rank rule of `acceleration` (a redundant set, or a state where a row
/// has lost rank): `λ` is then not unique (module docs). `Err(NonFinite)`
/// where `M` or `A` is not finite or has lost its digits to underflow, or
/// an entry of the result overflows.
#[allow(clippy::many_single_char_names, clippy::type_complexity)]
pub fn try_acceleration_and_multiplier_jacobians<
    T,
    S,
    const N: usize,
    const K: usize,
    const NU: usize,
    const D: usize,
>(
    system: &S,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    t: T,
    motion: Motion<T, N>,
) -> Result<(Jacobians<T, N, NU>, MultiplierJacobians<T, N, K, NU>), DynamicsError>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    const { assert!(D == 2 * N + NU, "D = 2N + NU columns") };
    let (qdd, force) = motion;
    let dense: Dense<T, N, K> = Dense::new(system, q, qd, t)?;
    if !dense.m.iter().chain(dense.a.iter()).all(|x| x.is_finite()) {
        return Err(DynamicsError::NonFinite);
    }
    let underflow = dense.gram.diagonal().iter().any(|&x| x < safe_minimum());
    if underflow || dense.ldlt.rank() < K {
        return Err(DynamicsError::NotDifferentiable);
    }
    let (w, s, ldlt) = (dense.w, dense.s, &dense.ldlt);
    // λ with Aᵀλ = Fᶜ: S λ = A M⁻¹ Fᶜ = Wᵀ Fᶜ.
    let lam = ldlt.solve_unchecked(&(w.transpose() * force));
    let auxiliary = S::SEMIDEFINITE_MASS.then_some(s);
    let projection = Projection::new(&dense.inverse, &w, ldlt, auxiliary);
    let (accelerations, lambdas) =
        projection.jacobians::<S, NU, D>(system, (q, qd, t), (&qdd, &lam), true);
    if accelerations.is_finite() && lambdas.is_finite() {
        Ok((accelerations, lambdas))
    } else {
        Err(DynamicsError::NonFinite)
    }
}
