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
//!
//! A redundant model's positions are taken one Newton step past the
//! tolerance, to rounding level. Its dependent rows are consequences of the
//! others, and amplified ones: a position left at the tolerance puts the
//! state that far off the surface, where a redundant row is weakly
//! independent, and its *velocity* residual, `(Aᵣ − Σ cᵢ Aᵢ) q̇`, then grows
//! with `|q̇|` and the distance, beyond the tolerance, where no velocity step
//! can reduce it (the four-bar in link angles with a distance closure:
//! `ProjectionFailed { residual: 3.7e-12 }` at a tolerance of 1e-12, its
//! positions within 5e-13 of the loop closures).

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
///
/// Each Newton step is the generated one (`W S⁺ r` through the
/// factorizations `acceleration` uses, O(n) for a chain) where the system
/// has it, and a dense one (Cholesky of `M`, pivoted `LDLᵀ` of `J M⁻¹ Jᵀ`)
/// where it does not: a singular `M`, a suspect rank decision, and the
/// positions of a system with velocity-level constraints (whose position
/// step must leave those rows out of `S`).
///
/// Never inlined: it runs once per step, and inlined into an integrator's
/// loop its code (two Newton solves, a generated factorization and a dense
/// fallback) crowds out the four accelerations of an RK4 step, and plain
/// steps, which never call it, slow down by half.
#[inline(never)]
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
    let position = |i: usize| S::CONSTRAINT_LEVELS[i] == ConstraintLevel::Position;
    let all_position = (0..K).all(position);
    let mut metric = DenseMetric { cholesky: None };
    // Positions: Newton on the position-level rows only.
    let position_rows = |s: &State<T, N>| {
        let (a, _) = system.constraint_matrices(s);
        SMatrix::<T, K, N>::from_fn(|i, c| if position(i) { a[(i, c)] } else { T::zero() })
    };
    // A redundant model's positions go to rounding level (module docs).
    let redundant = S::REDUNDANCY > 0;
    newton(
        state,
        tolerance,
        max_iterations,
        redundant,
        |s| {
            let phi = system.constraint_residual(s);
            SVector::<T, K>::from_fn(|i, _| if position(i) { phi[i] } else { T::zero() })
        },
        position_rows,
        |s, r| {
            let generated = if all_position {
                system.constraint_step(s, r)
            } else {
                None
            };
            match generated {
                Some(step) => Ok(step),
                None => metric.step(system, s, r, &position_rows(s)),
            }
        },
        |s| s.q,
        |s, dx| s.q -= dx,
    )?;
    // Velocities: every constraint at velocity level; Jacobian A.
    let all_rows = |s: &State<T, N>| system.constraint_matrices(s).0;
    newton(
        state,
        tolerance,
        max_iterations,
        false,
        |s| system.constraint_velocity_residual(s),
        all_rows,
        |s, r| match system.constraint_step(s, r) {
            Some(step) => Ok(step),
            None => metric.step(system, s, r, &all_rows(s)),
        },
        |s| s.qd,
        |s, dx| s.qd -= dx,
    )
}

/// The metric of the dense steps, factored when first needed: `M`, or
/// where `M` is only positive semi-definite (a rigid body in quaternions;
/// or `M` fails to factor) the auxiliary `M + s AᵀA`, positive definite
/// wherever `[M; A]` has full column rank. A semi-definite `M` is never
/// factored itself: its Cholesky factorization can succeed by rounding,
/// with a pivot at rounding level along the singular direction, and the
/// steps in that metric are noise there (a Newton iteration that stalls
/// above the tolerance). One for both phases of a projection (positions,
/// velocities), each of whose dense steps solves in it.
struct DenseMetric<T: RealField, const N: usize> {
    cholesky: Option<nalgebra::linalg::Cholesky<T, nalgebra::Const<N>>>,
}

impl<T: RealField + Copy, const N: usize> DenseMetric<T, N> {
    /// The dense Newton step `M⁻¹Jᵀ (J M⁻¹ Jᵀ)⁺ r` at `s` for the rows `j`,
    /// and the rows the rank rule kept (the metric factored at `s` if this
    /// is the first).
    fn step<S, const K: usize>(
        &mut self,
        system: &S,
        s: &State<T, N>,
        r: &SVector<T, K>,
        j: &SMatrix<T, K, N>,
    ) -> Result<(SVector<T, N>, [bool; K]), IntegrationError<T>>
    where
        S: ConstrainedSystem<T, N, K>,
    {
        if self.cholesky.is_none() {
            let m = system.mass_matrix(s);
            let own = if S::SEMIDEFINITE_MASS {
                None
            } else {
                nalgebra::linalg::Cholesky::new(m)
            };
            self.cholesky = match own {
                Some(chol) => Some(chol),
                None => {
                    let (a, _) = system.constraint_matrices(s);
                    nalgebra::linalg::Cholesky::new(crate::generated::auxiliary_mass(&m, &a).0)
                }
            };
        }
        let chol = self.cholesky.as_ref().ok_or(IntegrationError::Dynamics {
            t: s.t,
            error: DynamicsError::MassNotPositiveDefinite,
        })?;
        let minv_jt = chol.solve(&j.transpose());
        let ldlt = PivotedLdlt::factor(&(j * minv_jt));
        let kept: [bool; K] = core::array::from_fn(|i| ldlt.is_kept(i));
        Ok((minv_jt * ldlt.solve_unchecked(r), kept))
    }
}

/// Newton with `M`-weighted minimum-norm steps on `residual(state) = 0`:
/// `step` gives `M⁻¹Jᵀ (J M⁻¹ Jᵀ)⁺ r` and the rows its rank rule kept,
/// `jacobian` is `J` (for the floor below), `variables` are what the steps
/// move (`q` or `q̇`). With `past_tolerance`, one more step is taken once
/// every row is within the tolerance (unless the residual is already
/// zero), which takes a Newton iteration from the tolerance to rounding
/// level.
///
/// Converged when every row is within `tolerance`, or when the rows still
/// above it are ones the rank decision dropped as dependent and each is at
/// its rounding floor: `|rᵢ| ≤ 1000 ε Σⱼ |Jᵢⱼ xⱼ|`. A row that is redundant
/// on the constraint surface is a consequence of the others there, so once
/// they hold its residual is what evaluating it in floating point leaves
/// (`(tip distance)² − d²` of a linkage 1000 units across: ~1e-9), which no
/// Newton step can reduce. A dropped row above that floor is a real
/// violation and keeps the projection from converging.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn newton<T, const N: usize, const K: usize>(
    state: &mut State<T, N>,
    tolerance: T,
    max_iterations: usize,
    past_tolerance: bool,
    residual: impl Fn(&State<T, N>) -> SVector<T, K>,
    jacobian: impl Fn(&State<T, N>) -> SMatrix<T, K, N>,
    mut step: impl FnMut(
        &State<T, N>,
        &SVector<T, K>,
    ) -> Result<(SVector<T, N>, [bool; K]), IntegrationError<T>>,
    variables: impl Fn(&State<T, N>) -> SVector<T, N>,
    apply: impl Fn(&mut State<T, N>, SVector<T, N>),
) -> Result<(), IntegrationError<T>>
where
    T: RealField + Copy,
{
    let floor = consistency_tolerance::<T>();
    for _ in 0..=max_iterations {
        let r = residual(state);
        let worst = r.amax();
        if worst <= tolerance {
            if !past_tolerance || worst == T::zero() {
                return Ok(());
            }
            // Within the tolerance: one step to rounding level, kept only
            // if it does not leave the tolerance (it cannot, but a wild
            // step is not taken on trust).
            let (dx, _) = step(state, &r)?;
            let before = *state;
            apply(state, dx);
            let within = residual(state).amax() <= tolerance;
            if !within {
                *state = before;
            }
            return Ok(());
        }
        if !worst.is_finite() {
            return Err(IntegrationError::NonFiniteState { t: state.t });
        }
        let (dx, kept) = step(state, &r)?;
        // Only rows the rank rule dropped can be at their floor.
        if (0..K).all(|i| r[i].abs() <= tolerance || !kept[i]) {
            let j = jacobian(state);
            let x = variables(state);
            let at_floor = |i: usize| {
                let scale = (0..N).fold(T::zero(), |acc, c| acc + (j[(i, c)] * x[c]).abs());
                r[i].abs() <= floor * scale
            };
            if (0..K).all(|i| r[i].abs() <= tolerance || at_floor(i)) {
                return Ok(());
            }
        }
        apply(state, dx);
    }
    let r = residual(state);
    Err(IntegrationError::ProjectionFailed {
        t: state.t,
        residual: r.amax(),
    })
}
