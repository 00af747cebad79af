//! Generalized inverses for fixed sizes, without allocation.
//!
//! Gauss's principle gives `q̈ = a + M⁻¹ Aᵀ λ` with `S λ = r`, where
//! `S = A M⁻¹ Aᵀ` and `r = b − A a` (Udwadia & Kalaba, eq. 26). When the constraints
//! are redundant `S` is singular and any {1}-inverse of `S` gives the same
//! `q̈` on a consistent state; [`PivotedLdlt`] builds one.
//!
//! # The rank tolerance
//! `S` is the Gram matrix of the rows `wᵢ = M^{-1/2} aᵢ`, so the `LDLᵀ` pivot
//! `dⱼ` of row `j` is `|wⱼ|² sin²θⱼ`, where `θⱼ` is the angle between `wⱼ` and
//! the span of the rows already eliminated. A row is treated as dependent
//! when `sin²θⱼ = dⱼ / Sⱼⱼ` falls below [`rank_tolerance`], `max(1e-6, 64 ε)`:
//! rows within about 1e-3 rad of the others. The test is scale-free (each
//! row is measured against itself), and the value is deliberately loose:
//! redundancy holds only on the constraint surface, and the stages of an
//! integrator sit slightly off it, where a redundant row is weakly
//! independent. A cutoff near machine precision then enforces a spurious
//! constraint and the integration stalls or blows up (observed with cutoffs
//! up to 1e-9); 1e-6 is where it was observed to work. `64 ε`
//! keeps the test meaningful in `f32`.

use nalgebra::{RealField, SMatrix, SVector};

/// The relative pivot tolerance `max(1e-6, 64 ε)` on `sin²θ` (module docs).
#[inline]
pub fn rank_tolerance<T: RealField + Copy>() -> T {
    let floor = nalgebra::convert::<f64, T>(1e-6);
    let eps = T::default_epsilon() * nalgebra::convert::<f64, T>(64.0);
    if eps > floor {
        eps
    } else {
        floor
    }
}

/// The pivoted `LDLᵀ` factorization `P S Pᵀ = L D Lᵀ` of a symmetric
/// positive semidefinite `S`, rank revealing: at each step the remaining row
/// most independent of those eliminated (largest `sin²θ`) is pivoted on, and
/// rows whose `sin²θ` is below [`rank_tolerance`] get a zero pivot (`D⁺`),
/// which removes them from the system. Factor once with
/// [`PivotedLdlt::new`], then [`solve`](PivotedLdlt::solve) for any number
/// of right-hand sides. `O(K³)` operations on the stack; never divides by
/// zero. Non-finite input is refused (`None`), and so is a solution beyond
/// `T`'s range (`S = 5e-324 I`: `λ = 2e323 r`), rather than returned as
/// NaN or infinite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PivotedLdlt<T, const K: usize> {
    /// Unit lower factor, rows in the original order, columns by step.
    l: SMatrix<T, K, K>,
    /// Pivots by step; zero for a dropped row.
    d: SVector<T, K>,
    /// `order[step]`: the row pivoted on at that step.
    order: [usize; K],
}

impl<T: RealField + Copy, const K: usize> PivotedLdlt<T, K> {
    /// Factors `s` (only its values are read; it need not be definite).
    /// `None` when an entry of `s` is not finite.
    #[must_use]
    pub fn new(s: &SMatrix<T, K, K>) -> Option<Self> {
        if s.iter().all(|x| x.is_finite()) {
            Some(Self::factor(s))
        } else {
            None
        }
    }

    /// `λ = S^{1} r` with the {1}-inverse `Pᵀ L⁻ᵀ D⁺ L⁻¹ P`: for a
    /// consistent system (`r` in the range of `S`) `S λ = r`, and `Aᵀλ` is
    /// the same as with the Moore–Penrose inverse. `None` when `r` or the
    /// result is not finite: the exact solution is beyond `T`'s range (a
    /// subnormal pivot), never returned as NaN or infinite entries.
    #[must_use]
    pub fn solve(&self, r: &SVector<T, K>) -> Option<SVector<T, K>> {
        if !r.iter().all(|x| x.is_finite()) {
            return None;
        }
        let lambda = self.solve_unchecked(r);
        lambda.iter().all(|x| x.is_finite()).then_some(lambda)
    }

    /// [`new`](Self::new) without the finiteness check, for the runtime's
    /// own solvers, which check their results.
    #[inline]
    pub(crate) fn factor(s: &SMatrix<T, K, K>) -> Self {
        let tol = rank_tolerance::<T>();
        let mut a = *s; // Schur complements, in the original row order
        let mut l = SMatrix::<T, K, K>::zeros();
        let mut d = SVector::<T, K>::zeros();
        let mut order = [0usize; K];
        let mut done = [false; K];
        for step in 0..K {
            // The most independent remaining row: largest sin²θ = a_ii / s_ii.
            let mut best: Option<(usize, T)> = None;
            for i in 0..K {
                if done[i] {
                    continue;
                }
                let ratio = if s[(i, i)] > T::zero() {
                    a[(i, i)] / s[(i, i)]
                } else {
                    T::zero()
                };
                if best.is_none_or(|(_, b)| ratio > b) {
                    best = Some((i, ratio));
                }
            }
            let Some((p, ratio)) = best else { break };
            order[step] = p;
            done[p] = true;
            // Dependent (or NaN): zero pivot, no update.
            if ratio.partial_cmp(&tol) != Some(core::cmp::Ordering::Greater) {
                continue;
            }
            let dp = a[(p, p)];
            d[step] = dp;
            for i in 0..K {
                if !done[i] {
                    l[(i, step)] = a[(i, p)] / dp;
                }
            }
            for i in 0..K {
                for j in 0..K {
                    if !done[i] && !done[j] {
                        a[(i, j)] -= l[(i, step)] * dp * l[(j, step)];
                    }
                }
            }
        }
        PivotedLdlt { l, d, order }
    }

    /// The number of rows kept (nonzero pivots): the numerical rank of `S`.
    #[must_use]
    pub fn rank(&self) -> usize {
        self.d.iter().filter(|x| **x != T::zero()).count()
    }

    /// Whether row `row` of `S` was kept (a nonzero pivot), not dropped as
    /// dependent on the others. `false` for a row out of range.
    #[must_use]
    pub fn is_kept(&self, row: usize) -> bool {
        (0..K).any(|step| self.order[step] == row && self.d[step] != T::zero())
    }

    /// The matrix of [`solve_unchecked`](Self::solve_unchecked): its
    /// solves of the identity's columns (a {1}-inverse of the factored
    /// matrix, its inverse where every row is kept).
    #[must_use]
    pub(crate) fn inverse_unchecked(&self) -> SMatrix<T, K, K> {
        let mut inverse = SMatrix::<T, K, K>::zeros();
        for j in 0..K {
            let mut unit = SVector::<T, K>::zeros();
            unit[j] = T::one();
            inverse.set_column(j, &self.solve_unchecked(&unit));
        }
        inverse
    }

    /// [`solve`](Self::solve) without the finiteness check: a result
    /// beyond `T`'s range comes back as infinite or NaN entries (the
    /// runtime's solvers check what they derive from it).
    #[inline]
    #[must_use]
    pub(crate) fn solve_unchecked(&self, r: &SVector<T, K>) -> SVector<T, K> {
        let (l, d, order) = (&self.l, &self.d, &self.order);
        // Solve L y = P r, z = D⁺ y, Lᵀ w = z, λ = Pᵀ w.
        let mut y = SVector::<T, K>::zeros();
        for step in 0..K {
            let row = order[step];
            let mut v = r[row];
            for prev in 0..step {
                v -= l[(row, prev)] * y[prev];
            }
            y[step] = v;
        }
        let mut w = SVector::<T, K>::zeros();
        for step in (0..K).rev() {
            let mut v = if d[step] != T::zero() {
                y[step] / d[step]
            } else {
                T::zero()
            };
            for next in step + 1..K {
                v -= l[(order[next], step)] * w[next];
            }
            w[step] = v;
        }
        let mut lambda = SVector::<T, K>::zeros();
        for step in 0..K {
            lambda[order[step]] = w[step];
        }
        lambda
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    #[test]
    fn solves_a_definite_system() {
        let s = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        let r = Vector3::new(1.0, -2.0, 0.5);
        let lambda = PivotedLdlt::new(&s).unwrap().solve(&r).unwrap();
        assert!((s * lambda - r).norm() < 1e-14);
    }

    #[test]
    fn is_a_one_inverse_of_a_singular_matrix() {
        // S = B Bᵀ with rank 2; r in the range of S: S λ = r must hold.
        let b = nalgebra::Matrix3x2::new(1.0, 2.0, 0.5, -1.0, 1.5, 1.0);
        let s = b * b.transpose();
        let r = s * Vector3::new(0.3, -0.7, 1.1);
        let ldlt = PivotedLdlt::new(&s).unwrap();
        assert_eq!(ldlt.rank(), 2);
        let lambda = ldlt.solve(&r).unwrap();
        assert!(
            (s * lambda - r).norm() < 1e-12,
            "{}",
            (s * lambda - r).norm()
        );
        // S G S = S for the {1}-inverse G applied column by column.
        for j in 0..3 {
            let col = s.column(j).into_owned();
            assert!((s * ldlt.solve(&col).unwrap() - col).norm() < 1e-12);
        }
    }

    #[test]
    fn zero_matrix_gives_zero() {
        let ldlt = PivotedLdlt::new(&Matrix3::<f64>::zeros()).unwrap();
        assert_eq!(ldlt.rank(), 0);
        let lambda = ldlt.solve(&Vector3::new(1.0, 2.0, 3.0)).unwrap();
        assert_eq!(lambda, Vector3::zeros());
    }

    /// `S = 5e-324 I` gave `[NaN, NaN, inf]` for `r = [1, 1, 1]` (the
    /// exact `λ = 2e323` overflows): `None` now. A subnormal `S` whose
    /// solution is representable is still solved (to the few digits a
    /// subnormal holds).
    #[test]
    fn subnormal_pivots_give_a_finite_solution_or_none() {
        let tiny = f64::from_bits(1); // 5e-324
        let ldlt = PivotedLdlt::new(&(Matrix3::identity() * tiny)).unwrap();
        assert_eq!(ldlt.solve(&Vector3::new(1.0, 1.0, 1.0)), None);
        let s = Matrix3::from_diagonal(&Vector3::new(1e-310, 2e-310, 4e-310));
        let lambda = PivotedLdlt::new(&s)
            .unwrap()
            .solve(&Vector3::new(1e-310, 1e-310, 1e-310))
            .unwrap();
        for (got, want) in lambda.iter().zip([1.0f64, 0.5, 0.25]) {
            assert!((got - want).abs() < 1e-12 * want, "{lambda}");
        }
    }

    /// Non-finite input is refused, not factored into NaN.
    #[test]
    fn non_finite_input_is_refused() {
        for bad in [f64::NAN, f64::INFINITY] {
            let mut s = Matrix3::<f64>::identity();
            s[(1, 2)] = bad;
            assert!(PivotedLdlt::new(&s).is_none());
            let ldlt = PivotedLdlt::new(&Matrix3::<f64>::identity()).unwrap();
            assert_eq!(ldlt.solve(&Vector3::new(1.0, bad, 0.0)), None);
        }
    }

    #[test]
    fn tolerance_is_loose_in_f64_and_meaningful_in_f32() {
        assert_eq!(rank_tolerance::<f64>(), 1e-6);
        assert!(rank_tolerance::<f32>() > 64.0 * f32::EPSILON * 0.99);
    }
}
