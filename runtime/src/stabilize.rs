//! Control of constraint drift, opt-in.
//!
//! Integrating `A q̈ = b` keeps `φ̈` (or `φ̇`) at zero, not `φ` itself:
//! truncation and rounding errors make `φ` drift. Two remedies:
//!
//! - **Baumgarte stabilization** replaces the constraint equations by
//!   `φ̈ + 2α φ̇ + β² φ = 0` for position-level and `φ̇ + γ φ = 0` for
//!   velocity-level constraints, i.e. `A q̈ = b − 2α φ̇ − β² φ` (or
//!   `b − γ φ`): drift is damped, not removed; cheap, no iteration.
//! - **Projection** moves `q`, then `q̇`, back onto the constraints after
//!   each step with the `M`-weighted minimum-norm correction
//!   `Δ = −M⁻¹ Jᵀ (J M⁻¹ Jᵀ)^{1} r` — the same generalized inverse as the
//!   equation of motion, so redundant constraints are handled alike.
//!   Positions by Newton on the position-level constraints (`J = ∂φ/∂q`,
//!   their rows of `A`), velocities on every constraint at velocity level
//!   (`J = A`).

use crate::inverse::PivotedLdlt;
use crate::rank::consistency_tolerance;
use crate::{ConstrainedSystem, ConstraintLevel, DynamicsError, IntegrationError, State};
use nalgebra::{RealField, SMatrix, SVector};

/// How constraint drift is controlled during integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stabilization<T> {
    /// None: `A q̈ = b` as derived.
    None,
    /// Baumgarte: `A q̈ = b − 2α φ̇ − β² φ` (position level), `b − γ φ`
    /// (velocity level). `α`, `β`, `γ` have the units of a rate; about the
    /// inverse of the shortest time scale of interest is a common choice.
    Baumgarte {
        /// Damping of position-level drift.
        alpha: T,
        /// Stiffness of position-level drift.
        beta: T,
        /// Rate of decay of velocity-level drift.
        gamma: T,
    },
    /// Projection onto `φ = 0` and `φ̇ = 0` after every accepted step, by
    /// Newton with `M`-weighted minimum-norm steps, until the largest
    /// residual is at most `tolerance`.
    Projection {
        /// Largest residual accepted.
        tolerance: T,
        /// Newton iterations allowed for positions and for velocities.
        max_iterations: usize,
    },
}

impl<T: RealField + Copy> Stabilization<T> {
    /// Baumgarte with `α = β = γ = rate`: critically damped drift.
    pub fn baumgarte(rate: T) -> Self {
        Stabilization::Baumgarte {
            alpha: rate,
            beta: rate,
            gamma: rate,
        }
    }

    /// Projection to `tolerance`, with up to 10 Newton iterations.
    pub fn projection(tolerance: T) -> Self {
        Stabilization::Projection {
            tolerance,
            max_iterations: 10,
        }
    }
}

/// The Baumgarte correction `db` of `b`, or `None` when not asked for.
pub fn baumgarte_correction<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &State<T, N>,
    stabilization: &Stabilization<T>,
) -> Option<SVector<T, K>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    let Stabilization::Baumgarte { alpha, beta, gamma } = *stabilization else {
        return None;
    };
    let phi = system.constraint_residual(state);
    let phid = system.constraint_velocity_residual(state);
    let two = T::one() + T::one();
    let mut db = SVector::<T, K>::zeros();
    for (i, level) in S::CONSTRAINT_LEVELS.iter().enumerate() {
        db[i] = match level {
            ConstraintLevel::Position => -(two * alpha * phid[i] + beta * beta * phi[i]),
            ConstraintLevel::Velocity => -(gamma * phi[i]),
        };
    }
    Some(db)
}

/// Projects `state` onto the constraints (module docs). `Err` when `M` is
/// not positive definite or the residual does not fall to `tolerance`.
pub fn project<T, S, const N: usize, const K: usize>(
    system: &S,
    state: &mut State<T, N>,
    tolerance: T,
    max_iterations: usize,
) -> Result<(), IntegrationError<T>>
where
    T: RealField + Copy,
    S: ConstrainedSystem<T, N, K>,
{
    let dynamics = |error| IntegrationError::Dynamics { t: state.t, error };
    // The metric of the minimum-norm steps: M, or where M is only positive
    // semi-definite (a rigid body in quaternions) the auxiliary M + s AᵀA,
    // positive definite wherever [M; A] has full column rank.
    let m = system.mass_matrix(state);
    let chol = match nalgebra::linalg::Cholesky::new(m) {
        Some(chol) => chol,
        None => {
            let (a, _) = system.constraint_matrices(state);
            nalgebra::linalg::Cholesky::new(crate::generated::auxiliary_mass(&m, &a).0)
                .ok_or(dynamics(DynamicsError::MassNotPositiveDefinite))?
        }
    };
    let position = |i: usize| S::CONSTRAINT_LEVELS[i] == ConstraintLevel::Position;
    // Positions: Newton on the position-level rows only.
    newton(
        state,
        tolerance,
        max_iterations,
        |s| {
            let phi = system.constraint_residual(s);
            let (a, _) = system.constraint_matrices(s);
            let r = SVector::<T, K>::from_fn(|i, _| if position(i) { phi[i] } else { T::zero() });
            let j =
                SMatrix::<T, K, N>::from_fn(|i, c| if position(i) { a[(i, c)] } else { T::zero() });
            (r, j)
        },
        |s| s.q,
        |s, dx| s.q += dx,
        &chol,
    )?;
    // Velocities: every constraint at velocity level; Jacobian A.
    newton(
        state,
        tolerance,
        max_iterations,
        |s| {
            let (a, _) = system.constraint_matrices(s);
            (system.constraint_velocity_residual(s), a)
        },
        |s| s.qd,
        |s, dx| s.qd += dx,
        &chol,
    )
}

/// Newton with `M`-weighted minimum-norm steps on `residual(state) = 0`,
/// where `variables` are what the steps move (`q` or `q̇`).
///
/// Converged when every row is within `tolerance`, or when the rows still
/// above it are ones the rank decision dropped as dependent and each is at
/// its rounding floor: `|rᵢ| ≤ 1000 ε Σⱼ |Jᵢⱼ xⱼ|`. A row that is redundant
/// on the constraint surface is a consequence of the others there, so once
/// they hold its residual is what evaluating it in floating point leaves
/// (`(tip distance)² − d²` of a linkage 1000 units across: ~1e-9), which no
/// Newton step can reduce. A dropped row above that floor is a real
/// violation and keeps the projection from converging.
fn newton<T, const N: usize, const K: usize>(
    state: &mut State<T, N>,
    tolerance: T,
    max_iterations: usize,
    residual: impl Fn(&State<T, N>) -> (SVector<T, K>, SMatrix<T, K, N>),
    variables: impl Fn(&State<T, N>) -> SVector<T, N>,
    apply: impl Fn(&mut State<T, N>, SVector<T, N>),
    chol: &nalgebra::linalg::Cholesky<T, nalgebra::Const<N>>,
) -> Result<(), IntegrationError<T>>
where
    T: RealField + Copy,
{
    let floor = consistency_tolerance::<T>();
    for _ in 0..=max_iterations {
        let (r, j) = residual(state);
        let worst = r.amax();
        if worst <= tolerance {
            return Ok(());
        }
        if !worst.is_finite() {
            return Err(IntegrationError::NonFiniteState { t: state.t });
        }
        let minv_jt = chol.solve(&j.transpose());
        let ldlt = PivotedLdlt::new(&(j * minv_jt));
        let x = variables(state);
        let at_floor = |i: usize| {
            let scale = (0..N).fold(T::zero(), |acc, c| acc + (j[(i, c)] * x[c]).abs());
            !ldlt.is_kept(i) && r[i].abs() <= floor * scale
        };
        if (0..K).all(|i| r[i].abs() <= tolerance || at_floor(i)) {
            return Ok(());
        }
        let lambda = ldlt.solve(&r);
        apply(state, -(minv_jt * lambda));
    }
    let (r, _) = residual(state);
    Err(IntegrationError::ProjectionFailed {
        t: state.t,
        residual: r.amax(),
    })
}
