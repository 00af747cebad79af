//! The explicit Gibbs–Appell equation (Udwadia & Kalaba eq. 18 and 37) for
//! fixed sizes, without allocation.
//!
//! With `r` the rank of `A`, the accelerations of `r` coordinates `e` are
//! eliminated through `q̈_e = A_e⁺ (b − A_I q̈_I)` (eq. 8), `A_e⁺ = (A_eᵀ A_e)⁻¹ A_eᵀ`,
//! `R = A_e⁺ A_I`, and the system
//!
//! ```text
//! [ A_e   A_I ] [q̈_e]   [ b                                   ]
//! [ 0     B   ] [q̈_I] = [ F_I − Rᵀ F_e + (Rᵀ M_ee − M_Ie) A_e⁺ b ]
//! B = M_II + Rᵀ M_ee R − M_Ie R − Rᵀ M_Ieᵀ
//! ```
//!
//! is returned as an `N × N` matrix in the original column order: `r`
//! independent rows of `A q̈ = b`, then the `N − r` rows of eq. 35 (eq. 13
//! when `M_Ie = 0`, which the caller states at compile time).
//!
//! The partition preferred at compile time is used when its columns are
//! well conditioned at the state; otherwise `r` columns are re-chosen by
//! pivoted Gram–Schmidt (ẋ = 0 in Appell's example). A set of columns is
//! measured, in order, by the smallest of its Gram–Schmidt residuals squared
//! relative to the largest squared column norm of `A` (`sin²` of the angle
//! between a column and the span of the earlier ones, scaled). The preferred
//! set is kept while that measure is at least [`WELL_CONDITIONED`]; below
//! it, the pivoted set is used if it measures better. Why not only at rank
//! loss: the error of `q̈` grows like `ε / measure` (`A_e⁺` and `R = A_e⁺ A_I`
//! both grow like its inverse square root), so a folded double pendulum,
//! whose preferred columns `x₁, y₁` are nearly parallel while `A` keeps full
//! rank, loses 8 digits without this rule; with it, 14 digits remain.
//!
//! A column or row counts when its residual, squared, exceeds
//! [`rank_tolerance`] times the largest squared norm among the candidates.
//! Where fewer than `r` qualify, `A` has dropped below rank `r` and the
//! Gibbs–Appell form is undefined: [`GibbsAppellError::RankDeficient`] (the
//! generalized-inverse form is not).

pub use crate::error::GibbsAppellError;
use crate::inverse::rank_tolerance;
use nalgebra::{RealField, SMatrix, SVector};

/// What the system and its solution share.
struct Partitioned<
    T: RealField + Copy,
    const N: usize,
    const K: usize,
    const R: usize,
    const I: usize,
> {
    eliminated: [usize; R],
    independent: [usize; I],
    rows: [usize; R],
    a_i: SMatrix<T, K, I>,
    reduced_mass: SMatrix<T, I, I>,
    reduced_force: SVector<T, I>,
}

/// The Gibbs–Appell system `(S, s)` with `S q̈ = s`, `N × N`, columns in the
/// original order. `preferred` are the `R` eliminated coordinates chosen at
/// compile time, `I = N − R`; `mass_coupled` is whether `M` may couple the
/// eliminated and independent coordinates (eq. 37 rather than eq. 18).
pub fn system<
    T: RealField + Copy,
    const N: usize,
    const K: usize,
    const R: usize,
    const I: usize,
>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    m: &SMatrix<T, N, N>,
    f: &SVector<T, N>,
    preferred: &[usize; R],
    mass_coupled: bool,
) -> Result<(SMatrix<T, N, N>, SVector<T, N>), GibbsAppellError> {
    let p = partition::<T, N, K, R, I>(a, b, m, f, preferred, mass_coupled)?;
    let mut s = SMatrix::<T, N, N>::zeros();
    let mut rhs = SVector::<T, N>::zeros();
    for (i, &row) in p.rows.iter().enumerate() {
        s.row_mut(i).copy_from(&a.row(row));
        rhs[i] = b[row];
    }
    for i in 0..I {
        for (j, &col) in p.independent.iter().enumerate() {
            s[(R + i, col)] = p.reduced_mass[(i, j)];
        }
        rhs[R + i] = p.reduced_force[i];
    }
    Ok((s, rhs))
}

/// `q̈` from the Gibbs–Appell system, solved through its block structure:
/// the reduced (positive definite) block for `q̈_I` by Cholesky, then the
/// `r` chosen rows of `A q̈ = b` for `q̈_e`. Checked after the fact: the
/// chosen rows must hold to `√ε` (relative; else `IllConditioned`) and so
/// must every other row of `A q̈ = b` (else `Inconsistent`: off a redundant
/// model's surface).
pub fn acceleration<
    T: RealField + Copy,
    const N: usize,
    const K: usize,
    const R: usize,
    const I: usize,
>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    m: &SMatrix<T, N, N>,
    f: &SVector<T, N>,
    preferred: &[usize; R],
    mass_coupled: bool,
) -> Result<SVector<T, N>, GibbsAppellError> {
    let (a_scaled, b_scaled) = scaled_rows(a, b)?;
    let (a, b) = (&a_scaled, &b_scaled);
    let p = partition::<T, N, K, R, I>(a, b, m, f, preferred, mass_coupled)?;
    let qdd_i = reduced_solve(&p)?;
    let square = SMatrix::<T, R, R>::from_fn(|i, j| a[(p.rows[i], p.eliminated[j])]);
    let top = SVector::<T, R>::from_fn(|i, _| b[p.rows[i]] - (p.a_i.row(p.rows[i]) * qdd_i)[0]);
    let qdd_e = solve_square(square, top).ok_or(GibbsAppellError::RankDeficient)?;
    let mut qdd = SVector::<T, N>::zeros();
    for (j, &col) in p.eliminated.iter().enumerate() {
        qdd[col] = qdd_e[j];
    }
    for (j, &col) in p.independent.iter().enumerate() {
        qdd[col] = qdd_i[j];
    }
    check_rows(a, b, &p.rows, &qdd)?;
    Ok(qdd)
}

/// Each row of `A q̈ = b` scaled to unit largest entry: the same equations
/// and null space, but `A_eᵀA_e` neither overflows nor underflows for
/// coordinates far from 1 (1e154 or 1e-154 in f64). `Err(Underflow)` for a
/// row whose largest entry is below the smallest normal value.
fn scaled_rows<T: RealField + Copy, const N: usize, const K: usize>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
) -> Result<(SMatrix<T, K, N>, SVector<T, K>), GibbsAppellError> {
    let (mut a_scaled, mut b_scaled) = (*a, *b);
    // 2^-126 in f32, 2^-1022 in f64 (4 over the largest value); NaN, so
    // never above, for a `T` without one.
    let smallest_normal = nalgebra::convert::<f64, T>(4.0) / crate::generated::largest::<T>();
    for i in 0..K {
        let largest = a_scaled.row(i).amax();
        // Scaling would restore the row's size, not the digits it lost to
        // underflow: in `f32` at the smallest subnormal state Appell's
        // `b = α ż` rounds 0.7·2^-149 to 2^-149, and the `q̈` that solved the
        // rounded row exactly was 1.4 % (backward) off the model's, with
        // every check passing on the rounded row.
        if largest > T::zero() && largest < smallest_normal {
            return Err(GibbsAppellError::Underflow);
        }
        if largest > T::zero() {
            a_scaled.row_mut(i).unscale_mut(largest);
            b_scaled[i] /= largest;
        }
    }
    Ok((a_scaled, b_scaled))
}

/// `q̈_I` from the reduced (positive definite) block by Cholesky, refused
/// (`IllConditioned`) where its conditioning cannot give it to `√ε`.
fn reduced_solve<
    T: RealField + Copy,
    const N: usize,
    const K: usize,
    const R: usize,
    const I: usize,
>(
    p: &Partitioned<T, N, K, R, I>,
) -> Result<SVector<T, I>, GibbsAppellError> {
    let cholesky = nalgebra::linalg::Cholesky::new(p.reduced_mass)
        .ok_or(GibbsAppellError::MassNotPositiveDefinite)?;
    // (max Lᵢᵢ / min Lᵢᵢ)² bounds cond(B) from below: beyond 1/√ε the
    // reduced solve cannot give q̈ to √ε, and the result is not returned.
    let diagonal = cholesky.l_dirty().diagonal();
    let (largest, smallest) = (diagonal.max(), diagonal.min());
    let limit = T::one() / T::default_epsilon().sqrt();
    // A B at underflow scale (a quaternion model's M at |e| ~ 1e-155) has
    // lost its digits whatever its condition.
    let underflow = largest * largest < crate::rank::safe_minimum();
    let positive = smallest.partial_cmp(&T::zero()) == Some(core::cmp::Ordering::Greater);
    if underflow || !positive || (largest / smallest) * (largest / smallest) > limit {
        return Err(GibbsAppellError::IllConditioned);
    }
    Ok(cholesky.solve(&p.reduced_force))
}

/// The check after the fact: the `R` chosen `rows` of `A q̈ = b` must hold
/// to `√ε` (relative; else `IllConditioned`, or `NonFinite`), and so must
/// every other row (else `Inconsistent`).
fn check_rows<T: RealField + Copy, const N: usize, const K: usize, const R: usize>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    rows: &[usize; R],
    qdd: &SVector<T, N>,
) -> Result<(), GibbsAppellError> {
    // The r chosen rows of A q̈ = b must hold (to √ε, the form's accuracy).
    let chosen_a = SMatrix::<T, R, N>::from_fn(|i, j| a[(rows[i], j)]);
    let chosen_b = SVector::<T, R>::from_fn(|i, _| b[rows[i]]);
    let residual = crate::rank::relative_residual(&chosen_a, &chosen_b, qdd);
    let accurate = residual.partial_cmp(&T::default_epsilon().sqrt())
        != Some(core::cmp::Ordering::Greater)
        && residual.is_finite();
    if !accurate {
        return Err(if residual.is_finite() {
            GibbsAppellError::IllConditioned
        } else {
            GibbsAppellError::NonFinite
        });
    }
    // And so must every other row: the form's promise is A q̈ = b, which
    // the partition's rows imply only where the rest depend on them (a
    // redundant model on its surface). Off it the left-out row is violated
    // (the redundant double pendulum at 1e-8 scale: relative 1.01).
    if K > R && crate::rank::relative_residual(a, b, qdd) > T::default_epsilon().sqrt() {
        return Err(GibbsAppellError::Inconsistent);
    }
    Ok(())
}

fn partition<
    T: RealField + Copy,
    const N: usize,
    const K: usize,
    const R: usize,
    const I: usize,
>(
    a: &SMatrix<T, K, N>,
    b: &SVector<T, K>,
    m: &SMatrix<T, N, N>,
    f: &SVector<T, N>,
    preferred: &[usize; R],
    mass_coupled: bool,
) -> Result<Partitioned<T, N, K, R, I>, GibbsAppellError> {
    const {
        assert!(
            R + I == N,
            "the eliminated and independent coordinates must be all N"
        )
    };
    let eliminated = eliminated_columns(a, preferred)?;
    // With k = r and r independent columns, A_e is square and invertible:
    // every row is independent and none needs choosing.
    let rows = if K == R {
        core::array::from_fn(|i| i)
    } else {
        pivoted::<T, N, K, R>(&a.transpose())
            .ok_or(GibbsAppellError::RankDeficient)?
            .0
    };
    let mut independent = [0usize; I];
    let mut next = 0;
    for col in 0..N {
        if !eliminated.contains(&col) {
            if let Some(slot) = independent.get_mut(next) {
                *slot = col;
            }
            next += 1;
        }
    }
    let a_e = SMatrix::<T, K, R>::from_fn(|i, j| a[(i, eliminated[j])]);
    let a_i = SMatrix::<T, K, I>::from_fn(|i, j| a[(i, independent[j])]);
    let gram = nalgebra::linalg::Cholesky::new(a_e.transpose() * a_e)
        .ok_or(GibbsAppellError::RankDeficient)?;
    let a_e_pinv: SMatrix<T, R, K> = gram.solve(&a_e.transpose());
    let r = a_e_pinv * a_i;
    let m_ee = SMatrix::<T, R, R>::from_fn(|i, j| m[(eliminated[i], eliminated[j])]);
    let m_ii = SMatrix::<T, I, I>::from_fn(|i, j| m[(independent[i], independent[j])]);
    let f_e = SVector::<T, R>::from_fn(|i, _| f[eliminated[i]]);
    let f_i = SVector::<T, I>::from_fn(|i, _| f[independent[i]]);
    let y = a_e_pinv * b;
    let mut reduced_mass = m_ii + r.transpose() * m_ee * r;
    let mut reduced_force = f_i - r.transpose() * f_e + r.transpose() * (m_ee * y);
    if mass_coupled {
        // Eq. 37's extra terms; they vanish when M_Ie = 0 (eq. 18).
        let m_ie = SMatrix::<T, I, R>::from_fn(|i, j| m[(independent[i], eliminated[j])]);
        let coupling = m_ie * r;
        reduced_mass -= coupling + coupling.transpose();
        reduced_force -= m_ie * y;
    }
    Ok(Partitioned {
        eliminated,
        independent,
        rows,
        a_i,
        reduced_mass,
        reduced_force,
    })
}

/// The measure (module docs) above which the preferred partition is kept:
/// every preferred column at least `asin(1/4) ≈ 14°` from the span of the
/// earlier ones, at full scale. Below it the error bound is at least 16
/// times that of perfectly conditioned columns, and re-pivoting costs
/// `O(R·K·N)`, little beside the `O(N³)` of the reduced system.
pub const WELL_CONDITIONED: f64 = 1.0 / 16.0;

/// The `R` columns to eliminate at this state: the preferred ones while
/// well conditioned, else the better of them and the pivoted choice.
fn eliminated_columns<T: RealField + Copy, const K: usize, const N: usize, const R: usize>(
    a: &SMatrix<T, K, N>,
    preferred: &[usize; R],
) -> Result<[usize; R], GibbsAppellError> {
    if R == 0 {
        return Ok(*preferred);
    }
    let scale = largest_squared_norm(a);
    let threshold = rank_tolerance::<T>() * scale;
    let kept = measure_in_order(a, preferred);
    if kept >= nalgebra::convert::<f64, T>(WELL_CONDITIONED) * scale {
        return Ok(*preferred);
    }
    match pivoted::<T, K, N, R>(a) {
        Some((cols, measure)) if measure > kept => Ok(cols),
        // Greedy pivoting is not optimal: the preferred set may still win.
        _ if kept > threshold => Ok(*preferred),
        _ => Err(GibbsAppellError::RankDeficient),
    }
}

/// The smallest squared Gram–Schmidt residual of the columns `cols` of `a`,
/// taken in order; zero when one vanishes or is not finite.
fn measure_in_order<T: RealField + Copy, const K: usize, const N: usize, const R: usize>(
    a: &SMatrix<T, K, N>,
    cols: &[usize; R],
) -> T {
    let mut basis = [SVector::<T, K>::zeros(); R];
    let mut smallest: Option<T> = None;
    for (step, &c) in cols.iter().enumerate() {
        let residual = residual(&a.column(c).into_owned(), &basis[..step]);
        let norm2 = residual.norm_squared();
        if norm2.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
            return T::zero();
        }
        smallest = Some(smallest.map_or(norm2, |s| s.min(norm2)));
        basis[step] = residual / norm2.sqrt();
    }
    smallest.unwrap_or_else(T::zero)
}

/// `R` columns of `a` by pivoted (modified) Gram–Schmidt, largest residual
/// first, with the smallest squared residual taken, or `None` when fewer
/// than `R` are independent. The residuals are updated in place after each
/// choice: O(R·K·N) operations.
fn pivoted<T: RealField + Copy, const K: usize, const N: usize, const R: usize>(
    a: &SMatrix<T, K, N>,
) -> Option<([usize; R], T)> {
    let threshold = rank_tolerance::<T>() * largest_squared_norm(a);
    let mut residuals = *a;
    let mut chosen = [0usize; R];
    let mut taken = [false; N];
    let mut smallest: Option<T> = None;
    for slot in chosen.iter_mut() {
        let mut best: Option<(usize, T)> = None;
        for (c, column) in residuals.column_iter().enumerate() {
            let norm2 = column.norm_squared();
            if !taken[c] && best.is_none_or(|(_, b)| norm2 > b) {
                best = Some((c, norm2));
            }
        }
        let (c, norm2) = best?;
        if norm2.partial_cmp(&threshold) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        smallest = Some(smallest.map_or(norm2, |s| s.min(norm2)));
        *slot = c;
        taken[c] = true;
        let unit = residuals.column(c) / norm2.sqrt();
        for (j, mut column) in residuals.column_iter_mut().enumerate() {
            if !taken[j] {
                let projection = unit.dot(&column);
                column.axpy(-projection, &unit, T::one());
            }
        }
    }
    Some((chosen, smallest.unwrap_or_else(T::zero)))
}

/// `x` with `m x = rhs` by Gaussian elimination with partial pivoting, or
/// `None` for an exactly singular `m` (nalgebra's `LU` needs type-level
/// sizes a const generic cannot give).
fn solve_square<T: RealField + Copy, const R: usize>(
    mut m: SMatrix<T, R, R>,
    mut rhs: SVector<T, R>,
) -> Option<SVector<T, R>> {
    for c in 0..R {
        let p = (c..R).max_by(|&i, &j| {
            m[(i, c)]
                .abs()
                .partial_cmp(&m[(j, c)].abs())
                .unwrap_or(core::cmp::Ordering::Equal)
        })?;
        if m[(p, c)] == T::zero() {
            return None;
        }
        m.swap_rows(p, c);
        rhs.swap_rows(p, c);
        for i in c + 1..R {
            let factor = m[(i, c)] / m[(c, c)];
            for j in c..R {
                let v = m[(c, j)];
                m[(i, j)] -= factor * v;
            }
            let v = rhs[c];
            rhs[i] -= factor * v;
        }
    }
    for c in (0..R).rev() {
        let mut v = rhs[c];
        for j in c + 1..R {
            v -= m[(c, j)] * rhs[j];
        }
        rhs[c] = v / m[(c, c)];
    }
    Some(rhs)
}

fn residual<T: RealField + Copy, const K: usize>(
    v: &SVector<T, K>,
    basis: &[SVector<T, K>],
) -> SVector<T, K> {
    let mut r = *v;
    for u in basis {
        r -= u * u.dot(&r);
    }
    r
}

fn largest_squared_norm<T: RealField + Copy, const K: usize, const N: usize>(
    a: &SMatrix<T, K, N>,
) -> T {
    a.column_iter()
        .map(|c| c.norm_squared())
        .fold(T::zero(), |m, x| if x > m { x } else { m })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1x3, Matrix3, Vector1, Vector3};

    /// Appell's particle: eq. 33 entry by entry, with e = {x}.
    #[test]
    fn appell_eq33() {
        let (xd, yd, zd, g, b) = (1.3, -0.7, 0.4, 9.81, 0.25);
        let a = Matrix1x3::new(xd, yd, -zd);
        let (s, rhs) = system::<f64, 3, 1, 1, 2>(
            &a,
            &Vector1::new(b),
            &Matrix3::identity(),
            &Vector3::new(0.0, 0.0, -g),
            &[0],
            false,
        )
        .unwrap();
        let x2 = xd * xd;
        let expected = Matrix3::new(
            xd,
            yd,
            -zd,
            0.0,
            1.0 + yd * yd / x2,
            -yd * zd / x2,
            0.0,
            -yd * zd / x2,
            1.0 + zd * zd / x2,
        );
        assert!((s - expected).norm() < 1e-14, "{s} vs {expected}");
        let expected_rhs = Vector3::new(b, b * yd / x2, -g - b * zd / x2);
        assert!((rhs - expected_rhs).norm() < 1e-14);
    }

    #[test]
    fn re_pivots_when_the_preferred_column_vanishes() {
        // ẋ = 0: column x of A is zero; y and z remain.
        let a = Matrix1x3::new(0.0, 0.8, -0.3);
        let qdd = acceleration::<f64, 3, 1, 1, 2>(
            &a,
            &Vector1::new(0.1),
            &Matrix3::identity(),
            &Vector3::new(0.0, 0.0, -9.81),
            &[0],
            false,
        )
        .unwrap();
        assert!(((a * qdd)[0] - 0.1).abs() < 1e-14);
    }

    /// Appell's rows in `f32` at the smallest subnormal velocity: `b = α ż`
    /// rounds `0.7·2^-149` to `2^-149`, and the `q̈` solving the rounded row
    /// (which every check on it passed) is 1.4 % off the model's.
    #[test]
    fn a_subnormal_row_is_underflow_not_a_solution_of_its_rounding() {
        let tiny = f32::from_bits(1);
        let result = acceleration::<f32, 3, 1, 1, 2>(
            &Matrix1x3::new(tiny, tiny, -tiny),
            &Vector1::new(0.7 * tiny),
            &Matrix3::identity(),
            &Vector3::new(0.0, 0.0, -9.81),
            &[0],
            false,
        );
        assert_eq!(result, Err(GibbsAppellError::Underflow));
        // Just above the smallest normal number the row keeps its digits.
        let small = 2.0 * f32::MIN_POSITIVE;
        let qdd = acceleration::<f32, 3, 1, 1, 2>(
            &Matrix1x3::new(small, small, -small),
            &Vector1::new(0.7 * small),
            &Matrix3::identity(),
            &Vector3::new(0.0, 0.0, -9.81),
            &[0],
            false,
        )
        .expect("normal rows");
        let residual = (qdd[0] + qdd[1] - qdd[2] - 0.7) / 9.81;
        assert!(residual.abs() < 1e-6, "{qdd}");
    }

    #[test]
    fn rank_deficient_is_an_error() {
        let result = system::<f64, 3, 1, 1, 2>(
            &Matrix1x3::zeros(),
            &Vector1::new(0.0),
            &Matrix3::identity(),
            &Vector3::zeros(),
            &[0],
            false,
        );
        assert_eq!(result, Err(GibbsAppellError::RankDeficient));
    }
}
