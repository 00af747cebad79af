//! Every tangent system at once, where `M` and `S = A M⁻¹ Aᵀ` were
//! factored with every row kept: from the two factorizations, the
//! constrained inverse `P = M⁻¹ − W S⁻¹ Wᵀ` and `Q = W S⁻¹` (`W = M⁻¹Aᵀ`)
//! once, then each column is two products with the column's nonzeros,
//!
//! ```text
//! q̈ᵥ = P F̃ᵥ + Q b̃ᵥ,   λᵥ = S⁻¹ b̃ᵥ − Qᵀ F̃ᵥ,
//! ```
//!
//! the tangent system `M q̈ᵥ = F̃ᵥ + Aᵀλᵥ`, `A q̈ᵥ = b̃ᵥ` solved (the
//! per-column solve of the parent module, regrouped). An auxiliary mass
//! `M + s AᵀA` adds `s Aᵀ b̃ᵥ` to `F̃ᵥ`: `P Aᵀ = W − W S⁻¹ S = 0` leaves
//! `q̈ᵥ` as it is, and `λᵥ` gains `−Qᵀ s Aᵀ b̃ᵥ = −s b̃ᵥ`.
//!
//! Why: one solve per column through both factorizations, fifty columns
//! for a free-floating quadruped, cost more than forming `P` and `Q` and
//! skipping the columns' zeros (most of `F̃` and `b̃` are: a leg's
//! coordinate moves its own foot's rows and the base's forces only).

use super::{Jacobians, MultiplierJacobians, Tangent};
use crate::inverse::PivotedLdlt;
use nalgebra::{RealField, SMatrix, SVector};

/// `P`, `Q` and `Qᵀ`, and `S⁻¹ − s I` (`s = 0` for a definite `M`).
pub(super) struct Projection<T: RealField + Copy, const N: usize, const K: usize> {
    p: SMatrix<T, N, N>,
    q: SMatrix<T, N, K>,
    qt: SMatrix<T, K, N>,
    g: SMatrix<T, K, K>,
}

impl<T: RealField + Copy, const N: usize, const K: usize> Projection<T, N, K> {
    /// From `M⁻¹`, `W = M⁻¹Aᵀ`, `S`'s factorization (every row kept) and
    /// the auxiliary mass's `s` (`None` for `M` itself).
    pub(super) fn new(
        inverse: &SMatrix<T, N, N>,
        w: &SMatrix<T, N, K>,
        ldlt: &PivotedLdlt<T, K>,
        auxiliary: Option<T>,
    ) -> Self {
        let mut g = ldlt.inverse_unchecked();
        let q = w * g;
        // `M⁻¹ − Q Wᵀ`, symmetric: each entry once.
        let mut p = *inverse;
        for j in 0..N {
            for i in j..N {
                let mut sum = T::zero();
                for r in 0..K {
                    sum += q[(i, r)] * w[(j, r)];
                }
                p[(i, j)] -= sum;
                if i != j {
                    p[(j, i)] = p[(i, j)];
                }
            }
        }
        if let Some(s) = auxiliary {
            for j in 0..K {
                g[(j, j)] -= s;
            }
        }
        Projection {
            p,
            q,
            qt: q.transpose(),
            g,
        }
    }

    /// `(q̈ᵥ, λᵥ)` from `F̃ᵥ` and `b̃ᵥ`, one product per nonzero entry;
    /// `λᵥ` left zero unless `multipliers`.
    fn apply(
        &self,
        f: impl Iterator<Item = T>,
        b: impl Iterator<Item = T>,
        multipliers: bool,
    ) -> (SVector<T, N>, SVector<T, K>) {
        let mut qdd = SVector::<T, N>::zeros();
        let mut lam = SVector::<T, K>::zeros();
        for (j, x) in f.enumerate() {
            if x != T::zero() {
                qdd.axpy(x, &self.p.column(j), T::one());
                if multipliers {
                    lam.axpy(-x, &self.qt.column(j), T::one());
                }
            }
        }
        for (j, x) in b.enumerate() {
            if x != T::zero() {
                qdd.axpy(x, &self.q.column(j), T::one());
                if multipliers {
                    lam.axpy(x, &self.g.column(j), T::one());
                }
            }
        }
        (qdd, lam)
    }

    /// The Jacobians of `q̈` and (where `multipliers`, else zeros) `λ` at
    /// `(q, q̇, t)` with `q̈` and `λ`: the right-hand sides `F̃`, `b̃` of
    /// every column, each column through [`Projection::apply`].
    pub(super) fn jacobians<S, const NU: usize, const D: usize>(
        &self,
        system: &S,
        (q, qd, t): (&SVector<T, N>, &SVector<T, N>, T),
        (qdd, lam): (&SVector<T, N>, &SVector<T, K>),
        multipliers: bool,
    ) -> (Jacobians<T, N, NU>, MultiplierJacobians<T, N, K, NU>)
    where
        S: Tangent<T, N, K, D>,
    {
        let mut f_tilde = SMatrix::<T, N, D>::zeros();
        let mut b_tilde = SMatrix::<T, K, D>::zeros();
        system.tangent_rhs(q, qd, t, qdd, lam, &mut f_tilde, &mut b_tilde);
        let mut accelerations = Jacobians::<T, N, NU>::zeros();
        let mut lambdas = MultiplierJacobians::<T, N, K, NU>::zeros();
        for c in 0..D {
            let (x, y) = self.apply(
                f_tilde.column(c).iter().copied(),
                b_tilde.column(c).iter().copied(),
                multipliers,
            );
            if c < N {
                accelerations.dq.set_column(c, &x);
                lambdas.dq.set_column(c, &y);
            } else if c < 2 * N {
                accelerations.dqd.set_column(c - N, &x);
                lambdas.dqd.set_column(c - N, &y);
            } else {
                accelerations.du.set_column(c - 2 * N, &x);
                lambdas.du.set_column(c - 2 * N, &y);
            }
        }
        (accelerations, lambdas)
    }
}

/// `L⁻¹` of a lower-triangular `L` with a nonzero diagonal (a Cholesky
/// factor's), column by column by forward substitution.
pub(super) fn lower_inverse<T: RealField + Copy, const N: usize>(
    l: &SMatrix<T, N, N>,
) -> SMatrix<T, N, N> {
    let mut x = SMatrix::<T, N, N>::zeros();
    for j in 0..N {
        x[(j, j)] = T::one() / l[(j, j)];
        for i in j + 1..N {
            let mut sum = T::zero();
            for k in j..i {
                sum += l[(i, k)] * x[(k, j)];
            }
            x[(i, j)] = -sum / l[(i, i)];
        }
    }
    x
}

/// `XᵀX` of a lower-triangular `X` (`M⁻¹ = L⁻ᵀL⁻¹`), each entry of the
/// symmetric result once: `(XᵀX)ᵢⱼ = Σ_{k ≥ max(i, j)} Xₖᵢ Xₖⱼ`.
pub(super) fn lower_gram<T: RealField + Copy, const N: usize>(
    x: &SMatrix<T, N, N>,
) -> SMatrix<T, N, N> {
    let mut out = SMatrix::<T, N, N>::zeros();
    for j in 0..N {
        for i in j..N {
            let mut sum = T::zero();
            for k in i..N {
                sum += x[(k, i)] * x[(k, j)];
            }
            out[(i, j)] = sum;
            out[(j, i)] = sum;
        }
    }
    out
}

/// `B Aᵀ`, one column of `B` per nonzero entry of `A` (a contact row
/// touches the base and its own leg: half of `A` is zeros).
pub(super) fn times_transpose<T: RealField + Copy, const N: usize, const K: usize>(
    b: &SMatrix<T, N, N>,
    a: &SMatrix<T, K, N>,
) -> SMatrix<T, N, K> {
    let mut out = SMatrix::<T, N, K>::zeros();
    for r in 0..K {
        for j in 0..N {
            let x = a[(r, j)];
            if x != T::zero() {
                out.column_mut(r).axpy(x, &b.column(j), T::one());
            }
        }
    }
    out
}

/// `A W` for `W = M⁻¹Aᵀ` (symmetric), each entry once and over the
/// nonzero entries of `A`'s row only.
pub(super) fn gram<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    w: &SMatrix<T, N, K>,
) -> SMatrix<T, K, K> {
    let mut out = SMatrix::<T, K, K>::zeros();
    for r in 0..K {
        for c in r..K {
            let mut sum = T::zero();
            for j in 0..N {
                let x = a[(r, j)];
                if x != T::zero() {
                    sum += x * w[(j, c)];
                }
            }
            out[(r, c)] = sum;
            out[(c, r)] = sum;
        }
    }
    out
}
