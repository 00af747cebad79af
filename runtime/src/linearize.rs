//! Linearization: the exact Jacobians of `q̈(q, q̇, u)`, the linear model
//! `δẋ = A δx + B δu` in all coordinates, and the reduced one on the
//! constraint manifold.
//!
//! # The tangent systems
//!
//! `q̈` solves `M q̈ = F + Aᵀλ`, `A q̈ = b`. Differentiating both by one
//! variable `v` (a coordinate, a velocity or an input) gives the same
//! constrained system for `q̈ᵥ = ∂q̈/∂v`:
//!
//! ```text
//! M q̈ᵥ = F̃ᵥ + Aᵀλᵥ,   A q̈ᵥ = b̃ᵥ,
//! F̃ᵥ = ∂F/∂v − (∂M/∂v) q̈ + (∂A/∂v)ᵀ λ,   b̃ᵥ = ∂b/∂v − (∂A/∂v) q̈.
//! ```
//!
//! The macro differentiates `F`, `M`, `A` and `b` symbolically at compile
//! time and emits `F̃`, `b̃` for every column (`tangent_rhs`); here `M` and
//! `S = A M⁻¹ Aᵀ` are factored once (Cholesky; the rank-revealing
//! [`PivotedLdlt`] of `S` with the rank rule of `acceleration`) and every
//! column is one solve: `q̈ᵥ = M⁻¹F̃ᵥ + M⁻¹Aᵀ S⁺(b̃ᵥ − A M⁻¹F̃ᵥ)`. Nothing is
//! differenced.
//!
//! `λ` is recovered from the constraint force the solver returned,
//! `λ = S⁺ A M⁻¹ Fᶜ`; any `λ` with `Aᵀλ = Fᶜ` gives the same `q̈ᵥ` (the
//! difference lies in the null space of `Aᵀ`, which the solve projects
//! out), so redundant constraints behave. Where the rank decision drops
//! rows of a consistent `A`, the result is the Jacobian of the `q̈`
//! actually returned: the minimiser over the rows kept, whose tangent
//! system is solved with the same {1}-inverse. A semi-definite `M` is
//! solved through its auxiliary mass `M + s AᵀA`, whose tangent system
//! is the one above with `F̃ᵥ + s Aᵀ b̃ᵥ` (the `∂s` terms multiply
//! `A q̈ − b = 0`).

use crate::generated::{auxiliary_mass, Generated, Motion};
use crate::inverse::PivotedLdlt;
use nalgebra::{Cholesky, Const, RealField, SMatrix, SVector};

/// The Jacobians of `q̈(q, q̇, u)`: `dq = ∂q̈/∂q`, `dqd = ∂q̈/∂q̇`,
/// `du = ∂q̈/∂u`, column `j` the derivative by the `j`-th coordinate,
/// velocity or input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jacobians<T, const N: usize, const NU: usize> {
    /// `∂q̈/∂q`.
    pub dq: SMatrix<T, N, N>,
    /// `∂q̈/∂q̇`.
    pub dqd: SMatrix<T, N, N>,
    /// `∂q̈/∂u`.
    pub du: SMatrix<T, N, NU>,
}

impl<T: RealField + Copy, const N: usize, const NU: usize> Jacobians<T, N, NU> {
    /// Whether every entry is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.dq
            .iter()
            .chain(self.dqd.iter())
            .chain(self.du.iter())
            .all(|x| x.is_finite())
    }
}

/// What the generated code provides for the Jacobian: the right-hand sides
/// of the tangent systems. Implemented by `constrained_system!`.
#[doc(hidden)]
pub trait Tangent<T: RealField + Copy, const N: usize, const K: usize, const D: usize> {
    /// `(F̃, b̃)`, one column per variable: coordinates, velocities, inputs.
    #[allow(clippy::type_complexity)]
    fn tangent_rhs(
        &self,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        t: T,
        qdd: &SVector<T, N>,
        lam: &SVector<T, K>,
    ) -> (SMatrix<T, N, D>, SMatrix<T, K, D>);
}

/// `M⁻¹` applied by Cholesky, or, where `M` is not numerically positive
/// definite (possible only for states where `acceleration` already
/// answered by other means), by the rank-revealing `LDLᵀ`.
enum MassSolve<T: RealField + Copy, const N: usize> {
    Cholesky(Cholesky<T, Const<N>>),
    Ldlt(PivotedLdlt<T, N>),
}

impl<T: RealField + Copy, const N: usize> MassSolve<T, N> {
    fn new(m: SMatrix<T, N, N>) -> Self {
        match Cholesky::new(m) {
            Some(c) => MassSolve::Cholesky(c),
            None => MassSolve::Ldlt(PivotedLdlt::new(&m)),
        }
    }

    fn solve(&self, v: &SVector<T, N>) -> SVector<T, N> {
        match self {
            MassSolve::Cholesky(c) => c.solve(v),
            MassSolve::Ldlt(l) => l.solve(v),
        }
    }
}

/// The Jacobians of `q̈` at `(q, q̇, t)`, given the motion `(q̈, Fᶜ)` the
/// system's solver returned there. Called by the generated
/// `acceleration_jacobian`; `D = 2N + NU` columns.
#[allow(clippy::many_single_char_names)]
pub fn acceleration_jacobian<
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
) -> Jacobians<T, N, NU>
where
    T: RealField + Copy,
    S: Generated<T, N, K> + Tangent<T, N, K, D>,
{
    const { assert!(D == 2 * N + NU, "D = 2N + NU columns") };
    let (qdd, force) = motion;
    let (a, _) = system.constraint_matrices(q, qd, t);
    let m = system.mass_matrix(q, t);
    let (m, s) = if S::SEMIDEFINITE_MASS {
        auxiliary_mass(&m, &a)
    } else {
        (m, T::one())
    };
    let mass = MassSolve::new(m);
    // W = M⁻¹ Aᵀ, S = A W, one factorization of each.
    let mut w = SMatrix::<T, N, K>::zeros();
    for r in 0..K {
        let column = mass.solve(&a.row(r).transpose());
        w.set_column(r, &column);
    }
    let gram = a * w;
    let ldlt = PivotedLdlt::new(&gram);
    // λ with Aᵀλ = Fᶜ: S λ = A M⁻¹ Fᶜ = Wᵀ Fᶜ.
    let lam = ldlt.solve(&(w.transpose() * force));
    let (f_tilde, b_tilde) = system.tangent_rhs(q, qd, t, &qdd, &lam);
    let mut jac = Jacobians {
        dq: SMatrix::<T, N, N>::zeros(),
        dqd: SMatrix::<T, N, N>::zeros(),
        du: SMatrix::<T, N, NU>::zeros(),
    };
    for c in 0..D {
        let b_c: SVector<T, K> = b_tilde.column(c).into_owned();
        let mut f_c: SVector<T, N> = f_tilde.column(c).into_owned();
        if S::SEMIDEFINITE_MASS {
            f_c += a.transpose() * (b_c * s);
        }
        let unconstrained = mass.solve(&f_c);
        let mu = ldlt.solve(&(b_c - a * unconstrained));
        let dqdd = unconstrained + w * mu;
        if c < N {
            jac.dq.set_column(c, &dqdd);
        } else if c < 2 * N {
            jac.dqd.set_column(c - N, &dqdd);
        } else {
            jac.du.set_column(c - 2 * N, &dqdd);
        }
    }
    jac
}

/// `(A, B)` of `δẋ = A δx + B δu` for `x = (q, q̇)`:
/// `A = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]`, `B = [[0], [∂q̈/∂u]]`. `N2 = 2N`.
#[must_use]
pub fn linearization<T: RealField + Copy, const N: usize, const NU: usize, const N2: usize>(
    j: &Jacobians<T, N, NU>,
) -> (SMatrix<T, N2, N2>, SMatrix<T, N2, NU>) {
    const { assert!(N2 == 2 * N, "N2 = 2N") };
    let mut a = SMatrix::<T, N2, N2>::zeros();
    let mut b = SMatrix::<T, N2, NU>::zeros();
    for i in 0..N {
        a[(i, N + i)] = T::one();
        for c in 0..N {
            a[(N + i, c)] = j.dq[(i, c)];
            a[(N + i, N + c)] = j.dqd[(i, c)];
        }
        for c in 0..NU {
            b[(N + i, c)] = j.du[(i, c)];
        }
    }
    (a, b)
}
