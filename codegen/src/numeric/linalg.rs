//! Small dense `f64` linear algebra for compile-time checks, and the exact
//! inverse of a constant matrix.

use crate::expr::num::Num;

/// Whether the symmetric matrix `m` is positive definite (Cholesky succeeds
/// with pivots above a relative tolerance).
pub fn is_positive_definite(m: &[Vec<f64>]) -> bool {
    let n = m.len();
    let scale = (0..n).map(|i| m[i][i].abs()).fold(0.0, f64::max);
    let mut l = vec![vec![0.0; n]; n];
    for j in 0..n {
        let d = m[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        // Written so that a NaN pivot also fails.
        if d.partial_cmp(&(1e-12 * scale)) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        l[j][j] = d.sqrt();
        for i in j + 1..n {
            l[i][j] = (m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>()) / l[j][j];
        }
    }
    true
}

/// Whether the symmetric matrix `m` is positive semi-definite (to a
/// relative tolerance): `M + δI` is positive definite for a `δ` of 1e-10 of
/// the largest diagonal entry.
pub fn is_positive_semidefinite(m: &[Vec<f64>]) -> bool {
    let n = m.len();
    let scale = (0..n).map(|i| m[i][i].abs()).fold(0.0, f64::max);
    if scale == 0.0 {
        return m.iter().flatten().all(|&x| x == 0.0);
    }
    let shifted: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| m[i][j] + if i == j { 1e-10 * scale } else { 0.0 })
                .collect()
        })
        .collect();
    is_positive_definite(&shifted)
}

#[cfg(test)]
mod tests {
    use super::{is_positive_definite, is_positive_semidefinite};

    #[test]
    fn positive_semidefiniteness() {
        assert!(is_positive_semidefinite(&[vec![1.0, 1.0], vec![1.0, 1.0]]));
        assert!(is_positive_semidefinite(&[
            vec![5000.0, 0.0],
            vec![0.0, 1e-9]
        ]));
        assert!(!is_positive_semidefinite(&[vec![1.0, 2.0], vec![2.0, 1.0]]));
        assert!(!is_positive_semidefinite(&[vec![-1.0]]));
    }

    #[test]
    fn positive_definiteness() {
        assert!(is_positive_definite(&[vec![2.0, 1.0], vec![1.0, 2.0]]));
        assert!(!is_positive_definite(&[vec![1.0, 2.0], vec![2.0, 1.0]]));
        assert!(!is_positive_definite(&[vec![0.0]]));
        assert!(!is_positive_definite(&[vec![-1.0]]));
    }
}

/// The columns of `a` (rows × columns, row-major) chosen greedily by pivoted
/// Gram–Schmidt: each step takes the remaining column with the largest
/// `sin²` of its angle to the span of those already chosen, and stops when
/// that is at most `tol`. The number chosen is the numerical rank.
pub fn independent_columns(a: &[Vec<f64>], tol: f64) -> Vec<usize> {
    let cols = a.first().map_or(0, Vec::len);
    let column = |j: usize| -> Vec<f64> { a.iter().map(|row| row[j]).collect() };
    let norms: Vec<f64> = (0..cols).map(|j| dot(&column(j), &column(j))).collect();
    let mut residual: Vec<Vec<f64>> = (0..cols).map(column).collect();
    let mut chosen = Vec::new();
    while chosen.len() < cols {
        let best = (0..cols)
            .filter(|j| !chosen.contains(j))
            .map(|j| {
                let r = dot(&residual[j], &residual[j]);
                (j, if norms[j] > 0.0 { r / norms[j] } else { 0.0 })
            })
            .fold(None, |best: Option<(usize, f64)>, (j, s)| match best {
                Some((_, b)) if b >= s => best,
                _ => Some((j, s)),
            });
        let Some((p, sin2)) = best else { break };
        if sin2 <= tol {
            break;
        }
        chosen.push(p);
        let unit: Vec<f64> = {
            let n = dot(&residual[p], &residual[p]).sqrt();
            residual[p].iter().map(|x| x / n).collect()
        };
        for (j, r) in residual.iter_mut().enumerate() {
            if !chosen.contains(&j) {
                let c = dot(r, &unit);
                r.iter_mut().zip(&unit).for_each(|(x, u)| *x -= c * u);
            }
        }
    }
    chosen
}

/// The minimum-norm `x` with `J x = r` (least squares if inconsistent):
/// `x = Jᵀ y` with `(J Jᵀ) y = r` solved on the independent rows of `J`.
pub fn minimum_norm_solve(j: &[Vec<f64>], r: &[f64]) -> Vec<f64> {
    let n = j.first().map_or(0, Vec::len);
    let jt: Vec<Vec<f64>> = (0..n)
        .map(|c| j.iter().map(|row| row[c]).collect())
        .collect();
    // Independent rows of J are independent columns of Jᵀ.
    let rows = independent_columns(&jt, 1e-20);
    let m = rows.len();
    let mut gram: Vec<Vec<f64>> = (0..m)
        .map(|a| (0..m).map(|b| dot(&j[rows[a]], &j[rows[b]])).collect())
        .collect();
    let mut y: Vec<f64> = rows.iter().map(|&i| r[i]).collect();
    // Gaussian elimination on the (positive definite) Gram matrix.
    for c in 0..m {
        let pivot = gram[c][c];
        for i in c + 1..m {
            let f = gram[i][c] / pivot;
            let (above, below) = gram.split_at_mut(i);
            below[0][c..]
                .iter_mut()
                .zip(&above[c][c..])
                .for_each(|(x, p)| *x -= f * p);
            y[i] -= f * y[c];
        }
    }
    for c in (0..m).rev() {
        let s: f64 = (c + 1..m).map(|k| gram[c][k] * y[k]).sum();
        y[c] = (y[c] - s) / gram[c][c];
    }
    (0..n)
        .map(|col| rows.iter().zip(&y).map(|(&i, yi)| j[i][col] * yi).sum())
        .collect()
}

/// The damped least-squares step `x = (JᵀJ + μ I)⁻¹ Jᵀ r` (Levenberg–
/// Marquardt), `μ` a `damping` fraction of the largest diagonal entry of
/// `JᵀJ`: the least-squares `x` where `J` has full column rank, kept finite
/// and short along directions where it has not (an overdetermined residual
/// whose rows lose rank at its zero). `JᵀJ + μ I` is positive definite, so
/// elimination needs no pivoting.
pub fn damped_least_squares(j: &[Vec<f64>], r: &[f64], damping: f64) -> Vec<f64> {
    let n = j.first().map_or(0, Vec::len);
    let column = |c: usize| -> Vec<f64> { j.iter().map(|row| row[c]).collect() };
    let columns: Vec<Vec<f64>> = (0..n).map(column).collect();
    let mut normal: Vec<Vec<f64>> = (0..n)
        .map(|a| (0..n).map(|b| dot(&columns[a], &columns[b])).collect())
        .collect();
    let largest = (0..n).map(|i| normal[i][i]).fold(0.0, f64::max);
    let mu = damping * largest + f64::MIN_POSITIVE;
    (0..n).for_each(|i| normal[i][i] += mu);
    let mut x: Vec<f64> = columns.iter().map(|c| dot(c, r)).collect();
    for c in 0..n {
        let pivot = normal[c][c];
        for i in c + 1..n {
            let f = normal[i][c] / pivot;
            let (above, below) = normal.split_at_mut(i);
            below[0][c..]
                .iter_mut()
                .zip(&above[c][c..])
                .for_each(|(y, p)| *y -= f * p);
            x[i] -= f * x[c];
        }
    }
    for c in (0..n).rev() {
        let s: f64 = (c + 1..n).map(|k| normal[c][k] * x[k]).sum();
        x[c] = (x[c] - s) / normal[c][c];
    }
    x
}

/// `a · b`.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod rank_tests {
    use super::*;

    #[test]
    fn rank_and_choice_of_columns() {
        // Column 2 = column 0 + column 1; column 3 is zero.
        let a = vec![
            vec![1.0, 0.0, 1.0, 0.0],
            vec![0.0, 2.0, 2.0, 0.0],
            vec![1.0, 1.0, 2.0, 0.0],
        ];
        let chosen = independent_columns(&a, 1e-12);
        assert_eq!(chosen.len(), 2);
        assert!(!chosen.contains(&3));
    }

    #[test]
    fn minimum_norm_solution() {
        // x + y = 2 (twice, redundantly): minimum norm x = y = 1.
        let j = vec![vec![1.0, 1.0], vec![2.0, 2.0]];
        let x = minimum_norm_solve(&j, &[2.0, 4.0]);
        assert!(
            (x[0] - 1.0).abs() < 1e-14 && (x[1] - 1.0).abs() < 1e-14,
            "{x:?}"
        );
    }

    #[test]
    fn damped_least_squares_solves_consistent_rows_and_stays_finite_without_rank() {
        // Three consistent rows in two unknowns: the solution, to the damping.
        let j = vec![vec![1.0, 2.0], vec![3.0, -1.0], vec![1.0, 1.0]];
        let x = damped_least_squares(&j, &[5.0, 1.0, 3.0], 1e-14);
        assert!(
            (x[0] - 1.0).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12,
            "{x:?}"
        );
        // A zero column: that unknown is left alone, the other solved.
        let j = vec![vec![2.0, 0.0], vec![0.0, 0.0]];
        let x = damped_least_squares(&j, &[4.0, 1.0], 1e-12);
        assert!((x[0] - 2.0).abs() < 1e-10 && x[1] == 0.0, "{x:?}");
    }
}

/// The exact inverse of a constant matrix by Gauss–Jordan elimination in
/// rationals (floats only where a literal was not a short decimal), or
/// `None` when it is singular.
pub fn exact_inverse(m: &[Vec<Num>]) -> Option<Vec<Vec<Num>>> {
    let n = m.len();
    let mut work: Vec<Vec<Num>> = m
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let mut r = row.clone();
            r.extend((0..n).map(|j| if i == j { Num::ONE } else { Num::ZERO }));
            r
        })
        .collect();
    for c in 0..n {
        let p = (c..n).find(|&r| !work[r][c].is_zero())?;
        work.swap(c, p);
        let pivot = work[c][c];
        for x in work[c].iter_mut() {
            *x = *x / pivot;
        }
        let pivot_row = work[c].clone();
        for (r, row) in work.iter_mut().enumerate() {
            let f = row[c];
            if r != c && !f.is_zero() {
                for (x, p) in row.iter_mut().zip(&pivot_row) {
                    *x = *x + -(f * *p);
                }
            }
        }
    }
    Some(work.into_iter().map(|row| row[n..].to_vec()).collect())
}
